//! The document's clock: frames per second and the range of frames a sequence covers
//! (inclusive, as Blender's), and the one conversion between seconds, frames and a
//! simulation's steps. The scene's time stays in seconds; a frame is a moment of it.

use serde::{Deserialize, Serialize};

use crate::limits;

/// Frames per second and the frame range, inclusive.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Clock {
    /// Frames per second.
    pub fps: f32,
    /// First frame of the range.
    pub start: u32,
    /// Last frame of the range (inclusive).
    pub end: u32,
}

impl Default for Clock {
    fn default() -> Self {
        Self {
            fps: limits::FRAME_RATE.default as f32,
            start: 0,
            end: DEFAULT_END,
        }
    }
}

/// The default range's last frame: five seconds at the default rate.
const DEFAULT_END: u32 = 120;

impl Clock {
    /// Whether it is the default clock (a document leaves it out then).
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// The rate, or the default where a clock that skipped [`Clock::sanitize`] holds none.
    fn rate(&self) -> f64 {
        if self.fps.is_finite() && self.fps > 0.0 {
            f64::from(self.fps)
        } else {
            limits::FRAME_RATE.default
        }
    }

    /// The scene time of frame `frame`, in seconds (frame 0 is time 0).
    pub fn seconds(&self, frame: u32) -> f32 {
        (f64::from(frame) / self.rate()) as f32
    }

    /// The frame at scene time `seconds`, with its fraction (a time between two frames); a
    /// frame's own time ([`Clock::seconds`], rounded to the scene's f32 seconds) gives that
    /// frame back whole.
    pub fn frame(&self, seconds: f32) -> f64 {
        snapped(seconds, self.rate())
    }

    /// The frames of the range, first to last.
    pub fn frames(&self) -> std::ops::RangeInclusive<u32> {
        self.start..=self.end
    }

    /// The last frame whose time is within [`limits::MAX_TIME`] at this rate.
    pub fn last_frame(&self) -> u32 {
        (f64::from(limits::MAX_TIME) * self.rate()).floor() as u32
    }

    /// Repairs what a document may hold: a rate outside its range, a range past the last
    /// frame or ending before it starts.
    pub fn sanitize(&mut self) {
        self.fps = limits::FRAME_RATE.fix_f32(self.fps);
        let last = self.last_frame();
        self.start = self.start.min(last);
        self.end = self.end.clamp(self.start, last);
    }
}

/// `seconds` × `per_second`, snapped to the whole number it lies within the rounding of an
/// f32 time of (a frame's or a step's own time is stored as the nearest f32, often a hair
/// under it: frame 21 at 30 fps is 0.69999999 s, which must still be frame 21, not 20).
fn snapped(seconds: f32, per_second: f64) -> f64 {
    let seconds = if seconds.is_finite() {
        seconds.max(0.0)
    } else {
        0.0
    };
    let per_second = if per_second.is_finite() {
        per_second.max(0.0)
    } else {
        0.0
    };
    let x = f64::from(seconds) * per_second;
    // Half an f32 unit of the time, in units of the result, and a little more.
    let tolerance = f64::from(seconds) * f64::from(f32::EPSILON) * per_second + 1e-9;
    let whole = x.round();
    if (x - whole).abs() <= tolerance {
        whole
    } else {
        x
    }
}

/// Where scene time `seconds` falls among the steps of an automaton stepping `rate` times a
/// second, with the fraction toward the next step: the one conversion of time to steps (the
/// app's player and the command line both use it).
pub fn step_position(seconds: f32, rate: f32) -> f64 {
    snapped(seconds, f64::from(rate))
}

/// The step at or before scene time `seconds` ([`step_position`]; the player blends toward
/// the next one between).
pub fn steps_at(seconds: f32, rate: f32) -> u64 {
    step_position(seconds, rate).floor() as u64
}

/// A moment named on the command line: `--time SECONDS` or `--frame N`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Moment {
    /// Scene time in seconds.
    Seconds(f32),
    /// A frame of the document's clock.
    Frame(u32),
}

impl Moment {
    /// The moment from the command line's `--time` and `--frame` (at most one of them).
    pub fn from_args(time: Option<f32>, frame: Option<u32>) -> Result<Option<Self>, String> {
        match (time, frame) {
            (Some(_), Some(_)) => Err("give --time or --frame, not both".into()),
            (Some(t), None) => Ok(Some(Self::Seconds(t))),
            (None, Some(f)) => Ok(Some(Self::Frame(f))),
            (None, None) => Ok(None),
        }
    }

    /// The scene time it names on `clock`, or why it is out of range.
    pub fn seconds(self, clock: &Clock) -> Result<f32, String> {
        match self {
            Self::Seconds(t) if t.is_finite() && (0.0..=limits::MAX_TIME).contains(&t) => Ok(t),
            Self::Seconds(t) => Err(format!("--time {t}: 0 to {} seconds", limits::MAX_TIME)),
            Self::Frame(f) if f <= clock.last_frame() => Ok(clock.seconds(f)),
            Self::Frame(f) => Err(format!(
                "--frame {f}: 0 to {} at the scene's {} frames per second ({} s)",
                clock.last_frame(),
                clock.fps,
                limits::MAX_TIME
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_and_seconds_convert_both_ways() {
        let clock = Clock {
            fps: 24.0,
            ..Clock::default()
        };
        assert_eq!(clock.seconds(60), 2.5);
        assert_eq!(clock.frame(2.5), 60.0);
        assert_eq!(clock.frame(clock.seconds(12_345)), 12_345.0);
        let ntsc = Clock {
            fps: 29.97,
            ..Clock::default()
        };
        for f in [0, 1, 299, 30_000] {
            assert!(
                (ntsc.frame(ntsc.seconds(f)) - f64::from(f)).abs() < 1e-3,
                "{f}"
            );
        }
        assert_eq!(clock.frames().count(), 121, "inclusive");
        // Every frame's own time gives it back whole, and the simulation's step at it is the
        // exact one, at the common rates (frame 21 at 30 fps is 0.69999999 s as an f32).
        for fps in [24.0, 25.0, 30.0, 29.97, 60.0, 120.0] {
            let c = Clock {
                fps,
                ..Clock::default()
            };
            for f in (0..5000).chain([100_000, 1_000_000]) {
                let t = c.seconds(f);
                assert_eq!(c.frame(t).floor(), f64::from(f), "frame {f} at {fps} fps");
                let exact = (f64::from(f) * 10.0 / f64::from(fps) + 1e-9).floor();
                if f < 5000 {
                    assert_eq!(steps_at(t, 10.0) as f64, exact, "frame {f} at {fps} fps");
                }
            }
        }
        assert!(clock.frame(f32::NAN) == 0.0 && steps_at(f32::INFINITY, 10.0) == 0);
        let broken = Clock {
            fps: 0.0,
            ..Clock::default()
        };
        assert!(
            broken.seconds(10).is_finite(),
            "a clock without a rate takes the default"
        );
        assert_eq!(steps_at(2.5, 4.0), 10);
        assert_eq!(steps_at(2.49, 4.0), 9);
        assert_eq!(steps_at(-1.0, 4.0), 0);
    }

    #[test]
    fn a_moment_is_a_time_or_a_frame_within_the_clock() {
        let clock = Clock::default();
        assert_eq!(Moment::from_args(None, None), Ok(None));
        assert!(Moment::from_args(Some(1.0), Some(2)).is_err());
        let frame = Moment::from_args(None, Some(48)).unwrap().unwrap();
        assert_eq!(frame.seconds(&clock), Ok(2.0));
        assert_eq!(Moment::Seconds(2.0).seconds(&clock), Ok(2.0));
        assert!(Moment::Seconds(f32::NAN).seconds(&clock).is_err());
        assert!(Moment::Seconds(-1.0).seconds(&clock).is_err());
        let last = clock.last_frame();
        assert!(Moment::Frame(last).seconds(&clock).is_ok());
        let err = Moment::Frame(last + 1).seconds(&clock).unwrap_err();
        assert!(err.contains("--frame"), "{err}");
    }

    #[test]
    fn a_damaged_clock_is_repaired() {
        let mut c = Clock {
            fps: f32::NAN,
            start: 50,
            end: 10,
        };
        c.sanitize();
        assert_eq!(c.fps, limits::FRAME_RATE.default as f32);
        assert_eq!(
            (c.start, c.end),
            (50, 50),
            "the range ends where it starts at least"
        );
        let mut far = Clock {
            fps: 1000.0,
            start: u32::MAX,
            end: u32::MAX,
        };
        far.sanitize();
        assert_eq!(far.fps, limits::FRAME_RATE.max as f32);
        assert_eq!(far.end, far.last_frame());
    }
}
