//! The counters the shaders keep for every frame (shared.h's STAT_* words): per eye what the
//! trace counted, per eye and layer the lattice points the plan traced, and the trace's
//! indirect dispatch sizes, and with a profiling trace its traversal work. They live in device memory, where atomics and the indirect
//! dispatch are fast on a GPU, are zeroed by the frame's first command and copied by its last
//! into the frame slot's host-visible buffer (passes.rs) (frames in flight each have their own).

use super::frame::{EyeCounters, TraversalCounts};
use super::graph::FrameGraph;
use super::slots::MAX_FRAMES_IN_FLIGHT;
use super::RenderError;
use crate::gpu::{vk, Buffer, GpuContext, PlannedAllocation};
use crate::shader_layout::*;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

const BYTES: u64 = STAT_WORDS as u64 * 4;

pub struct FrameCounters {
    /// The shaders' counters (BINDING_STATS), also the trace's indirect arguments.
    pub device: Buffer,
    /// One read-back per frame slot.
    host: Vec<Buffer>,
}

/// What one frame counted.
pub struct CountedFrame {
    /// Per eye (STAT_EYES of them; callers keep the frame's).
    pub eyes: Vec<EyeCounters>,
    /// Per eye, lattice points traced per layer (MAX_LAYERS of them).
    pub layer_points: Vec<Vec<u64>>,
    /// Per eye, lattice points the fill pass filled.
    pub filled_points: Vec<u64>,
    /// Per eye, the workgroups the trace ran (GpuLayer::lanes threads per traced point).
    pub trace_workgroups: Vec<u64>,
    /// Per eye, the traversal's work (zero unless the trace pipeline profiles).
    pub traversal: Vec<TraversalCounts>,
}

impl FrameCounters {
    pub fn new(ctx: &Arc<GpuContext>) -> Result<Self, RenderError> {
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::INDIRECT_BUFFER
            | vk::BufferUsageFlags::TRANSFER_SRC
            | vk::BufferUsageFlags::TRANSFER_DST;
        Ok(Self {
            device: Buffer::new(ctx, "counters", BYTES, usage, MemoryLocation::GpuOnly)?,
            host: (0..MAX_FRAMES_IN_FLIGHT)
                .map(|_| {
                    Buffer::new(
                        ctx,
                        "counters read-back",
                        BYTES,
                        vk::BufferUsageFlags::TRANSFER_DST,
                        MemoryLocation::GpuToCpu,
                    )
                })
                .collect::<Result<_, _>>()?,
        })
    }

    /// The allocations, for a scene's memory check.
    pub fn allocations() -> Vec<PlannedAllocation> {
        let mut plan = vec![PlannedAllocation::storage("counters", BYTES)];
        plan.extend(
            (0..MAX_FRAMES_IN_FLIGHT)
                .map(|_| PlannedAllocation::host("counters read-back", BYTES, true)),
        );
        plan
    }

    /// A pass zeroing every counter, before the passes that add to them.
    pub fn reset(&self, g: &mut FrameGraph) {
        let stats = &self.device;
        g.pass()
            .fills(stats)
            .record(|r| stats.cmd_zero(r.cmd, BYTES));
    }

    /// A pass copying the counters into slot `slot`'s read-back, which the host reads after
    /// the fence.
    pub fn collect(&self, g: &mut FrameGraph, slot: usize) {
        let (stats, host) = (&self.device, &self.host[slot]);
        g.pass()
            .copies_from(stats)
            .copies_into(host)
            .record(|r| stats.cmd_copy_to(r.cmd, host, BYTES));
        g.host_reads(host);
    }

    /// The counters of slot `slot`'s frame (its fence has signalled).
    pub fn read(&self, slot: usize) -> Result<CountedFrame, RenderError> {
        let bytes = self.host[slot].read()?;
        let words: &[u32] = bytemuck::cast_slice(&bytes[..BYTES as usize]);
        let eyes = words[..(STAT_COUNT * STAT_EYES) as usize]
            .chunks_exact(STAT_COUNT as usize)
            .map(|c| EyeCounters {
                nonfinite_samples: c[STAT_NONFINITE as usize] as u64,
                stack_overflows: c[STAT_STACK_OVERFLOW as usize] as u64,
                paths: c[STAT_PATHS as usize] as u64,
                rays: c[STAT_RAYS as usize] as u64,
            })
            .collect();
        let layer_points = words[STAT_LAYER_POINTS as usize..STAT_DISPATCH as usize]
            .chunks_exact(MAX_LAYERS as usize)
            .map(|c| c.iter().map(|&n| n as u64).collect())
            .collect();
        let filled_points = words[STAT_FILL_DISPATCH as usize..STAT_PROFILE as usize]
            .chunks_exact(4)
            .map(|c| c[STAT_WORK_COUNT as usize] as u64)
            .collect();
        let trace_workgroups = words[STAT_DISPATCH as usize..STAT_FILL_DISPATCH as usize]
            .chunks_exact(4)
            .map(|c| c[..3].iter().map(|&n| n as u64).product())
            .collect();
        let traversal = words[STAT_PROFILE as usize..STAT_WORDS as usize]
            .chunks_exact(PROFILE_COUNTERS as usize * 2)
            .map(|eye| {
                let wide: Vec<u64> = eye
                    .chunks_exact(2)
                    .map(|w| w[0] as u64 | (w[1] as u64) << 32)
                    .collect();
                TraversalCounts::from_counters(&wide)
            })
            .collect();
        Ok(CountedFrame {
            eyes,
            layer_points,
            filled_points,
            trace_workgroups,
            traversal,
        })
    }
}
