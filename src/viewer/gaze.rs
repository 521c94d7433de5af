//! The mouse as the gaze. In mono the cursor's pixel is the gaze pixel. In stereo the cursor
//! lies in one eye's half of the window: that eye looks at the pixel under it, and the other
//! eye looks at the same point in the scene, found as in the XR path (the gaze ray's closest
//! hit, projected into the other eye; a miss fixates at infinity), so both eyes converge on
//! what the cursor points at.

use crate::foveation::fixation;
use crate::foveation::gaze_source::GazeSource;
use crate::foveation::gaze_trace::TraceStatus;
use crate::foveation::{Gaze, ImageGeometry};
use crate::scene::cpu_raycast::CpuRaycaster;
use crate::scene::Camera;

/// The eye under a window pixel and the pixel in that eye's image (continuous coordinates),
/// for `eyes` eyes of `eye_size` pixels shown side by side, scaled to fill `window` pixels.
pub fn window_to_eye(
    cursor: [f64; 2],
    window: [u32; 2],
    eyes: usize,
    eye_size: [u32; 2],
) -> (usize, [f64; 2]) {
    let per_eye = window[0] as f64 / eyes as f64;
    let eye = ((cursor[0] / per_eye).floor().max(0.0) as usize).min(eyes - 1);
    let x = (cursor[0] - eye as f64 * per_eye) / per_eye * eye_size[0] as f64;
    let y = cursor[1] / window[1] as f64 * eye_size[1] as f64;
    (eye, [x, y])
}

/// The mouse as a [`GazeSource`], for one frame: the cursor where it was last seen in the
/// window (a cursor that left the window holds its last position; none seen yet is the view
/// axis), the window's size now, and the scene to find what the cursor points at.
pub struct MouseGaze<'a> {
    pub cursor: Option<[f64; 2]>,
    pub window: [u32; 2],
    pub raycaster: &'a CpuRaycaster,
}

impl GazeSource for MouseGaze<'_> {
    fn gaze(&mut self, _frame: u64, _time_s: f64, eyes: &[(Camera, ImageGeometry)]) -> Vec<Gaze> {
        match self.cursor {
            Some(cursor) => mouse_gazes(cursor, self.window, eyes, self.raycaster),
            None => vec![Gaze::Forward; eyes.len()],
        }
    }

    fn status(&self) -> TraceStatus {
        match self.cursor {
            Some(_) => TraceStatus::Tracked,
            None => TraceStatus::Centre,
        }
    }
}

/// Each eye's gaze for the cursor at window pixel `cursor`, the eyes (pose and image, left
/// first) shown side by side in a window of `window` pixels.
pub fn mouse_gazes(
    cursor: [f64; 2],
    window: [u32; 2],
    eyes: &[(Camera, ImageGeometry)],
    raycaster: &CpuRaycaster,
) -> Vec<Gaze> {
    let size = [eyes[0].1.width, eyes[0].1.height];
    let (looking, pixel) = window_to_eye(cursor, window, eyes.len(), size);
    let on_cursor = Gaze::Pixel(pixel[0], pixel[1]);
    if eyes.len() == 1 {
        return vec![on_cursor];
    }
    let (camera, image) = &eyes[looking];
    let t = image.tan_of(pixel[0], pixel[1]);
    let (r, u, f) = camera.basis();
    let dir = f + r * t[0] as f32 + u * t[1] as f32;
    let projected = fixation::eye_gazes(
        |o, d| raycaster.closest_hit(o, d),
        camera.position,
        dir,
        eyes,
    );
    projected
        .iter()
        .enumerate()
        .map(|(e, p)| match (e == looking, p) {
            // The eye under the cursor looks exactly there (its own projection only adds rounding).
            (true, _) => on_cursor,
            (false, Some(p)) => Gaze::Pixel(p[0], p[1]),
            // Not projectable into the other eye (behind it): the same pixel there.
            (false, None) => on_cursor,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::GazeChoice;
    use crate::render::{eye_views, FovChoice};
    use crate::scene::builtin::builtin;

    #[test]
    fn window_pixels_map_to_eyes() {
        assert_eq!(
            window_to_eye([48.0, 32.0], [96, 64], 1, [96, 64]),
            (0, [48.0, 32.0])
        );
        // Rendering at half the window's resolution.
        assert_eq!(
            window_to_eye([48.0, 32.0], [96, 64], 1, [48, 32]),
            (0, [24.0, 16.0])
        );
        // Two eyes of 48x64 side by side in a 96x64 window.
        assert_eq!(
            window_to_eye([60.0, 10.0], [96, 64], 2, [48, 64]),
            (1, [12.0, 10.0])
        );
        assert_eq!(window_to_eye([-5.0, 10.0], [96, 64], 2, [48, 64]).0, 0);
        assert_eq!(window_to_eye([500.0, 10.0], [96, 64], 2, [48, 64]).0, 1);
    }

    #[test]
    fn stereo_eyes_converge_on_the_surface_under_the_cursor() {
        let (w, h) = (64u32, 64u32);
        let scene = builtin("cornell", w as f32 / h as f32).unwrap();
        let raycaster = CpuRaycaster::new(&scene);
        let forward: GazeChoice = "forward".parse().unwrap();
        let eyes: Vec<_> = eye_views(&scene.camera, 1.0, FovChoice::Scene, true, forward)
            .iter()
            .map(|e| (e.camera, e.image(w, h)))
            .collect();
        // The cursor on the left eye's centre: the left eye looks there; the right eye, IPD to
        // the right, sees the same near surface a little to the left of its own centre.
        let mut mouse = MouseGaze {
            cursor: Some([32.0, 32.0]),
            window: [128, 64],
            raycaster: &raycaster,
        };
        assert_eq!(mouse.status(), TraceStatus::Tracked);
        let gazes = mouse.gaze(0, 0.0, &eyes);
        assert_eq!(gazes[0], Gaze::Pixel(32.0, 32.0));
        let Gaze::Pixel(x, y) = gazes[1] else {
            panic!("{:?}", gazes[1])
        };
        assert!(x < 32.0 && x > 28.0, "{x}");
        assert!((y - 32.0).abs() < 1e-3, "{y}");
    }
}
