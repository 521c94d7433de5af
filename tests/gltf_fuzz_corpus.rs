//! The glTF fuzz corpus as a stable-Rust regression test: every file of
//! `fuzz/corpus/gltf_load/` (hand-made seeds and what the fuzzer kept) and of `fuzz/regressions/`
//! (inputs that once crashed the loader, named after what they triggered) is loaded from disk
//! and from memory. None may panic; a refusal must be a non-empty message naming the input; an
//! accepted scene must pass the fuzz target's checks (finite positions and materials, in-range
//! indices, a GPU layout that does not panic). Run the fuzzer itself with `tools/fuzz.sh`.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::Instant;

use fovea::scene::gltf_load::{load_gltf, load_gltf_bytes, mesh_from_glb_bytes};
use fovea::scene::{Scene, SceneError};

#[path = "../fuzz/src/checks.rs"]
mod checks;

const ASPECT: f32 = 16.0 / 9.0;
/// At least this many corpus files must load (39 hand-made seeds, 10 fuzzer finds)...
const MIN_VALID: usize = 40;
/// ...and at least this many must be refused (9 hand-made seeds, 30 fuzzer finds).
const MIN_INVALID: usize = 30;
/// The corpus' size limits: today 91 files, 95 KiB, loaded in about a second.
const MAX_FILES: usize = 300;
const MAX_BYTES: u64 = 1 << 20;

fn files(dir: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{} is missing ({e})", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// Runs `load` without letting a panic escape; `Err` carries the panic message.
fn guarded<T>(load: impl FnOnce() -> T) -> Result<T, String> {
    catch_unwind(AssertUnwindSafe(load)).map_err(|panic| {
        panic
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| panic.downcast_ref::<&str>().map(|s| (*s).to_owned()))
            .unwrap_or_else(|| "a panic without a message".to_owned())
    })
}

/// What loading one file gave, when it kept every promise.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Outcome {
    Accepted,
    Refused,
}

/// Loads one file from disk, from memory and as a merged mesh; `Err` is a broken promise
/// (panic, bad scene, message that does not name the input, disagreement).
fn check_file(path: &Path) -> Result<Outcome, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let what = path.to_str().ok_or("the path is not UTF-8")?;
    let judge = |result: Result<Scene, SceneError>| -> Result<Option<Scene>, String> {
        match result {
            Ok(scene) => checks::check_scene(&scene).map(|()| Some(scene)),
            Err(e) => checks::check_error(&e, what).map(|()| None),
        }
    };
    let from_file = guarded(|| judge(load_gltf(path, ASPECT)))
        .map_err(|p| format!("load_gltf panicked: {p}"))??;
    let from_memory = guarded(|| judge(load_gltf_bytes(&bytes, what, ASPECT)))
        .map_err(|p| format!("load_gltf_bytes panicked: {p}"))??;
    if from_file.is_some() != from_memory.is_some() {
        return Err(format!(
            "load_gltf accepted: {}, load_gltf_bytes accepted: {}; they share one code path \
             and must agree",
            from_file.is_some(),
            from_memory.is_some()
        ));
    }
    guarded(|| match mesh_from_glb_bytes(&bytes, what) {
        Ok(mesh) => checks::check_mesh(&mesh),
        Err(e) => checks::check_error(&e, what),
    })
    .map_err(|p| format!("mesh_from_glb_bytes panicked: {p}"))?
    .map_err(|e| format!("mesh_from_glb_bytes: {e}"))?;
    let Some(scene) = from_memory else {
        return Ok(Outcome::Refused);
    };
    // obvhs's debug-only self-checks (BVHs 32+ levels deep from one far vertex, node bounds
    // missing a primitive by rounding at 5e8) are off in every profile (Cargo.toml): a deep
    // BVH is traced, its stack overflows counted and reported, instead of a panic.
    guarded(|| checks::build_gpu_layout(&scene))
        .map(|()| Outcome::Accepted)
        .map_err(|p| format!("GpuScene::build panicked: {p}"))
}

thread_local! {
    /// Whether panics on this thread are expected (caught by [`guarded`]) and not printed.
    static QUIET: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Checks every file, without printing the panics it catches (tests run in parallel threads,
/// so the panic hook stays installed and asks the thread whether to be quiet).
fn check_all(paths: &[PathBuf]) -> (Vec<(PathBuf, Outcome)>, Vec<String>) {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(|q| q.get()) {
                default(info);
            }
        }));
    });
    QUIET.with(|q| q.set(true));
    let (mut outcomes, mut failures) = (Vec::new(), Vec::new());
    for path in paths {
        match check_file(path) {
            Ok(outcome) => outcomes.push((path.clone(), outcome)),
            Err(problem) => failures.push(format!("{}: {problem}", path.display())),
        }
    }
    QUIET.with(|q| q.set(false));
    (outcomes, failures)
}

fn count(outcomes: &[(PathBuf, Outcome)], which: Outcome) -> usize {
    outcomes.iter().filter(|(_, o)| *o == which).count()
}

#[test]
fn corpus_loads_or_is_refused_with_a_message() {
    let start = Instant::now();
    let paths = files("fuzz/corpus/gltf_load");
    let (outcomes, failures) = check_all(&paths);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let valid = count(&outcomes, Outcome::Accepted);
    let invalid = count(&outcomes, Outcome::Refused);
    eprintln!(
        "{} files: {valid} valid, {invalid} invalid, in {:?}",
        paths.len(),
        start.elapsed()
    );
    assert!(
        valid >= MIN_VALID && invalid >= MIN_INVALID,
        "{valid} valid and {invalid} invalid files in the corpus; expected at least \
         {MIN_VALID} and {MIN_INVALID} (is fuzz/corpus/gltf_load complete?)"
    );
    // Hand-made seeds say in their name whether they are broken.
    for (path, outcome) in &outcomes {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if let Some(seed) = name.strip_prefix("seed-") {
            assert_eq!(
                *outcome == Outcome::Refused,
                seed.starts_with("bad-"),
                "{name}: a seed named bad-* must be refused and the others accepted"
            );
        }
    }
    // Small enough to load in seconds on every test run: a bound on the work, not the time.
    let bytes: u64 = paths.iter().map(|p| p.metadata().unwrap().len()).sum();
    assert!(
        paths.len() <= MAX_FILES && bytes <= MAX_BYTES,
        "the corpus holds {} files, {bytes} bytes (at most {MAX_FILES} and {MAX_BYTES}); keep it \
         small (cargo fuzz cmin)",
        paths.len()
    );
}

#[test]
fn regressions_no_longer_crash() {
    let paths = files("fuzz/regressions");
    assert!(!paths.is_empty(), "fuzz/regressions is empty");
    let (outcomes, failures) = check_all(&paths);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert_eq!(outcomes.len(), paths.len());
}
