//! Pearson's chi-square goodness-of-fit test, as Mitsuba's and pbrt's sampler tests use it:
//! observed counts per cell against expected ones, cells with too few expected samples pooled,
//! and the statistic's p-value from the chi-square distribution (the regularized upper
//! incomplete gamma function, Numerical Recipes §6.2).

/// Cells expecting fewer samples than this are pooled into one (the statistic's chi-square
/// approximation needs about 5 per cell).
pub const MIN_EXPECTED: f64 = 5.0;

/// The outcome of one test.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct ChiSquare {
    pub statistic: f64,
    pub degrees_of_freedom: usize,
    /// The probability of a statistic at least this large if the samples follow the density.
    pub p_value: f64,
}

/// Tests `observed` counts against `expected` ones (the same cells; their totals should agree).
pub fn chi_square(observed: &[f64], expected: &[f64]) -> ChiSquare {
    let (mut statistic, mut cells) = (0.0, 0usize);
    let (mut pooled_observed, mut pooled_expected) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < MIN_EXPECTED {
            pooled_observed += o;
            pooled_expected += e;
        } else {
            statistic += (o - e).powi(2) / e;
            cells += 1;
        }
    }
    if pooled_expected > 0.0 {
        statistic += (pooled_observed - pooled_expected).powi(2) / pooled_expected;
        cells += 1;
    } else if pooled_observed > 0.0 {
        // Samples where the density says none can land: as unlikely as it gets.
        statistic = f64::INFINITY;
    }
    let degrees_of_freedom = cells.saturating_sub(1).max(1);
    ChiSquare {
        statistic,
        degrees_of_freedom,
        p_value: gamma_q(0.5 * degrees_of_freedom as f64, 0.5 * statistic),
    }
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9; about 15 digits).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularized upper incomplete gamma function Q(a, x) = Γ(a, x) / Γ(a).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x.is_infinite() {
        return 0.0;
    }
    if x <= 0.0 {
        return 1.0;
    }
    let front = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // Series for P(a, x).
        let (mut term, mut sum, mut n) = (1.0 / a, 1.0 / a, a);
        for _ in 0..1000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        (1.0 - sum * front).clamp(0.0, 1.0)
    } else {
        // Continued fraction for Q(a, x) (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let delta = d * c;
            h *= delta;
            if (delta - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (front * h).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn p_values_match_published_chi_square_tables() {
        // Critical values at p = 0.05 and 0.01 (any statistics table).
        for (dof, x05, x01) in [
            (1.0, 3.841, 6.635),
            (10.0, 18.307, 23.209),
            (100.0, 124.342, 135.807),
        ] {
            assert!(
                (gamma_q(0.5 * dof, 0.5 * x05) - 0.05).abs() < 1e-4,
                "dof {dof}"
            );
            assert!(
                (gamma_q(0.5 * dof, 0.5 * x01) - 0.01).abs() < 1e-4,
                "dof {dof}"
            );
        }
    }

    #[test]
    fn counts_that_follow_the_expectation_pass_and_others_fail() {
        let expected = [100.0; 10];
        let close = [
            96.0, 104.0, 99.0, 101.0, 110.0, 92.0, 100.0, 98.0, 103.0, 97.0,
        ];
        assert!(chi_square(&close, &expected).p_value > 0.5);
        let skewed = [
            150.0, 50.0, 100.0, 100.0, 100.0, 100.0, 100.0, 100.0, 100.0, 100.0,
        ];
        assert!(chi_square(&skewed, &expected).p_value < 1e-6);
        // A sample where nothing is expected.
        assert_eq!(chi_square(&[1.0, 99.0], &[0.0, 100.0]).p_value, 0.0);
    }
}
