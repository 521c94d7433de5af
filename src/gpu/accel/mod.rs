//! Acceleration structures for ray queries (VK_KHR_acceleration_structure), built on the
//! device once per scene from the same arrays the software traversal reads: one BLAS per
//! distinct mesh (its instances share it) and one of AABBs for all boxes and spheres (for the
//! shader's own tests), and a TLAS with an instance per mesh instance, whose custom index is
//! the object's index, and one for the boxes and spheres, whose AABB index is the object's
//! index: both traversals name hits alike (glsl/ray_query.glsl).
//!
//! Boxes and spheres first had a BLAS and an instance each (an instance transition per box):
//! one shared BLAS traced faster on lavapipe, same session, 256x256, 16 spp, alternated
//! runs: cubes-441 3.2-4.3 s against 3.2-3.9 s (medians 3.2 / 3.9), mirror-room 3.4-3.9 s
//! against 4.8 s.

mod inputs;

use super::context::GpuContext;
use super::device_pick::RayQueryLimits;
use super::error::{GpuError, VkContext};
use super::memory::Buffer;
use super::sync::Scope;
use crate::shader_layout::{AccelObject, GpuTriangle};
use ash::vk;
use gpu_allocator::MemoryLocation;
use inputs::{
    align, blas_info, blas_sources, build_info, instance, instances_geometry, range, too_many,
    upload, BlasInput, Geometry, Layout, Place, Placed, INPUT_USAGE, PROCEDURAL_INSTANCE,
};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The scene's acceleration structures: the TLAS the shaders bind (BINDING_TLAS) and the
/// BLASes it refers to, all in one device-local buffer.
pub struct AccelStructures {
    loader: ash::khr::acceleration_structure::Device,
    blases: Vec<vk::AccelerationStructureKHR>,
    pub(crate) tlas: vk::AccelerationStructureKHR,
    /// Holds the context (through the buffer) alive until the structures are destroyed.
    storage: Buffer,
}

impl AccelStructures {
    /// Builds the BLASes and the TLAS of `objects` over `triangles`, and waits for the build.
    pub fn build(
        ctx: &Arc<GpuContext>,
        triangles: &[GpuTriangle],
        objects: &[AccelObject],
    ) -> Result<Self, GpuError> {
        let limits = checked_limits(ctx, objects)?;
        let loader = ash::khr::acceleration_structure::Device::new(&ctx.instance, &ctx.device);
        let (sources, placed) = blas_sources(objects);
        let geometry = Geometry::upload(ctx, triangles, objects)?;
        let inputs = geometry.blas_inputs(&sources, &limits, objects.len() as u32)?;
        let layout = Layout::new(&loader, &inputs, objects.len() as u32, &limits);
        let this = Self::create_all(ctx, loader, &layout)?;
        let instances = this.upload_instances(ctx, &placed)?;
        let took = this.build_all(
            ctx,
            &inputs,
            &layout,
            &instances,
            placed.len() as u32,
            &limits,
        )?;
        tracing::info!(
            "acceleration structures: {} BLAS, TLAS of {} instances, {} bytes, built in {:.1} ms",
            this.blases.len(),
            placed.len(),
            this.bytes(),
            took.as_secs_f64() * 1e3
        );
        Ok(this)
    }

    /// The storage buffer of `layout` and every structure in it (the BLASes, then the TLAS),
    /// not built yet.
    fn create_all(
        ctx: &Arc<GpuContext>,
        loader: ash::khr::acceleration_structure::Device,
        layout: &Layout,
    ) -> Result<Self, GpuError> {
        let storage = Buffer::new(
            ctx,
            "acceleration structures",
            layout.storage_bytes,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        // Drop destroys whatever exists of it from here on.
        let mut this = Self {
            loader,
            blases: Vec::with_capacity(layout.blases.len()),
            tlas: vk::AccelerationStructureKHR::null(),
            storage,
        };
        for place in &layout.blases {
            let handle = this.create(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, place)?;
            this.blases.push(handle);
        }
        this.tlas = this.create(vk::AccelerationStructureTypeKHR::TOP_LEVEL, &layout.tlas)?;
        Ok(this)
    }

    /// The TLAS's instances, now that the BLASes have addresses, in a build-input buffer.
    fn upload_instances(
        &self,
        ctx: &Arc<GpuContext>,
        placed: &[Placed],
    ) -> Result<Buffer, GpuError> {
        let blas_addresses: Vec<u64> = self.blases.iter().map(|&b| self.address(b)).collect();
        let bytes: Vec<u8> = placed
            .iter()
            .flat_map(|p| {
                instance(
                    p.to_world,
                    p.custom_index,
                    p.surface,
                    blas_addresses[p.blas],
                )
            })
            .collect();
        upload(ctx, "ray-query instances", &bytes, INPUT_USAGE)
    }

    /// Builds every BLAS (together, each in its own part of the scratch), then the TLAS of
    /// `instance_count` instances (reusing the scratch), and waits for the builds; returns
    /// how long the submission took.
    fn build_all(
        &self,
        ctx: &Arc<GpuContext>,
        inputs: &[BlasInput],
        layout: &Layout,
        instances: &Buffer,
        instance_count: u32,
        limits: &RayQueryLimits,
    ) -> Result<Duration, GpuError> {
        // The scratch, its start rounded up to the builds' alignment.
        let scratch = Buffer::new(
            ctx,
            "acceleration-structure build scratch",
            layout.scratch_bytes + limits.scratch_alignment,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        let scratch_base = align(scratch.device_address(), limits.scratch_alignment);
        let blas_builds: Vec<_> = inputs
            .iter()
            .zip(&layout.blases)
            .zip(&self.blases)
            .map(|((input, place), &blas)| {
                blas_info(&input.geometry)
                    .dst_acceleration_structure(blas)
                    .scratch_data(vk::DeviceOrHostAddressKHR {
                        device_address: scratch_base + place.scratch,
                    })
            })
            .collect();
        let blas_ranges: Vec<[vk::AccelerationStructureBuildRangeInfoKHR; 1]> = inputs
            .iter()
            .map(|input| [range(input.primitives)])
            .collect();
        let instance_geometry = [instances_geometry(instances.device_address())];
        let tlas_build = build_info(
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            &instance_geometry,
        )
        .dst_acceleration_structure(self.tlas)
        .scratch_data(vk::DeviceOrHostAddressKHR {
            device_address: scratch_base,
        });
        let builds = Builds {
            blases: &blas_builds,
            blas_ranges: &blas_ranges.iter().map(|r| r.as_slice()).collect::<Vec<_>>(),
            tlas: tlas_build,
            tlas_range: [range(instance_count)],
        };
        let started = Instant::now();
        ctx.submit_and_wait("build acceleration structures", |cmd| {
            self.cmd_build(ctx, cmd, &builds)
        })?;
        Ok(started.elapsed())
    }

    /// Records the builds: the BLASes, a barrier, the TLAS, and the barrier before shaders
    /// trace rays through it.
    fn cmd_build(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, builds: &Builds) {
        // SAFETY: cmd is recording; every structure, input and scratch buffer is alive until
        // the submission is waited for; each BLAS build has its own scratch part, and the
        // TLAS build (which reuses it) waits for them behind the barrier.
        unsafe {
            if !builds.blases.is_empty() {
                self.loader.cmd_build_acceleration_structures(
                    cmd,
                    builds.blases,
                    builds.blas_ranges,
                );
                ctx.cmd_barrier(cmd, Scope::AS_BUILD_WRITE, Scope::AS_BUILD_READ_WRITE);
            }
            self.loader.cmd_build_acceleration_structures(
                cmd,
                &[builds.tlas],
                &[&builds.tlas_range],
            );
        }
        ctx.cmd_barrier(cmd, Scope::AS_BUILD_WRITE, Scope::COMPUTE_AS_READ);
    }

    /// Bytes the structures occupy on the GPU.
    pub fn bytes(&self) -> u64 {
        self.storage.size
    }

    /// The structure of `kind` at `place` in the storage buffer.
    fn create(
        &self,
        kind: vk::AccelerationStructureTypeKHR,
        place: &Place,
    ) -> Result<vk::AccelerationStructureKHR, GpuError> {
        let info = vk::AccelerationStructureCreateInfoKHR::default()
            .buffer(self.storage.buffer)
            .offset(place.offset)
            .size(place.size)
            .ty(kind);
        // SAFETY: the range lies inside the storage buffer (sized from the same build sizes),
        // starts 256-byte aligned, and the buffer has ACCELERATION_STRUCTURE_STORAGE usage.
        unsafe { self.loader.create_acceleration_structure(&info, None) }
            .vk("vkCreateAccelerationStructureKHR")
    }

    fn address(&self, structure: vk::AccelerationStructureKHR) -> u64 {
        let info = vk::AccelerationStructureDeviceAddressInfoKHR::default()
            .acceleration_structure(structure);
        // SAFETY: the structure was created by this loader's device and is alive.
        unsafe { self.loader.get_acceleration_structure_device_address(&info) }
    }
}

impl Drop for AccelStructures {
    fn drop(&mut self) {
        // SAFETY: users wait for the GPU before dropping what they used; the structures are
        // destroyed before their storage buffer (a field, dropped after this).
        unsafe {
            for &blas in &self.blases {
                self.loader.destroy_acceleration_structure(blas, None);
            }
            if self.tlas != vk::AccelerationStructureKHR::null() {
                self.loader.destroy_acceleration_structure(self.tlas, None);
            }
        }
    }
}

/// The device's ray-query limits, if `objects` fit them.
fn checked_limits(ctx: &GpuContext, objects: &[AccelObject]) -> Result<RayQueryLimits, GpuError> {
    let limits = ctx
        .info
        .ray_query
        .ok_or_else(|| GpuError::Limit("ray queries are not enabled on this device".into()))?;
    // The custom index that names an object is 24 bits wide (and all ones is the boxes'
    // and spheres' instance); the procedural BLAS has an AABB per object.
    let max_objects = limits
        .max_instances
        .min(limits.max_primitives)
        .min(PROCEDURAL_INSTANCE as u64);
    if objects.len() as u64 > max_objects {
        return Err(too_many(format!(
            "{} objects (ray queries here name at most {max_objects})",
            objects.len()
        )));
    }
    Ok(limits)
}

/// The build commands' arguments, in the order they are recorded.
struct Builds<'a> {
    blases: &'a [vk::AccelerationStructureBuildGeometryInfoKHR<'a>],
    blas_ranges: &'a [&'a [vk::AccelerationStructureBuildRangeInfoKHR]],
    tlas: vk::AccelerationStructureBuildGeometryInfoKHR<'a>,
    tlas_range: [vk::AccelerationStructureBuildRangeInfoKHR; 1],
}
