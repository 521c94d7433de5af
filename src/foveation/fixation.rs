//! Where each eye looks, from one gaze ray (thesis §2.7, fig. 2.7). A headset reports the gaze
//! as a ray from the head (the cyclopean eye between the two); the eyes converge on the point
//! that ray meets in the scene, so the point is found first (the fixation) and then projected
//! into each eye with the eye's own pose and asymmetric field of view. The two gaze pixels
//! then differ by the parallax of that point: IPD / distance in tangent units. A ray that
//! meets nothing fixates at infinity, where both eyes see the same direction.
//!
//! Everything here is pure arithmetic in f64; whatever cannot be projected (a point behind or
//! beside an eye, NaN or ∞ input) comes back as `None` for the caller's fallback, never NaN.

use super::view::ImageGeometry;
use crate::scene::Camera;
use glam::{DVec3, Vec3};

/// What the eyes converge on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fixation {
    /// A point in the world (the gaze ray hit a surface).
    Point(DVec3),
    /// A direction at infinity (the gaze ray left the scene); unit length.
    Direction(DVec3),
}

/// The fixation of a gaze ray from `origin` along `dir` that hits a surface after
/// `hit_distance` (along the normalised `dir`), or nothing (`None`). `None` when the ray is
/// not usable: non-finite or zero `dir`, non-finite `origin`, or a distance that is negative
/// or NaN. An infinite distance is a miss.
pub fn fixate(origin: DVec3, dir: DVec3, hit_distance: Option<f64>) -> Option<Fixation> {
    let dir = dir.try_normalize()?;
    if !origin.is_finite() {
        return None;
    }
    match hit_distance {
        None => Some(Fixation::Direction(dir)),
        Some(t) if t == f64::INFINITY => Some(Fixation::Direction(dir)),
        Some(t) if t >= 0.0 => Some(Fixation::Point(origin + t * dir)),
        Some(_) => None,
    }
}

/// The fixation in an eye's tangent space (x right, y up, as `ImageGeometry` has it), or
/// `None` when it is behind the eye or on its plane, or the eye's pose is unusable.
pub fn project_tan(fixation: &Fixation, eye: &Camera) -> Option<[f64; 2]> {
    let f = eye.forward.as_dvec3().try_normalize()?;
    let r = f.cross(eye.up.as_dvec3()).try_normalize()?;
    let u = r.cross(f);
    let v = match fixation {
        Fixation::Point(p) => *p - eye.position.as_dvec3(),
        Fixation::Direction(d) => *d,
    };
    let z = v.dot(f);
    // On the eye's plane (or within the rounding of f32 pose vectors of it) the tangent is
    // meaningless: demand at least 1e-6 of the offset in depth, i.e. |tan| < 1e6, far beyond
    // any display's field of view (a 170° one has |tan| < 12).
    // Written so that NaN (an unusable pose) fails the test too.
    let in_front = z > 1e-6 * v.length();
    if !in_front {
        return None;
    }
    let t = [v.dot(r) / z, v.dot(u) / z];
    (t[0].is_finite() && t[1].is_finite()).then_some(t)
}

/// The fixation as a continuous pixel of the eye's image (possibly off the image), or `None`
/// as for [`project_tan`].
pub fn project(fixation: &Fixation, eye: &Camera, image: &ImageGeometry) -> Option<[f64; 2]> {
    project_tan(fixation, eye).map(|t| image.pixel_of(t))
}

/// Each eye's gaze in its tangent space, for a gaze ray from `origin` along `dir` traced with
/// `hit` (e.g. `CpuRaycaster::closest_hit`: distance along the normalised direction, or
/// `None` for a miss).
pub fn eye_tangents(
    hit: impl Fn(Vec3, Vec3) -> Option<f32>,
    origin: Vec3,
    dir: Vec3,
    eyes: &[Camera],
) -> Vec<Option<[f64; 2]>> {
    let fixation = fixate(
        origin.as_dvec3(),
        dir.as_dvec3(),
        hit(origin, dir).map(f64::from),
    );
    eyes.iter()
        .map(|eye| fixation.and_then(|f| project_tan(&f, eye)))
        .collect()
}

/// Each eye's gaze pixel for a gaze ray, as [`eye_tangents`] with each eye's image.
pub fn eye_gazes(
    hit: impl Fn(Vec3, Vec3) -> Option<f32>,
    origin: Vec3,
    dir: Vec3,
    eyes: &[(Camera, ImageGeometry)],
) -> Vec<Option<[f64; 2]>> {
    let cameras: Vec<Camera> = eyes.iter().map(|(c, _)| *c).collect();
    eye_tangents(hit, origin, dir, &cameras)
        .into_iter()
        .zip(eyes)
        .map(|(t, (_, image))| t.map(|t| image.pixel_of(t)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::EyeFov;

    const IPD: f64 = 0.063;

    /// A head at (1, 1.6, 2) looking along a tilted direction, and its two eyes IPD apart
    /// along its right vector, each with the Vive Pro Eye's field of view.
    fn head() -> (Camera, [(Camera, ImageGeometry); 2]) {
        let fov = |c: Camera, f: EyeFov| Camera {
            angle_left: f.left,
            angle_right: f.right,
            angle_up: f.up,
            angle_down: f.down,
            ..c
        };
        let centre = Camera {
            position: Vec3::new(1.0, 1.6, 2.0),
            forward: Vec3::new(0.3, -0.2, -1.0).normalize(),
            up: Vec3::Y,
            angle_left: 0.0,
            angle_right: 0.0,
            angle_up: 0.0,
            angle_down: 0.0,
        };
        let (r, _, _) = centre.basis();
        let eye = |side: f32, f: EyeFov| {
            let c = Camera {
                position: centre.position + r * (side * IPD as f32 * 0.5),
                ..centre
            };
            (fov(c, f), ImageGeometry::new(1440, 1600, f))
        };
        (
            centre,
            [
                eye(-1.0, EyeFov::VIVE_PRO_EYE_LEFT),
                eye(1.0, EyeFov::VIVE_PRO_EYE_RIGHT),
            ],
        )
    }

    fn near(a: [f64; 2], b: [f64; 2], tol: f64) -> bool {
        (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
    }

    #[test]
    fn straight_ahead_at_infinity_is_the_axis_pixel_in_both_eyes() {
        let (centre, eyes) = head();
        let miss = |_: Vec3, _: Vec3| None;
        let got = eye_gazes(miss, centre.position, centre.forward, &eyes);
        for ((_, image), g) in eyes.iter().zip(got) {
            let g = g.unwrap();
            // f32 pose vectors: about 1e-7 in tangent, 1e-4 pixels.
            assert!(
                near(g, image.axis_pixel(), 1e-3),
                "{g:?} {:?}",
                image.axis_pixel()
            );
        }
    }

    #[test]
    fn a_direction_lands_on_the_pixel_of_its_tangent() {
        let (centre, eyes) = head();
        let (r, u, f) = centre.basis();
        let dir = f + 0.5 * r - 0.25 * u;
        let got = eye_gazes(|_, _| None, centre.position, dir, &eyes);
        for ((_, image), g) in eyes.iter().zip(got) {
            let want = image.pixel_of([0.5, -0.25]);
            assert!(near(g.unwrap(), want, 1e-3), "{g:?} {want:?}");
        }
        // The same direction through `fixate` and `project` alone.
        let fix = fixate(DVec3::ZERO, dir.as_dvec3(), None).unwrap();
        let t = project_tan(&fix, &eyes[0].0).unwrap();
        assert!(near(t, [0.5, -0.25], 1e-6), "{t:?}");
    }

    #[test]
    fn a_near_point_shows_the_parallax_of_the_eyes() {
        let (centre, eyes) = head();
        for d in [0.5f64, 2.0, 10.0] {
            let wall = move |_: Vec3, _: Vec3| Some(d as f32);
            let got = eye_gazes(wall, centre.position, centre.forward, &eyes);
            // The point is IPD/2 right of the left eye and IPD/2 left of the right one, d ahead.
            let half = IPD / (2.0 * d);
            let (left, right) = (got[0].unwrap(), got[1].unwrap());
            let (li, ri) = (&eyes[0].1, &eyes[1].1);
            assert!(near(left, li.pixel_of([half, 0.0]), 2e-3), "{d}: {left:?}");
            assert!(
                near(right, ri.pixel_of([-half, 0.0]), 2e-3),
                "{d}: {right:?}"
            );
            // In pixels from each axis: ±(IPD / 2d) × pixels per tangent unit.
            let px_per_tan = |i: &ImageGeometry| 1440.0 / (i.tan_right - i.tan_left);
            let dl = left[0] - li.axis_pixel()[0];
            let dr = right[0] - ri.axis_pixel()[0];
            assert!((dl - half * px_per_tan(li)).abs() < 2e-3, "{d}: {dl}");
            assert!((dr + half * px_per_tan(ri)).abs() < 2e-3, "{d}: {dr}");
            // The disparity in tangent is IPD / d.
            let tl = project_tan(
                &fixate(
                    centre.position.as_dvec3(),
                    centre.forward.as_dvec3(),
                    Some(d),
                )
                .unwrap(),
                &eyes[0].0,
            )
            .unwrap();
            let tr = project_tan(
                &fixate(
                    centre.position.as_dvec3(),
                    centre.forward.as_dvec3(),
                    Some(d),
                )
                .unwrap(),
                &eyes[1].0,
            )
            .unwrap();
            assert!(((tl[0] - tr[0]) - IPD / d).abs() < 1e-6, "{d}");
        }
    }

    #[test]
    fn points_behind_or_beside_an_eye_do_not_project() {
        let (centre, eyes) = head();
        let eye = &eyes[0].0;
        let f = eye.forward.as_dvec3();
        let p = eye.position.as_dvec3();
        let (r, _, _) = eye.basis();
        for point in [p - f, p + r.as_dvec3(), p] {
            assert_eq!(project_tan(&Fixation::Point(point), eye), None, "{point}");
        }
        assert_eq!(project_tan(&Fixation::Direction(-f), eye), None);
        // Looking backwards from the head: the hit is behind both eyes.
        let back = eye_gazes(|_, _| Some(3.0), centre.position, -centre.forward, &eyes);
        assert_eq!(back, vec![None, None]);
    }

    #[test]
    fn nan_and_infinite_input_give_no_projection() {
        let (centre, eyes) = head();
        let o = centre.position.as_dvec3();
        let d = centre.forward.as_dvec3();
        assert_eq!(fixate(o, DVec3::new(f64::NAN, 0.0, 1.0), None), None);
        assert_eq!(fixate(o, DVec3::ZERO, None), None);
        assert_eq!(fixate(DVec3::splat(f64::INFINITY), d, Some(1.0)), None);
        assert_eq!(fixate(o, d, Some(f64::NAN)), None);
        assert_eq!(fixate(o, d, Some(-1.0)), None);
        // An infinite hit distance is a miss: the direction, not a point at infinity.
        assert_eq!(
            fixate(o, d, Some(f64::INFINITY)),
            Some(Fixation::Direction(d.normalize()))
        );
        let nan = Vec3::new(f32::NAN, 0.0, 0.0);
        assert_eq!(
            eye_gazes(|_, _| Some(1.0), nan, centre.forward, &eyes),
            vec![None, None]
        );
        assert_eq!(
            eye_gazes(|_, _| None, centre.position, nan, &eyes),
            vec![None, None]
        );
        let broken = Camera {
            forward: Vec3::ZERO,
            ..eyes[0].0
        };
        assert_eq!(project_tan(&Fixation::Direction(d), &broken), None);
        let huge = Fixation::Point(o + DVec3::new(1e300, 0.0, 0.0));
        assert!(project_tan(&huge, &eyes[0].0).is_none_or(|t| t[0].is_finite()));
    }
}
