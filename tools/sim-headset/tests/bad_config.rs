//! A bad `SIM_HEADSET_*` value makes xrCreateInstance fail with
//! XR_ERROR_INITIALIZATION_FAILED (and a message on stderr) instead of running with a
//! configuration the test author did not mean. One test: the environment is process-global.

use openxr as xr;

#[test]
fn bad_environment_fails_instance_creation() {
    std::env::set_var("SIM_HEADSET_SIZE", "64 by 64");
    // SAFETY: the simulated headset implements every core function.
    let entry = unsafe {
        xr::Entry::from_get_instance_proc_addr(sim_headset::get_instance_proc_addr(), &())
    }
    .unwrap();
    let err = entry
        .create_instance(
            &xr::ApplicationInfo {
                application_name: "bad config",
                ..Default::default()
            },
            &xr::ExtensionSet::default(),
            &[],
            &(),
        )
        .err();
    assert_eq!(err, Some(xr::sys::Result::ERROR_INITIALIZATION_FAILED));
    assert!(sim_headset::Config::from_env()
        .unwrap_err()
        .to_string()
        .contains("SIM_HEADSET_SIZE"));

    // The Rust-level override takes precedence over the environment on this thread.
    sim_headset::set_config_override(Some(sim_headset::Config::default()));
    let instance = entry
        .create_instance(
            &xr::ApplicationInfo {
                application_name: "override",
                ..Default::default()
            },
            &xr::ExtensionSet::default(),
            &[],
            &(),
        )
        .expect("override ignores the bad environment");
    // An extension the headset does not offer is refused.
    let mut exts = xr::ExtensionSet::default();
    exts.khr_opengl_enable = true;
    let err = entry
        .create_instance(
            &xr::ApplicationInfo {
                application_name: "gl",
                ..Default::default()
            },
            &exts,
            &[],
            &(),
        )
        .err();
    assert_eq!(err, Some(xr::sys::Result::ERROR_EXTENSION_NOT_PRESENT));
    drop(instance);
}
