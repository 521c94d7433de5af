//! An environment as the shaders read it (shared.h's BINDING_ENVIRONMENT): per texel, its
//! radiance and the probability of choosing it, then its alias-table bucket. Next-event
//! estimation picks a texel from the table and a uniform point in it; texel k of a W × H map
//! at polar angle θ covers 2π²/(W·H) · sin θ of solid angle, so a direction in it has density
//! pmf[k] · W·H / (2π² sin θ).

use super::alias_table::AliasTable;
use super::env_map::EnvironmentLight;
use super::lights::luminance;

/// How next-event estimation chooses environment texels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum EnvSampling {
    /// In proportion to luminance × sin θ: where the light comes from.
    #[default]
    Importance,
    /// In proportion to sin θ alone: directions uniform over the sphere (for comparison).
    Uniform,
}

/// The GPU's texels of `env`: two per environment texel, rows from the top. First
/// (r, g, b, pmf) as float bits, the radiance × `env.intensity`; then (alias, keep bits, 0, 0).
pub fn environment_texels(env: &EnvironmentLight) -> Vec<[u32; 4]> {
    let map = &env.map;
    let (w, h) = (map.width as usize, map.height as usize);
    let weights: Vec<f64> = (0..w * h)
        .map(|i| {
            let theta = ((i / w) as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            let light = match env.sampling {
                EnvSampling::Importance => luminance(map.texels[i]) as f64,
                EnvSampling::Uniform => 1.0,
            };
            light * theta.sin()
        })
        .collect();
    let table = AliasTable::new(&weights);
    let mut texels = Vec::with_capacity(2 * w * h);
    for (i, t) in map.texels.iter().enumerate() {
        let l = *t * env.intensity;
        let pmf = table.pmf[i] as f32;
        texels.push([l.x.to_bits(), l.y.to_bits(), l.z.to_bits(), pmf.to_bits()]);
        texels.push([table.alias[i], table.keep[i].to_bits(), 0, 0]);
    }
    texels
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::env_map::EnvironmentMap;
    use glam::Vec3;
    use std::sync::Arc;

    fn env(texels: Vec<Vec3>, w: u32, sampling: EnvSampling) -> EnvironmentLight {
        let map = EnvironmentMap::from_texels("t.exr".as_ref(), w, w / 2, texels).unwrap();
        EnvironmentLight {
            map: Arc::new(map),
            rotate_deg: 0.0,
            intensity: 2.0,
            sampling,
        }
    }

    #[test]
    fn a_bright_texel_is_chosen_in_proportion_to_its_light_and_solid_angle() {
        let mut texels = vec![Vec3::splat(1.0); 8];
        texels[5] = Vec3::splat(7.0); // row 1 (of 2): the same sin θ as row 0
        let gpu = environment_texels(&env(texels, 4, EnvSampling::Importance));
        let pmf = |i: usize| f32::from_bits(gpu[2 * i][3]);
        assert!((pmf(5) - 7.0 / 14.0).abs() < 1e-6);
        assert!((pmf(0) - 1.0 / 14.0).abs() < 1e-6);
        // Radiance × intensity.
        assert_eq!(f32::from_bits(gpu[10][0]), 14.0);
        let uniform = environment_texels(&env(vec![Vec3::ONE; 8], 4, EnvSampling::Uniform));
        assert!((f32::from_bits(uniform[10][3]) - 1.0 / 8.0).abs() < 1e-6);
    }
}
