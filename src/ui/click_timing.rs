//! Clicks held across a slow frame. egui times a press by the frames that see it (their start
//! times, not the events') and takes a release more than `max_click_duration` (0.8 s) after
//! the press's frame for a long press, not a click. A frame over 0.8 s between the two (a
//! heavy edit, a busy machine, the page's main thread held) lost the click, on any button.
//! [`HeldClock`] lengthens the limit by the stalls the press was held through, so what counts
//! is the hold the frames could see, as a browser's own buttons count it; a still press held
//! through frames at their usual rate still becomes a long press (a touch's context menu) at
//! egui's 0.8 s.

/// egui's own limit between a click and a long press.
const CLICK: f64 = 0.8;
/// A frame gap up to this long is a frame's usual time; beyond it, a stall.
const FRAME: f64 = 0.1;

/// Counts the stalls a press is held through (see the module's doc).
#[derive(Debug, Default)]
pub struct HeldClock {
    /// The start time of the frame before.
    last: Option<f64>,
    /// Seconds of stall since the pointer went down.
    stalled: f64,
}

impl HeldClock {
    /// The limit between a click and a long press for the frame starting at `time`, the
    /// pointer being `down` as the frame before left it (before this frame's events).
    pub fn max_click_duration(&mut self, time: f64, down: bool) -> f64 {
        let gap = self.last.map_or(0.0, |t| (time - t).max(0.0));
        self.last = Some(time);
        self.stalled = if down {
            self.stalled + (gap - FRAME).max(0.0)
        } else {
            0.0
        };
        CLICK + self.stalled
    }
}

/// Sets `ctx`'s limit between a click and a long press for the frame `raw` starts (eframe's
/// input hook, before egui reads the frame's events).
pub fn apply(clock: &mut HeldClock, ctx: &egui::Context, raw: &egui::RawInput) {
    let Some(time) = raw.time else {
        return;
    };
    let down = ctx.input(|i| i.pointer.any_down());
    let limit = clock.max_click_duration(time, down);
    if ctx.options(|o| o.input_options.max_click_duration) != limit {
        ctx.options_mut(|o| o.input_options.max_click_duration = limit);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::{Event, PointerButton, Pos2, RawInput};

    /// Frames of a button: press at the first, release at the last, at these start times,
    /// through the clock or not (egui alone); returns whether the button was clicked.
    fn held(times: &[f64], with_clock: bool) -> bool {
        let ctx = egui::Context::default();
        let mut clock = HeldClock::default();
        let mut at = Pos2::ZERO;
        let mut clicked = false;
        // Two frames first: one lays the button out, one brings the pointer over it.
        let first = times[0];
        let frames = [first - 0.04, first - 0.02]
            .into_iter()
            .chain(times.iter().copied());
        for (i, t) in frames.enumerate() {
            let button = |pressed| Event::PointerButton {
                pos: at,
                button: PointerButton::Primary,
                pressed,
                modifiers: Default::default(),
            };
            let mut events = vec![];
            if i >= 1 {
                events.push(Event::PointerMoved(at));
            }
            if i == 2 {
                events.push(button(true));
            }
            if i == times.len() + 1 {
                events.push(button(false));
            }
            let raw = RawInput {
                time: Some(t),
                screen_rect: Some(crate::ui::test_view()),
                events,
                ..Default::default()
            };
            if with_clock {
                apply(&mut clock, &ctx, &raw);
            }
            let mut output = ctx.run_ui(raw, |ui| {
                let response = ui.button("Play");
                at = response.rect.center();
                clicked |= response.clicked();
            });
            output.textures_delta.clear();
        }
        clicked
    }

    #[test]
    fn a_click_held_across_a_slow_frame_still_clicks() {
        // Pressed, then one frame 1.2 s long, released at once after it: egui alone loses it.
        let stalled = [10.0, 10.02, 11.25];
        assert!(held(&stalled, true));
        assert!(!held(&stalled, false), "egui alone keeps the click");
        // Frames at 60 a second throughout: a 0.3 s click, and a 1.2 s still hold, which
        // stays a long press.
        let steady = |secs: f64| -> Vec<f64> {
            (0..=(secs * 60.0) as usize)
                .map(|i| 10.0 + i as f64 / 60.0)
                .collect()
        };
        assert!(held(&steady(0.3), true));
        assert!(
            !held(&steady(1.2), true),
            "a still 1.2 s hold is a long press"
        );
    }
}
