//! The Pareto front of measured configs (perceptual quality against GPU time) and the best
//! config within a time budget, which always lies on it.

/// A measured config: its GPU ms and its JOD.
pub trait Measured {
    fn ms(&self) -> f64;
    fn jod(&self) -> f64;
}

fn usable<T: Measured>(p: &T) -> bool {
    p.ms().is_finite() && p.jod().is_finite()
}

/// Whether `a` dominates `b`: no slower and no worse, and better in one of the two.
fn dominates<T: Measured>(a: &T, b: &T) -> bool {
    a.ms() <= b.ms() && a.jod() >= b.jod() && (a.ms() < b.ms() || a.jod() > b.jod())
}

/// The indices of the points no other point dominates, fastest first (non-finite points
/// are never on it).
pub fn pareto_front<T: Measured>(points: &[T]) -> Vec<usize> {
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| usable(&points[i]))
        .filter(|&i| {
            !points
                .iter()
                .any(|other| usable(other) && dominates(other, &points[i]))
        })
        .collect();
    front.sort_by(|&a, &b| points[a].ms().total_cmp(&points[b].ms()));
    // Equal points: keep the first measured.
    front.dedup_by(|a, b| {
        points[*a].ms() == points[*b].ms() && points[*a].jod() == points[*b].jod()
    });
    front
}

/// The index of the best JOD among points within `budget_ms` (the faster on a tie, and of
/// equal points the first measured, as the front keeps it).
pub fn best_within<T: Measured>(points: &[T], budget_ms: f64) -> Option<usize> {
    (0..points.len())
        .filter(|&i| usable(&points[i]) && points[i].ms() <= budget_ms)
        .max_by(|&a, &b| {
            let (pa, pb) = (&points[a], &points[b]);
            pa.jod()
                .total_cmp(&pb.jod())
                .then(pb.ms().total_cmp(&pa.ms()))
                .then(b.cmp(&a))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Measured for (f64, f64) {
        fn ms(&self) -> f64 {
            self.0
        }
        fn jod(&self) -> f64 {
            self.1
        }
    }

    #[test]
    fn the_front_keeps_what_nothing_beats() {
        let points = [
            (10.0, 8.0),
            (5.0, 7.0),
            (12.0, 7.5), // slower and worse than (10, 8)
            (20.0, 9.0),
            (5.0, 6.5), // as fast as (5, 7) but worse
            (f64::NAN, 9.9),
            (30.0, 9.0), // as good as (20, 9) but slower
        ];
        assert_eq!(pareto_front(&points), vec![1, 0, 3]);
        assert_eq!(best_within(&points, 11.0), Some(0));
        assert_eq!(best_within(&points, 100.0), Some(3));
        assert_eq!(best_within(&points, 4.0), None);
        // Of equal points (a cost counted, not timed, ties exactly), the first measured.
        let tied = [(5.0, 7.0), (10.0, 8.0), (10.0, 8.0)];
        assert_eq!(pareto_front(&tied), vec![0, 1]);
        assert_eq!(best_within(&tied, 10.0), Some(1));
        // The best within any budget is on the front.
        for budget in [5.0, 9.0, 10.0, 15.0, 25.0, 40.0] {
            let best = best_within(&points, budget).unwrap();
            assert!(pareto_front(&points).contains(&best), "{budget}");
        }
    }
}
