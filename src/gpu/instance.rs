//! Creating the Vulkan instance: the loader, the validation layer and its optional checks
//! where asked for, the extensions the caller needs, and the debug messenger.

use super::context_needs::ContextNeeds;
use super::device_pick::driver_env;
use super::error::{GpuError, VkContext};
use super::options::GpuOptions;
use super::owned::{Instance, Messenger};
use super::validation::ValidationLog;
use ash::vk;
use std::ffi::{c_char, CStr};
use std::sync::Arc;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// The instance, and with validation its messenger, which reports into `log`.
pub(super) fn create_instance(
    options: &GpuOptions,
    needs: &ContextNeeds,
    log: &Arc<ValidationLog>,
) -> Result<(Instance, Option<Messenger>), GpuError> {
    // SAFETY: loading the system Vulkan loader; its symbols are used only through ash.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| GpuError::NoLoader(e.to_string()))?;
    let layers = Layers::wanted(&entry, options, needs)?;
    let app = vk::ApplicationInfo::default()
        .application_name(c"fovea")
        .engine_name(c"fovea")
        .api_version(vk::API_VERSION_1_2);
    let mut features =
        vk::ValidationFeaturesEXT::default().enabled_validation_features(&layers.checks);
    let mut create = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers.layers)
        .enabled_extension_names(&layers.extensions);
    if !layers.checks.is_empty() {
        create = create.push_next(&mut features);
    }
    let instance = Instance::new(entry.clone(), instantiate(&entry, &create, needs)?);
    let messenger = match options.validation {
        true => Some(Messenger::new(&instance, log.clone())?),
        false => None,
    };
    Ok((instance, messenger))
}

/// The layers, instance extensions and validation checks to create the instance with.
struct Layers {
    layers: Vec<*const c_char>,
    extensions: Vec<*const c_char>,
    checks: Vec<vk::ValidationFeatureEnableEXT>,
}

impl Layers {
    /// What `options` and `needs` ask for, refused with a reason where the loader lacks it.
    fn wanted(
        entry: &ash::Entry,
        options: &GpuOptions,
        needs: &ContextNeeds,
    ) -> Result<Self, GpuError> {
        let mut this = Self {
            layers: Vec::new(),
            extensions: Vec::new(),
            checks: validation_features(options),
        };
        if options.validation {
            this.add_validation_layer(entry)?;
        }
        (this.extensions).extend(needs.instance_extensions.iter().map(|e| e.as_ptr()));
        if !this.checks.is_empty() {
            this.add_validation_features(entry)?;
        }
        Ok(this)
    }

    fn add_validation_layer(&mut self, entry: &ash::Entry) -> Result<(), GpuError> {
        // SAFETY: plain enumeration call on a loaded entry.
        let available = unsafe { entry.enumerate_instance_layer_properties() }
            .vk("vkEnumerateInstanceLayerProperties")?;
        if !available
            .iter()
            .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER))
        {
            return Err(GpuError::NoValidationLayer);
        }
        self.layers.push(VALIDATION_LAYER.as_ptr());
        self.extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        Ok(())
    }

    /// VK_EXT_validation_features, which switches the layer's optional checks on.
    fn add_validation_features(&mut self, entry: &ash::Entry) -> Result<(), GpuError> {
        // SAFETY: plain enumeration call on a loaded entry, for a layer that is present.
        let offered =
            unsafe { entry.enumerate_instance_extension_properties(Some(VALIDATION_LAYER)) }
                .vk("vkEnumerateInstanceExtensionProperties")?;
        if !offered
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::validation_features::NAME))
        {
            return Err(GpuError::NoValidationFeatures);
        }
        self.extensions
            .push(ash::ext::validation_features::NAME.as_ptr());
        Ok(())
    }
}

/// Creates the instance, through the caller's creator where it has one (an OpenXR runtime).
fn instantiate(
    entry: &ash::Entry,
    create: &vk::InstanceCreateInfo,
    needs: &ContextNeeds,
) -> Result<ash::Instance, GpuError> {
    let created = match needs.creator {
        Some(creator) => creator.create_instance(entry, create).map(|handle| {
            // SAFETY: the creator returned a live instance made from this entry's loader.
            unsafe { ash::Instance::load(entry.static_fn(), handle) }
        }),
        // SAFETY: the create info and the arrays it points to live until the call returns.
        None => unsafe { entry.create_instance(create, None) }.map_err(|result| GpuError::Vulkan {
            call: "vkCreateInstance",
            result,
        }),
    };
    match created {
        // What the loader returns when it finds no driver at all.
        Err(GpuError::Vulkan {
            result: result @ vk::Result::ERROR_INCOMPATIBLE_DRIVER,
            ..
        }) => Err(GpuError::NoDevice {
            detail: format!(
                "the Vulkan loader found no driver (vkCreateInstance: {result}){}",
                driver_env()
            ),
        }),
        other => other,
    }
}

/// The validation layer's optional checks that `options` asks for (none without validation).
fn validation_features(options: &GpuOptions) -> Vec<vk::ValidationFeatureEnableEXT> {
    let checks = &options.checks;
    let mut enabled = Vec::new();
    if options.validation && checks.synchronization {
        enabled.push(vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION);
    }
    if options.validation && checks.gpu_assisted {
        enabled.push(vk::ValidationFeatureEnableEXT::GPU_ASSISTED);
    }
    enabled
}
