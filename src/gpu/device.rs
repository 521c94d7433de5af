//! Creating the logical device on the picked physical device: one queue, the extensions and
//! features fovea uses (synchronization2 always; ray queries, the memory budget and AMD's
//! buffer markers where there), and those the caller needs.

use super::context_needs::ContextNeeds;
use super::device_pick::{DeviceInfo, Picked, RAY_QUERY_EXTENSIONS};
use super::error::GpuError;
use super::options::{GpuOptions, RayQueries};
use super::owned::{Device, Instance};
use ash::vk;
use std::ffi::c_char;

/// Whether the device gets ray queries, and whether frames trace with them by default.
#[derive(Clone, Copy)]
pub(super) struct RayQueryUse {
    pub(super) enabled: bool,
    pub(super) preferred: bool,
}

impl RayQueryUse {
    /// What `options` ask for on the device `info` describes; clears `info.ray_query` when
    /// they are off, and refuses a device without them when they are required.
    pub(super) fn decide(options: &GpuOptions, info: &mut DeviceInfo) -> Result<Self, GpuError> {
        match options.ray_queries {
            RayQueries::Off => info.ray_query = None,
            RayQueries::Required if info.ray_query.is_none() => {
                return Err(GpuError::NoRayQueries {
                    device: info.name.clone(),
                })
            }
            _ => {}
        }
        let enabled = info.ray_query.is_some();
        // On a CPU driver ray queries run the driver's traversal on the same cores as ours,
        // and lavapipe's measured 2.3-5.9x slower than fovea's (README, "Ray queries"): there
        // `auto` keeps the software traversal (both stay available, e.g. to render --bench).
        let preferred =
            enabled && (options.ray_queries == RayQueries::Required || info.kind != "CPU");
        Ok(Self { enabled, preferred })
    }
}

/// Creates the device with one queue of the picked family, through the caller's creator
/// where it has one (an OpenXR runtime).
pub(super) fn create_device(
    instance: &Instance,
    picked: &Picked,
    ray_query: bool,
    needs: &ContextNeeds,
) -> Result<Device, GpuError> {
    let priorities = [1.0f32];
    let queue_info = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(picked.family)
        .queue_priorities(&priorities)];
    let extensions = device_extensions(picked, ray_query, needs);
    let mut features12 = vk::PhysicalDeviceVulkan12Features::default()
        .host_query_reset(true)
        .buffer_device_address(ray_query)
        .shader_sampled_image_array_non_uniform_indexing(true)
        .shader_uniform_texel_buffer_array_dynamic_indexing(true)
        .descriptor_binding_partially_bound(true);
    let mut sync2 = vk::PhysicalDeviceSynchronization2Features::default().synchronization2(true);
    let mut accel_features =
        vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
    let mut query_features = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
    let mut info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_info)
        .enabled_extension_names(&extensions)
        .push_next(&mut features12)
        .push_next(&mut sync2);
    if ray_query {
        info = info
            .push_next(&mut accel_features)
            .push_next(&mut query_features);
    }
    let physical_device = picked.physical_device;
    let device =
        match needs.creator {
            Some(creator) => creator
                .create_device(instance.entry(), physical_device, &info)
                .map(|handle| {
                    // SAFETY: the creator returned a live device of this instance.
                    unsafe { ash::Device::load(instance.fp_v1_0(), handle) }
                })?,
            // SAFETY: physical_device came from this instance; the create info outlives the call.
            None => unsafe { instance.create_device(physical_device, &info, None) }.map_err(
                |result| GpuError::Vulkan {
                    call: "vkCreateDevice",
                    result,
                },
            )?,
        };
    Ok(Device::new(device))
}

/// The device extensions to enable: the memory budget and AMD's buffer markers where the
/// device has them, synchronization2, ray queries if enabled, and the caller's.
fn device_extensions(picked: &Picked, ray_query: bool, needs: &ContextNeeds) -> Vec<*const c_char> {
    let mut extensions = Vec::new();
    if picked.budget {
        extensions.push(ash::ext::memory_budget::NAME.as_ptr());
    }
    if picked.amd_marker {
        extensions.push(ash::amd::buffer_marker::NAME.as_ptr());
    }
    extensions.push(ash::khr::synchronization2::NAME.as_ptr());
    if ray_query {
        extensions.extend(RAY_QUERY_EXTENSIONS.iter().map(|e| e.as_ptr()));
    }
    extensions.extend(needs.device_extensions.iter().map(|e| e.as_ptr()));
    extensions
}
