//! What fovea may allocate: the device's heaps and limits, the memory fovea holds now, and
//! the check of a whole plan of allocations before any of it is made.

use super::device_pick::Picked;
use super::error::{exact_bytes, human_bytes, GpuError, MemoryShortfall, ResourceLimit};
use super::options::MEMORY_LIMIT_VAR;
use ash::vk;
use std::sync::atomic::{AtomicU64, Ordering};

/// One allocation of a plan checked by
/// [`GpuContext::check_memory`](super::GpuContext::check_memory) before any is made.
#[derive(Clone, Debug)]
pub struct PlannedAllocation {
    /// As the message should name it, e.g. "layer images".
    pub name: String,
    pub bytes: u64,
    /// In host-visible memory (staging, per-frame uploads, read-backs), not device-local.
    pub host_visible: bool,
    /// Bound as one storage buffer, so also limited by maxStorageBufferRange.
    pub storage_buffer: bool,
    /// Also read through texel views of 16-byte texels, the largest this many bytes, so also
    /// limited by maxTexelBufferElements.
    pub texel_view: Option<u64>,
}

impl PlannedAllocation {
    /// A device-local storage buffer.
    pub fn storage(name: &str, bytes: u64) -> Self {
        Self {
            name: name.into(),
            bytes,
            host_visible: false,
            storage_buffer: true,
            texel_view: None,
        }
    }

    /// A device-local storage buffer that passes also read through a texel view
    /// (`TexelView::of_frame`).
    pub fn storage_with_texels(name: &str, bytes: u64) -> Self {
        Self::storage_with_views(name, bytes, bytes)
    }

    /// A device-local storage buffer that passes also read through texel views of parts of
    /// it, the largest `view_bytes` long (`EyeTexels`: one view per eye).
    pub fn storage_with_views(name: &str, bytes: u64, view_bytes: u64) -> Self {
        Self {
            texel_view: Some(view_bytes),
            ..Self::storage(name, bytes)
        }
    }

    /// A device-local image.
    pub fn image(name: &str, bytes: u64) -> Self {
        Self {
            name: name.into(),
            bytes,
            host_visible: false,
            storage_buffer: false,
            texel_view: None,
        }
    }

    /// A host-visible buffer (`storage_buffer`: bound to a shader, not only copied).
    pub fn host(name: &str, bytes: u64, storage_buffer: bool) -> Self {
        Self {
            name: name.into(),
            bytes,
            host_visible: true,
            storage_buffer,
            texel_view: None,
        }
    }
}

/// Whether a plan fits, and what each heap it uses (and the memory limit) offers.
struct Room {
    fits: bool,
    offered: Vec<String>,
}

/// Memory facts of the device, fixed at creation.
pub(super) struct MemoryFacts {
    pub(super) physical_device: vk::PhysicalDevice,
    /// Size of every heap.
    pub(super) heaps: Vec<u64>,
    /// The largest heap with a device-local memory type (where images and static buffers go).
    pub(super) device_heap: usize,
    /// The largest heap with a host-visible memory type (staging, read-backs). The same as
    /// `device_heap` on unified-memory devices (integrated GPUs, lavapipe).
    pub(super) host_heap: usize,
    /// VK_EXT_memory_budget is enabled: the current budget can be asked for.
    pub(super) budget: bool,
    pub(super) max_memory_allocation_size: u64,
    /// The largest storage buffer a shader can bind.
    pub(super) max_storage_buffer_range: u64,
    /// The largest texel view, in bytes (maxTexelBufferElements 16-byte texels).
    pub(super) max_texel_view_bytes: u64,
    pub(super) limit: Option<u64>,
}

/// The heaps, where allocations go, and the per-allocation limits of the picked device.
pub(super) fn memory_facts(
    instance: &ash::Instance,
    picked: &Picked,
    limit: Option<u64>,
) -> MemoryFacts {
    let physical_device = picked.physical_device;
    // SAFETY: physical_device was enumerated from this instance.
    let props = unsafe { instance.get_physical_device_memory_properties(physical_device) };
    let heaps: Vec<u64> = props
        .memory_heaps_as_slice()
        .iter()
        .map(|h| h.size)
        .collect();
    let largest_with = |flag: vk::MemoryPropertyFlags| {
        props
            .memory_types_as_slice()
            .iter()
            .filter(|t| t.property_flags.contains(flag))
            .map(|t| t.heap_index as usize)
            .max_by_key(|&h| heaps.get(h).copied().unwrap_or(0))
            .unwrap_or(0)
    };
    let mut maintenance3 = vk::PhysicalDeviceMaintenance3Properties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut maintenance3);
    // SAFETY: a Vulkan 1.2 device: properties2 and maintenance3 are core.
    unsafe { instance.get_physical_device_properties2(physical_device, &mut props2) };
    MemoryFacts {
        physical_device,
        device_heap: largest_with(vk::MemoryPropertyFlags::DEVICE_LOCAL),
        host_heap: largest_with(vk::MemoryPropertyFlags::HOST_VISIBLE),
        heaps,
        budget: picked.budget,
        max_memory_allocation_size: maintenance3.max_memory_allocation_size,
        max_storage_buffer_range: picked.info.max_storage_buffer_range,
        max_texel_view_bytes: picked.info.max_texel_buffer_elements.saturating_mul(16),
        limit,
    }
}

/// The memory fovea holds, counted as it allocates and frees, beside what the device offers:
/// the context's memory checks and accounting, which it forwards here.
pub(super) struct MemoryBudget {
    facts: MemoryFacts,
    /// Bytes fovea holds now: [device-local, host-visible].
    allocated: [AtomicU64; 2],
    /// The most of `allocated` held at once.
    peak_allocated: AtomicU64,
}

impl MemoryBudget {
    /// Nothing held yet on the device `facts` describe.
    pub(super) fn new(facts: MemoryFacts) -> Self {
        Self {
            facts,
            allocated: [AtomicU64::new(0), AtomicU64::new(0)],
            peak_allocated: AtomicU64::new(0),
        }
    }

    /// The GPU memory cap from
    /// [`GpuOptions::memory_limit`](super::GpuOptions::memory_limit), if any.
    pub(super) fn limit(&self) -> Option<u64> {
        self.facts.limit
    }

    /// Bytes of GPU memory fovea's buffers and images hold now.
    pub(super) fn in_use(&self) -> u64 {
        self.allocated
            .iter()
            .map(|a| a.load(Ordering::Relaxed))
            .sum()
    }

    /// The most bytes fovea's buffers and images held at once since the context was made.
    pub(super) fn peak(&self) -> u64 {
        self.peak_allocated.load(Ordering::Relaxed)
    }

    fn heap_of(&self, host_visible: bool) -> usize {
        match host_visible {
            true => self.facts.host_heap,
            false => self.facts.device_heap,
        }
    }

    /// (budget, usage) of every heap now, with VK_EXT_memory_budget (`instance`: the one the
    /// device was picked from).
    fn budget_now(&self, instance: &ash::Instance) -> Option<Vec<(u64, u64)>> {
        if !self.facts.budget {
            return None;
        }
        let mut budget = vk::PhysicalDeviceMemoryBudgetPropertiesEXT::default();
        let mut props = vk::PhysicalDeviceMemoryProperties2::default().push_next(&mut budget);
        // SAFETY: VK_EXT_memory_budget is enabled on the device; the chain lives for the call.
        unsafe {
            instance.get_physical_device_memory_properties2(self.facts.physical_device, &mut props)
        };
        Some(
            (0..self.facts.heaps.len())
                .map(|h| (budget.heap_budget[h], budget.heap_usage[h]))
                .collect(),
        )
    }

    /// Checks, before anything is allocated, that `plan` fits: the total against the memory
    /// the device offers (heap size, and the budget with VK_EXT_memory_budget) beside what
    /// fovea already holds and against
    /// [`GpuOptions::memory_limit`](super::GpuOptions::memory_limit); each item against
    /// maxMemoryAllocationSize, and storage buffers against maxStorageBufferRange. `what`
    /// names the plan ("scene 'bunny'", "frame targets of ..."); `advice` says what to change.
    pub(super) fn check(
        &self,
        instance: &ash::Instance,
        what: &str,
        plan: &[PlannedAllocation],
        advice: &str,
    ) -> Result<(), GpuError> {
        let room = self.room_for(instance, plan);
        if !room.fits {
            return Err(self.shortfall(what, plan, &room.offered, advice));
        }
        for p in plan {
            self.check_item(what, p, advice)?;
        }
        Ok(())
    }

    /// Whether `plan` fits beside what fovea holds: on every heap it uses (its size, and the
    /// budget with VK_EXT_memory_budget) and under the memory limit; and what each offers,
    /// for the message when it does not.
    fn room_for(&self, instance: &ash::Instance, plan: &[PlannedAllocation]) -> Room {
        let heaps = &self.facts.heaps;
        let mut needed_on = vec![0u64; heaps.len()];
        for p in plan {
            needed_on[self.heap_of(p.host_visible)] += p.bytes;
        }
        let mut held_on = vec![0u64; heaps.len()];
        for (host, held) in [(false, &self.allocated[0]), (true, &self.allocated[1])] {
            held_on[self.heap_of(host)] += held.load(Ordering::Relaxed);
        }
        let budget = self.budget_now(instance);
        let mut room = Room {
            fits: true,
            offered: Vec::new(),
        };
        for (h, &size) in heaps.iter().enumerate() {
            if needed_on[h] == 0 {
                continue;
            }
            let (free, text) = self.heap_room(h, size, held_on[h], budget.as_ref().map(|b| b[h]));
            room.fits &= needed_on[h] <= free;
            room.offered.push(text);
        }
        if let Some(limit) = self.facts.limit {
            let needed: u64 = plan.iter().map(|p| p.bytes).sum();
            room.fits &= self.in_use().saturating_add(needed) <= limit;
            room.offered.push(format!(
                "{MEMORY_LIMIT_VAR} caps fovea at {}",
                exact_bytes(limit)
            ));
        }
        room
    }

    /// The bytes free on heap `h` of `size` bytes, `held` of them fovea's, within the driver's
    /// (budget, usage) where known; and the heap described for a message.
    fn heap_room(
        &self,
        h: usize,
        size: u64,
        held: u64,
        budget: Option<(u64, u64)>,
    ) -> (u64, String) {
        let kind = match (h == self.facts.device_heap, h == self.facts.host_heap) {
            (true, true) => "device-local, also host-visible",
            (true, false) => "device-local",
            _ => "host-visible",
        };
        let mut free = size.saturating_sub(held);
        let mut text = format!("memory heap {h} ({kind}) has {}", exact_bytes(size));
        if let Some((heap_budget, usage)) = budget {
            let within = heap_budget.saturating_sub(usage);
            free = free.min(within);
            text += &format!(
                ", {} of it free within the driver's budget (VK_EXT_memory_budget)",
                exact_bytes(within)
            );
        }
        (free, text)
    }

    /// The error for a plan that does not fit: what it needs, item by item (largest first),
    /// what fovea holds and what the device offers.
    fn shortfall(
        &self,
        what: &str,
        plan: &[PlannedAllocation],
        offered: &[String],
        advice: &str,
    ) -> GpuError {
        let needed: u64 = plan.iter().map(|p| p.bytes).sum();
        let mut items: Vec<&PlannedAllocation> = plan.iter().filter(|p| p.bytes > 0).collect();
        items.sort_by_key(|p| std::cmp::Reverse(p.bytes));
        let breakdown = items
            .iter()
            .map(|p| format!("{} {}", p.name, human_bytes(p.bytes)))
            .collect::<Vec<_>>()
            .join(", ");
        let mut advice = advice.to_owned();
        if self.facts.limit.is_some() {
            advice += &format!(", or raise or unset {MEMORY_LIMIT_VAR}");
        }
        GpuError::NotEnoughMemory(Box::new(MemoryShortfall {
            what: what.to_owned(),
            needed: format!(
                "it needs {}, {needed} bytes ({breakdown})",
                human_bytes(needed)
            ),
            in_use: human_bytes(self.in_use()),
            offered: offered.join(" and "),
            advice,
        }))
    }

    /// One item of a plan against the per-resource limits: maxStorageBufferRange for a
    /// storage buffer, maxTexelBufferElements for one read through a texel view,
    /// maxMemoryAllocationSize for all.
    fn check_item(&self, what: &str, p: &PlannedAllocation, advice: &str) -> Result<(), GpuError> {
        let limits = [
            (
                p.texel_view,
                "texel view (16-byte texels)",
                self.facts.max_texel_view_bytes,
                "maxTexelBufferElements × 16",
            ),
            (
                p.storage_buffer.then_some(p.bytes),
                "storage buffer",
                self.facts.max_storage_buffer_range,
                "maxStorageBufferRange",
            ),
            (
                Some(p.bytes),
                "allocation",
                self.facts.max_memory_allocation_size,
                "maxMemoryAllocationSize",
            ),
        ];
        // Each limit applies to the bytes one binding or allocation spans (None: not bound so).
        for (spans, kind, limit, limit_name) in limits {
            if let Some(bytes) = spans.filter(|&b| b > limit) {
                return Err(GpuError::ResourceTooLarge(Box::new(ResourceLimit {
                    what: what.to_owned(),
                    item: p.name.clone(),
                    kind,
                    bytes: exact_bytes(bytes),
                    limit: exact_bytes(limit),
                    limit_name,
                    advice: advice.to_owned(),
                })));
            }
        }
        Ok(())
    }

    /// Counts an allocation of `bytes` that memory.rs is about to make, refusing one that
    /// would take fovea past [`GpuOptions::memory_limit`](super::GpuOptions::memory_limit).
    pub(super) fn reserve(
        &self,
        name: &str,
        bytes: u64,
        host_visible: bool,
    ) -> Result<(), GpuError> {
        let in_use = self.in_use();
        if let Some(limit) = self.facts.limit {
            if in_use.saturating_add(bytes) > limit {
                return Err(GpuError::NotEnoughMemory(Box::new(MemoryShortfall {
                    what: name.to_owned(),
                    needed: format!("it needs {}", exact_bytes(bytes)),
                    in_use: human_bytes(in_use),
                    offered: format!("{MEMORY_LIMIT_VAR} caps fovea at {}", exact_bytes(limit)),
                    advice: format!(
                        "raise or unset {MEMORY_LIMIT_VAR}, or use a smaller scene or resolution"
                    ),
                })));
            }
        }
        self.allocated[host_visible as usize].fetch_add(bytes, Ordering::Relaxed);
        self.peak_allocated
            .fetch_max(self.in_use(), Ordering::Relaxed);
        Ok(())
    }

    /// Uncounts an allocation counted by [`Self::reserve`] once it is freed (or failed).
    pub(super) fn release(&self, bytes: u64, host_visible: bool) {
        self.allocated[host_visible as usize].fetch_sub(bytes, Ordering::Relaxed);
    }
}
