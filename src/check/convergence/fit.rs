//! Straight lines in log-log space: how error falls with samples or time.

use serde::Serialize;

/// A least-squares line `ln y = intercept + slope · ln x`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LogLogFit {
    pub slope: f64,
    pub intercept: f64,
    /// Coefficient of determination of the fit in log-log space (1 = every point on the line).
    pub r2: f64,
}

impl LogLogFit {
    /// Fits the points with positive, finite `x` and `y`; `None` with fewer than two distinct
    /// `x`.
    pub fn fit(points: &[(f64, f64)]) -> Option<Self> {
        let logs: Vec<(f64, f64)> = points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
            .map(|(x, y)| (x.ln(), y.ln()))
            .collect();
        let n = logs.len() as f64;
        let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
        let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
        let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let syy: f64 = logs.iter().map(|p| (p.1 - my).powi(2)).sum();
        if logs.len() < 2 || sxx <= 0.0 {
            return None;
        }
        let slope = sxy / sxx;
        let intercept = my - slope * mx;
        let r2 = if syy > 0.0 {
            sxy * sxy / (sxx * syy)
        } else {
            1.0
        };
        Some(Self {
            slope,
            intercept,
            r2,
        })
    }

    /// The fitted `y` at `x`.
    pub fn at(&self, x: f64) -> f64 {
        (self.intercept + self.slope * x.ln()).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_law_fits_exactly() {
        let points: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(-0.5)))
            .collect();
        let f = LogLogFit::fit(&points).unwrap();
        assert!((f.slope + 0.5).abs() < 1e-12, "{f:?}");
        assert!((f.r2 - 1.0).abs() < 1e-12, "{f:?}");
        assert!((f.at(16.0) - 0.75).abs() < 1e-12, "{f:?}");
        assert!(LogLogFit::fit(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
        assert!(LogLogFit::fit(&[(1.0, 1.0), (2.0, 0.0)]).is_none());
    }
}
