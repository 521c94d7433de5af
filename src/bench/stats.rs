//! Statistics as the thesis reports them (§3.1): per scene and mode the mean
//! frames per second ± standard deviation, and the *impact factor* of
//! foveation (mean fps of foveated over mean fps of regular rendering) with a
//! range derived from the standard deviations.
//!
//! Conventions, fixed here so every report agrees:
//! - **Non-finite values** (NaN, ±∞) are *excluded* from every summary; they
//!   never poison a mean. [`Summary::n`] counts only the values used, so
//!   `values.len() - summary.n` is the number skipped.
//! - **Standard deviation** is the sample standard deviation (divisor n − 1,
//!   Bessel's correction); for n = 1 it is 0.
//! - **Quantiles** use linear interpolation between closest ranks ("R-7", the
//!   NumPy and Excel default): h = (n − 1)·p, interpolated between the sorted
//!   values at ⌊h⌋ and ⌈h⌉. The median is the 0.5 quantile, which is the mean
//!   of the two middle values for even n.

use serde::Serialize;

/// Descriptive statistics of a series (see the module docs for conventions).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Number of finite values summarized (non-finite inputs are excluded).
    pub n: usize,
    /// Arithmetic mean.
    pub mean: f64,
    /// Sample standard deviation (divisor n − 1; 0 when n = 1).
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// 0.5 quantile (mean of the two middle values for even n).
    pub median: f64,
    /// 0.99 quantile, R-7 linear interpolation.
    pub p99: f64,
}

/// Summarizes the finite values of `values`.
///
/// NaN and ±∞ are skipped (and not counted in [`Summary::n`]). Returns `None`
/// when no finite value remains, e.g. for an empty slice.
pub fn summarize(values: &[f64]) -> Option<Summary> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return None;
    }
    // total_cmp is a total order, so sorting cannot panic; all values are finite anyway.
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let mean = sorted.iter().sum::<f64>() / n as f64;
    Some(Summary {
        n,
        mean,
        std: sample_std(&sorted, mean),
        min: sorted[0],
        max: sorted[n - 1],
        median: quantile_sorted(&sorted, 0.5)?,
        p99: quantile_sorted(&sorted, 0.99)?,
    })
}

/// Sample standard deviation around a known `mean` (divisor n − 1; 0 for n ≤ 1).
///
/// Two-pass (mean first) rather than the sum-of-squares shortcut, which loses
/// precision when the spread is small relative to the mean (e.g. 2.81 ± 0.05 fps).
fn sample_std(values: &[f64], mean: f64) -> f64 {
    if values.len() < 2 {
        return 0.0;
    }
    let ss: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
    (ss / (values.len() - 1) as f64).sqrt()
}

/// The `p` quantile (0 ≤ p ≤ 1) of an ascending, finite, non-empty slice, by
/// linear interpolation between closest ranks (R-7, NumPy's default):
/// h = (n − 1)·p, result = x[⌊h⌋] + (h − ⌊h⌋)·(x[⌈h⌉] − x[⌊h⌋]).
///
/// Returns `None` for an empty slice or a `p` outside [0, 1] (or NaN). The
/// slice must already be sorted; this is not checked.
pub fn quantile_sorted(sorted: &[f64], p: f64) -> Option<f64> {
    if sorted.is_empty() || !(0.0..=1.0).contains(&p) {
        return None;
    }
    let h = (sorted.len() - 1) as f64 * p;
    let lo = h.floor() as usize;
    let hi = (h.ceil() as usize).min(sorted.len() - 1);
    Some(sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo]))
}

/// The median of `values` in any order (the R-7 quantile at 1/2: the mean of the middle two
/// for an even count); NaN for none.
pub fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    quantile_sorted(&sorted, 0.5).unwrap_or(f64::NAN)
}

/// Frame-rate statistics of one run: per-frame fps and per-frame time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FrameRates {
    /// Summary of 1000 / ms per frame (the thesis' "mean fps ± std").
    pub fps: Summary,
    /// Summary of the frame times in milliseconds (median and p99 frame time).
    pub ms: Summary,
}

/// Summarizes per-frame times `frame_ms` (milliseconds) as fps and ms.
///
/// The thesis averages the per-frame rates 1000/ms (not 1000 / mean ms), so
/// that is what `fps` is. Frames whose time is not finite or is ≤ 0 (no
/// meaningful rate) are skipped in *both* summaries, so `fps.n == ms.n` is the
/// number of frames used. Returns `None` if no frame is usable.
pub fn frame_rates(frame_ms: &[f64]) -> Option<FrameRates> {
    let valid: Vec<f64> = frame_ms
        .iter()
        .copied()
        .filter(|ms| ms.is_finite() && *ms > 0.0)
        .collect();
    let fps: Vec<f64> = valid.iter().map(|ms| 1000.0 / ms).collect();
    Some(FrameRates {
        fps: summarize(&fps)?,
        ms: summarize(&valid)?,
    })
}

/// The thesis' impact factor of foveation with its range.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Impact {
    /// μf / μr: how many times faster foveated rendering is.
    pub factor: f64,
    /// (μf − σf) / (μr + σr), clamped at 0 (a speed ratio cannot be negative).
    pub min: f64,
    /// (μf + σf) / (μr − σr); `f64::INFINITY` when μr − σr ≤ 0 (unbounded).
    /// Note that serde_json writes infinity as `null`.
    pub max: f64,
}

/// Impact factor of `foveated` over `regular`, both fps summaries.
///
/// Follows the thesis: factor = μf/μr, min = (μf − σf)/(μr + σr),
/// max = (μf + σf)/(μr − σr). The max is `f64::INFINITY` when μr − σr ≤ 0.
/// Returns `None` when a mean or std is not finite, a std is negative, or the
/// regular mean is ≤ 0 (no meaningful ratio).
pub fn impact(regular: &Summary, foveated: &Summary) -> Option<Impact> {
    let (mr, sr, mf, sf) = (regular.mean, regular.std, foveated.mean, foveated.std);
    let finite = [mr, sr, mf, sf].iter().all(|v| v.is_finite());
    if !finite || sr < 0.0 || sf < 0.0 || mr <= 0.0 {
        return None;
    }
    let upper_den = mr - sr;
    let max = if upper_den > 0.0 {
        (mf + sf) / upper_den
    } else {
        f64::INFINITY
    };
    Some(Impact {
        factor: mf / mr,
        min: ((mf - sf) / (mr + sr)).max(0.0),
        max,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    /// A summary with only mean and std set, as the thesis reports them.
    fn ms(mean: f64, std: f64) -> Summary {
        Summary {
            n: 100,
            mean,
            std,
            min: mean,
            max: mean,
            median: mean,
            p99: mean,
        }
    }

    #[test]
    fn summarize_small_series() {
        let s = summarize(&[16.0, 10.0, 14.0, 12.0]).unwrap();
        assert_eq!(s.n, 4);
        assert!(close(s.mean, 13.0, 1e-12));
        // sqrt(((9+1+1+9)/3)) = sqrt(20/3)
        assert!(close(s.std, (20.0f64 / 3.0).sqrt(), 1e-12));
        assert!(close(s.std, 2.582, 1e-3));
        assert_eq!(s.median, 13.0);
        assert_eq!((s.min, s.max), (10.0, 16.0));
        // h = 3 * 0.99 = 2.97 → 14 + 0.97 * 2
        assert!(close(s.p99, 15.94, 1e-12));
    }

    #[test]
    fn median_odd_and_p99_of_1_to_100() {
        assert_eq!(summarize(&[3.0, 1.0, 2.0]).unwrap().median, 2.0);
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        let s = summarize(&v).unwrap();
        assert!(close(s.p99, 99.01, 1e-9));
        assert!(close(s.median, 50.5, 1e-12));
    }

    #[test]
    fn single_value_has_zero_std() {
        let s = summarize(&[7.5]).unwrap();
        assert_eq!(
            (s.n, s.mean, s.std, s.median, s.p99),
            (1, 7.5, 0.0, 7.5, 7.5)
        );
    }

    #[test]
    fn empty_and_all_nan_are_none() {
        assert_eq!(summarize(&[]), None);
        assert_eq!(summarize(&[f64::NAN, f64::INFINITY]), None);
        assert_eq!(frame_rates(&[]), None);
        assert_eq!(frame_rates(&[0.0, -1.0, f64::NAN]), None);
    }

    #[test]
    fn nan_is_skipped_and_counted() {
        let v = [10.0, f64::NAN, 12.0, f64::NEG_INFINITY, 14.0, 16.0];
        let s = summarize(&v).unwrap();
        assert_eq!(s.n, 4);
        assert!(close(s.mean, 13.0, 1e-12));
    }

    #[test]
    fn quantile_bounds() {
        assert_eq!(quantile_sorted(&[], 0.5), None);
        assert_eq!(quantile_sorted(&[1.0], 1.5), None);
        assert_eq!(quantile_sorted(&[1.0], f64::NAN), None);
        assert_eq!(quantile_sorted(&[1.0, 2.0], 1.0), Some(2.0));
        assert_eq!(quantile_sorted(&[1.0, 2.0], 0.0), Some(1.0));
    }

    #[test]
    fn constant_frame_time_is_90_fps() {
        let r = frame_rates(&[11.111_111_111_111; 100]).unwrap();
        assert!(close(r.fps.mean, 90.0, 1e-6));
        assert!(r.fps.std < 1e-9);
        assert_eq!(r.fps.n, 100);
        assert!(close(r.ms.median, 11.111_111, 1e-5));
    }

    #[test]
    fn frame_rates_averages_rates_and_skips_bad_frames() {
        // 10 ms and 20 ms → 100 and 50 fps → mean 75 (not 1000/15 = 66.7).
        let r = frame_rates(&[10.0, 0.0, 20.0, -3.0, f64::NAN]).unwrap();
        assert_eq!((r.fps.n, r.ms.n), (2, 2));
        assert!(close(r.fps.mean, 75.0, 1e-12));
        assert!(close(r.ms.mean, 15.0, 1e-12));
    }

    /// The thesis' own numbers (low-triangle, high-triangle and cubes scenes).
    #[test]
    fn thesis_impact_factors() {
        let cases = [
            // regular, foveated, factor, min, max
            ((22.45, 2.89), (44.89, 7.69), 1.99, 1.47, 2.69),
            ((22.45, 2.89), (89.69, 4.8), 3.99, 3.35, 4.83),
            ((2.81, 0.05), (4.94, 0.38), 1.75, 1.59, 1.93),
        ];
        for ((mr, sr), (mf, sf), factor, lo, hi) in cases {
            let i = impact(&ms(mr, sr), &ms(mf, sf)).unwrap();
            assert!(close(i.factor, factor, 0.01), "{i:?} vs {factor}");
            assert!(close(i.min, lo, 0.01), "{i:?} vs {lo}");
            assert!(close(i.max, hi, 0.01), "{i:?} vs {hi}");
        }
        let cubes = impact(&ms(3.25, 0.07), &ms(16.61, 1.4)).unwrap();
        assert!(close(cubes.factor, 5.11, 0.01));
        // Hand-check of the low-triangle forward range.
        let low = impact(&ms(22.45, 2.89), &ms(44.89, 7.69)).unwrap();
        assert!(close(low.min, 1.468, 1e-3) && close(low.max, 2.688, 1e-3));
    }

    #[test]
    fn impact_edge_cases() {
        let unbounded = impact(&ms(2.0, 2.0), &ms(4.0, 1.0)).unwrap();
        assert_eq!(unbounded.max, f64::INFINITY);
        assert!(close(unbounded.factor, 2.0, 1e-12));
        assert_eq!(impact(&ms(0.0, 0.0), &ms(4.0, 1.0)), None);
        assert_eq!(impact(&ms(f64::NAN, 0.0), &ms(4.0, 1.0)), None);
        assert_eq!(impact(&ms(2.0, -1.0), &ms(4.0, 1.0)), None);
        // σf > μf would give a negative lower bound; clamped to 0.
        assert_eq!(impact(&ms(2.0, 0.1), &ms(1.0, 3.0)).unwrap().min, 0.0);
    }
}
