//! Image error against a reference: MSE, relMSE, PSNR over the whole image and per
//! eccentricity band around the gaze, and FLIP.
//!
//! Images are linear RGB radiance, 3 `f32` per pixel, row-major from the top-left, passed as
//! slices with their width and height so that the metrics stay independent of how a frame
//! was produced. Every function checks sizes and returns a [`MetricsError`] instead of
//! panicking on bad input.

pub mod bands;
pub mod error;
pub mod flicker;
pub mod flip;
pub mod jod;
pub mod jod_inputs;
pub mod visible;

pub use bands::{band_errors, band_masks, eccentricity_deg, Band, BandError, BANDS, BANDS_DEG};
pub use error::{image_error, ImageError};
pub use flicker::flicker;
pub use flip::{
    flip, flip_masked_mean, flip_shown, magma_rgb8, pixels_per_degree, pixels_per_degree_at,
    FlipResult,
};
pub use visible::{hidden_black, visible_pixels};

/// What was wrong with the input of a metric.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MetricsError {
    /// An RGB image slice does not hold 3 floats for every pixel of the stated size.
    #[error(
        "{image} image has {got} floats but a {width}x{height} RGB image needs {need} \
         (3 per pixel); compare images of the same size"
    )]
    ImageLength {
        image: &'static str,
        got: usize,
        need: usize,
        width: u32,
        height: u32,
    },
    /// A per-pixel array (pixel mask, FLIP map) does not hold one entry per pixel.
    #[error("{what} has {got} entries but a {width}x{height} image needs {need} (one per pixel)")]
    PerPixelLength {
        what: &'static str,
        got: usize,
        need: usize,
        width: u32,
        height: u32,
    },
    /// A per-pixel array (pixel mask) does not match the length of the array it selects from.
    #[error("{what} has {got} entries but selects from {need}; they must be the same length")]
    SelectionLength {
        what: &'static str,
        got: usize,
        need: usize,
    },
    /// The image has more pixels than can be addressed (by this machine, or by the FLIP
    /// library, which counts bytes in 32 bits).
    #[error("a {width}x{height} image is too large: {why}")]
    TooLarge {
        width: u32,
        height: u32,
        why: &'static str,
    },
    /// The reference holds a NaN or infinity, so no error against it means anything.
    #[error(
        "reference has a non-finite value ({value}) at pixel ({x}, {y}); \
         a reference image must be finite everywhere"
    )]
    NonFiniteReference { x: u32, y: u32, value: f32 },
    /// FLIP needs a positive, finite pixels-per-degree.
    #[error("pixels per degree must be positive and finite, got {0}")]
    PixelsPerDegree(f64),
    /// The gaze position is not a finite pixel position.
    #[error("gaze must be a finite pixel position, got ({0}, {1})")]
    NonFiniteGaze(f64, f64),
}

/// Number of pixels in a `width`×`height` image and the length of its RGB slice, or an error
/// if that does not fit in memory addresses (only possible on 32-bit targets).
pub(crate) fn pixel_count(width: u32, height: u32) -> Result<(usize, usize), MetricsError> {
    let pixels = u64::from(width) * u64::from(height);
    let too_large = MetricsError::TooLarge {
        width,
        height,
        why: "its pixel count overflows this machine's address size",
    };
    let n = usize::try_from(pixels).map_err(|_| too_large.clone())?;
    let floats = n.checked_mul(3).ok_or(too_large)?;
    Ok((n, floats))
}

/// Checks that an RGB slice named `image` holds exactly 3 floats per pixel.
pub(crate) fn check_rgb(
    image: &'static str,
    data: &[f32],
    width: u32,
    height: u32,
) -> Result<(), MetricsError> {
    let (_, need) = pixel_count(width, height)?;
    if data.len() == need {
        Ok(())
    } else {
        Err(MetricsError::ImageLength {
            image,
            got: data.len(),
            need,
            width,
            height,
        })
    }
}

/// Checks that a per-pixel array named `what` holds exactly one entry per pixel.
pub(crate) fn check_per_pixel(
    what: &'static str,
    len: usize,
    width: u32,
    height: u32,
) -> Result<(), MetricsError> {
    let (need, _) = pixel_count(width, height)?;
    if len == need {
        Ok(())
    } else {
        Err(MetricsError::PerPixelLength {
            what,
            got: len,
            need,
            width,
            height,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_say_what_was_wrong() {
        let e = check_rgb("test", &[0.0; 32 * 64 * 3], 64, 64).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("test image has 6144 floats"), "{msg}");
        assert!(msg.contains("64x64 RGB image needs 12288"), "{msg}");
        assert!(msg.contains("same size"), "{msg}");
        let e = check_per_pixel("mask", 3, 2, 2).unwrap_err();
        assert_eq!(
            e.to_string(),
            "mask has 3 entries but a 2x2 image needs 4 (one per pixel)"
        );
        assert!(check_rgb("reference", &[0.0; 12], 2, 2).is_ok());
        assert!(check_rgb("reference", &[], 0, 5).is_ok());
    }
}
