//! A progress line for long work (a large render on a CPU adapter, a long simulation), on
//! standard error when it is a terminal: nothing is printed into a pipe or a log.

use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

/// How long work runs before its progress line appears (short work shows none).
const DELAY: Duration = Duration::from_millis(500);
/// How often the line is redrawn.
const EVERY: Duration = Duration::from_millis(100);

/// One progress line: `rendering 8192x8192: 42%`, redrawn in place.
pub struct Progress {
    label: String,
    on: bool,
    start: Instant,
    drawn: Option<Instant>,
}

impl Progress {
    /// A line for `label`, drawn only when standard error is a terminal.
    pub fn new(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            on: std::io::stderr().is_terminal(),
            start: Instant::now(),
            drawn: None,
        }
    }

    /// Whether the line is drawn at all (standard error is a terminal).
    pub fn shown(&self) -> bool {
        self.on
    }

    /// The share of the work done, 0–1.
    pub fn set(&mut self, done: f32) {
        let now = Instant::now();
        if !self.on || now - self.start < DELAY || self.drawn.is_some_and(|at| now - at < EVERY) {
            return;
        }
        self.drawn = Some(now);
        let percent = (done.clamp(0.0, 1.0) * 100.0).floor();
        let mut err = std::io::stderr().lock();
        let _ = write!(err, "\r{}: {percent:>3}%", self.label);
        let _ = err.flush();
    }
}

impl Drop for Progress {
    /// Clears the line, so what is printed next starts at the margin.
    fn drop(&mut self) {
        if self.drawn.is_some() {
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\r\x1b[K");
            let _ = err.flush();
        }
    }
}
