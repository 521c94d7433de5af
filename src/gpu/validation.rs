//! The validation layer's debug messenger: every error (and warning) it reports is kept, so a
//! test can fail on the first validation message its own work caused.

use ash::vk;
use std::ffi::CStr;
use std::sync::Mutex;

/// Messages the validation layer reported, oldest first.
#[derive(Default)]
pub struct ValidationLog {
    messages: Mutex<Vec<String>>,
}

impl ValidationLog {
    /// Takes (and clears) every message reported so far.
    pub fn take(&self) -> Vec<String> {
        std::mem::take(&mut *self.messages.lock().unwrap_or_else(|e| e.into_inner()))
    }
    fn push(&self, message: String) {
        self.messages
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(message);
    }
}

/// Called by the validation layer on its own thread of control; `user_data` is the
/// `ValidationLog` the messenger (owned.rs) holds an `Arc` of until it is destroyed.
pub(crate) unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut std::ffi::c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes a valid callback-data pointer for the duration of the call,
    // and user_data is the ValidationLog that outlives the messenger.
    let (message, log) = unsafe {
        let message = if data.is_null() || (*data).p_message.is_null() {
            String::from("(no message)")
        } else {
            CStr::from_ptr((*data).p_message)
                .to_string_lossy()
                .into_owned()
        };
        (message, &*(user_data as *const ValidationLog))
    };
    let text = format!("[{severity:?} {kind:?}] {message}");
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        tracing::error!("validation: {text}");
    } else {
        tracing::warn!("validation: {text}");
    }
    log.push(text);
    vk::FALSE
}
