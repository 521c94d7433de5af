//! Blend masks (thesis eq. 3.18): how much of layer `k` shows at an angle from the gaze.
//! resolve.comp computes the same weight per pixel; the CPU version states the bound the
//! tests hold the GPU to.

/// The blend-mask value `v_b` of a layer of angular radius `radius` with a blend band of
/// width `band` just inside it: 1 inside `radius - band`, 0 from `radius` out, linear
/// between. A band of 0 is a hard edge.
pub fn weight(theta: f64, radius: f64, band: f64) -> f64 {
    if theta >= radius {
        0.0
    } else if band <= 0.0 || theta <= radius - band {
        1.0
    } else {
        (radius - theta) / band
    }
}

/// The most the merged image can step between neighbouring pixels at a layer border where
/// the two layers differ by `difference`: the mask changes by at most one pixel's angle over
/// the band width per pixel (a hard edge steps by the full difference).
pub fn max_border_step(difference: f64, band: f64, radians_per_pixel: f64) -> f64 {
    if band <= 0.0 {
        difference
    } else {
        difference * (radians_per_pixel / band).min(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_is_one_inside_zero_outside_and_linear_in_the_band() {
        assert_eq!(weight(0.0, 0.1, 0.02), 1.0);
        assert_eq!(weight(0.08, 0.1, 0.02), 1.0);
        assert!((weight(0.09, 0.1, 0.02) - 0.5).abs() < 1e-12);
        assert_eq!(weight(0.1, 0.1, 0.02), 0.0);
        assert_eq!(weight(0.0999, 0.1, 0.0), 1.0);
        assert_eq!(max_border_step(0.5, 0.0, 0.001), 0.5);
        assert!((max_border_step(0.5, 0.02, 0.001) - 0.025).abs() < 1e-12);
    }
}
