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
}
