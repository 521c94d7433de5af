//! Error per eccentricity band around the gaze, the rings in which the foveated renderer's
//! layers spend different effort. Eccentricity is a true angle between view directions,
//! computed through the image's geometry, never a pixel distance: with a wide asymmetric
//! field of view, one degree spans about twice as many pixels at the edge as at the axis.

use super::{check_rgb, image_error, ImageError, MetricsError};
use crate::foveation::view::{angle_between, ImageGeometry};

/// A ring of eccentricities `[lo_deg, hi_deg)` around the gaze, in degrees.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Band {
    pub name: &'static str,
    pub lo_deg: f64,
    pub hi_deg: f64,
}

/// The bands' limits in degrees, half-open `[lo, hi)`: the thesis' layers (fovea to 6°,
/// 6–10°, 10–20°, periphery beyond 20°). Together they cover every angle exactly once.
pub const BANDS_DEG: [(f64, f64); 4] =
    [(0.0, 6.0), (6.0, 10.0), (10.0, 20.0), (20.0, f64::INFINITY)];

/// The bands of [`BANDS_DEG`] with their names.
pub const BANDS: [Band; 4] = [
    Band {
        name: "0-6",
        lo_deg: BANDS_DEG[0].0,
        hi_deg: BANDS_DEG[0].1,
    },
    Band {
        name: "6-10",
        lo_deg: BANDS_DEG[1].0,
        hi_deg: BANDS_DEG[1].1,
    },
    Band {
        name: "10-20",
        lo_deg: BANDS_DEG[2].0,
        hi_deg: BANDS_DEG[2].1,
    },
    Band {
        name: "20+",
        lo_deg: BANDS_DEG[3].0,
        hi_deg: BANDS_DEG[3].1,
    },
];

impl Band {
    /// Whether an eccentricity in degrees lies in `[lo_deg, hi_deg)`. NaN lies in none.
    pub fn contains(&self, deg: f64) -> bool {
        self.lo_deg <= deg && deg < self.hi_deg
    }
}

/// The error of one band; `error.pixels` is 0 for a band with no pixel on the image (for
/// instance the periphery of a narrow field of view).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BandError {
    pub band: &'static str,
    pub lo_deg: f64,
    pub hi_deg: f64,
    pub error: ImageError,
}

/// Eccentricity in degrees of every pixel centre (row-major from the top-left): the true
/// angle between the pixel's view direction and the gaze direction, where the gaze is a
/// continuous pixel position (its direction is `image.tan_of(gaze_px)`; it may lie off the
/// image). A non-finite gaze gives NaN everywhere.
pub fn eccentricity_deg(image: &ImageGeometry, gaze_px: [f64; 2]) -> Vec<f32> {
    eccentricity_deg_f64(image, gaze_px)
        .map(|deg| deg as f32)
        .collect()
}

/// [`eccentricity_deg`] in `f64`, which band membership uses so that a band's edge is
/// decided on the exact angle rather than on its `f32` rounding.
fn eccentricity_deg_f64(
    image: &ImageGeometry,
    gaze_px: [f64; 2],
) -> impl Iterator<Item = f64> + '_ {
    let gaze = image.tan_of(gaze_px[0], gaze_px[1]);
    let (w, h) = (i64::from(image.width), i64::from(image.height));
    (0..h).flat_map(move |y| {
        (0..w).map(move |x| angle_between(image.pixel_centre_tan(x, y), gaze).to_degrees())
    })
}

/// For each band of [`BANDS`], which pixels of the image (row-major) lie in it. Every pixel
/// is in exactly one band. Use these with [`super::flip_masked_mean`] for FLIP per band.
pub fn band_masks(
    image: &ImageGeometry,
    gaze_px: [f64; 2],
) -> Result<[Vec<bool>; 4], MetricsError> {
    if !(gaze_px[0].is_finite() && gaze_px[1].is_finite()) {
        return Err(MetricsError::NonFiniteGaze(gaze_px[0], gaze_px[1]));
    }
    let (n, _) = super::pixel_count(image.width, image.height)?;
    let mut masks: [Vec<bool>; 4] = std::array::from_fn(|_| vec![false; n]);
    for (i, deg) in eccentricity_deg_f64(image, gaze_px).enumerate() {
        if let Some(b) = BANDS.iter().position(|b| b.contains(deg)) {
            masks[b][i] = true;
        }
    }
    Ok(masks)
}

/// The [`ImageError`] of `test` against `reference` (linear RGB images of `image`'s size) in
/// each eccentricity band of [`BANDS`] around the gaze, in that order.
pub fn band_errors(
    reference: &[f32],
    test: &[f32],
    image: &ImageGeometry,
    gaze_px: [f64; 2],
) -> Result<Vec<BandError>, MetricsError> {
    check_rgb("reference", reference, image.width, image.height)?;
    check_rgb("test", test, image.width, image.height)?;
    let masks = band_masks(image, gaze_px)?;
    BANDS
        .iter()
        .zip(&masks)
        .map(|(band, mask)| {
            Ok(BandError {
                band: band.name,
                lo_deg: band.lo_deg,
                hi_deg: band.hi_deg,
                error: image_error(reference, test, image.width, image.height, Some(mask))?,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::view::EyeFov;

    fn vive_small() -> ImageGeometry {
        // The Vive's asymmetric field of view on a small grid keeps the tests fast.
        ImageGeometry::new(144, 160, EyeFov::VIVE_PRO_EYE_LEFT)
    }

    fn symmetric(half_deg: f32, size: u32) -> ImageGeometry {
        let a = half_deg.to_radians();
        ImageGeometry::new(
            size,
            size,
            EyeFov {
                left: -a,
                right: a,
                up: a,
                down: -a,
            },
        )
    }

    #[test]
    fn bands_tile_the_angles() {
        assert_eq!(BANDS.map(|b| b.name), ["0-6", "6-10", "10-20", "20+"]);
        assert_eq!(BANDS.map(|b| (b.lo_deg, b.hi_deg)), BANDS_DEG);
        assert_eq!(BANDS[0].lo_deg, 0.0);
        for pair in BANDS.windows(2) {
            assert_eq!(pair[0].hi_deg, pair[1].lo_deg);
        }
        assert!(BANDS[0].contains(0.0) && !BANDS[0].contains(6.0) && BANDS[1].contains(6.0));
        assert!(BANDS[3].contains(179.9) && !BANDS.iter().any(|b| b.contains(f64::NAN)));
    }

    #[test]
    fn gaze_pixel_has_zero_eccentricity() {
        let g = vive_small();
        let (x, y) = (30u32, 100u32);
        let ecc = eccentricity_deg(&g, [x as f64 + 0.5, y as f64 + 0.5]);
        assert_eq!(ecc.len(), 144 * 160);
        let own = ecc[(y * g.width + x) as usize] as f64;
        assert!(own < 1e-6, "{own}");
        // A gaze anywhere inside the pixel is less than half a pixel's angle from its centre.
        let ecc = eccentricity_deg(&g, [x as f64 + 0.9, y as f64 + 0.1]);
        let own = ecc[(y * g.width + x) as usize] as f64;
        assert!(own < 0.5 * g.max_radians_per_pixel().to_degrees() * 2f64.sqrt());
    }

    #[test]
    fn a_direction_five_degrees_away_has_that_eccentricity() {
        let g = symmetric(30.0, 601);
        let gaze = g.axis_pixel(); // centre of pixel (300, 300)
                                   // Where the direction 5° right of the axis meets the image.
        let p = g.pixel_of([5f64.to_radians().tan(), 0.0]);
        let (x, y) = (p[0].floor() as u32, p[1].floor() as u32);
        let ecc = eccentricity_deg(&g, gaze);
        let got = ecc[(y * g.width + x) as usize] as f64;
        // The pixel centre is within half a pixel of the exact point.
        let half_pixel = 0.5 * g.max_radians_per_pixel().to_degrees();
        assert!((got - 5.0).abs() < half_pixel, "{got}");
        // And exactly the angle of its own centre.
        let centre = g.pixel_centre_tan(x as i64, y as i64);
        let exact = centre[0].atan().to_degrees();
        assert!((got - exact).abs() < 1e-4, "{got} vs {exact}");
    }

    #[test]
    fn band_counts_match_a_brute_force_count() {
        let g = vive_small();
        let gaze = [40.3, 70.8];
        let masks = band_masks(&g, gaze).unwrap();
        // Independent angle: acos of the dot product of normalised directions.
        let mut counts = [0u64; 4];
        let gt = g.tan_of(gaze[0], gaze[1]);
        let gn = (gt[0] * gt[0] + gt[1] * gt[1] + 1.0).sqrt();
        for y in 0..g.height as i64 {
            for x in 0..g.width as i64 {
                let t = g.pixel_centre_tan(x, y);
                let tn = (t[0] * t[0] + t[1] * t[1] + 1.0).sqrt();
                let cos = (t[0] * gt[0] + t[1] * gt[1] + 1.0) / (tn * gn);
                let deg = cos.clamp(-1.0, 1.0).acos().to_degrees();
                let b = BANDS_DEG.iter().position(|&(lo, hi)| lo <= deg && deg < hi);
                counts[b.unwrap()] += 1;
            }
        }
        let r = vec![0.25f32; 144 * 160 * 3];
        let errs = band_errors(&r, &r, &g, gaze).unwrap();
        let got: Vec<u64> = errs.iter().map(|e| e.error.pixels).collect();
        assert_eq!(got, counts.to_vec());
        assert_eq!(got.iter().sum::<u64>(), 144 * 160);
        assert!(got.iter().all(|&c| c > 0), "{got:?}");
        for (m, c) in masks.iter().zip(counts) {
            assert_eq!(m.iter().filter(|&&b| b).count() as u64, c);
        }
    }

    #[test]
    fn errors_land_in_their_band() {
        let g = symmetric(40.0, 101);
        let gaze = g.axis_pixel();
        let r = vec![0.5f32; 101 * 101 * 3];
        let mut t = r.clone();
        t[..3].copy_from_slice(&[0.0; 3]); // the top-left corner, about 50° out
        let errs = band_errors(&r, &t, &g, gaze).unwrap();
        assert_eq!(
            errs.iter().map(|e| e.band).collect::<Vec<_>>(),
            BANDS.map(|b| b.name)
        );
        assert!(errs[..3].iter().all(|e| e.error.mse == 0.0));
        assert!(errs[3].error.mse > 0.0);
    }

    #[test]
    fn bands_off_a_narrow_image_are_empty() {
        let g = symmetric(4.0, 33);
        let r = vec![0.1f32; 33 * 33 * 3];
        let errs = band_errors(&r, &r, &g, g.axis_pixel()).unwrap();
        assert_eq!(errs[0].error.pixels, 33 * 33);
        for e in &errs[1..] {
            assert_eq!(e.error, ImageError::EMPTY);
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        let g = symmetric(30.0, 8);
        let r = vec![0.0f32; 8 * 8 * 3];
        let err = band_errors(&r, &r[..10], &g, [4.0, 4.0]).unwrap_err();
        assert!(matches!(
            err,
            MetricsError::ImageLength { image: "test", .. }
        ));
        let err = band_errors(&r, &r, &g, [f64::NAN, 4.0]).unwrap_err();
        assert!(matches!(err, MetricsError::NonFiniteGaze(..)));
        assert!(eccentricity_deg(&g, [f64::NAN, 0.0])
            .iter()
            .all(|d| d.is_nan()));
    }
}
