//! What a measured config costs, as the front and the search see it: its time in ms against
//! the budget, from raw GPU ms or from its pace ratio to regular rendering.

use super::files::CandidateRow;
use super::front::Measured;
use super::plan::{Budget, TunePlan};
use super::space::describe;
use crate::foveation::FoveationConfig;

/// A measured config as the front sees it: its cost in ms (see [`costs`]) and its JOD.
#[derive(Clone, Copy)]
pub struct Point {
    pub cost_ms: f64,
    pub jod: f64,
}

impl Measured for Point {
    fn ms(&self) -> f64 {
        self.cost_ms
    }
    fn jod(&self) -> f64 {
        self.jod
    }
}

/// Each row's cost in ms and the budget: raw GPU ms against a budget in ms; with a budget of
/// regular rendering's time, each row's pace ratio (its time over the regular frames
/// interleaved with it) times regular rendering's own measured ms, which is the budget.
/// None while a regular budget's own row is not measured.
pub fn costs(plan: &TunePlan, rows: &[CandidateRow]) -> (Vec<Point>, Option<f64>) {
    let (scale, budget) = match plan.budget {
        Budget::Ms(ms) => (None, Some(ms)),
        Budget::Regular(spp) => {
            let name = describe(&FoveationConfig::regular(spp));
            let ms = rows.iter().find(|r| r.config == name).map(|r| r.gpu_ms);
            (Some(ms.unwrap_or(f64::NAN)), ms)
        }
    };
    let points = rows
        .iter()
        .map(|r| Point {
            cost_ms: scale.map_or(r.gpu_ms, |s| r.pace_ratio * s),
            jod: r.jod,
        })
        .collect();
    (points, budget)
}

/// The config whose frames pace a config's timed frames: regular rendering at the budget's
/// spp, for a budget of its time; none for a budget in ms.
pub fn pace_config(plan: &TunePlan) -> Option<FoveationConfig> {
    match plan.budget {
        Budget::Regular(spp) => Some(FoveationConfig::regular(spp)),
        Budget::Ms(_) => None,
    }
}
