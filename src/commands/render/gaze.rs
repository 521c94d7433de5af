//! Gaze from a source (a replayed trace) for the eyes of a frame, shared by the single
//! frame, `--bench` and `--camera-path`.

use fovea::foveation::{GazeSource, ImageGeometry};
use fovea::render::{EyeView, RenderSettings};
use fovea::scene::Camera;

/// The eyes with the gazes `source` gives for frame `frame` (time: `frame` at 90 Hz, a
/// headset's rate; the sources here do not look at it).
pub fn with_source_gaze(
    eyes: &[EyeView],
    source: &mut dyn GazeSource,
    frame: u64,
    settings: &RenderSettings,
) -> Vec<EyeView> {
    let views: Vec<(Camera, ImageGeometry)> = eyes
        .iter()
        .map(|e| (e.camera, e.image(settings.width, settings.height)))
        .collect();
    let gazes = source.gaze(frame, frame as f64 / 90.0, &views);
    eyes.iter()
        .zip(gazes)
        .map(|(e, gaze)| EyeView { gaze, ..*e })
        .collect()
}
