//! The window title: what is shown and what it costs (GPU ms per pass, fps, rays per frame).

use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// Frames per second over the last second of wall-clock time.
#[derive(Default)]
pub struct FrameRate {
    times: VecDeque<Instant>,
}

/// The window fps is averaged over.
const FPS_WINDOW: Duration = Duration::from_secs(1);

impl FrameRate {
    pub fn frame(&mut self, now: Instant) {
        self.times.push_back(now);
        while self
            .times
            .front()
            .is_some_and(|t| now.duration_since(*t) > FPS_WINDOW)
            && self.times.len() > 2
        {
            self.times.pop_front();
        }
    }

    pub fn fps(&self) -> f64 {
        match (self.times.front(), self.times.back()) {
            (Some(a), Some(b)) if self.times.len() >= 2 && b > a => {
                (self.times.len() - 1) as f64 / b.duration_since(*a).as_secs_f64()
            }
            _ => 0.0,
        }
    }
}

/// GPU milliseconds per kind of pass ("plan", "trace", "resolve", "accumulate"), summed over
/// eyes ("left trace" and "right trace" are both "trace") and over the frames of a view
/// (the regular frame of the difference view), in the order first seen.
pub fn passes_by_kind<'a>(passes: impl Iterator<Item = (&'a str, f64)>) -> Vec<(String, f64)> {
    let mut kinds: Vec<(String, f64)> = Vec::new();
    for (name, ms) in passes {
        let kind = name.rsplit(' ').next().unwrap_or(name);
        match kinds.iter_mut().find(|(k, _)| k == kind) {
            Some((_, total)) => *total += ms,
            None => kinds.push((kind.to_string(), ms)),
        }
    }
    kinds
}

/// Everything the title shows.
pub struct TitleInfo<'a> {
    pub scene: &'a str,
    /// "thesis", "wide-fovea", … or "off".
    pub foveation: &'a str,
    pub spp: &'a str,
    pub view: &'a str,
    pub accumulated: u32,
    pub passes: &'a [(String, f64)],
    pub fps: f64,
    pub rays: u64,
}

pub fn title(t: &TitleInfo) -> String {
    let gpu: f64 = t.passes.iter().map(|(_, ms)| ms).sum();
    let passes: Vec<String> = t
        .passes
        .iter()
        .map(|(name, ms)| format!("{name} {ms:.2}"))
        .collect();
    format!(
        "fovea view | {} | foveation {} | {} spp | view: {} | {} frame(s) accumulated | GPU {:.2} ms ({}) | {:.1} fps | {:.2} Mrays/frame",
        t.scene,
        t.foveation,
        t.spp,
        t.view,
        t.accumulated,
        gpu,
        passes.join(", "),
        t.fps,
        t.rays as f64 * 1e-6
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_are_summed_over_eyes_in_first_seen_order() {
        let passes = [
            ("left trace", 2.0),
            ("left merge", 0.5),
            ("right trace", 3.0),
            ("right merge", 0.25),
            ("accumulate", 0.125),
        ];
        assert_eq!(
            passes_by_kind(passes.into_iter()),
            vec![
                ("trace".to_string(), 5.0),
                ("merge".to_string(), 0.75),
                ("accumulate".to_string(), 0.125)
            ]
        );
    }

    #[test]
    fn fps_counts_intervals_over_the_last_second() {
        let mut rate = FrameRate::default();
        let t0 = Instant::now();
        assert_eq!(rate.fps(), 0.0);
        for i in 0..=20 {
            rate.frame(t0 + Duration::from_millis(100 * i));
        }
        // The last second holds 11 frames, 10 intervals of 0.1 s.
        assert!((rate.fps() - 10.0).abs() < 1e-9, "{}", rate.fps());
    }

    #[test]
    fn title_has_every_number() {
        let passes = vec![("trace".to_string(), 3.0), ("merge".to_string(), 0.5)];
        let t = title(&TitleInfo {
            scene: "cornell",
            foveation: "thesis",
            spp: "4",
            view: "image",
            accumulated: 12,
            passes: &passes,
            fps: 14.24,
            rays: 1_234_567,
        });
        for part in [
            "cornell",
            "foveation thesis",
            "4 spp",
            "12 frame(s)",
            "GPU 3.50 ms (trace 3.00, merge 0.50)",
            "14.2 fps",
            "1.23 Mrays/frame",
        ] {
            assert!(t.contains(part), "{part} in {t}");
        }
    }
}
