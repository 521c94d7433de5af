//! Fractional sampling: a layer may trace only 1 in `fraction` (1, 2 or 4) of its lattice
//! points per frame, at any spacing, so that a full-resolution layer can cost half or a
//! quarter of 1 spp. The points traced form a pattern on the lattice (a checkerboard for 2,
//! one point of every 2×2 block for 4) chosen by the frame's phase; the phase turns with the
//! history as the lattice shift does, so every point is traced once in `fraction` visits and a
//! still view's history converges to the full image. A point the frame skips but needs is
//! filled from the traced points around it (glsl/lattice_fill.comp), whose pattern always
//! holds its owner: the traced point it sits next to.
//!
//! glsl/fraction.glsl decides the same with the same integer operations; the plan pass and
//! the CPU planner (plan.rs) use them.

use super::lattice_shift::lattice_shift;

/// The fractions a layer may take: every point, every second, every fourth.
pub const FRACTIONS: [u32; 3] = [1, 2, 4];

/// The pattern a layer of `fraction` and `spacing` traces in history frame `history_frame`
/// (0 without history). The lattice shift visits the `spacing²` offsets first; the phase then
/// moves on once per round of them, so a pixel comes back onto the lattice with the next
/// phase each time (turning with every frame would skip points whenever `fraction` and
/// `spacing²` share a factor).
pub fn phase(history_frame: u32, spacing: u32, fraction: u32) -> u32 {
    let round = history_frame / (spacing.max(1) * spacing.max(1));
    round % fraction.max(1)
}

/// Does a layer of `fraction` trace its lattice point (i, j) in `phase`?
pub fn traces(fraction: u32, phase: u32, i: i32, j: i32) -> bool {
    match fraction {
        2 => (i + j + phase as i32) & 1 == 0,
        4 => {
            let [cx, cy] = lattice_shift(phase, 2);
            i & 1 == cx && j & 1 == cy
        }
        _ => true,
    }
}

/// The traced point next to the skipped point (i, j) (its left neighbour for 2, its 2×2
/// block's traced point for 4): while the owner is traced, the point is filled from its
/// neighbours, else traced itself (at the edge of the layer's region).
pub fn owner(fraction: u32, phase: u32, i: i32, j: i32) -> [i32; 2] {
    match fraction {
        2 => [i - 1, j],
        4 => {
            let [cx, cy] = lattice_shift(phase, 2);
            [i - ((i - cx) & 1), j - ((j - cy) & 1)]
        }
        _ => [i, j],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_point_is_traced_once_in_fraction_phases() {
        for fraction in FRACTIONS {
            for j in -5..5 {
                for i in -5..5 {
                    let n = (0..fraction).filter(|&p| traces(fraction, p, i, j)).count();
                    assert_eq!(n, 1, "fraction {fraction}: point {i},{j} traced {n} times");
                }
            }
        }
    }

    #[test]
    fn a_skipped_points_owner_is_traced_and_next_to_it() {
        for fraction in [2, 4] {
            for phase in 0..fraction {
                for j in -5..5 {
                    for i in -5..5 {
                        if traces(fraction, phase, i, j) {
                            continue;
                        }
                        let [oi, oj] = owner(fraction, phase, i, j);
                        assert!(
                            traces(fraction, phase, oi, oj),
                            "{fraction} {phase} {i},{j}"
                        );
                        assert!((oi - i).abs() <= 1 && (oj - j).abs() <= 1);
                    }
                }
            }
        }
    }

    #[test]
    fn every_pixel_is_traced_once_per_fraction_rounds_of_the_shift() {
        // A spacing-2 layer at fraction 2: pixel (x, y) is lattice point ((x - sx) / 2, ...)
        // in the frames whose shift (sx, sy) puts the lattice on it.
        let (spacing, fraction) = (2u32, 2u32);
        for y in 0..4i32 {
            for x in 0..4i32 {
                let period = spacing * spacing * fraction;
                let traced = (0..period)
                    .filter(|&f| {
                        let [sx, sy] = lattice_shift(f, spacing);
                        let (dx, dy) = (x - sx, y - sy);
                        let d = spacing as i32;
                        dx % d == 0
                            && dy % d == 0
                            && traces(fraction, phase(f, spacing, fraction), dx / d, dy / d)
                    })
                    .count();
                assert_eq!(traced, 1, "pixel {x},{y}");
            }
        }
        assert_eq!(phase(0, 3, 4), 0);
        assert_eq!(phase(9, 3, 4), 1);
        assert_eq!(phase(7, 1, 4), 3);
    }
}
