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

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::memory::Buffer;
use super::shared::GpuTriangle;
use super::sync::Scope;
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;
use std::sync::Arc;

/// What one object of the scene is to the ray-query traversal (indexed as OBJECTS).
#[derive(Clone, Copy, Debug)]
pub enum AccelObject {
    /// A mesh instance: triangles `first .. first + count` of the triangle array (object
    /// space), placed by `to_world` (the rows of its 3x4 object-to-world matrix).
    Mesh {
        first: u32,
        count: u32,
        to_world: [[f32; 4]; 3],
    },
    /// A box or a sphere: the world bounds inside which the shader tests it.
    Bounds { min: [f32; 3], max: [f32; 3] },
}

/// The scene's acceleration structures: the TLAS the shaders bind (BINDING_TLAS) and the
/// BLASes it refers to, all in one device-local buffer.
pub struct AccelStructures {
    loader: ash::khr::acceleration_structure::Device,
    blases: Vec<vk::AccelerationStructureKHR>,
    pub(crate) tlas: vk::AccelerationStructureKHR,
    /// Holds the context (through the buffer) alive until the structures are destroyed.
    storage: Buffer,
}

/// Acceleration structures must start at multiples of 256 bytes of their buffer.
const AS_ALIGNMENT: u64 = 256;
/// VkAabbPositionsKHR: min xyz, max xyz.
const AABB_BYTES: u64 = 24;
/// VkAccelerationStructureInstanceKHR.
const INSTANCE_BYTES: usize = 64;

fn align(value: u64, to: u64) -> u64 {
    value.div_ceil(to) * to
}

/// One BLAS to build: its geometry and primitive count.
struct BlasInput<'a> {
    geometry: vk::AccelerationStructureGeometryKHR<'a>,
    primitives: u32,
}

impl AccelStructures {
    /// Builds the BLASes and the TLAS of `objects` over `triangles`, and waits for the build.
    pub fn build(
        ctx: &Arc<GpuContext>,
        triangles: &[GpuTriangle],
        objects: &[AccelObject],
    ) -> Result<Self, GpuError> {
        let limits = ctx
            .info
            .ray_query
            .ok_or_else(|| GpuError::Limit("ray queries are not enabled on this device".into()))?;
        let too_many = |what: String| {
            GpuError::Limit(format!(
                "{what}: more than ray queries allow on this device; simplify the scene, or use \
                 --traversal software"
            ))
        };
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
        let loader = ash::khr::acceleration_structure::Device::new(&ctx.instance, &ctx.device);

        // The build inputs, read by the device during the build only: host-visible buffers.
        let input_usage = vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS
            | vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR;
        let vertices = upload(
            ctx,
            "ray-query vertices",
            bytemuck::cast_slice(triangles),
            input_usage,
        )?;
        let (sources, placed) = blas_sources(objects);
        // One AABB per object, so that a procedural hit's primitive index is the object's
        // index. A mesh instance's is a point at a box's or sphere's corner: Vulkan's
        // inactive AABB (a NaN minimum x) made lavapipe (Mesa 25.0.7) miss every box and
        // sphere of bunny-low, and a point is never a candidate unless a ray passes exactly
        // through it, when the shader ignores it (not a box, not a sphere).
        let anchor = objects
            .iter()
            .find_map(|o| match o {
                AccelObject::Bounds { min, .. } => Some(*min),
                AccelObject::Mesh { .. } => None,
            })
            .unwrap_or([0.0; 3]);
        let boxes: Vec<[f32; 6]> = objects
            .iter()
            .map(|object| match *object {
                AccelObject::Bounds { min, max } => {
                    [min[0], min[1], min[2], max[0], max[1], max[2]]
                }
                AccelObject::Mesh { .. } => [anchor, anchor].concat().try_into().expect("6 floats"),
            })
            .collect();
        let aabbs = upload(
            ctx,
            "ray-query bounds",
            bytemuck::cast_slice(&boxes),
            input_usage,
        )?;

        let mut inputs = Vec::with_capacity(sources.len());
        for source in &sources {
            inputs.push(match *source {
                BlasSource::Mesh { first, count } => {
                    if count as u64 > limits.max_primitives {
                        return Err(too_many(format!(
                            "a mesh of {count} triangles (a BLAS holds at most {})",
                            limits.max_primitives
                        )));
                    }
                    let triangles = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
                        .vertex_format(vk::Format::R32G32B32_SFLOAT)
                        .vertex_data(vk::DeviceOrHostAddressConstKHR {
                            device_address: vertices.device_address()
                                + first as u64 * std::mem::size_of::<GpuTriangle>() as u64,
                        })
                        .vertex_stride(16)
                        .max_vertex(count * 3 - 1)
                        .index_type(vk::IndexType::NONE_KHR);
                    BlasInput {
                        geometry: vk::AccelerationStructureGeometryKHR::default()
                            .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
                            .geometry(vk::AccelerationStructureGeometryDataKHR { triangles })
                            .flags(vk::GeometryFlagsKHR::OPAQUE),
                        primitives: count,
                    }
                }
                BlasSource::Procedural => {
                    let aabbs = vk::AccelerationStructureGeometryAabbsDataKHR::default()
                        .data(vk::DeviceOrHostAddressConstKHR {
                            device_address: aabbs.device_address(),
                        })
                        .stride(AABB_BYTES);
                    BlasInput {
                        geometry: vk::AccelerationStructureGeometryKHR::default()
                            .geometry_type(vk::GeometryTypeKHR::AABBS)
                            .geometry(vk::AccelerationStructureGeometryDataKHR { aabbs })
                            .flags(vk::GeometryFlagsKHR::OPAQUE),
                        primitives: objects.len() as u32,
                    }
                }
            });
        }

        // Sizes first: every structure's place in the one storage buffer, and each build's
        // scratch (the BLAS builds run together, each in its own part; the TLAS reuses it).
        let mut places = Vec::with_capacity(inputs.len());
        let (mut storage_bytes, mut scratch_bytes) = (0u64, 0u64);
        for input in &inputs {
            let sizes = build_sizes(&loader, &blas_info(&input.geometry), input.primitives);
            places.push((
                storage_bytes,
                sizes.acceleration_structure_size,
                scratch_bytes,
            ));
            storage_bytes = align(
                storage_bytes + sizes.acceleration_structure_size,
                AS_ALIGNMENT,
            );
            scratch_bytes = align(
                scratch_bytes + sizes.build_scratch_size,
                limits.scratch_alignment,
            );
        }
        let instance_geometry = [instances_geometry(0)];
        let tlas_sizes = build_sizes(
            &loader,
            &build_info(
                vk::AccelerationStructureTypeKHR::TOP_LEVEL,
                &instance_geometry,
            ),
            objects.len() as u32,
        );
        let tlas_offset = storage_bytes;
        storage_bytes += tlas_sizes.acceleration_structure_size;
        scratch_bytes = scratch_bytes.max(tlas_sizes.build_scratch_size);

        let storage = Buffer::new(
            ctx,
            "acceleration structures",
            storage_bytes,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR
                | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        let mut this = Self {
            loader,
            blases: Vec::with_capacity(places.len()),
            tlas: vk::AccelerationStructureKHR::null(),
            storage,
        };
        for &(offset, size, _) in &places {
            let handle =
                this.create(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, offset, size)?;
            this.blases.push(handle);
        }
        this.tlas = this.create(
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            tlas_offset,
            tlas_sizes.acceleration_structure_size,
        )?;

        // The instances, now that the BLASes have addresses.
        let blas_addresses: Vec<u64> = this.blases.iter().map(|&b| this.address(b)).collect();
        let instance_bytes: Vec<u8> = placed
            .iter()
            .flat_map(|p| instance(p.to_world, p.custom_index, blas_addresses[p.blas]))
            .collect();
        let instances = upload(ctx, "ray-query instances", &instance_bytes, input_usage)?;
        let instance_geometry = [instances_geometry(instances.device_address())];

        // The scratch, its start rounded up to the builds' alignment.
        let scratch = Buffer::new(
            ctx,
            "acceleration-structure build scratch",
            scratch_bytes + limits.scratch_alignment,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS,
            MemoryLocation::GpuOnly,
        )?;
        let scratch_base = align(scratch.device_address(), limits.scratch_alignment);
        let blas_builds: Vec<_> = inputs
            .iter()
            .zip(&places)
            .zip(&this.blases)
            .map(|((input, &(_, _, scratch_offset)), &blas)| {
                blas_info(&input.geometry)
                    .dst_acceleration_structure(blas)
                    .scratch_data(vk::DeviceOrHostAddressKHR {
                        device_address: scratch_base + scratch_offset,
                    })
            })
            .collect();
        let blas_ranges: Vec<[vk::AccelerationStructureBuildRangeInfoKHR; 1]> = inputs
            .iter()
            .map(|input| [range(input.primitives)])
            .collect();
        let blas_range_refs: Vec<&[vk::AccelerationStructureBuildRangeInfoKHR]> =
            blas_ranges.iter().map(|r| r.as_slice()).collect();
        let tlas_build = build_info(
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            &instance_geometry,
        )
        .dst_acceleration_structure(this.tlas)
        .scratch_data(vk::DeviceOrHostAddressKHR {
            device_address: scratch_base,
        });
        let tlas_range = [range(placed.len() as u32)];
        let started = std::time::Instant::now();
        ctx.submit_and_wait("build acceleration structures", |cmd| {
            // SAFETY: cmd is recording; every structure, input and scratch buffer is alive
            // until the wait returns; each BLAS build has its own scratch part, and the TLAS
            // build (which reuses it) waits for them behind the barrier.
            unsafe {
                if !blas_builds.is_empty() {
                    this.loader.cmd_build_acceleration_structures(
                        cmd,
                        &blas_builds,
                        &blas_range_refs,
                    );
                    ctx.cmd_barrier(cmd, Scope::AS_BUILD_WRITE, Scope::AS_BUILD_READ_WRITE);
                }
                this.loader
                    .cmd_build_acceleration_structures(cmd, &[tlas_build], &[&tlas_range]);
            }
            ctx.cmd_barrier(cmd, Scope::AS_BUILD_WRITE, Scope::COMPUTE_AS_READ);
        })?;
        tracing::info!(
            "acceleration structures: {} BLAS, TLAS of {} instances, {} bytes, built in {:.1} ms",
            this.blases.len(),
            placed.len(),
            this.bytes(),
            started.elapsed().as_secs_f64() * 1e3
        );
        drop((vertices, aabbs, instances, scratch));
        Ok(this)
    }

    /// Bytes the structures occupy on the GPU.
    pub fn bytes(&self) -> u64 {
        self.storage.size
    }

    fn create(
        &self,
        kind: vk::AccelerationStructureTypeKHR,
        offset: u64,
        size: u64,
    ) -> Result<vk::AccelerationStructureKHR, GpuError> {
        let info = vk::AccelerationStructureCreateInfoKHR::default()
            .buffer(self.storage.buffer)
            .offset(offset)
            .size(size)
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

const IDENTITY: [[f32; 4]; 3] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

/// Where one BLAS's primitives come from.
#[derive(Debug, PartialEq)]
enum BlasSource {
    Mesh {
        first: u32,
        count: u32,
    },
    /// Every box and sphere: one AABB per object (glsl/ray_query.glsl reads the object's
    /// index as the primitive index).
    Procedural,
}

/// One TLAS instance: its BLAS (index into the sources), custom index and transform.
#[derive(Debug, PartialEq)]
struct Placed {
    blas: usize,
    custom_index: u32,
    to_world: [[f32; 4]; 3],
}

/// The custom index of the boxes-and-spheres instance (its hits name their object by
/// primitive index instead).
const PROCEDURAL_INSTANCE: u32 = 0xff_ffff;

/// The BLASes to build (a mesh's once, however many instances it has; one for all boxes and
/// spheres) and the TLAS's instances: one per mesh instance, whose custom index is its object
/// index, and one for the boxes and spheres.
fn blas_sources(objects: &[AccelObject]) -> (Vec<BlasSource>, Vec<Placed>) {
    let mut sources = Vec::new();
    let mut meshes: HashMap<(u32, u32), usize> = HashMap::new();
    let mut placed = Vec::new();
    for (index, object) in objects.iter().enumerate() {
        if let AccelObject::Mesh {
            first,
            count,
            to_world,
        } = *object
        {
            let blas = *meshes.entry((first, count)).or_insert_with(|| {
                sources.push(BlasSource::Mesh { first, count });
                sources.len() - 1
            });
            placed.push(Placed {
                blas,
                custom_index: index as u32,
                to_world,
            });
        }
    }
    if objects
        .iter()
        .any(|o| matches!(o, AccelObject::Bounds { .. }))
    {
        sources.push(BlasSource::Procedural);
        placed.push(Placed {
            blas: sources.len() - 1,
            custom_index: PROCEDURAL_INSTANCE,
            to_world: IDENTITY,
        });
    }
    (sources, placed)
}

fn upload(
    ctx: &Arc<GpuContext>,
    name: &str,
    bytes: &[u8],
    usage: vk::BufferUsageFlags,
) -> Result<Buffer, GpuError> {
    let mut buffer = Buffer::new(
        ctx,
        name,
        bytes.len() as u64,
        usage,
        MemoryLocation::CpuToGpu,
    )?;
    buffer.write(0, bytes)?;
    Ok(buffer)
}

fn blas_info<'a>(
    geometry: &'a vk::AccelerationStructureGeometryKHR<'a>,
) -> vk::AccelerationStructureBuildGeometryInfoKHR<'a> {
    build_info(
        vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
        std::slice::from_ref(geometry),
    )
}

fn build_info<'a>(
    kind: vk::AccelerationStructureTypeKHR,
    geometries: &'a [vk::AccelerationStructureGeometryKHR<'a>],
) -> vk::AccelerationStructureBuildGeometryInfoKHR<'a> {
    // Built once per scene and traced millions of times: the fastest traversal wins.
    vk::AccelerationStructureBuildGeometryInfoKHR::default()
        .ty(kind)
        .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE)
        .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
        .geometries(geometries)
}

fn build_sizes(
    loader: &ash::khr::acceleration_structure::Device,
    info: &vk::AccelerationStructureBuildGeometryInfoKHR,
    primitives: u32,
) -> vk::AccelerationStructureBuildSizesInfoKHR<'static> {
    let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
    // SAFETY: the info describes one geometry, whose primitive count is given.
    unsafe {
        loader.get_acceleration_structure_build_sizes(
            vk::AccelerationStructureBuildTypeKHR::DEVICE,
            info,
            &[primitives],
            &mut sizes,
        )
    };
    sizes
}

fn instances_geometry(address: u64) -> vk::AccelerationStructureGeometryKHR<'static> {
    let instances = vk::AccelerationStructureGeometryInstancesDataKHR::default()
        .array_of_pointers(false)
        .data(vk::DeviceOrHostAddressConstKHR {
            device_address: address,
        });
    vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::INSTANCES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { instances })
}

fn range(primitives: u32) -> vk::AccelerationStructureBuildRangeInfoKHR {
    vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(primitives)
}

/// A VkAccelerationStructureInstanceKHR's bytes: the 3x4 row-major transform, the custom
/// index (24 bits) with mask 0xff, SBT offset 0 with its flags, the BLAS's address. Opaque and
/// never culled: the integrators shade both faces.
fn instance(to_world: [[f32; 4]; 3], custom_index: u32, blas: u64) -> [u8; INSTANCE_BYTES] {
    let flags = (vk::GeometryInstanceFlagsKHR::FORCE_OPAQUE
        | vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE)
        .as_raw();
    let mut bytes = [0u8; INSTANCE_BYTES];
    let floats: Vec<f32> = to_world.iter().flatten().copied().collect();
    bytes[..48].copy_from_slice(bytemuck::cast_slice(&floats));
    bytes[48..52].copy_from_slice(&(custom_index | 0xff << 24).to_le_bytes());
    bytes[52..56].copy_from_slice(&(flags << 24).to_le_bytes());
    bytes[56..].copy_from_slice(&blas.to_le_bytes());
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn instances_are_laid_out_as_vulkan_reads_them() {
        let to_world = [
            [1.0, 2.0, 3.0, 4.0],
            [5.0, 6.0, 7.0, 8.0],
            [9.0, 10.0, 11.0, 12.0],
        ];
        let bytes = instance(to_world, 0x123456, 0x1122_3344_5566_7788);
        let word = |i: usize| u32::from_le_bytes(bytes[i * 4..i * 4 + 4].try_into().unwrap());
        assert_eq!(f32::from_bits(word(3)), 4.0);
        assert_eq!(f32::from_bits(word(11)), 12.0);
        assert_eq!(word(12), 0xff12_3456);
        assert_eq!(word(13) >> 24, 0b101); // TRIANGLE_FACING_CULL_DISABLE | FORCE_OPAQUE
        assert_eq!(
            u64::from_le_bytes(bytes[56..].try_into().unwrap()),
            0x1122_3344_5566_7788
        );
    }

    #[test]
    fn instances_of_one_mesh_share_its_blas_and_boxes_and_spheres_share_one() {
        let mesh = |first| AccelObject::Mesh {
            first,
            count: 4,
            to_world: IDENTITY,
        };
        let bounds = AccelObject::Bounds {
            min: [0.0; 3],
            max: [1.0; 3],
        };
        let (sources, placed) = blas_sources(&[mesh(0), bounds, mesh(4), mesh(0), bounds]);
        assert_eq!(sources.len(), 3);
        assert_eq!(sources[2], BlasSource::Procedural);
        let blas: Vec<(usize, u32)> = placed.iter().map(|p| (p.blas, p.custom_index)).collect();
        assert_eq!(blas, vec![(0, 0), (1, 2), (0, 3), (2, PROCEDURAL_INSTANCE)]);
    }
}
