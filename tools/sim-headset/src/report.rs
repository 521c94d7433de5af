//! The JSON report written at `xrDestroyInstance` (`SIM_HEADSET_REPORT`): what the app did,
//! what it got wrong, and what it left behind.

use std::path::Path;

use openxr_sys as xr;
use serde::Serialize;

/// Errors kept in full; beyond this only `error_count` grows, so a runaway loop of failing
/// calls cannot make the report unbounded.
const MAX_LISTED_ERRORS: usize = 1000;

#[derive(Clone, Debug, Default, Serialize, PartialEq, Eq)]
pub struct HandleCounts {
    pub sessions: u64,
    pub swapchains: u64,
    pub spaces: u64,
    pub actions: u64,
    pub action_sets: u64,
}

impl HandleCounts {
    pub fn total(&self) -> u64 {
        self.sessions + self.swapchains + self.spaces + self.actions + self.action_sets
    }
}

#[derive(Clone, Debug, Default, Serialize, PartialEq, Eq)]
pub struct VulkanCounts {
    pub images: u64,
    pub memory_allocations: u64,
}

#[derive(Clone, Debug, Serialize, PartialEq, Eq)]
pub struct ErrorEntry {
    pub function: String,
    pub result: String,
}

/// Accumulated over an instance's life.
#[derive(Default)]
pub struct ReportLog {
    pub frames_waited: u64,
    pub frames_submitted: u64,
    pub frames_with_layers: u64,
    pub images_saved: u64,
    pub sessions_lost: u64,
    pub session_states: Vec<String>,
    pub errors: Vec<ErrorEntry>,
    pub error_count: u64,
    /// Handles the app never destroyed that went away with their parent session.
    pub destroyed_with_parent: HandleCounts,
}

impl ReportLog {
    pub fn record_error(&mut self, function: &str, result: xr::Result) {
        self.error_count += 1;
        if self.errors.len() < MAX_LISTED_ERRORS {
            self.errors.push(ErrorEntry {
                function: function.to_string(),
                result: crate::instance::result_name(result),
            });
        }
    }

    pub fn record_state(&mut self, state: xr::SessionState) {
        let name = format!("{state:?}");
        self.session_states.push(name);
    }
}

#[derive(Debug, Serialize)]
pub struct Report {
    pub runtime: &'static str,
    pub frames_waited: u64,
    pub frames_submitted: u64,
    /// Submitted frames with at least one composition layer (the others were empty).
    pub frames_with_layers: u64,
    pub images_saved: u64,
    /// Sessions lost by the script (SIM_HEADSET_LOSS_AT_FRAME).
    pub sessions_lost: u64,
    /// Every state any session of the instance entered, in order (e.g. IDLE, READY, ...).
    pub session_states: Vec<String>,
    /// Handles the app had not destroyed when it destroyed the instance (leaks).
    pub alive_at_instance_destroy: HandleCounts,
    /// Swapchain images and their memory allocations the runtime still held then.
    pub vulkan_alive_at_instance_destroy: VulkanCounts,
    /// Handles the app never destroyed that went away with their session earlier.
    pub destroyed_with_parent: HandleCounts,
    pub error_count: u64,
    /// Errors returned to the app, in order (at most 1000 listed).
    pub errors: Vec<ErrorEntry>,
    /// No leaks of any kind (the three counters above are all zero).
    pub clean_teardown: bool,
}

impl Report {
    pub fn new(log: ReportLog, alive: HandleCounts, vulkan: VulkanCounts) -> Self {
        let clean_teardown = alive.total() == 0
            && log.destroyed_with_parent.total() == 0
            && vulkan == VulkanCounts::default();
        Self {
            runtime: crate::RUNTIME_NAME,
            frames_waited: log.frames_waited,
            frames_submitted: log.frames_submitted,
            frames_with_layers: log.frames_with_layers,
            images_saved: log.images_saved,
            sessions_lost: log.sessions_lost,
            session_states: log.session_states,
            alive_at_instance_destroy: alive,
            vulkan_alive_at_instance_destroy: vulkan,
            destroyed_with_parent: log.destroyed_with_parent,
            error_count: log.error_count,
            errors: log.errors,
            clean_teardown,
        }
    }

    pub fn write(&self, path: &Path) {
        let text = serde_json::to_string_pretty(self).expect("report serialises");
        if let Err(e) = std::fs::write(path, text) {
            eprintln!(
                "sim-headset: cannot write the report to {}: {e}",
                path.display()
            );
        }
    }
}
