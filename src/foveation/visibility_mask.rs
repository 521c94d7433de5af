//! The lens's visibility mask as pixels: which pixels of an eye's image the headset's optics
//! show. OpenXR (XR_KHR_visibility_mask) gives the hidden area as triangles in the view's
//! tangent plane (z = −1, x right, y up); they are rasterised here at pixel centres. A hidden
//! pixel is never traced, which makes the thesis' circular occlusion mask (§3.2.1) exact.
//!
//! A layer with spacing d fills pixels from lattice points up to 2d pixels away (Catmull-Rom
//! taps reach two lattice points to each side), so a lattice point is traced when any visible
//! pixel lies within 2d pixels of it: the "needed" map, one per spacing.

use super::view::ImageGeometry;
use std::collections::HashMap;

#[derive(Clone, Debug)]
pub struct VisibilityMask {
    pub width: u32,
    pub height: u32,
    /// Row-major, `true` where the lens shows the pixel.
    visible: Vec<bool>,
    /// Lattice points needed per layer spacing (see the module docs), built on first use,
    /// with each row's runs of needed pixels `[start, end)`: layers that trace whole rows
    /// (regular rendering, the background) emit spans from these instead of testing every
    /// pixel each frame.
    needed: HashMap<u32, Needed>,
}

impl VisibilityMask {
    /// Rasterises hidden triangles (tangent-space vertices, any winding) over `image`: a
    /// pixel is hidden when its centre is inside one of them.
    pub fn from_hidden_triangles(
        image: &ImageGeometry,
        vertices: &[[f32; 2]],
        indices: &[u32],
    ) -> Self {
        let (w, h) = (image.width as usize, image.height as usize);
        let mut visible = vec![true; w * h];
        for tri in indices.chunks_exact(3) {
            let Some(corners) = tri
                .iter()
                .map(|&i| {
                    vertices
                        .get(i as usize)
                        .map(|v| image.pixel_of([v[0] as f64, v[1] as f64]))
                })
                .collect::<Option<Vec<_>>>()
            else {
                continue; // an index out of range: the runtime's bug; skip the triangle
            };
            let [a, b, c] = [corners[0], corners[1], corners[2]];
            let area = edge(a, b, c);
            if area == 0.0 || !area.is_finite() {
                continue;
            }
            let x0 = a[0].min(b[0]).min(c[0]).floor().max(0.0) as usize;
            let x1 = (a[0].max(b[0]).max(c[0]).ceil().max(0.0) as usize).min(w);
            let y0 = a[1].min(b[1]).min(c[1]).floor().max(0.0) as usize;
            let y1 = (a[1].max(b[1]).max(c[1]).ceil().max(0.0) as usize).min(h);
            for y in y0..y1 {
                for x in x0..x1 {
                    let p = [x as f64 + 0.5, y as f64 + 0.5];
                    let (e0, e1, e2) = (edge(a, b, p), edge(b, c, p), edge(c, a, p));
                    // Inside (or on an edge) for either winding.
                    let inside = match area > 0.0 {
                        true => e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0,
                        false => e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0,
                    };
                    if inside {
                        visible[y * w + x] = false;
                    }
                }
            }
        }
        Self {
            width: image.width,
            height: image.height,
            visible,
            needed: HashMap::new(),
        }
    }

    pub fn visible(&self, x: u32, y: u32) -> bool {
        self.visible[(y * self.width + x) as usize]
    }

    /// The mask as bits, row-major, 1 where the pixel is visible, packed 32 to a word (low
    /// bit first): one plane of shared.h's BINDING_VISIBILITY layout.
    pub fn bits(&self) -> Vec<u32> {
        pack_bits(&self.visible)
    }

    /// The pixels whose lattice points a layer of this spacing needs ([`Self::needed`]), as
    /// bits like [`Self::bits`]; prepares the spacing first.
    pub fn needed_bits(&mut self, spacing: u32) -> Vec<u32> {
        self.prepare(spacing);
        pack_bits(&self.needed[&spacing].map)
    }

    /// Visible pixels of the image.
    pub fn visible_count(&self) -> usize {
        self.visible.iter().filter(|v| **v).count()
    }

    /// Builds the "needed" map of a layer spacing, so that [`Self::needed`] can answer.
    pub fn prepare(&mut self, spacing: u32) {
        if !self.needed.contains_key(&spacing) {
            let reach = if spacing <= 1 {
                0
            } else {
                2 * spacing as usize
            };
            let map = dilate(
                &self.visible,
                self.width as usize,
                self.height as usize,
                reach,
            );
            let rows = row_runs(&map, self.width as usize);
            self.needed.insert(spacing, Needed { map, rows });
        }
    }

    /// Must a layer with this spacing trace its lattice point at pixel `(x, y)`? (After
    /// [`Self::prepare`] for the spacing; unprepared spacings answer "visible".)
    pub fn needed(&self, spacing: u32, x: u32, y: u32) -> bool {
        let i = (y * self.width + x) as usize;
        match self.needed.get(&spacing) {
            Some(needed) => needed.map[i],
            None => self.visible[i],
        }
    }

    /// Row `y`'s runs of needed pixels `[start, end)` for a spacing, after [`Self::prepare`]
    /// for it (`None` before).
    pub fn needed_runs(&self, spacing: u32, y: u32) -> Option<&[(i32, i32)]> {
        self.needed
            .get(&spacing)
            .map(|n| n.rows[y as usize].as_slice())
    }
}

/// Booleans packed 32 to a word, low bit first.
fn pack_bits(flags: &[bool]) -> Vec<u32> {
    let mut words = vec![0u32; flags.len().div_ceil(32)];
    for (i, v) in flags.iter().enumerate() {
        words[i / 32] |= (*v as u32) << (i % 32);
    }
    words
}

#[derive(Clone, Debug)]
struct Needed {
    map: Vec<bool>,
    rows: Vec<Vec<(i32, i32)>>,
}

/// Runs of `true` in each row: `[start, end)` pixel ranges.
fn row_runs(map: &[bool], w: usize) -> Vec<Vec<(i32, i32)>> {
    map.chunks_exact(w)
        .map(|row| {
            let mut runs = Vec::new();
            let mut start = None;
            for (x, v) in row.iter().chain([&false]).enumerate() {
                match (v, start) {
                    (true, None) => start = Some(x as i32),
                    (false, Some(s)) => {
                        runs.push((s, x as i32));
                        start = None;
                    }
                    _ => {}
                }
            }
            runs
        })
        .collect()
}

/// Twice the signed area of the triangle (a, b, p): positive when p is left of a → b.
fn edge(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

/// `true` where any `true` lies within `reach` pixels (Chebyshev distance): a box max filter,
/// separable, with running counts so each pass is linear in the pixels.
fn dilate(mask: &[bool], w: usize, h: usize, reach: usize) -> Vec<bool> {
    if reach == 0 {
        return mask.to_vec();
    }
    let pass = |src: &[bool], len: usize, lines: usize, at: &dyn Fn(usize, usize) -> usize| {
        let mut out = vec![false; src.len()];
        for line in 0..lines {
            // Count of `true` in the window [i - reach, i + reach].
            let mut count = 0usize;
            for i in 0..len.min(reach + 1) {
                count += src[at(line, i)] as usize;
            }
            for i in 0..len {
                out[at(line, i)] = count > 0;
                if i + reach + 1 < len {
                    count += src[at(line, i + reach + 1)] as usize;
                }
                if i >= reach {
                    count -= src[at(line, i - reach)] as usize;
                }
            }
        }
        out
    };
    let rows = pass(mask, w, h, &|y, x| y * w + x);
    pass(&rows, h, w, &|x, y| y * w + x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::EyeFov;

    fn image() -> ImageGeometry {
        ImageGeometry::new(40, 30, EyeFov::VIVE_PRO_EYE_LEFT)
    }

    #[test]
    fn a_hidden_triangle_hides_the_pixels_whose_centres_it_covers() {
        let g = image();
        // The top-left quarter of the image (in tangent space), as two triangles, one of
        // each winding.
        let tl = [g.tan_left as f32, g.tan_up as f32];
        let mid = g.tan_of(20.0, 15.0);
        let mid = [mid[0] as f32, mid[1] as f32];
        let vertices = [tl, [mid[0], tl[1]], mid, [tl[0], mid[1]]];
        let mask = VisibilityMask::from_hidden_triangles(&g, &vertices, &[0, 1, 2, 0, 3, 2]);
        for y in 0..30 {
            for x in 0..40 {
                assert_eq!(mask.visible(x, y), !(x < 20 && y < 15), "pixel {x},{y}");
            }
        }
        assert_eq!(mask.visible_count(), 40 * 30 - 20 * 15);
    }

    #[test]
    fn bits_pack_pixels_low_bit_first() {
        let g = ImageGeometry::new(40, 30, EyeFov::VIVE_PRO_EYE_LEFT);
        let a = g.tan_of(-1.0, -1.0);
        let b = g.tan_of(2.5, -1.0);
        let c = g.tan_of(-1.0, 2.5);
        let v: Vec<[f32; 2]> = [a, b, c]
            .iter()
            .map(|t| [t[0] as f32, t[1] as f32])
            .collect();
        // Hides pixel (0, 0) only: its centre is on the edge x + y = 1.5, the next ones beyond.
        let mask = VisibilityMask::from_hidden_triangles(&g, &v, &[0, 1, 2]);
        let bits = mask.bits();
        assert_eq!(bits.len(), (40 * 30usize).div_ceil(32));
        assert_eq!(bits[0], !1u32);
        assert!(bits[1..bits.len() - 1].iter().all(|w| *w == u32::MAX));
        assert_eq!(
            bits.iter().map(|w| w.count_ones()).sum::<u32>(),
            40 * 30 - 1
        );
    }

    #[test]
    fn bad_triangles_are_skipped() {
        let g = image();
        let v = [[0.0, 0.0], [f32::NAN, 0.0], [0.1, 0.1]];
        let mask = VisibilityMask::from_hidden_triangles(&g, &v, &[0, 1, 2, 0, 1, 7]);
        assert_eq!(mask.visible_count(), 40 * 30);
    }

    #[test]
    fn needed_points_reach_two_spacings_into_the_hidden_area() {
        let g = image();
        // Hide everything left of x = 20.
        let a = g.tan_of(-1.0, -1.0);
        let b = g.tan_of(20.0, -1.0);
        let c = g.tan_of(20.0, 31.0);
        let d = g.tan_of(-1.0, 31.0);
        let v: Vec<[f32; 2]> = [a, b, c, d]
            .iter()
            .map(|t| [t[0] as f32, t[1] as f32])
            .collect();
        let mut mask = VisibilityMask::from_hidden_triangles(&g, &v, &[0, 1, 2, 0, 2, 3]);
        mask.prepare(1);
        mask.prepare(3);
        for x in 0..40 {
            assert_eq!(mask.needed(1, x, 10), x >= 20, "spacing 1, x {x}");
            assert_eq!(mask.needed(3, x, 10), x + 6 >= 20, "spacing 3, x {x}");
        }
    }

    #[test]
    fn dilation_matches_brute_force() {
        let (w, h) = (13, 9);
        let mask: Vec<bool> = (0..w * h).map(|i| (i * 7919) % 23 == 0).collect();
        for reach in [1, 2, 4] {
            let fast = dilate(&mask, w, h, reach);
            for y in 0..h {
                for x in 0..w {
                    let slow = (0..h).any(|yy| {
                        (0..w).any(|xx| {
                            mask[yy * w + xx]
                                && (xx as i64 - x as i64).abs() <= reach as i64
                                && (yy as i64 - y as i64).abs() <= reach as i64
                        })
                    });
                    assert_eq!(fast[y * w + x], slow, "reach {reach} at {x},{y}");
                }
            }
        }
    }
}
