//! The eye's acuity against eccentricity, as the lattice filter (glsl/lattice_filter.comp)
//! sizes its blur by it: the minimum angle of resolution grows about linearly with the angle
//! from the gaze (Guenter et al. 2012, "Foveated 3D Graphics", from Weymouth's data), 0.022°
//! per degree of eccentricity plus 1/48° at the centre. The shader has the same line
//! (MAR_SLOPE, MAR_CENTRE); this is its host side, for tests and for reasoning about widths.

/// Degrees of minimum angle of resolution per degree of eccentricity.
pub const MAR_SLOPE: f64 = 0.022;
/// The minimum angle of resolution at the centre of the gaze, in degrees.
pub const MAR_CENTRE_DEG: f64 = 1.0 / 48.0;
/// Below this width (in lattice steps) the filter copies the point as traced.
pub const MIN_FILTER_WIDTH: f64 = 0.25;

/// The minimum angle of resolution, in radians, `eccentricity` radians from the gaze.
pub fn minimum_angle_of_resolution(eccentricity: f64) -> f64 {
    MAR_SLOPE * eccentricity + MAR_CENTRE_DEG.to_radians()
}

/// The lattice filter's Gaussian width, in lattice steps, at a point `eccentricity` radians
/// from the gaze whose lattice step spans `step_angle` radians, for a layer of `spacing`
/// with widths `filter_mar` (minimum angles of resolution) and `filter_px` (pixels).
pub fn filter_width(
    filter_mar: f64,
    filter_px: f64,
    spacing: u32,
    eccentricity: f64,
    step_angle: f64,
) -> f64 {
    let by_acuity = filter_mar * minimum_angle_of_resolution(eccentricity) / step_angle;
    by_acuity.max(filter_px / spacing as f64)
}

/// The denoiser's width, in pixels, after its iterations 0..=`i` (glsl/denoise.comp's
/// `width_after`, which a layer's `denoise_mar` limits): iteration i's B3-spline kernel has
/// a standard deviation of its tap spacing, 2^i pixels, and the iterations add in variance.
pub fn denoise_width_after(i: u32) -> f64 {
    ((4f64.powi(i as i32 + 1) - 1.0) / 3.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acuity_falls_linearly_from_the_centre() {
        let deg = |d: f64| minimum_angle_of_resolution(d.to_radians()).to_degrees();
        assert!((deg(0.0) - 1.0 / 48.0).abs() < 1e-12);
        // 20° out the eye resolves 0.46°: 6 pixels of the Vive Pro Eye's 13.7 per degree.
        assert!((deg(20.0) - (0.44 + 1.0 / 48.0)).abs() < 1e-9);
        assert!(deg(40.0) > 2.0 * deg(20.0) - deg(0.0) - 1e-9);
    }

    #[test]
    fn the_width_is_the_wider_of_acuity_and_pixels() {
        let step = (4.0f64 / 13.7).to_radians(); // spacing 4 at 13.7 px/°
        let at_30 = filter_width(1.0, 0.0, 4, 30f64.to_radians(), step);
        assert!((at_30 - (0.66 + 1.0 / 48.0) / (4.0 / 13.7)).abs() < 1e-6);
        assert_eq!(filter_width(0.0, 2.0, 4, 0.5, step), 0.5);
        assert_eq!(filter_width(0.0, 0.0, 4, 0.5, step), 0.0);
    }

    #[test]
    fn the_denoisers_width_adds_its_iterations_in_variance() {
        // The B3 spline's taps (1, 4, 6, 4, 1) / 16 at -2..=2 have variance 1 tap spacing^2.
        let taps = [1.0, 4.0, 6.0, 4.0, 1.0].map(|w: f64| w / 16.0);
        let variance: f64 = (0..5).map(|j| taps[j] * (j as f64 - 2.0).powi(2)).sum();
        assert!((variance - 1.0).abs() < 1e-12);
        let mut summed = 0.0;
        for i in 0..5 {
            summed += 4f64.powi(i as i32);
            assert!((denoise_width_after(i) - summed.sqrt()).abs() < 1e-9);
        }
        assert!((denoise_width_after(2) - 21f64.sqrt()).abs() < 1e-12);
    }
}
