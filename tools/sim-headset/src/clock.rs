//! The headset's clock: a 90 Hz display, an eye tracker sampling at 120 Hz, and a compositor
//! that may need more than one display period per frame.
//!
//! Two clocks, chosen by `SIM_HEADSET_REALTIME`:
//! - *virtual* (the default, for tests on a CPU driver): the app is always on time. Frame
//!   `n`'s display time is `1 s + n × period × compositor periods`; `xrWaitFrame` returns at
//!   once and the clock then reads two display periods before that display time, moving on
//!   with real time from there for at most one period (the app's time to render): a gaze
//!   located 0.1 ms after `xrWaitFrame` comes from the tracker's last sample before that
//!   moment, and a frame that took longer on the CPU is shown on time all the same.
//! - *real*: runtime time is real time since the session was created (plus an offset that
//!   puts the first display at about 1 s); `xrWaitFrame` sleeps until two periods before the
//!   next display slot the compositor can take, and a late app gets a later display time
//!   (the frames in between are missed).

use std::time::{Duration, Instant};

/// 90 Hz, the Vive Pro Eye's refresh rate.
pub const FRAME_PERIOD_NS: i64 = 1_000_000_000 / 90;
/// 120 Hz, the Vive Pro Eye's eye tracker.
pub const GAZE_PERIOD_NS: i64 = 1_000_000_000 / 120;
/// The first frame's predicted display time: one second, so no valid time is ever ≤ 0.
pub const FIRST_DISPLAY_TIME_NS: i64 = 1_000_000_000;
/// How far ahead of its display time `xrWaitFrame` hands out a frame: one period to render,
/// one to composite.
pub const LEAD_NS: i64 = 2 * FRAME_PERIOD_NS;

/// One session's clock and display slots.
pub struct Clock {
    realtime: bool,
    /// Display periods per frame the compositor needs (≥ 1).
    periods_per_frame: i64,
    /// Real time of runtime time `FIRST_DISPLAY_TIME_NS - LEAD_NS` (real clock).
    origin: Instant,
    /// The display time of the frame `xrWaitFrame` handed out last, and the earliest the
    /// next one can get.
    display_ns: i64,
    next_display_ns: i64,
    /// When `xrWaitFrame` last returned, and the runtime time it returned at (virtual clock).
    woke: (Instant, i64),
}

impl Clock {
    /// A clock starting now; `compositor_ms`: the compositor's time per frame.
    pub fn new(realtime: bool, compositor_ms: f64) -> Self {
        let periods = (compositor_ms * 1e6 / FRAME_PERIOD_NS as f64).ceil() as i64;
        let now = Instant::now();
        Self {
            realtime,
            periods_per_frame: periods.max(1),
            origin: now,
            display_ns: FIRST_DISPLAY_TIME_NS,
            next_display_ns: FIRST_DISPLAY_TIME_NS,
            woke: (now, FIRST_DISPLAY_TIME_NS - LEAD_NS),
        }
    }

    /// The runtime's time now, ns.
    pub fn now_ns(&self) -> i64 {
        match self.realtime {
            true => FIRST_DISPLAY_TIME_NS - LEAD_NS + self.origin.elapsed().as_nanos() as i64,
            false => {
                let (at, ns) = self.woke;
                // The app's period to render: a frame later than that is still shown on
                // time, as if it had been quick.
                (ns + at.elapsed().as_nanos() as i64).min(self.display_ns - FRAME_PERIOD_NS)
            }
        }
    }

    /// `xrWaitFrame`: waits (real clock) until the next frame is due and returns its
    /// predicted display time, ns.
    pub fn wait_frame(&mut self) -> i64 {
        let display = match self.realtime {
            true => {
                let due = self.next_display_ns - LEAD_NS;
                let now = self.now_ns();
                if due > now {
                    std::thread::sleep(Duration::from_nanos((due - now) as u64));
                }
                // An app on time (within half a period: sleeps overshoot) gets the next
                // slot; a late one the first slot it can still make.
                let now = self.now_ns();
                match now - due < FRAME_PERIOD_NS / 2 {
                    true => self.next_display_ns,
                    false => {
                        let slots =
                            (now + LEAD_NS - FIRST_DISPLAY_TIME_NS) as f64 / FRAME_PERIOD_NS as f64;
                        FIRST_DISPLAY_TIME_NS + slots.ceil() as i64 * FRAME_PERIOD_NS
                    }
                }
            }
            false => self.next_display_ns,
        };
        self.display_ns = display;
        self.next_display_ns = display + self.periods_per_frame * FRAME_PERIOD_NS;
        self.woke = (Instant::now(), display - LEAD_NS);
        display
    }

    /// The display time of the frame handed out last (the time of its events).
    pub fn display_ns(&self) -> i64 {
        self.display_ns
    }

    /// When the eye tracker took its newest sample, ns: the last 120 Hz tick at or before now.
    pub fn gaze_sample_ns(&self) -> i64 {
        self.now_ns().div_euclid(GAZE_PERIOD_NS) * GAZE_PERIOD_NS
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_virtual_clock_hands_out_display_slots_a_period_apart() {
        let mut clock = Clock::new(false, 0.0);
        assert_eq!(clock.wait_frame(), FIRST_DISPLAY_TIME_NS);
        assert_eq!(clock.wait_frame(), FIRST_DISPLAY_TIME_NS + FRAME_PERIOD_NS);
        // Two periods before the display, never past one period before it.
        let now = clock.now_ns();
        assert!(now >= clock.display_ns() - LEAD_NS);
        assert!(now <= clock.display_ns() - FRAME_PERIOD_NS);
    }

    #[test]
    fn a_slow_compositor_shows_a_frame_every_few_periods() {
        // 20 ms a frame: every second 11.1 ms slot.
        let mut clock = Clock::new(false, 20.0);
        let first = clock.wait_frame();
        assert_eq!(clock.wait_frame() - first, 2 * FRAME_PERIOD_NS);
    }

    #[test]
    fn gaze_samples_fall_on_a_120_hz_grid_before_now() {
        let mut clock = Clock::new(false, 0.0);
        for _ in 0..5 {
            clock.wait_frame();
            let sample = clock.gaze_sample_ns();
            assert_eq!(sample % GAZE_PERIOD_NS, 0);
            assert!(sample <= clock.now_ns() && clock.now_ns() - sample < GAZE_PERIOD_NS);
        }
    }

    #[test]
    fn the_real_clock_paces_frames_and_moves_a_late_frame_to_a_later_slot() {
        let mut clock = Clock::new(true, 0.0);
        let first = clock.wait_frame();
        let paced = Instant::now();
        let second = clock.wait_frame();
        // Waited until two periods before the second slot, about one period after the first.
        assert!(
            paced.elapsed() >= Duration::from_millis(5),
            "{:?}",
            paced.elapsed()
        );
        assert_eq!(second - first, FRAME_PERIOD_NS);
        std::thread::sleep(Duration::from_millis(40));
        let late = clock.wait_frame();
        assert!(late - second >= 3 * FRAME_PERIOD_NS, "{}", late - second);
        assert_eq!((late - FIRST_DISPLAY_TIME_NS) % FRAME_PERIOD_NS, 0);
    }
}
