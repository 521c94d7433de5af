//! How fast held movement keys fly the camera, from the scene's scale.

use super::session::Session;

/// Held movement keys fly this fraction of the distance to what the camera looks at per
/// second: a scene crosses in a few seconds whatever its scale.
const SPEED_PER_DISTANCE: f32 = 0.5;

/// The speed of held movement keys for the session's scene: half the distance to what the
/// camera looks at per second (1 unit if it looks at nothing).
pub(super) fn move_speed(session: &Session) -> f32 {
    let c = &session.scene.camera;
    let distance = session
        .raycaster
        .closest_hit(c.position, c.forward.normalize())
        .filter(|d| d.is_finite() && *d > 0.0)
        .unwrap_or(1.0);
    distance * SPEED_PER_DISTANCE
}
