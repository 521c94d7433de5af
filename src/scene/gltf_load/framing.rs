//! The camera made up for a file that has none.

use glam::Vec3;

use crate::scene::{Camera, Instance, Mesh};

/// Vertical field of view of the camera made up when the file has none.
const FRAMING_FOV_Y_DEG: f32 = 40.0;
/// Frames the world bounding box of all instances: from +Z, slightly above, 40° vertical field
/// of view, far enough back that the bounding sphere fits both fields of view.
pub(super) fn frame_bounds(meshes: &[Mesh], instances: &[Instance], aspect: f32) -> Camera {
    let mut min = Vec3::splat(f32::INFINITY);
    let mut max = Vec3::splat(f32::NEG_INFINITY);
    for instance in instances {
        let Some(mesh) = meshes.get(instance.mesh as usize) else {
            continue;
        };
        for &p in &mesh.positions {
            let w = instance.transform.transform_point3(p);
            min = min.min(w);
            max = max.max(w);
        }
    }
    let (centre, radius) = if min.cmple(max).all() {
        (0.5 * (min + max), (0.5 * (max - min).length()).max(1e-3))
    } else {
        (Vec3::ZERO, 1.0)
    };
    let half_y = (0.5 * FRAMING_FOV_Y_DEG).to_radians();
    let half_x = (half_y.tan() * aspect).atan();
    let distance = 1.05 * radius / half_y.min(half_x).sin();
    let direction = Vec3::new(0.0, 0.35, 1.0).normalize();
    Camera::look_at(
        centre + direction * distance,
        centre,
        Vec3::Y,
        FRAMING_FOV_Y_DEG,
        aspect,
    )
}
