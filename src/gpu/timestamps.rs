//! GPU time per pass from timestamp queries: two queries around every pass in a frame, and
//! after each pass its crash marker (see `GpuContext::submit_and_wait`).

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use ash::vk;
use std::sync::Arc;

/// One timed pass: its name, when it began after the frame's first pass began, and how long
/// it took, in GPU milliseconds.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTime {
    pub name: String,
    pub start_ms: f64,
    pub ms: f64,
}

pub struct TimestampPool {
    ctx: Arc<GpuContext>,
    pool: vk::QueryPool,
    capacity: u32,
    names: Vec<String>,
}

impl TimestampPool {
    /// Room for `passes` timed passes per frame.
    pub fn new(ctx: &Arc<GpuContext>, passes: u32) -> Result<Self, GpuError> {
        let capacity = passes * 2;
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(capacity);
        // SAFETY: valid device and create info.
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
        // SAFETY: hostQueryReset was enabled at device creation; the pool is unused.
        unsafe { ctx.device.reset_query_pool(pool, 0, capacity) };
        Ok(Self {
            ctx: ctx.clone(),
            pool,
            capacity,
            names: Vec::new(),
        })
    }

    /// Records the reset of the pool at the start of a frame's command buffer.
    pub(crate) fn cmd_reset(&mut self, cmd: vk::CommandBuffer) {
        self.names.clear();
        // SAFETY: cmd is recording, outside any render pass.
        unsafe {
            self.ctx
                .device
                .cmd_reset_query_pool(cmd, self.pool, 0, self.capacity)
        };
    }

    /// Records `work` between two timestamps under `name`, then the pass's crash marker (see
    /// [`GpuContext::submit_and_wait`]), so a device loss names the pass as the timings do.
    /// Records nothing once an injected device loss (`FOVEA_INJECT_DEVICE_LOST`) has ended the
    /// command buffer.
    pub(crate) fn cmd_timed(&mut self, cmd: vk::CommandBuffer, name: &str, work: impl FnOnce()) {
        if !self.ctx.begin_pass(name) {
            return;
        }
        let index = self.names.len() as u32 * 2;
        if index + 1 >= self.capacity {
            work();
            self.ctx.cmd_pass_done(cmd);
            return;
        }
        self.names.push(name.to_string());
        let d = &self.ctx.device;
        // SAFETY: cmd is recording; the queries were reset in this command buffer.
        unsafe {
            d.cmd_write_timestamp(cmd, vk::PipelineStageFlags::TOP_OF_PIPE, self.pool, index)
        };
        work();
        // SAFETY: as above.
        unsafe {
            d.cmd_write_timestamp(
                cmd,
                vk::PipelineStageFlags::BOTTOM_OF_PIPE,
                self.pool,
                index + 1,
            )
        };
        self.ctx.cmd_pass_done(cmd);
    }

    /// Every timed pass of the last submitted frame (which must have completed).
    pub fn read(&self) -> Result<Vec<PassTime>, GpuError> {
        let count = self.names.len() * 2;
        if count == 0 {
            return Ok(Vec::new());
        }
        let mut ticks = vec![0u64; count];
        // SAFETY: the frame completed; WAIT makes the call block until results are available.
        unsafe {
            self.ctx.device.get_query_pool_results(
                self.pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .vk("vkGetQueryPoolResults")?;
        let period = self.ctx.info.timestamp_period_ns;
        let ms = |from: u64, to: u64| to.wrapping_sub(from) as f64 * period * 1e-6;
        Ok(self
            .names
            .iter()
            .enumerate()
            .map(|(i, n)| PassTime {
                name: n.clone(),
                start_ms: ms(ticks[0], ticks[2 * i]),
                ms: ms(ticks[2 * i], ticks[2 * i + 1]),
            })
            .collect())
    }
}

impl Drop for TimestampPool {
    fn drop(&mut self) {
        // SAFETY: no pending work uses the pool.
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
    }
}
