//! FLIP's colour pipeline written out again from the paper (Andersson et al. 2020, §4) in
//! `f64`, to check nv-flip against values computed independently of it.
//!
//! For a *uniform* image FLIP reduces to this colour part: its spatial filters are
//! normalised and clamp to the edge, so they leave a uniform image unchanged, and the edge
//! and point detectors (derivatives of a Gaussian, positive and negative weights normalised
//! to ±1) respond with zero, so the feature difference ΔE_f is 0 and
//! FLIP = ΔE_c^(1 − ΔE_f) = ΔE_c.

use super::tests::linear_of;
use super::*;

/// Linear sRGB to CIE XYZ under D65, the exact rational form FLIP's code cites
/// (image-engineering.de technote 958); rows sum to the D65 white point.
const RGB_TO_XYZ: [[f64; 3]; 3] = [
    [
        10135552.0 / 24577794.0,
        8788810.0 / 24577794.0,
        4435075.0 / 24577794.0,
    ],
    [
        2613072.0 / 12288897.0,
        8788810.0 / 12288897.0,
        887015.0 / 12288897.0,
    ],
    [
        1425312.0 / 73733382.0,
        8788810.0 / 73733382.0,
        70074185.0 / 73733382.0,
    ],
];

/// FLIP's constants (paper §4): q_c = 0.7, p_c = 0.4, p_t = 0.95.
const QC: f64 = 0.7;
const PC: f64 = 0.4;
const PT: f64 = 0.95;

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// Inverse of a 3×3 matrix by cofactors (FLIP's code hard-codes XYZ→RGB to 9 digits).
fn invert(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |r: usize, k: usize| {
        let (r1, r2, k1, k2) = ((r + 1) % 3, (r + 2) % 3, (k + 1) % 3, (k + 2) % 3);
        m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    std::array::from_fn(|i| std::array::from_fn(|j| c(j, i) / det))
}

fn white() -> [f64; 3] {
    mul(&RGB_TO_XYZ, [1.0; 3])
}

fn srgb8_to_linear(c: u8) -> f64 {
    let s = f64::from(c) / 255.0;
    if s <= 0.04045 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// YCxCz, the linearised CIELab opponent space FLIP filters in (paper §4.1).
fn xyz_to_ycxcz(xyz: [f64; 3]) -> [f64; 3] {
    let w = white();
    let (x, y, z) = (xyz[0] / w[0], xyz[1] / w[1], xyz[2] / w[2]);
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

fn ycxcz_to_xyz(c: [f64; 3]) -> [f64; 3] {
    let w = white();
    let y = (c[0] + 16.0) / 116.0;
    [
        (y + c[1] / 500.0) * w[0],
        y * w[1],
        (y - c[2] / 200.0) * w[2],
    ]
}

/// CIELab (CIE 1976) relative to the D65 white.
fn lab(xyz: [f64; 3]) -> [f64; 3] {
    let w = white();
    let d: f64 = 6.0 / 29.0;
    let f = |t: f64| {
        if t > d * d * d {
            t.cbrt()
        } else {
            t / (3.0 * d * d) + 4.0 / 29.0
        }
    };
    let (fx, fy, fz) = (f(xyz[0] / w[0]), f(xyz[1] / w[1]), f(xyz[2] / w[2]));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// Hunt-adjusted Lab: chroma scaled by 0.01·L (paper §4.1, eq. 2).
fn hunt(l: [f64; 3]) -> [f64; 3] {
    [l[0], 0.01 * l[0] * l[1], 0.01 * l[0] * l[2]]
}

/// HyAB distance: city-block in L plus Euclidean in (a, b) (paper §4.1, eq. 3).
fn hyab(p: [f64; 3], q: [f64; 3]) -> f64 {
    (p[0] - q[0]).abs() + ((p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
}

/// A linear RGB colour through the colour pipeline up to Hunt-adjusted Lab, with the
/// (identity, for a uniform image) spatial filter in YCxCz and the clamp after it.
fn hunt_lab_of_linear(rgb: [f64; 3]) -> [f64; 3] {
    let filtered = xyz_to_ycxcz(mul(&RGB_TO_XYZ, rgb)); // filter = identity
    let back = mul(&invert(&RGB_TO_XYZ), ycxcz_to_xyz(filtered));
    hunt(lab(mul(&RGB_TO_XYZ, back.map(|c| c.clamp(0.0, 1.0)))))
}

/// FLIP of two uniform 8-bit sRGB colours: ΔE_c after the compression of paper §4.1 eq. 4,
/// with c_max the compressed distance from pure green to pure blue.
pub(super) fn flip_uniform(reference: [u8; 3], test: [u8; 3]) -> f64 {
    let cmax = hyab(
        hunt_lab_of_linear([0.0, 1.0, 0.0]),
        hunt_lab_of_linear([0.0, 0.0, 1.0]),
    )
    .powf(QC);
    let e = hyab(
        hunt_lab_of_linear(reference.map(srgb8_to_linear)),
        hunt_lab_of_linear(test.map(srgb8_to_linear)),
    )
    .powf(QC);
    if e < PC * cmax {
        PT / (PC * cmax) * e
    } else {
        PT + (e - PC * cmax) / (cmax - PC * cmax) * (1.0 - PT)
    }
}

/// nv-flip's mean FLIP for 16×16 images of the two colours, through [`flip`].
fn nv_flip_uniform(reference: [u8; 3], test: [u8; 3], ppd: f64) -> f64 {
    let n = 16u32;
    let img = |c: [u8; 3]| c.map(linear_of).repeat((n * n) as usize);
    flip(&img(reference), &img(test), n, n, ppd).unwrap().mean
}

/// Pairs of uniform colours with the FLIP the pipeline above gives (to 6 places), so a
/// change in either implementation shows up as a changed number. Black against white is
/// not 1: its compressed HyAB distance (100^0.7 ≈ 25.1) lies above p_c·c_max (≈ 16.5) but
/// below c_max (≈ 41.2, green against blue), so it maps to 0.95 + 0.0174.
const PAIRS: [([u8; 3], [u8; 3], f64); 10] = [
    ([0, 0, 0], [255, 255, 255], 0.967380),
    ([255, 255, 255], [0, 0, 0], 0.967380),
    ([128, 128, 128], [138, 138, 138], 0.148985),
    ([64, 64, 64], [70, 70, 70], 0.113261),
    ([200, 200, 200], [201, 201, 201], 0.028194),
    ([255, 0, 0], [0, 255, 0], 0.986662),
    ([0, 255, 0], [0, 0, 255], 1.000000),
    ([0, 0, 255], [255, 255, 0], 0.998972),
    ([30, 60, 90], [40, 60, 80], 0.083456),
    ([180, 120, 60], [182, 121, 60], 0.061286),
];

/// How far nv-flip may be from the f64 pipeline. It computes in f32, and in f32 the edge
/// and point detectors' weights cancel only to rounding, leaving a feature difference of
/// order 1e-4 after its square root; ΔE_c^(1 − 1e-4) is a little above ΔE_c. Observed
/// differences are all positive and at most 4e-5 (128 against 138 grey at 67 ppd).
const TOLERANCE: f64 = 1e-4;

#[test]
fn nv_flip_equals_the_hand_computed_colour_pipeline() {
    for (r, t, stated) in PAIRS {
        let expected = flip_uniform(r, t);
        assert!(
            (expected - stated).abs() < 1e-6,
            "{r:?} vs {t:?}: hand {expected}"
        );
        // The default viewing condition of the FLIP tool, and the Vive's axis.
        for ppd in [67.0, 9.6] {
            let got = nv_flip_uniform(r, t, ppd);
            assert!(
                (got - expected).abs() < TOLERANCE,
                "{r:?} vs {t:?} at {ppd} ppd: nv-flip {got}, hand {expected}"
            );
        }
    }
}

#[test]
fn green_versus_blue_is_the_top_of_the_scale() {
    // c_max is defined by this pair, so it maps to exactly 1.
    assert!((flip_uniform([0, 255, 0], [0, 0, 255]) - 1.0).abs() < 1e-12);
}

/// A one-pixel checkerboard of 0.2 and 0.8 (linear) against the flat 0.5 it averages to.
fn checkerboard_against_its_mean(ppd: f64) -> (FlipResult, f64) {
    let n = 64u32;
    let (lo, hi, mean) = (0.2f32, 0.8f32, 0.5f32);
    let board: Vec<f32> = (0..n * n)
        .flat_map(|i| {
            [if (i % n + i / n).is_multiple_of(2) {
                lo
            } else {
                hi
            }; 3]
        })
        .collect();
    let grey = vec![mean; board.len()];
    let f = flip(&board, &grey, n, n, ppd).unwrap();
    // The colour term alone cannot exceed this: the spatial filters are non-negative and
    // normalised, so a filtered pixel of the board is a grey between lo and hi, and for
    // greys ΔE_c grows with the luminance difference.
    let srgb8 = |v: f32| [linear_to_srgb8(&[v])[0]; 3];
    let bound = flip_uniform(srgb8(lo), srgb8(mean)).max(flip_uniform(srgb8(hi), srgb8(mean)));
    (f, bound)
}

#[test]
fn the_feature_term_is_live() {
    // At the Vive's axis resolution the board is resolved and its edges differ from the
    // flat grey's none: FLIP = ΔE_c^(1 − ΔE_f) rises well above what colour alone allows.
    let (f, colour_bound) = checkerboard_against_its_mean(10.0);
    assert!((colour_bound - 0.5359).abs() < 1e-3, "{colour_bound}");
    assert!(
        f.mean > 0.7 && f.mean > colour_bound + 0.2,
        "{} vs {colour_bound}",
        f.mean
    );
    // At 67 px/° the same board is finer than the eye resolves: the contrast-sensitivity
    // filters blur it to its mean grey, so ΔE_c ≈ 0 and FLIP is small.
    let (f, _) = checkerboard_against_its_mean(67.0);
    assert!(f.mean < 0.05, "{}", f.mean);
}
