//! A rendered frame on the host: linear RGB radiance plus what it cost and what went wrong.

use super::settings::Traversal;
use std::time::Instant;

use crate::shader_layout::{
    PROFILE_BLAS_GROUP_STEPS, PROFILE_BLAS_LANE_STEPS, PROFILE_BLAS_NODES, PROFILE_PRIMITIVES,
    PROFILE_TLAS_GROUP_STEPS, PROFILE_TLAS_LANE_STEPS, PROFILE_TLAS_NODES, PROFILE_TRIANGLES,
};

/// What trace.comp counted for one eye of a frame (shared.h's STAT_*).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EyeCounters {
    pub nonfinite_samples: u64,
    pub stack_overflows: u64,
    pub paths: u64,
    pub rays: u64,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Samples that came out NaN or infinite and were dropped.
    pub nonfinite_samples: u64,
    /// BVH traversals whose stack overflowed.
    pub stack_overflows: u64,
    /// Camera paths traced (pixels × spp).
    pub paths: u64,
    /// All rays traced: camera, bounce and shadow rays.
    pub rays: u64,
    /// The same counters for each eye, left first.
    pub eyes: Vec<EyeCounters>,
    /// GPU milliseconds per pass, from timestamp queries.
    pub pass_ms: Vec<(String, f64)>,
    /// When each pass of `pass_ms` began, in GPU milliseconds after the first one began.
    pub pass_start_ms: Vec<f64>,
    /// Camera paths planned per foveation layer (innermost first), summed over the eyes.
    pub layer_samples: Vec<u64>,
    /// Lattice points the fill pass filled from their traced neighbours (fractional layers:
    /// points skipped this frame but needed), all eyes.
    pub filled_points: u64,
    /// Workgroups the trace pass ran, all eyes (Renderer::set_trace_lanes threads per traced
    /// point, TRACE_WORKGROUP_SIZE per workgroup).
    pub trace_workgroups: u64,
    /// CPU milliseconds spent planning the frame (gaze → every eye's layer parameters; which
    /// lattice points are traced is decided on the GPU).
    pub plan_ms: f64,
    /// CPU milliseconds spent recording the frame's command buffer.
    pub record_ms: f64,
    /// The traversal's work, summed over the eyes, when the renderer profiles
    /// (`Renderer::set_traversal_profile`).
    pub traversal: Option<TraversalCounts>,
    /// The traversal that traced the frame.
    pub traced_with: Traversal,
    /// Earlier frames whose GPU work had not completed when this frame was submitted: 0
    /// when frames are rendered one at a time, up to the frames in flight less one.
    pub busy_at_submit: u32,
    /// When the frame was submitted, and when the renderer saw its fence signalled (which it
    /// looks at when asked for finished frames, so this is an upper bound).
    pub submitted_at: Option<Instant>,
    pub completed_at: Option<Instant>,
}

/// What the trace's BVH traversals did in one frame (shared.h's PROFILE_* counters).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalCounts {
    pub tlas_nodes: u64,
    pub blas_nodes: u64,
    pub triangles: u64,
    /// Ray-box and ray-sphere tests.
    pub primitives: u64,
    /// Iterations of the traversal loop at the TLAS and at the BLAS level (counted at the level
    /// of the node a step may visit), summed over invocations (lane) and counted once
    /// per subgroup step (group).
    pub tlas_lane_steps: u64,
    pub tlas_group_steps: u64,
    pub blas_lane_steps: u64,
    pub blas_group_steps: u64,
}

impl TraversalCounts {
    /// From PROFILE_COUNTERS values, indexed by shared.h's PROFILE_*.
    pub fn from_counters(c: &[u64]) -> Self {
        let at = |i: u32| c[i as usize];
        Self {
            tlas_nodes: at(PROFILE_TLAS_NODES),
            blas_nodes: at(PROFILE_BLAS_NODES),
            triangles: at(PROFILE_TRIANGLES),
            primitives: at(PROFILE_PRIMITIVES),
            tlas_lane_steps: at(PROFILE_TLAS_LANE_STEPS),
            tlas_group_steps: at(PROFILE_TLAS_GROUP_STEPS),
            blas_lane_steps: at(PROFILE_BLAS_LANE_STEPS),
            blas_group_steps: at(PROFILE_BLAS_GROUP_STEPS),
        }
    }
}

impl std::ops::Add for TraversalCounts {
    type Output = Self;

    fn add(self, o: Self) -> Self {
        Self {
            tlas_nodes: self.tlas_nodes + o.tlas_nodes,
            blas_nodes: self.blas_nodes + o.blas_nodes,
            triangles: self.triangles + o.triangles,
            primitives: self.primitives + o.primitives,
            tlas_lane_steps: self.tlas_lane_steps + o.tlas_lane_steps,
            tlas_group_steps: self.tlas_group_steps + o.tlas_group_steps,
            blas_lane_steps: self.blas_lane_steps + o.blas_lane_steps,
            blas_group_steps: self.blas_group_steps + o.blas_group_steps,
        }
    }
}

impl TraversalCounts {
    /// The fraction of a subgroup's lanes busy in a loop's average step (SIMD occupancy):
    /// lane steps / (group steps × subgroup size); None when the loop never ran.
    pub fn occupancy(lane_steps: u64, group_steps: u64, subgroup_size: u32) -> Option<f64> {
        (group_steps > 0).then(|| lane_steps as f64 / (group_steps as f64 * subgroup_size as f64))
    }
}

impl FrameStats {
    pub fn gpu_ms(&self) -> f64 {
        self.pass_ms.iter().map(|(_, ms)| ms).sum()
    }
    /// Millions of camera paths (samples) per second of GPU time.
    pub fn msamples_per_s(&self) -> f64 {
        let ms = self.gpu_ms();
        if ms > 0.0 {
            self.paths as f64 / (ms * 1e3)
        } else {
            0.0
        }
    }
}

#[derive(Clone, Debug)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Linear RGB radiance, row-major from the top-left, 3 floats per pixel.
    pub rgb: Vec<f32>,
    /// Per eye: the gaze pixel used and whether the requested gaze had to be fixed.
    pub gazes: Vec<([f64; 2], crate::foveation::gaze::GazeFix)>,
    pub stats: FrameStats,
}

impl Frame {
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }
    /// Mean of each channel over the whole image.
    pub fn mean(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for p in self.rgb.chunks_exact(3) {
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
        }
        let n = (self.rgb.len() / 3).max(1) as f64;
        sum.map(|s| s / n)
    }
}
