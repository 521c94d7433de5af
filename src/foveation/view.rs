//! An eye's image as geometry: which direction every pixel looks in, and angles between
//! directions. Degrees become pixels through this, never through a constant
//! pixels-per-degree: with a 110° asymmetric field of view, one degree spans about twice as
//! many pixels at the edge of the image as at its centre.

/// A field of view as the four half-angles OpenXR reports per eye, in radians
/// (`left < 0 < right`, `down < 0 < up`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeFov {
    pub left: f32,
    pub right: f32,
    pub up: f32,
    pub down: f32,
}

impl EyeFov {
    /// HTC Vive Pro Eye, left eye, as SteamVR reports it (tangents about -1.39, 1.24, 1.47,
    /// -1.46: about 105° wide and 111° tall, wider towards the nose side of the other eye).
    /// Approximate values typical of the device; the real ones come from `xrLocateViews`.
    pub const VIVE_PRO_EYE_LEFT: EyeFov = EyeFov {
        left: -0.9470,
        right: 0.8922,
        up: 0.9733,
        down: -0.9700,
    };
    /// The right eye mirrors the left.
    pub const VIVE_PRO_EYE_RIGHT: EyeFov = EyeFov {
        left: -0.8922,
        right: 0.9470,
        up: 0.9733,
        down: -0.9700,
    };
    /// Per-eye resolution of the Vive Pro Eye's panels.
    pub const VIVE_PRO_EYE_SIZE: (u32, u32) = (1440, 1600);
    /// Varjo XR-4, either eye: the spec sheet's 120° × 105°, taken as symmetric (Varjo
    /// publishes no per-eye asymmetry; the runtime's `xrLocateViews` has the real angles).
    pub const VARJO_XR_4: EyeFov = EyeFov {
        left: -std::f32::consts::FRAC_PI_3, // 60°
        right: std::f32::consts::FRAC_PI_3,
        up: 0.916_297_9, // 52.5°
        down: -0.916_297_9,
    };
    /// Per-eye resolution of the Varjo XR-4's panels.
    pub const VARJO_XR_4_SIZE: (u32, u32) = (3840, 3744);

    /// The field of view of the `window` pixels about the view axis of an image of `full`
    /// pixels over this field: each tangent scaled by window ÷ full, so every pixel of the
    /// window looks where the same pixel of the full image does (the same density, a smaller
    /// field).
    pub fn central_window(self, full: [u32; 2], window: [u32; 2]) -> EyeFov {
        let cut = |angle: f32, of: f32| (angle.tan() * of).atan();
        let [sx, sy] = [0, 1].map(|i| window[i] as f32 / full[i] as f32);
        EyeFov {
            left: cut(self.left, sx),
            right: cut(self.right, sx),
            up: cut(self.up, sy),
            down: cut(self.down, sy),
        }
    }
}

/// The pixel grid of one eye's image over its field of view. Pixel `(x, y)` covers
/// `[x, x+1) × [y, y+1)` in continuous pixel coordinates, row 0 at the top; the view looks
/// along `(tx, ty, 1)` in tangent space (`ty` up), matching trace.comp's camera rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageGeometry {
    pub width: u32,
    pub height: u32,
    pub tan_left: f64,
    pub tan_right: f64,
    pub tan_up: f64,
    pub tan_down: f64,
}

impl ImageGeometry {
    pub fn new(width: u32, height: u32, fov: EyeFov) -> Self {
        Self {
            width,
            height,
            tan_left: (fov.left as f64).tan(),
            tan_right: (fov.right as f64).tan(),
            tan_up: (fov.up as f64).tan(),
            tan_down: (fov.down as f64).tan(),
        }
    }

    /// Tangent-space coordinates of a continuous pixel position.
    pub fn tan_of(&self, px: f64, py: f64) -> [f64; 2] {
        [
            self.tan_left + px / self.width as f64 * (self.tan_right - self.tan_left),
            self.tan_up + py / self.height as f64 * (self.tan_down - self.tan_up),
        ]
    }

    /// Continuous pixel position of a tangent-space point (inverse of [`Self::tan_of`]).
    pub fn pixel_of(&self, t: [f64; 2]) -> [f64; 2] {
        [
            (t[0] - self.tan_left) / (self.tan_right - self.tan_left) * self.width as f64,
            (t[1] - self.tan_up) / (self.tan_down - self.tan_up) * self.height as f64,
        ]
    }

    /// Tangent-space point of the centre of pixel `(x, y)`.
    pub fn pixel_centre_tan(&self, x: i64, y: i64) -> [f64; 2] {
        self.tan_of(x as f64 + 0.5, y as f64 + 0.5)
    }

    /// The largest change of tangent across one pixel, in either axis. Because
    /// `dθ = cos²θ · d(tan θ) ≤ d(tan θ)`, no pixel subtends more than this many radians:
    /// the bound that turns "within k pixels" into a safe angular margin.
    pub fn max_radians_per_pixel(&self) -> f64 {
        ((self.tan_right - self.tan_left) / self.width as f64)
            .max((self.tan_up - self.tan_down) / self.height as f64)
    }

    /// Where the view axis (straight ahead) meets the image, in continuous pixels. With an
    /// asymmetric field of view this is not the image centre.
    pub fn axis_pixel(&self) -> [f64; 2] {
        self.pixel_of([0.0, 0.0])
    }
}

/// Unit direction of a tangent-space point.
pub fn direction(t: [f64; 2]) -> [f64; 3] {
    let n = (t[0] * t[0] + t[1] * t[1] + 1.0).sqrt();
    [t[0] / n, t[1] / n, 1.0 / n]
}

/// Angle in radians between the directions of two tangent-space points, accurate for small
/// angles too (atan2 of the cross and dot products, not acos).
pub fn angle_between(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (a, b) = (direction(a), direction(b));
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let sin = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
    let cos = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    sin.atan2(cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vive() -> ImageGeometry {
        ImageGeometry::new(1440, 1600, EyeFov::VIVE_PRO_EYE_LEFT)
    }

    #[test]
    fn pixel_and_tangent_round_trip() {
        let g = vive();
        for (px, py) in [(0.0, 0.0), (1440.0, 1600.0), (100.25, 1333.5)] {
            let p = g.pixel_of(g.tan_of(px, py));
            assert!((p[0] - px).abs() < 1e-9 && (p[1] - py).abs() < 1e-9);
        }
        // The image corners are the field of view's tangents; row 0 is the top.
        assert_eq!(g.tan_of(0.0, 0.0), [g.tan_left, g.tan_up]);
        let t = g.tan_of(1440.0, 1600.0);
        assert!((t[0] - g.tan_right).abs() < 1e-12 && (t[1] - g.tan_down).abs() < 1e-12);
    }

    #[test]
    fn a_central_window_keeps_the_pixels_where_they_were() {
        let full = ImageGeometry::new(3840, 3744, EyeFov::VARJO_XR_4);
        let fov = EyeFov::VARJO_XR_4.central_window([3840, 3744], [1600, 1560]);
        let window = ImageGeometry::new(1600, 1560, fov);
        // Pixel (x, y) of the window is pixel (x + 1120, y + 1092) of the panel.
        for (x, y) in [(0, 0), (799, 780), (1599, 1559), (17, 1200)] {
            let a = window.pixel_centre_tan(x, y);
            let b = full.pixel_centre_tan(x + 1120, y + 1092);
            assert!(
                (a[0] - b[0]).abs() < 1e-5 && (a[1] - b[1]).abs() < 1e-5,
                "{a:?} {b:?}"
            );
        }
        // An asymmetric field keeps its axis where it was, as a fraction of the image.
        let vive = vive();
        let cut = ImageGeometry::new(
            720,
            800,
            EyeFov::VIVE_PRO_EYE_LEFT.central_window([1440, 1600], [720, 800]),
        );
        let (a, b) = (cut.axis_pixel(), vive.axis_pixel());
        assert!((a[0] * 2.0 - b[0]).abs() < 1e-3 && (a[1] * 2.0 - b[1]).abs() < 1e-3);
        let density = |g: &ImageGeometry| g.max_radians_per_pixel();
        assert!((density(&cut) - density(&vive)).abs() < 1e-9);
    }

    #[test]
    fn vive_field_of_view_is_about_110_degrees_and_asymmetric() {
        let g = vive();
        let h = angle_between([g.tan_left, 0.0], [g.tan_right, 0.0]).to_degrees();
        let v = angle_between([0.0, g.tan_up], [0.0, g.tan_down]).to_degrees();
        assert!((100.0..112.0).contains(&h), "horizontal {h}");
        assert!((105.0..115.0).contains(&v), "vertical {v}");
        // The axis sits right of centre in the left eye: more field towards the left.
        assert!(g.axis_pixel()[0] > 720.0 + 10.0);
    }

    #[test]
    fn a_degree_spans_more_pixels_at_the_edge_than_at_the_axis() {
        let g = vive();
        let axis = g.axis_pixel();
        let at = |px: f64| {
            let a = g.tan_of(px, axis[1]);
            let b = g.tan_of(px + 1.0, axis[1]);
            1.0 / angle_between(a, b).to_degrees()
        };
        let centre = at(axis[0]);
        let edge = at(2.0);
        assert!(
            edge > 1.8 * centre,
            "edge {edge} px/deg, centre {centre} px/deg"
        );
        // And never more radians per pixel than the bound says.
        assert!(1.0 / centre <= g.max_radians_per_pixel().to_degrees() * (1.0 + 1e-9));
    }

    #[test]
    fn small_angles_are_accurate() {
        let a = [0.3, -0.2];
        let d = 1e-7;
        let b = [0.3 + d, -0.2];
        let exact = d * (1.0f64 + 0.04).sqrt() / (1.0 + 0.09 + 0.04); // dθ for a step along x
        let got = angle_between(a, b);
        assert!((got - exact).abs() / exact < 1e-4, "{got} vs {exact}");
    }
}
