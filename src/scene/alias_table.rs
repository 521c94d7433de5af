//! The alias method (Walker 1977, built by Vose's method, 1991): a discrete distribution
//! sampled with one uniform bucket and one comparison, whatever its size. Next-event
//! estimation picks lights with one (light_selection.rs).

/// Bucket i (chosen uniformly) gives item i with probability `keep[i]`, else `alias[i]`; the
/// result is item j with probability `pmf[j]`.
pub struct AliasTable {
    pub pmf: Vec<f64>,
    pub keep: Vec<f32>,
    pub alias: Vec<u32>,
}

impl AliasTable {
    /// The table of `weights` normalised (negative, NaN and infinite weights count as 0);
    /// uniform when no weight is positive.
    pub fn new(weights: &[f64]) -> Self {
        let n = weights.len();
        let usable = |p: f64| if p.is_finite() && p > 0.0 { p } else { 0.0 };
        let total: f64 = weights.iter().map(|&p| usable(p)).sum();
        let pmf: Vec<f64> = if total > 0.0 {
            weights.iter().map(|&p| usable(p) / total).collect()
        } else {
            vec![1.0 / n.max(1) as f64; n]
        };
        // Scaled probabilities n·p; buckets below 1 are topped up from ones above.
        let mut scaled: Vec<f64> = pmf.iter().map(|p| p * n as f64).collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) =
            (0..n).partition(|&i| scaled[i] < 1.0);
        let mut keep = vec![1.0f32; n];
        let mut alias: Vec<u32> = (0..n as u32).collect();
        while let (Some(s), Some(&l)) = (small.pop(), large.last()) {
            keep[s] = scaled[s] as f32;
            alias[s] = l as u32;
            scaled[l] -= 1.0 - scaled[s];
            if scaled[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What remains in either list is full up to rounding.
        for i in small.into_iter().chain(large) {
            keep[i] = 1.0;
            alias[i] = i as u32;
        }
        Self { pmf, keep, alias }
    }
}
