//! The viewport's notice line: what just happened, or why something was refused.

/// A message for the user (errors stay until replaced; notes fade).
#[derive(Clone, Debug, PartialEq)]
pub struct Notice {
    /// Text.
    pub text: String,
    /// Whether it reports a refusal.
    pub error: bool,
    /// When it was posted (egui time).
    pub at: f64,
}

/// How long a note (not an error) stays, in seconds.
pub const NOTE_SECONDS: f64 = 6.0;

/// The latest notice.
#[derive(Default)]
pub struct Notices {
    /// The latest message, if any.
    pub latest: Option<Notice>,
}

impl Notices {
    /// Posts a note.
    pub fn note(&mut self, now: f64, text: impl Into<String>) {
        self.latest = Some(Notice {
            text: text.into(),
            error: false,
            at: now,
        });
    }

    /// Posts an error (a refusal).
    pub fn error(&mut self, now: f64, text: impl Into<String>) {
        self.latest = Some(Notice {
            text: text.into(),
            error: true,
            at: now,
        });
    }

    /// The notice to show at `now`, if any.
    pub fn visible(&self, now: f64) -> Option<&Notice> {
        self.latest
            .as_ref()
            .filter(|n| n.error || now - n.at < NOTE_SECONDS)
    }
}
