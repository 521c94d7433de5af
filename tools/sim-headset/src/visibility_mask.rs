//! XR_KHR_visibility_mask: a lens-shaped visible area, like a real HMD's.
//!
//! Geometry lives in tangent space (view space at z = -1, +Y up), as the spec asks. The
//! field of view spans x in [tan(left), tan(right)], y in [tan(down), tan(up)]. The visible
//! area is an "ellipse" centred on the view axis whose semi-axis towards each side is
//! `ELLIPSE_SCALE` times the field of view's extent on that side (four quarter-ellipses, as
//! the field of view is asymmetric), so the corners of the image are hidden. All triangles
//! wind counter-clockwise, as the spec demands.

use openxr_sys as xr;

use crate::ffi::{self, XrResult};
use crate::registry::Runtime;

/// Fraction of the field of view's half-extent covered by the ellipse's semi-axes.
pub const ELLIPSE_SCALE: f32 = 0.92;
/// Polygon segments approximating the ellipse: fine enough that no pixel at 1440×1600
/// falls more than ~1 px off the true curve (sagitta of a 5.6° step).
pub const SEGMENTS: usize = 64;

#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub vertices: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
}

/// The field of view as tangent-space bounds.
#[derive(Clone, Copy, Debug)]
pub struct TanRect {
    pub left: f32,
    pub right: f32,
    pub down: f32,
    pub up: f32,
}

impl TanRect {
    pub fn from_fov(fov: &xr::Fovf) -> Self {
        Self {
            left: fov.angle_left.tan(),
            right: fov.angle_right.tan(),
            down: fov.angle_down.tan(),
            up: fov.angle_up.tan(),
        }
    }
}

/// The ellipse polygon, counter-clockwise from +X.
pub fn ellipse(r: &TanRect) -> Vec<[f32; 2]> {
    (0..SEGMENTS)
        .map(|i| {
            let t = i as f32 / SEGMENTS as f32 * std::f32::consts::TAU;
            let (s, c) = t.sin_cos();
            let ax = ELLIPSE_SCALE * if c >= 0.0 { r.right } else { -r.left };
            let ay = ELLIPSE_SCALE * if s >= 0.0 { r.up } else { -r.down };
            [c * ax, s * ay]
        })
        .collect()
}

/// Where the ray from the origin through `p` leaves the rectangle.
fn project_to_rect(p: [f32; 2], r: &TanRect) -> [f32; 2] {
    let sx = if p[0] > 0.0 {
        r.right / p[0]
    } else if p[0] < 0.0 {
        r.left / p[0]
    } else {
        f32::INFINITY
    };
    let sy = if p[1] > 0.0 {
        r.up / p[1]
    } else if p[1] < 0.0 {
        r.down / p[1]
    } else {
        f32::INFINITY
    };
    let s = sx.min(sy);
    [p[0] * s, p[1] * s]
}

fn angle(p: [f32; 2]) -> f32 {
    p[1].atan2(p[0]).rem_euclid(std::f32::consts::TAU)
}

/// The visible area: a fan from the view axis over the ellipse polygon.
pub fn visible_mesh(r: &TanRect) -> Mesh {
    let mut vertices = vec![[0.0, 0.0]];
    vertices.extend(ellipse(r));
    let n = SEGMENTS as u32;
    let indices = (0..n).flat_map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    Mesh { vertices, indices }
}

/// The hidden area between the ellipse and the rectangle: per ellipse segment, the sector
/// out to the rectangle, fan-triangulated from its inner vertex, with a rectangle corner
/// added where one falls inside the sector.
pub fn hidden_mesh(r: &TanRect) -> Mesh {
    let inner = ellipse(r);
    let corners = [
        [r.right, r.up],
        [r.left, r.up],
        [r.left, r.down],
        [r.right, r.down],
    ];
    let mut vertices: Vec<[f32; 2]> = Vec::new();
    let mut indices = Vec::new();
    for i in 0..SEGMENTS {
        let (p0, p1) = (inner[i], inner[(i + 1) % SEGMENTS]);
        let (a0, mut a1) = (angle(p0), angle(p1));
        if a1 <= a0 {
            a1 += std::f32::consts::TAU;
        }
        // The sector's boundary, counter-clockwise: out along ray i, along the rectangle,
        // back in along ray i+1.
        let mut ring = vec![p0, project_to_rect(p0, r)];
        for c in corners {
            let mut a = angle(c);
            if a < a0 {
                a += std::f32::consts::TAU;
            }
            if a > a0 + 1e-6 && a < a1 - 1e-6 {
                ring.push(c);
            }
        }
        ring.push(project_to_rect(p1, r));
        ring.push(p1);
        let base = vertices.len() as u32;
        vertices.extend_from_slice(&ring);
        for k in 1..ring.len() as u32 - 1 {
            indices.extend_from_slice(&[base, base + k, base + k + 1]);
        }
    }
    Mesh { vertices, indices }
}

/// The ellipse outline as a closed line loop.
pub fn line_loop(r: &TanRect) -> Mesh {
    Mesh {
        vertices: ellipse(r),
        indices: (0..SEGMENTS as u32).collect(),
    }
}

/// `xrGetVisibilityMaskKHR` (after the handle and argument checks in the entry point).
pub fn get_visibility_mask(
    rt: &Runtime,
    session: xr::Session,
    view_configuration_type: xr::ViewConfigurationType,
    view_index: u32,
    mask_type: xr::VisibilityMaskTypeKHR,
    out: *mut xr::VisibilityMaskKHR,
) -> XrResult {
    rt.live_session(session)?;
    if view_configuration_type != xr::ViewConfigurationType::PRIMARY_STEREO {
        return Err(xr::Result::ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
    }
    if view_index > 1 {
        return Err(xr::Result::ERROR_VALIDATION_FAILURE);
    }
    let rect = TanRect::from_fov(&crate::views::eye_fov(view_index as usize));
    let mesh = match mask_type {
        xr::VisibilityMaskTypeKHR::HIDDEN_TRIANGLE_MESH => hidden_mesh(&rect),
        xr::VisibilityMaskTypeKHR::VISIBLE_TRIANGLE_MESH => visible_mesh(&rect),
        xr::VisibilityMaskTypeKHR::LINE_LOOP => line_loop(&rect),
        _ => return Err(xr::Result::ERROR_VALIDATION_FAILURE),
    };
    // SAFETY: the entry point checked `out` for null; the app owns the struct and its arrays
    // for the duration of the call, with the capacities it declares.
    unsafe {
        let out = &mut *out;
        ffi::check_type(out.ty, xr::StructureType::VISIBILITY_MASK_KHR)?;
        out.vertex_count_output = mesh.vertices.len() as u32;
        out.index_count_output = mesh.indices.len() as u32;
        if out.vertex_capacity_input == 0 && out.index_capacity_input == 0 {
            return Ok(xr::Result::SUCCESS);
        }
        if (out.vertex_capacity_input as usize) < mesh.vertices.len()
            || (out.index_capacity_input as usize) < mesh.indices.len()
        {
            return Err(xr::Result::ERROR_SIZE_INSUFFICIENT);
        }
        if out.vertices.is_null() || out.indices.is_null() {
            return Err(xr::Result::ERROR_VALIDATION_FAILURE);
        }
        for (i, v) in mesh.vertices.iter().enumerate() {
            *out.vertices.add(i) = xr::Vector2f { x: v[0], y: v[1] };
        }
        std::ptr::copy_nonoverlapping(mesh.indices.as_ptr(), out.indices, mesh.indices.len());
    }
    Ok(xr::Result::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn left_eye() -> TanRect {
        TanRect::from_fov(&crate::views::eye_fov(0))
    }

    fn tri_area(m: &Mesh, t: &[u32]) -> f32 {
        let [a, b, c] = [0, 1, 2].map(|k| m.vertices[t[k] as usize]);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
    }

    fn total_area(m: &Mesh) -> f32 {
        m.indices.chunks(3).map(|t| tri_area(m, t)).sum()
    }

    fn inside(p: [f32; 2], r: &TanRect) -> bool {
        let e = 1e-5;
        p[0] >= r.left - e && p[0] <= r.right + e && p[1] >= r.down - e && p[1] <= r.up + e
    }

    #[test]
    fn every_triangle_winds_counter_clockwise() {
        let r = left_eye();
        for m in [hidden_mesh(&r), visible_mesh(&r)] {
            assert_eq!(m.indices.len() % 3, 0);
            for t in m.indices.chunks(3) {
                assert!(tri_area(&m, t) > 0.0, "triangle {t:?} is not CCW");
            }
        }
    }

    #[test]
    fn hidden_and_visible_tile_the_fov_rectangle() {
        for r in [left_eye(), TanRect::from_fov(&crate::views::eye_fov(1))] {
            let rect_area = (r.right - r.left) * (r.up - r.down);
            let sum = total_area(&hidden_mesh(&r)) + total_area(&visible_mesh(&r));
            assert!(
                (sum - rect_area).abs() < 1e-4 * rect_area,
                "{sum} vs {rect_area}"
            );
            // The corners are hidden: a real share of the image is masked.
            let hidden = total_area(&hidden_mesh(&r)) / rect_area;
            assert!(hidden > 0.2 && hidden < 0.4, "hidden fraction {hidden}");
        }
    }

    #[test]
    fn ellipse_lies_strictly_inside_and_touches_scaled_extents() {
        let r = left_eye();
        let e = ellipse(&r);
        for p in &e {
            assert!(p[0] > r.left && p[0] < r.right && p[1] > r.down && p[1] < r.up);
        }
        assert!((e[0][0] - ELLIPSE_SCALE * r.right).abs() < 1e-6);
        assert!((e[SEGMENTS / 2][0] - ELLIPSE_SCALE * r.left).abs() < 1e-5);
        for m in [hidden_mesh(&r), visible_mesh(&r), line_loop(&r)] {
            assert!(m.vertices.iter().all(|&p| inside(p, &r)));
            assert!(m.indices.iter().all(|&i| (i as usize) < m.vertices.len()));
        }
    }

    #[test]
    fn line_loop_visits_every_ellipse_vertex_once() {
        let m = line_loop(&left_eye());
        assert_eq!(m.vertices.len(), SEGMENTS);
        assert_eq!(m.indices, (0..SEGMENTS as u32).collect::<Vec<_>>());
    }
}
