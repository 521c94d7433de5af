//! Which config the search measures next: the baselines and `--include`d configs, then
//! configs drawn at random from the seed, then mutations of the best ones within the budget
//! (so the same seed and measurements give the same search).

use super::cost::costs;
use super::files::CandidateRow;
use super::plan::TunePlan;
use super::space::describe;
use crate::check::rng::Rng;
use crate::foveation::FoveationConfig;

/// Parents a mutation picks from: this many of the best within the budget.
const PARENTS: usize = 3;
/// Draws before a mutation gives up finding a config not yet measured.
const FRESH_TRIES: usize = 32;

/// The configs drawn at random from the seed, none a baseline or drawn twice.
pub fn random_configs(plan: &TunePlan) -> Vec<FoveationConfig> {
    let first = first_configs(plan);
    let count = (plan.candidates as usize - first.len()) / 2;
    let mut seen: Vec<String> = first.iter().map(|(c, _)| describe(c)).collect();
    let mut rng = Rng::new(plan.seed);
    let mut out = Vec::new();
    for _ in 0..count * FRESH_TRIES {
        if out.len() == count {
            break;
        }
        let config = plan.space.random(&mut rng);
        let name = describe(&config);
        if !seen.contains(&name) {
            seen.push(name);
            out.push(config);
        }
    }
    out
}

/// What every search measures first: the baselines, then the `--include` configs.
pub fn first_configs(plan: &TunePlan) -> Vec<(FoveationConfig, &'static str)> {
    let baselines = plan.space.baselines().into_iter().map(|c| (c, "baseline"));
    let included = plan.include.iter().map(|c| (c.clone(), "included"));
    baselines.chain(included).collect()
}

/// Candidate `index` of the search: a baseline, a random draw, or a mutation of one of the
/// best configs measured before it (so the same seed and measurements give the same one).
pub fn candidate(
    plan: &TunePlan,
    index: u32,
    randoms: &[FoveationConfig],
    rows: &[CandidateRow],
) -> (FoveationConfig, String) {
    let first = first_configs(plan);
    let i = index as usize;
    if let Some((config, origin)) = first.get(i) {
        return (config.clone(), origin.to_string());
    }
    if let Some(config) = randoms.get(i - first.len()) {
        return (config.clone(), "random".into());
    }
    let earlier: Vec<CandidateRow> = rows.iter().filter(|r| r.index < index).cloned().collect();
    let (points, budget) = costs(plan, &earlier);
    let budget = budget.unwrap_or(f64::INFINITY);
    let mut parents: Vec<usize> = (0..earlier.len())
        .filter(|&i| points[i].cost_ms <= budget && points[i].jod.is_finite())
        .collect();
    parents.sort_by(|&a, &b| points[b].jod.total_cmp(&points[a].jod));
    if parents.is_empty() {
        parents = (0..earlier.len()).collect();
        parents.sort_by(|&a, &b| points[a].cost_ms.total_cmp(&points[b].cost_ms));
    }
    parents.truncate(PARENTS);
    let parents: Vec<&CandidateRow> = parents.iter().map(|&i| &earlier[i]).collect();
    let mut rng = Rng::new(plan.seed ^ (index as u64).wrapping_mul(0x2545_f491_4f6c_dd1d));
    let mut fallback = None;
    for _ in 0..FRESH_TRIES {
        let parent = parents[rng.below(parents.len())];
        let Ok(config) = parent.foveation() else {
            continue;
        };
        let child = plan.space.mutate(&config, &mut rng);
        let name = describe(&child);
        let origin = format!("mutation of {}", parent.index);
        if !rows.iter().any(|r| r.config == name) {
            return (child, origin);
        }
        fallback.get_or_insert((child, origin));
    }
    // Every neighbour was measured: a fresh random draw instead.
    let fresh = plan.space.random(&mut rng);
    match rows.iter().any(|r| r.config == describe(&fresh)) {
        false => (fresh, "random".into()),
        true => fallback.unwrap_or((fresh, "random".into())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(seed: u64) -> TunePlan {
        TunePlan::for_tests(seed)
    }

    fn row(index: u32, config: &FoveationConfig, pace_ratio: f64, jod: f64) -> CandidateRow {
        CandidateRow {
            index,
            origin: String::new(),
            config: describe(config),
            gpu_ms: 100.0 * pace_ratio,
            pace_ratio,
            jod,
            jod_motion: f64::NAN,
            jod_forward: jod,
            jod_off_axis: jod,
            jod_corner: jod,
            paths_per_pixel: 1.0,
            rays_per_pixel: 3.0,
            scenes_json: String::new(),
            config_json: serde_json::to_string(config).unwrap(),
        }
    }

    /// A plan written before the motion warm-up was a field reads as the 8 frames it was
    /// measured with, so it resumes only as what it was (a new run's plan differs).
    #[test]
    fn a_plan_from_before_the_warm_up_field_reads_as_eight_frames() {
        let mut json = serde_json::to_value(plan(1)).unwrap();
        json.as_object_mut().unwrap().remove("motion_warm_up");
        let old: TunePlan = serde_json::from_value(json).unwrap();
        assert_eq!(old.motion_warm_up, 8);
        assert_ne!(old, plan(1));
    }

    /// Render seed 1 is the seed plans had before the flag (and is not written), so they
    /// resume as they were; other render seeds start sequences that share no frame's seed.
    #[test]
    fn render_seeds_keep_old_plans_and_draw_disjoint_sequences() {
        let first = plan(1);
        let json = serde_json::to_value(&first).unwrap();
        assert!(json.get("render_seed").is_none());
        let old: TunePlan = serde_json::from_value(json).unwrap();
        assert_eq!((old.render_seed, old.frame_seed()), (1, 1));
        let seeds = |render_seed| {
            let p = TunePlan {
                render_seed,
                ..plan(1)
            };
            p.frame_seed()..p.frame_seed() + 1000
        };
        let (a, b) = (seeds(2), seeds(3));
        assert!(a.start >= seeds(1).end && b.start >= a.end, "{a:?} {b:?}");
        let second = TunePlan {
            render_seed: 2,
            ..plan(1)
        };
        let json = serde_json::to_value(&second).unwrap();
        assert_eq!(json["render_seed"], 2);
        assert_eq!(serde_json::from_value::<TunePlan>(json).unwrap(), second);
    }

    #[test]
    fn the_seed_decides_the_search_and_measurements_steer_it() {
        let (a, b) = (plan(1), plan(2));
        assert!(a.validate().is_ok());
        // Baselines (regular, regular with two uniform filters, thesis; at 3 spp each; four
        // full-resolution foveae), then the included config, then seeded draws.
        let first = first_configs(&a);
        assert_eq!(first.len(), 17);
        assert_eq!(
            first[16],
            (FoveationConfig::thesis().with_spp(8), "included")
        );
        assert_eq!(random_configs(&a), random_configs(&a));
        assert_ne!(random_configs(&a), random_configs(&b));
        assert_eq!(random_configs(&a).len(), (24 - 17) / 2);

        // Measured so far: regular 1 spp (the budget) and two configs, one within it.
        let cheap = FoveationConfig::thesis().with_spp(2);
        let dear = FoveationConfig::thesis().with_spp(16);
        let rows = vec![
            row(0, &FoveationConfig::regular(1), 1.0, 8.0),
            row(1, &cheap, 0.5, 8.5),
            row(2, &dear, 1.5, 9.5),
        ];
        let (points, budget) = costs(&a, &rows);
        assert_eq!(budget, Some(100.0));
        assert_eq!(points[1].cost_ms, 50.0);
        // A mutation's parent is the best within the budget (regular or cheap), never dear;
        // the same seed and rows give the same child.
        let index = 23;
        let (child, origin) = candidate(&a, index, &random_configs(&a), &rows);
        assert_eq!(candidate(&a, index, &random_configs(&a), &rows).0, child);
        assert!(
            origin == "mutation of 0" || origin == "mutation of 1",
            "{origin}"
        );
        assert!(rows.iter().all(|r| r.config != describe(&child)));
    }
}
