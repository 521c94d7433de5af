//! The runtime as a shared library behind the real Khronos OpenXR loader (Debian's
//! libopenxr-loader1), found through an `XR_RUNTIME_JSON` manifest. The environment is
//! process-global, so this binary holds exactly one test.

use std::path::PathBuf;

use openxr as xr;

/// The freshest built `libsim_headset.so`: `cargo build` puts it in target/debug,
/// `cargo test` (which builds the cdylib with the tests) in target/debug/deps.
fn runtime_library() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let candidates = [
        deps.join("libsim_headset.so"),
        deps.parent().unwrap().join("libsim_headset.so"),
    ];
    candidates
        .iter()
        .filter_map(|p| Some((std::fs::metadata(p).ok()?.modified().ok()?, p.clone())))
        .max()
        .map(|(_, p)| p)
        .unwrap_or_else(|| {
            panic!(
                "the runtime library is missing (looked for {candidates:?}); build it with `cargo build -p sim-headset`"
            )
        })
}

#[test]
fn loader_negotiates_and_drives_the_runtime() {
    let dir = std::env::temp_dir().join(format!("sim-headset-loader-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let manifest = dir.join("runtime.json");
    let json = serde_json::json!({
        "file_format_version": "1.0.0",
        "runtime": { "name": "fovea simulated headset", "library_path": runtime_library() },
    });
    std::fs::write(&manifest, json.to_string()).unwrap();
    let report = dir.join("report.json");
    let _ = std::fs::remove_file(&report);
    // The loaded library reads its own configuration from the environment.
    std::env::set_var("XR_RUNTIME_JSON", &manifest);
    std::env::set_var("SIM_HEADSET_SIZE", "32x16");
    std::env::set_var("SIM_HEADSET_EYE_GAZE", "unsupported");
    std::env::set_var("SIM_HEADSET_REPORT", &report);

    // SAFETY: loads the system's Khronos loader.
    let entry =
        unsafe { xr::Entry::load(&()) }.expect("libopenxr_loader.so.1 (install libopenxr-loader1)");
    let available = entry
        .enumerate_extensions()
        .expect("extensions through the loader");
    assert!(available.khr_vulkan_enable2);
    assert!(
        available.ext_eye_gaze_interaction,
        "offered even when unsupported"
    );
    assert!(available.khr_visibility_mask);
    let mut exts = xr::ExtensionSet::default();
    exts.khr_vulkan_enable2 = true;
    exts.ext_eye_gaze_interaction = true;
    let instance = entry
        .create_instance(
            &xr::ApplicationInfo {
                application_name: "sim-headset loader test",
                ..Default::default()
            },
            &exts,
            &[],
            &(),
        )
        .expect("xrCreateInstance through the loader");
    assert_eq!(
        instance.properties().unwrap().runtime_name,
        "fovea simulated headset"
    );
    let system = instance
        .system(xr::FormFactor::HEAD_MOUNTED_DISPLAY)
        .unwrap();
    let views = instance
        .enumerate_view_configuration_views(system, xr::ViewConfigurationType::PRIMARY_STEREO)
        .unwrap();
    assert_eq!(
        (
            views[1].recommended_image_rect_width,
            views[1].recommended_image_rect_height
        ),
        (32, 16)
    );
    let path = instance.string_to_path("/user/eyes_ext").unwrap();
    assert_eq!(instance.path_to_string(path).unwrap(), "/user/eyes_ext");
    assert_eq!(
        instance.string_to_path("/User//bad").unwrap_err(),
        xr::sys::Result::ERROR_PATH_FORMAT_INVALID
    );
    let reqs = instance
        .graphics_requirements::<xr::Vulkan>(system)
        .unwrap();
    assert_eq!(reqs.max_api_version_supported.minor(), 4);
    drop(instance);

    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&report).expect("report written by the loaded runtime"),
    )
    .unwrap();
    assert_eq!(report["clean_teardown"], true);
    assert_eq!(report["errors"][0]["function"], "xrStringToPath");
    assert_eq!(
        report["errors"][0]["result"],
        "XR_ERROR_PATH_FORMAT_INVALID"
    );
}
