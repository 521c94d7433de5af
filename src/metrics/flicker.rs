//! Temporal flicker of a rendered sequence: how much a frame changed from the one before
//! *beyond* what the converged reference changed between the same two poses. Motion itself
//! (the reference's own change) is not flicker; a frame-to-frame change of the noise, a
//! crawling fovea or a shimmering periphery, is. A constant bias does not flicker.

use super::{check_per_pixel, check_rgb, MetricsError};

/// Mean over the selected pixels and the 3 channels of
/// `((t_k − t_{k−1}) − (r_k − r_{k−1}))² / (r_k² + 0.01)`, the relMSE convention of
/// [`super::ImageError::rel_mse`] applied to the frame-to-frame change, so flicker and
/// error read on one scale (independent noise of variance σ² in every frame gives 2σ²
/// where relMSE gives σ²). `None` when `mask` selects no pixel. A non-finite test value
/// makes it infinite; a non-finite reference value is an error.
#[allow(clippy::too_many_arguments)]
pub fn flicker(
    reference: &[f32],
    reference_before: &[f32],
    test: &[f32],
    test_before: &[f32],
    width: u32,
    height: u32,
    mask: Option<&[bool]>,
) -> Result<Option<f64>, MetricsError> {
    check_rgb("reference", reference, width, height)?;
    check_rgb("reference (frame before)", reference_before, width, height)?;
    check_rgb("test", test, width, height)?;
    check_rgb("test (frame before)", test_before, width, height)?;
    if let Some(mask) = mask {
        check_per_pixel("mask", mask.len(), width, height)?;
    }
    let (mut sum, mut pixels) = (0.0f64, 0u64);
    for i in 0..(width as usize * height as usize) {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        pixels += 1;
        for c in 3 * i..3 * i + 3 {
            let (r, rb) = (reference[c], reference_before[c]);
            if !r.is_finite() || !rb.is_finite() {
                let w = width as usize;
                return Err(MetricsError::NonFiniteReference {
                    x: (i % w) as u32,
                    y: (i / w) as u32,
                    value: if r.is_finite() { rb } else { r },
                });
            }
            let change = (test[c] as f64 - test_before[c] as f64) - (r as f64 - rb as f64);
            sum += if change.is_finite() {
                change * change / (r as f64 * r as f64 + 0.01)
            } else {
                f64::INFINITY
            };
        }
    }
    Ok((pixels > 0).then(|| sum / (3 * pixels) as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::rng::Rng;

    const W: u32 = 64;
    const H: u32 = 48;

    fn ramp(shift: f32) -> Vec<f32> {
        (0..W * H * 3)
            .map(|i| 0.5 + 0.4 * ((i / 3 % W) as f32 * 0.1 + shift).sin())
            .collect()
    }

    #[test]
    fn motion_and_bias_are_not_flicker_but_fresh_noise_is() {
        let (r0, r1) = (ramp(0.0), ramp(0.3));
        // A render that follows the motion exactly, or with a constant bias, does not flicker.
        assert_eq!(flicker(&r1, &r0, &r1, &r0, W, H, None).unwrap(), Some(0.0));
        let biased = |r: &[f32]| r.iter().map(|v| v + 0.2).collect::<Vec<f32>>();
        let f = flicker(&r1, &r0, &biased(&r1), &biased(&r0), W, H, None).unwrap();
        assert!(f.unwrap() < 1e-12);
        // A still render of a moving view flickers by the motion it misses.
        assert!(flicker(&r1, &r0, &r0, &r0, W, H, None).unwrap().unwrap() > 1e-3);
        // Fresh noise of σ in every frame: 2σ² / (r² + 0.01) on average.
        let mut rng = Rng::new(7);
        let sigma = 0.05f32;
        let mut noisy = |r: &[f32]| -> Vec<f32> {
            r.iter()
                .map(|v| v + sigma * (rng.unit() as f32 * 2.0 - 1.0) * 3f32.sqrt())
                .collect()
        };
        let (t0, t1) = (noisy(&r0), noisy(&r1));
        let f = flicker(&r1, &r0, &t1, &t0, W, H, None).unwrap().unwrap();
        let expected: f64 = r1
            .iter()
            .map(|&r| 2.0 * (sigma as f64).powi(2) / (r as f64 * r as f64 + 0.01))
            .sum::<f64>()
            / r1.len() as f64;
        assert!((f / expected - 1.0).abs() < 0.1, "{f} vs {expected}");
    }

    #[test]
    fn masks_select_and_bad_input_is_an_error() {
        let (r0, r1) = (ramp(0.0), ramp(0.3));
        let none = vec![false; (W * H) as usize];
        assert_eq!(
            flicker(&r1, &r0, &r0, &r0, W, H, Some(&none)).unwrap(),
            None
        );
        assert!(flicker(&r1, &r0, &r0[3..], &r0, W, H, None).is_err());
        let mut bad = r1.clone();
        bad[5] = f32::NAN;
        assert!(matches!(
            flicker(&bad, &r0, &r1, &r0, W, H, None),
            Err(MetricsError::NonFiniteReference { x: 1, y: 0, .. })
        ));
        let mut broken = r1.clone();
        broken[0] = f32::INFINITY;
        let f = flicker(&r1, &r0, &broken, &r0, W, H, None).unwrap();
        assert_eq!(f, Some(f64::INFINITY));
    }
}
