//! One eye's frame plan on the CPU: given the gaze, which rays of the ray buffer are traced.
//! Each layer traces the lattice points whose angle from the gaze lies in its region (plus
//! the margin its Catmull-Rom taps need), that are on the image and inside the occlusion
//! mask. The renderer decides this per point on the GPU (glsl/plan.comp) from [`Regions`]'
//! numbers; this planner, which walks the lattice rows and lists the traced points as index
//! ranges (spans), is the oracle the GPU's counts are tested against.

use super::fraction;
use super::ray_buffer::RayBuffer;
use super::view::{direction, ImageGeometry};
use super::visibility_mask::VisibilityMask;

/// A run of consecutive ray-buffer entries of one layer, all traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    pub first: u32,
    pub count: u32,
    pub layer: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct LayerPlan {
    /// Pixel the layer's lattice offsets are relative to.
    pub anchor: [i32; 2],
    /// Target pixels traced (each with the layer's spp samples).
    pub targets: u64,
    /// First and last lattice points on the image (pixels), for clamping Catmull-Rom taps.
    pub lattice_min: [i32; 2],
    pub lattice_max: [i32; 2],
}

#[derive(Clone, Debug, PartialEq)]
pub struct EyePlan {
    pub gaze_px: [f64; 2],
    pub gaze_tan: [f64; 2],
    pub layers: Vec<LayerPlan>,
    /// Spans of all layers, layer by layer.
    pub spans: Vec<Span>,
}

/// Angular membership tests for one eye and gaze, shared by the planner and by anyone who
/// wants to count traced rays another way. The numbers are the f32 values the GPU's plan
/// pass gets (`GpuLayer`) and [`Self::traced`] is glsl/plan.glsl's `traced_point` with the
/// same operations in the same order, so the CPU and the GPU decide every point alike.
pub struct Regions {
    /// Tangent-space point of pixel (0, 0)'s centre, then its step per pixel in x and y.
    tan_map: [f32; 4],
    gaze_dir: [f32; 3],
    layers: Vec<[f32; 3]>,
}

/// `cos` of an angle limit as the shaders test it (`dot > cos·|t|`): limits of π or more
/// (everything is within) become -2, limits of 0 or less (nothing is) 2.
pub fn cos_limit(angle: f64) -> f32 {
    if angle >= std::f64::consts::PI {
        -2.0
    } else if angle <= 0.0 {
        2.0
    } else {
        angle.cos() as f32
    }
}

impl Regions {
    pub fn new(buffer: &RayBuffer, image: &ImageGeometry, gaze_px: [f64; 2]) -> Self {
        let layers = buffer
            .layers
            .iter()
            .map(|l| {
                [
                    cos_limit(buffer.occlusion + l.margin),
                    cos_limit(l.outer + l.margin),
                    cos_limit(l.inner - l.margin),
                ]
            })
            .collect();
        let centre = image.pixel_centre_tan(0, 0);
        let g = direction(image.tan_of(gaze_px[0], gaze_px[1]));
        Self {
            tan_map: [
                centre[0] as f32,
                centre[1] as f32,
                ((image.tan_right - image.tan_left) / image.width as f64) as f32,
                ((image.tan_down - image.tan_up) / image.height as f64) as f32,
            ],
            gaze_dir: [g[0] as f32, g[1] as f32, g[2] as f32],
            layers,
        }
    }

    /// The pixel → tangent-space map (GpuLayer::pixel_tan).
    pub fn tan_map(&self) -> [f32; 4] {
        self.tan_map
    }

    /// The unit gaze direction in the eye's view space.
    pub fn gaze_dir(&self) -> [f32; 3] {
        self.gaze_dir
    }

    /// Cosines of `layer`'s traced region, margins included: occlusion, outer, inner
    /// (GpuLayer::plan_cos).
    pub fn plan_cos(&self, layer: usize) -> [f32; 3] {
        self.layers[layer]
    }

    /// Does `layer` trace every lattice point on the image (no radius, inner edge or mask)?
    pub fn traces_everything(&self, layer: usize) -> bool {
        self.layers[layer] == [-2.0, -2.0, 2.0]
    }

    /// Is pixel `(x, y)` (on the image) traced by `layer` if it is one of its lattice points?
    pub fn traced(&self, layer: usize, x: i64, y: i64) -> bool {
        // θ < limit ⇔ cos θ > cos limit (cos decreases on [0, π]); comparing unnormalised
        // dot products with cos·|t| avoids a division and any trig per point.
        let [occlusion, outer, inner] = self.layers[layer];
        let m = self.tan_map;
        let g = self.gaze_dir;
        let tx = m[0] + x as f32 * m[2];
        let ty = m[1] + y as f32 * m[3];
        let norm = (tx * tx + ty * ty + 1.0).sqrt();
        let to_gaze = tx * g[0] + ty * g[1] + g[2];
        1.0 > occlusion * norm && to_gaze > outer * norm && to_gaze <= inner * norm
    }
}

/// Lattice indices `(i0, i1, j0, j1)` (inclusive) of a layer's points that are on the image
/// and within the ray buffer's extent, for a lattice anchored at `anchor`: the box the plan
/// pass visits and the points Catmull-Rom taps clamp to. `i0 > i1` or `j0 > j1` when empty.
pub fn layer_box(
    layer: &super::ray_buffer::LayerLattice,
    image: &ImageGeometry,
    anchor: [i32; 2],
) -> (i32, i32, i32, i32) {
    let d = layer.spacing as i32;
    let (w, h) = (image.width as i32, image.height as i32);
    let lo = |a: i32| (-a).div_euclid(d) + i32::from((-a).rem_euclid(d) != 0);
    let hi = |a: i32, size: i32| (size - 1 - a).div_euclid(d);
    (
        lo(anchor[0]).max(layer.col_min),
        hi(anchor[0], w).min(layer.col_max),
        lo(anchor[1]).max(layer.row_min),
        hi(anchor[1], h).min(layer.row_max),
    )
}

/// The pixel a gaze-anchored lattice is anchored at: the gaze's pixel, kept on the image.
pub fn gaze_anchor(image: &ImageGeometry, gaze_px: [f64; 2]) -> [i32; 2] {
    [
        (gaze_px[0].floor() as i64).clamp(0, image.width as i64 - 1) as i32,
        (gaze_px[1].floor() as i64).clamp(0, image.height as i64 - 1) as i32,
    ]
}

impl EyePlan {
    /// Plans one eye's frame. `gaze_px` must be finite and on the image (see
    /// `Gaze::resolve`).
    pub fn new(buffer: &RayBuffer, image: &ImageGeometry, gaze_px: [f64; 2]) -> Self {
        Self::masked(buffer, image, gaze_px, None)
    }

    /// Plans one eye's frame, tracing no lattice point that the lens's visibility mask
    /// makes useless (see [`VisibilityMask::needed`]; the mask must be prepared for every
    /// layer spacing of `buffer` and be of the image's size).
    pub fn masked(
        buffer: &RayBuffer,
        image: &ImageGeometry,
        gaze_px: [f64; 2],
        mask: Option<&VisibilityMask>,
    ) -> Self {
        let regions = Regions::new(buffer, image, gaze_px);
        let mut spans = Vec::new();
        let mut layers = Vec::new();
        for (k, l) in buffer.layers.iter().enumerate() {
            let d = l.spacing as i32;
            let anchor = if l.gaze_anchored {
                gaze_anchor(image, gaze_px)
            } else {
                [0, 0]
            };
            // Lattice indices whose pixels are on the image, within the buffer's extent.
            let (i0, i1, j0, j1) = layer_box(l, image, anchor);
            let mut targets = 0u64;
            let mut emit = |start: i32, count: u32, j: i32| {
                spans.push(Span {
                    first: l.index(start, j),
                    count,
                    layer: k as u32,
                });
                targets += count as u64;
            };
            // A layer without limits (regular rendering, an unmasked background) traces whole
            // rows: one span each, without testing every point.
            let whole_rows = regions.traces_everything(k) && l.fraction == 1;
            for j in j0..=j1 {
                let y = anchor[1] + j * d;
                if whole_rows {
                    match mask.map(|m| m.needed_runs(l.spacing, y as u32)) {
                        None => {
                            if i0 <= i1 {
                                emit(i0, (i1 - i0 + 1) as u32, j);
                            }
                            continue;
                        }
                        // Behind a lens: one span per run of needed pixels, no per-point test.
                        Some(Some(runs)) => {
                            for (a, count) in lattice_runs(runs, anchor[0], d, (i0, i1)) {
                                emit(a, count, j);
                            }
                            continue;
                        }
                        // A mask not prepared for this spacing: test every point below.
                        Some(None) => {}
                    }
                }
                let in_region = |i: i32, j: i32| {
                    let (x, y) = (anchor[0] + i * d, anchor[1] + j * d);
                    regions.traced(k, x as i64, y as i64)
                        && mask.is_none_or(|m| m.needed(l.spacing, x as u32, y as u32))
                };
                // A fractional layer skips what its pattern skips (frame 0's) while the
                // point's owner is traced (glsl/plan.comp).
                let skipped = |i: i32| {
                    let [oi, oj] = fraction::owner(l.fraction, 0, i, j);
                    !fraction::traces(l.fraction, 0, i, j)
                        && (i0..=i1).contains(&oi)
                        && (j0..=j1).contains(&oj)
                        && in_region(oi, oj)
                };
                let inside = |i: i32| in_region(i, j) && !skipped(i);
                for (start, count) in point_runs((i0, i1), inside) {
                    emit(start, count, j);
                }
            }
            layers.push(LayerPlan {
                anchor,
                targets,
                lattice_min: [anchor[0] + i0 * d, anchor[1] + j0 * d],
                lattice_max: [anchor[0] + i1 * d, anchor[1] + j1 * d],
            });
        }
        Self {
            gaze_px,
            gaze_tan: image.tan_of(gaze_px[0], gaze_px[1]),
            layers,
            spans,
        }
    }

    /// Camera paths this plan traces: targets × spp over all layers.
    pub fn samples(&self, buffer: &RayBuffer) -> u64 {
        self.layers
            .iter()
            .zip(&buffer.layers)
            .map(|(p, l)| p.targets * l.spp as u64)
            .sum()
    }
}

/// The lattice columns, within `cols` (first, last), of each run `[x0, x1)` of needed pixels
/// on a row: as (first column, count), for a layer of spacing `d` anchored at `anchor_x`.
fn lattice_runs(
    runs: &[(i32, i32)],
    anchor_x: i32,
    d: i32,
    cols: (i32, i32),
) -> impl Iterator<Item = (i32, u32)> + '_ {
    runs.iter().filter_map(move |&(x0, x1)| {
        let a = (x0 - anchor_x).div_euclid(d) + i32::from((x0 - anchor_x).rem_euclid(d) != 0);
        let (a, b) = (a.max(cols.0), (x1 - 1 - anchor_x).div_euclid(d).min(cols.1));
        (a <= b).then(|| (a, (b - a + 1) as u32))
    })
}

/// The runs of consecutive columns within `cols` (first, last) for which `inside` holds, as
/// (first column, count).
fn point_runs(cols: (i32, i32), inside: impl Fn(i32) -> bool) -> Vec<(i32, u32)> {
    let mut runs = Vec::new();
    let mut run: Option<(i32, u32)> = None;
    for i in cols.0..=cols.1 + 1 {
        match (i <= cols.1 && inside(i), &mut run) {
            (true, Some((_, count))) => *count += 1,
            (true, None) => run = Some((i, 1)),
            (false, Some(done)) => {
                runs.push(*done);
                run = None;
            }
            (false, None) => {}
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::ray_buffer::unpack_offset;
    use crate::foveation::view::EyeFov;
    use crate::foveation::{FoveationConfig, Gaze, Layer, VisibilityMask, DEFAULT_DENOISE_SIGMA};

    /// Counts traced rays per layer by visiting every pixel of the image: on the layer's
    /// lattice (relative to its anchor) and inside its region.
    fn brute_force(buffer: &RayBuffer, image: &ImageGeometry, gaze: [f64; 2]) -> Vec<u64> {
        let regions = Regions::new(buffer, image, gaze);
        buffer
            .layers
            .iter()
            .enumerate()
            .map(|(k, l)| {
                let d = l.spacing as i64;
                let a = if l.gaze_anchored {
                    gaze_anchor(image, gaze)
                } else {
                    [0, 0]
                };
                let mut n = 0;
                for y in 0..image.height as i64 {
                    for x in 0..image.width as i64 {
                        let on = (x - a[0] as i64).rem_euclid(d) == 0
                            && (y - a[1] as i64).rem_euclid(d) == 0;
                        if on && regions.traced(k, x, y) {
                            n += 1;
                        }
                    }
                }
                n
            })
            .collect()
    }

    fn configs() -> Vec<FoveationConfig> {
        let mut occluded = FoveationConfig::thesis();
        occluded.occlusion_deg = Some(45.0);
        let two = FoveationConfig {
            layers: vec![
                Layer {
                    radius_deg: Some(15.0),
                    spacing: 2,
                    spp: 2,
                    denoise: 0,
                    filter_mar: 0.0,
                    filter_px: 0.0,
                    denoise_mar: 0.0,
                    denoise_sigma: DEFAULT_DENOISE_SIGMA,
                    fraction: 1,
                },
                Layer {
                    radius_deg: None,
                    spacing: 5,
                    spp: 1,
                    denoise: 0,
                    filter_mar: 0.0,
                    filter_px: 0.0,
                    denoise_mar: 0.0,
                    denoise_sigma: DEFAULT_DENOISE_SIGMA,
                    fraction: 1,
                },
            ],
            blend_deg: 3.0,
            occlusion_deg: None,
        };
        vec![
            FoveationConfig::thesis(),
            occluded,
            two,
            FoveationConfig::regular(2),
        ]
    }

    #[test]
    fn span_counts_equal_a_brute_force_count_over_every_pixel() {
        for (w, h, fov) in [
            (360, 400, EyeFov::VIVE_PRO_EYE_LEFT),
            (333, 250, EyeFov::VIVE_PRO_EYE_RIGHT),
        ] {
            let image = ImageGeometry::new(w, h, fov);
            for config in configs() {
                let buffer = RayBuffer::build(&config, &[image]);
                for gaze in [Gaze::Forward, Gaze::Corner, Gaze::Pixel(300.0, 20.0)] {
                    let (g, _) = gaze.resolve(&image);
                    let plan = EyePlan::new(&buffer, &image, g);
                    let planned: Vec<u64> = plan.layers.iter().map(|l| l.targets).collect();
                    assert_eq!(
                        planned,
                        brute_force(&buffer, &image, g),
                        "{config:?} {gaze:?}"
                    );
                    let spans: u64 = plan.spans.iter().map(|s| s.count as u64).sum();
                    assert_eq!(spans, planned.iter().sum::<u64>());
                }
            }
        }
    }

    #[test]
    fn every_span_entry_points_at_a_traced_on_screen_lattice_pixel() {
        let image = ImageGeometry::new(300, 320, EyeFov::VIVE_PRO_EYE_LEFT);
        let buffer = RayBuffer::build(&FoveationConfig::thesis(), &[image]);
        let (g, _) = Gaze::Pixel(40.0, 250.0).resolve(&image);
        let plan = EyePlan::new(&buffer, &image, g);
        let regions = Regions::new(&buffer, &image, g);
        for s in &plan.spans {
            let a = plan.layers[s.layer as usize].anchor;
            for r in s.first..s.first + s.count {
                let (dx, dy) = unpack_offset(buffer.offsets[r as usize]);
                let (x, y) = (a[0] + dx, a[1] + dy);
                assert!(x >= 0 && y >= 0 && x < 300 && y < 320);
                assert!(regions.traced(s.layer as usize, x as i64, y as i64));
            }
        }
    }

    fn forward_and_corner(image: &ImageGeometry, config: &FoveationConfig) -> (u64, u64) {
        let buffer = RayBuffer::build(config, &[*image]);
        let count =
            |gaze: Gaze| EyePlan::new(&buffer, image, gaze.resolve(image).0).samples(&buffer);
        (count(Gaze::Forward), count(Gaze::Corner))
    }

    #[test]
    fn corner_gaze_traces_fewer_rays_than_forward() {
        // Headset: the thesis config's occlusion mask hides the corner the gaze sits in.
        let vive = ImageGeometry::new(720, 800, EyeFov::VIVE_PRO_EYE_LEFT);
        let (forward, corner) = forward_and_corner(&vive, &FoveationConfig::thesis());
        assert!(corner < forward, "corner {corner} forward {forward}");
        assert!(forward * 10 < 720 * 800 * 4, "forward {forward}");
        // Desktop field of view (60° by 45°), no mask needed: most of each disc is off screen.
        let fov = EyeFov {
            left: -30f32.to_radians(),
            right: 30f32.to_radians(),
            up: 22.5f32.to_radians(),
            down: -22.5f32.to_radians(),
        };
        let desk = ImageGeometry::new(640, 480, fov);
        let mut unmasked = FoveationConfig::thesis();
        unmasked.occlusion_deg = None;
        let (forward, corner) = forward_and_corner(&desk, &unmasked);
        assert!(corner < forward, "corner {corner} forward {forward}");
    }

    #[test]
    fn true_angles_make_a_corner_gaze_cover_more_pixels_on_a_wide_unmasked_view() {
        // A degree at 63° off axis spans ~5x the pixels it spans on the axis (radially), so
        // without a lens mask a corner gaze's discs cover more pixels than a forward one's:
        // the price of measuring radii in real degrees rather than pixels.
        let vive = ImageGeometry::new(720, 800, EyeFov::VIVE_PRO_EYE_LEFT);
        let mut unmasked = FoveationConfig::thesis();
        unmasked.occlusion_deg = None;
        let (forward, corner) = forward_and_corner(&vive, &unmasked);
        assert!(corner > forward, "corner {corner} forward {forward}");
    }

    #[test]
    fn regular_traces_every_pixel_once() {
        let image = ImageGeometry::new(64, 48, EyeFov::VIVE_PRO_EYE_LEFT);
        let buffer = RayBuffer::build(&FoveationConfig::regular(3), &[image]);
        let plan = EyePlan::new(&buffer, &image, Gaze::Corner.resolve(&image).0);
        assert_eq!(plan.layers[0].targets, 64 * 48);
        assert_eq!(plan.samples(&buffer), 64 * 48 * 3);
        assert_eq!(plan.spans.len(), 48, "one span per row");
    }

    #[test]
    fn foveal_disc_has_the_area_its_angle_implies() {
        // On the axis of a large image a 6° disc is nearly flat: area ≈ π r², r in pixels
        // from the tangent scale. Independent of the planner's predicate.
        let image = ImageGeometry::new(1440, 1600, EyeFov::VIVE_PRO_EYE_LEFT);
        let config = FoveationConfig::thesis();
        let buffer = RayBuffer::build(&config, &[image]);
        let plan = EyePlan::new(&buffer, &image, Gaze::Forward.resolve(&image).0);
        let px_per_tan = 1440.0 / (image.tan_right - image.tan_left);
        let r = (6.0f64.to_radians() + buffer.layers[0].margin).tan() * px_per_tan;
        let area = std::f64::consts::PI * r * r;
        let got = plan.layers[0].targets as f64;
        assert!((got / area - 1.0).abs() < 0.03, "{got} vs {area}");
    }

    #[test]
    fn a_visibility_mask_removes_exactly_the_hidden_rays() {
        let image = ImageGeometry::new(64, 48, EyeFov::VIVE_PRO_EYE_LEFT);
        let corner = |x: f64, y: f64| {
            let t = image.tan_of(x, y);
            [t[0] as f32, t[1] as f32]
        };
        // Hidden: a triangle over the top-left corner and one over the right edge (so rows
        // have runs that end inside the image).
        let vertices = [
            corner(-1.0, -1.0),
            corner(40.0, -1.0),
            corner(-1.0, 30.0),
            corner(65.0, 10.0),
            corner(50.0, 30.0),
            corner(65.0, 49.0),
        ];
        let mut mask =
            VisibilityMask::from_hidden_triangles(&image, &vertices, &[0, 1, 2, 3, 4, 5]);
        let hidden = 64 * 48 - mask.visible_count() as u64;
        assert!(hidden > 500, "{hidden}");
        // Regular (spacing 1): every visible pixel once, no hidden one.
        let buffer = RayBuffer::build(&FoveationConfig::regular(1), &[image]);
        mask.prepare(1);
        let plan = EyePlan::masked(&buffer, &image, [32.0, 24.0], Some(&mask));
        assert_eq!(plan.layers[0].targets, 64 * 48 - hidden);
        for span in &plan.spans {
            for i in span.first..span.first + span.count {
                let (dx, dy) = unpack_offset(buffer.offsets[i as usize]);
                assert!(
                    mask.visible(dx as u32, dy as u32),
                    "traced hidden pixel {dx},{dy}"
                );
            }
        }
        // Foveated: fewer rays than unmasked, and more than the visible fraction alone
        // would give (lattice points near the edge are kept for the fill).
        let config = FoveationConfig::thesis();
        let buffer = RayBuffer::build(&config, &[image]);
        for l in &buffer.layers {
            mask.prepare(l.spacing);
        }
        let gaze = [32.0, 24.0];
        let open = EyePlan::new(&buffer, &image, gaze).samples(&buffer);
        let plan = EyePlan::masked(&buffer, &image, gaze, Some(&mask));
        let masked = plan.samples(&buffer);
        assert!(masked < open, "{masked} vs {open}");
        // Per layer, exactly the lattice points in the layer's region that the mask needs
        // (counted point by point: the background layer's spans come from row runs).
        let regions = Regions::new(&buffer, &image, gaze);
        for (k, l) in buffer.layers.iter().enumerate() {
            let d = l.spacing as i64;
            let a = match l.gaze_anchored {
                true => gaze_anchor(&image, gaze),
                false => [0, 0],
            };
            let mut n = 0;
            for y in 0..48i64 {
                for x in 0..64i64 {
                    let on = (x - a[0] as i64).rem_euclid(d) == 0
                        && (y - a[1] as i64).rem_euclid(d) == 0;
                    if on && regions.traced(k, x, y) && mask.needed(l.spacing, x as u32, y as u32) {
                        n += 1;
                    }
                }
            }
            assert_eq!(plan.layers[k].targets, n, "layer {k}");
        }
    }
}
