//! The side-by-side pictures of a scene: reference, regular, forward, corner and the FLIP
//! error of the forward image, all of the left eye at the protocol's spp.

use super::error::BenchError;
use super::plots::{image_strip, Panel};
use super::protocol::{BenchPlan, Mode};
use super::quality::{eye_image, Point};
use crate::metrics::magma_rgb8;
use std::collections::BTreeMap;
use std::path::Path;

/// Writes the strip of `scene`; `reference` is the side-by-side reference of both eyes,
/// `shown` the protocol-spp point of every mode. The pictures go through the scene's display
/// transform, as its PNGs do.
pub fn write_strip(
    path: &Path,
    plan: &BenchPlan,
    scene: &str,
    reference: &[f32],
    shown: &BTreeMap<Mode, Point>,
) -> Result<(), BenchError> {
    let display = plan.display.transform(scene);
    let (w, h) = (plan.width, plan.height);
    let panel = |label: String, rgb8: Vec<u8>| Panel {
        label,
        width: w,
        height: h,
        rgb8,
    };
    let mut panels = vec![panel(
        format!("reference ({} spp)", plan.reference_spp),
        display.srgb8(&eye_image(reference, super::protocol::EYES, w, h, 0)),
    )];
    for (mode, point) in shown {
        panels.push(panel(
            format!("{} ({} spp)", mode.name(), plan.spp),
            display.srgb8(&point.left_rgb),
        ));
    }
    if let Some(forward) = shown.get(&Mode::Forward) {
        panels.push(panel(
            "FLIP error, forward".to_string(),
            magma_rgb8(&forward.left_flip, w, h)?,
        ));
    }
    image_strip(path, &panels)?;
    Ok(())
}
