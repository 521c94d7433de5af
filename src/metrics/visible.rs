//! What the lens shows, the same for every metric: a comparison (error, FLIP, FovVideoVDP in
//! `bench` and `tune`) judges only the pixels within the occlusion mask, with the rest black
//! in both images.

use super::bands::eccentricity_deg;
use crate::foveation::ImageGeometry;

/// The pixels an eye can see: those within `occlusion_deg` of the view axis (the lens hides
/// the rest, foveated frames leave them black, and no mode is judged on them); every pixel
/// without a mask.
pub fn visible_pixels(image: &ImageGeometry, occlusion_deg: Option<f32>) -> Vec<bool> {
    match occlusion_deg {
        Some(deg) => eccentricity_deg(image, image.axis_pixel())
            .iter()
            .map(|&e| e <= deg)
            .collect(),
        None => vec![true; (image.width * image.height) as usize],
    }
}

/// `rgb` with the pixels outside `visible` black: what the lens hides is judged in neither
/// image (and FLIP's edge filters do not see the mask's rim as an error).
pub fn hidden_black(mut rgb: Vec<f32>, visible: &[bool]) -> Vec<f32> {
    for (px, _) in rgb.chunks_mut(3).zip(visible).filter(|(_, v)| !**v) {
        px.fill(0.0);
    }
    rgb
}
