//! The OpenXR session from start to clean teardown, in the order of openxrs'
//! `examples/vulkan.rs`: instance → Vulkan through the runtime → session → spaces, swapchains,
//! eye gaze → frame loop (poll events, wait, begin, locate, render both eyes, end) → destroy in
//! reverse. Every session state is handled; `frames` ends the session by asking the runtime
//! to stop, as a user quitting would.

use super::error::{XrContext, XrError};
use super::eye_gaze::EyeGaze;
use super::headset_gaze::HeadsetGaze;
use super::instance::{RuntimeSource, XrInstance};
use super::poses::SpacePlacement;
use super::probe::ProbeReport;
use super::swapchains::{choose_format, EyeSwapchain};
use super::vulkan::RuntimeVulkan;
use crate::foveation::gaze_filter::FilteredGaze;
use crate::foveation::{FoveationConfig, ImageGeometry, VisibilityMask};
use crate::gpu::{ContextNeeds, GpuContext, GpuOptions, SourceRect};
use crate::render::{
    DebugView, EyeView, Frame, FrameRequest, RenderSettings, Renderer, TemporalSettings,
};
use crate::scene::Scene;
use openxr as xr;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

const VIEW_TYPE: xr::ViewConfigurationType = xr::ViewConfigurationType::PRIMARY_STEREO;

/// How long to wait for the runtime to stop the session after fovea asked it to, before
/// tearing down regardless (a runtime that never answers must not hang fovea).
const STOP_TIMEOUT: Duration = Duration::from_secs(5);

/// Sleep between polls while the session is not running (the headset not worn, or the
/// runtime not ready): the runtime's events arrive at display rate at most.
const IDLE_POLL: Duration = Duration::from_millis(5);

pub struct XrOptions {
    pub source: RuntimeSource,
    pub gpu: GpuOptions,
    pub scene: Scene,
    /// Per-eye image size; `None`: the runtime's recommended size.
    pub size: Option<[u32; 2]>,
    /// Seed, integrator and bounces (width and height come from the swapchains).
    pub settings: RenderSettings,
    pub foveation: FoveationConfig,
    pub debug: DebugView,
    /// End the session cleanly after this many rendered frames.
    pub frames: Option<u64>,
    /// Seconds a lost gaze is held before falling back to the centre.
    pub gaze_hold_s: f64,
    /// Use the runtime's visibility mask where offered.
    pub visibility_mask: bool,
    /// Render nothing: set everything up, submit empty frames until `frames`, and report
    /// what the runtime offers ([`XrSummary::probe`]).
    pub probe: bool,
    /// Set (by a Ctrl+C or termination handler) to end the session as `frames` does: the
    /// runtime is asked to stop, and everything is torn down and recorded.
    pub stop: Arc<AtomicBool>,
    /// Frames submitted before the CPU waits for the oldest one's GPU work (1: each frame
    /// finished before the next is planned; at most MAX_FRAMES_IN_FLIGHT).
    pub frames_in_flight: usize,
    /// Temporal history (`Renderer::set_temporal`); None: off.
    pub temporal: Option<TemporalSettings>,
}

/// One rendered frame, for whoever records the session.
pub struct FrameRecord<'a> {
    pub index: u64,
    /// Predicted display time, seconds (the runtime's clock).
    pub display_time_s: f64,
    /// The runtime's display period, seconds.
    pub display_period_s: f64,
    /// When the eye tracker took the gaze sample (XrEyeGazeSampleTimeEXT), else the display
    /// time.
    pub gaze_time_s: f64,
    /// Whether the eye tracker gave a sample (its time) for the frame.
    pub gaze_sampled: bool,
    /// GPU timings and counters of both eyes (no pixels: the image went to the headset).
    pub frame: &'a Frame,
    pub gaze: &'a FilteredGaze,
    pub images: &'a [ImageGeometry],
    /// CPU milliseconds from the end of xrWaitFrame to the end of xrEndFrame.
    pub cpu_ms: f64,
    /// CPU milliseconds from the end of xrWaitFrame to the gaze latch (right before the
    /// frame's submission) and to the end of its GPU work (when fovea saw its fence
    /// signalled: it looks after every xrWaitFrame and xrEndFrame).
    pub latch_ms: f64,
    pub gpu_done_ms: f64,
    /// fovea's GPU memory in use after the frame, bytes.
    pub gpu_bytes: u64,
}

/// How a session ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SessionEnd {
    /// fovea asked to stop (`frames` reached) and the runtime stopped the session.
    Requested,
    /// The runtime (or the user through it) stopped the session.
    RuntimeExit,
    /// The session or instance was lost (headset unplugged, runtime restarted).
    Lost,
}

pub struct XrSummary {
    pub runtime: String,
    pub device: String,
    /// Frames rendered in all sessions.
    pub frames: u64,
    /// Sessions run: more than one after the runtime lost one and fovea started another.
    pub sessions: u32,
    pub eye_size: [u32; 2],
    pub swapchain_format: String,
    /// Why there was no eye gaze, if there was none.
    pub no_gaze: Option<&'static str>,
    pub visibility_mask: bool,
    pub states: Vec<xr::SessionState>,
    pub end: SessionEnd,
    /// Validation messages, including those reported while the Vulkan device was destroyed.
    pub validation: Vec<String>,
    /// What `--probe` found (probe sessions only).
    pub probe: Option<ProbeReport>,
}

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
    // The session and everything in it are gone (run_with_context returned); the Vulkan
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
    record: &mut impl FnMut(&FrameRecord) -> Result<(), XrError>,
) -> Result<XrSummary, XrError> {
    let mut summary = run_with_context(xr_instance, ctx, options, record, 0)?;
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
        match run_with_context(xr_instance, ctx, options, record, summary.frames) {
            Ok(next) => summary = next.after(summary),
            Err(e) => {
                eprintln!("fovea xr: no new session: {e}");
                break;
            }
        }
    }
    Ok(summary)
}

impl XrSummary {
    /// This session's summary continuing `earlier` sessions': their states first.
    fn after(mut self, earlier: XrSummary) -> XrSummary {
        let mut states = earlier.states;
        states.append(&mut self.states);
        self.states = states;
        let mut validation = earlier.validation;
        validation.append(&mut self.validation);
        self.validation = validation;
        self.sessions += earlier.sessions;
        self
    }
}

fn run_with_context(
    xr_instance: &XrInstance,
    ctx: &Arc<GpuContext>,
    options: &XrOptions,
    record: &mut impl FnMut(&FrameRecord) -> Result<(), XrError>,
    frames_before: u64,
) -> Result<XrSummary, XrError> {
    let instance = &xr_instance.instance;
    let system = xr_instance.system;
    let views = instance
        .enumerate_view_configuration_views(system, VIEW_TYPE)
        .xr("xrEnumerateViewConfigurationViews")?;
    if views.len() != 2 {
        return Err(XrError::Output(format!(
            "the headset has {} views in its stereo configuration; fovea renders two",
            views.len()
        )));
    }
    let size = options.size.unwrap_or([
        views[0].recommended_image_rect_width,
        views[0].recommended_image_rect_height,
    ]);
    let (vk_instance, physical_device, device, _) = ctx.raw_handles();
    // SAFETY: the handles are the live instance, device and queue family made through this
    // runtime; fovea submits to the queue only from this thread.
    let (session, mut waiter, mut stream) = unsafe {
        instance.create_session::<xr::Vulkan>(
            system,
            &xr::vulkan::SessionCreateInfo {
                instance: ash::vk::Handle::as_raw(vk_instance) as _,
                physical_device: ash::vk::Handle::as_raw(physical_device) as _,
                device: ash::vk::Handle::as_raw(device) as _,
                queue_family_index: ctx.queue_family(),
                queue_index: 0,
            },
        )
    }
    .xr("xrCreateSession")?;
    let mut headset_gaze = HeadsetGaze::new(
        EyeGaze::new(xr_instance, &session)?,
        &options.scene,
        options.gaze_hold_s,
    );
    let no_gaze = headset_gaze.unavailable();
    if let Some(message) = no_gaze {
        eprintln!("fovea xr: {message}");
    }
    let space = session
        .create_reference_space(xr::ReferenceSpaceType::LOCAL, xr::Posef::IDENTITY)
        .xr("xrCreateReferenceSpace")?;
    let offered = session
        .enumerate_swapchain_formats()
        .xr("xrEnumerateSwapchainFormats")?;
    let format = choose_format(&offered, ctx)?;
    let probe = match options.probe {
        true => Some(ProbeReport::new(
            xr_instance,
            &views,
            &session,
            &offered,
            format,
            &ctx.info,
        )?),
        false => None,
    };
    let mut swapchains = [
        EyeSwapchain::new(&session, format, size)?,
        EyeSwapchain::new(&session, format, size)?,
    ];
    let mut renderer = Renderer::new(ctx, &options.scene)?;
    // Frames are copied from the output image into the swapchains.
    renderer.set_output_image(true);
    renderer.set_frames_in_flight(options.frames_in_flight)?;
    renderer.set_temporal(options.temporal)?;
    let mut submitted_frames = VecDeque::new();
    let placement = SpacePlacement::at_camera(&options.scene.camera);
    let use_mask = options.visibility_mask && xr_instance.visibility_mask;
    let mut masks_stale = use_mask;

    let mut summary = XrSummary {
        runtime: xr_instance.runtime.clone(),
        device: String::new(),
        frames: frames_before,
        sessions: 1,
        eye_size: size,
        swapchain_format: format!("{format:?}"),
        no_gaze,
        visibility_mask: use_mask,
        states: Vec::new(),
        end: SessionEnd::RuntimeExit,
        validation: Vec::new(),
        probe: None,
    };
    let mut running = false;
    let mut exit_asked: Option<Instant> = None;
    let mut focused = false;
    let mut events = xr::EventDataBuffer::new();
    // The frame loop; a session lost in any call ends it as lost (teardown is the same).
    let looped = (|| -> Result<(), XrError> {
        'session: loop {
            while let Some(event) = instance.poll_event(&mut events).xr("xrPollEvent")? {
                match event {
                    // Events queue per instance: a lost session's last ones may still be
                    // there when the next session starts.
                    xr::Event::SessionStateChanged(change)
                        if change.session() != session.as_raw() => {}
                    xr::Event::SessionStateChanged(change) => {
                        let state = change.state();
                        summary.states.push(state);
                        focused = state == xr::SessionState::FOCUSED;
                        tracing::info!("OpenXR session state: {state:?}");
                        match state {
                            xr::SessionState::READY => {
                                session.begin(VIEW_TYPE).xr("xrBeginSession")?;
                                running = true;
                            }
                            xr::SessionState::STOPPING => {
                                session.end().xr("xrEndSession")?;
                                running = false;
                            }
                            xr::SessionState::EXITING => {
                                summary.end = match exit_asked {
                                    Some(_) => SessionEnd::Requested,
                                    None => SessionEnd::RuntimeExit,
                                };
                                break 'session;
                            }
                            xr::SessionState::LOSS_PENDING => {
                                tracing::warn!("the OpenXR session is being lost; ending it");
                                summary.end = SessionEnd::Lost;
                                break 'session;
                            }
                            _ => {}
                        }
                    }
                    xr::Event::InstanceLossPending(_) => {
                        tracing::warn!("the OpenXR instance is being lost; ending the session");
                        summary.end = SessionEnd::Lost;
                        break 'session;
                    }
                    xr::Event::VisibilityMaskChangedKHR(_) => masks_stale = use_mask,
                    _ => {}
                }
            }
            if exit_asked.is_none() && options.stop.load(Ordering::Relaxed) {
                eprintln!("fovea xr: stopping the session (interrupted)");
                if !running {
                    summary.end = SessionEnd::Requested;
                    break;
                }
                session.request_exit().xr("xrRequestExitSession")?;
                exit_asked = Some(Instant::now());
            }
            if let Some(asked) = exit_asked {
                if asked.elapsed() > STOP_TIMEOUT {
                    tracing::warn!(
                        "the runtime did not stop the session within {STOP_TIMEOUT:?} of fovea asking; tearing down"
                    );
                    summary.end = SessionEnd::Requested;
                    break;
                }
            }
            if !running || exit_asked.is_some() {
                std::thread::sleep(IDLE_POLL);
                continue;
            }
            let state = waiter.wait().xr("xrWaitFrame")?;
            let started = Instant::now();
            // Frames that finished while xrWaitFrame blocked.
            record_finished(
                &mut renderer,
                &mut submitted_frames,
                ctx,
                record,
                usize::MAX,
            )?;
            stream.begin().xr("xrBeginFrame")?;
            if !state.should_render {
                stream
                    .end(
                        state.predicted_display_time,
                        xr::EnvironmentBlendMode::OPAQUE,
                        &[],
                    )
                    .xr("xrEndFrame")?;
                continue;
            }
            let time = state.predicted_display_time;
            let (_, located) = session
                .locate_views(VIEW_TYPE, time, &space)
                .xr("xrLocateViews")?;
            let cameras: Vec<_> = located
                .iter()
                .map(|v| placement.eye_camera(&v.pose, &v.fov))
                .collect();
            let eyes_in_request: Vec<EyeView> = cameras
                .iter()
                .map(|c| EyeView {
                    camera: *c,
                    gaze: crate::foveation::Gaze::Forward,
                })
                .collect();
            let images: Vec<ImageGeometry> = eyes_in_request
                .iter()
                .map(|e| e.image(size[0], size[1]))
                .collect();
            if masks_stale {
                renderer.set_visibility_masks(visibility_masks(&session, &images)?);
                masks_stale = false;
            }
            let time_s = time.as_nanos() as f64 * 1e-9;
            if probe.is_some() {
                headset_gaze.frame(
                    &session, &space, &placement, time, focused, &cameras, &images,
                )?;
                // The probe renders nothing; an empty frame keeps the session running.
                stream
                    .end(time, xr::EnvironmentBlendMode::OPAQUE, &[])
                    .xr("xrEndFrame")?;
                summary.frames += 1;
                if options.frames.is_some_and(|n| summary.frames >= n) {
                    session.request_exit().xr("xrRequestExitSession")?;
                    exit_asked = Some(Instant::now());
                }
                continue;
            }
            let settings = RenderSettings {
                width: size[0],
                height: size[1],
                spp: options.foveation.layers[0].spp,
                seed: options.settings.seed.wrapping_add(summary.frames as u32),
                ..options.settings
            };
            // Both eyes' swapchain images, written by the frame's own submission and released
            // right after it (the runtime orders its reads after our queue's work); released
            // whatever happened, so the runtime's image accounting stays right.
            let mut targets = Vec::with_capacity(2);
            for (e, swapchain) in swapchains.iter_mut().enumerate() {
                let rect = SourceRect {
                    offset: [e as u32 * size[0], 0],
                    extent: size,
                };
                targets.push((rect, swapchain.acquire()?));
            }
            // The gaze is located as the last step before the frame's submission (its commands
            // are recorded by then): the newest sample the tracker has for this display time.
            let mut latched = None;
            let submitted = renderer.submit_frame_latched(
                &FrameRequest {
                    settings,
                    foveation: &options.foveation,
                    eyes: &eyes_in_request,
                    debug: options.debug,
                },
                &mut || {
                    let gaze = headset_gaze.frame(
                        &session, &space, &placement, time, focused, &cameras, &images,
                    );
                    let gazes = match &gaze {
                        Ok(g) => g.filtered.gazes(&images),
                        Err(_) => vec![crate::foveation::Gaze::Forward; images.len()],
                    };
                    latched = Some((gaze, started.elapsed()));
                    gazes
                },
                &mut |cmd, output| ctx.cmd_copy_to_external(cmd, output, &targets),
            );
            for swapchain in &mut swapchains {
                swapchain.release()?;
            }
            submitted?;
            let (gaze, latch) = latched.expect("the renderer latches the gaze of every frame");
            let gaze = gaze?;
            let projection_views: Vec<_> = located
                .iter()
                .zip(&swapchains)
                .map(|(view, swapchain)| {
                    xr::CompositionLayerProjectionView::new()
                        .pose(view.pose)
                        .fov(view.fov)
                        .sub_image(swapchain.sub_image())
                })
                .collect();
            stream
                .end(
                    time,
                    xr::EnvironmentBlendMode::OPAQUE,
                    &[&xr::CompositionLayerProjection::new()
                        .space(&space)
                        .views(&projection_views)],
                )
                .xr("xrEndFrame")?;
            submitted_frames.push_back(SubmittedFrame {
                index: summary.frames,
                display_time_s: time_s,
                display_period_s: state.predicted_display_period.as_nanos() as f64 * 1e-9,
                gaze_time_s: gaze.time_s,
                gaze_sampled: gaze.sampled,
                gaze: gaze.filtered,
                images,
                started,
                cpu_ms: started.elapsed().as_secs_f64() * 1e3,
                latch_ms: latch.as_secs_f64() * 1e3,
            });
            // Room for the next frame now, so that nothing waits between its xrWaitFrame and
            // its latch.
            let keep = options.frames_in_flight - 1;
            record_finished(&mut renderer, &mut submitted_frames, ctx, record, keep)?;
            summary.frames += 1;
            if options.frames.is_some_and(|n| summary.frames >= n) {
                session.request_exit().xr("xrRequestExitSession")?;
                exit_asked = Some(Instant::now());
            }
        }
        Ok(())
    })();
    match looped {
        Ok(()) => {}
        Err(XrError::SessionLost(call)) => {
            tracing::warn!("the OpenXR session was lost ({call}); ending it");
            summary.end = SessionEnd::Lost;
        }
        Err(e) => return Err(e),
    }
    // The frames still in flight were rendered: they are recorded like the others.
    record_finished(&mut renderer, &mut submitted_frames, ctx, record, 0)?;
    summary.probe = probe.map(|report| ProbeReport {
        gaze: headset_gaze.activity(),
        frames: summary.frames,
        ..report
    });
    // Teardown in reverse order of creation: the swapchains' images and the spaces belong
    // to the session, which must go before the Vulkan device it uses.
    drop(swapchains);
    drop(headset_gaze);
    drop(space);
    drop(stream);
    drop(waiter);
    drop(session);
    drop(renderer);
    summary.validation = ctx.take_validation_messages();
    Ok(summary)
}

/// A frame submitted and handed to the runtime, whose GPU work may still be running.
struct SubmittedFrame {
    index: u64,
    display_time_s: f64,
    display_period_s: f64,
    gaze_time_s: f64,
    gaze_sampled: bool,
    gaze: FilteredGaze,
    images: Vec<ImageGeometry>,
    /// The end of its xrWaitFrame.
    started: Instant,
    cpu_ms: f64,
    latch_ms: f64,
}

/// Records the submitted frames whose GPU work has finished, oldest first, after waiting for
/// the oldest ones until at most `keep` are left in flight.
fn record_finished(
    renderer: &mut Renderer,
    submitted: &mut VecDeque<SubmittedFrame>,
    ctx: &GpuContext,
    record: &mut impl FnMut(&FrameRecord) -> Result<(), XrError>,
    keep: usize,
) -> Result<(), XrError> {
    while let Some(frame) = renderer.next_finished(renderer.in_flight() > keep)? {
        let sent = submitted
            .pop_front()
            .expect("every finished frame was submitted by this loop");
        let done = frame.stats.completed_at.unwrap_or_else(Instant::now);
        record(&FrameRecord {
            index: sent.index,
            display_time_s: sent.display_time_s,
            display_period_s: sent.display_period_s,
            gaze_time_s: sent.gaze_time_s,
            gaze_sampled: sent.gaze_sampled,
            frame: &frame,
            gaze: &sent.gaze,
            images: &sent.images,
            cpu_ms: sent.cpu_ms,
            latch_ms: sent.latch_ms,
            gpu_done_ms: done.duration_since(sent.started).as_secs_f64() * 1e3,
            gpu_bytes: ctx.memory_in_use(),
        })?;
    }
    Ok(())
}

/// Each eye's visibility mask from the runtime's hidden-triangle meshes.
fn visibility_masks(
    session: &xr::Session<xr::Vulkan>,
    images: &[ImageGeometry],
) -> Result<Vec<VisibilityMask>, XrError> {
    images
        .iter()
        .enumerate()
        .map(|(e, image)| {
            let mesh = session
                .get_visibility_mask_khr(
                    VIEW_TYPE,
                    e as u32,
                    xr::VisibilityMaskTypeKHR::HIDDEN_TRIANGLE_MESH,
                )
                .xr("xrGetVisibilityMaskKHR")?;
            let vertices: Vec<[f32; 2]> = mesh.vertices.iter().map(|v| [v.x, v.y]).collect();
            let mask = VisibilityMask::from_hidden_triangles(image, &vertices, &mesh.indices);
            tracing::info!(
                "eye {e}: the lens shows {} of {} pixels",
                mask.visible_count(),
                image.width * image.height
            );
            Ok(mask)
        })
        .collect()
}
