//! The scripted eye tracker: gaze keyframes by frame index.
//!
//! One keyframe per line (or per `;`-separated item): `FRAME YAW_DEG PITCH_DEG [STATUS]`,
//! yaw positive to the right, pitch positive up, STATUS one of `valid` (default),
//! `invalid` (no pose at all) or `untracked` (a pose flagged VALID but not TRACKED, like a
//! tracker holding its last estimate). `#` starts a comment. The gaze holds the last
//! keyframe at or before the current frame; before the first keyframe it looks straight
//! ahead with a valid sample, so an empty script means "always forward".

use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleStatus {
    Valid,
    Invalid,
    Untracked,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GazeKeyframe {
    pub frame: u64,
    pub yaw_deg: f32,
    pub pitch_deg: f32,
    pub status: SampleStatus,
}

/// Keyframes sorted by frame, at most one per frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GazeScript {
    keyframes: Vec<GazeKeyframe>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct GazeScriptError {
    /// 1-based index of the offending line or `;` item.
    pub item: usize,
    pub text: String,
    pub reason: String,
}

impl fmt::Display for GazeScriptError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "gaze script item {} ({:?}): {}; expected `FRAME YAW_DEG PITCH_DEG [valid|invalid|untracked]`",
            self.item, self.text, self.reason
        )
    }
}

impl std::error::Error for GazeScriptError {}

impl GazeScript {
    /// Parses a script; items are separated by newlines or `;`.
    pub fn parse(text: &str) -> Result<Self, GazeScriptError> {
        let mut keyframes: Vec<GazeKeyframe> = Vec::new();
        for (index, raw) in text.split(['\n', ';']).enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let fail = |reason: &str| GazeScriptError {
                item: index + 1,
                text: raw.trim().to_string(),
                reason: reason.to_string(),
            };
            let fields: Vec<&str> = line.split_whitespace().collect();
            if !(3..=4).contains(&fields.len()) {
                return Err(fail("wrong number of fields"));
            }
            let frame: u64 = fields[0]
                .parse()
                .map_err(|_| fail("FRAME is not a non-negative integer"))?;
            let angle = |s: &str, what: &str, limit: f32| -> Result<f32, GazeScriptError> {
                let v: f32 = s
                    .parse()
                    .map_err(|_| fail(&format!("{what} is not a number")))?;
                if !v.is_finite() || v.abs() > limit {
                    return Err(fail(&format!("{what} must be within ±{limit} degrees")));
                }
                Ok(v)
            };
            let yaw_deg = angle(fields[1], "YAW_DEG", 180.0)?;
            let pitch_deg = angle(fields[2], "PITCH_DEG", 90.0)?;
            let status = match fields.get(3).copied() {
                None | Some("valid") => SampleStatus::Valid,
                Some("invalid") => SampleStatus::Invalid,
                Some("untracked") => SampleStatus::Untracked,
                Some(_) => return Err(fail("status must be valid, invalid or untracked")),
            };
            if keyframes.iter().any(|k| k.frame == frame) {
                return Err(fail("a keyframe for this frame was already given"));
            }
            keyframes.push(GazeKeyframe {
                frame,
                yaw_deg,
                pitch_deg,
                status,
            });
        }
        keyframes.sort_by_key(|k| k.frame);
        Ok(Self { keyframes })
    }

    pub fn keyframes(&self) -> &[GazeKeyframe] {
        &self.keyframes
    }

    /// The sample in effect at `frame`: the last keyframe at or before it.
    pub fn sample(&self, frame: u64) -> GazeKeyframe {
        let after = self.keyframes.partition_point(|k| k.frame <= frame);
        match after.checked_sub(1) {
            Some(i) => self.keyframes[i],
            None => GazeKeyframe {
                frame: 0,
                yaw_deg: 0.0,
                pitch_deg: 0.0,
                status: SampleStatus::Valid,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_lines_semicolons_comments_and_statuses() {
        let s =
            GazeScript::parse("# header\n0 0 0\n5 10 -5 invalid # blink\n; 8 -20.5 3 untracked")
                .unwrap();
        assert_eq!(s.keyframes().len(), 3);
        assert_eq!(s.keyframes()[1].status, SampleStatus::Invalid);
        assert_eq!(s.keyframes()[2].yaw_deg, -20.5);
        assert_eq!(s.keyframes()[2].status, SampleStatus::Untracked);
    }

    #[test]
    fn holds_last_keyframe_at_or_before_frame() {
        let s = GazeScript::parse("10 30 0; 2 -10 5").unwrap();
        // Before the first keyframe: straight ahead, valid.
        assert_eq!(s.sample(0).yaw_deg, 0.0);
        assert_eq!(s.sample(0).status, SampleStatus::Valid);
        assert_eq!(s.sample(2).yaw_deg, -10.0);
        assert_eq!(s.sample(9).pitch_deg, 5.0);
        assert_eq!(s.sample(10).yaw_deg, 30.0);
        assert_eq!(s.sample(1_000_000).yaw_deg, 30.0);
    }

    #[test]
    fn empty_script_looks_forward() {
        let s = GazeScript::parse("  \n# only a comment\n").unwrap();
        assert!(s.keyframes().is_empty());
        assert_eq!(s.sample(42).status, SampleStatus::Valid);
    }

    #[test]
    fn rejects_malformed_items_with_their_position() {
        for (text, item) in [
            ("0 0", 1),
            ("0 0 0\n-1 0 0", 2),
            ("0 x 0", 1),
            ("0 0 95", 1),
            ("0 200 0", 1),
            ("0 0 0 blinking", 1),
            ("0 0 0; 0 1 1", 2),
            ("0 NaN 0", 1),
            ("0 0 0 valid extra", 1),
        ] {
            let err = GazeScript::parse(text).unwrap_err();
            assert_eq!(err.item, item, "{text}: {err}");
        }
    }
}
