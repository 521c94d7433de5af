//! A headset run: the OpenXR instance, the Vulkan device made through the runtime, and one
//! session after another until one ends other than by loss (frame_loop.rs runs each, from
//! set-up to teardown). `frames` ends a session by asking the runtime to stop it, as a user
//! quitting would.

use super::error::{XrContext, XrError};
use super::frame_loop::run_session;
use super::frame_record::{FrameRecord, Record};
use super::instance::XrInstance;
use super::options::XrOptions;
use super::summary::{SessionEnd, XrSummary};
use super::vulkan::RuntimeVulkan;
use crate::gpu::{ContextNeeds, GpuContext};
use openxr as xr;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

/// Runs a session to its end; `record` sees every rendered frame.
pub fn run(
    options: XrOptions,
    mut record: impl FnMut(&FrameRecord) -> Result<(), XrError>,
) -> Result<XrSummary, XrError> {
    let xr_instance = XrInstance::new(options.source)?;
    let requirements = xr_instance
        .instance
        .graphics_requirements::<xr::Vulkan>(xr_instance.system)
        .xr("xrGetVulkanGraphicsRequirements2KHR")?;
    let (min, max) = (
        requirements.min_api_version_supported,
        requirements.max_api_version_supported,
    );
    if (min.major(), min.minor()) > (1, 2) || (max.major(), max.minor()) < (1, 2) {
        return Err(XrError::VulkanVersion {
            min: format!("{}.{}", min.major(), min.minor()),
            max: format!("{}.{}", max.major(), max.minor()),
        });
    }
    let creator = RuntimeVulkan {
        instance: &xr_instance.instance,
        system: xr_instance.system,
    };
    let ctx = Arc::new(GpuContext::new_with(
        &options.gpu,
        &ContextNeeds {
            graphics_queue: true,
            creator: Some(&creator),
            ..ContextNeeds::default()
        },
    )?);
    let validation_log = ctx.validation_log();
    let result = run_sessions(&xr_instance, &ctx, &options, &mut record);
    // The traversal too: it decides a headset frame's cost (ray queries on a GPU with them).
    let device = format!(
        "{} ({} traversal)",
        ctx.info.name,
        crate::render::Traversal::preferred(&ctx).name()
    );
    // The sessions and everything in them are gone (run_session tears each down); the Vulkan
    // device goes next, then the instance (dropped last, at the end of this function).
    drop(ctx);
    let mut summary = result?;
    summary.device = device;
    summary.validation.extend(validation_log.take());
    Ok(summary)
}

/// New sessions fovea creates after the runtime lost one, before it gives up.
pub const SESSION_RETRIES: u32 = 3;
/// The wait before the first new session; it doubles for each further one.
const FIRST_RETRY_WAIT: Duration = Duration::from_millis(500);

/// Runs sessions on `ctx` until one ends other than by loss, or until a lost session has been
/// followed by SESSION_RETRIES new ones (bounded back-off between them). Frames count on
/// across the sessions; a new session that cannot be created ends the run as lost, with what
/// the earlier ones recorded.
fn run_sessions(
    xr_instance: &XrInstance,
    ctx: &Arc<GpuContext>,
    options: &XrOptions,
    record: &mut Record,
) -> Result<XrSummary, XrError> {
    let mut summary = run_session(xr_instance, ctx, options, record, 0)?;
    for retry in 0..SESSION_RETRIES {
        let wanted_more = options.frames.is_none_or(|n| summary.frames < n);
        if summary.end != SessionEnd::Lost
            || options.probe
            || !wanted_more
            || options.stop.load(Ordering::Relaxed)
        {
            break;
        }
        let wait = FIRST_RETRY_WAIT * 2u32.pow(retry);
        eprintln!(
            "fovea xr: the OpenXR session was lost after {} frames; starting a new one in {} ms \
             ({} of {SESSION_RETRIES})",
            summary.frames,
            wait.as_millis(),
            retry + 1
        );
        std::thread::sleep(wait);
        match run_session(xr_instance, ctx, options, record, summary.frames) {
            Ok(next) => summary = next.after(summary),
            Err(e) => {
                eprintln!("fovea xr: no new session: {e}");
                break;
            }
        }
    }
    Ok(summary)
}
