//! The CPU's share of planning a frame: per eye, the push constants its commands are
//! recorded with (camera, image: no gaze), and the O(layers) numbers the GPU plans, traces
//! and resolves from (one `GpuLayer` per layer: gaze, anchor, limits as cosines, the lattice
//! box), which are written after recording, right before the submission, so that the gaze is
//! the latest one. Which lattice points are traced is decided per point on the GPU
//! (glsl/plan.comp); nothing here visits a lattice point.

use super::request::FrameRequest;
use super::trace_lanes::lane_unit;
use crate::foveation::fraction::phase;
use crate::foveation::gaze::GazeFix;
use crate::foveation::lattice_shift::lattice_shift;
use crate::foveation::plan::{cos_limit, gaze_anchor, layer_box, Regions};
use crate::foveation::Gaze;
use crate::foveation::{ImageGeometry, Layer, RayBuffer};
use crate::scene::Camera;
use crate::shader_layout::{
    EyePush, GpuLayer, PushCamera, PushEye, ALBEDO_DIVIDED, ALBEDO_ON, NO_LIMIT, PLAN_RUN,
};

/// One eye's layers for a frame: what the gaze decides, written into the GPU's layer buffer
/// right before the frame is submitted (the recorded commands do not depend on it).
pub struct EyeLayers {
    /// The eye's layers, innermost first (LAYERS[eye * layer_count ..]).
    pub layers: Vec<GpuLayer>,
    /// The gaze pixel used and whether the requested gaze had to be fixed.
    pub gaze: ([f64; 2], GazeFix),
}

impl EyeLayers {
    /// Threads of the eye's plan pass (every layer holds the count, GpuLayer::plan_runs):
    /// every row of every layer's lattice box, in runs of PLAN_RUN points.
    pub fn plan_runs(&self) -> u32 {
        self.layers.first().map_or(0, |l| l.plan_runs)
    }
}

/// Where the eyes' parts of the frame's lattice and work lists lie: eye after eye, this many
/// entries and slots apart (`FrameTargets::lattice_len`, `work_stride`).
#[derive(Clone, Copy, Debug)]
pub struct EyeStrides {
    pub lattice: u32,
    pub work: u32,
}

/// EyePush::albedo of a frame, before its history adds ALBEDO_CARRIED: a frame with a
/// history keeps albedos, so that the history clamps them within a surface (temporal.comp);
/// a frame with a denoising layer keeps them whether it has a history or not, and only then
/// is the frame divided by them. Without either nothing reads them.
pub fn frame_albedo(denoises: bool, history_on: bool) -> u32 {
    match (denoises, history_on) {
        (true, _) => ALBEDO_ON | ALBEDO_DIVIDED,
        (false, true) => ALBEDO_ON,
        (false, false) => 0,
    }
}

/// The push constants of eye `e` of `request` (its camera, the image, the frame's settings)
/// in a frame with a history or not (`history_on`): everything its recorded commands hold.
pub fn eye_push(
    request: &FrameRequest,
    e: usize,
    buffer: &RayBuffer,
    strides: EyeStrides,
    history_on: bool,
) -> EyePush {
    let s = &request.settings;
    EyePush {
        cam: push_camera(&request.eyes[e].camera),
        eye: PushEye {
            width: s.width,
            height: s.height,
            index: e as u32,
            seed: s.seed,
            layer_count: buffer.layers.len() as u32,
            work_stride: strides.work,
            debug: request.debug.id(),
            ..Default::default()
        },
        albedo: frame_albedo(request.foveation.denoise_iterations() > 0, history_on),
        lattice_base: e as u32 * strides.lattice,
        ..Default::default()
    }
}

/// Where eye `e`'s layers are planned: its image and the frame's ray buffer, lattice shift
/// and trace lanes (FrameTargets::layer_lanes).
pub struct EyePlanInput<'a> {
    pub buffer: &'a RayBuffer,
    /// Entries from one eye's lattice points to the next (`FrameTargets::lattice_len`).
    pub lattice_stride: u32,
    pub image: &'a ImageGeometry,
    /// Shifts the sparse layers' lattices (`lattice_shift`; 0: unshifted) and turns the
    /// fractional layers' patterns (`fraction::phase`).
    pub history_frame: u32,
    /// Trace threads per point of each layer.
    pub layer_lanes: &'a [u32],
}

/// Plans eye `e` of `request` looking at `gaze`.
pub fn eye_layers(request: &FrameRequest, e: usize, gaze: Gaze, input: &EyePlanInput) -> EyeLayers {
    let (buffer, image, history_frame) = (input.buffer, input.image, input.history_frame);
    let (gaze_px, fix) = gaze.resolve(image);
    match fix {
        GazeFix::None => {}
        GazeFix::NotFinite => {
            tracing::warn!("eye {e}: gaze {gaze:?} is not finite; foveating around the view axis")
        }
        GazeFix::Clamped => {
            tracing::info!("eye {e}: gaze {gaze:?} is off the image; clamped to its border")
        }
    }
    let regions = Regions::new(buffer, image, gaze_px);
    let stride = input.lattice_stride;
    let layer_count = buffer.layers.len() as u32;
    let blend = (request.foveation.blend_deg as f64).to_radians();
    let g = regions.gaze_dir();
    let mut prefix = 0u32;
    let mut layers: Vec<GpuLayer> = buffer
        .layers
        .iter()
        .enumerate()
        .map(|(k, l)| {
            let [sx, sy] = lattice_shift(history_frame, l.spacing);
            let anchor = match l.gaze_anchored {
                true => gaze_anchor(image, gaze_px),
                false => [0, 0],
            };
            let anchor = [anchor[0] + sx, anchor[1] + sy];
            let (i0, i1, j0, j1) = layer_box(l, image, anchor);
            let (box_cols, box_rows) = ((i1 - i0 + 1).max(0) as u32, (j1 - j0 + 1).max(0) as u32);
            let box_prefix = prefix;
            prefix += box_cols.div_ceil(PLAN_RUN) * box_rows;
            let [occlusion, outer, inner] = regions.plan_cos(k);
            GpuLayer {
                gaze: [g[0], g[1], g[2], blend as f32],
                plan_cos: [occlusion, outer, inner, 0.0],
                resolve_cos: [
                    cos_limit(l.outer),
                    cos_limit(l.outer - blend),
                    cos_limit(buffer.occlusion),
                    0.0,
                ],
                pixel_tan: regions.tan_map(),
                anchor_x: anchor[0],
                anchor_y: anchor[1],
                spacing: l.spacing as i32,
                spp: l.spp,
                box_i0: i0,
                box_j0: j0,
                box_cols,
                box_rows,
                col_min: l.col_min,
                row_min: l.row_min,
                cols: l.cols() as u32,
                first: e as u32 * stride + l.first,
                box_prefix,
                // shared.h's VISIBILITY planes: per eye the shown pixels, then one per layer.
                mask_plane: e as u32 * (layer_count + 1) + 1 + k as u32,
                outer: l.outer.clamp(-NO_LIMIT as f64, NO_LIMIT as f64) as f32,
                plan_runs: 0,
                fraction: l.fraction,
                fraction_phase: phase(history_frame, l.spacing, l.fraction),
                lanes: input.layer_lanes[k],
                lane_unit: lane_unit(input.layer_lanes),
                ..history_filters(&request.foveation.layers[k])
            }
        })
        .collect();
    for layer in &mut layers {
        layer.plan_runs = prefix;
    }
    EyeLayers {
        layers,
        gaze: (gaze_px, fix),
    }
}

/// A layer's settings for the passes that follow the history's surfaces (denoise.comp and
/// lattice_filter.comp), the rest of its GpuLayer zero.
fn history_filters(layer: &Layer) -> GpuLayer {
    GpuLayer {
        denoise: layer.denoise,
        denoise_mar: layer.denoise_mar,
        denoise_sigma: layer.denoise_sigma,
        filter_mar: layer.filter_mar,
        filter_px: layer.filter_px,
        ..Default::default()
    }
}

/// The camera as every pass of a frame sees it.
pub fn push_camera(camera: &Camera) -> PushCamera {
    let (r, u, f) = camera.basis();
    let v = |v: glam::Vec3| [v.x, v.y, v.z, 0.0];
    PushCamera {
        position: v(camera.position),
        right: v(r),
        up: v(u),
        forward: v(f),
        // Image row 0 is the top edge, so the shader goes from the "up" tangent to "down".
        tan: [
            camera.angle_left.tan(),
            camera.angle_right.tan(),
            camera.angle_up.tan(),
            camera.angle_down.tan(),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn albedos_are_kept_where_something_reads_them_and_divided_only_where_a_layer_denoises() {
        assert_eq!(frame_albedo(false, false), 0);
        assert_eq!(frame_albedo(false, true), ALBEDO_ON);
        assert_eq!(frame_albedo(true, false), ALBEDO_ON | ALBEDO_DIVIDED);
        assert_eq!(frame_albedo(true, true), ALBEDO_ON | ALBEDO_DIVIDED);
    }
}
