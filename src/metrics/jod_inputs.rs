//! FovVideoVDP's inputs kept for study: with `FOVEA_KEEP_JOD_INPUTS=DIR` every request fovea
//! sends the metric (a first frame or a motion video) is copied into DIR as it is sent: the
//! test and reference frames (raw little-endian f32, display-encoded, frames × height × width
//! × RGB) and the request, pointing at those copies, as JSON. `tools/foveated-blur.py` reads
//! them to score what a reconstruction would do to the same frames without rendering again.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};

/// The environment variable that names the folder.
pub const KEEP_ENV: &str = "FOVEA_KEEP_JOD_INPUTS";

/// A file that could not be kept, and why.
#[derive(Debug)]
pub struct KeepError {
    pub path: PathBuf,
    pub source: std::io::Error,
}

/// Copies a request's frames into the folder `KEEP_ENV` names, when it names one.
pub fn keep_if_asked(
    request: &serde_json::Value,
    test: &Path,
    reference: &Path,
) -> Result<(), KeepError> {
    match std::env::var_os(KEEP_ENV) {
        Some(dir) if !dir.is_empty() => keep_in(Path::new(&dir), request, test, reference),
        _ => Ok(()),
    }
}

/// Copies a request's frames into `dir` as `PID-N-test.f32`, `PID-N-reference.f32` and
/// `PID-N.json` (N counts this process's requests, so runs side by side do not collide).
pub fn keep_in(
    dir: &Path,
    request: &serde_json::Value,
    test: &Path,
    reference: &Path,
) -> Result<(), KeepError> {
    static KEPT: AtomicU32 = AtomicU32::new(0);
    let name = format!(
        "{}-{}",
        std::process::id(),
        KEPT.fetch_add(1, Ordering::Relaxed)
    );
    let file_error = |path: &Path| {
        let path = path.to_path_buf();
        move |source| KeepError { path, source }
    };
    std::fs::create_dir_all(dir).map_err(file_error(dir))?;
    let mut kept = request.clone();
    for (from, key) in [(test, "test"), (reference, "reference")] {
        let to = dir.join(format!("{name}-{key}.f32"));
        std::fs::copy(from, &to).map_err(file_error(&to))?;
        kept[key] = serde_json::json!(to);
    }
    let json = dir.join(format!("{name}.json"));
    std::fs::write(&json, kept.to_string()).map_err(file_error(&json))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_kept_request_points_at_copies_of_its_frames() {
        let dir = crate::test_dir::TestDir::new("jod-inputs");
        let (test, reference) = (dir.join("t.f32"), dir.join("r.f32"));
        std::fs::write(&test, [1u8, 2, 3, 4]).unwrap();
        std::fs::write(&reference, [5u8, 6, 7, 8]).unwrap();
        let request = serde_json::json!({"frames": 1, "test": test, "reference": reference});
        let kept = dir.join("kept");
        keep_in(&kept, &request, &test, &reference).unwrap();
        let jsons: Vec<_> = std::fs::read_dir(&kept)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        assert_eq!(jsons.len(), 1);
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&jsons[0]).unwrap()).unwrap();
        assert_eq!(json["frames"], 1);
        let copy = |key: &str| std::fs::read(json[key].as_str().unwrap()).unwrap();
        assert_eq!(copy("test"), [1, 2, 3, 4]);
        assert_eq!(copy("reference"), [5, 6, 7, 8]);
        assert_ne!(json["test"], request["test"]);
        // A folder that cannot be made is an error that names it, not a silent skip.
        let blocked = test.join("inside-a-file");
        let err = keep_in(&blocked, &request, &test, &reference).unwrap_err();
        assert!(err.path.ends_with("inside-a-file"), "{:?}", err.path);
    }
}
