//! `KHR_lights_punctual`: a node's light in world space (the node's position, its −Z axis as
//! the direction light travels), with its intensity in fovea's units (scene/lights.rs).

use glam::{Mat4, Vec3};
use gltf::khr_lights_punctual::{Kind, Light};

use crate::scene::{LightKind, PunctualLight};

/// The light `light` placed by the node's world transform; the error says what is wrong.
/// The extension's properties are unaffected by the node's scale (range, intensity), and the
/// direction is the transformed −Z axis made unit length.
pub(super) fn world_light(light: &Light, world: Mat4) -> Result<PunctualLight, String> {
    let kind = match light.kind() {
        Kind::Point => LightKind::Point,
        Kind::Directional => LightKind::Directional,
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => LightKind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        },
    };
    let axis = world.transform_vector3(Vec3::NEG_Z);
    if axis.length() <= 0.0 || !axis.is_finite() {
        return Err(
            "its node's transform collapses the light's direction (a zero scale): fix the \
             node's scale"
                .to_owned(),
        );
    }
    let result = PunctualLight {
        kind,
        intensity: Vec3::from(light.color()) * light.intensity(),
        position: world.transform_point3(Vec3::ZERO),
        direction: axis.normalize(),
        range: light.range(),
    };
    match result.problem() {
        Some(problem) => Err(problem),
        None => Ok(result),
    }
}
