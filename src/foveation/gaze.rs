//! Gaze points in an eye's image, and what `--gaze` asks for. A gaze that is not a finite
//! point on the image never reaches the GPU: it is made safe here, and the caller is told.

use super::view::ImageGeometry;

/// Where an eye looks, as asked for on the command line (or by a gaze source).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gaze {
    /// Straight ahead along the view axis (not the image centre when the field of view is
    /// asymmetric, as in a headset).
    Forward,
    /// The top-left corner of the image, as in the thesis' "corner" tests (§3.1.1).
    Corner,
    /// A point in continuous pixel coordinates of the eye's image.
    Pixel(f64, f64),
}

/// `--gaze`: one gaze for both eyes, or `LEFT:RIGHT`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GazeChoice {
    pub left: Gaze,
    pub right: Gaze,
}

/// What had to be done to a gaze to make it usable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GazeFix {
    None,
    /// NaN or infinite coordinates: the view axis is used instead.
    NotFinite,
    /// Off the image: moved to the nearest point on its border.
    Clamped,
}

impl Gaze {
    fn parse_one(text: &str) -> Result<Self, String> {
        match text.trim() {
            "forward" => Ok(Gaze::Forward),
            "corner" => Ok(Gaze::Corner),
            other => {
                let parts: Vec<&str> = other.split(',').collect();
                let [x, y] = parts[..] else {
                    return Err(format!(
                        "gaze '{other}' is not understood: use forward, corner or X,Y in pixels (e.g. 320,240)"
                    ));
                };
                let num = |s: &str| {
                    s.trim().parse::<f64>().map_err(|_| {
                        format!("gaze '{other}': '{s}' is not a number; use X,Y in pixels (e.g. 320,240)")
                    })
                };
                Ok(Gaze::Pixel(num(x)?, num(y)?))
            }
        }
    }

    /// The gaze as a finite point on the image, and whether it had to be fixed. NaN or
    /// infinite input falls back to the view axis; a point off the image is clamped to its
    /// border (the layers then reach in from the edge, and rays off the image are not traced).
    pub fn resolve(self, image: &ImageGeometry) -> ([f64; 2], GazeFix) {
        let (w, h) = (image.width as f64, image.height as f64);
        let axis = image.axis_pixel();
        let axis = [axis[0].clamp(0.0, w), axis[1].clamp(0.0, h)];
        let (x, y) = match self {
            Gaze::Forward => return (axis, GazeFix::None),
            // The centre of the top-left pixel: the corner itself lies on no pixel.
            Gaze::Corner => return ([0.5, 0.5], GazeFix::None),
            Gaze::Pixel(x, y) => (x, y),
        };
        if !x.is_finite() || !y.is_finite() {
            return (axis, GazeFix::NotFinite);
        }
        let clamped = [x.clamp(0.0, w), y.clamp(0.0, h)];
        let fix = if clamped == [x, y] {
            GazeFix::None
        } else {
            GazeFix::Clamped
        };
        (clamped, fix)
    }
}

impl std::str::FromStr for GazeChoice {
    type Err = String;
    fn from_str(text: &str) -> Result<Self, String> {
        match text.split_once(':') {
            Some((l, r)) => Ok(Self {
                left: Gaze::parse_one(l)?,
                right: Gaze::parse_one(r)?,
            }),
            None => {
                let g = Gaze::parse_one(text)?;
                Ok(Self { left: g, right: g })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::view::EyeFov;

    fn image() -> ImageGeometry {
        ImageGeometry::new(1440, 1600, EyeFov::VIVE_PRO_EYE_LEFT)
    }

    #[test]
    fn parses_names_points_and_per_eye_pairs() {
        let both: GazeChoice = "corner".parse().unwrap();
        assert_eq!((both.left, both.right), (Gaze::Corner, Gaze::Corner));
        let pair: GazeChoice = "forward: 10.5,20".parse().unwrap();
        assert_eq!(pair.left, Gaze::Forward);
        assert_eq!(pair.right, Gaze::Pixel(10.5, 20.0));
        for bad in ["", "up", "1,2,3", "x,2", "1;2"] {
            let e = bad.parse::<GazeChoice>().unwrap_err();
            assert!(
                e.contains("forward, corner or X,Y") || e.contains("not a number"),
                "{e}"
            );
        }
    }

    #[test]
    fn forward_is_the_view_axis_not_the_image_centre() {
        let g = image();
        let (p, fix) = Gaze::Forward.resolve(&g);
        assert_eq!(fix, GazeFix::None);
        let t = g.tan_of(p[0], p[1]);
        assert!(t[0].abs() < 1e-12 && t[1].abs() < 1e-12);
        assert!((p[0] - 720.0).abs() > 10.0);
    }

    #[test]
    fn bad_gazes_become_safe_points() {
        let g = image();
        for (x, y) in [
            (f64::NAN, 3.0),
            (1.0, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NAN),
        ] {
            let (p, fix) = Gaze::Pixel(x, y).resolve(&g);
            assert_eq!(fix, GazeFix::NotFinite);
            assert_eq!(p, Gaze::Forward.resolve(&g).0);
        }
        let (p, fix) = Gaze::Pixel(-50.0, 1e30).resolve(&g);
        assert_eq!(fix, GazeFix::Clamped);
        assert_eq!(p, [0.0, 1600.0]);
        let (p, fix) = Gaze::Pixel(100.0, 200.0).resolve(&g);
        assert_eq!((p, fix), ([100.0, 200.0], GazeFix::None));
    }
}
