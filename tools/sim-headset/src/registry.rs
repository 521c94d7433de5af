//! Every live object, behind one mutex. Handles are u64 ids from a single counter, so an id
//! names exactly one object of one kind and a stale or foreign id is simply not found
//! (XR_ERROR_HANDLE_INVALID) instead of being dereferenced.

use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::{LazyLock, Mutex, MutexGuard};

use openxr_sys as xr;
use openxr_sys::Handle as _;

use crate::config::Config;
use crate::report::ReportLog;
use crate::vulkan::{SwapchainImages, VkBootstrap, VkContext};

/// The extensions an instance enabled.
#[derive(Clone, Copy, Debug, Default)]
pub struct Extensions {
    pub vulkan_enable2: bool,
    pub vulkan_enable: bool,
    pub eye_gaze: bool,
    pub visibility_mask: bool,
}

pub enum Event {
    SessionStateChanged {
        session: u64,
        state: xr::SessionState,
        time: xr::Time,
    },
    InteractionProfileChanged {
        session: u64,
    },
}

pub struct Instance {
    pub config: Config,
    pub extensions: Extensions,
    /// Path strings; `XrPath` n is `paths[n - 1]` (0 is XR_NULL_PATH).
    pub paths: Vec<String>,
    pub events: VecDeque<Event>,
    /// xrGetVulkanGraphicsRequirements(2)KHR was called, as xrCreateSession requires.
    pub requirements_queried: bool,
    pub vk: VkBootstrap,
    /// Suggested bindings per interaction profile path: (action, binding path).
    pub suggested: HashMap<u64, Vec<(u64, u64)>>,
    pub log: ReportLog,
}

pub struct FrameLoop {
    /// xrWaitFrame calls so far; the current frame index is `waits - 1`.
    pub waits: u64,
    /// A wait has returned that no xrBeginFrame has consumed yet.
    pub wait_pending: bool,
    pub frame_begun: bool,
    /// Display slots and the eye tracker's samples.
    pub clock: crate::clock::Clock,
}

impl FrameLoop {
    pub fn new(config: &crate::config::Config) -> Self {
        Self {
            waits: 0,
            wait_pending: false,
            frame_begun: false,
            clock: crate::clock::Clock::new(config.realtime, config.compositor_ms),
        }
    }
}

pub struct Session {
    pub instance: u64,
    pub state: xr::SessionState,
    pub running: bool,
    pub exit_requested: bool,
    pub lost: bool,
    pub frames: FrameLoop,
    pub vk: VkContext,
    pub attached_sets: Vec<u64>,
    /// Action sets named in the last xrSyncActions, and whether that sync happened while
    /// FOCUSED (the spec makes every action inactive otherwise).
    pub synced_sets: HashSet<u64>,
    pub synced_focused: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpaceKind {
    Reference(xr::ReferenceSpaceType),
    Action { action: u64, subaction: u64 },
}

pub struct Space {
    pub session: u64,
    pub kind: SpaceKind,
    /// The space's origin relative to its reference space or its action's pose.
    pub offset: xr::Posef,
}

pub struct Swapchain {
    pub session: u64,
    pub format: i64,
    pub width: u32,
    pub height: u32,
    pub array_size: u32,
    pub images: SwapchainImages,
    /// Acquired images in acquisition order, with whether each has been waited on.
    pub acquired: VecDeque<(u32, bool)>,
    pub next_acquire: u32,
    pub last_released: Option<u32>,
}

pub struct ActionSet {
    pub instance: u64,
    pub name: String,
    pub attached: bool,
}

pub struct Action {
    pub instance: u64,
    pub set: u64,
    pub name: String,
    pub ty: xr::ActionType,
    pub subaction_paths: Vec<u64>,
}

#[derive(Default)]
pub struct Runtime {
    next_id: u64,
    pub instances: HashMap<u64, Instance>,
    pub sessions: HashMap<u64, Session>,
    pub spaces: HashMap<u64, Space>,
    pub swapchains: HashMap<u64, Swapchain>,
    pub action_sets: HashMap<u64, ActionSet>,
    pub actions: HashMap<u64, Action>,
}

static RUNTIME: LazyLock<Mutex<Runtime>> = LazyLock::new(|| Mutex::new(Runtime::default()));

/// Locks the runtime. A panic inside an entry point poisons the mutex; the state is still
/// consistent enough to keep answering (the entry point reported RUNTIME_FAILURE).
pub fn lock() -> MutexGuard<'static, Runtime> {
    RUNTIME.lock().unwrap_or_else(|e| e.into_inner())
}

pub fn record_error(function: &'static str, handle: u64, result: xr::Result) {
    let mut rt = lock();
    if let Some(instance) = rt.owner_instance(handle) {
        if let Some(i) = rt.instances.get_mut(&instance) {
            i.log.record_error(function, result);
        }
    }
}

fn found<T>(map: &HashMap<u64, T>, id: u64) -> Result<&T, xr::Result> {
    map.get(&id).ok_or(xr::Result::ERROR_HANDLE_INVALID)
}

fn found_mut<T>(map: &mut HashMap<u64, T>, id: u64) -> Result<&mut T, xr::Result> {
    map.get_mut(&id).ok_or(xr::Result::ERROR_HANDLE_INVALID)
}

impl Runtime {
    pub fn new_id(&mut self) -> u64 {
        self.next_id += 1;
        self.next_id
    }

    /// The instance that (transitively) owns the object `id`, whatever its kind.
    pub fn owner_instance(&self, id: u64) -> Option<u64> {
        if self.instances.contains_key(&id) {
            return Some(id);
        }
        let session_owner = |s: u64| self.sessions.get(&s).map(|s| s.instance);
        if let Some(s) = self.sessions.get(&id) {
            return Some(s.instance);
        }
        if let Some(s) = self.spaces.get(&id) {
            return session_owner(s.session);
        }
        if let Some(s) = self.swapchains.get(&id) {
            return session_owner(s.session);
        }
        if let Some(s) = self.action_sets.get(&id) {
            return Some(s.instance);
        }
        self.actions.get(&id).map(|a| a.instance)
    }

    pub fn instance(&self, h: xr::Instance) -> Result<&Instance, xr::Result> {
        found(&self.instances, h.into_raw())
    }
    pub fn instance_mut(&mut self, h: xr::Instance) -> Result<&mut Instance, xr::Result> {
        found_mut(&mut self.instances, h.into_raw())
    }
    pub fn session(&self, h: xr::Session) -> Result<&Session, xr::Result> {
        found(&self.sessions, h.into_raw())
    }
    pub fn session_mut(&mut self, h: xr::Session) -> Result<&mut Session, xr::Result> {
        found_mut(&mut self.sessions, h.into_raw())
    }
    pub fn space(&self, h: xr::Space) -> Result<&Space, xr::Result> {
        found(&self.spaces, h.into_raw())
    }
    pub fn swapchain(&self, h: xr::Swapchain) -> Result<&Swapchain, xr::Result> {
        found(&self.swapchains, h.into_raw())
    }
    pub fn swapchain_mut(&mut self, h: xr::Swapchain) -> Result<&mut Swapchain, xr::Result> {
        found_mut(&mut self.swapchains, h.into_raw())
    }
    pub fn action_set(&self, h: xr::ActionSet) -> Result<&ActionSet, xr::Result> {
        found(&self.action_sets, h.into_raw())
    }
    pub fn action(&self, h: xr::Action) -> Result<&Action, xr::Result> {
        found(&self.actions, h.into_raw())
    }

    /// Like [`Runtime::session`], but a lost session answers XR_ERROR_SESSION_LOST.
    pub fn live_session(&self, h: xr::Session) -> Result<&Session, xr::Result> {
        let s = self.session(h)?;
        if s.lost {
            return Err(xr::Result::ERROR_SESSION_LOST);
        }
        Ok(s)
    }

    /// The path string for `path` in `instance`.
    pub fn path_str(&self, instance: u64, path: xr::Path) -> Result<&str, xr::Result> {
        let i = found(&self.instances, instance)?;
        let n = path.into_raw();
        if n == 0 || n as usize > i.paths.len() {
            return Err(xr::Result::ERROR_PATH_INVALID);
        }
        Ok(&i.paths[n as usize - 1])
    }

    /// The `XrPath` for `s` in `instance`, interning it if needed (the string must already
    /// be well-formed).
    pub fn intern_path(&mut self, instance: u64, s: &str) -> Result<xr::Path, xr::Result> {
        let i = found_mut(&mut self.instances, instance)?;
        let n = match i.paths.iter().position(|p| p == s) {
            Some(k) => k + 1,
            None => {
                i.paths.push(s.to_string());
                i.paths.len()
            }
        };
        Ok(xr::Path::from_raw(n as u64))
    }
}
