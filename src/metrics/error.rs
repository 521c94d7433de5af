//! Per-pixel error statistics of a test image against a reference: MSE and relMSE on linear
//! radiance, PSNR on the displayed (sRGB) image.

use super::{check_per_pixel, check_rgb, MetricsError};
use crate::render::output::linear_to_srgb;

/// The error of a test image against a reference over a set of pixels.
///
/// A non-finite test value (NaN or ±inf, a broken render) is never skipped: it makes the
/// squared error of its channel `+inf`, so `mse` and `rel_mse` become infinite and the
/// breakage is obvious. For `psnr_db` it is displayed as 0 (black), as
/// [`linear_to_srgb`] and so the written PNG show it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ImageError {
    /// Number of pixels the statistics are over (those selected by the mask).
    pub pixels: u64,
    /// Mean squared error over pixels and the 3 channels of `(test − ref)²`, on linear
    /// radiance (values may exceed 1).
    pub mse: f64,
    /// Relative MSE: the mean over pixels and the 3 channels of
    /// `(test − ref)² / (ref² + 0.01)`, the convention of Rousselle, Knaus and Zwicker,
    /// "Adaptive Sampling and Reconstruction using Greedy Error Minimization", SIGGRAPH Asia
    /// 2011; the 0.01 keeps dark pixels from dominating.
    pub rel_mse: f64,
    /// Peak signal-to-noise ratio of the displayed image: both images through
    /// [`linear_to_srgb`] (clamped to [0, 1], not quantised to 8 bits), then
    /// `10·log10(1 / mse_display)`. `f64::INFINITY` when the displayed images are identical.
    pub psnr_db: f64,
}

impl ImageError {
    /// The statistics of an empty selection: no pixels, no error, infinite PSNR. Never NaN,
    /// so it serialises and sorts cleanly; check `pixels` to tell it from a perfect match.
    pub const EMPTY: ImageError = ImageError {
        pixels: 0,
        mse: 0.0,
        rel_mse: 0.0,
        psnr_db: f64::INFINITY,
    };
}

/// The [`ImageError`] of `test` against `reference`, both linear RGB `width`×`height`
/// images (3 floats per pixel, row-major from the top-left), over the pixels where `mask`
/// is true (one entry per pixel), or over every pixel if `mask` is `None`.
///
/// Sums are accumulated in `f64`. A selection of zero pixels gives [`ImageError::EMPTY`].
///
/// Errors: a slice or mask of the wrong length, or a non-finite value in a selected pixel of
/// the reference (a broken reference makes every number meaningless).
pub fn image_error(
    reference: &[f32],
    test: &[f32],
    width: u32,
    height: u32,
    mask: Option<&[bool]>,
) -> Result<ImageError, MetricsError> {
    check_rgb("reference", reference, width, height)?;
    check_rgb("test", test, width, height)?;
    if let Some(mask) = mask {
        check_per_pixel("mask", mask.len(), width, height)?;
    }

    let mut pixels = 0u64;
    let (mut sq, mut rel, mut sq_display) = (0.0f64, 0.0f64, 0.0f64);
    let pairs = reference.chunks_exact(3).zip(test.chunks_exact(3));
    for (i, (r, t)) in pairs.enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        pixels += 1;
        for (&rv, &tv) in r.iter().zip(t) {
            if !rv.is_finite() {
                let w = width as usize;
                return Err(MetricsError::NonFiniteReference {
                    x: (i % w) as u32,
                    y: (i / w) as u32,
                    value: rv,
                });
            }
            let (rf, tf) = (f64::from(rv), f64::from(tv));
            let d2 = if tv.is_finite() {
                (tf - rf) * (tf - rf)
            } else {
                // NaN − ref would be NaN and vanish from comparisons; make it loud instead.
                f64::INFINITY
            };
            sq += d2;
            rel += d2 / (rf * rf + 0.01);
            let dd = f64::from(linear_to_srgb(tv)) - f64::from(linear_to_srgb(rv));
            sq_display += dd * dd;
        }
    }
    if pixels == 0 {
        return Ok(ImageError::EMPTY);
    }
    let n = 3.0 * pixels as f64;
    let mse_display = sq_display / n;
    Ok(ImageError {
        pixels,
        mse: sq / n,
        rel_mse: rel / n,
        psnr_db: if mse_display > 0.0 {
            10.0 * (1.0 / mse_display).log10()
        } else {
            f64::INFINITY
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sRGB transfer function written out again, so the PSNR check does not just
    /// repeat the code under test.
    fn srgb(v: f64) -> f64 {
        if v <= 0.0031308 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        }
    }

    fn uniform(v: f32, w: u32, h: u32) -> Vec<f32> {
        vec![v; (w * h * 3) as usize]
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs().max(1.0)
    }

    #[test]
    fn identical_images_have_no_error() {
        let img: Vec<f32> = (0..4 * 3 * 3).map(|i| i as f32 * 0.37).collect();
        let e = image_error(&img, &img, 4, 3, None).unwrap();
        assert_eq!(e.pixels, 12);
        assert_eq!((e.mse, e.rel_mse), (0.0, 0.0));
        assert_eq!(e.psnr_db, f64::INFINITY);
    }

    #[test]
    fn known_values_for_a_uniform_offset() {
        let (r, t) = (uniform(0.5, 8, 4), uniform(0.6, 8, 4));
        let e = image_error(&r, &t, 8, 4, None).unwrap();
        // f32 0.5 and 0.6 differ by 0.1 only to f32 precision.
        let d = f64::from(0.6f32) - 0.5;
        assert!(close(e.mse, 0.01, 1e-6), "{}", e.mse);
        assert!(close(e.rel_mse, d * d / (0.25 + 0.01), 1e-12));
        assert!(close(e.rel_mse, 0.01 / 0.26, 1e-6));
        let dd = srgb(0.6) - srgb(0.5); // 0.797738 − 0.735357
        let psnr = 10.0 * (1.0 / (dd * dd)).log10();
        assert!(close(e.psnr_db, psnr, 1e-5), "{} vs {psnr}", e.psnr_db);
        assert!((psnr - 24.1).abs() < 0.1, "{psnr}");
    }

    #[test]
    fn hdr_values_count_in_mse_but_clamp_in_psnr() {
        let (r, t) = (uniform(2.0, 2, 2), uniform(4.0, 2, 2));
        let e = image_error(&r, &t, 2, 2, None).unwrap();
        assert_eq!(e.mse, 4.0);
        assert!(close(e.rel_mse, 4.0 / 4.01, 1e-12));
        // Both display as white.
        assert_eq!(e.psnr_db, f64::INFINITY);
    }

    #[test]
    fn mask_selects_pixels() {
        // Left half: exact; right half: off by 1.
        let (w, h) = (4u32, 2u32);
        let r = uniform(0.0, w, h);
        let mut t = r.clone();
        let mut right = vec![false; (w * h) as usize];
        for y in 0..h {
            for x in w / 2..w {
                let i = (y * w + x) as usize;
                right[i] = true;
                t[3 * i..3 * i + 3].copy_from_slice(&[1.0, 1.0, 1.0]);
            }
        }
        let left: Vec<bool> = right.iter().map(|b| !b).collect();
        let all = image_error(&r, &t, w, h, None).unwrap();
        let l = image_error(&r, &t, w, h, Some(&left)).unwrap();
        let rr = image_error(&r, &t, w, h, Some(&right)).unwrap();
        assert_eq!((l.pixels, rr.pixels, all.pixels), (4, 4, 8));
        assert_eq!((l.mse, l.psnr_db), (0.0, f64::INFINITY));
        assert_eq!(rr.mse, 1.0);
        assert_eq!(rr.rel_mse, 100.0);
        // Black against white on screen: PSNR 0 dB, up to f32's sRGB of 1.0 (0.99999994).
        assert!(rr.psnr_db.abs() < 1e-6, "{}", rr.psnr_db);
        assert_eq!(all.mse, 0.5);
        let none = image_error(&r, &t, w, h, Some(&[false; 8])).unwrap();
        assert_eq!(none, ImageError::EMPTY);
    }

    #[test]
    fn non_finite_test_values_are_loud() {
        let r = uniform(0.5, 3, 3);
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let mut t = r.clone();
            t[4] = bad;
            let e = image_error(&r, &t, 3, 3, None).unwrap();
            assert_eq!(e.mse, f64::INFINITY, "{bad}");
            assert_eq!(e.rel_mse, f64::INFINITY, "{bad}");
            // On screen the bad channel is black: one channel of 27 off by srgb(0.5).
            let psnr = 10.0 * (27.0 / (srgb(0.5) * srgb(0.5))).log10();
            assert!(close(e.psnr_db, psnr, 1e-6), "{bad}: {}", e.psnr_db);
        }
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let r = uniform(0.5, 64, 64);
        let t = uniform(0.5, 32, 64);
        let err = image_error(&r, &t, 64, 64, None).unwrap_err();
        assert!(matches!(
            err,
            MetricsError::ImageLength { image: "test", .. }
        ));
        let err = image_error(&t, &r, 64, 64, None).unwrap_err();
        assert!(matches!(
            err,
            MetricsError::ImageLength {
                image: "reference",
                ..
            }
        ));
        let err = image_error(&r, &r, 64, 64, Some(&[true; 10])).unwrap_err();
        assert!(matches!(err, MetricsError::PerPixelLength { got: 10, .. }));
        let mut bad = r.clone();
        bad[3 * (2 * 64 + 5) + 1] = f32::NAN;
        let err = image_error(&bad, &r, 64, 64, None).unwrap_err();
        assert!(matches!(
            err,
            MetricsError::NonFiniteReference { x: 5, y: 2, .. }
        ));
    }

    #[test]
    fn empty_image_is_empty() {
        assert_eq!(
            image_error(&[], &[], 0, 7, None).unwrap(),
            ImageError::EMPTY
        );
    }
}
