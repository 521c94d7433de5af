//! From OpenXR poses to scene cameras. OpenXR's reference space has x right, y up and looks
//! down −z; the scene's camera says where that space sits in the scene: its position is the
//! space's origin, its forward is the space's −z and its up the space's +y. An eye's camera
//! is the view pose carried into the scene by that placement.

use crate::scene::Camera;
use glam::{Quat, Vec3};
use openxr as xr;

/// Where the headset's reference space sits in the scene.
#[derive(Clone, Copy, Debug)]
pub struct SpacePlacement {
    origin: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
}

impl SpacePlacement {
    /// The reference space placed at the scene camera (the user starts where the desktop
    /// view starts).
    pub fn at_camera(camera: &Camera) -> Self {
        let (right, up, forward) = camera.basis();
        Self {
            origin: camera.position,
            right,
            up,
            forward,
        }
    }

    /// A direction in the reference space, in the scene.
    pub fn direction(&self, v: Vec3) -> Vec3 {
        self.right * v.x + self.up * v.y - self.forward * v.z
    }

    /// A point of the reference space, in the scene.
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.origin + self.direction(p)
    }

    /// The camera of a view located in the reference space, with the view's (asymmetric)
    /// field of view.
    pub fn eye_camera(&self, pose: &xr::Posef, fov: &xr::Fovf) -> Camera {
        let q = quat(&pose.orientation);
        Camera {
            position: self.point(vec(&pose.position)),
            forward: self.direction(q * Vec3::NEG_Z),
            up: self.direction(q * Vec3::Y),
            angle_left: fov.angle_left,
            angle_right: fov.angle_right,
            angle_up: fov.angle_up,
            angle_down: fov.angle_down,
        }
    }

    /// The ray a gaze pose looks along (origin and unit direction), in the scene.
    pub fn gaze_ray(&self, pose: &xr::Posef) -> (Vec3, Vec3) {
        let q = quat(&pose.orientation);
        (
            self.point(vec(&pose.position)),
            self.direction(q * Vec3::NEG_Z).normalize(),
        )
    }
}

fn vec(v: &xr::Vector3f) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// The pose's orientation, normalised (runtimes send unit quaternions up to rounding; a
/// zero one, which a broken runtime could send, becomes the identity).
fn quat(q: &xr::Quaternionf) -> Quat {
    let q = Quat::from_xyzw(q.x, q.y, q.z, q.w);
    match q.length_squared() > 1e-12 && q.is_finite() {
        true => q.normalize(),
        false => Quat::IDENTITY,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::look_at(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::Y,
            60.0,
            1.0,
        )
    }

    fn pose(position: Vec3, orientation: Quat) -> xr::Posef {
        xr::Posef {
            orientation: xr::Quaternionf {
                x: orientation.x,
                y: orientation.y,
                z: orientation.z,
                w: orientation.w,
            },
            position: xr::Vector3f {
                x: position.x,
                y: position.y,
                z: position.z,
            },
        }
    }

    #[test]
    fn identity_pose_is_the_scene_camera() {
        let c = camera();
        let fov = xr::Fovf {
            angle_left: -0.9,
            angle_right: 0.8,
            angle_up: 0.7,
            angle_down: -0.6,
        };
        let eye = SpacePlacement::at_camera(&c).eye_camera(&pose(Vec3::ZERO, Quat::IDENTITY), &fov);
        assert!((eye.position - c.position).length() < 1e-6);
        assert!((eye.forward - c.forward).length() < 1e-6);
        assert!((eye.up - Vec3::Y).length() < 1e-6);
        assert_eq!((eye.angle_left, eye.angle_down), (-0.9, -0.6));
    }

    #[test]
    fn eye_offsets_and_turns_follow_the_camera_axes() {
        // The camera looks down −z from (1, 2, 3): its right is +x, like the space's.
        let place = SpacePlacement::at_camera(&camera());
        let left_eye = place.eye_camera(
            &pose(Vec3::new(-0.03, 0.0, 0.0), Quat::IDENTITY),
            &xr::Fovf::default(),
        );
        assert!((left_eye.position - Vec3::new(0.97, 2.0, 3.0)).length() < 1e-6);
        // A head turned 90° to the left (about +y) looks down −x.
        let turned = place.eye_camera(
            &pose(
                Vec3::ZERO,
                Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            ),
            &xr::Fovf::default(),
        );
        assert!((turned.forward - Vec3::NEG_X).length() < 1e-6);
        let (o, d) = place.gaze_ray(&pose(Vec3::new(0.0, 0.1, 0.0), Quat::from_rotation_x(0.5)));
        assert!((o - Vec3::new(1.0, 2.1, 3.0)).length() < 1e-6);
        // Pitched up by 0.5 rad about +x: y grows, still looking down −z.
        assert!((d - Vec3::new(0.0, 0.5f32.sin(), -0.5f32.cos())).length() < 1e-6);
    }

    #[test]
    fn a_broken_orientation_is_the_identity() {
        let place = SpacePlacement::at_camera(&camera());
        let mut p = pose(Vec3::ZERO, Quat::IDENTITY);
        p.orientation = xr::Quaternionf {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 0.0,
        };
        let (_, d) = place.gaze_ray(&p);
        assert!((d - Vec3::NEG_Z).length() < 1e-6);
        p.orientation.x = f32::NAN;
        assert!(place.gaze_ray(&p).1.is_finite());
    }
}
