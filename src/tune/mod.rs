//! `fovea tune`: searches foveation configs (layer count, radii, spacings, spp, denoising per
//! layer) for the best perceptual quality (FovVideoVDP JOD, mean over scenes and gazes)
//! within a GPU time budget, and writes the winner as a foveation TOML with the whole Pareto
//! front.
//!
//! One direction: `run` drives the search and imports the stages, none of which imports it:
//! `search` picks the next config from the `space`, `measure` judges it, and `finish` takes
//! the `front` and writes the `files`. Below them all: `plan` (what to search, how),
//! `cost` (a config's cost against the budget) and `error`.

pub mod cost;
pub mod error;
pub mod files;
pub mod finish;
pub mod front;
pub mod measure;
pub mod motion;
pub mod plan;
pub mod run;
pub mod search;
pub mod space;

pub use error::TuneError;
pub use finish::TuneOutcome;
pub use plan::{Budget, Cost, Objective, TuneGaze, TuneOptions, TunePlan};
pub use run::run;
