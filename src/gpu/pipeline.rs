//! The one descriptor-set layout every fovea compute shader uses (all of shared.h's bindings,
//! the texture array partially bound, and BINDING_TLAS where the context has ray queries), its pipeline layout with the push
//! constants, and compute pipelines with specialization constants. Each pass gets its own set
//! of this layout with only its bindings written (descriptors.rs).

use super::context::GpuContext;
use super::error::{GpuError, VkContext};
use super::memory::Buffer;
use crate::shader_layout::*;
use ash::vk;
use std::sync::Arc;

/// The bindings that are storage images and those that are uniform texel buffers (see
/// TexelView); all others are storage buffers.
const IMAGE_BINDINGS: [u32; 3] = [BINDING_OUTPUT, BINDING_LAYER_IMAGES, BINDING_DISPLAY];
const TEXEL_BINDINGS: [u32; 12] = [
    BINDING_NODES,
    BINDING_TRIANGLES,
    BINDING_SHADING,
    BINDING_OBJECTS,
    BINDING_MATERIALS,
    BINDING_EMITTERS,
    BINDING_LATTICE_TEXELS,
    BINDING_ENVIRONMENT,
    BINDING_DENOISE_INPUT,
    BINDING_HISTORY_TEXELS,
    BINDING_SURFACE_TEXELS,
    BINDING_LATTICE_SURFACE_TEXELS,
];

/// The bindings that are arrays of one texel view per eye (EyeTexels).
pub(super) const EYE_TEXEL_BINDINGS: [u32; 2] =
    [BINDING_LATTICE_TEXELS, BINDING_LATTICE_SURFACE_TEXELS];

fn descriptor_type(binding: u32) -> vk::DescriptorType {
    if binding == BINDING_TEXTURES {
        vk::DescriptorType::COMBINED_IMAGE_SAMPLER
    } else if IMAGE_BINDINGS.contains(&binding) {
        vk::DescriptorType::STORAGE_IMAGE
    } else if TEXEL_BINDINGS.contains(&binding) {
        vk::DescriptorType::UNIFORM_TEXEL_BUFFER
    } else {
        vk::DescriptorType::STORAGE_BUFFER
    }
}

pub struct PipelineLayout {
    ctx: Arc<GpuContext>,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    pub(crate) layout: vk::PipelineLayout,
}

impl PipelineLayout {
    pub fn new(ctx: &Arc<GpuContext>) -> Result<Self, GpuError> {
        let device = &ctx.device;
        let binding = |b, kind| {
            let count = match b {
                BINDING_TEXTURES => MAX_TEXTURES,
                _ if EYE_TEXEL_BINDINGS.contains(&b) => EYE_TEXEL_VIEWS,
                _ => 1,
            };
            vk::DescriptorSetLayoutBinding::default()
                .binding(b)
                .descriptor_type(kind)
                .descriptor_count(count)
                .stage_flags(vk::ShaderStageFlags::COMPUTE)
        };
        let mut bindings: Vec<_> = (0..BINDING_COUNT)
            .map(|b| binding(b, descriptor_type(b)))
            .collect();
        // The texture array is partially bound: a scene writes as many as it has (none, most
        // often), and the shaders index only those.
        let mut flags: Vec<vk::DescriptorBindingFlags> = (0..BINDING_COUNT)
            .map(|b| match b == BINDING_TEXTURES {
                true => vk::DescriptorBindingFlags::PARTIALLY_BOUND,
                false => vk::DescriptorBindingFlags::empty(),
            })
            .collect();
        // A device without ray queries knows no such descriptor type.
        let ray_query = ctx.info.ray_query.is_some();
        if ray_query {
            bindings.push(binding(
                BINDING_TLAS,
                vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            ));
            flags.push(vk::DescriptorBindingFlags::empty());
        }
        let mut binding_flags =
            vk::DescriptorSetLayoutBindingFlagsCreateInfo::default().binding_flags(&flags);
        let info = vk::DescriptorSetLayoutCreateInfo::default()
            .bindings(&bindings)
            .push_next(&mut binding_flags);
        // SAFETY: valid device and create info.
        let set_layout = unsafe { device.create_descriptor_set_layout(&info, None) }
            .vk("vkCreateDescriptorSetLayout")?;
        let mut this = Self {
            ctx: ctx.clone(),
            set_layout,
            layout: vk::PipelineLayout::null(),
        };
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::COMPUTE)
            .size(PUSH_BYTES as u32)];
        let layouts = [set_layout];
        let info = vk::PipelineLayoutCreateInfo::default()
            .set_layouts(&layouts)
            .push_constant_ranges(&ranges);
        // SAFETY: the set layout is alive.
        this.layout =
            unsafe { device.create_pipeline_layout(&info, None) }.vk("vkCreatePipelineLayout")?;
        Ok(this)
    }
}

impl Drop for PipelineLayout {
    fn drop(&mut self) {
        // SAFETY: no command buffer using these is pending.
        unsafe {
            let d = &self.ctx.device;
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

pub struct ComputePipeline {
    ctx: Arc<GpuContext>,
    pub(crate) pipeline: vk::Pipeline,
    pub name: &'static str,
}

impl ComputePipeline {
    /// Creates a pipeline from SPIR-V with `(constant_id, value)` specialization constants
    /// (booleans as 0/1, all 32-bit).
    pub fn new(
        ctx: &Arc<GpuContext>,
        layout: &PipelineLayout,
        name: &'static str,
        spirv: &[u8],
        specialization: &[(u32, u32)],
    ) -> Result<Self, GpuError> {
        let device = &ctx.device;
        let words: Vec<u32> = spirv
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let info = vk::ShaderModuleCreateInfo::default().code(&words);
        // SAFETY: the SPIR-V was produced by glslc (shaderc) at build time.
        let module =
            unsafe { device.create_shader_module(&info, None) }.vk("vkCreateShaderModule")?;
        let entries: Vec<vk::SpecializationMapEntry> = specialization
            .iter()
            .enumerate()
            .map(|(i, (id, _))| vk::SpecializationMapEntry {
                constant_id: *id,
                offset: (i * 4) as u32,
                size: 4,
            })
            .collect();
        let data: Vec<u8> = specialization
            .iter()
            .flat_map(|(_, v)| v.to_le_bytes())
            .collect();
        let spec = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(&data);
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec);
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout.layout)];
        // SAFETY: module and layout are alive; the create infos outlive the call.
        let result =
            unsafe { device.create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
        // SAFETY: the module is no longer needed once the pipeline exists (or failed).
        unsafe { device.destroy_shader_module(module, None) };
        let pipeline = result.map_err(|(_, e)| e).vk("vkCreateComputePipelines")?[0];
        Ok(Self {
            ctx: ctx.clone(),
            pipeline,
            name,
        })
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // SAFETY: no pending work uses the pipeline.
        unsafe { self.ctx.device.destroy_pipeline(self.pipeline, None) };
    }
}

impl ComputePipeline {
    /// Records binding the pipeline, the pass's descriptor set and `push`.
    fn cmd_bind(
        &self,
        cmd: vk::CommandBuffer,
        layout: &PipelineLayout,
        set: vk::DescriptorSet,
        push: &[u8],
    ) {
        let d = &self.ctx.device;
        // SAFETY: cmd is recording; pipeline, layout and set are alive until the submit completes.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::COMPUTE,
                layout.layout,
                0,
                &[set],
                &[],
            );
            // A pass without push constants (an empty struct) pushes nothing.
            if !push.is_empty() {
                d.cmd_push_constants(cmd, layout.layout, vk::ShaderStageFlags::COMPUTE, 0, push);
            }
        }
    }

    /// Records binding, push constants and a dispatch of `groups` workgroups.
    pub fn cmd_dispatch<P: bytemuck::NoUninit>(
        &self,
        cmd: vk::CommandBuffer,
        layout: &PipelineLayout,
        set: vk::DescriptorSet,
        push: &P,
        groups: [u32; 3],
    ) {
        self.cmd_bind(cmd, layout, set, bytemuck::bytes_of(push));
        // SAFETY: cmd is recording, with this pipeline and its resources bound just above.
        unsafe {
            self.ctx
                .device
                .cmd_dispatch(cmd, groups[0], groups[1], groups[2])
        };
    }

    /// Records binding, push constants and a dispatch whose workgroup counts the GPU wrote:
    /// a VkDispatchIndirectCommand at byte `offset` of `args` (INDIRECT_BUFFER usage).
    pub fn cmd_dispatch_indirect<P: bytemuck::NoUninit>(
        &self,
        cmd: vk::CommandBuffer,
        layout: &PipelineLayout,
        set: vk::DescriptorSet,
        push: &P,
        args: &Buffer,
        offset: u64,
    ) {
        self.cmd_bind(cmd, layout, set, bytemuck::bytes_of(push));
        // SAFETY: cmd is recording, with this pipeline bound; `args` is alive until the
        // submission completes.
        unsafe {
            self.ctx
                .device
                .cmd_dispatch_indirect(cmd, args.buffer, offset)
        };
    }
}
