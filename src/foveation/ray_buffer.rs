//! The ray buffer (thesis §3.2.1), built once per layer config and resolution: for every
//! layer, the lattice of target-pixel offsets that layer can ever need, stored row by row so
//! that each frame picks its rays as contiguous index ranges (`plan::Span`). Layers with a
//! radius are anchored at the gaze pixel, so moving the gaze moves them without a rebuild;
//! the background layer is anchored at the image's top-left pixel and does not move.
//!
//! One entry per target pixel, not per sample: a sample's jitter and random numbers derive
//! from (pixel, sample index, seed) in the shader. Storing them per sample would cost spp×
//! the memory (a 1024-spp reference frame at 1440×1600 would need 2.4 G entries), and deriving
//! them from the pixel is what makes the foveal layer bit-identical to a regular render.

use super::config::FoveationConfig;
use super::view::{direction, ImageGeometry};
use std::f64::consts::SQRT_2;

/// One layer's part of the buffer and the angular regions (radians) it covers.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerLattice {
    pub spacing: u32,
    pub spp: u32,
    /// The layer traces 1 in `fraction` of its points per frame (foveation/fraction.rs).
    pub fraction: u32,
    /// Offsets are relative to the gaze pixel (true) or to pixel (0, 0) (background).
    pub gaze_anchored: bool,
    /// Index of the layer's first entry in `RayBuffer::offsets`.
    pub first: u32,
    /// Lattice columns `i` run over `col_min..=col_max`, rows `j` over `row_min..=row_max`;
    /// entry `(i, j)` is at `first + (j - row_min) * cols + (i - col_min)` and holds the
    /// offset `(i, j) * spacing`.
    pub col_min: i32,
    pub col_max: i32,
    pub row_min: i32,
    pub row_max: i32,
    /// The layer is shown where the angle from the gaze lies in `(inner, outer)`: `outer` is
    /// its radius (∞ for the background), `inner` is where the next layer in stops being
    /// fully opaque, i.e. that layer's radius minus the blend width (−∞ for the innermost).
    pub outer: f64,
    pub inner: f64,
    /// Extra angle traced beyond both edges and the occlusion mask, so that every pixel the
    /// fill pass interpolates finds all 16 of its Catmull-Rom taps traced.
    pub margin: f64,
}

impl LayerLattice {
    pub fn cols(&self) -> i32 {
        self.col_max - self.col_min + 1
    }
    pub fn rows(&self) -> i32 {
        self.row_max - self.row_min + 1
    }
    pub fn len(&self) -> u32 {
        (self.cols() * self.rows()) as u32
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Index into `RayBuffer::offsets` of lattice point `(i, j)`.
    pub fn index(&self, i: i32, j: i32) -> u32 {
        self.first + ((j - self.row_min) * self.cols() + (i - self.col_min)) as u32
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RayBuffer {
    /// `(dx, dy)` per target pixel as two i16 in one u32 (dx in the low half).
    pub offsets: Vec<u32>,
    pub layers: Vec<LayerLattice>,
    /// Occlusion radius around the view axis in radians (∞: no mask).
    pub occlusion: f64,
    pub width: u32,
    pub height: u32,
}

/// Packs a lattice offset the way the shaders unpack it.
pub fn pack_offset(dx: i32, dy: i32) -> u32 {
    (dx as i16 as u16 as u32) | ((dy as i16 as u16 as u32) << 16)
}

pub fn unpack_offset(v: u32) -> (i32, i32) {
    (
        (v & 0xffff) as u16 as i16 as i32,
        (v >> 16) as u16 as i16 as i32,
    )
}

impl RayBuffer {
    /// Builds the buffer for `config` on images of the given geometries (one per eye; all the
    /// same size). Extents are taken over every eye and every gaze on the image.
    pub fn build(config: &FoveationConfig, eyes: &[ImageGeometry]) -> Self {
        let (width, height) = (eyes[0].width, eyes[0].height);
        let rad_per_px = eyes
            .iter()
            .map(|e| e.max_radians_per_pixel())
            .fold(0.0, f64::max);
        let blend = (config.blend_deg as f64).to_radians();
        let mut offsets = Vec::new();
        let mut layers = Vec::new();
        for (k, layer) in config.layers.iter().enumerate() {
            let d = layer.spacing as i32;
            // Catmull-Rom taps reach 2 lattice steps (2√2·d pixels diagonally) from the pixel
            // filled; 2 more pixels absorb float differences between CPU and GPU angles.
            let margin = (2.0 * SQRT_2 * d as f64 + 2.0) * rad_per_px;
            let outer = layer
                .radius_deg
                .map_or(f64::INFINITY, |r| (r as f64).to_radians());
            let inner = match k {
                0 => f64::NEG_INFINITY,
                _ => config.layers[k - 1]
                    .radius_deg
                    .map_or(f64::NEG_INFINITY, |r| (r as f64).to_radians() - blend),
            };
            let gaze_anchored = layer.radius_deg.is_some();
            let (col_min, col_max, row_min, row_max) = if gaze_anchored {
                let [ex, ey] = max_extent(eyes, outer + margin);
                let up = |a: i32| (a + d - 1) / d; // ceil for positive a (i32::div_ceil is unstable)
                let cols = up(ex + 2 * d + 2).min(up(width as i32));
                let rows = up(ey + 2 * d + 2).min(up(height as i32));
                (-cols, cols, -rows, rows)
            } else {
                (0, (width as i32 - 1) / d, 0, (height as i32 - 1) / d)
            };
            let lattice = LayerLattice {
                spacing: layer.spacing,
                spp: layer.spp,
                fraction: layer.fraction,
                gaze_anchored,
                first: offsets.len() as u32,
                col_min,
                col_max,
                row_min,
                row_max,
                outer,
                inner,
                margin,
            };
            for j in row_min..=row_max {
                for i in col_min..=col_max {
                    offsets.push(pack_offset(i * d, j * d));
                }
            }
            layers.push(lattice);
        }
        Self {
            offsets,
            layers,
            occlusion: config
                .occlusion_deg
                .map_or(f64::INFINITY, |o| (o as f64).to_radians()),
            width,
            height,
        }
    }
}

/// The largest pixel offsets `(|dx|, |dy|)` from a gaze anywhere on any of the images to a
/// direction at `angle` from it, capped at the image size. Sampled over a 33×33 grid of gaze
/// points and 256 directions; the callers add two lattice steps of slack, and the ray-count
/// tests compare against a brute-force count over every pixel.
fn max_extent(eyes: &[ImageGeometry], angle: f64) -> [i32; 2] {
    let mut ext = [0.0f64; 2];
    for g in eyes {
        let cap = [g.width as f64, g.height as f64];
        if angle >= std::f64::consts::FRAC_PI_2 {
            return [cap[0].ceil() as i32, cap[1].ceil() as i32];
        }
        for gy in 0..=32 {
            for gx in 0..=32 {
                let gaze = [gx as f64 / 32.0 * cap[0], gy as f64 / 32.0 * cap[1]];
                let c = direction(g.tan_of(gaze[0], gaze[1]));
                let (e1, e2) = orthonormal(c);
                for s in 0..256 {
                    let phi = s as f64 / 256.0 * std::f64::consts::TAU;
                    let (sp, cp) = phi.sin_cos();
                    let (sa, ca) = angle.sin_cos();
                    let d: [f64; 3] =
                        std::array::from_fn(|k| ca * c[k] + sa * (cp * e1[k] + sp * e2[k]));
                    if d[2] <= 1e-9 {
                        // The circle leaves the image plane: it can reach any pixel.
                        return [cap[0].ceil() as i32, cap[1].ceil() as i32];
                    }
                    let p = g.pixel_of([d[0] / d[2], d[1] / d[2]]);
                    for k in 0..2 {
                        ext[k] = ext[k].max((p[k] - gaze[k]).abs().min(cap[k]));
                    }
                }
            }
        }
    }
    [ext[0].ceil() as i32, ext[1].ceil() as i32]
}

/// Two unit vectors perpendicular to `c` and to each other.
fn orthonormal(c: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = if c[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let e1 = cross(c, a);
    let n = (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]).sqrt();
    let e1 = [e1[0] / n, e1[1] / n, e1[2] / n];
    (e1, cross(c, e1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::view::EyeFov;

    #[test]
    fn offsets_pack_and_unpack_with_sign() {
        for (dx, dy) in [(0, 0), (-1, 5), (16383, -16384), (-7, -9)] {
            assert_eq!(unpack_offset(pack_offset(dx, dy)), (dx, dy));
        }
    }

    #[test]
    fn regular_config_is_one_entry_per_pixel() {
        let g = ImageGeometry::new(37, 23, EyeFov::VIVE_PRO_EYE_LEFT);
        let b = RayBuffer::build(&FoveationConfig::regular(3), &[g]);
        assert_eq!(b.offsets.len(), 37 * 23);
        assert_eq!(b.layers.len(), 1);
        assert_eq!(
            unpack_offset(b.offsets[b.layers[0].index(36, 22) as usize]),
            (36, 22)
        );
    }

    #[test]
    fn thesis_layers_are_smaller_than_the_screen_and_spaced() {
        let g = ImageGeometry::new(1440, 1600, EyeFov::VIVE_PRO_EYE_LEFT);
        let b = RayBuffer::build(&FoveationConfig::thesis(), &[g]);
        assert_eq!(b.layers.len(), 4);
        let fovea = &b.layers[0];
        assert!(fovea.gaze_anchored && !b.layers[3].gaze_anchored);
        // 6° spans ~9.5 px/deg on the axis and ~5x that radially in the corners.
        assert!(fovea.col_max > 50 && fovea.col_max < 500, "{fovea:?}");
        let l1 = &b.layers[1];
        let (dx, dy) = unpack_offset(b.offsets[l1.index(l1.col_min, l1.row_min) as usize]);
        assert_eq!((dx, dy), (l1.col_min * 2, l1.row_min * 2));
        // Background: every 4th pixel of 1440×1600.
        assert_eq!(b.layers[3].len(), 360 * 400);
    }
}
