//! Rigid-transform maths on OpenXR's own `Posef`, just enough to locate spaces.
//!
//! Every space in the simulated world is a fixed rigid transform relative to the LOCAL
//! origin ("world"), so locating A in B is `inverse(B) * A`.

use openxr_sys::{Posef, Quaternionf, Vector3f};

pub const IDENTITY: Posef = Posef {
    orientation: Quaternionf {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    },
    position: Vector3f {
        x: 0.0,
        y: 0.0,
        z: 0.0,
    },
};

fn quat_mul(a: Quaternionf, b: Quaternionf) -> Quaternionf {
    Quaternionf {
        w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
        x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
        y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
        z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
    }
}

fn conjugate(q: Quaternionf) -> Quaternionf {
    Quaternionf {
        x: -q.x,
        y: -q.y,
        z: -q.z,
        w: q.w,
    }
}

/// Rotates `v` by the unit quaternion `q` (q v q*).
pub fn rotate(q: Quaternionf, v: Vector3f) -> Vector3f {
    let p = Quaternionf {
        x: v.x,
        y: v.y,
        z: v.z,
        w: 0.0,
    };
    let r = quat_mul(quat_mul(q, p), conjugate(q));
    Vector3f {
        x: r.x,
        y: r.y,
        z: r.z,
    }
}

/// `a * b`: the transform that first applies `b`, then `a`.
pub fn compose(a: Posef, b: Posef) -> Posef {
    let moved = rotate(a.orientation, b.position);
    Posef {
        orientation: normalize(quat_mul(a.orientation, b.orientation)),
        position: Vector3f {
            x: a.position.x + moved.x,
            y: a.position.y + moved.y,
            z: a.position.z + moved.z,
        },
    }
}

pub fn inverse(p: Posef) -> Posef {
    let inv = conjugate(p.orientation);
    let t = rotate(inv, p.position);
    Posef {
        orientation: inv,
        position: Vector3f {
            x: -t.x,
            y: -t.y,
            z: -t.z,
        },
    }
}

pub fn normalize(q: Quaternionf) -> Quaternionf {
    let n = (q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w).sqrt();
    Quaternionf {
        x: q.x / n,
        y: q.y / n,
        z: q.z / n,
        w: q.w / n,
    }
}

/// True when `q` is a unit quaternion within the spec's tolerance; `xrCreate*Space`
/// must reject anything else with XR_ERROR_POSE_INVALID.
pub fn is_valid(p: &Posef) -> bool {
    let q = p.orientation;
    let n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    let finite = [q.x, q.y, q.z, q.w, p.position.x, p.position.y, p.position.z]
        .iter()
        .all(|c| c.is_finite());
    finite && (n2 - 1.0).abs() < 1e-2
}

/// The orientation that turns the view axis (-Z) towards the direction `yaw` to the right
/// and `pitch` up (radians): a pitch about +X followed by a yaw about +Y. A positive yaw
/// is a rotation by `-yaw` about +Y because +Y rotations carry -Z towards -X.
pub fn gaze_orientation(yaw: f32, pitch: f32) -> Quaternionf {
    let q_yaw = Quaternionf {
        x: 0.0,
        y: (-yaw * 0.5).sin(),
        z: 0.0,
        w: (-yaw * 0.5).cos(),
    };
    let q_pitch = Quaternionf {
        x: (pitch * 0.5).sin(),
        y: 0.0,
        z: 0.0,
        w: (pitch * 0.5).cos(),
    };
    normalize(quat_mul(q_yaw, q_pitch))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vector3f, b: [f32; 3]) -> bool {
        (a.x - b[0]).abs() < 1e-5 && (a.y - b[1]).abs() < 1e-5 && (a.z - b[2]).abs() < 1e-5
    }

    const FORWARD: Vector3f = Vector3f {
        x: 0.0,
        y: 0.0,
        z: -1.0,
    };

    #[test]
    fn gaze_yaw_right_turns_forward_to_plus_x() {
        let q = gaze_orientation(90f32.to_radians(), 0.0);
        assert!(close(rotate(q, FORWARD), [1.0, 0.0, 0.0]));
    }

    #[test]
    fn gaze_pitch_up_turns_forward_to_plus_y() {
        let q = gaze_orientation(0.0, 90f32.to_radians());
        assert!(close(rotate(q, FORWARD), [0.0, 1.0, 0.0]));
    }

    #[test]
    fn gaze_direction_matches_spherical_formula() {
        let (yaw, pitch) = (20f32.to_radians(), -10f32.to_radians());
        let d = rotate(gaze_orientation(yaw, pitch), FORWARD);
        let expected = [
            pitch.cos() * yaw.sin(),
            pitch.sin(),
            -pitch.cos() * yaw.cos(),
        ];
        assert!(close(d, expected), "{d:?} vs {expected:?}");
    }

    #[test]
    fn inverse_composes_to_identity() {
        let p = Posef {
            orientation: gaze_orientation(0.3, 0.2),
            position: Vector3f {
                x: 1.0,
                y: -2.0,
                z: 0.5,
            },
        };
        let id = compose(inverse(p), p);
        assert!(close(id.position, [0.0, 0.0, 0.0]));
        assert!((id.orientation.w.abs() - 1.0).abs() < 1e-5);
    }
}
