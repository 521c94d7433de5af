//! Full sessions against the in-process runtime on lavapipe with validation enabled.
//! Configuration goes through `set_config_override` (thread-local), so these tests can run
//! in parallel threads of this binary.

mod common;

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

use ash::vk;
use openxr as xr;
use openxr::sys::Handle as _;

use common::{direction, forward, App, EYE_SIZE};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("sim-headset-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(
        std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    );
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

fn close(a: [f32; 3], b: [f32; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4)
}

fn projection_views<'a>(
    views: &[xr::View],
    swapchains: &'a [xr::Swapchain<xr::Vulkan>],
) -> Vec<xr::CompositionLayerProjectionView<'a, xr::Vulkan>> {
    (0..2)
        .map(|eye| {
            xr::CompositionLayerProjectionView::new()
                .pose(views[eye].pose)
                .fov(views[eye].fov)
                .sub_image(
                    xr::SwapchainSubImage::new()
                        .swapchain(&swapchains[eye])
                        .image_array_index(0)
                        .image_rect(xr::Rect2Di {
                            offset: xr::Offset2Di { x: 0, y: 0 },
                            extent: xr::Extent2Di {
                                width: EYE_SIZE as i32,
                                height: EYE_SIZE as i32,
                            },
                        }),
                )
        })
        .collect()
}

/// Clears both eyes and submits one projection layer; returns the frame state.
fn render_frame(
    app: &mut App,
    swapchains: &mut [xr::Swapchain<xr::Vulkan>],
    images: &[Vec<vk::Image>],
    colours: [[f32; 4]; 2],
    space: &xr::Space,
    before_end: impl FnOnce(&App, xr::Time),
) -> xr::FrameState {
    let state = app.waiter.wait().expect("xrWaitFrame");
    app.stream.begin().expect("xrBeginFrame");
    for eye in 0..2 {
        let index = swapchains[eye].acquire_image().expect("acquire");
        swapchains[eye]
            .wait_image(xr::Duration::INFINITE)
            .expect("wait");
        app.clear(images[eye][index as usize], colours[eye]);
        swapchains[eye].release_image().expect("release");
    }
    let (_, views) = app
        .session
        .locate_views(
            xr::ViewConfigurationType::PRIMARY_STEREO,
            state.predicted_display_time,
            space,
        )
        .expect("xrLocateViews");
    // Eyes at ∓IPD/2 around the head at the origin, with the Vive Pro Eye's fields of view.
    for (eye, view) in views.iter().enumerate() {
        let x = if eye == 0 { -0.0315 } else { 0.0315 };
        assert!(
            (view.pose.position.x - x).abs() < 1e-6,
            "eye {eye}: {:?}",
            view.pose
        );
        assert_eq!(view.fov.angle_left, sim_headset::eye_fov(eye).angle_left);
    }
    assert_eq!(views[0].fov.angle_left, -views[1].fov.angle_right);
    before_end(app, state.predicted_display_time);
    let proj_views = projection_views(&views, swapchains);
    app.stream
        .end(
            state.predicted_display_time,
            xr::EnvironmentBlendMode::OPAQUE,
            &[&xr::CompositionLayerProjection::new()
                .space(space)
                .views(&proj_views)],
        )
        .expect("xrEndFrame");
    app.poll();
    state
}

fn config(dir: &Path, gaze: &str) -> sim_headset::Config {
    sim_headset::Config {
        gaze: sim_headset::GazeScript::parse(gaze).unwrap(),
        eye_size: (EYE_SIZE, EYE_SIZE),
        save_dir: Some(dir.join("frames")),
        report_path: Some(dir.join("report.json")),
        ..Default::default()
    }
}

fn read_report(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("report.json")).expect("report written");
    serde_json::from_str(&text).unwrap()
}

fn state_names(states: &[xr::SessionState]) -> Vec<String> {
    states.iter().map(|s| format!("{s:?}")).collect()
}

/// The main scenario: 10 frames with a scripted gaze, saved images, visibility mask, clean
/// teardown and a report that says so.
#[test]
fn full_session_with_gaze_images_and_report() {
    let dir = temp_dir("full");
    let script = "0 0 0; 3 10 5; 6 -20 -10 untracked; 8 15 0 invalid";
    let mut app = common::start(config(&dir, script));
    let inst = app.xr_instance.clone();

    // System: the configured size, two views, eye gaze supported.
    let views = inst
        .enumerate_view_configuration_views(app.system, xr::ViewConfigurationType::PRIMARY_STEREO)
        .unwrap();
    assert_eq!(views.len(), 2);
    assert_eq!(views[0].recommended_image_rect_width, EYE_SIZE);
    assert!(common::supports_eye_gaze(&inst, app.system));
    assert_eq!(
        inst.enumerate_environment_blend_modes(
            app.system,
            xr::ViewConfigurationType::PRIMARY_STEREO
        )
        .unwrap(),
        [xr::EnvironmentBlendMode::OPAQUE]
    );

    // Actions: an eye-gaze pose, plus controller bindings as hello_xr suggests them.
    let set = inst.create_action_set("main", "Main", 0).unwrap();
    let gaze = set.create_action::<xr::Posef>("gaze", "Gaze", &[]).unwrap();
    let left = inst.string_to_path("/user/hand/left").unwrap();
    let select = set
        .create_action::<bool>("select", "Select", &[left])
        .unwrap();
    inst.suggest_interaction_profile_bindings(
        inst.string_to_path("/interaction_profiles/ext/eye_gaze_interaction")
            .unwrap(),
        &[xr::Binding::new(
            &gaze,
            inst.string_to_path("/user/eyes_ext/input/gaze_ext/pose")
                .unwrap(),
        )],
    )
    .unwrap();
    inst.suggest_interaction_profile_bindings(
        inst.string_to_path("/interaction_profiles/htc/vive_controller")
            .unwrap(),
        &[xr::Binding::new(
            &select,
            inst.string_to_path("/user/hand/left/input/trigger/click")
                .unwrap(),
        )],
    )
    .unwrap();
    // An unknown profile is rejected (and lands in the report's error list).
    let unknown = inst.suggest_interaction_profile_bindings(
        inst.string_to_path("/interaction_profiles/acme/wand")
            .unwrap(),
        &[xr::Binding::new(
            &select,
            inst.string_to_path("/user/hand/left/input/trigger/click")
                .unwrap(),
        )],
    );
    assert_eq!(
        unknown.unwrap_err(),
        xr::sys::Result::ERROR_PATH_UNSUPPORTED
    );
    app.session.attach_action_sets(&[&set]).unwrap();

    let local = app
        .session
        .create_reference_space(xr::ReferenceSpaceType::LOCAL, xr::Posef::IDENTITY)
        .unwrap();
    let gaze_space = gaze
        .create_space(&app.session, xr::Path::NULL, xr::Posef::IDENTITY)
        .unwrap();

    // Visibility mask, two-call idiom, CCW triangles inside the fov.
    let mask_fn = inst.exts().khr_visibility_mask.unwrap().get_visibility_mask;
    let mut mask = xr::sys::VisibilityMaskKHR {
        ty: xr::sys::StructureType::VISIBILITY_MASK_KHR,
        next: std::ptr::null_mut(),
        vertex_capacity_input: 0,
        vertex_count_output: 0,
        vertices: std::ptr::null_mut(),
        index_capacity_input: 0,
        index_count_output: 0,
        indices: std::ptr::null_mut(),
    };
    // SAFETY: valid session and output structure; arrays sized by the first call.
    unsafe {
        let r = mask_fn(
            app.session.as_raw(),
            xr::ViewConfigurationType::PRIMARY_STEREO,
            0,
            xr::VisibilityMaskTypeKHR::HIDDEN_TRIANGLE_MESH,
            &mut mask,
        );
        assert_eq!(r, xr::sys::Result::SUCCESS);
        assert!(mask.vertex_count_output > 64 && mask.index_count_output.is_multiple_of(3));
        let mut vertices = vec![xr::Vector2f::default(); mask.vertex_count_output as usize];
        let mut indices = vec![0u32; mask.index_count_output as usize];
        mask.vertex_capacity_input = vertices.len() as u32;
        mask.index_capacity_input = indices.len() as u32;
        mask.vertices = vertices.as_mut_ptr();
        mask.indices = indices.as_mut_ptr();
        let r = mask_fn(
            app.session.as_raw(),
            xr::ViewConfigurationType::PRIMARY_STEREO,
            0,
            xr::VisibilityMaskTypeKHR::HIDDEN_TRIANGLE_MESH,
            &mut mask,
        );
        assert_eq!(r, xr::sys::Result::SUCCESS);
        for t in indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| vertices[t[k] as usize]);
            let area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            assert!(area > 0.0, "clockwise hidden triangle");
        }
        let fov = sim_headset::eye_fov(0);
        assert!(vertices
            .iter()
            .all(|v| v.x >= fov.angle_left.tan() - 1e-5 && v.x <= fov.angle_right.tan() + 1e-5));
    }

    // Two swapchains of different formats, to exercise both conversions when saving.
    let (sc0, img0) = app.swapchain(vk::Format::R8G8B8A8_SRGB);
    let (sc1, img1) = app.swapchain(vk::Format::R16G16B16A16_SFLOAT);
    let mut swapchains = [sc0, sc1];
    let images = [img0, img1];

    app.poll();
    assert_eq!(state_names(&app.states), ["IDLE", "READY"]);
    app.session
        .begin(xr::ViewConfigurationType::PRIMARY_STEREO)
        .unwrap();
    // Beginning twice is an error.
    assert_eq!(
        app.session
            .begin(xr::ViewConfigurationType::PRIMARY_STEREO)
            .unwrap_err(),
        xr::sys::Result::ERROR_SESSION_RUNNING
    );

    // Linear colours: eye 0 is sRGB-encoded by the hardware, eye 1 by the runtime.
    let colours = [[0.5, 0.0, 0.25, 1.0], [0.0, 0.5, 1.0, 0.0]];
    let expected_rgb = [[188u8, 0, 137], [0, 188, 255]];
    let mut previous_time = None;
    for frame in 0..10u64 {
        let mut located = None;
        let state = render_frame(
            &mut app,
            &mut swapchains,
            &images,
            colours,
            &local,
            |app, time| {
                app.session
                    .sync_actions(&[xr::ActiveActionSet::new(&set)])
                    .unwrap();
                let active = gaze.is_active(&app.session, xr::Path::NULL).unwrap();
                let mut sample = xr::sys::EyeGazeSampleTimeEXT {
                    ty: xr::sys::StructureType::EYE_GAZE_SAMPLE_TIME_EXT,
                    next: std::ptr::null_mut(),
                    time: xr::Time::from_nanos(0),
                };
                let mut location = xr::sys::SpaceLocation {
                    ty: xr::sys::StructureType::SPACE_LOCATION,
                    next: &mut sample as *mut _ as *mut _,
                    location_flags: xr::SpaceLocationFlags::EMPTY,
                    pose: xr::Posef::IDENTITY,
                };
                // SAFETY: valid spaces and output chain.
                let r = unsafe {
                    (app.xr_instance.fp().locate_space)(
                        gaze_space.as_raw(),
                        local.as_raw(),
                        time,
                        &mut location,
                    )
                };
                assert_eq!(r, xr::sys::Result::SUCCESS);
                located = Some((
                    active,
                    location.location_flags,
                    location.pose,
                    sample.time,
                    time,
                ));
            },
        );
        if let Some(previous) = previous_time {
            assert_eq!(
                state.predicted_display_time.as_nanos() - previous,
                1_000_000_000 / 90
            );
        }
        previous_time = Some(state.predicted_display_time.as_nanos());
        // Frame 0 is SYNCHRONIZED (nothing shown), VISIBLE from frame 1.
        assert_eq!(state.should_render, frame >= 1, "frame {frame}");

        let (active, flags, pose, sample_time, time) = located.unwrap();
        // Actions are only active when synced while FOCUSED, which starts at frame 2.
        assert_eq!(active, frame >= 2, "frame {frame}");
        let tracked = xr::SpaceLocationFlags::ORIENTATION_VALID
            | xr::SpaceLocationFlags::POSITION_VALID
            | xr::SpaceLocationFlags::ORIENTATION_TRACKED
            | xr::SpaceLocationFlags::POSITION_TRACKED;
        let untracked =
            xr::SpaceLocationFlags::ORIENTATION_VALID | xr::SpaceLocationFlags::POSITION_VALID;
        let (want_flags, want_dir) = match frame {
            0 | 1 => (xr::SpaceLocationFlags::EMPTY, None),
            2 => (tracked, Some(direction(0.0, 0.0))),
            3..=5 => (tracked, Some(direction(10.0, 5.0))),
            6 | 7 => (untracked, Some(direction(-20.0, -10.0))),
            _ => (xr::SpaceLocationFlags::EMPTY, None),
        };
        assert_eq!(flags, want_flags, "frame {frame}");
        if let Some(d) = want_dir {
            assert!(
                close(forward(pose.orientation), d),
                "frame {frame}: {pose:?}"
            );
            assert!(close(
                [pose.position.x, pose.position.y, pose.position.z],
                [0.0; 3]
            ));
            // The tracker's newest 120 Hz sample when the gaze was located, right after
            // xrWaitFrame: two display periods (and less than one sample) before display.
            let (time, sample_time) = (time.as_nanos(), sample_time.as_nanos());
            let age = time - sample_time;
            assert_eq!(
                sample_time % sim_headset::GAZE_PERIOD_NS,
                0,
                "frame {frame}"
            );
            assert!(
                (sim_headset::FRAME_PERIOD_NS..=sim_headset::LEAD_NS + sim_headset::GAZE_PERIOD_NS)
                    .contains(&age),
                "frame {frame}: sample {sample_time} for display {time}"
            );
        }
    }

    // Out-of-order calls are refused: xrBeginFrame without xrWaitFrame.
    let begin_info = xr::sys::FrameBeginInfo {
        ty: xr::sys::StructureType::FRAME_BEGIN_INFO,
        next: std::ptr::null(),
    };
    // SAFETY: valid session and input structure.
    let r = unsafe { (inst.fp().begin_frame)(app.session.as_raw(), &begin_info) };
    assert_eq!(r, xr::sys::Result::ERROR_CALL_ORDER_INVALID);

    app.session.request_exit().unwrap();
    app.poll();
    app.session.end().unwrap();
    app.poll();
    assert_eq!(
        state_names(&app.states),
        [
            "IDLE",
            "READY",
            "SYNCHRONIZED",
            "VISIBLE",
            "FOCUSED",
            "VISIBLE",
            "SYNCHRONIZED",
            "STOPPING",
            "IDLE",
            "EXITING"
        ]
    );

    drop((swapchains, gaze_space, local, gaze, select, set, inst));
    app.finish();

    // Saved images: every frame, both eyes, the cleared colours.
    for frame in 0..10 {
        for (eye, expected) in expected_rgb.iter().enumerate() {
            let path = dir.join(format!("frames/frame-{frame:04}-eye-{eye}.png"));
            let (w, h, rgb) = read_png(&path);
            assert_eq!((w, h), (EYE_SIZE, EYE_SIZE));
            for px in rgb.chunks(3) {
                for (got, want) in px.iter().zip(expected) {
                    let d = (*got as i32 - *want as i32).abs();
                    assert!(d <= 1, "{}: pixel {px:?} vs {expected:?}", path.display());
                }
            }
        }
    }

    let report = read_report(&dir);
    assert_eq!(report["frames_submitted"], 10);
    assert_eq!(report["images_saved"], 20);
    assert_eq!(report["clean_teardown"], true, "{report:#}");
    for kind in ["sessions", "swapchains", "spaces", "actions", "action_sets"] {
        assert_eq!(report["alive_at_instance_destroy"][kind], 0, "{kind}");
    }
    assert_eq!(report["vulkan_alive_at_instance_destroy"]["images"], 0);
    assert_eq!(report["session_states"].as_array().unwrap().len(), 10);
    let errors: Vec<(String, String)> = report["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["function"].as_str().unwrap().into(),
                e["result"].as_str().unwrap().into(),
            )
        })
        .collect();
    assert_eq!(
        errors,
        [
            (
                "xrSuggestInteractionProfileBindings".into(),
                "XR_ERROR_PATH_UNSUPPORTED".into()
            ),
            ("xrBeginSession".into(), "XR_ERROR_SESSION_RUNNING".into()),
            ("xrBeginFrame".into(), "XR_ERROR_CALL_ORDER_INVALID".into()),
        ]
    );
    assert_eq!(
        common::VALIDATION_MESSAGES.load(Ordering::SeqCst),
        0,
        "{:?}",
        common::validation_log()
    );
}

/// The "user" quits at frame 3: the session walks down to STOPPING on its own, and the
/// report counts what the app leaked.
#[test]
fn scripted_exit_and_leak_report() {
    let dir = temp_dir("exit");
    let mut cfg = config(&dir, "");
    cfg.exit_at_frame = Some(3);
    cfg.save_dir = None;
    let mut app = common::start(cfg);
    let local = app
        .session
        .create_reference_space(xr::ReferenceSpaceType::STAGE, xr::Posef::IDENTITY)
        .unwrap();
    // A space made through the raw API and never destroyed: a leak the report must show
    // (the openxr crate's wrappers would keep the session alive instead).
    let info = xr::sys::ReferenceSpaceCreateInfo {
        ty: xr::sys::StructureType::REFERENCE_SPACE_CREATE_INFO,
        next: std::ptr::null(),
        reference_space_type: xr::ReferenceSpaceType::VIEW,
        pose_in_reference_space: xr::Posef::IDENTITY,
    };
    let mut leaked = xr::sys::Space::NULL;
    // SAFETY: valid session, input and output.
    let r = unsafe {
        (app.xr_instance.fp().create_reference_space)(app.session.as_raw(), &info, &mut leaked)
    };
    assert_eq!(r, xr::sys::Result::SUCCESS);
    let (sc0, img0) = app.swapchain(vk::Format::B8G8R8A8_SRGB);
    let (sc1, img1) = app.swapchain(vk::Format::B8G8R8A8_SRGB);
    let mut swapchains = [sc0, sc1];
    let images = [img0, img1];
    app.poll();
    app.session
        .begin(xr::ViewConfigurationType::PRIMARY_STEREO)
        .unwrap();
    let white = [1.0; 4];
    for _ in 0..3 {
        render_frame(
            &mut app,
            &mut swapchains,
            &images,
            [white, white],
            &local,
            |_, _| {},
        );
    }
    let state = render_frame(
        &mut app,
        &mut swapchains,
        &images,
        [white, white],
        &local,
        |_, _| {},
    );
    assert!(!state.should_render, "frame 3 is after the user quit");
    assert_eq!(app.states.last(), Some(&xr::SessionState::STOPPING));
    app.session.end().unwrap();
    app.poll();
    assert_eq!(app.states.last(), Some(&xr::SessionState::EXITING));

    drop((swapchains, local));
    app.finish();
    let report = read_report(&dir);
    assert_eq!(report["destroyed_with_parent"]["spaces"], 1);
    assert_eq!(report["clean_teardown"], false);
    assert_eq!(report["frames_submitted"], 4);
    assert_eq!(
        common::VALIDATION_MESSAGES.load(Ordering::SeqCst),
        0,
        "{:?}",
        common::validation_log()
    );
}

/// Session loss at frame 2: LOSS_PENDING, then XR_ERROR_SESSION_LOST.
#[test]
fn scripted_loss() {
    let dir = temp_dir("loss");
    let mut cfg = config(&dir, "");
    cfg.loss_at_frame = Some(2);
    cfg.save_dir = None;
    let mut app = common::start(cfg);
    let local = app
        .session
        .create_reference_space(xr::ReferenceSpaceType::LOCAL, xr::Posef::IDENTITY)
        .unwrap();
    let (sc0, img0) = app.swapchain(vk::Format::R8G8B8A8_UNORM);
    let (sc1, img1) = app.swapchain(vk::Format::R8G8B8A8_UNORM);
    let mut swapchains = [sc0, sc1];
    let images = [img0, img1];
    app.poll();
    app.session
        .begin(xr::ViewConfigurationType::PRIMARY_STEREO)
        .unwrap();
    for _ in 0..2 {
        render_frame(
            &mut app,
            &mut swapchains,
            &images,
            [[0.0; 4]; 2],
            &local,
            |_, _| {},
        );
    }
    // The openxr crate maps the success code XR_SESSION_LOSS_PENDING to Ok.
    app.waiter
        .wait()
        .expect("the loss frame's wait still succeeds");
    app.poll();
    assert_eq!(app.states.last(), Some(&xr::SessionState::LOSS_PENDING));
    assert_eq!(
        app.stream.begin().unwrap_err(),
        xr::sys::Result::ERROR_SESSION_LOST
    );
    assert_eq!(
        app.session.request_exit().unwrap_err(),
        xr::sys::Result::ERROR_SESSION_LOST
    );
    drop((swapchains, local));
    app.finish();
    let report = read_report(&dir);
    assert_eq!(report["clean_teardown"], true);
    assert_eq!(
        common::VALIDATION_MESSAGES.load(Ordering::SeqCst),
        0,
        "{:?}",
        common::validation_log()
    );
}
