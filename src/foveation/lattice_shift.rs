//! Where a sparse layer's lattice sits frame after frame while history is on (temporal
//! rendering): shifted by a different offset every frame, so that every pixel of a layer of
//! spacing `d` is traced once in every `d²` frames and a still view's history converges to
//! the full-resolution image. Offset 0 (frame 0, and every frame without history) is the
//! lattice of a single frame.

/// The offset (pixels, each in `0..spacing`) of a spacing-`spacing` lattice in history frame
/// `frame`. Frames `0..d²` visit the `d²` offsets once each, in an order that spreads
/// consecutive ones over the cell: cell `frame · g mod d²` (row-major), `g` the step coprime
/// to `d²` nearest to `d²` times the golden ratio's conjugate (the golden-ratio walk, whose
/// consecutive points are far apart in both coordinates).
pub fn lattice_shift(frame: u32, spacing: u32) -> [i32; 2] {
    let d = spacing.max(1) as u64;
    let n = d * d;
    let cell = (frame as u64 % n) * golden_step(n) % n;
    [(cell % d) as i32, (cell / d) as i32]
}

/// The step coprime to `n` nearest to `n · 0.618…`.
fn golden_step(n: u64) -> u64 {
    let ideal = n as f64 * (5f64.sqrt() - 1.0) / 2.0;
    (1..n)
        .filter(|&g| gcd(g, n) == 1)
        .min_by(|a, b| {
            (*a as f64 - ideal)
                .abs()
                .total_cmp(&(*b as f64 - ideal).abs())
        })
        .unwrap_or(1)
}

fn gcd(a: u64, b: u64) -> u64 {
    match b {
        0 => a,
        _ => gcd(b, a % b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_offset_once_in_spacing_squared_frames() {
        for d in 1..=8u32 {
            let mut seen = vec![false; (d * d) as usize];
            for frame in 0..d * d {
                let [x, y] = lattice_shift(frame, d);
                assert!((0..d as i32).contains(&x) && (0..d as i32).contains(&y));
                let cell = (y * d as i32 + x) as usize;
                assert!(!seen[cell], "spacing {d}: offset {x},{y} twice");
                seen[cell] = true;
            }
            // The sequence repeats with period d².
            assert_eq!(lattice_shift(d * d + 3, d), lattice_shift(3, d));
        }
        assert_eq!(lattice_shift(0, 4), [0, 0]);
    }

    #[test]
    fn consecutive_offsets_are_spread() {
        // Spacing 4: the step is 9, so frame 1 is (1, 2), not a neighbour of (0, 0) in a row.
        assert_eq!(lattice_shift(1, 4), [1, 2]);
        assert_eq!(lattice_shift(1, 2), [1, 1]);
    }
}
