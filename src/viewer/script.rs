//! `--script FILE`: what a user would do, at given frames, so a run can be repeated (tests,
//! demos). One event a line, `FRAME EVENT ARGS...`, `#` starts a comment:
//!
//! ```text
//! 0 mouse 40 30        # the cursor at window pixel (40, 30): the gaze, if the mouse is the gaze source
//! 2 resize 120 80      # ask for a 120x80 window
//! 3 minimise           # also: restore, hide, show (hide/show unmap/map the window)
//! 6 key F              # a key press, by winit's KeyCode name or a letter/digit: F toggles foveation
//! 7 turn 10 -5         # look 10 degrees right and 5 degrees down, as a mouse drag would
//! 8 move 0 0 0.5       # fly 0.5 scene units right, up, forward (camera axes)
//! 9 screenshot a.png   # save the image shown after this frame (PNG + linear EXR beside it)
//! ```
//!
//! Frames count from 0 and include frames skipped while the window has no area, so a script
//! that minimises the window still reaches its `restore`.

use std::path::{Path, PathBuf};
use winit::keyboard::KeyCode;

/// One scripted action.
#[derive(Clone, Debug, PartialEq)]
pub enum ScriptEvent {
    /// The cursor moves to this window pixel.
    Mouse(f64, f64),
    Resize(u32, u32),
    Minimise,
    Restore,
    Hide,
    Show,
    Key(KeyCode),
    /// Degrees right and up.
    Turn(f32, f32),
    /// Scene units along the camera's right, up and forward axes.
    Move([f32; 3]),
    Screenshot(PathBuf),
}

/// Events sorted by frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    events: Vec<(u64, ScriptEvent)>,
}

impl Script {
    pub fn load(path: &Path) -> Result<Self, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read --script '{}': {e}", path.display()))?;
        Self::parse(&text).map_err(|e| format!("--script '{}': {e}", path.display()))
    }

    pub fn parse(text: &str) -> Result<Self, String> {
        let mut events = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let event = parse_line(line).map_err(|e| format!("line {}: '{line}': {e}", i + 1))?;
            events.push(event);
        }
        // Stable: events of one frame keep their order in the file.
        events.sort_by_key(|(frame, _)| *frame);
        Ok(Self { events })
    }

    /// Removes and returns the events of `frame` and of any earlier frame still pending.
    pub fn take_until(&mut self, frame: u64) -> Vec<ScriptEvent> {
        let n = self.events.partition_point(|(f, _)| *f <= frame);
        self.events.drain(..n).map(|(_, e)| e).collect()
    }

    pub fn is_empty(&self) -> bool {
        self.events.is_empty()
    }

    /// The frame of the last event, if any.
    pub fn last_frame(&self) -> Option<u64> {
        self.events.last().map(|(f, _)| *f)
    }
}

const USAGE: &str = "use FRAME followed by mouse X Y, resize W H, minimise, restore, hide, show, \
                     key NAME, turn RIGHT_DEG UP_DEG, move RIGHT UP FORWARD or screenshot FILE";

fn parse_line(line: &str) -> Result<(u64, ScriptEvent), String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let frame: u64 = words[0]
        .parse()
        .map_err(|_| format!("'{}' is not a frame number; {USAGE}", words[0]))?;
    let Some(&name) = words.get(1) else {
        return Err(format!("no event; {USAGE}"));
    };
    let args = &words[2..];
    let count = |n: usize| match args.len() == n {
        true => Ok(()),
        false => Err(format!(
            "{name} takes {n} argument(s), not {}; {USAGE}",
            args.len()
        )),
    };
    let num = |s: &str| -> Result<f64, String> {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{s}' is not a finite number"))
    };
    let size = |s: &str| -> Result<u32, String> {
        s.parse::<u32>()
            .ok()
            .filter(|v| (1..=16384).contains(v))
            .ok_or_else(|| format!("'{s}' is not a window size from 1 to 16384 pixels"))
    };
    let event = match name {
        "mouse" => {
            count(2)?;
            ScriptEvent::Mouse(num(args[0])?, num(args[1])?)
        }
        "resize" => {
            count(2)?;
            ScriptEvent::Resize(size(args[0])?, size(args[1])?)
        }
        "minimise" | "minimize" => {
            count(0)?;
            ScriptEvent::Minimise
        }
        "restore" => {
            count(0)?;
            ScriptEvent::Restore
        }
        "hide" => {
            count(0)?;
            ScriptEvent::Hide
        }
        "show" => {
            count(0)?;
            ScriptEvent::Show
        }
        "key" => {
            count(1)?;
            ScriptEvent::Key(
                key_code(args[0]).ok_or_else(|| format!("'{}' is not a key name", args[0]))?,
            )
        }
        "turn" => {
            count(2)?;
            ScriptEvent::Turn(num(args[0])? as f32, num(args[1])? as f32)
        }
        "move" => {
            count(3)?;
            ScriptEvent::Move([
                num(args[0])? as f32,
                num(args[1])? as f32,
                num(args[2])? as f32,
            ])
        }
        "screenshot" => {
            count(1)?;
            ScriptEvent::Screenshot(PathBuf::from(args[0]))
        }
        other => return Err(format!("unknown event '{other}'; {USAGE}")),
    };
    Ok((frame, event))
}

/// A key by winit's `KeyCode` name (`KeyF`, `Equal`, `F12`) or, for letters and digits, the
/// character itself (`f`, `3`); also `+` and `-`.
pub fn key_code(name: &str) -> Option<KeyCode> {
    use KeyCode::*;
    let letters = [
        KeyA, KeyB, KeyC, KeyD, KeyE, KeyF, KeyG, KeyH, KeyI, KeyJ, KeyK, KeyL, KeyM, KeyN, KeyO,
        KeyP, KeyQ, KeyR, KeyS, KeyT, KeyU, KeyV, KeyW, KeyX, KeyY, KeyZ,
    ];
    let digits = [
        Digit0, Digit1, Digit2, Digit3, Digit4, Digit5, Digit6, Digit7, Digit8, Digit9,
    ];
    let mut chars = name.chars();
    if let (Some(c), None) = (chars.next(), chars.next()) {
        let c = c.to_ascii_lowercase();
        return match c {
            'a'..='z' => Some(letters[(c as u8 - b'a') as usize]),
            '0'..='9' => Some(digits[(c as u8 - b'0') as usize]),
            '+' | '=' => Some(Equal),
            '-' => Some(Minus),
            _ => None,
        };
    }
    let named = [
        ("Escape", Escape),
        ("Space", Space),
        ("Tab", Tab),
        ("Equal", Equal),
        ("Minus", Minus),
        ("NumpadAdd", NumpadAdd),
        ("NumpadSubtract", NumpadSubtract),
        ("F12", F12),
    ];
    if let Some((_, code)) = named.iter().find(|(n, _)| n.eq_ignore_ascii_case(name)) {
        return Some(*code);
    }
    let rest = name
        .strip_prefix("Key")
        .or_else(|| name.strip_prefix("Digit"))?;
    key_code(rest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_event_in_frame_order() {
        let script = Script::parse(
            "# a comment\n5 screenshot out.png\n0 mouse 40 30.5 # trailing comment\n\
             2 resize 120 80\n3 minimise\n4 restore\n4 key f\n4 key KeyV\n1 turn 10 -5\n\
             1 move 0 0 0.5\n6 hide\n6 show\n",
        )
        .unwrap();
        let mut s = script.clone();
        assert_eq!(s.take_until(0), vec![ScriptEvent::Mouse(40.0, 30.5)]);
        assert_eq!(
            s.take_until(1),
            vec![
                ScriptEvent::Turn(10.0, -5.0),
                ScriptEvent::Move([0.0, 0.0, 0.5])
            ]
        );
        assert_eq!(
            s.take_until(4),
            vec![
                ScriptEvent::Resize(120, 80),
                ScriptEvent::Minimise,
                ScriptEvent::Restore,
                ScriptEvent::Key(KeyCode::KeyF),
                ScriptEvent::Key(KeyCode::KeyV),
            ]
        );
        assert_eq!(
            s.take_until(5),
            vec![ScriptEvent::Screenshot("out.png".into())]
        );
        assert_eq!(script.last_frame(), Some(6));
        assert_eq!(
            s.take_until(100),
            vec![ScriptEvent::Hide, ScriptEvent::Show]
        );
        assert!(s.is_empty());
    }

    #[test]
    fn bad_lines_say_which_and_why() {
        for (text, expect) in [
            ("x mouse 1 2", "not a frame number"),
            ("1", "no event"),
            ("1 mouse 1", "takes 2 argument(s)"),
            ("1 mouse 1 nan", "not a finite number"),
            ("1 resize 0 10", "window size"),
            ("1 key Hyper", "not a key name"),
            ("1 jump", "unknown event 'jump'"),
        ] {
            let e = Script::parse(&format!("\n{text}\n")).unwrap_err();
            assert!(e.contains("line 2") && e.contains(expect), "{text}: {e}");
        }
    }

    #[test]
    fn key_names() {
        assert_eq!(key_code("F"), Some(KeyCode::KeyF));
        assert_eq!(key_code("KeyF"), Some(KeyCode::KeyF));
        assert_eq!(key_code("Digit3"), Some(KeyCode::Digit3));
        assert_eq!(key_code("+"), Some(KeyCode::Equal));
        assert_eq!(key_code("escape"), Some(KeyCode::Escape));
        assert_eq!(key_code("F12"), Some(KeyCode::F12));
        assert_eq!(key_code("Key"), None);
    }
}
