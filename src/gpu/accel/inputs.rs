//! What the acceleration-structure builds read, and where the structures go: the BLASes and
//! TLAS instances the scene's objects become, their geometry in build-input buffers, the
//! instances' bytes, and each structure's place in the one storage buffer.

use crate::gpu::context::GpuContext;
use crate::gpu::device_pick::RayQueryLimits;
use crate::gpu::error::GpuError;
use crate::gpu::memory::Buffer;
use crate::shader_layout::GpuTriangle;
use crate::shader_layout::{AccelObject, OBJECT_CUTOUT, OBJECT_SINGLE_SIDED};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;
use std::sync::Arc;

/// Acceleration structures must start at multiples of 256 bytes of their buffer.
const AS_ALIGNMENT: u64 = 256;
/// VkAabbPositionsKHR: min xyz, max xyz.
const AABB_BYTES: u64 = 24;
/// VkAccelerationStructureInstanceKHR.
const INSTANCE_BYTES: usize = 64;

pub(super) fn align(value: u64, to: u64) -> u64 {
    value.div_ceil(to) * to
}

/// One BLAS to build: its geometry and primitive count.
pub(super) struct BlasInput<'a> {
    pub(super) geometry: vk::AccelerationStructureGeometryKHR<'a>,
    pub(super) primitives: u32,
}

const IDENTITY: [[f32; 4]; 3] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

/// Where one BLAS's primitives come from.
#[derive(Debug, PartialEq)]
pub(super) enum BlasSource {
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
pub(super) struct Placed {
    pub(super) blas: usize,
    pub(super) custom_index: u32,
    pub(super) to_world: [[f32; 4]; 3],
    /// shared.h's OBJECT_* flags (0 for the boxes and spheres).
    pub(super) surface: u32,
}

/// The custom index of the boxes-and-spheres instance (its hits name their object by
/// primitive index instead).
pub(super) const PROCEDURAL_INSTANCE: u32 = 0xff_ffff;

/// The BLASes to build (a mesh's once, however many instances it has; one for all boxes and
/// spheres) and the TLAS's instances: one per mesh instance, whose custom index is its object
/// index, and one for the boxes and spheres.
pub(super) fn blas_sources(objects: &[AccelObject]) -> (Vec<BlasSource>, Vec<Placed>) {
    let mut sources = Vec::new();
    let mut meshes: HashMap<(u32, u32), usize> = HashMap::new();
    let mut placed = Vec::new();
    for (index, object) in objects.iter().enumerate() {
        if let AccelObject::Mesh {
            first,
            count,
            to_world,
            surface,
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
                surface,
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
            surface: 0,
        });
    }
    (sources, placed)
}

pub(super) fn too_many(what: String) -> GpuError {
    GpuError::Limit(format!(
        "{what}: more than ray queries allow on this device; simplify the scene, or use \
         --traversal software"
    ))
}

/// The build inputs, read by the device during the build only: host-visible buffers.
pub(super) const INPUT_USAGE: vk::BufferUsageFlags = vk::BufferUsageFlags::from_raw(
    vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS.as_raw()
        | vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR.as_raw(),
);

/// What the BLASes are built from: the triangles' vertices and one AABB per object.
pub(super) struct Geometry {
    vertices: Buffer,
    aabbs: Buffer,
}

impl Geometry {
    pub(super) fn upload(
        ctx: &Arc<GpuContext>,
        triangles: &[GpuTriangle],
        objects: &[AccelObject],
    ) -> Result<Self, GpuError> {
        let vertices = upload(
            ctx,
            "ray-query vertices",
            bytemuck::cast_slice(triangles),
            INPUT_USAGE,
        )?;
        let aabbs = upload(
            ctx,
            "ray-query bounds",
            bytemuck::cast_slice(&object_aabbs(objects)),
            INPUT_USAGE,
        )?;
        Ok(Self { vertices, aabbs })
    }

    /// The geometry of each BLAS of `sources`; the procedural one has an AABB for each of
    /// the `objects`. A mesh larger than a BLAS may hold is refused.
    pub(super) fn blas_inputs(
        &self,
        sources: &[BlasSource],
        limits: &RayQueryLimits,
        objects: u32,
    ) -> Result<Vec<BlasInput<'static>>, GpuError> {
        sources
            .iter()
            .map(|source| match *source {
                BlasSource::Mesh { first, count } => {
                    if count as u64 > limits.max_primitives {
                        return Err(too_many(format!(
                            "a mesh of {count} triangles (a BLAS holds at most {})",
                            limits.max_primitives
                        )));
                    }
                    Ok(self.triangles(first, count))
                }
                BlasSource::Procedural => Ok(self.boxes(objects)),
            })
            .collect()
    }

    /// Triangles `first .. first + count`, three vertices each, not indexed.
    fn triangles(&self, first: u32, count: u32) -> BlasInput<'static> {
        let triangles = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
            .vertex_format(vk::Format::R32G32B32_SFLOAT)
            .vertex_data(vk::DeviceOrHostAddressConstKHR {
                device_address: self.vertices.device_address()
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

    /// The AABBs of all `objects`.
    fn boxes(&self, objects: u32) -> BlasInput<'static> {
        let aabbs = vk::AccelerationStructureGeometryAabbsDataKHR::default()
            .data(vk::DeviceOrHostAddressConstKHR {
                device_address: self.aabbs.device_address(),
            })
            .stride(AABB_BYTES);
        BlasInput {
            geometry: vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::AABBS)
                .geometry(vk::AccelerationStructureGeometryDataKHR { aabbs })
                .flags(vk::GeometryFlagsKHR::OPAQUE),
            primitives: objects,
        }
    }
}

/// One AABB per object, so that a procedural hit's primitive index is the object's index. A
/// mesh instance's is a point at a box's or sphere's corner: Vulkan's inactive AABB (a NaN
/// minimum x) made lavapipe (Mesa 25.0.7) miss every box and sphere of bunny-low, and a point
/// is never a candidate unless a ray passes exactly through it, when the shader ignores it
/// (not a box, not a sphere).
fn object_aabbs(objects: &[AccelObject]) -> Vec<[f32; 6]> {
    let anchor = objects
        .iter()
        .find_map(|o| match o {
            AccelObject::Bounds { min, .. } => Some(*min),
            AccelObject::Mesh { .. } => None,
        })
        .unwrap_or([0.0; 3]);
    objects
        .iter()
        .map(|object| match *object {
            AccelObject::Bounds { min, max } => [min[0], min[1], min[2], max[0], max[1], max[2]],
            AccelObject::Mesh { .. } => [anchor, anchor].concat().try_into().expect("6 floats"),
        })
        .collect()
}

/// Where a structure lies in the storage buffer, and where its build's scratch starts.
pub(super) struct Place {
    pub(super) offset: u64,
    pub(super) size: u64,
    pub(super) scratch: u64,
}

/// Every structure's place in the one storage buffer, and the scratch the builds need (the
/// BLAS builds run together, each in its own part; the TLAS build reuses it).
pub(super) struct Layout {
    pub(super) blases: Vec<Place>,
    pub(super) tlas: Place,
    pub(super) storage_bytes: u64,
    pub(super) scratch_bytes: u64,
}

impl Layout {
    /// The layout for `inputs` and a TLAS of at most `max_instances` instances.
    pub(super) fn new(
        loader: &ash::khr::acceleration_structure::Device,
        inputs: &[BlasInput],
        max_instances: u32,
        limits: &RayQueryLimits,
    ) -> Self {
        let mut blases = Vec::with_capacity(inputs.len());
        let (mut storage_bytes, mut scratch_bytes) = (0u64, 0u64);
        for input in inputs {
            let sizes = build_sizes(loader, &blas_info(&input.geometry), input.primitives);
            blases.push(Place {
                offset: storage_bytes,
                size: sizes.acceleration_structure_size,
                scratch: scratch_bytes,
            });
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
            loader,
            &build_info(
                vk::AccelerationStructureTypeKHR::TOP_LEVEL,
                &instance_geometry,
            ),
            max_instances,
        );
        let tlas = Place {
            offset: storage_bytes,
            size: tlas_sizes.acceleration_structure_size,
            scratch: 0,
        };
        Self {
            storage_bytes: storage_bytes + tlas.size,
            scratch_bytes: scratch_bytes.max(tlas_sizes.build_scratch_size),
            blases,
            tlas,
        }
    }
}

pub(super) fn upload(
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

pub(super) fn blas_info<'a>(
    geometry: &'a vk::AccelerationStructureGeometryKHR<'a>,
) -> vk::AccelerationStructureBuildGeometryInfoKHR<'a> {
    build_info(
        vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
        std::slice::from_ref(geometry),
    )
}

pub(super) fn build_info<'a>(
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

pub(super) fn instances_geometry(address: u64) -> vk::AccelerationStructureGeometryKHR<'static> {
    let instances = vk::AccelerationStructureGeometryInstancesDataKHR::default()
        .array_of_pointers(false)
        .data(vk::DeviceOrHostAddressConstKHR {
            device_address: address,
        });
    vk::AccelerationStructureGeometryKHR::default()
        .geometry_type(vk::GeometryTypeKHR::INSTANCES)
        .geometry(vk::AccelerationStructureGeometryDataKHR { instances })
}

pub(super) fn range(primitives: u32) -> vk::AccelerationStructureBuildRangeInfoKHR {
    vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(primitives)
}

/// A VkAccelerationStructureInstanceKHR's bytes: the 3x4 row-major transform, the custom
/// index (24 bits) with mask 0xff, SBT offset 0 with its flags, the BLAS's address.
pub(super) fn instance(
    to_world: [[f32; 4]; 3],
    custom_index: u32,
    surface: u32,
    blas: u64,
) -> [u8; INSTANCE_BYTES] {
    let flags = instance_flags(surface).as_raw();
    let mut bytes = [0u8; INSTANCE_BYTES];
    let floats: Vec<f32> = to_world.iter().flatten().copied().collect();
    bytes[..48].copy_from_slice(bytemuck::cast_slice(&floats));
    bytes[48..52].copy_from_slice(&(custom_index | 0xff << 24).to_le_bytes());
    bytes[52..56].copy_from_slice(&(flags << 24).to_le_bytes());
    bytes[56..].copy_from_slice(&blas.to_le_bytes());
    bytes
}

/// How the driver treats an instance's triangles, from its OBJECT_* flags. Opaque ones are
/// committed by the driver; alpha-cut ones come back to ray_query.glsl's loop as candidates.
/// Culling is off but for single-sided instances, and applies only to rays that ask for it
/// (ray_query.glsl's flags in a scene with single-sided instances). Vulkan's front face is
/// clockwise seen from the ray in a left-handed frame, which is glTF's counter-clockwise in
/// its right-handed one: no flip. Both are in object space, so a mirroring transform leaves
/// them alone, as glTF's determinant rule wants.
fn instance_flags(surface: u32) -> vk::GeometryInstanceFlagsKHR {
    let alpha = if surface & OBJECT_CUTOUT != 0 {
        vk::GeometryInstanceFlagsKHR::FORCE_NO_OPAQUE
    } else {
        vk::GeometryInstanceFlagsKHR::FORCE_OPAQUE
    };
    if surface & OBJECT_SINGLE_SIDED != 0 {
        alpha
    } else {
        alpha | vk::GeometryInstanceFlagsKHR::TRIANGLE_FACING_CULL_DISABLE
    }
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
        let bytes = instance(to_world, 0x123456, 0, 0x1122_3344_5566_7788);
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
            surface: 0,
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
