//! [`image_strip`]: images side by side under captions, written as one PNG.

use std::path::{Path, PathBuf};

use plotters::backend::RGBPixel;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::canvas::{create_parent, ensure_font, FONT};
use super::types::{Panel, PlotError, STRIP_CAPTION_HEIGHT, STRIP_GAP};

/// Writes a PNG (at `path`, used as given) with the panels side by side, left
/// to right, each under a caption band of [`STRIP_CAPTION_HEIGHT`] px, with
/// [`STRIP_GAP`] px of white between panels. Width = Σ widths + gap·(k − 1);
/// height = caption band + tallest panel (shorter panels are top-aligned on
/// white). Errors: no panels, an `rgb8` length ≠ width·height·3, or an empty
/// or oversized (> u32 pixels) result.
pub fn image_strip(path: &Path, panels: &[Panel]) -> Result<PathBuf, PlotError> {
    let (buf, size) = compose(path, panels)?;
    create_parent(path)?;
    encode_png(path, &buf, size)?;
    Ok(path.into())
}

/// Writes an animated PNG (APNG; a viewer without APNG shows the first frame) at `path`:
/// frame `k` is the strip of `frames[k]`, as [`image_strip`] draws it, shown for
/// `delay_ms` milliseconds; it loops forever. Every frame must have panels of the same
/// sizes (the strip's size is the first frame's).
pub fn animated_strip(
    path: &Path,
    frames: &[Vec<Panel>],
    delay_ms: u16,
) -> Result<PathBuf, PlotError> {
    let Some(first) = frames.first() else {
        return Err(PlotError::NoPanels { path: path.into() });
    };
    let size = strip_size(path, first)?;
    create_parent(path)?;
    let io = |source| PlotError::Io {
        path: path.into(),
        source,
    };
    let encode = |source| PlotError::Encode {
        path: path.into(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), size.0, size.1);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    // Rendered noise compresses poorly: the best deflate and per-row filters make the
    // animation about a quarter smaller than the defaults, for a moment's more CPU.
    enc.set_compression(png::Compression::Best);
    enc.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
    enc.set_animated(frames.len() as u32, 0).map_err(encode)?;
    enc.set_frame_delay(delay_ms, 1000).map_err(encode)?;
    let mut writer = enc.write_header().map_err(encode)?;
    for panels in frames {
        let (buf, this_size) = compose(path, panels)?;
        if this_size != size {
            return Err(PlotError::BadSize {
                path: path.into(),
                width: this_size.0.into(),
                height: this_size.1.into(),
            });
        }
        writer.write_image_data(&buf).map_err(encode)?;
    }
    writer.finish().map_err(encode)?;
    Ok(path.into())
}

/// The strip's pixels and size: panels blitted side by side under their captions.
fn compose(path: &Path, panels: &[Panel]) -> Result<(Vec<u8>, (u32, u32)), PlotError> {
    if panels.is_empty() {
        return Err(PlotError::NoPanels { path: path.into() });
    }
    check_panels(path, panels)?;
    let (w, h) = strip_size(path, panels)?;
    let mut buf = vec![255u8; w as usize * h as usize * 3];
    let mut x0 = 0u32;
    for p in panels {
        blit(&mut buf, w, p, x0, STRIP_CAPTION_HEIGHT);
        x0 += p.width + STRIP_GAP;
    }
    ensure_font(path)?;
    draw_captions(&mut buf, (w, h), panels).map_err(|message| PlotError::Draw {
        path: path.into(),
        message,
    })?;
    Ok((buf, (w, h)))
}

fn check_panels(path: &Path, panels: &[Panel]) -> Result<(), PlotError> {
    for (index, p) in panels.iter().enumerate() {
        let expected = u64::from(p.width) * u64::from(p.height) * 3;
        if p.rgb8.len() as u64 != expected {
            let (label, width, height, actual) = (p.label.clone(), p.width, p.height, p.rgb8.len());
            return Err(PlotError::PanelSize {
                path: path.into(),
                index,
                label,
                width,
                height,
                expected,
                actual,
            });
        }
    }
    Ok(())
}

/// Strip size, checked so that width·height fits in u32 (plotters and PNG
/// both index pixels with u32).
fn strip_size(path: &Path, panels: &[Panel]) -> Result<(u32, u32), PlotError> {
    let gaps = u64::from(STRIP_GAP) * (panels.len() as u64 - 1);
    let w = panels.iter().map(|p| u64::from(p.width)).sum::<u64>() + gaps;
    let h = u64::from(STRIP_CAPTION_HEIGHT)
        + panels
            .iter()
            .map(|p| u64::from(p.height))
            .max()
            .unwrap_or(0);
    let fits = w > 0 && w.checked_mul(h).is_some_and(|px| px <= u64::from(u32::MAX));
    match (fits, u32::try_from(w), u32::try_from(h)) {
        (true, Ok(w32), Ok(h32)) => Ok((w32, h32)),
        _ => Err(PlotError::BadSize {
            path: path.into(),
            width: w,
            height: h,
        }),
    }
}

/// Copies a panel's rows into the strip buffer at (x0, y0).
fn blit(buf: &mut [u8], strip_w: u32, p: &Panel, x0: u32, y0: u32) {
    let row_bytes = p.width as usize * 3;
    if row_bytes == 0 {
        return;
    }
    for (y, row) in p.rgb8.chunks_exact(row_bytes).enumerate() {
        let start = ((y0 as usize + y) * strip_w as usize + x0 as usize) * 3;
        buf[start..start + row_bytes].copy_from_slice(row);
    }
}

/// Renders each caption centred above its panel, straight into the buffer.
fn draw_captions(buf: &mut [u8], size: (u32, u32), panels: &[Panel]) -> Result<(), String> {
    let backend =
        BitMapBackend::<RGBPixel>::with_buffer_and_format(buf, size).map_err(|e| e.to_string())?;
    let root = backend.into_drawing_area();
    let style = TextStyle::from((FONT, 18).into_font()).pos(Pos::new(HPos::Center, VPos::Center));
    let mut x0 = 0i32;
    for p in panels {
        let centre = (x0 + p.width as i32 / 2, STRIP_CAPTION_HEIGHT as i32 / 2);
        root.draw_text(&p.label, &style, centre)
            .map_err(|e| e.to_string())?;
        x0 += (p.width + STRIP_GAP) as i32;
    }
    root.present().map_err(|e| e.to_string())
}

fn encode_png(path: &Path, rgb: &[u8], (w, h): (u32, u32)) -> Result<(), PlotError> {
    let io = |source| PlotError::Io {
        path: path.into(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let encode = |source| PlotError::Encode {
        path: path.into(),
        source,
    };
    let mut writer = enc.write_header().map_err(encode)?;
    writer.write_image_data(rgb).map_err(encode)?;
    writer.finish().map_err(encode)
}
