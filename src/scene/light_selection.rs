//! How next-event estimation picks a light: in proportion to its estimated power, so that a
//! scene with a bright sun and many dim lamps spends its shadow rays where the light is. The
//! choice is an alias table (alias_table.rs): one uniform bucket and one comparison, whatever
//! the number of lights. Its buckets live in the emitters themselves
//! (`GpuEmitter::keep`, `alias`), with each emitter's probability (`pmf`) for MIS weights. The directional lights come last.

use super::alias_table::AliasTable;
use super::lights::{luminance, LightKind, LightSelection, PunctualLight};
use crate::shader_layout::*;
use glam::Vec3;

/// Appends the scene's punctual lights (those that emit anything) to the area emitters and
/// builds the table over all of them. Local lights (area, point, spot) are picked by power
/// among themselves; a light at infinity (directional) cannot be compared with them by power,
/// which for it grows with the extent of the scene (a sun over a 100 m ground plane would
/// outweigh every lamp in the room the camera is in), so each one takes an equal share with
/// the local lights as a group — pbrt-v4's split between infinite and local lights.
/// An HDR environment map (`environment`) is a light at infinity too.
/// Returns the environment's probability (0 without one).
/// With [`LightSelection::Uniform`] every emitter weighs the same instead.
pub fn add_lights_and_select_by_power(
    emitters: &mut Vec<GpuEmitter>,
    lights: &[PunctualLight],
    environment: bool,
    selection: LightSelection,
) -> f32 {
    let mut local_powers: Vec<f32> = emitters.iter().map(area_power).collect();
    let mut infinite = Vec::new();
    if environment {
        infinite.push(GpuEmitter {
            kind: KIND_ENVIRONMENT,
            object: NO_OBJECT,
            ..Default::default()
        });
    }
    for light in lights.iter().filter(|l| l.intensity.max_element() > 0.0) {
        match light.kind {
            LightKind::Directional => infinite.push(punctual_emitter(light)),
            _ => {
                emitters.push(punctual_emitter(light));
                local_powers.push(light.local_power());
            }
        }
    }
    let local_total: f64 = local_powers.iter().map(|&p| usable(p)).sum();
    let groups = infinite.len() + usize::from(local_total > 0.0);
    let mut weights: Vec<f64> = local_powers
        .iter()
        .map(|&p| usable(p) / local_total.max(f64::MIN_POSITIVE) / groups as f64)
        .collect();
    weights.extend(infinite.iter().map(|_| 1.0 / groups as f64));
    emitters.extend(infinite);
    if selection == LightSelection::Uniform {
        weights = vec![1.0; emitters.len()];
    }
    assign_alias_table(emitters, &weights);
    (emitters.iter())
        .find(|e| e.kind == KIND_ENVIRONMENT)
        .map_or(0.0, |e| e.pmf)
}

/// A power the table can use: positive and finite, else 0.
fn usable(p: f32) -> f64 {
    if p.is_finite() && p > 0.0 {
        p as f64
    } else {
        0.0
    }
}

/// A punctual light as the shaders read it (shared.h's GpuEmitter).
fn punctual_emitter(light: &PunctualLight) -> GpuEmitter {
    let (spot_scale, spot_offset) = light.spot_scale_offset();
    let p = light.position;
    let d = light.direction;
    GpuEmitter {
        p0: [p.x, p.y, p.z, 0.0],
        p1: [d.x, d.y, d.z, 0.0],
        emission: [light.intensity.x, light.intensity.y, light.intensity.z, 0.0],
        kind: match light.kind {
            LightKind::Point => KIND_POINT_LIGHT,
            LightKind::Spot { .. } => KIND_SPOT_LIGHT,
            LightKind::Directional => KIND_DIRECTIONAL_LIGHT,
        },
        object: NO_OBJECT,
        range: light.range.unwrap_or(0.0),
        spot_scale,
        spot_offset,
        ..Default::default()
    }
}

/// An area emitter's power as the table weighs it: π × area × luminance of its radiance (what a
/// Lambertian emitter sends into its hemisphere).
pub fn area_power(e: &GpuEmitter) -> f32 {
    let radiance = Vec3::from_slice(&e.emission[..3]);
    std::f32::consts::PI * e.emission[3] * luminance(radiance)
}

/// Sets every emitter's `pmf`, `keep` and `alias` from the table over `powers`.
pub fn assign_alias_table(emitters: &mut [GpuEmitter], powers: &[f64]) {
    assert_eq!(emitters.len(), powers.len());
    let table = AliasTable::new(powers);
    for (i, e) in emitters.iter_mut().enumerate() {
        e.pmf = table.pmf[i] as f32;
        e.keep = table.keep[i];
        e.alias = table.alias[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The probability of each emitter under the table, summed over buckets.
    fn chosen(emitters: &[GpuEmitter]) -> Vec<f64> {
        let n = emitters.len() as f64;
        let mut p = vec![0.0; emitters.len()];
        for (i, e) in emitters.iter().enumerate() {
            p[i] += e.keep as f64 / n;
            p[e.alias as usize] += (1.0 - e.keep as f64) / n;
        }
        p
    }

    #[test]
    fn the_table_picks_each_emitter_in_proportion_to_its_power() {
        let powers = [1000.0, 1.0, 1.0, 0.0, 3.0, 0.5, 7.0];
        let mut emitters = vec![GpuEmitter::default(); powers.len()];
        assign_alias_table(&mut emitters, &powers);
        let total: f64 = powers.iter().sum();
        for (i, p) in chosen(&emitters).iter().enumerate() {
            let expected = powers[i] / total;
            assert!(
                (p - expected).abs() < 1e-6,
                "emitter {i}: {p} vs {expected}"
            );
            assert!((emitters[i].pmf as f64 - expected).abs() < 1e-6);
        }
    }

    #[test]
    fn without_power_the_choice_is_uniform() {
        let mut emitters = vec![GpuEmitter::default(); 4];
        assign_alias_table(&mut emitters, &[0.0, f64::NAN, 0.0, 0.0]);
        for p in chosen(&emitters) {
            assert!((p - 0.25).abs() < 1e-9);
        }
    }
}
