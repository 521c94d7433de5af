//! What a still run and a motion run both do before they measure: read or write the run's
//! plan, add the command line to its list, start FovVideoVDP, and show progress. Below both
//! runs, so neither imports the other.

use super::error::BenchError;
use super::files::{COMMANDS_FILE, PLAN_FILE};
use super::protocol::{BenchPlan, RunOptions};
use crate::foveation::DisplayProfile;
use crate::gpu::GpuContext;
use crate::metrics::jod::{Fvvdp, JodError};
use crate::render::Renderer;
use crate::scene::{self, Scene};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;
use std::sync::Arc;

/// Reads the plan of an existing results directory (for `--resume`).
pub fn read_plan(dir: &Path) -> Result<BenchPlan, BenchError> {
    let path = dir.join(PLAN_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| {
        BenchError::file(
            &path,
            format!("{e}; --resume needs the directory of an earlier `fovea bench` run"),
        )
    })?;
    serde_json::from_str(&text).map_err(|e| {
        BenchError::file(
            &path,
            format!("not a bench plan of this version of fovea ({e})"),
        )
    })
}

/// Checks the plan and its scenes, writes plan.json (or checks that the directory's is the
/// same) and adds this command line to commands.txt. Returns every command line so far.
pub fn open_run_dir(
    plan: &BenchPlan,
    dir: &Path,
    options: &RunOptions,
) -> Result<String, BenchError> {
    plan.validate().map_err(BenchError::Plan)?;
    // Every scene must load before anything is written: a typo should not leave a run
    // directory behind that can only fail again on resume.
    let aspect = plan.width as f32 / plan.height as f32;
    for name in &plan.scenes {
        scene::load(name, aspect)?;
    }
    std::fs::create_dir_all(dir).map_err(|e| BenchError::file(dir, e))?;
    write_or_check_plan(plan, dir)?;
    append_command_line(dir, &options.command_line)
}

/// Writes plan.json, or checks that the one in `dir` is `plan`.
fn write_or_check_plan(plan: &BenchPlan, dir: &Path) -> Result<(), BenchError> {
    let plan_path = dir.join(PLAN_FILE);
    if plan_path.exists() {
        if read_plan(dir)? != *plan {
            return Err(BenchError::Plan(format!(
                "{} holds a run with other parameters; resume it with --resume {} alone, or \
                 measure into a new directory",
                dir.display(),
                dir.display()
            )));
        }
    } else {
        let json = serde_json::to_string_pretty(plan).expect("plans serialize");
        std::fs::write(&plan_path, json).map_err(|e| BenchError::file(&plan_path, e))?;
    }
    Ok(())
}

/// Adds `command_line` to commands.txt; returns the file's whole text.
fn append_command_line(dir: &Path, command_line: &str) -> Result<String, BenchError> {
    let commands_path = dir.join(COMMANDS_FILE);
    let mut commands = std::fs::read_to_string(&commands_path).unwrap_or_default();
    commands.push_str(command_line);
    commands.push('\n');
    std::fs::write(&commands_path, &commands).map_err(|e| BenchError::file(&commands_path, e))?;
    Ok(commands)
}

/// FovVideoVDP, started once for the run; without its venv the run goes on without JOD
/// scores and says how to get them.
pub fn perceptual_metric(display: DisplayProfile) -> Result<Option<Fvvdp>, BenchError> {
    match Fvvdp::start_for(display) {
        Ok(metric) => Ok(Some(metric)),
        Err(e @ JodError::NotFound { .. }) => {
            eprintln!("fovea bench: no JOD scores in this run: {e}");
            Ok(None)
        }
        Err(e) => Err(e.into()),
    }
}

/// The run's progress bar over `len` steps.
pub fn progress_bar(len: u64) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed_precise} (eta {eta}) {msg}")
            .expect("a valid template"),
    );
    bar
}

/// Loads scene `name` for the plan's image aspect, with a renderer that traverses it the
/// plan's way: what the still and the motion run both start a scene with.
pub fn scene_renderer(
    ctx: &Arc<GpuContext>,
    plan: &BenchPlan,
    name: &str,
) -> Result<(Scene, Renderer), BenchError> {
    let scene = scene::load(name, plan.width as f32 / plan.height as f32)?;
    let mut renderer = Renderer::new(ctx, &scene).map_err(BenchError::render(name))?;
    renderer
        .set_traversal(plan.traversal)
        .map_err(BenchError::render(name))?;
    Ok((scene, renderer))
}
