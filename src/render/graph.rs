//! The frame as a list of passes that declare what they touch, the way kajiya's render graph
//! passes do: `graph.pass().reads(..).writes(..).record(..)`. From the declarations the graph
//! derives, for each pass,
//! - its descriptor set: exactly the declared bindings (gpu/descriptors.rs), and
//! - the barrier before it, by one rule: an access waits for the last write of the same
//!   memory (read after write, write after write, made visible to the access), and a write
//!   also waits for the reads since that write (write after read: execution order only).
//!   All of a pass's waits go into one memory barrier; a pass that waits for nothing gets none.
//!
//! A frame starts by waiting for everything submitted before it (the frames in flight share
//! the GPU-only buffers, see in_flight.rs), so the tracking starts empty each frame. Within a
//! pass nothing is ordered: its dispatches (one per eye, each writing its own part) may run
//! side by side.

use crate::gpu::{
    vk, Bound, Buffer, ComputePipeline, DescriptorArena, GpuContext, GpuError, PipelineLayout,
    Scope, TimestampPool,
};
use std::collections::HashMap;

/// How a pass touches one resource.
#[derive(Clone, Copy)]
struct Access {
    resource: u64,
    scope: Scope,
    writes: bool,
}

/// What the graph knows of one resource since the frame began.
#[derive(Clone, Copy)]
struct State {
    /// The last write's scope.
    written: Option<Scope>,
    /// Accesses the last write has been made visible to (a barrier already waited for it).
    visible: Scope,
    /// Stages that read since the last write.
    read_by: vk::PipelineStageFlags2,
}

/// The frame's command buffer with the state the passes share.
pub struct FrameGraph<'a> {
    ctx: &'a GpuContext,
    cmd: vk::CommandBuffer,
    layout: &'a PipelineLayout,
    descriptors: &'a mut DescriptorArena,
    timestamps: &'a mut TimestampPool,
    tracker: Tracker,
    /// A pass's descriptor set that failed to be made: reported by `finish`.
    error: Option<GpuError>,
}

/// One pass being declared: its bindings and accesses, then its commands.
#[must_use = "a declared pass records nothing until `record`"]
pub struct Pass<'g, 'a, 'r> {
    graph: &'g mut FrameGraph<'a>,
    bindings: Vec<(u32, Bound<'r>)>,
    accesses: Vec<Access>,
}

/// What a pass's commands are recorded with.
pub struct Recorder<'g> {
    pub cmd: vk::CommandBuffer,
    layout: &'g PipelineLayout,
    set: vk::DescriptorSet,
    timestamps: &'g mut TimestampPool,
}

impl<'a> FrameGraph<'a> {
    /// Starts the frame in `cmd`: the work submitted before it first (frames in flight share
    /// buffers), and its timings reset. `descriptors` must hold no set a pending command
    /// buffer uses: it is reset here.
    pub fn begin(
        ctx: &'a GpuContext,
        cmd: vk::CommandBuffer,
        layout: &'a PipelineLayout,
        descriptors: &'a mut DescriptorArena,
        timestamps: &'a mut TimestampPool,
    ) -> Result<Self, GpuError> {
        descriptors.reset()?;
        ctx.cmd_barrier(cmd, Scope::EARLIER_WORK, Scope::LATER_WORK);
        timestamps.cmd_reset(cmd);
        Ok(Self {
            ctx,
            cmd,
            layout,
            descriptors,
            timestamps,
            tracker: Tracker::default(),
            error: None,
        })
    }

    /// A new pass: declare what it touches, then `record` it.
    pub fn pass<'g, 'r>(&'g mut self) -> Pass<'g, 'a, 'r> {
        Pass {
            graph: self,
            bindings: Vec::new(),
            accesses: Vec::new(),
        }
    }

    /// The host reads `buffer` after the frame's fence: its last write made visible to it.
    pub fn host_reads(&mut self, buffer: &Buffer) {
        let access = Access {
            resource: Bound::Storage(buffer).resource(),
            scope: Scope::HOST_READ,
            writes: false,
        };
        self.wait_for(&[access]);
    }

    /// Ends the frame's recording; an error if a pass could not get its descriptor set.
    pub fn finish(self) -> Result<(), GpuError> {
        self.error.map_or(Ok(()), Err)
    }

    /// Records the barrier `accesses` need, if any.
    fn wait_for(&mut self, accesses: &[Access]) {
        if let Some((before, after)) = self.tracker.barrier(accesses) {
            self.ctx.cmd_barrier(self.cmd, before, after);
        }
    }
}

/// What every resource's accesses so far ask of the next ones.
#[derive(Default)]
struct Tracker {
    states: HashMap<u64, State>,
}

impl Tracker {
    /// The barrier (before, after) that `accesses` need, none when they wait for nothing;
    /// notes them as done.
    fn barrier(&mut self, accesses: &[Access]) -> Option<(Scope, Scope)> {
        let mut before = Scope::NOTHING;
        let mut after = Scope::NOTHING;
        for a in accesses {
            let state = self.states.entry(a.resource).or_insert(State {
                written: None,
                visible: Scope::NOTHING,
                read_by: vk::PipelineStageFlags2::NONE,
            });
            if let Some(written) = state.written {
                if a.writes || !state.visible.contains(a.scope) {
                    before = before.and(written);
                    after = after.and(a.scope);
                }
            }
            if a.writes && !state.read_by.is_empty() {
                before = before.and(Scope::stages(state.read_by));
                after = after.and(a.scope);
            }
        }
        for a in accesses {
            let state = self.states.get_mut(&a.resource).expect("entered above");
            if state.written.is_some() {
                state.visible = state.visible.and(after);
            }
            if a.writes {
                *state = State {
                    written: Some(a.scope.writes()),
                    visible: Scope::NOTHING,
                    read_by: vk::PipelineStageFlags2::NONE,
                };
            } else {
                state.read_by |= a.scope.stages;
            }
        }
        (after != Scope::NOTHING).then_some((before, after))
    }
}

impl<'g, 'a, 'r> Pass<'g, 'a, 'r> {
    fn touch(mut self, binding: Option<u32>, bound: Bound<'r>, scope: Scope, writes: bool) -> Self {
        if let Some(binding) = binding {
            self.bindings.push((binding, bound));
        }
        self.accesses.push(Access {
            resource: bound.resource(),
            scope,
            writes,
        });
        self
    }

    /// The shader reads `binding` (a storage buffer, texel buffer, image or the TLAS).
    pub fn reads(self, binding: u32, bound: impl Into<Bound<'r>>) -> Self {
        let bound = bound.into();
        let scope = match bound {
            Bound::Tlas(_) => Scope::COMPUTE_AS_READ,
            _ => Scope::COMPUTE_READ,
        };
        self.touch(Some(binding), bound, scope, false)
    }

    /// The shader writes `binding` without reading it.
    pub fn writes(self, binding: u32, bound: impl Into<Bound<'r>>) -> Self {
        self.touch(Some(binding), bound.into(), Scope::COMPUTE_WRITE, true)
    }

    /// The shader reads and writes `binding` (atomics, a value updated in place).
    pub fn reads_writes(self, binding: u32, bound: impl Into<Bound<'r>>) -> Self {
        let scope = Scope::COMPUTE_READ_WRITE;
        self.touch(Some(binding), bound.into(), scope, true)
    }

    /// An indirect dispatch reads its workgroup counts from `buffer`.
    pub fn indirect_args(self, buffer: &'r Buffer) -> Self {
        self.touch(None, buffer.into(), Scope::INDIRECT_READ, false)
    }

    /// A copy reads `buffer`.
    pub fn copies_from(self, buffer: &'r Buffer) -> Self {
        self.touch(None, buffer.into(), Scope::COPY_READ, false)
    }

    /// A copy writes `into`.
    pub fn copies_into(self, into: impl Into<Bound<'r>>) -> Self {
        self.touch(None, into.into(), Scope::COPY_WRITE, true)
    }

    /// A fill (vkCmdFillBuffer) writes `buffer`. A clear in synchronization2's terms, a
    /// copy-stage transfer to the installed validation layer (1.3.239): the scope names both.
    pub fn fills(self, buffer: &'r Buffer) -> Self {
        let scope = Scope::FILL_WRITE.and(Scope::COPY_WRITE);
        self.touch(None, buffer.into(), scope, true)
    }

    /// Records the pass: its barrier, its descriptor set (when it binds anything), then
    /// `work`'s commands.
    pub fn record(self, work: impl FnOnce(&mut Recorder)) {
        let graph = self.graph;
        graph.wait_for(&self.accesses);
        let set = match self.bindings.is_empty() {
            true => Ok(vk::DescriptorSet::null()),
            false => graph.descriptors.set(graph.layout, &self.bindings),
        };
        let set = match set {
            Ok(set) => set,
            Err(e) => {
                // Nothing is recorded; `finish` reports it before anything is submitted.
                graph.error.get_or_insert(e);
                return;
            }
        };
        work(&mut Recorder {
            cmd: graph.cmd,
            layout: graph.layout,
            set,
            timestamps: graph.timestamps,
        });
    }
}

impl Recorder<'_> {
    /// A timed dispatch of `groups` workgroups.
    pub fn dispatch<P: bytemuck::NoUninit>(
        &mut self,
        name: &str,
        pipeline: &ComputePipeline,
        push: &P,
        groups: [u32; 3],
    ) {
        let (cmd, layout, set) = (self.cmd, self.layout, self.set);
        self.timestamps.cmd_timed(cmd, name, || {
            pipeline.cmd_dispatch(cmd, layout, set, push, groups)
        });
    }

    /// A timed dispatch whose workgroup counts are at byte `offset` of `args` (declared with
    /// `indirect_args`).
    pub fn dispatch_indirect<P: bytemuck::NoUninit>(
        &mut self,
        name: &str,
        pipeline: &ComputePipeline,
        push: &P,
        args: &Buffer,
        offset: u64,
    ) {
        let (cmd, layout, set) = (self.cmd, self.layout, self.set);
        self.timestamps.cmd_timed(cmd, name, || {
            pipeline.cmd_dispatch_indirect(cmd, layout, set, push, args, offset)
        });
    }

    /// Commands that are not timed (a layout transition).
    pub fn untimed(&mut self, work: impl FnOnce(vk::CommandBuffer)) {
        work(self.cmd);
    }

    /// Timed commands other than dispatches (copies).
    pub fn timed(&mut self, name: &str, work: impl FnOnce(vk::CommandBuffer)) {
        let cmd = self.cmd;
        self.timestamps.cmd_timed(cmd, name, || work(cmd));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(resource: u64, scope: Scope) -> Access {
        Access {
            resource,
            scope,
            writes: false,
        }
    }

    fn write(resource: u64, scope: Scope) -> Access {
        Access {
            resource,
            scope,
            writes: true,
        }
    }

    #[test]
    fn a_first_access_waits_for_nothing() {
        let mut t = Tracker::default();
        assert_eq!(t.barrier(&[read(1, Scope::COMPUTE_READ)]), None);
        assert_eq!(t.barrier(&[write(2, Scope::COMPUTE_WRITE)]), None);
    }

    #[test]
    fn a_read_waits_for_the_write_once() {
        let mut t = Tracker::default();
        t.barrier(&[write(1, Scope::COMPUTE_WRITE)]);
        assert_eq!(
            t.barrier(&[read(1, Scope::COMPUTE_READ)]),
            Some((Scope::COMPUTE_WRITE, Scope::COMPUTE_READ))
        );
        // Made visible to compute reads already: a second reader needs nothing.
        assert_eq!(t.barrier(&[read(1, Scope::COMPUTE_READ)]), None);
        // A copy reading it does: the write was not made visible to copies.
        assert_eq!(
            t.barrier(&[read(1, Scope::COPY_READ)]),
            Some((Scope::COMPUTE_WRITE, Scope::COPY_READ))
        );
    }

    #[test]
    fn a_write_waits_for_the_write_and_the_reads_before_it() {
        let mut t = Tracker::default();
        t.barrier(&[write(1, Scope::COMPUTE_READ_WRITE)]);
        t.barrier(&[read(1, Scope::COPY_READ)]);
        let (before, after) = t.barrier(&[write(1, Scope::COMPUTE_WRITE)]).unwrap();
        // The earlier write's writes only (not its reads), and the copy's execution.
        assert_eq!(
            before,
            Scope::COMPUTE_WRITE.and(Scope::stages(vk::PipelineStageFlags2::COPY))
        );
        assert_eq!(after, Scope::COMPUTE_WRITE);
    }

    #[test]
    fn one_barrier_covers_every_access_of_a_pass() {
        let mut t = Tracker::default();
        t.barrier(&[write(1, Scope::COMPUTE_WRITE), write(2, Scope::COPY_WRITE)]);
        let pass = [
            read(1, Scope::COMPUTE_READ),
            read(2, Scope::INDIRECT_READ),
            read(3, Scope::COMPUTE_READ),
        ];
        assert_eq!(
            t.barrier(&pass),
            Some((
                Scope::COMPUTE_WRITE.and(Scope::COPY_WRITE),
                Scope::COMPUTE_READ.and(Scope::INDIRECT_READ)
            ))
        );
    }
}
