//! A progress line for long work (a large render on a CPU adapter, a long simulation, a
//! sequence's frames), drawn by `indicatif` on standard error when it is a terminal: nothing
//! is printed into a pipe or a log.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long work runs before its progress line appears (short work shows none), unless
/// `CLOUDSKETCH_PROGRESS_AT_ONCE` is set (the CLI tests, which must not race the clock).
const DELAY: Duration = Duration::from_millis(500);
/// How often the line is redrawn, at most.
const REDRAWS_PER_SECOND: u8 = 10;
/// The steps a share of the work (`Progress::share`) is counted in.
const SHARE_STEPS: u64 = 1000;

/// One progress line, redrawn in place: `rendering 8192x8192:  42% [=====>    ] 3s left`,
/// or, counting things, `frames 0..119:  35% [===>      ] 42/120, 1m left`.
pub struct Progress {
    label: String,
    total: u64,
    counting: bool,
    on: bool,
    start: Instant,
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A line for `label` whose work is a share from 0 to 1 (`set`).
    pub fn share(label: impl Into<String>) -> Self {
        Self::with(label.into(), SHARE_STEPS, false)
    }

    /// A line for `label` whose work is `total` things (`done`): frames, say.
    pub fn counting(label: impl Into<String>, total: u64) -> Self {
        Self::with(label.into(), total.max(1), true)
    }

    fn with(label: String, total: u64, counting: bool) -> Self {
        Self {
            label,
            total,
            counting,
            // Where indicatif would draw: a terminal, and not a dumb one.
            on: std::io::stderr().is_terminal() && !ProgressDrawTarget::stderr().is_hidden(),
            start: Instant::now(),
            bar: None,
        }
    }

    /// Whether the line is drawn at all (standard error is a terminal).
    pub fn shown(&self) -> bool {
        self.on
    }

    /// The share of the work done, 0–1.
    pub fn set(&mut self, share: f32) {
        let steps = (share.clamp(0.0, 1.0) as f64 * self.total as f64).floor() as u64;
        self.done(steps);
    }

    /// How many of the things are done.
    pub fn done(&mut self, done: u64) {
        let at_once = std::env::var_os("CLOUDSKETCH_PROGRESS_AT_ONCE").is_some();
        if !self.on || (self.bar.is_none() && !at_once && self.start.elapsed() < DELAY) {
            return;
        }
        let done = done.min(self.total);
        let bar = self.bar.get_or_insert_with(|| {
            let what = if self.counting { " {pos}/{len}," } else { "" };
            let template = format!("{{msg}}: {{percent:>3}}% [{{bar:30}}]{what} {{eta}} left");
            let style = ProgressStyle::with_template(&template)
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> ");
            let bar = ProgressBar::with_draw_target(
                Some(self.total),
                ProgressDrawTarget::stderr_with_hz(REDRAWS_PER_SECOND),
            )
            .with_style(style)
            .with_message(self.label.clone())
            .with_elapsed(self.start.elapsed());
            // The time left counts from here, with the work done so far already done.
            bar.set_position(done);
            bar.reset_eta();
            bar
        });
        bar.set_position(done);
    }

    /// Prints `text` on its own line on standard error, the progress line (if drawn) put
    /// aside for it and drawn again below.
    pub fn note(&self, text: &str) {
        match &self.bar {
            Some(bar) => bar.suspend(|| eprintln!("{text}")),
            None => eprintln!("{text}"),
        }
    }
}

impl Drop for Progress {
    /// Clears the line, so what is printed next starts at the margin.
    fn drop(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}
