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
    /// Passes recorded since the last reset that found the pool full: an error when the
    /// frame is read ([`Self::read`]), never a silently shorter frame.
    untimed: Vec<String>,
}

impl TimestampPool {
    /// Room for `passes` timed passes per frame.
    pub fn new(ctx: &Arc<GpuContext>, passes: u32) -> Result<Self, GpuError> {
        let capacity = passes * 2;
        Ok(Self {
            ctx: ctx.clone(),
            pool: create_pool(ctx, capacity)?,
            capacity,
            names: Vec::new(),
            untimed: Vec::new(),
        })
    }

    /// Timed passes a frame can have.
    pub fn passes(&self) -> u32 {
        self.capacity / 2
    }

    /// Makes room for `passes` timed passes: a larger pool when this one is smaller. The
    /// caller guarantees that no submitted work uses the pool (its frame slot is free).
    pub fn ensure_passes(&mut self, passes: u32) -> Result<(), GpuError> {
        if passes <= self.passes() {
            return Ok(());
        }
        let pool = create_pool(&self.ctx, passes * 2)?;
        // SAFETY: no pending work uses the old pool (the caller's guarantee).
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
        self.pool = pool;
        self.capacity = passes * 2;
        self.names.clear();
        Ok(())
    }

    /// Records the reset of the pool at the start of a frame's command buffer.
    pub(crate) fn cmd_reset(&mut self, cmd: vk::CommandBuffer) {
        self.names.clear();
        self.untimed.clear();
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
    /// command buffer. A pass past the pool's room is recorded untimed and makes [`Self::read`]
    /// fail: size the pool from the frame's pass list ([`Self::ensure_passes`]).
    pub(crate) fn cmd_timed(&mut self, cmd: vk::CommandBuffer, name: &str, work: impl FnOnce()) {
        if !self.ctx.begin_pass(name) {
            return;
        }
        let index = self.names.len() as u32 * 2;
        if index + 1 >= self.capacity {
            self.untimed.push(name.to_string());
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

    /// Every timed pass of the last submitted frame (which must have completed); an error
    /// when a pass of it could not be timed.
    pub fn read(&self) -> Result<Vec<PassTime>, GpuError> {
        if !self.untimed.is_empty() {
            return Err(GpuError::UntimedPasses {
                room: self.passes(),
                untimed: self.untimed.clone(),
            });
        }
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

/// A timestamp pool of `capacity` queries, reset.
fn create_pool(ctx: &GpuContext, capacity: u32) -> Result<vk::QueryPool, GpuError> {
    let info = vk::QueryPoolCreateInfo::default()
        .query_type(vk::QueryType::TIMESTAMP)
        .query_count(capacity);
    // SAFETY: valid device and create info.
    let pool = unsafe { ctx.device.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
    // SAFETY: hostQueryReset was enabled at device creation; the pool is unused.
    unsafe { ctx.device.reset_query_pool(pool, 0, capacity) };
    Ok(pool)
}

impl Drop for TimestampPool {
    fn drop(&mut self) {
        // SAFETY: no pending work uses the pool.
        unsafe { self.ctx.device.destroy_query_pool(self.pool, None) };
    }
}
