//! FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström and Fairchild, "FLIP: A
//! Difference Evaluator for Alternating Images", HPG 2020): a per-pixel perceptual error in
//! [0, 1] for images as they are displayed, combining a colour difference of spatially
//! filtered images with an edge and point feature difference. This is LDR-FLIP, computed by
//! NVIDIA's own C++ implementation through the `nv-flip` crate, on the 8-bit sRGB images our
//! PNGs hold.

use super::{check_per_pixel, check_rgb, pixel_count, MetricsError};
use crate::foveation::view::{angle_between, ImageGeometry};
use crate::render::display::DisplayTransform;
#[cfg(test)]
use crate::render::output::linear_to_srgb8;

/// A FLIP error map and its mean.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipResult {
    /// Mean of `map` (accumulated in `f64`): the single number the FLIP authors recommend.
    pub mean: f64,
    /// FLIP per pixel, in [0, 1], row-major from the top-left.
    pub map: Vec<f32>,
}

/// LDR-FLIP of `test` against `reference`, linear RGB `width`×`height` images, both first
/// encoded to 8-bit sRGB as our PNGs are (clipped: a NaN shows as black, values above 1 as
/// white). `pixels_per_degree` is the observer's angular resolution, which sets the size of
/// FLIP's contrast-sensitivity and feature filters; see [`pixels_per_degree`].
///
/// An empty image gives mean 0 and an empty map.
pub fn flip(
    reference: &[f32],
    test: &[f32],
    width: u32,
    height: u32,
    pixels_per_degree: f64,
) -> Result<FlipResult, MetricsError> {
    let clamp = DisplayTransform::CLAMP;
    flip_shown(reference, test, width, height, pixels_per_degree, &clamp)
}

/// [`flip`] of the images as `display` shows them (exposed and tone mapped before the
/// sRGB encoding), as a PNG of the scene is written.
pub fn flip_shown(
    reference: &[f32],
    test: &[f32],
    width: u32,
    height: u32,
    pixels_per_degree: f64,
    display: &DisplayTransform,
) -> Result<FlipResult, MetricsError> {
    check_rgb("reference", reference, width, height)?;
    check_rgb("test", test, width, height)?;
    // The filters are sized from it; nv-flip takes an f32.
    let ppd = pixels_per_degree as f32;
    if !(ppd.is_finite() && ppd > 0.0) {
        return Err(MetricsError::PixelsPerDegree(pixels_per_degree));
    }
    let (pixels, bytes) = pixel_count(width, height)?;
    // nv-flip checks the data length as `width * height * 3` in u32.
    if bytes > u32::MAX as usize {
        return Err(MetricsError::TooLarge {
            width,
            height,
            why: "nv-flip counts its RGB8 bytes in 32 bits",
        });
    }
    if pixels == 0 {
        return Ok(FlipResult {
            mean: 0.0,
            map: Vec::new(),
        });
    }
    let r = nv_flip::FlipImageRgb8::with_data(width, height, &display.srgb8(reference));
    let t = nv_flip::FlipImageRgb8::with_data(width, height, &display.srgb8(test));
    // Sizes were checked above: nv_flip::flip panics on a mismatch.
    let map = nv_flip::flip(r, t, ppd).to_vec();
    // FlipPool's mean sums in f32, which drifts on megapixel images; sum in f64 instead.
    let mean = map.iter().map(|&v| f64::from(v)).sum::<f64>() / pixels as f64;
    Ok(FlipResult { mean, map })
}

/// Mean of a FLIP map over the pixels where `mask` is true (for instance one band of
/// [`super::band_masks`]), accumulated in `f64`; 0 when no pixel is selected.
pub fn flip_masked_mean(map: &[f32], mask: &[bool]) -> Result<f64, MetricsError> {
    if map.len() != mask.len() {
        return Err(MetricsError::SelectionLength {
            what: "mask",
            got: mask.len(),
            need: map.len(),
        });
    }
    let (sum, n) = map
        .iter()
        .zip(mask)
        .filter(|(_, &m)| m)
        .fold((0.0f64, 0u64), |(s, n), (&v, _)| (s + f64::from(v), n + 1));
    Ok(if n == 0 { 0.0 } else { sum / n as f64 })
}

/// A FLIP map as an 8-bit RGB image (3 bytes per pixel) through the magma colour map of
/// nv-flip, indexed as the FLIP tool does: `round(255 · value)`. Values are clamped to
/// [0, 1]; a non-finite value shows as the top of the scale, so it cannot pass unnoticed.
pub fn magma_rgb8(map: &[f32], width: u32, height: u32) -> Result<Vec<u8>, MetricsError> {
    check_per_pixel("FLIP map", map.len(), width, height)?;
    // The table is 256 entries; looking it up here rather than through
    // `FlipImageFloat::apply_color_lut` keeps out-of-range values away from C++ indexing.
    let lut = nv_flip::magma_lut().to_vec();
    let mut out = Vec::with_capacity(3 * map.len());
    for &v in map {
        let v = if v.is_finite() {
            v.clamp(0.0, 1.0)
        } else {
            1.0
        };
        let i = (v * 255.0 + 0.5) as usize;
        out.extend_from_slice(&lut[3 * i..3 * i + 3]);
    }
    Ok(out)
}

/// Pixels per degree at the continuous pixel position `at`, along the image's rows: one
/// degree over the angle between the two horizontal neighbours half a pixel either side.
pub fn pixels_per_degree_at(image: &ImageGeometry, at: [f64; 2]) -> f64 {
    let a = image.tan_of(at[0] - 0.5, at[1]);
    let b = image.tan_of(at[0] + 0.5, at[1]);
    1.0 / angle_between(a, b).to_degrees()
}

/// Pixels per degree of `image` at its view axis, the number FLIP's filters are sized by.
///
/// FLIP takes one pixels-per-degree for the whole image, but on a tangent-space pixel grid
/// the angular size of a pixel shrinks away from the axis (the Vive's 1440 px over ~105°
/// give about 9.6 px/° at the axis but about twice that at the edge). The axis value is
/// used because it is where pixels are largest, so FLIP's filters are never sharper than
/// the display can show, and because the fovea, where error is judged most strictly, sits
/// near the axis when the eye looks ahead. It is not `width / fov_degrees` (13.7 for the
/// Vive), which averages over the whole field of view.
pub fn pixels_per_degree(image: &ImageGeometry) -> f64 {
    pixels_per_degree_at(image, image.axis_pixel())
}

#[cfg(test)]
#[path = "flip_reference.rs"]
mod flip_reference;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::view::EyeFov;

    /// A linear value whose 8-bit sRGB encoding is exactly `byte`.
    pub(super) fn linear_of(byte: u8) -> f32 {
        let s = f64::from(byte) / 255.0;
        let l = if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        };
        l as f32
    }

    #[test]
    fn flip_sees_what_the_display_shows() {
        // Two images that differ only above white: clipped alike, tone mapped apart.
        let (w, h) = (32u32, 32u32);
        let reference: Vec<f32> = (0..w * h * 3).map(|i| 2.0 + (i % 7) as f32 * 0.3).collect();
        let test: Vec<f32> = reference.iter().map(|v| 0.5 * v + 1.0).collect();
        let clipped = flip(&reference, &test, w, h, 30.0).unwrap().mean;
        assert_eq!(clipped, 0.0);
        let neutral = crate::render::display::DisplayTransform {
            tonemap: crate::render::display::Tonemap::PbrNeutral,
            ..DisplayTransform::CLAMP
        };
        let mapped = flip_shown(&reference, &test, w, h, 30.0, &neutral)
            .unwrap()
            .mean;
        assert!(mapped > 0.0, "{mapped}");
    }

    #[test]
    fn encoding_matches_the_png_writer() {
        for byte in 0..=255u8 {
            assert_eq!(linear_to_srgb8(&[linear_of(byte)]), [byte]);
        }
        assert_eq!(linear_to_srgb8(&[f32::NAN, 7.0, -1.0]), [0, 255, 0]);
    }

    #[test]
    fn identical_images_have_zero_flip() {
        let (w, h) = (40u32, 30u32);
        let img: Vec<f32> = (0..w * h * 3)
            .map(|i| ((i * 37) % 101) as f32 / 50.0)
            .collect();
        let f = flip(&img, &img, w, h, 67.0).unwrap();
        assert_eq!(f.map.len(), (w * h) as usize);
        assert_eq!(f.mean, 0.0);
        assert!(f.map.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let r = vec![0.5f32; 64 * 64 * 3];
        let err = flip(&r, &r[..32 * 64 * 3], 64, 64, 10.0).unwrap_err();
        assert!(matches!(
            err,
            MetricsError::ImageLength { image: "test", .. }
        ));
        for ppd in [0.0, -3.0, f64::NAN, f64::INFINITY, 1e300] {
            let err = flip(&r, &r, 64, 64, ppd).unwrap_err();
            assert!(matches!(err, MetricsError::PixelsPerDegree(_)), "{ppd}");
        }
        assert!(flip_masked_mean(&[0.5; 4], &[true; 3]).is_err());
        assert!(magma_rgb8(&[0.5; 4], 2, 3).is_err());
        let empty = flip(&[], &[], 0, 0, 10.0).unwrap();
        assert_eq!((empty.mean, empty.map.len()), (0.0, 0));
    }

    #[test]
    fn masked_mean_averages_the_selected_pixels() {
        let map = [0.1f32, 0.2, 0.3, 0.4];
        let m = flip_masked_mean(&map, &[true, false, true, false]).unwrap();
        assert!((m - 0.2).abs() < 1e-7);
        assert_eq!(flip_masked_mean(&map, &[false; 4]).unwrap(), 0.0);
    }

    #[test]
    fn magma_matches_nv_flip_colour_mapping() {
        let (w, h) = (64u32, 2u32);
        let map: Vec<f32> = (0..w * h).map(|i| i as f32 / (w * h - 1) as f32).collect();
        let ours = magma_rgb8(&map, w, h).unwrap();
        let theirs = nv_flip::FlipImageFloat::with_data(w, h, &map)
            .apply_color_lut(&nv_flip::magma_lut())
            .to_vec();
        assert_eq!(ours, theirs);
        // Magma runs from near black to pale yellow; broken values show as the top.
        let ends = magma_rgb8(&[0.0, 1.0, f32::NAN, 7.0], 4, 1).unwrap();
        assert!(ends[..3].iter().all(|&c| c < 10), "{:?}", &ends[..3]);
        assert!(ends[3..6].iter().all(|&c| c > 180), "{:?}", &ends[3..6]);
        assert_eq!(&ends[6..9], &ends[3..6]);
        assert_eq!(&ends[9..12], &ends[3..6]);
    }

    #[test]
    fn pixels_per_degree_from_the_geometry() {
        // A narrow symmetric field of view is nearly linear in angle: width / fov.
        let a = 5f32.to_radians();
        let g = ImageGeometry::new(
            400,
            300,
            EyeFov {
                left: -a,
                right: a,
                up: a,
                down: -a,
            },
        );
        let ppd = pixels_per_degree(&g);
        assert!((ppd / 40.0 - 1.0).abs() < 0.01, "{ppd}");
        // The Vive Pro Eye: coarsest at the axis, finer towards the edge.
        let (w, h) = EyeFov::VIVE_PRO_EYE_SIZE;
        let v = ImageGeometry::new(w, h, EyeFov::VIVE_PRO_EYE_LEFT);
        let axis = pixels_per_degree(&v);
        assert!((9.0..10.5).contains(&axis), "{axis}");
        let exact = 1.0
            / ((v.tan_right - v.tan_left) / f64::from(w))
                .atan()
                .to_degrees();
        assert!((axis / exact - 1.0).abs() < 1e-6, "{axis} vs {exact}");
        let edge = pixels_per_degree_at(&v, [2.0, v.axis_pixel()[1]]);
        assert!(edge > 1.8 * axis, "{edge} vs {axis}");
    }

    #[test]
    fn the_mean_agrees_with_nv_flip_pooling() {
        let (w, h) = (50u32, 40u32);
        let r: Vec<f32> = (0..w * h * 3)
            .map(|i| ((i * 13) % 29) as f32 / 28.0)
            .collect();
        let t: Vec<f32> = r.iter().map(|v| (v * 0.8 + 0.05).min(1.0)).collect();
        let f = flip(&r, &t, w, h, 20.0).unwrap();
        let pooled =
            nv_flip::FlipPool::from_image(&nv_flip::FlipImageFloat::with_data(w, h, &f.map));
        assert!(f.mean > 0.01);
        assert!(
            (f.mean - f64::from(pooled.mean())).abs() < 1e-5,
            "{} vs {}",
            f.mean,
            pooled.mean()
        );
    }
}
