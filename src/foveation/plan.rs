//! One eye's frame plan: given the gaze, which rays of the ray buffer are traced. Each layer
//! traces the lattice points whose angle from the gaze lies in its region (plus a margin the
//! fill needs), that are on the image and inside the occlusion mask; everything else is
//! neither traced nor dispatched. Traced points of one lattice row are consecutive in the
//! buffer, so the plan is a short list of index ranges (spans) that the trace pass walks.

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
    /// Pixels the fill pass visits: `[min, max)`; empty for spacing 1 or nothing traced.
    pub fill_min: [i32; 2],
    pub fill_max: [i32; 2],
}

impl LayerPlan {
    pub fn fill_is_empty(&self) -> bool {
        self.fill_max[0] <= self.fill_min[0] || self.fill_max[1] <= self.fill_min[1]
    }
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
/// wants to count traced rays another way.
pub struct Regions<'a> {
    image: &'a ImageGeometry,
    gaze_dir: [f64; 3],
    layers: Vec<LayerCosines>,
}

/// `cos` of an angle limit, with limits of π or more (everything is within) and of 0 or
/// less (nothing is) turned into cosines no dot product can fail or pass.
fn cos_limit(angle: f64) -> f64 {
    if angle >= std::f64::consts::PI {
        f64::NEG_INFINITY
    } else if angle <= 0.0 {
        f64::INFINITY
    } else {
        angle.cos()
    }
}

/// Cosines of one layer's traced region: the occlusion mask and the outer and inner edges,
/// each widened by the layer's margin.
#[derive(Clone, Copy)]
struct LayerCosines {
    occlusion: f64,
    outer: f64,
    inner: f64,
}

impl LayerCosines {
    /// No limit at all (a background layer without a mask): skip the dot products.
    fn everything(&self) -> bool {
        self.occlusion == f64::NEG_INFINITY
            && self.outer == f64::NEG_INFINITY
            && self.inner == f64::INFINITY
    }
}

impl<'a> Regions<'a> {
    pub fn new(buffer: &'a RayBuffer, image: &'a ImageGeometry, gaze_px: [f64; 2]) -> Self {
        let layers = buffer
            .layers
            .iter()
            .map(|l| LayerCosines {
                occlusion: cos_limit(buffer.occlusion + l.margin),
                outer: cos_limit(l.outer + l.margin),
                inner: cos_limit(l.inner - l.margin),
            })
            .collect();
        Self {
            image,
            gaze_dir: direction(image.tan_of(gaze_px[0], gaze_px[1])),
            layers,
        }
    }

    /// Does `layer` trace every lattice point on the image (no radius, inner edge or mask)?
    pub fn traces_everything(&self, layer: usize) -> bool {
        self.layers[layer].everything()
    }

    /// Is pixel `(x, y)` (on the image) traced by `layer` if it is one of its lattice points?
    pub fn traced(&self, layer: usize, x: i64, y: i64) -> bool {
        // θ < limit ⇔ cos θ > cos limit (cos decreases on [0, π]); comparing unnormalised
        // dot products with cos·|u| avoids a division and any trig per point.
        let c = &self.layers[layer];
        if c.everything() {
            return true;
        }
        let t = self.image.pixel_centre_tan(x, y);
        let norm = (t[0] * t[0] + t[1] * t[1] + 1.0).sqrt();
        let g = self.gaze_dir;
        let to_gaze = t[0] * g[0] + t[1] * g[1] + g[2];
        1.0 > c.occlusion * norm && to_gaze > c.outer * norm && to_gaze <= c.inner * norm
    }
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
        let (w, h) = (image.width as i32, image.height as i32);
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
            let lo = |a: i32| (-a).div_euclid(d) + i32::from((-a).rem_euclid(d) != 0);
            let hi = |a: i32, size: i32| (size - 1 - a).div_euclid(d);
            let (i0, i1) = (
                lo(anchor[0]).max(l.col_min),
                hi(anchor[0], w).min(l.col_max),
            );
            let (j0, j1) = (
                lo(anchor[1]).max(l.row_min),
                hi(anchor[1], h).min(l.row_max),
            );
            let mut targets = 0u64;
            let (mut min, mut max) = ([i32::MAX; 2], [i32::MIN; 2]);
            let mut emit = |start: i32, count: u32, j: i32| {
                spans.push(Span {
                    first: l.index(start, j),
                    count,
                    layer: k as u32,
                });
                targets += count as u64;
                let (x0, y) = (anchor[0] + start * d, anchor[1] + j * d);
                min = [min[0].min(x0), min[1].min(y)];
                max = [max[0].max(x0 + (count as i32 - 1) * d), max[1].max(y)];
            };
            // A layer without limits (regular rendering, an unmasked background) traces whole
            // rows: one span each, without testing every point.
            let whole_rows = regions.traces_everything(k);
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
                            for &(x0, x1) in runs {
                                let a = (x0 - anchor[0]).div_euclid(d)
                                    + i32::from((x0 - anchor[0]).rem_euclid(d) != 0);
                                let (a, b) =
                                    (a.max(i0), (x1 - 1 - anchor[0]).div_euclid(d).min(i1));
                                if a <= b {
                                    emit(a, (b - a + 1) as u32, j);
                                }
                            }
                            continue;
                        }
                        // A mask not prepared for this spacing: test every point below.
                        Some(None) => {}
                    }
                }
                let mut run: Option<(i32, u32)> = None;
                for i in i0..=i1 + 1 {
                    let x = anchor[0] + i * d;
                    let inside = i <= i1
                        && regions.traced(k, x as i64, y as i64)
                        && mask.is_none_or(|m| m.needed(l.spacing, x as u32, y as u32));
                    match (inside, &mut run) {
                        (true, Some((_, count))) => *count += 1,
                        (true, None) => run = Some((i, 1)),
                        (false, Some((start, count))) => {
                            emit(*start, *count, j);
                            run = None;
                        }
                        (false, None) => {}
                    }
                }
            }
            // Pixels up to d-1 beyond the outermost traced points are filled (between
            // lattice points, or extrapolated at the image border by clamped taps).
            let (fill_min, fill_max) = if d == 1 || targets == 0 {
                ([0, 0], [0, 0])
            } else {
                (
                    [(min[0] - d + 1).max(0), (min[1] - d + 1).max(0)],
                    [(max[0] + d).min(w), (max[1] + d).min(h)],
                )
            };
            layers.push(LayerPlan {
                anchor,
                targets,
                lattice_min: [anchor[0] + lo(anchor[0]) * d, anchor[1] + lo(anchor[1]) * d],
                lattice_max: [
                    anchor[0] + hi(anchor[0], w) * d,
                    anchor[1] + hi(anchor[1], h) * d,
                ],
                fill_min,
                fill_max,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::ray_buffer::unpack_offset;
    use crate::foveation::view::EyeFov;
    use crate::foveation::{FoveationConfig, Gaze, Layer, VisibilityMask};

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
                },
                Layer {
                    radius_deg: None,
                    spacing: 5,
                    spp: 1,
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
        assert!(plan.layers[0].fill_is_empty());
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
