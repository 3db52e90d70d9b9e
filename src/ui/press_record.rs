//! Every pointer sample of the primary button's presses, recorded as the platform hears them
//! (the page's own listeners; natively egui's events, fed once a frame), so that a stroke keeps
//! every sample however few frames it spans: egui recognises a drag a frame or more after the
//! press, and a stroke within one long frame is no drag at all to egui.

use std::cell::RefCell;

/// A pointer position in points, with the pen's pressure when a pen drew it.
pub type Sample = (egui::Pos2, Option<f32>);

thread_local! {
    /// The UI thread's record, fed by the platform (`platform::record_frame` natively, the
    /// page's pointer listeners in the browser).
    static RECORD: RefCell<PressRecord> = RefCell::new(PressRecord::default());
}

/// Runs `f` on this thread's record.
pub fn with_record<R>(f: impl FnOnce(&mut PressRecord) -> R) -> R {
    RECORD.with(|r| f(&mut r.borrow_mut()))
}

/// The primary button's last whole press → release (every sample, from the press), once: a
/// stroke drawn within one long frame, which egui reports as neither a drag nor a click.
pub fn take_finished_press() -> Option<Vec<Sample>> {
    with_record(PressRecord::take_finished)
}

/// Pointer positions (in points) since the last call while the primary button was down, each
/// with the pen's pressure when a pen drew it.
pub fn take_pointer_samples() -> Vec<Sample> {
    with_record(PressRecord::take_samples)
}

/// Every sample of the press under way, from where the button went down.
pub fn press_samples() -> Vec<Sample> {
    with_record(|r| r.press_so_far())
}

/// The primary button's press being recorded, the samples since they were last taken, and the
/// last whole press → release.
#[derive(Default)]
pub struct PressRecord {
    /// The primary button is down.
    down: bool,
    /// Every sample since the button went down (its own position first).
    press: Vec<Sample>,
    /// The samples since [`PressRecord::take_samples`] last took them.
    samples: Vec<Sample>,
    /// The last whole press → release, until taken.
    finished: Option<Vec<Sample>>,
}

impl PressRecord {
    /// The primary button went down (at `at`, where the platform knows it).
    pub fn pressed(&mut self, at: Option<Sample>) {
        self.down = true;
        self.samples.clear();
        self.press = at.into_iter().collect();
    }

    /// The pointer moved through `new` with a button down. Both buffers keep at most a plane's
    /// worth of points, the first ones, as a stroke being drawn does (a held button must not
    /// grow them unbounded).
    pub fn moved(&mut self, new: &[Sample]) {
        let cap = crate::limits::MAX_PLANE_POINTS;
        for buffer in [&mut self.samples, &mut self.press] {
            let room = cap.saturating_sub(buffer.len());
            buffer.extend(new.iter().take(room));
        }
    }

    /// The primary button came up (at `at`, where the platform knows it): the press, if any
    /// was recorded, is finished.
    pub fn released(&mut self, at: Option<Sample>) {
        if let Some(at) = at
            && self.down
            && self.press.last().map(|s| s.0) != Some(at.0)
        {
            self.moved(&[at]);
        }
        self.down = false;
        let press = std::mem::take(&mut self.press);
        if !press.is_empty() {
            self.finished = Some(press);
        }
    }

    /// Whether the primary button is down as far as the record knows.
    pub fn is_down(&self) -> bool {
        self.down
    }

    /// The button is up though no release was heard (the window lost it): the press is
    /// dropped, not finished.
    pub fn lost(&mut self) {
        self.down = false;
        self.press.clear();
        self.samples.clear();
    }

    /// The samples since the last call.
    pub fn take_samples(&mut self) -> Vec<Sample> {
        std::mem::take(&mut self.samples)
    }

    /// Every sample of the press under way, from where the button went down.
    pub fn press_so_far(&self) -> Vec<Sample> {
        self.press.clone()
    }

    /// The last whole press → release, once.
    pub fn take_finished(&mut self) -> Option<Vec<Sample>> {
        self.finished.take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::pos2;

    fn at(x: f32) -> Option<Sample> {
        Some((pos2(x, 0.0), None))
    }

    fn xs(samples: &[Sample]) -> Vec<f32> {
        samples.iter().map(|s| s.0.x).collect()
    }

    #[test]
    fn a_press_keeps_every_sample_from_the_button_going_down_and_finishes_once() {
        let mut r = PressRecord::default();
        r.pressed(at(0.0));
        r.moved(&[at(1.0).unwrap(), at(2.0).unwrap()]);
        assert_eq!(xs(&r.press_so_far()), [0.0, 1.0, 2.0]);
        assert_eq!(xs(&r.take_samples()), [1.0, 2.0]);
        assert!(r.take_finished().is_none(), "not before the release");
        r.moved(&[at(3.0).unwrap()]);
        // The release where the last move was adds no sample; elsewhere it does.
        r.released(at(3.0));
        assert_eq!(xs(&r.take_finished().unwrap()), [0.0, 1.0, 2.0, 3.0]);
        assert!(r.take_finished().is_none(), "once");
        r.pressed(at(5.0));
        r.released(at(6.0));
        assert_eq!(xs(&r.take_finished().unwrap()), [5.0, 6.0]);
        assert!(!r.is_down());
    }

    #[test]
    fn a_held_button_stays_capped_and_a_lost_press_is_not_finished() {
        let mut r = PressRecord::default();
        r.pressed(at(0.0));
        let moves: Vec<Sample> = (0..crate::limits::MAX_PLANE_POINTS + 50)
            .map(|i| (pos2(i as f32, 0.0), None))
            .collect();
        r.moved(&moves);
        let press = r.press_so_far();
        assert_eq!(press.len(), crate::limits::MAX_PLANE_POINTS);
        assert_eq!(press[0].0.x, 0.0, "the press's start is kept");
        assert_eq!(r.take_samples().len(), crate::limits::MAX_PLANE_POINTS);
        r.lost();
        assert!(!r.is_down() && r.press_so_far().is_empty());
        r.released(None);
        assert!(r.take_finished().is_none());
    }
}
