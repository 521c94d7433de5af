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

    /// Bicubic value at pixel `(x, y)` as resolve.comp shows it: on a sparse lattice
    /// (spacing > 1) within the range of the pixel's 2x2 nearest lattice points, so that an
    /// edge does not ring; spacing 1 as it is.
    pub fn interpolate_clamped(&self, x: i32, y: i32, at: impl Fn(i32, i32) -> f32) -> f32 {
        let value = self.interpolate(x, y, &at);
        if self.spacing == 1 {
            return value;
        }
        let d = self.spacing;
        let (cx, cy) = (
            (x - self.anchor[0]).div_euclid(d),
            (y - self.anchor[1]).div_euclid(d),
        );
        let tap = |c: i32, k: usize| (self.anchor[k] + c * d).clamp(self.min[k], self.max[k]);
        let near = (0..4).map(|i| at(tap(cx + i % 2, 0), tap(cy + i / 2, 1)));
        let (lo, hi) = near.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        value.clamp(lo, hi)
    }
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

    /// A lamp (radiance 20) over a dim ceiling (0.5) on a spacing-4 lattice: the plain cubic
    /// overshoots the lamp and rings below zero beside it; clamped, every pixel stays within
    /// its nearest points' range, and the lamp's radiance reaches no pixel whose nearest
    /// points are all ceiling.
    #[test]
    fn a_lamp_edge_does_not_ring_on_a_sparse_lattice() {
        let lattice = Lattice {
            anchor: [0, 0],
            spacing: 4,
            min: [0, 0],
            max: [40, 40],
        };
        let lamp = |x: i32, _y: i32| if x >= 20 { 20.0 } else { 0.5 };
        let plain: Vec<f32> = (8..32).map(|x| lattice.interpolate(x, 8, lamp)).collect();
        let clamped: Vec<f32> = (8..32)
            .map(|x| lattice.interpolate_clamped(x, 8, lamp))
            .collect();
        assert!(
            plain.iter().any(|&v| v < 0.0),
            "the plain cubic rings below zero"
        );
        assert!(plain.iter().any(|&v| v > 20.5), "and overshoots the lamp");
        assert!(
            clamped.iter().all(|&v| (0.5..=20.0).contains(&v)),
            "{clamped:?}"
        );
        // Pixels 8..16 have only ceiling points nearest: exactly the ceiling.
        assert!(clamped[..8].iter().all(|&v| v == 0.5), "{clamped:?}");
        // The lattice points themselves are untouched.
        assert_eq!((clamped[16 - 8], clamped[24 - 8]), (0.5, 20.0));
    }
}
