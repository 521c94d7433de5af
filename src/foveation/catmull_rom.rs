//! The thesis' cubic interpolation (eq. 3.17, Catmull-Rom) and its bicubic use over a layer's
//! lattice (fig. 3.10): the CPU reference that resolve.comp is tested against.

/// Eq. 3.17: the value between `v[1]` (t = 0) and `v[2]` (t = 1).
pub fn cubic(v: [f32; 4], t: f32) -> f32 {
    let a = -0.5 * v[0] + 1.5 * v[1] - 1.5 * v[2] + 0.5 * v[3];
    let b = v[0] - 2.5 * v[1] + 2.0 * v[2] - 0.5 * v[3];
    let c = -0.5 * v[0] + 0.5 * v[2];
    ((a * t + b) * t + c) * t + v[1]
}

/// A layer's lattice on the image: points `anchor + (i, j) * spacing`, clamped to
/// `[min, max]` (the first and last lattice points on the image) when a tap falls outside.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lattice {
    pub anchor: [i32; 2],
    pub spacing: i32,
    pub min: [i32; 2],
    pub max: [i32; 2],
}

impl Lattice {
    pub fn contains(&self, x: i32, y: i32) -> bool {
        (x - self.anchor[0]).rem_euclid(self.spacing) == 0
            && (y - self.anchor[1]).rem_euclid(self.spacing) == 0
    }

    /// Bicubic Catmull-Rom value at pixel `(x, y)` from the lattice values `at(x, y)`:
    /// four horizontal cubics, then one vertical (fig. 3.10).
    pub fn interpolate(&self, x: i32, y: i32, at: impl Fn(i32, i32) -> f32) -> f32 {
        let d = self.spacing;
        let (rx, ry) = (x - self.anchor[0], y - self.anchor[1]);
        let (cx, cy) = (rx.div_euclid(d), ry.div_euclid(d));
        let tx = (rx - cx * d) as f32 / d as f32;
        let ty = (ry - cy * d) as f32 / d as f32;
        let tap = |c: i32, k: usize| (self.anchor[k] + c * d).clamp(self.min[k], self.max[k]);
        let rows: [f32; 4] = std::array::from_fn(|j| {
            let yy = tap(cy + j as i32 - 1, 1);
            cubic(
                std::array::from_fn(|i| at(tap(cx + i as i32 - 1, 0), yy)),
                tx,
            )
        });
        cubic(rows, ty)
    }

    /// Bicubic value of an RGB lattice at pixel `(x, y)` as resolve.comp shows it: on a
    /// sparse lattice (spacing > 1) the cubics run on [`hdr_weighted`] values, the result is
    /// clamped to the range of the pixel's 2x2 nearest lattice points and divided by its
    /// weight ([`hdr_unweighted`]); spacing 1 stays linear.
    pub fn interpolate_rgb(&self, x: i32, y: i32, at: impl Fn(i32, i32) -> [f32; 3]) -> [f32; 3] {
        if self.spacing == 1 {
            return std::array::from_fn(|c| self.interpolate(x, y, |x, y| at(x, y)[c]));
        }
        let value = |x, y| hdr_weighted(at(x, y));
        let d = self.spacing;
        let (cx, cy) = (
            (x - self.anchor[0]).div_euclid(d),
            (y - self.anchor[1]).div_euclid(d),
        );
        let tap = |c: i32, k: usize| (self.anchor[k] + c * d).clamp(self.min[k], self.max[k]);
        let near: Vec<[f32; 4]> = (0..4)
            .map(|i| value(tap(cx + i % 2, 0), tap(cy + i / 2, 1)))
            .collect();
        hdr_unweighted(std::array::from_fn(|c| {
            let lo = near.iter().map(|v| v[c]).fold(f32::INFINITY, f32::min);
            let hi = near.iter().map(|v| v[c]).fold(f32::NEG_INFINITY, f32::max);
            self.interpolate(x, y, |x, y| value(x, y)[c]).clamp(lo, hi)
        }))
    }
}

/// Relative luminance of linear Rec. 709 RGB (colour.glsl's `luminance`).
pub fn luminance(x: [f32; 3]) -> f32 {
    0.2126 * x[0] + 0.7152 * x[1] + 0.0722 * x[2]
}

/// colour.glsl's `hdr_weighted`: `(x, 1) / (1 + luminance(x))`, what sparse layers are
/// interpolated on, so that a lamp's edge neither bleeds nor rings.
pub fn hdr_weighted(x: [f32; 3]) -> [f32; 4] {
    let w = 1.0 / (1.0 + luminance(x).max(0.0));
    [x[0] * w, x[1] * w, x[2] * w, w]
}

/// colour.glsl's `hdr_unweighted`: an interpolated [`hdr_weighted`] value's radiance.
pub fn hdr_unweighted(y: [f32; 4]) -> [f32; 3] {
    let w = y[3].max(1e-6);
    [y[0], y[1], y[2]].map(|v| v.max(0.0) / w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_hits_its_end_points_and_is_exact_on_lines_and_parabolas() {
        let v = [3.0, -1.0, 4.0, 1.5];
        assert_eq!(cubic(v, 0.0), -1.0);
        assert!((cubic(v, 1.0) - 4.0).abs() < 1e-6);
        // Catmull-Rom reproduces polynomials up to degree 2 from uniform samples.
        let f = |x: f32| 0.5 * x * x - 2.0 * x + 1.0;
        for t in [0.25f32, 0.5, 0.9] {
            let got = cubic([f(-1.0), f(0.0), f(1.0), f(2.0)], t);
            assert!((got - f(t)).abs() < 1e-5, "{got} vs {}", f(t));
        }
    }

    #[test]
    fn bicubic_fill_reproduces_a_linear_gradient() {
        let lattice = Lattice {
            anchor: [2, 1],
            spacing: 3,
            min: [2, 1],
            max: [29, 28],
        };
        let f = |x: i32, y: i32| 0.25 * x as f32 - 0.125 * y as f32 + 3.0;
        for y in 4..26 {
            for x in 5..27 {
                let got = lattice.interpolate(x, y, f);
                assert!(
                    (got - f(x, y)).abs() < 1e-5,
                    "({x},{y}): {got} vs {}",
                    f(x, y)
                );
            }
        }
        assert!(lattice.contains(5, 7) && !lattice.contains(6, 7));
    }

    #[test]
    fn weighting_round_trips() {
        for x in [
            [0.0, 0.0, 0.0],
            [0.01, 0.5, 0.2],
            [18.7, 15.0, 9.0],
            [1e4, 0.0, 3.0],
        ] {
            let back = hdr_unweighted(hdr_weighted(x));
            for c in 0..3 {
                assert!(
                    (back[c] - x[c]).abs() <= 1e-6 * x[c].max(1.0),
                    "{x:?} -> {back:?}"
                );
            }
        }
        assert_eq!(hdr_unweighted([-0.2, 0.3, -1e-3, 0.5]), [0.0, 0.6, 0.0]);
    }

    /// A lamp (radiance 20) over a dim ceiling (0.5) on a spacing-4 lattice: interpolated
    /// linearly the lamp's radiance bleeds into the ceiling's pixels next to it (the lamp
    /// looks bigger) and the cubic rings beyond; weighted and clamped, the pixels between
    /// stay near the display's blend of the two and none leaves the two's range.
    #[test]
    fn a_lamp_edge_neither_bleeds_nor_rings_on_a_sparse_lattice() {
        let lattice = Lattice {
            anchor: [0, 0],
            spacing: 4,
            min: [0, 0],
            max: [40, 40],
        };
        let lamp = |x: i32, _y: i32| if x >= 20 { 20.0 } else { 0.5 };
        let linear: Vec<f32> = (8..32).map(|x| lattice.interpolate(x, 8, lamp)).collect();
        let rgb: Vec<f32> = (8..32)
            .map(|x| lattice.interpolate_rgb(x, 8, |x, y| [lamp(x, y); 3])[0])
            .collect();
        // The ceiling's pixel half a step from the lamp's first lattice point.
        let half = (18 - 8) as usize;
        assert!(linear[half] > 9.0, "linear bleeds: {}", linear[half]);
        assert!(rgb[half] < 2.5, "weighted: {}", rgb[half]);
        assert!(
            linear.iter().any(|&v| v < 0.45),
            "the linear cubic undershoots"
        );
        assert!(linear.iter().any(|&v| v > 21.0), "and overshoots");
        assert!(
            rgb.iter().all(|&v| (0.5..=20.0 + 1e-3).contains(&v)),
            "{rgb:?}"
        );
        // Lattice points keep their values (to rounding), on both sides.
        assert!(
            (rgb[(16 - 8) as usize] - 0.5).abs() < 1e-5
                && (rgb[(24 - 8) as usize] - 20.0).abs() < 1e-3
        );
    }
}
