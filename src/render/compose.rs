//! For tests only (the `test-hooks` feature): a frame whose lattice values the caller gives
//! instead of tracing them, so that resolve (and the debug views) can be checked against
//! CPU references on data with known answers.

use super::eye_params::EyeLayers;
use super::frame::Frame;
use super::renderer::Renderer;
use super::request::{FrameOptions, FrameRequest};
use super::targets::FrameTargets;
use super::RenderError;
use crate::gpu::{Buffer, GpuContext};
use std::sync::Arc;

/// A lattice point whose value [`Renderer::compose`] asks for: eye, layer (innermost first)
/// and the point's pixel (which may lie off the image; those are never read).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LatticePoint {
    pub eye: usize,
    pub layer: usize,
    pub x: i32,
    pub y: i32,
}

impl Renderer {
    /// Runs only the resolve pass of `request`, on lattice values given by the caller
    /// (`value` of every lattice point of every eye and layer) instead of traced ones.
    pub fn compose(
        &mut self,
        request: &FrameRequest,
        value: impl Fn(LatticePoint) -> [f32; 4],
    ) -> Result<Frame, RenderError> {
        self.prepare(request)?;
        // The lattice buffer is replaced: no frame in flight may still use it.
        self.ring.wait_all(&self.counters)?;
        let gazes: Vec<_> = request.eyes.iter().map(|e| e.gaze).collect();
        let (eyes, _) = self.plan_eyes(request, &gazes);
        let targets = self
            .targets
            .current_mut()
            .expect("prepared by the frame above");
        let lattice = given_lattice(&self.ctx, targets, &eyes, &value)?;
        targets.replace_lattice(lattice)?;
        self.submit(request, FrameOptions::default(), false)?;
        let mut frame = self.ring.wait_newest(&self.counters)?;
        frame.rgb = self.targets.current().expect("prepared").read_pixels()?;
        Ok(frame)
    }
}

/// The lattice values `value` gives every lattice point of every eye and layer, uploaded
/// in place of the frame's traced ones.
fn given_lattice(
    ctx: &Arc<GpuContext>,
    targets: &FrameTargets,
    eyes: &[EyeLayers],
    value: &dyn Fn(LatticePoint) -> [f32; 4],
) -> Result<Buffer, RenderError> {
    let mut values = vec![0.0f32; eyes.len() * targets.lattice_len() * 4];
    for (e, eye) in eyes.iter().enumerate() {
        for (k, (layer, lattice)) in eye.layers.iter().zip(&targets.buffer.layers).enumerate() {
            for j in lattice.row_min..=lattice.row_max {
                for i in lattice.col_min..=lattice.col_max {
                    let point = LatticePoint {
                        eye: e,
                        layer: k,
                        x: layer.anchor_x + i * layer.spacing,
                        y: layer.anchor_y + j * layer.spacing,
                    };
                    let at = e * targets.lattice_len() + lattice.index(i, j) as usize;
                    values[at * 4..at * 4 + 4].copy_from_slice(&value(point));
                }
            }
        }
    }
    Ok(Buffer::with_data(
        ctx,
        "lattice values",
        bytemuck::cast_slice(&values),
    )?)
}
