//! The largest samples per pixel in the fovea at which a frame fits a time budget: doubling
//! until a frame is over it, then bisection between the last fit and the first miss. Every
//! spp probed is measured once and kept, so several budgets share one set of measurements;
//! each answer lists the spp its own search visited, all of which agree with it (those up to
//! the answer fit, those above did not), whatever noise does to measurements it never saw.

use std::collections::BTreeMap;

/// Every spp the search measured, with its frame time.
#[derive(Clone, Debug, Default)]
pub struct Probes {
    pub ms: BTreeMap<u32, f64>,
}

/// The answer for one budget.
#[derive(Clone, Debug, PartialEq)]
pub struct SppAnswer {
    pub budget_ms: f64,
    /// The largest spp that fits; 0 when even 1 spp does not.
    pub spp: u32,
    /// Its measured time (NaN when `spp` is 0).
    pub ms: f64,
    /// The smallest probed spp that did not fit (None: `max_spp` fit).
    pub first_over: Option<u32>,
    /// The spp this search visited, in order.
    pub visited: Vec<u32>,
}

impl Probes {
    /// The largest spp up to `max_spp` whose frame fits `budget_ms`, measuring with `cost`
    /// (the frame time at an spp) what was not measured yet. Assumes time grows with spp;
    /// by construction every probe up to the answer fit and every probe above it did not.
    pub fn largest_within<E>(
        &mut self,
        budget_ms: f64,
        max_spp: u32,
        cost: &mut impl FnMut(u32) -> Result<f64, E>,
    ) -> Result<SppAnswer, E> {
        let mut visited = Vec::new();
        let mut fits = |probes: &mut Self, spp: u32| -> Result<bool, E> {
            visited.push(spp);
            let ms = match probes.ms.get(&spp) {
                Some(&ms) => ms,
                None => {
                    let ms = cost(spp)?;
                    probes.ms.insert(spp, ms);
                    ms
                }
            };
            Ok(ms <= budget_ms)
        };
        if !fits(self, 1)? {
            return Ok(self.answer(budget_ms, 0, Some(1), visited));
        }
        // Doubling: `low` fits; `high` is the first that did not (or past the maximum).
        let mut low = 1;
        let mut high = None;
        while low < max_spp {
            let next = (low * 2).min(max_spp);
            if fits(self, next)? {
                low = next;
            } else {
                high = Some(next);
                break;
            }
        }
        let Some(mut high) = high else {
            return Ok(self.answer(budget_ms, low, None, visited));
        };
        while high - low > 1 {
            let mid = low + (high - low) / 2;
            if fits(self, mid)? {
                low = mid;
            } else {
                high = mid;
            }
        }
        Ok(self.answer(budget_ms, low, Some(high), visited))
    }

    fn answer(
        &self,
        budget_ms: f64,
        spp: u32,
        first_over: Option<u32>,
        visited: Vec<u32>,
    ) -> SppAnswer {
        SppAnswer {
            budget_ms,
            spp,
            ms: self.ms.get(&spp).copied().unwrap_or(f64::NAN),
            first_over,
            visited,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn search(budget: f64, max: u32, per_spp: f64, fixed: f64) -> (SppAnswer, Vec<u32>) {
        let mut probes = Probes::default();
        let mut order = Vec::new();
        let answer = probes
            .largest_within::<()>(budget, max, &mut |spp| {
                order.push(spp);
                Ok(fixed + per_spp * spp as f64)
            })
            .unwrap();
        (answer, order)
    }

    #[test]
    fn finds_the_largest_spp_within_the_budget() {
        // 1 ms + 0.5 ms per spp: 20 spp take 11 ms, 21 take 11.5.
        let (a, order) = search(11.1, 1024, 0.5, 1.0);
        assert_eq!((a.spp, a.first_over), (20, Some(21)));
        assert_eq!(a.ms, 11.0);
        assert_eq!(&order[..6], &[1, 2, 4, 8, 16, 32]);
        assert!(order.len() <= 12, "{order:?}");
        // Nothing fits, everything fits.
        assert_eq!(search(0.5, 1024, 0.5, 1.0).0.spp, 0);
        assert!(search(0.5, 1024, 0.5, 1.0).0.ms.is_nan());
        let all = search(1e9, 1000, 0.5, 1.0).0;
        assert_eq!((all.spp, all.first_over), (1000, None));
    }

    #[test]
    fn each_answer_agrees_with_what_its_own_search_measured_even_under_noise() {
        // Frame times that dip at 26 spp (noise): the 8.3 ms search never visits 26.
        let mut probes = Probes::default();
        let mut cost = |spp: u32| -> Result<f64, ()> {
            Ok(if spp == 26 {
                6.0
            } else {
                2.0 + 0.4 * spp as f64
            })
        };
        let a = probes.largest_within(11.1, 1024, &mut cost).unwrap();
        let b = probes.largest_within(8.3, 1024, &mut cost).unwrap();
        for answer in [&a, &b] {
            for spp in &answer.visited {
                let fits = probes.ms[spp] <= answer.budget_ms;
                assert_eq!(*spp <= answer.spp, fits, "{answer:?} at {spp}");
            }
        }
        assert_eq!(b.spp, 15);
    }

    #[test]
    fn a_second_budget_reuses_the_measurements_and_agrees_with_them() {
        let mut probes = Probes::default();
        let mut measured = 0;
        let mut cost = |spp: u32| -> Result<f64, ()> {
            measured += 1;
            Ok(2.0 + 0.25 * spp as f64)
        };
        let a = probes.largest_within(11.1, 1024, &mut cost).unwrap();
        let b = probes.largest_within(8.3, 1024, &mut cost).unwrap();
        assert_eq!((a.spp, b.spp), (36, 25));
        assert!(measured < 2 * 12, "{measured} frames measured");
        // Every probe up to an answer fits, every probe above it does not.
        assert!(b.visited.len() < a.visited.len() * 2);
        for answer in [a, b] {
            for (&spp, &ms) in &probes.ms {
                assert_eq!(spp <= answer.spp, ms <= answer.budget_ms, "{spp} {ms}");
            }
        }
    }
}
