//! `fovea bench`: the thesis' evaluation protocol (§3.1), automated: GPU timestamps of every
//! pass of both eyes, frame-rate statistics and impact factors, image error against a
//! converged reference, and run time against error, written to a results directory as CSV,
//! JSON, Markdown, SVG/PNG plots and a Perfetto trace.
//!
//! One direction, run → measure → report: `runner` runs the frames and calls the measuring
//! (`quality`, `images`) and then the report (`summary`, `report`, `report_plots`, `plots`);
//! nothing imports the stage before it. A `--motion` run goes the same way in `motion/`
//! (`run`, `images`, `report`; `script` is what it plays), handed over by `runner` once the
//! directory is open; both reports open with `report_head`. What they share is below them:
//! `setup` (the results directory, FovVideoVDP, progress), `protocol` (the plan), `rows`
//! (what is recorded), `files` (where), `csv_log`, `perfetto`, `stats` and `error`.

pub mod csv_log;
pub mod error;
pub mod files;
pub mod images;
pub mod motion;
pub mod perfetto;
pub mod plots;
pub mod protocol;
pub mod quality;
pub mod report;
pub mod report_head;
pub mod report_plots;
pub mod rows;
pub mod runner;
pub mod setup;
pub mod stats;
pub mod summary;

pub use error::BenchError;
pub use protocol::{BenchPlan, Mode, RunOptions};
pub use runner::run;
pub use setup::read_plan;
