//! Punctual lights (glTF's `KHR_lights_punctual`): points, spots and directional lights, in
//! world space, with the extension's units taken as fovea's radiometric units one for one.
//!
//! Units: a point or spot light of intensity I candela has radiant intensity I in fovea's
//! radiance × m² (a surface facing it at distance d receives irradiance I / d²); a
//! directional light of E lux gives irradiance E. Emission (`emissiveFactor` ×
//! `KHR_materials_emissive_strength`) is radiance in the same units, so a 1 cd point light and
//! a white emissive surface of strength 1 are as the Khronos glTF Sample Viewer and three.js
//! show them. This is Blender's glTF importer's "Unitless" lighting mode (W = cd × 4π, sun
//! strength = lux); its default "Standard" mode divides every light by 683 lm/W and leaves
//! emission alone, so a scene imported that way has lights 683× dimmer than fovea's.

use glam::Vec3;

/// What kind of punctual light, with its shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Light in every direction from a point.
    Point,
    /// A point light limited to a cone around `direction`: full intensity within
    /// `inner_cone_angle`, none beyond `outer_cone_angle` (radians, 0 ≤ inner < outer ≤ π/2),
    /// the extension's smooth falloff between.
    Spot {
        inner_cone_angle: f32,
        outer_cone_angle: f32,
    },
    /// Parallel light travelling along `direction` (the sun).
    Directional,
}

/// One punctual light in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PunctualLight {
    pub kind: LightKind,
    /// Linear RGB colour × intensity: radiant intensity (point, spot) or irradiance
    /// (directional) per channel, in fovea's units (module docs).
    pub intensity: Vec3,
    /// Position (point, spot); unused for a directional light.
    pub position: Vec3,
    /// The unit direction light travels (spot, directional): the node's −Z axis.
    pub direction: Vec3,
    /// The distance beyond which the light has no effect, windowed smoothly
    /// (`clamp(1 − (d/range)⁴, 0, 1)` as the extension recommends); `None`: unlimited.
    pub range: Option<f32>,
}

impl PunctualLight {
    /// The extension's spot falloff as `(scale, offset)`: the intensity is multiplied by
    /// `saturate(cos θ · scale + offset)²`, θ from the spot's axis. A point light's is 1.
    pub fn spot_scale_offset(&self) -> (f32, f32) {
        match self.kind {
            LightKind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let (cos_inner, cos_outer) = (inner_cone_angle.cos(), outer_cone_angle.cos());
                let scale = 1.0 / (cos_inner - cos_outer).max(1e-3);
                (scale, -cos_outer * scale)
            }
            _ => (0.0, 1.0),
        }
    }

    /// The fraction of its full intensity the light sends at angle θ from its axis
    /// (`cos θ` given): the spot's falloff, 1 for the others.
    pub fn cone_falloff(&self, cos_theta: f32) -> f32 {
        let (scale, offset) = self.spot_scale_offset();
        let s = (cos_theta * scale + offset).clamp(0.0, 1.0);
        s * s
    }

    /// What is wrong with the light, if anything (a zero intensity is allowed: it is dropped).
    pub fn problem(&self) -> Option<String> {
        if !(self.intensity.is_finite() && self.intensity.min_element() >= 0.0) {
            return Some(format!(
                "its colour × intensity {} is negative or not finite: give a colour in [0, 1] \
                 and an intensity ≥ 0",
                self.intensity
            ));
        }
        if !(self.position.is_finite() && self.direction.is_finite())
            || (self.direction.length() - 1.0).abs() > 1e-3
        {
            return Some(format!(
                "its position {} or direction {} is not finite (or not unit length): fix the \
                 node's transform",
                self.position, self.direction
            ));
        }
        if let Some(range) = self.range {
            if !(range > 0.0 && range.is_finite()) {
                return Some(format!(
                    "its range {range} is not a positive number: omit it for an unlimited light"
                ));
            }
        }
        if let LightKind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } = self.kind
        {
            let right_angle = std::f32::consts::FRAC_PI_2;
            if !(0.0..right_angle + 1e-6).contains(&outer_cone_angle)
                || outer_cone_angle <= 0.0
                || !(0.0..outer_cone_angle).contains(&inner_cone_angle)
            {
                return Some(format!(
                    "its cone angles (inner {inner_cone_angle}, outer {outer_cone_angle} \
                     radians) are outside the extension's range 0 ≤ inner < outer ≤ π/2"
                ));
            }
        }
        None
    }

    /// A local light's power as next-event estimation weighs it (luminance, in fovea's
    /// units): 4π I for a point, the solid angle of its cone (to the falloff's middle) × I for
    /// a spot. A directional light has none that compares (light_selection.rs): 0.
    pub fn local_power(&self) -> f32 {
        let y = luminance(self.intensity);
        match self.kind {
            LightKind::Point => 4.0 * std::f32::consts::PI * y,
            LightKind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let half = 0.5 * (inner_cone_angle + outer_cone_angle);
                2.0 * std::f32::consts::PI * (1.0 - half.cos()) * y
            }
            LightKind::Directional => 0.0,
        }
    }
}

/// How next-event estimation weighs the lights it picks from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum LightSelection {
    /// Local lights by power, each light at infinity with an equal share beside them.
    #[default]
    Power,
    /// Every emitter equally likely (for comparison).
    Uniform,
}

/// Rec. 709 luminance of linear RGB.
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot(inner: f32, outer: f32) -> PunctualLight {
        PunctualLight {
            kind: LightKind::Spot {
                inner_cone_angle: inner,
                outer_cone_angle: outer,
            },
            intensity: Vec3::ONE,
            position: Vec3::ZERO,
            direction: -Vec3::Y,
            range: None,
        }
    }

    #[test]
    fn the_spot_falloff_is_full_inside_the_inner_cone_and_zero_beyond_the_outer() {
        let light = spot(0.2, 0.5);
        assert_eq!(light.cone_falloff(0.1f32.cos()), 1.0);
        assert_eq!(light.cone_falloff(0.6f32.cos()), 0.0);
        // Half way in cosine between the cones: (1/2)².
        let mid = 0.5 * (0.2f32.cos() + 0.5f32.cos());
        assert!((light.cone_falloff(mid) - 0.25).abs() < 1e-5);
    }

    #[test]
    fn bad_lights_are_named() {
        assert!(spot(0.5, 0.5).problem().unwrap().contains("cone angles"));
        assert!(spot(0.1, 1.7).problem().unwrap().contains("cone angles"));
        assert!(spot(0.0, 1.0).problem().is_none());
        let mut negative = spot(0.0, 1.0);
        negative.intensity = Vec3::new(1.0, -1.0, 1.0);
        assert!(negative.problem().unwrap().contains("negative"));
        let mut ranged = spot(0.0, 1.0);
        ranged.range = Some(0.0);
        assert!(ranged.problem().unwrap().contains("range"));
    }
}
