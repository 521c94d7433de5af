//! `--trace-split N --samples-per-lane M --trace-threads T`: how many threads trace each
//! lattice point (render::TraceLanes), for `fovea render` and `fovea gpu-report`.

use anyhow::Result;
use clap::Args;
use fovea::gpu::GpuContext;
use fovea::render::{preferred_trace_lanes, TraceLanes};

#[derive(Args, Clone, Copy, Default)]
pub struct TraceLaneArgs {
    /// At most N trace threads per lattice point, a power of two up to 64 (default: the
    /// device's, 1 on a CPU, 16 on a GPU). The image is the same up to rounding; bit for bit
    /// where each layer's spp is at most its lanes.
    #[arg(long, value_name = "N")]
    pub trace_split: Option<u32>,
    /// Each trace thread keeps at least M of its point's samples (default: the device's, 4
    /// on a GPU): a layer gets the largest power of two <= spp / M threads per point.
    #[arg(long, value_name = "M")]
    pub samples_per_lane: Option<u32>,
    /// While an eye's trace has fewer than T threads, the layer whose threads keep the most
    /// samples gets twice the lanes, up to N and its spp (default: the device's, 0 on a CPU,
    /// 524288 on a GPU; 0: never).
    #[arg(long, value_name = "T")]
    pub trace_threads: Option<u64>,
}

impl TraceLaneArgs {
    /// The lanes asked for, each flag not given from the device's; None when neither is.
    pub fn lanes(&self, ctx: &GpuContext) -> Result<Option<TraceLanes>> {
        if self.trace_split.is_none()
            && self.samples_per_lane.is_none()
            && self.trace_threads.is_none()
        {
            return Ok(None);
        }
        let device = preferred_trace_lanes(ctx);
        let lanes = TraceLanes::new(
            self.trace_split.unwrap_or(device.max_lanes),
            self.samples_per_lane.unwrap_or(device.samples_per_lane),
        )
        .map_err(anyhow::Error::msg)?
        .with_fill_threads(self.trace_threads.unwrap_or(device.fill_threads));
        Ok(Some(lanes))
    }
}
