//! Why a bench run stopped. Every message says what was wrong and what to do.

use super::csv_log::CsvLogError;
use crate::metrics::MetricsError;
use crate::render::RenderError;
use crate::scene::SceneError;

#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("{0}")]
    Plan(String),
    /// The renderer's message is in this one (not a `source`, which would print it twice).
    #[error("{scene}: {problem}")]
    Render { scene: String, problem: RenderError },
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Log(#[from] CsvLogError),
    #[error("comparing images: {0}")]
    Metrics(#[from] MetricsError),
    #[error(transparent)]
    Plot(#[from] super::plots::PlotError),
    #[error("{path}: {problem}")]
    File { path: String, problem: String },
    #[error("perceptual metric: {0}")]
    Jod(#[from] crate::metrics::jod::JodError),
}

impl BenchError {
    pub fn file(path: &std::path::Path, problem: impl std::fmt::Display) -> Self {
        BenchError::File {
            path: path.display().to_string(),
            problem: problem.to_string(),
        }
    }

    pub fn render(scene: &str) -> impl FnOnce(RenderError) -> BenchError + '_ {
        move |problem| BenchError::Render {
            scene: scene.to_string(),
            problem,
        }
    }
}
