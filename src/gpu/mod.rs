//! The only module that calls Vulkan (ash). Everything above it speaks in scenes, frames and
//! passes; everything here owns raw handles and destroys them on drop.

mod accel;
mod commands;
mod context;
mod context_needs;
mod crash_markers;
mod descriptors;
mod device;
mod device_pick;
mod error;
mod instance;
mod memory;
mod memory_budget;
mod options;
mod owned;
mod pipeline;
mod present;
pub mod shaders;
mod swapchain;
mod sync;
mod texel_view;
mod texture;
mod timestamps;
mod validation;
pub use validation::ValidationLog;

pub use accel::AccelStructures;
pub use ash::vk;
pub use commands::Commands;
pub use context::GpuContext;
pub use context_needs::{ContextNeeds, VulkanCreator};
pub use descriptors::{Bound, DescriptorArena};
pub use device_pick::{DeviceInfo, RayQueryLimits};
pub use error::{GpuError, MemoryShortfall, ResourceLimit};
pub use memory::{Buffer, StorageImage};
pub use memory_budget::PlannedAllocation;
pub use options::{
    GpuOptions, RayQueries, ValidationChecks, INJECT_DEVICE_LOST_VAR, MEMORY_LIMIT_VAR,
};
pub use pipeline::{ComputePipeline, PipelineLayout};
pub use present::{check_copies, ExternalImage, SourceRect};
pub use swapchain::{
    surface_instance_extensions, swapchain_device_extensions, PresentPreference, Presented,
    Swapchain,
};
pub use sync::Scope;
pub use texel_view::{EyeTexels, TexelView};
pub use texture::{mip_chain_bytes, MipLevel, SamplerDesc, TextureSet, TextureUpload};
pub use timestamps::{PassTime, TimestampPool};
