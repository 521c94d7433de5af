//! FovVideoVDP's JOD score (Mantiuk et al. 2021): how a foveated viewer judges an image or a
//! video against its reference, 10 = indistinguishable. The metric is pyfvvdp, a peer tool
//! like Mitsuba: `tools/setup-fvvdp.sh` makes a venv with it, and [`Fvvdp`] runs
//! `tools/fvvdp/jod_server.py` (built into the binary) with that venv's Python, once per run,
//! speaking one JSON line per request. Images travel as raw float files in a private
//! temporary directory.
//!
//! What fovea hands the metric is what the headset shows: the linear image clamped to [0, 1]
//! and sRGB-encoded, on the display's photometry (`--display`'s profile; by default the HTC
//! Vive Pro's, pyfvvdp's `htc_vive_pro`: 133 cd/m² peak, 0.1 black), at the eye image's own
//! resolution and horizontal field of view, foveated around the gaze pixel.

use crate::foveation::{DisplayProfile, ImageGeometry, Photometry};
use crate::render::display::DisplayTransform;
use crate::render::output::linear_to_srgb;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

/// The venv `tools/setup-fvvdp.sh` makes, at the repository root.
pub const VENV_DIR: &str = ".venv-fvvdp";
/// Overrides where the venv is looked for.
pub const VENV_ENV: &str = "FOVEA_FVVDP_VENV";
/// The best score: the test cannot be told from the reference.
pub const JOD_MAX: f64 = 10.0;

const SERVER: &str = include_str!("../../tools/fvvdp/jod_server.py");
const HOW_TO_GET_IT: &str = "run `bash tools/setup-fvvdp.sh` in fovea's repository (it makes \
     .venv-fvvdp/ with pyfvvdp from the Python package index), or set FOVEA_FVVDP_VENV to a \
     venv that has pyfvvdp";

/// Why no JOD score came back.
#[derive(Debug, thiserror::Error)]
pub enum JodError {
    #[error("FovVideoVDP's venv not found (looked for {}); {HOW_TO_GET_IT}", searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "))]
    NotFound { searched: Vec<PathBuf> },
    #[error("cannot start FovVideoVDP with {}: {source}; {HOW_TO_GET_IT}", python.display())]
    Start {
        python: PathBuf,
        source: std::io::Error,
    },
    #[error("FovVideoVDP ({}) failed: {message}{}; if the venv is broken, delete it and {HOW_TO_GET_IT}", python.display(), stderr_tail(stderr))]
    Server {
        python: PathBuf,
        message: String,
        stderr: String,
    },
    #[error("FovVideoVDP's input file {}: {source}", path.display())]
    File {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("FovVideoVDP input: {0}")]
    Input(String),
}

fn stderr_tail(stderr: &str) -> String {
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    match lines.len() {
        0 => String::new(),
        n => format!(
            " (its last words: {})",
            lines[n.saturating_sub(3)..].join(" | ")
        ),
    }
}

/// The venv's Python: `$FOVEA_FVVDP_VENV`, else `.venv-fvvdp` in the working directory or one
/// above it, or above fovea's executable (`target/release/fovea` inside the repository).
pub fn locate_python() -> Result<PathBuf, JodError> {
    let mut roots: Vec<PathBuf> = Vec::new();
    if let Some(venv) = std::env::var_os(VENV_ENV) {
        roots.push(PathBuf::from(venv));
    } else {
        let starts = [
            std::env::current_dir().ok(),
            std::env::current_exe()
                .ok()
                .and_then(|e| e.parent().map(Path::to_path_buf)),
        ];
        for start in starts.into_iter().flatten() {
            roots.extend(start.ancestors().map(|a| a.join(VENV_DIR)));
        }
    }
    let pythons = |root: &PathBuf| [root.join("bin/python"), root.join("Scripts/python.exe")];
    roots
        .iter()
        .flat_map(pythons)
        .find(|p| p.is_file())
        .ok_or(JodError::NotFound { searched: roots })
}

/// The horizontal field of view, in degrees, of a symmetric image with `image`'s pixel size at
/// its axis: what pyfvvdp's display geometry takes (it assumes a centred, square-pixel view).
pub fn fov_horizontal_deg(image: &ImageGeometry) -> f64 {
    (2.0 * ((image.tan_right - image.tan_left) / 2.0).atan()).to_degrees()
}

/// One comparison: `frames` images of `image`'s size, each linear RGB (3 floats a pixel),
/// with the gaze pixel of each frame.
pub struct JodInput<'a> {
    pub test: &'a [&'a [f32]],
    pub reference: &'a [&'a [f32]],
    pub image: &'a ImageGeometry,
    pub fixation: &'a [[f64; 2]],
    /// Frames per second of a video (ignored for one frame).
    pub fps: f64,
    /// What the display shows of the frames' radiance: FovVideoVDP judges that.
    pub display: &'a DisplayTransform,
}

/// A running FovVideoVDP: start once, score many.
pub struct Fvvdp {
    python: PathBuf,
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
    dir: PathBuf,
    /// The display's luminance range the metric judges on.
    photometry: Photometry,
    /// torch's version, as the server reported it.
    pub torch: String,
}

impl Fvvdp {
    /// Finds the venv ([`locate_python`]) and starts the metric, judging on the Vive Pro's
    /// photometry.
    pub fn start() -> Result<Self, JodError> {
        Self::start_for(DisplayProfile::ViveProEye)
    }

    /// [`Fvvdp::start`], judging on `display`'s photometry.
    pub fn start_for(display: DisplayProfile) -> Result<Self, JodError> {
        let python = locate_python()?;
        let dir = private_dir("fovea-jod")?;
        let stderr_path = dir.join("stderr.txt");
        let stderr = std::fs::File::create(&stderr_path).map_err(|source| JodError::File {
            path: stderr_path,
            source,
        })?;
        let mut child = Command::new(&python)
            .args(["-u", "-c", SERVER])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(stderr)
            .spawn()
            .map_err(|source| JodError::Start {
                python: python.clone(),
                source,
            })?;
        let (stdin, stdout) = match (child.stdin.take(), child.stdout.take()) {
            (Some(i), Some(o)) => (i, BufReader::new(o)),
            _ => unreachable!("both pipes were asked for"),
        };
        let mut metric = Self {
            python,
            child,
            stdin,
            stdout,
            dir,
            photometry: display.photometry(),
            torch: String::new(),
        };
        let hello = metric.answer()?;
        metric.torch = hello["torch"].as_str().unwrap_or("?").to_string();
        Ok(metric)
    }

    /// The JOD of one image against its reference, foveated at `fixation`, as `display`
    /// shows them.
    pub fn image(
        &mut self,
        test: &[f32],
        reference: &[f32],
        image: &ImageGeometry,
        fixation: [f64; 2],
        display: &DisplayTransform,
    ) -> Result<f64, JodError> {
        self.score(&JodInput {
            test: &[test],
            reference: &[reference],
            image,
            fixation: &[fixation],
            fps: 0.0,
            display,
        })
    }

    /// The JOD of an image or a video (FovVideoVDP's temporal channels see flicker).
    pub fn score(&mut self, input: &JodInput) -> Result<f64, JodError> {
        let frames = input.test.len();
        let (w, h) = (input.image.width, input.image.height);
        let need = w as usize * h as usize * 3;
        if frames == 0 || input.reference.len() != frames || input.fixation.len() != frames {
            return Err(JodError::Input(format!(
                "{frames} test frames, {} reference frames and {} fixations; give the same \
                 number (at least one) of each",
                input.reference.len(),
                input.fixation.len()
            )));
        }
        if let Some(bad) = input
            .test
            .iter()
            .chain(input.reference)
            .find(|f| f.len() != need)
        {
            return Err(JodError::Input(format!(
                "a frame has {} floats, a {w}x{h} RGB image needs {need}",
                bad.len()
            )));
        }
        if input.fixation.iter().flatten().any(|v| !v.is_finite()) {
            return Err(JodError::Input(
                "a fixation is not a finite pixel position".into(),
            ));
        }
        let test = self.dir.join("test.f32");
        let reference = self.dir.join("reference.f32");
        write_display_encoded(&test, input.test, false, input.display)?;
        write_display_encoded(&reference, input.reference, false, input.display)?;
        self.request(&test, &reference, input.image, input.fixation, input.fps)
    }

    /// Scores the frames in two files of display-encoded floats (see [`VideoJod`]).
    fn request(
        &mut self,
        test: &Path,
        reference: &Path,
        image: &ImageGeometry,
        fixation: &[[f64; 2]],
        fps: f64,
    ) -> Result<f64, JodError> {
        let frames = fixation.len();
        let request = serde_json::json!({
            "width": image.width,
            "height": image.height,
            "frames": frames,
            "fps": if frames > 1 { fps } else { 0.0 },
            "test": test,
            "reference": reference,
            "fixation": fixation,
            "peak_cd_m2": self.photometry.peak_cd_m2,
            "black_cd_m2": self.photometry.black_cd_m2,
            "fov_horizontal_deg": fov_horizontal_deg(image),
        });
        super::jod_inputs::keep_if_asked(&request, test, reference).map_err(|e| {
            JodError::File {
                path: e.path,
                source: e.source,
            }
        })?;
        let line = format!("{request}\n");
        if let Err(e) = self.stdin.write_all(line.as_bytes()) {
            return Err(self.failed(format!("it stopped reading requests ({e})")));
        }
        let answer = self.answer()?;
        answer["jod"]
            .as_f64()
            .ok_or_else(|| self.failed(format!("answer without a score: {answer}")))
    }

    /// The next answer line; an `error` in it, or no line at all, is an error.
    fn answer(&mut self) -> Result<serde_json::Value, JodError> {
        let mut line = String::new();
        match self.stdout.read_line(&mut line) {
            Ok(0) | Err(_) => return Err(self.failed("it exited".into())),
            Ok(_) => {}
        }
        let value: serde_json::Value = serde_json::from_str(&line)
            .map_err(|e| self.failed(format!("unreadable answer {line:?} ({e})")))?;
        match value["error"].as_str() {
            Some(message) => Err(self.failed(message.to_string())),
            None => Ok(value),
        }
    }

    fn failed(&mut self, message: String) -> JodError {
        if message == "it exited" {
            // Its exit status and last words tell more than the closed pipe.
            let _ = self.child.wait();
        }
        JodError::Server {
            python: self.python.clone(),
            message,
            stderr: std::fs::read_to_string(self.dir.join("stderr.txt")).unwrap_or_default(),
        }
    }
}

impl Drop for Fvvdp {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A new temporary directory of this process (`PREFIX-PID-N`), for frames in flight.
fn private_dir(prefix: &str) -> Result<PathBuf, JodError> {
    static DIRS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = DIRS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("{prefix}-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|source| JodError::File {
        path: dir.clone(),
        source,
    })?;
    Ok(dir)
}

/// Frames as `display` shows them (exposed, tone mapped, sRGB-encoded), little-endian f32,
/// one after the other; appended to the file, or replacing it.
fn write_display_encoded(
    path: &Path,
    frames: &[&[f32]],
    append: bool,
    display: &DisplayTransform,
) -> Result<(), JodError> {
    let bytes: Vec<u8> = (frames.iter().copied())
        .flat_map(|f| f.chunks_exact(3))
        .flat_map(|p| display.apply([p[0], p[1], p[2]]))
        .flat_map(|v| linear_to_srgb(v).to_le_bytes())
        .collect();
    let file_error = |source| JodError::File {
        path: path.into(),
        source,
    };
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .write(true)
        .append(append)
        .truncate(!append)
        .open(path)
        .map_err(file_error)?;
    file.write_all(&bytes).map_err(file_error)
}

/// A video scored as it is rendered: frames go to files as they come (a long sequence at the
/// headset's size need not fit in memory), and [`VideoJod::score`] judges them all at once,
/// so FovVideoVDP's temporal channels see the flicker between them.
pub struct VideoJod {
    dir: PathBuf,
    image: ImageGeometry,
    fixation: Vec<[f64; 2]>,
    /// What the display shows of the frames.
    display: DisplayTransform,
}

impl VideoJod {
    pub fn new(image: ImageGeometry, display: DisplayTransform) -> Result<Self, JodError> {
        let dir = private_dir("fovea-jod-video")?;
        for f in ["test.f32", "reference.f32"] {
            write_display_encoded(&dir.join(f), &[], false, &display)?;
        }
        Ok(Self {
            dir,
            image,
            fixation: Vec::new(),
            display,
        })
    }

    /// Adds a frame (linear RGB of the image's size) with its gaze pixel.
    pub fn push(
        &mut self,
        test: &[f32],
        reference: &[f32],
        fixation: [f64; 2],
    ) -> Result<(), JodError> {
        let need = self.image.width as usize * self.image.height as usize * 3;
        if test.len() != need || reference.len() != need {
            return Err(JodError::Input(format!(
                "a video frame has {} and {} floats, a {}x{} RGB image needs {need}",
                test.len(),
                reference.len(),
                self.image.width,
                self.image.height
            )));
        }
        if !(fixation[0].is_finite() && fixation[1].is_finite()) {
            return Err(JodError::Input(
                "a fixation is not a finite pixel position".into(),
            ));
        }
        write_display_encoded(&self.dir.join("test.f32"), &[test], true, &self.display)?;
        write_display_encoded(
            &self.dir.join("reference.f32"),
            &[reference],
            true,
            &self.display,
        )?;
        self.fixation.push(fixation);
        Ok(())
    }

    pub fn frames(&self) -> usize {
        self.fixation.len()
    }

    /// The JOD of the frames so far, shown at `fps`.
    pub fn score(&self, metric: &mut Fvvdp, fps: f64) -> Result<f64, JodError> {
        if self.fixation.is_empty() {
            return Err(JodError::Input("a video with no frames".into()));
        }
        metric.request(
            &self.dir.join("test.f32"),
            &self.dir.join("reference.f32"),
            &self.image,
            &self.fixation,
            fps,
        )
    }
}

impl Drop for VideoJod {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_symmetric_field_of_view_is_passed_as_it_is() {
        let fov = crate::foveation::view::EyeFov {
            left: (-45f32).to_radians(),
            right: 45f32.to_radians(),
            up: 45f32.to_radians(),
            down: (-45f32).to_radians(),
        };
        let image = ImageGeometry::new(100, 100, fov);
        assert!((fov_horizontal_deg(&image) - 90.0).abs() < 1e-4);
    }

    #[test]
    fn a_missing_venv_says_how_to_make_one() {
        let e = JodError::NotFound {
            searched: vec![PathBuf::from("/x/.venv-fvvdp")],
        };
        let msg = e.to_string();
        assert!(msg.contains("/x/.venv-fvvdp"), "{msg}");
        assert!(msg.contains("tools/setup-fvvdp.sh"), "{msg}");
    }
}
