//! Choosing the physical device: what each offers, which ones can run fovea, and which wins.

use super::error::GpuError;
use ash::vk;
use std::ffi::{c_char, CStr};

/// Facts about the chosen device, for reports.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub name: String,
    pub kind: String,
    pub driver: String,
    pub api_version: String,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f64,
    pub max_storage_buffer_range: u64,
    /// The most texels one texel-buffer view may span.
    pub max_texel_buffer_elements: u64,
    /// The byte offsets a texel-buffer view may start at are multiples of this.
    pub min_texel_buffer_offset_alignment: u64,
    /// Invocations per subgroup (SIMD width on lavapipe, warp or wave size on a GPU).
    pub subgroup_size: u32,
    /// The largest side of a 2D image (textures).
    pub max_image_dimension_2d: u32,
    /// Ray queries (VK_KHR_ray_query with VK_KHR_acceleration_structure): their limits when
    /// the context enabled them, None when the device lacks them or they were not wanted.
    pub ray_query: Option<RayQueryLimits>,
}

/// What VK_KHR_acceleration_structure allows on a device (src/gpu/accel/mod.rs checks a scene
/// against them before building).
#[derive(Clone, Copy, Debug)]
pub struct RayQueryLimits {
    pub max_instances: u64,
    pub max_primitives: u64,
    /// Alignment of each build's scratch memory.
    pub scratch_alignment: u64,
}

/// The device extensions ray queries need.
pub(super) const RAY_QUERY_EXTENSIONS: [&CStr; 3] = [
    ash::khr::acceleration_structure::NAME,
    ash::khr::ray_query::NAME,
    ash::khr::deferred_host_operations::NAME,
];

/// The chosen device, its compute queue family and what it offers.
pub(super) struct Picked {
    pub(super) physical_device: vk::PhysicalDevice,
    pub(super) family: u32,
    pub(super) info: DeviceInfo,
    /// VK_EXT_memory_budget is supported.
    pub(super) budget: bool,
    /// VK_AMD_buffer_marker is supported.
    pub(super) amd_marker: bool,
}

/// Device preference: a discrete GPU beats an integrated one, which beats a CPU driver.
fn device_rank(kind: vk::PhysicalDeviceType) -> u32 {
    match kind {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

fn cstr_to_string(bytes: &[c_char]) -> String {
    // SAFETY: Vulkan fills these fixed arrays with NUL-terminated strings.
    unsafe { CStr::from_ptr(bytes.as_ptr()) }
        .to_string_lossy()
        .into_owned()
}

/// The loader's driver-selecting environment variables that are set, for a no-device message.
pub(super) fn driver_env() -> String {
    let set: Vec<String> = [
        "VK_DRIVER_FILES",
        "VK_ICD_FILENAMES",
        "VK_ADD_DRIVER_FILES",
        "VK_LOADER_DRIVERS_SELECT",
        "VK_LOADER_DRIVERS_DISABLE",
    ]
    .iter()
    .filter_map(|var| std::env::var(var).ok().map(|v| format!("{var}={v}")))
    .collect();
    match set.is_empty() {
        true => String::new(),
        false => format!(
            " ({} is set and limits the drivers the loader tries: unset it to use the installed ones)",
            set.join(", ")
        ),
    }
}

/// What the caller asks of the device beyond fovea's own needs.
pub(super) struct DeviceWanted<'a> {
    /// `--device`: a part of the device's name.
    pub(super) name: Option<&'a str>,
    /// The device an OpenXR runtime requires (the one driving the headset).
    pub(super) physical_device: Option<vk::PhysicalDevice>,
    /// The queue must support graphics as well as compute.
    pub(super) graphics: bool,
    pub(super) extensions: &'a [&'static CStr],
}

/// The limits of a device that has the ray-query extensions, if it also has the features ray
/// queries use: acceleration structures, ray queries in shaders, and buffer device addresses
/// (build inputs and instances are given by address).
fn ray_query_limits(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Option<RayQueryLimits> {
    let mut accel = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
    let mut query = vk::PhysicalDeviceRayQueryFeaturesKHR::default();
    let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut features = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut accel)
        .push_next(&mut query)
        .push_next(&mut v12);
    // SAFETY: pd was enumerated from this instance, a Vulkan 1.2 one (features2 is core).
    unsafe { instance.get_physical_device_features2(pd, &mut features) };
    let usable = accel.acceleration_structure == vk::TRUE
        && query.ray_query == vk::TRUE
        && v12.buffer_device_address == vk::TRUE;
    let mut limits = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
    let mut props = vk::PhysicalDeviceProperties2::default().push_next(&mut limits);
    // SAFETY: as above; the device has VK_KHR_acceleration_structure, whose properties these are.
    unsafe { instance.get_physical_device_properties2(pd, &mut props) };
    usable.then_some(RayQueryLimits {
        max_instances: limits.max_instance_count,
        max_primitives: limits.max_primitive_count,
        scratch_alignment: limits.min_acceleration_structure_scratch_offset_alignment as u64,
    })
}

/// The best device that can run fovea and is what `wanted` asks for; none is an error that
/// lists every device and why it cannot.
pub(super) fn pick_device(
    instance: &ash::Instance,
    wanted: &DeviceWanted,
) -> Result<Picked, GpuError> {
    let mut candidates = Vec::new();
    let mut unusable = Vec::new();
    for pd in physical_devices(instance)? {
        if wanted
            .physical_device
            .is_some_and(|required| required != pd)
        {
            continue;
        }
        match examine(instance, pd, wanted) {
            Ok(candidate) => candidates.push(candidate),
            Err(why) => unusable.push(why),
        }
    }
    if candidates.is_empty() {
        let detail = match unusable.is_empty() {
            true => format!("the Vulkan loader lists no device{}", driver_env()),
            false => format!("none of the devices can run fovea: {}", unusable.join(", ")),
        };
        return Err(GpuError::NoDevice { detail });
    }
    if let Some(name) = wanted.name {
        keep_named(&mut candidates, name)?;
    }
    candidates.sort_by_key(|c| c.0);
    Ok(candidates.swap_remove(0).1)
}

fn physical_devices(instance: &ash::Instance) -> Result<Vec<vk::PhysicalDevice>, GpuError> {
    // SAFETY: enumeration on a valid instance.
    match unsafe { instance.enumerate_physical_devices() } {
        Ok(devices) => Ok(devices),
        Err(result @ vk::Result::ERROR_INITIALIZATION_FAILED) => Err(GpuError::NoDevice {
            detail: format!(
                "the Vulkan loader found drivers but none found a device (vkEnumeratePhysicalDevices: {result}){}",
                driver_env()
            ),
        }),
        Err(result) => Err(GpuError::Vulkan {
            call: "vkEnumeratePhysicalDevices",
            result,
        }),
    }
}

/// `pd` as a candidate, with its rank ([`device_rank`]), or why it cannot run fovea: Vulkan
/// 1.2, a queue family with compute (and graphics, if wanted) and timestamps, subgroup votes
/// in compute shaders, synchronization2 and the wanted extensions.
fn examine(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    wanted: &DeviceWanted,
) -> Result<(u32, Picked), String> {
    // SAFETY: pd was enumerated from this instance.
    let (props, families) = unsafe {
        (
            instance.get_physical_device_properties(pd),
            instance.get_physical_device_queue_family_properties(pd),
        )
    };
    let name = cstr_to_string(&props.device_name);
    if props.api_version < vk::API_VERSION_1_2 {
        return Err(format!(
            "{name} (Vulkan 1.{}, fovea needs 1.2)",
            vk::api_version_minor(props.api_version)
        ));
    }
    let mut flags = vk::QueueFlags::COMPUTE;
    if wanted.graphics {
        flags |= vk::QueueFlags::GRAPHICS;
    }
    let Some(family) = families
        .iter()
        .position(|f| f.queue_flags.contains(flags) && f.timestamp_valid_bits > 0)
    else {
        return Err(format!("{name} (no {flags:?} queue with timestamps)"));
    };
    let (driver, subgroups) = driver_and_subgroups(instance, pd);
    // resolve.comp branches on subgroup votes (GL_KHR_shader_subgroup_vote).
    if !subgroups
        .supported_stages
        .contains(vk::ShaderStageFlags::COMPUTE)
        || !subgroups
            .supported_operations
            .contains(vk::SubgroupFeatureFlags::VOTE)
    {
        return Err(format!("{name} (no subgroup votes in compute shaders)"));
    }
    // Textures are one partially bound array of samplers indexed per hit (textures.glsl);
    // the lattice's texel views are arrays of one per eye, indexed by the eye.
    if !descriptor_indexing(instance, pd) {
        return Err(format!(
            "{name} (no non-uniform indexing of partially bound sampled-image arrays, or no \
             dynamic indexing of uniform texel buffer arrays)"
        ));
    }
    let extensions = Extensions::of(instance, pd);
    let required = [ash::khr::synchronization2::NAME];
    if let Some(missing) = required
        .iter()
        .chain(wanted.extensions)
        .find(|e| !extensions.has(e))
    {
        return Err(format!("{name} (no {})", missing.to_string_lossy()));
    }
    let ray_query = match RAY_QUERY_EXTENSIONS.iter().all(|e| extensions.has(e)) {
        true => ray_query_limits(instance, pd),
        false => None,
    };
    let picked = Picked {
        physical_device: pd,
        family: family as u32,
        info: device_info(name, &props, &driver, &subgroups, ray_query),
        budget: extensions.has(ash::ext::memory_budget::NAME),
        amd_marker: extensions.has(ash::amd::buffer_marker::NAME),
    };
    Ok((device_rank(props.device_type), picked))
}

/// Whether the device indexes arrays of sampled images non-uniformly and binds them partially
/// (Vulkan 1.2's descriptor-indexing features that the texture array needs), and indexes
/// arrays of uniform texel buffers by a dynamically uniform index (the lattice's per-eye
/// views, indexed by the dispatch's eye).
fn descriptor_indexing(instance: &ash::Instance, pd: vk::PhysicalDevice) -> bool {
    let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut features = vk::PhysicalDeviceFeatures2::default().push_next(&mut v12);
    // SAFETY: pd was enumerated from this instance, a Vulkan 1.2 one (features2 is core).
    unsafe { instance.get_physical_device_features2(pd, &mut features) };
    v12.shader_sampled_image_array_non_uniform_indexing == vk::TRUE
        && v12.descriptor_binding_partially_bound == vk::TRUE
        && v12.shader_uniform_texel_buffer_array_dynamic_indexing == vk::TRUE
}

/// The driver's name and version, and the subgroup properties.
fn driver_and_subgroups(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
) -> (
    vk::PhysicalDeviceDriverProperties<'static>,
    vk::PhysicalDeviceSubgroupProperties<'static>,
) {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut subgroups = vk::PhysicalDeviceSubgroupProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default()
        .push_next(&mut driver)
        .push_next(&mut subgroups);
    // SAFETY: Vulkan 1.2 device, properties2 is core.
    unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
    (driver, subgroups)
}

/// The extensions a device offers.
struct Extensions(Vec<vk::ExtensionProperties>);

impl Extensions {
    fn of(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Self {
        // SAFETY: pd was enumerated from this instance.
        Self(unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default())
    }

    fn has(&self, wanted: &CStr) -> bool {
        self.0
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(wanted))
    }
}

fn device_info(
    name: String,
    props: &vk::PhysicalDeviceProperties,
    driver: &vk::PhysicalDeviceDriverProperties,
    subgroups: &vk::PhysicalDeviceSubgroupProperties,
    ray_query: Option<RayQueryLimits>,
) -> DeviceInfo {
    DeviceInfo {
        name,
        kind: format!("{:?}", props.device_type),
        driver: format!(
            "{} {}",
            cstr_to_string(&driver.driver_name),
            cstr_to_string(&driver.driver_info)
        ),
        api_version: format!(
            "{}.{}.{}",
            vk::api_version_major(props.api_version),
            vk::api_version_minor(props.api_version),
            vk::api_version_patch(props.api_version)
        ),
        timestamp_period_ns: props.limits.timestamp_period as f64,
        max_storage_buffer_range: props.limits.max_storage_buffer_range as u64,
        max_texel_buffer_elements: props.limits.max_texel_buffer_elements as u64,
        min_texel_buffer_offset_alignment: props.limits.min_texel_buffer_offset_alignment,
        subgroup_size: subgroups.subgroup_size,
        max_image_dimension_2d: props.limits.max_image_dimension2_d,
        ray_query,
    }
}

/// Keeps the candidates whose name contains `wanted` (`--device`, any case); none is an
/// error that lists the names there are.
fn keep_named(candidates: &mut Vec<(u32, Picked)>, wanted: &str) -> Result<(), GpuError> {
    let needle = wanted.to_lowercase();
    let available = candidates
        .iter()
        .map(|c| c.1.info.name.clone())
        .collect::<Vec<_>>()
        .join(", ");
    candidates.retain(|c| c.1.info.name.to_lowercase().contains(&needle));
    match candidates.is_empty() {
        true => Err(GpuError::DeviceNotFound {
            wanted: wanted.to_string(),
            available,
        }),
        false => Ok(()),
    }
}
