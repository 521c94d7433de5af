//! Why a tune run stops.

use crate::bench::BenchError;
use crate::metrics::jod::JodError;
use crate::render::RenderError;

/// Why a tune run stopped. Every message says what was wrong and what to do.
#[derive(Debug, thiserror::Error)]
pub enum TuneError {
    #[error("{0}")]
    Plan(String),
    /// The renderer's message is in this one (not a `source`, which would print it twice).
    #[error("{scene}: {problem}")]
    Render { scene: String, problem: RenderError },
    #[error(transparent)]
    Bench(#[from] BenchError),
    #[error("perceptual metric: {0}")]
    Jod(#[from] JodError),
    #[error(transparent)]
    Log(#[from] crate::bench::csv_log::CsvLogError),
    #[error(transparent)]
    Plot(#[from] crate::bench::plots::PlotError),
    #[error("{0}")]
    File(String),
    #[error(
        "no config fits in the budget of {budget_ms:.3} ms per eye: the fastest measured took \
         {fastest_ms:.3} ms; raise --budget-ms (the front is in {front})"
    )]
    NothingWithin {
        budget_ms: f64,
        fastest_ms: f64,
        front: String,
    },
}

impl TuneError {
    pub fn render(scene: &str) -> impl FnOnce(RenderError) -> TuneError + '_ {
        move |problem| TuneError::Render {
            scene: scene.to_string(),
            problem,
        }
    }
}
