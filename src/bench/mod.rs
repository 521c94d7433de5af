//! `fovea bench`: the thesis' evaluation protocol (§3.1), automated.

pub mod plots;
pub mod stats;
