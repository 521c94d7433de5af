//! One OpenXR session, in the order of openxrs' `examples/vulkan.rs`: set-up makes the
//! session, the eye-gaze actions, the reference space, the swapchains and the renderer; the
//! loop pumps the runtime's events (which begin and end the session) and renders a frame
//! whenever the session runs; teardown is the drop of what set-up made, last made first,
//! also when set-up fails half-way.

use super::error::{XrContext, XrError};
use super::eye_gaze::EyeGaze;
use super::frame_record::Record;
use super::headset_gaze::HeadsetGaze;
use super::headset_renderer::{HeadsetRenderer, SubmittedFrame};
use super::instance::XrInstance;
use super::options::XrOptions;
use super::poses::SpacePlacement;
use super::probe::ProbeReport;
use super::summary::{SessionEnd, XrSummary};
use super::swapchains::{choose_format, EyeSwapchain};
use super::views::{visibility_masks, EyeViews, VIEW_TYPE};
use crate::foveation::Gaze;
use crate::gpu::{ExternalImage, GpuContext, SourceRect};
use openxr as xr;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long to wait for the runtime to stop the session after fovea asked it to, before
/// tearing down regardless (a runtime that never answers must not hang fovea).
const STOP_TIMEOUT: Duration = Duration::from_secs(5);

/// Sleep between polls while the session is not running (the headset not worn, or the
/// runtime not ready): the runtime's events arrive at display rate at most.
const IDLE_POLL: Duration = Duration::from_millis(5);

/// Runs one session on `ctx` to its end; its frames are counted on from `frames_before`.
pub(super) fn run_session(
    xr_instance: &XrInstance,
    ctx: &Arc<GpuContext>,
    options: &XrOptions,
    record: &mut Record,
    frames_before: u64,
) -> Result<XrSummary, XrError> {
    let mut frame_loop = FrameLoop::new(xr_instance, ctx, options, frames_before)?;
    let looped = frame_loop.run(record);
    let mut summary = frame_loop.end(looped, record)?;
    // Taken once the session's objects are gone: what destroying them reported counts too.
    summary.validation = ctx.take_validation_messages();
    Ok(summary)
}

/// A session's objects and the state of its loop. The objects are the first fields,
/// declared in the reverse order of their creation, which is the order they drop in: the
/// renderer first (it waits for its frames in flight, which write the swapchain images), the
/// session last, all of them before the Vulkan device the session uses (the caller's).
struct FrameLoop<'a> {
    renderer: HeadsetRenderer<'a>,
    swapchains: [EyeSwapchain; 2],
    space: xr::Space,
    gaze: HeadsetGaze,
    stream: xr::FrameStream<xr::Vulkan>,
    waiter: xr::FrameWaiter,
    session: xr::Session<xr::Vulkan>,
    xr_instance: &'a XrInstance,
    options: &'a XrOptions,
    /// Each eye's image size.
    size: [u32; 2],
    placement: SpacePlacement,
    /// What `--probe` found at set-up; its gaze activity and frames are added at the end.
    probe: Option<ProbeReport>,
    state: LoopState,
    events: xr::EventDataBuffer,
    summary: XrSummary,
}

/// Where the session stands, as the runtime's events and fovea's requests left it.
#[derive(Default)]
struct LoopState {
    /// From READY (xrBeginSession) to STOPPING (xrEndSession): frames are rendered.
    running: bool,
    /// The session has input focus (actions are active only then, OpenXR 1.0 §11).
    focused: bool,
    /// When fovea asked the runtime to end the session.
    exit_asked: Option<Instant>,
    /// The visibility masks are to be read (again) before the next frame is rendered.
    masks_stale: bool,
}

impl<'a> FrameLoop<'a> {
    /// Creates the session on `ctx`'s device, then its eye-gaze actions (attached before
    /// the first frame), reference space, swapchains and renderer.
    fn new(
        xr_instance: &'a XrInstance,
        ctx: &'a Arc<GpuContext>,
        options: &'a XrOptions,
        frames_before: u64,
    ) -> Result<Self, XrError> {
        let views = stereo_views(xr_instance)?;
        let size = options.size.unwrap_or([
            views[0].recommended_image_rect_width,
            views[0].recommended_image_rect_height,
        ]);
        let (session, waiter, stream) = create_session(xr_instance, ctx)?;
        let gaze = headset_gaze(xr_instance, &session, options)?;
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
        let swapchains = [
            EyeSwapchain::new(&session, format, size)?,
            EyeSwapchain::new(&session, format, size)?,
        ];
        // The layers: the shipped config of the headset the runtime reports, unless given.
        let system = xr_instance
            .instance
            .system_properties(xr_instance.system)
            .xr("xrGetSystemProperties")?;
        let recommended = [
            views[0].recommended_image_rect_width,
            views[0].recommended_image_rect_height,
        ];
        let (foveation, foveation_source) =
            options
                .foveation
                .resolve(&system.system_name, recommended, options.temporal.is_some());
        let renderer = HeadsetRenderer::new(ctx, options, foveation)?;
        let use_mask = options.visibility_mask && xr_instance.visibility_mask;
        let summary = XrSummary {
            frames: frames_before,
            eye_size: size,
            swapchain_format: format!("{format:?}"),
            no_gaze: gaze.unavailable(),
            visibility_mask: use_mask,
            foveation: foveation_source,
            ..XrSummary::new(xr_instance.runtime.clone())
        };
        Ok(Self {
            renderer,
            swapchains,
            space,
            gaze,
            stream,
            waiter,
            session,
            xr_instance,
            options,
            size,
            placement: SpacePlacement::at_camera(&options.scene.camera),
            probe,
            state: LoopState {
                masks_stale: use_mask,
                ..LoopState::default()
            },
            events: xr::EventDataBuffer::new(),
            summary,
        })
    }

    /// Events, then a frame whenever the session runs, until the session ends (its end is
    /// in the summary). A session lost in any call ends the loop with that error.
    fn run(&mut self, record: &mut Record) -> Result<(), XrError> {
        loop {
            let ended = match self.pump_events()? {
                Some(end) => Some(end),
                None => self.stop_if_asked()?,
            };
            if let Some(end) = ended {
                self.summary.end = end;
                return Ok(());
            }
            if self.state.running && self.state.exit_asked.is_none() {
                self.frame(record)?;
            } else {
                std::thread::sleep(IDLE_POLL);
            }
        }
    }

    /// Handles every event the runtime has queued; the session's end once one says so.
    fn pump_events(&mut self) -> Result<Option<SessionEnd>, XrError> {
        let instance = &self.xr_instance.instance;
        while let Some(event) = instance.poll_event(&mut self.events).xr("xrPollEvent")? {
            let end = match event {
                // Events queue per instance: a lost session's last ones may still be there
                // when the next session starts.
                xr::Event::SessionStateChanged(change)
                    if change.session() != self.session.as_raw() =>
                {
                    None
                }
                xr::Event::SessionStateChanged(change) => {
                    let state = change.state();
                    self.state_changed(state)?
                }
                xr::Event::InstanceLossPending(_) => {
                    tracing::warn!("the OpenXR instance is being lost; ending the session");
                    Some(SessionEnd::Lost)
                }
                xr::Event::VisibilityMaskChangedKHR(_) => {
                    self.state.masks_stale = self.summary.visibility_mask;
                    None
                }
                _ => None,
            };
            if end.is_some() {
                return Ok(end);
            }
        }
        Ok(None)
    }

    /// Follows the session into `state`: begins it when ready, ends it when stopping.
    fn state_changed(&mut self, state: xr::SessionState) -> Result<Option<SessionEnd>, XrError> {
        self.summary.states.push(state);
        self.state.focused = state == xr::SessionState::FOCUSED;
        tracing::info!("OpenXR session state: {state:?}");
        match state {
            xr::SessionState::READY => {
                self.session.begin(VIEW_TYPE).xr("xrBeginSession")?;
                self.state.running = true;
            }
            xr::SessionState::STOPPING => {
                self.session.end().xr("xrEndSession")?;
                self.state.running = false;
            }
            xr::SessionState::EXITING => {
                return Ok(Some(match self.state.exit_asked {
                    Some(_) => SessionEnd::Requested,
                    None => SessionEnd::RuntimeExit,
                }))
            }
            xr::SessionState::LOSS_PENDING => {
                tracing::warn!("the OpenXR session is being lost; ending it");
                return Ok(Some(SessionEnd::Lost));
            }
            _ => {}
        }
        Ok(None)
    }

    /// Asks the runtime to stop the session once fovea is told to stop (Ctrl+C, a
    /// termination signal), as a user quitting would; the end when no session runs to be
    /// stopped, or the runtime has not stopped it in time.
    fn stop_if_asked(&mut self) -> Result<Option<SessionEnd>, XrError> {
        if self.state.exit_asked.is_none() && self.options.stop.load(Ordering::Relaxed) {
            eprintln!("fovea xr: stopping the session (interrupted)");
            if !self.state.running {
                return Ok(Some(SessionEnd::Requested));
            }
            self.request_exit()?;
        }
        if let Some(asked) = self.state.exit_asked {
            if asked.elapsed() > STOP_TIMEOUT {
                tracing::warn!(
                    "the runtime did not stop the session within {STOP_TIMEOUT:?} of fovea asking; tearing down"
                );
                return Ok(Some(SessionEnd::Requested));
            }
        }
        Ok(None)
    }

    fn request_exit(&mut self) -> Result<(), XrError> {
        self.session.request_exit().xr("xrRequestExitSession")?;
        self.state.exit_asked = Some(Instant::now());
        Ok(())
    }

    /// One frame, top to bottom: wait for the runtime, begin, locate the eyes, render them
    /// into the swapchain images, end. A frame the compositor does not want is ended empty
    /// and not counted.
    fn frame(&mut self, record: &mut Record) -> Result<(), XrError> {
        let state = self.waiter.wait().xr("xrWaitFrame")?;
        let started = Instant::now();
        // Frames that finished while xrWaitFrame blocked.
        self.renderer.record_finished(record, usize::MAX)?;
        self.stream.begin().xr("xrBeginFrame")?;
        if !state.should_render {
            return self.end_empty(state.predicted_display_time);
        }
        let views = EyeViews::locate(
            &self.session,
            &self.space,
            &self.placement,
            state.predicted_display_time,
            self.size,
        )?;
        if self.state.masks_stale {
            let masks = visibility_masks(&self.session, &views.images)?;
            self.renderer.set_visibility_masks(masks);
            self.state.masks_stale = false;
        }
        match self.probe.is_some() {
            true => self.probe_frame(&views)?,
            false => self.render_frame(views, &state, started, record)?,
        }
        self.count_frame()
    }

    /// The probe renders nothing: it locates the gaze (the report says how often it was
    /// active), and an empty frame keeps the session running.
    fn probe_frame(&mut self, views: &EyeViews) -> Result<(), XrError> {
        let focused = self.state.focused;
        (self.gaze).frame(&self.session, &self.space, &self.placement, focused, views)?;
        self.end_empty(views.time)
    }

    /// Renders the eyes into their swapchain images and ends the frame with them. One
    /// submission latches the gaze, plans, renders and copies into the images; they are
    /// released right after it (the runtime orders its reads after our queue's work).
    fn render_frame(
        &mut self,
        views: EyeViews,
        state: &xr::FrameState,
        started: Instant,
        record: &mut Record,
    ) -> Result<(), XrError> {
        let targets = self.acquire_images()?;
        // The gaze is located as the last step before the frame's submission (its commands
        // are recorded by then): the newest sample the tracker has for this display time.
        let mut latched = None;
        let mut latch_gaze = || {
            let gaze = (self.gaze).frame(
                &self.session,
                &self.space,
                &self.placement,
                self.state.focused,
                &views,
            );
            let gazes = match &gaze {
                Ok(g) => g.filtered.gazes(&views.images),
                Err(_) => vec![Gaze::Forward; views.images.len()],
            };
            latched = Some((gaze, started.elapsed()));
            gazes
        };
        let submitted =
            (self.renderer).submit(self.summary.frames, &views, &mut latch_gaze, &targets);
        // Released whatever happened, so the runtime's image accounting stays right.
        self.release_images()?;
        submitted?;
        let (gaze, latch) = latched.expect("the renderer latches the gaze of every frame");
        let gaze = gaze?;
        self.end_projection(&views)?;
        self.renderer.sent(SubmittedFrame {
            index: self.summary.frames,
            display_time_s: views.time_s(),
            display_period_s: state.predicted_display_period.as_nanos() as f64 * 1e-9,
            gaze_time_s: gaze.time_s,
            gaze_sampled: gaze.sampled,
            gaze: gaze.filtered,
            images: views.images,
            started,
            cpu_ms: started.elapsed().as_secs_f64() * 1e3,
            latch_ms: latch.as_secs_f64() * 1e3,
        });
        // Room for the next frame now, so that nothing waits between its xrWaitFrame and
        // its latch.
        let keep = self.options.frames_in_flight - 1;
        self.renderer.record_finished(record, keep)
    }

    /// Both eyes' swapchain images, each with the part of the output image that goes into
    /// it (the eyes side by side, left first).
    fn acquire_images(&mut self) -> Result<Vec<(SourceRect, ExternalImage)>, XrError> {
        let size = self.size;
        (self.swapchains.iter_mut().enumerate())
            .map(|(e, swapchain)| {
                let rect = SourceRect {
                    offset: [e as u32 * size[0], 0],
                    extent: size,
                };
                Ok((rect, swapchain.acquire()?))
            })
            .collect()
    }

    fn release_images(&mut self) -> Result<(), XrError> {
        for swapchain in &mut self.swapchains {
            swapchain.release()?;
        }
        Ok(())
    }

    /// Ends the frame with nothing to show.
    fn end_empty(&mut self, time: xr::Time) -> Result<(), XrError> {
        (self.stream)
            .end(time, xr::EnvironmentBlendMode::OPAQUE, &[])
            .xr("xrEndFrame")
    }

    /// Ends the frame with the eyes' swapchain images as its projection layer.
    fn end_projection(&mut self, views: &EyeViews) -> Result<(), XrError> {
        let projection_views = views.projection_views(&self.swapchains);
        let layer = xr::CompositionLayerProjection::new()
            .space(&self.space)
            .views(&projection_views);
        (self.stream)
            .end(views.time, xr::EnvironmentBlendMode::OPAQUE, &[&layer])
            .xr("xrEndFrame")
    }

    /// Counts the frame; the last one asked for (`frames`) asks the runtime to end the
    /// session.
    fn count_frame(&mut self) -> Result<(), XrError> {
        self.summary.frames += 1;
        if self
            .options
            .frames
            .is_some_and(|n| self.summary.frames >= n)
        {
            self.request_exit()?;
        }
        Ok(())
    }

    /// Ends the loop that returned `looped`: a lost session ends like any other, other errors
    /// are returned. The frames still in flight were rendered and are recorded like the
    /// others. Consuming the loop destroys the session's objects (the fields left after the
    /// summary is taken drop as the function returns, in the order they are declared).
    fn end(
        mut self,
        looped: Result<(), XrError>,
        record: &mut Record,
    ) -> Result<XrSummary, XrError> {
        match looped {
            Ok(()) => {}
            Err(XrError::SessionLost(call)) => {
                tracing::warn!("the OpenXR session was lost ({call}); ending it");
                self.summary.end = SessionEnd::Lost;
            }
            Err(e) => return Err(e),
        }
        self.renderer.record_finished(record, 0)?;
        let gaze = self.gaze.activity();
        let frames = self.summary.frames;
        self.summary.probe = (self.probe.take()).map(|report| ProbeReport {
            gaze,
            frames,
            ..report
        });
        Ok(self.summary)
    }
}

/// The runtime's two views of the stereo configuration (their recommended and largest image
/// sizes); a headset with another count is refused.
fn stereo_views(xr_instance: &XrInstance) -> Result<Vec<xr::ViewConfigurationView>, XrError> {
    let views = (xr_instance.instance)
        .enumerate_view_configuration_views(xr_instance.system, VIEW_TYPE)
        .xr("xrEnumerateViewConfigurationViews")?;
    if views.len() != 2 {
        return Err(XrError::Output(format!(
            "the headset has {} views in its stereo configuration; fovea renders two",
            views.len()
        )));
    }
    Ok(views)
}

/// The session's eye gaze: its actions where the runtime offers them, else why not (said
/// once, here).
fn headset_gaze(
    xr_instance: &XrInstance,
    session: &xr::Session<xr::Vulkan>,
    options: &XrOptions,
) -> Result<HeadsetGaze, XrError> {
    let tracker = EyeGaze::new(xr_instance, session)?;
    let gaze = HeadsetGaze::new(tracker, &options.scene, options.gaze_hold_s);
    if let Some(message) = gaze.unavailable() {
        eprintln!("fovea xr: {message}");
    }
    Ok(gaze)
}

/// The session on `ctx`'s device and queue (made through this runtime), with its frame
/// waiter and frame stream.
fn create_session(
    xr_instance: &XrInstance,
    ctx: &GpuContext,
) -> Result<
    (
        xr::Session<xr::Vulkan>,
        xr::FrameWaiter,
        xr::FrameStream<xr::Vulkan>,
    ),
    XrError,
> {
    let (vk_instance, physical_device, device, _) = ctx.raw_handles();
    // SAFETY: the handles are the live instance, device and queue family made through this
    // runtime; fovea submits to the queue only from this thread.
    unsafe {
        xr_instance.instance.create_session::<xr::Vulkan>(
            xr_instance.system,
            &xr::vulkan::SessionCreateInfo {
                instance: ash::vk::Handle::as_raw(vk_instance) as _,
                physical_device: ash::vk::Handle::as_raw(physical_device) as _,
                device: ash::vk::Handle::as_raw(device) as _,
                queue_family_index: ctx.queue_family(),
                queue_index: 0,
            },
        )
    }
    .xr("xrCreateSession")
}
