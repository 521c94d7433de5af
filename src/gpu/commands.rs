//! Recording and submitting command buffers: [`Commands`], a recorded command buffer and its
//! fence, and the spares that finished submissions leave for the next ones.

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::owned::Pending;
use super::sync::Scope;
use ash::vk;
use std::ops::Deref;
use std::sync::Arc;

impl GpuContext {
    /// Records commands with `record`, submits them and waits for completion. `submission`
    /// names the work; passes recorded through the timestamp pool get crash markers, so a
    /// device loss says which pass completed last and which was running.
    pub fn submit_and_wait(
        &self,
        submission: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<(), GpuError> {
        self.record(submission, record)?.submit_and_wait()
    }

    /// Records commands with `record` into a command buffer that is submitted later
    /// ([`Commands::submit`]): what the host writes in between (into host-visible buffers
    /// the commands read) is what the GPU sees — a frame's gaze is latched that way.
    pub fn record(
        &self,
        submission: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<Commands<&GpuContext>, GpuError> {
        Commands::record(self, submission, record)
    }

    /// Like [`Self::record`], for commands that outlive the borrow: a frame in flight, kept
    /// by its renderer until its fence has signalled.
    pub fn record_owned(
        self: &Arc<Self>,
        submission: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<Commands<Arc<GpuContext>>, GpuError> {
        Commands::record(self.clone(), submission, record)
    }

    /// A spare command buffer and fence (unsignalled), or new ones.
    fn command_buffer_and_fence(&self) -> Result<(vk::CommandBuffer, vk::Fence), GpuError> {
        if let Some(pair) = self.spare.lock().unwrap_or_else(|e| e.into_inner()).pop() {
            return Ok(pair);
        }
        // SAFETY: fence creation with default info.
        let fence = unsafe {
            self.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .vk("vkCreateFence")?;
        let fence = Pending::new(&self.device, fence);
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool.handle)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool belongs to this device and is only used from this thread.
        let cmd = unsafe { self.device.allocate_command_buffers(&alloc) }
            .vk("vkAllocateCommandBuffers")?[0];
        Ok((cmd, fence.keep()))
    }

    /// Takes back a command buffer and fence that no submission uses any more: kept as
    /// spares (reset) up to MAX_SPARES, else destroyed.
    fn return_spare(&self, cmd: vk::CommandBuffer, fence: vk::Fence) {
        // SAFETY: the caller guarantees that neither is in use (never submitted, or its
        // submission completed or failed). Resetting the buffer puts it back in the initial
        // state from any state but pending (a recording cut short included).
        let reset = unsafe {
            self.device.reset_fences(&[fence]).and_then(|()| {
                self.device
                    .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
            })
        };
        let mut spare = self.spare.lock().unwrap_or_else(|e| e.into_inner());
        if reset.is_ok() && spare.len() < MAX_SPARES {
            spare.push((cmd, fence));
            return;
        }
        drop(spare);
        // SAFETY: as above.
        unsafe {
            self.device.destroy_fence(fence, None);
            self.device
                .free_command_buffers(self.command_pool.handle, &[cmd]);
        }
    }

    /// Destroys the spare fences (the context's drop, once the device is idle; the spare
    /// command buffers go with their pool).
    pub(super) fn destroy_spares(&mut self) {
        let spare = self.spare.get_mut().unwrap_or_else(|e| e.into_inner());
        for (_, fence) in spare.drain(..) {
            // SAFETY: the device is idle, and a spare is used by no submission.
            unsafe { self.device.destroy_fence(fence, None) };
        }
    }
}

/// Spare command buffers and fences kept at most (more are freed): frames in flight, and
/// the odd upload or read-back between them.
const MAX_SPARES: usize = 6;

/// Where a [`Commands`]' work stands.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Progress {
    Recorded,
    Submitted,
    /// Completed, or failed (a device loss): nothing of it runs any more.
    Done,
}

/// A recorded command buffer and its fence (see [`GpuContext::record`]), through any handle
/// to the context (a borrow, or an `Arc` for work kept in flight). Submitted at most once;
/// back to the context's spares when dropped — after its work completed, which a drop of
/// submitted, unfinished work waits for.
pub struct Commands<C: Deref<Target = GpuContext>> {
    ctx: C,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    submission: String,
    progress: Progress,
    /// This command buffer's crash-marker set (see crash_markers.rs), held until it is
    /// dropped.
    markers: usize,
}

impl<C: Deref<Target = GpuContext>> Commands<C> {
    fn record(
        ctx: C,
        submission: &str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<Self, GpuError> {
        let markers = ctx.markers.begin()?;
        let (cmd, fence) = match ctx.command_buffer_and_fence() {
            Ok(pair) => pair,
            Err(e) => {
                ctx.markers.end();
                ctx.markers.release(markers);
                return Err(e);
            }
        };
        // Back to the spares (and the markers freed) on every path from here on, recorded
        // or not.
        let commands = Commands {
            ctx,
            cmd,
            fence,
            submission: submission.to_string(),
            progress: Progress::Recorded,
            markers,
        };
        let ctx = &*commands.ctx;
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: cmd is a primary command buffer of this device, not in use (fresh, or a
        // spare whose submission completed); its pool lets vkBeginCommandBuffer reset it.
        if let Err(e) = unsafe { ctx.device.begin_command_buffer(cmd, &begin) } {
            ctx.markers.end();
            return Err(e).vk("vkBeginCommandBuffer");
        }
        record(cmd);
        if ctx.markers.end() {
            // The crash markers (fills, or AMD buffer-marker writes at the end of the pipe)
            // before the host reads them after a device loss.
            ctx.cmd_barrier(
                cmd,
                Scope::ALL_WORK.and(Scope::FILL_WRITE),
                Scope::HOST_READ,
            );
        }
        // SAFETY: recording was begun above.
        unsafe { ctx.device.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")?;
        Ok(commands)
    }

    /// Submits the commands to the queue and returns at once; their fence signals when
    /// they complete ([`Self::is_done`], [`Self::wait`]).
    pub fn submit(&mut self) -> Result<(), GpuError> {
        assert!(
            self.progress == Progress::Recorded,
            "recorded commands are submitted once"
        );
        let cmds = [self.cmd];
        let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
        // SAFETY: the queue is used only from this thread; cmd (ended, not pending) and the
        // unsignalled fence are valid.
        let submitted = unsafe {
            self.ctx
                .device
                .queue_submit(self.ctx.queue, &submit, self.fence)
        };
        match submitted {
            Ok(()) => {
                self.progress = Progress::Submitted;
                Ok(())
            }
            Err(e) => {
                self.progress = Progress::Done;
                Err(self.failed(e, "vkQueueSubmit"))
            }
        }
    }

    /// Whether the submitted commands have completed (their fence has signalled); never
    /// blocks.
    pub fn is_done(&self) -> Result<bool, GpuError> {
        if self.progress != Progress::Submitted {
            return Ok(self.progress == Progress::Done);
        }
        // SAFETY: the fence belongs to this device.
        match unsafe { self.ctx.device.get_fence_status(self.fence) } {
            Ok(done) => Ok(done),
            Err(e) => Err(self.failed(e, "vkGetFenceStatus")),
        }
    }

    /// Waits for the submitted commands to complete.
    pub fn wait(&mut self) -> Result<(), GpuError> {
        if self.progress != Progress::Submitted {
            return Ok(());
        }
        // SAFETY: the fence belongs to this device and was submitted with the commands.
        let waited = unsafe {
            self.ctx
                .device
                .wait_for_fences(&[self.fence], true, u64::MAX)
        };
        self.progress = Progress::Done;
        let injected = self.ctx.markers.cut(self.markers);
        match (waited, injected) {
            // The command buffer ended after the injected pass: fail as a driver would.
            (Ok(()), true) => Err(self.failed(vk::Result::ERROR_DEVICE_LOST, "vkWaitForFences")),
            (Ok(()), false) => Ok(()),
            (Err(e), _) => Err(self.failed(e, "vkWaitForFences")),
        }
    }

    /// Submits the commands and waits for them to complete.
    pub fn submit_and_wait(mut self) -> Result<(), GpuError> {
        self.submit()?;
        self.wait()
    }

    /// The error of a failed call: a device loss names the pass it happened in.
    fn failed(&self, e: vk::Result, call: &'static str) -> GpuError {
        if e != vk::Result::ERROR_DEVICE_LOST {
            return GpuError::Vulkan { call, result: e };
        }
        self.ctx.markers.device_lost(&self.submission, self.markers)
    }
}

impl<C: Deref<Target = GpuContext>> Drop for Commands<C> {
    fn drop(&mut self) {
        if self.progress == Progress::Submitted {
            // SAFETY: the fence belongs to this device; the command buffer may not be freed
            // or reused while pending. An error (a lost device) means nothing runs any more.
            let _ = unsafe {
                self.ctx
                    .device
                    .wait_for_fences(&[self.fence], true, u64::MAX)
            };
        }
        self.ctx.return_spare(self.cmd, self.fence);
        self.ctx.markers.release(self.markers);
    }
}
