//! What to do with a bad gaze sample. Eye trackers drop out (blinks, the headset slipping,
//! SteamVR listing eye gaze it does not deliver) and a dropped sample must never cost a
//! frame: the last good gaze is held for a short time (a blink lasts 0.1–0.4 s, so holding
//! bridges most of them without the fovea jumping), then the view falls back to the centre
//! (the view axis). Each change of state is logged once, not every frame.
//!
//! Samples are per-eye gaze points in tangent space (x right, y up; see `view`), so the
//! filter knows nothing of resolutions and works for mouse, trace and headset alike.

use super::gaze::Gaze;
use super::view::ImageGeometry;

/// How long a lost gaze is held before falling back to the centre, in seconds.
pub const DEFAULT_HOLD_S: f64 = 0.2;

/// Where the gaze in use came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GazeStatus {
    /// This frame's sample was good.
    Tracked,
    /// The last good sample, `age_s` seconds old (at most the hold time).
    Held { age_s: f64 },
    /// No good sample for longer than the hold time (or none yet): the view axis.
    Centre,
}

impl GazeStatus {
    /// The status as a gaze trace writes it.
    pub fn name(self) -> &'static str {
        match self {
            GazeStatus::Tracked => "tracked",
            GazeStatus::Held { .. } => "held",
            GazeStatus::Centre => "centre",
        }
    }
}

/// The gaze to use this frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FilteredGaze {
    /// Per-eye tangent-space gaze; `None` for the centre.
    pub tangents: Option<Vec<[f64; 2]>>,
    pub status: GazeStatus,
}

impl FilteredGaze {
    /// Each eye's gaze for a frame request: its tangent point as a pixel of its image, or
    /// the view axis.
    pub fn gazes(&self, images: &[ImageGeometry]) -> Vec<Gaze> {
        images
            .iter()
            .enumerate()
            .map(|(e, image)| {
                // A single tangent serves every eye (a mono sample).
                match self.tangents.as_ref().and_then(|t| t.get(e).or(t.last())) {
                    Some(t) => {
                        let p = image.pixel_of(*t);
                        Gaze::Pixel(p[0], p[1])
                    }
                    None => Gaze::Forward,
                }
            })
            .collect()
    }
}

/// Why a sample was not used (for the log).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Bad {
    Untracked,
    NotFinite,
    OffScreen,
    WrongEyeCount,
}

impl Bad {
    fn describe(self) -> &'static str {
        match self {
            Bad::Untracked => "the tracker reports no gaze",
            Bad::NotFinite => "the gaze is NaN or infinite",
            Bad::OffScreen => "the gaze is off the image",
            Bad::WrongEyeCount => "the sample has the wrong number of eyes",
        }
    }
}

/// The state machine: feed it every frame's sample, use what it returns.
#[derive(Clone, Debug)]
pub struct GazeFilter {
    hold_s: f64,
    /// Time and tangents of the last good sample.
    last_good: Option<(f64, Vec<[f64; 2]>)>,
    /// The status of the previous frame, without its age: logging happens when it changes.
    previous: Kind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Tracked,
    Held,
    Centre,
}

impl Default for GazeFilter {
    fn default() -> Self {
        Self::new(DEFAULT_HOLD_S)
    }
}

impl GazeFilter {
    /// A filter that holds a lost gaze for `hold_s` seconds (0: fall back at once). Starts at
    /// the centre, as nothing has been tracked yet.
    pub fn new(hold_s: f64) -> Self {
        Self {
            hold_s: if hold_s.is_finite() {
                hold_s.max(0.0)
            } else {
                0.0
            },
            last_good: None,
            previous: Kind::Centre,
        }
    }

    /// The gaze to use at `time_s` (seconds, any origin, non-decreasing) given this frame's
    /// `sample`: one tangent-space point per eye of `images`, or `None` when the tracker has
    /// none. A sample with a NaN or infinite coordinate, or a point off its eye's image, is
    /// as bad as none.
    pub fn update(
        &mut self,
        time_s: f64,
        sample: Option<&[[f64; 2]]>,
        images: &[ImageGeometry],
    ) -> FilteredGaze {
        match check(sample, images) {
            Ok(tangents) => {
                self.last_good = Some((time_s, tangents.to_vec()));
                self.log(Kind::Tracked, None);
                FilteredGaze {
                    tangents: Some(tangents.to_vec()),
                    status: GazeStatus::Tracked,
                }
            }
            Err(why) => {
                // NaN times (or a clock that jumped) make the age NaN: not within the hold.
                let held = self.last_good.as_ref().and_then(|(t, tangents)| {
                    let age = time_s - t;
                    (age <= self.hold_s).then(|| (age.max(0.0), tangents.clone()))
                });
                match held {
                    Some((age_s, tangents)) => {
                        self.log(Kind::Held, Some(why));
                        FilteredGaze {
                            tangents: Some(tangents),
                            status: GazeStatus::Held { age_s },
                        }
                    }
                    None => {
                        self.log(Kind::Centre, Some(why));
                        FilteredGaze {
                            tangents: None,
                            status: GazeStatus::Centre,
                        }
                    }
                }
            }
        }
    }

    fn log(&mut self, now: Kind, why: Option<Bad>) {
        if now == self.previous {
            return;
        }
        let why = why.map_or("", Bad::describe);
        match now {
            Kind::Tracked => tracing::info!("gaze tracked: foveating around it"),
            Kind::Held => tracing::warn!(
                "gaze lost ({why}): holding the last good gaze for up to {} s",
                self.hold_s
            ),
            Kind::Centre => tracing::warn!(
                "no good gaze ({why}) for more than {} s: foveating around the view axis until \
                 the gaze is tracked again",
                self.hold_s
            ),
        }
        self.previous = now;
    }
}

fn check<'a>(
    sample: Option<&'a [[f64; 2]]>,
    images: &[ImageGeometry],
) -> Result<&'a [[f64; 2]], Bad> {
    let tangents = sample.ok_or(Bad::Untracked)?;
    if tangents.len() != images.len() || tangents.is_empty() {
        return Err(Bad::WrongEyeCount);
    }
    if tangents.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Bad::NotFinite);
    }
    let on_image = |t: &[f64; 2], i: &ImageGeometry| {
        (i.tan_left..=i.tan_right).contains(&t[0]) && (i.tan_down..=i.tan_up).contains(&t[1])
    };
    if !tangents.iter().zip(images).all(|(t, i)| on_image(t, i)) {
        return Err(Bad::OffScreen);
    }
    Ok(tangents)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::foveation::EyeFov;
    use std::io::Write;
    use std::sync::{Arc, Mutex};

    fn images() -> Vec<ImageGeometry> {
        vec![
            ImageGeometry::new(1440, 1600, EyeFov::VIVE_PRO_EYE_LEFT),
            ImageGeometry::new(1440, 1600, EyeFov::VIVE_PRO_EYE_RIGHT),
        ]
    }

    const GOOD: [[f64; 2]; 2] = [[0.1, -0.2], [0.05, -0.2]];
    const OTHER: [[f64; 2]; 2] = [[-0.3, 0.4], [-0.35, 0.4]];

    #[test]
    fn a_lost_gaze_is_held_exactly_up_to_the_limit_then_centred() {
        // Powers of two: the ages below are exact, so the boundary is tested exactly.
        let mut f = GazeFilter::new(0.25);
        let i = images();
        assert_eq!(f.update(1.0, Some(&GOOD), &i).status, GazeStatus::Tracked);
        let held = f.update(1.125, None, &i);
        assert_eq!(held.status, GazeStatus::Held { age_s: 0.125 });
        assert_eq!(held.tangents.as_deref(), Some(&GOOD[..]));
        let at_limit = f.update(1.25, None, &i);
        assert_eq!(at_limit.status, GazeStatus::Held { age_s: 0.25 });
        let past = f.update(1.25 + 1e-9, None, &i);
        assert_eq!(past.status, GazeStatus::Centre);
        assert_eq!(past.tangents, None);
        assert_eq!(past.gazes(&i), vec![Gaze::Forward, Gaze::Forward]);
        // Still centred later, whatever comes in that is bad.
        assert_eq!(
            f.update(2.0, Some(&[[f64::NAN, 0.0]; 2]), &i).status,
            GazeStatus::Centre
        );
    }

    #[test]
    fn the_next_good_sample_recovers_at_once() {
        let mut f = GazeFilter::default();
        let i = images();
        f.update(0.0, Some(&GOOD), &i);
        f.update(5.0, None, &i);
        let back = f.update(5.01, Some(&OTHER), &i);
        assert_eq!(back.status, GazeStatus::Tracked);
        assert_eq!(back.tangents.as_deref(), Some(&OTHER[..]));
        // While held, a good sample also wins immediately.
        f.update(5.02, None, &i);
        assert_eq!(f.update(5.03, Some(&GOOD), &i).status, GazeStatus::Tracked);
    }

    #[test]
    fn nan_infinite_off_screen_and_miscounted_samples_are_bad() {
        let i = images();
        let bad: [&[[f64; 2]]; 5] = [
            &[[f64::NAN, 0.0], [0.0, 0.0]],
            &[[0.0, 0.0], [0.0, f64::INFINITY]],
            &[[0.0, 0.0], [i[1].tan_right + 1e-9, 0.0]],
            &[[0.0, i[0].tan_up * 1.01], [0.0, 0.0]],
            &[[0.0, 0.0]],
        ];
        for sample in bad {
            let mut f = GazeFilter::new(0.2);
            f.update(0.0, Some(&GOOD), &i);
            let out = f.update(0.1, Some(sample), &i);
            assert!(matches!(out.status, GazeStatus::Held { .. }), "{sample:?}");
            assert_eq!(out.tangents.as_deref(), Some(&GOOD[..]), "{sample:?}");
        }
        // The image's own edges are on it.
        let mut f = GazeFilter::new(0.2);
        let edge = [
            [i[0].tan_left, i[0].tan_down],
            [i[1].tan_right, i[1].tan_up],
        ];
        assert_eq!(f.update(0.0, Some(&edge), &i).status, GazeStatus::Tracked);
    }

    #[test]
    fn nothing_tracked_yet_is_the_centre_and_bad_times_never_hold() {
        let i = images();
        let mut f = GazeFilter::default();
        assert_eq!(f.update(0.0, None, &i).status, GazeStatus::Centre);
        f.update(1.0, Some(&GOOD), &i);
        assert_eq!(f.update(f64::NAN, None, &i).status, GazeStatus::Centre);
        // A clock that steps back counts as no time passed, not a negative age.
        f.update(3.0, Some(&GOOD), &i);
        assert_eq!(
            f.update(2.5, None, &i).status,
            GazeStatus::Held { age_s: 0.0 }
        );
        // A nonsense hold time means no hold.
        let mut f = GazeFilter::new(f64::NAN);
        f.update(0.0, Some(&GOOD), &i);
        assert_eq!(
            f.update(0.0, None, &i).status,
            GazeStatus::Held { age_s: 0.0 }
        );
        assert_eq!(f.update(0.001, None, &i).status, GazeStatus::Centre);
    }

    #[test]
    fn pixels_are_each_eyes_own() {
        let i = images();
        let mut f = GazeFilter::default();
        let out = f.update(0.0, Some(&GOOD), &i);
        let g = out.gazes(&i);
        for e in 0..2 {
            let p = i[e].pixel_of(GOOD[e]);
            assert_eq!(g[e], Gaze::Pixel(p[0], p[1]));
        }
    }

    /// Collects formatted log lines.
    #[derive(Clone, Default)]
    struct Lines(Arc<Mutex<Vec<u8>>>);
    impl Write for Lines {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn each_transition_is_logged_once() {
        let lines = Lines::default();
        let writer = lines.clone();
        let subscriber = tracing_subscriber::fmt()
            .with_writer(move || writer.clone())
            .with_ansi(false)
            .with_max_level(tracing::Level::INFO)
            .finish();
        tracing::subscriber::with_default(subscriber, || {
            let i = images();
            let mut f = GazeFilter::new(0.25);
            for k in 0..10 {
                f.update(k as f64 * 0.01, Some(&GOOD), &i);
            }
            for k in 10..100 {
                f.update(k as f64 * 0.01, None, &i);
            }
            f.update(1.0, Some(&GOOD), &i);
        });
        let text = String::from_utf8(lines.0.lock().unwrap().clone()).unwrap();
        let count = |what: &str| text.lines().filter(|l| l.contains(what)).count();
        // centre → tracked, tracked → held, held → centre, centre → tracked.
        assert_eq!(count("gaze tracked"), 2, "{text}");
        assert_eq!(count("holding the last good gaze"), 1, "{text}");
        assert_eq!(count("foveating around the view axis"), 1, "{text}");
        assert!(text.contains("reports no gaze"), "{text}");
    }
}
