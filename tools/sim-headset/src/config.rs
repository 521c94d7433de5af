//! What the simulated headset does, read from `SIM_HEADSET_*` environment variables at
//! `xrCreateInstance`, or set per thread from Rust with [`set_config_override`] so that
//! tests running in parallel threads of one process do not fight over the environment.

use std::cell::RefCell;
use std::fmt;
use std::path::PathBuf;

use crate::gaze_script::GazeScript;

/// How the simulated eye tracker presents itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EyeGazeMode {
    /// XR_EXT_eye_gaze_interaction offered, supported and delivering the script.
    #[default]
    On,
    /// The extension is not offered at all.
    Off,
    /// Offered, but `supportsEyeGazeInteraction` is false (like SteamVR without a tracker).
    Unsupported,
    /// Supported, but the gaze action never becomes active.
    Inactive,
}

/// Everything configurable about the headset.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// `SIM_HEADSET_GAZE` / `SIM_HEADSET_GAZE_FILE`.
    pub gaze: GazeScript,
    /// `SIM_HEADSET_EYE_GAZE`.
    pub eye_gaze: EyeGazeMode,
    /// `SIM_HEADSET_VISIBILITY_MASK`: whether XR_KHR_visibility_mask is offered.
    pub visibility_mask: bool,
    /// `SIM_HEADSET_SIZE`: recommended image size per eye (width, height).
    pub eye_size: (u32, u32),
    /// `SIM_HEADSET_SAVE_DIR`: where submitted eye images are written as PNG.
    pub save_dir: Option<PathBuf>,
    /// `SIM_HEADSET_EXIT_AT_FRAME`: the "user" quits at this frame (session goes STOPPING).
    pub exit_at_frame: Option<u64>,
    /// `SIM_HEADSET_LOSS_AT_FRAME`: the session is lost at this frame (of its own frames).
    pub loss_at_frame: Option<u64>,
    /// `SIM_HEADSET_LOSSES`: how many of the instance's sessions are lost that way (None:
    /// every one), so that a session the app creates after a loss can run on.
    pub losses: Option<u64>,
    /// `SIM_HEADSET_REPORT`: JSON report written at `xrDestroyInstance`.
    pub report_path: Option<PathBuf>,
    /// `SIM_HEADSET_REALTIME=1`: `xrWaitFrame` sleeps to pace frames at 90 Hz.
    pub realtime: bool,
    /// `SIM_HEADSET_NO_RENDER=FROM-TO`: frames (inclusive) whose `shouldRender` is false, as
    /// when the compositor shows something else over the app.
    pub no_render: Option<(u64, u64)>,
    /// `SIM_HEADSET_COMPOSITOR_MS`: the compositor's time per frame; over a display period,
    /// frames are shown every few periods (the ones between missed).
    pub compositor_ms: f64,
}

/// The Vive Pro Eye's recommended per-eye size, which the simulated headset imitates.
pub const DEFAULT_EYE_SIZE: (u32, u32) = (1440, 1600);
/// Largest image size accepted anywhere (swapchains, `SIM_HEADSET_SIZE`).
pub const MAX_IMAGE_SIZE: u32 = 8192;

impl Default for Config {
    fn default() -> Self {
        Self {
            gaze: GazeScript::default(),
            eye_gaze: EyeGazeMode::On,
            visibility_mask: true,
            eye_size: DEFAULT_EYE_SIZE,
            save_dir: None,
            exit_at_frame: None,
            loss_at_frame: None,
            losses: None,
            report_path: None,
            realtime: false,
            no_render: None,
            compositor_ms: 0.0,
        }
    }
}

/// A bad configuration value: which variable, and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigError {
    pub variable: &'static str,
    pub message: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "sim-headset: bad {}: {}", self.variable, self.message)
    }
}

impl std::error::Error for ConfigError {}

thread_local! {
    static OVERRIDE: RefCell<Option<Config>> = const { RefCell::new(None) };
}

/// Sets (or with `None` clears) the configuration used by `xrCreateInstance` calls made
/// **on the calling thread**, instead of the environment. Thread-local on purpose: Rust
/// tests in one binary run in parallel threads and the environment is process-global.
pub fn set_config_override(config: Option<Config>) {
    OVERRIDE.with(|o| *o.borrow_mut() = config);
}

/// The configuration for a new instance: this thread's override, else the environment.
pub fn current() -> Result<Config, ConfigError> {
    match OVERRIDE.with(|o| o.borrow().clone()) {
        Some(config) => Ok(config),
        None => Config::from_env(),
    }
}

impl Config {
    /// Reads the `SIM_HEADSET_*` variables; unset or empty variables take the defaults.
    pub fn from_env() -> Result<Self, ConfigError> {
        Self::from_lookup(|name| std::env::var(name).ok())
    }

    /// Like [`Config::from_env`] with any variable source (used by the unit tests).
    pub fn from_lookup(lookup: impl Fn(&str) -> Option<String>) -> Result<Self, ConfigError> {
        let get = |name: &str| lookup(name).filter(|v| !v.trim().is_empty());
        let mut config = Config::default();

        let inline = get("SIM_HEADSET_GAZE");
        let file = get("SIM_HEADSET_GAZE_FILE");
        config.gaze = match (inline, file) {
            (Some(_), Some(_)) => {
                return Err(ConfigError {
                    variable: "SIM_HEADSET_GAZE",
                    message: "SIM_HEADSET_GAZE and SIM_HEADSET_GAZE_FILE are both set; use one"
                        .into(),
                })
            }
            (Some(text), None) => GazeScript::parse(&text).map_err(|e| ConfigError {
                variable: "SIM_HEADSET_GAZE",
                message: e.to_string(),
            })?,
            (None, Some(path)) => {
                let text = std::fs::read_to_string(&path).map_err(|e| ConfigError {
                    variable: "SIM_HEADSET_GAZE_FILE",
                    message: format!("cannot read {path:?}: {e}"),
                })?;
                GazeScript::parse(&text).map_err(|e| ConfigError {
                    variable: "SIM_HEADSET_GAZE_FILE",
                    message: format!("{path}: {e}"),
                })?
            }
            (None, None) => GazeScript::default(),
        };

        if let Some(v) = get("SIM_HEADSET_EYE_GAZE") {
            config.eye_gaze = match v.trim() {
                "on" => EyeGazeMode::On,
                "off" => EyeGazeMode::Off,
                "unsupported" => EyeGazeMode::Unsupported,
                "inactive" => EyeGazeMode::Inactive,
                other => {
                    return Err(ConfigError {
                        variable: "SIM_HEADSET_EYE_GAZE",
                        message: format!("{other:?} is not one of on, off, unsupported, inactive"),
                    })
                }
            };
        }
        if let Some(v) = get("SIM_HEADSET_VISIBILITY_MASK") {
            config.visibility_mask = parse_switch("SIM_HEADSET_VISIBILITY_MASK", &v)?;
        }
        if let Some(v) = get("SIM_HEADSET_SIZE") {
            config.eye_size = parse_size(&v)?;
        }
        config.save_dir = get("SIM_HEADSET_SAVE_DIR").map(PathBuf::from);
        if let Some(v) = get("SIM_HEADSET_EXIT_AT_FRAME") {
            config.exit_at_frame = Some(parse_frame("SIM_HEADSET_EXIT_AT_FRAME", &v)?);
        }
        if let Some(v) = get("SIM_HEADSET_LOSS_AT_FRAME") {
            config.loss_at_frame = Some(parse_frame("SIM_HEADSET_LOSS_AT_FRAME", &v)?);
        }
        if let Some(v) = get("SIM_HEADSET_LOSSES") {
            config.losses = Some(parse_frame("SIM_HEADSET_LOSSES", &v)?);
        }
        config.report_path = get("SIM_HEADSET_REPORT").map(PathBuf::from);
        if let Some(v) = get("SIM_HEADSET_REALTIME") {
            config.realtime = parse_switch("SIM_HEADSET_REALTIME", &v)?;
        }
        if let Some(v) = get("SIM_HEADSET_NO_RENDER") {
            config.no_render = Some(parse_frame_range("SIM_HEADSET_NO_RENDER", &v)?);
        }
        if let Some(v) = get("SIM_HEADSET_COMPOSITOR_MS") {
            config.compositor_ms = v
                .trim()
                .parse()
                .ok()
                .filter(|ms: &f64| (0.0..=1000.0).contains(ms))
                .ok_or_else(|| ConfigError {
                    variable: "SIM_HEADSET_COMPOSITOR_MS",
                    message: format!("{v:?} is not milliseconds from 0 to 1000"),
                })?;
        }
        Ok(config)
    }
}

fn parse_switch(variable: &'static str, value: &str) -> Result<bool, ConfigError> {
    match value.trim() {
        "1" | "on" | "true" | "yes" => Ok(true),
        "0" | "off" | "false" | "no" => Ok(false),
        other => Err(ConfigError {
            variable,
            message: format!("{other:?} is not on/off (or 1/0)"),
        }),
    }
}

fn parse_frame(variable: &'static str, value: &str) -> Result<u64, ConfigError> {
    value.trim().parse().map_err(|_| ConfigError {
        variable,
        message: format!("{value:?} is not a frame number (a non-negative integer)"),
    })
}

fn parse_frame_range(variable: &'static str, value: &str) -> Result<(u64, u64), ConfigError> {
    let fail = || ConfigError {
        variable,
        message: format!("{value:?} is not FROM-TO, two frame numbers with FROM <= TO"),
    };
    let (from, to) = value.trim().split_once('-').ok_or_else(fail)?;
    let from: u64 = from.trim().parse().map_err(|_| fail())?;
    let to: u64 = to.trim().parse().map_err(|_| fail())?;
    match from <= to {
        true => Ok((from, to)),
        false => Err(fail()),
    }
}

fn parse_size(value: &str) -> Result<(u32, u32), ConfigError> {
    let fail = || ConfigError {
        variable: "SIM_HEADSET_SIZE",
        message: format!("{value:?} is not WIDTHxHEIGHT with each side in 1..={MAX_IMAGE_SIZE}"),
    };
    let (w, h) = value.trim().split_once(['x', 'X']).ok_or_else(fail)?;
    let w: u32 = w.trim().parse().map_err(|_| fail())?;
    let h: u32 = h.trim().parse().map_err(|_| fail())?;
    if !(1..=MAX_IMAGE_SIZE).contains(&w) || !(1..=MAX_IMAGE_SIZE).contains(&h) {
        return Err(fail());
    }
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn parse(vars: &[(&str, &str)]) -> Result<Config, ConfigError> {
        let map: HashMap<String, String> = vars
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        Config::from_lookup(|k| map.get(k).cloned())
    }

    #[test]
    fn defaults_without_variables() {
        assert_eq!(parse(&[]).unwrap(), Config::default());
        assert_eq!(Config::default().eye_size, (1440, 1600));
    }

    #[test]
    fn reads_every_variable() {
        let c = parse(&[
            ("SIM_HEADSET_GAZE", "0 10 5; 3 -4 2 invalid"),
            ("SIM_HEADSET_EYE_GAZE", "inactive"),
            ("SIM_HEADSET_VISIBILITY_MASK", "off"),
            ("SIM_HEADSET_SIZE", "64x48"),
            ("SIM_HEADSET_SAVE_DIR", "/tmp/x"),
            ("SIM_HEADSET_EXIT_AT_FRAME", "12"),
            ("SIM_HEADSET_LOSS_AT_FRAME", "20"),
            ("SIM_HEADSET_REPORT", "/tmp/r.json"),
            ("SIM_HEADSET_REALTIME", "1"),
            ("SIM_HEADSET_NO_RENDER", "5-9"),
            ("SIM_HEADSET_LOSSES", "1"),
            ("SIM_HEADSET_COMPOSITOR_MS", "20"),
        ])
        .unwrap();
        assert_eq!(c.gaze.keyframes().len(), 2);
        assert_eq!(c.eye_gaze, EyeGazeMode::Inactive);
        assert!(!c.visibility_mask);
        assert_eq!(c.eye_size, (64, 48));
        assert_eq!(c.save_dir, Some(PathBuf::from("/tmp/x")));
        assert_eq!(c.exit_at_frame, Some(12));
        assert_eq!(c.loss_at_frame, Some(20));
        assert!(c.realtime);
        assert_eq!(c.no_render, Some((5, 9)));
        assert_eq!(c.losses, Some(1));
        assert_eq!(c.compositor_ms, 20.0);
    }

    #[test]
    fn bad_values_name_their_variable() {
        for (var, value) in [
            ("SIM_HEADSET_EYE_GAZE", "maybe"),
            ("SIM_HEADSET_VISIBILITY_MASK", "2"),
            ("SIM_HEADSET_SIZE", "64"),
            ("SIM_HEADSET_SIZE", "0x10"),
            ("SIM_HEADSET_SIZE", "99999x10"),
            ("SIM_HEADSET_EXIT_AT_FRAME", "-1"),
            ("SIM_HEADSET_LOSS_AT_FRAME", "soon"),
            ("SIM_HEADSET_REALTIME", "fast"),
            ("SIM_HEADSET_NO_RENDER", "9-5"),
            ("SIM_HEADSET_NO_RENDER", "7"),
            ("SIM_HEADSET_COMPOSITOR_MS", "-3"),
            ("SIM_HEADSET_COMPOSITOR_MS", "slow"),
            ("SIM_HEADSET_GAZE", "0 0"),
            ("SIM_HEADSET_GAZE_FILE", "/nonexistent/gaze.txt"),
        ] {
            let err = parse(&[(var, value)]).unwrap_err();
            assert_eq!(err.variable, var, "{var}={value}: {err}");
            assert!(err.to_string().contains(var));
        }
    }

    #[test]
    fn inline_and_file_gaze_are_exclusive() {
        let err = parse(&[
            ("SIM_HEADSET_GAZE", "0 0 0"),
            ("SIM_HEADSET_GAZE_FILE", "/tmp/g"),
        ])
        .unwrap_err();
        assert!(err.message.contains("both"));
    }

    #[test]
    fn override_is_per_thread() {
        let c = Config {
            eye_size: (8, 8),
            ..Config::default()
        };
        set_config_override(Some(c.clone()));
        assert_eq!(current().unwrap().eye_size, (8, 8));
        let other = std::thread::spawn(|| OVERRIDE.with(|o| o.borrow().is_none()))
            .join()
            .unwrap();
        assert!(other);
        set_config_override(None);
    }
}
