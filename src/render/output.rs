//! Writing frames as files a user can open: 8-bit sRGB PNG (through the display transform)
//! and linear, scene-referred float EXR.

use super::display::DisplayTransform;
use super::{Frame, RenderError};
use std::path::{Path, PathBuf};

fn output_error(path: &Path, problem: impl std::fmt::Display) -> RenderError {
    RenderError::Output {
        path: path.display().to_string(),
        problem: problem.to_string(),
    }
}

// The sRGB encodings live with the display transform; callers know them from here too.
pub use super::display::{linear_to_srgb, linear_to_srgb8};

pub fn write_png(
    frame: &Frame,
    path: &Path,
    display: &DisplayTransform,
) -> Result<(), RenderError> {
    let file = std::fs::File::create(path).map_err(|e| output_error(path, e))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), frame.width, frame.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder.write_header().map_err(|e| output_error(path, e))?;
    let bytes = display.srgb8(&frame.rgb);
    writer
        .write_image_data(&bytes)
        .map_err(|e| output_error(path, e))?;
    writer.finish().map_err(|e| output_error(path, e))
}

pub fn write_exr(frame: &Frame, path: &Path) -> Result<(), RenderError> {
    write_rgb_exr(path, frame.width, frame.height, &frame.rgb).map_err(|e| output_error(path, e))
}

/// Writes linear RGB (row-major, `width` x `height`) as an EXR whose bytes depend on the
/// pixels alone: its chunks are compressed one after the other, in order (the exr crate's
/// parallel writer stores them in whatever order its threads finish, so the same image made
/// different files).
pub fn write_rgb_exr(path: &Path, width: u32, height: u32, rgb: &[f32]) -> exr::error::UnitResult {
    use exr::prelude::*;
    let w = width as usize;
    let channels = SpecificChannels::rgb(|at: Vec2<usize>| {
        let i = 3 * (at.y() * w + at.x());
        (rgb[i], rgb[i + 1], rgb[i + 2])
    });
    Image::from_channels((w, height as usize), channels)
        .write()
        .non_parallel()
        .to_file(path)
}

/// Writes `path` (.png or .exr). A PNG shows the frame through `display` and also gets a
/// linear .exr beside it, so no precision is lost. Returns every file written.
pub fn write_frame(
    frame: &Frame,
    path: &Path,
    display: &DisplayTransform,
) -> Result<Vec<PathBuf>, RenderError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_lowercase);
    match ext.as_deref() {
        Some("exr") => {
            write_exr(frame, path)?;
            Ok(vec![path.to_path_buf()])
        }
        Some("png") => {
            write_png(frame, path, display)?;
            let exr = path.with_extension("exr");
            write_exr(frame, &exr)?;
            Ok(vec![path.to_path_buf(), exr])
        }
        _ => Err(output_error(
            path,
            "the output name must end in .png or .exr",
        )),
    }
}
