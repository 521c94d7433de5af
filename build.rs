//! Compiles every `glsl/*.comp` to SPIR-V with glslc (shaderc's compiler, Debian package
//! `glslc`, installed by tools/setup.sh); `src/gpu/shaders.rs` embeds the results. Shaders
//! include `glsl/*.glsl` and `glsl/shared.h`, so any change under glsl/ rebuilds them.
//!
//! glslc runs as a program on the build host, so cross-builds (Windows) compile the same
//! SPIR-V and nothing of shaderc is linked into anything. `GLSLC` names another glslc.

use std::path::{Path, PathBuf};
use std::process::Command;

// The crate's own fingerprint (FNV-1a), so the shaders' stamp is hashed as cache keys are.
#[path = "src/scene/fingerprint.rs"]
#[allow(dead_code)]
mod fingerprint;
use fingerprint::Fingerprint;

fn main() {
    let glsl = Path::new("glsl");
    println!("cargo:rerun-if-changed=glsl");
    println!("cargo:rerun-if-env-changed=GLSLC");
    stamp_commit();
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    write_shared_constants(&glsl.join("shared.h"), &out.join("shared_consts.rs"));
    let glslc = std::env::var("GLSLC").unwrap_or_else(|_| "glslc".into());
    // This script also runs when only Rust sources changed (for the commit stamp): compile
    // the shaders only when glsl/ or the compiler changed since the last time.
    let fingerprint = format!("{glslc}\n{}", glsl_fingerprint(glsl));
    let stamp = out.join("shaders.fingerprint");
    if std::fs::read_to_string(&stamp).is_ok_and(|s| s == fingerprint) {
        return;
    }
    let mut entries: Vec<_> = std::fs::read_dir(glsl)
        .expect("glsl/ directory")
        .map(|e| e.expect("glsl/ entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "comp"))
        .collect();
    entries.sort();
    for path in entries {
        let stem = path.file_stem().unwrap().to_string_lossy().to_string();
        compile(&glslc, glsl, &path, &out.join(format!("{stem}.spv")), &[]);
        // The shaders that trace rays again, with VK_KHR_ray_query in place of the software
        // traversal (glsl/ray_query.glsl): SPIR-V that declares the RayQueryKHR capability
        // cannot even be loaded on a device without it, so it is a second module, not a
        // specialization constant.
        if RAY_QUERY_SHADERS.contains(&stem.as_str()) {
            let spv = out.join(format!("{stem}_rq.spv"));
            compile(&glslc, glsl, &path, &spv, &["-DRAY_QUERY"]);
        }
        // The trace that also writes each point's surface for the temporal history: a
        // module of its own, so that without history the trace does not use (and no pass
        // binds) the surfaces' buffer at all.
        // The fill that also fills the skipped points' surfaces, for the same reason.
        if stem == "lattice_fill" {
            let spv = out.join("lattice_fill_surfaces.spv");
            compile(&glslc, glsl, &path, &spv, &["-DKEEPS_SURFACES"]);
        }
        if stem == "trace" {
            let surfaces = ["-DKEEPS_SURFACES"];
            compile(
                &glslc,
                glsl,
                &path,
                &out.join("trace_surfaces.spv"),
                &surfaces,
            );
            let both = ["-DKEEPS_SURFACES", "-DRAY_QUERY"];
            compile(
                &glslc,
                glsl,
                &path,
                &out.join("trace_rq_surfaces.spv"),
                &both,
            );
        }
    }
    std::fs::write(&stamp, fingerprint).expect("write shaders.fingerprint");
}

/// Every file under glsl/ (names and contents) as one number.
fn glsl_fingerprint(glsl: &Path) -> u64 {
    let mut files: Vec<PathBuf> = std::fs::read_dir(glsl)
        .expect("glsl/ directory")
        .map(|e| e.expect("glsl/ entry").path())
        .collect();
    files.sort();
    files
        .iter()
        .fold(Fingerprint::default(), |f, file| {
            f.bytes(file.to_string_lossy().as_bytes())
                .bytes(&std::fs::read(file).unwrap_or_default())
        })
        .value()
}

/// `FOVEA_COMMIT` for the reports' headers: the commit the binary was built from, `+changes`
/// when what goes into the binary differed from it, or `unknown` outside a git checkout. The
/// script runs again whenever a source, the index or HEAD changes, so the stamp stays true.
fn stamp_commit() {
    for path in [
        "src",
        "build.rs",
        "Cargo.toml",
        "Cargo.lock",
        "tools/fvvdp",
        "tools/sim-headset",
    ] {
        println!("cargo:rerun-if-changed={path}");
    }
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
    };
    let commit = git(&["rev-parse", "--short=12", "HEAD"]);
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        for file in ["HEAD", "index", "packed-refs"] {
            let path = Path::new(&dir).join(file);
            if path.exists() {
                println!("cargo:rerun-if-changed={}", path.display());
            }
        }
        if let Some(reference) = git(&["symbolic-ref", "-q", "HEAD"]) {
            let path = Path::new(&dir).join(reference);
            if path.exists() {
                println!("cargo:rerun-if-changed={}", path.display());
            }
        }
    }
    let changed = git(&[
        "status",
        "--porcelain",
        "--untracked-files=no",
        "--",
        "src",
        "glsl",
        "build.rs",
        "Cargo.toml",
        "Cargo.lock",
        "tools/fvvdp",
        "tools/sim-headset",
    ])
    .is_some_and(|s| !s.is_empty());
    let stamp = match commit {
        Some(c) if changed => format!("{c}+changes"),
        Some(c) => c,
        None => "unknown".into(),
    };
    println!("cargo:rustc-env=FOVEA_COMMIT={stamp}");
}

/// The shaders that call trace_scene (glsl/bvh.glsl).
const RAY_QUERY_SHADERS: [&str; 2] = ["trace", "raycast"];

fn compile(glslc: &str, glsl: &Path, path: &Path, spv: &Path, defines: &[&str]) {
    // Vulkan 1.2 / SPIR-V 1.5, optimized for performance (spirv-opt -O), with debug
    // information (names and lines for profilers and GPU-assisted validation reports).
    let run = Command::new(glslc)
        .args(["-fshader-stage=compute", "--target-env=vulkan1.2"])
        .args(["--target-spv=spv1.5", "-O", "-g"])
        .args(defines)
        .arg("-I")
        .arg(glsl)
        .arg(path)
        .arg("-o")
        .arg(spv)
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "cannot run the shader compiler `{glslc}` ({e}): run tools/setup.sh, which \
                 installs Debian's glslc, or set GLSLC to a glslc"
            )
        });
    if !run.status.success() {
        panic!(
            "shader {} failed to compile:\n{}{}",
            path.display(),
            String::from_utf8_lossy(&run.stdout),
            String::from_utf8_lossy(&run.stderr)
        );
    }
}

/// Turns every `#define NAME <integer>` of shared.h into a Rust `pub const NAME: u32`, so the
/// binding numbers, ids and limits have one source.
fn write_shared_constants(header: &Path, out: &Path) {
    let text = std::fs::read_to_string(header).expect("read glsl/shared.h");
    let mut rust = String::from("// Generated by build.rs from glsl/shared.h. Do not edit.\n");
    for line in text.lines() {
        let mut words = line.split_whitespace();
        if words.next() != Some("#define") {
            continue;
        }
        let (Some(name), Some(value)) = (words.next(), words.next()) else {
            continue;
        };
        let value = value.trim_end_matches('u');
        let parsed = if let Some(hex) = value.strip_prefix("0x") {
            u32::from_str_radix(hex, 16).ok()
        } else {
            value.parse::<u32>().ok()
        };
        if let Some(v) = parsed {
            rust.push_str(&format!("pub const {name}: u32 = {v:#x};\n"));
        }
    }
    std::fs::write(out, rust).expect("write shared_consts.rs");
}
