//! Clicks held across a slow frame. egui times a press by the frames that see it (their start
//! times, not the events') and takes a release more than `max_click_duration` (0.8 s) after
//! the press's frame for a long press, not a click. A frame over 0.8 s between the two (a
//! heavy edit, a busy machine, the page's main thread held) lost the click, on any button.
//! [`HeldClock`] lengthens the limit by the frame gaps over a frame's usual time that a mouse
//! press was held through, as a browser's own buttons click however long they are held.
//!
//! The gaps it counts are not all stalls: an idle app draws no frames while a button is held
//! still, so for a mouse a still hold of any length clicks (as in a browser), and becomes a
//! drag only by moving. Touches are left to egui: a still touch is a long press (a context
//! menu) at 0.8 s whatever the frames do.

/// egui's own limit between a click and a long press.
const CLICK: f64 = 0.8;
/// A frame gap up to this long is a frame's usual time; beyond it, a stall.
const FRAME: f64 = 0.1;

/// Counts the frame gaps a press is held through (see the module's doc).
#[derive(Debug, Default)]
pub struct HeldClock {
    /// The start time of the frame before.
    last: Option<f64>,
    /// Seconds of frame gaps over [`FRAME`] since the pointer went down.
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
    let (down, touch) = ctx.input(|i| (i.pointer.any_down(), i.any_touches()));
    // (A touch's gaps are counted as none: egui's long press stays at 0.8 s.)
    let counted = clock.max_click_duration(time, down && !touch);
    let limit = if touch { CLICK } else { counted };
    if ctx.options(|o| o.input_options.max_click_duration) != limit {
        ctx.options_mut(|o| o.input_options.max_click_duration = limit);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::{Event, PointerButton, Pos2, RawInput, TouchDeviceId, TouchId, TouchPhase};

    /// Frames of a button: pressed at the first of `times`, released at the last (as a mouse,
    /// or as a touch: egui's touch events beside the pointer's, as eframe sends them), through
    /// the clock or not (egui alone); returns whether the button was clicked.
    fn held(times: &[f64], with_clock: bool, touch: bool) -> bool {
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
            let finger = |phase| Event::Touch {
                device_id: TouchDeviceId(1),
                id: TouchId(1),
                phase,
                pos: at,
                force: None,
            };
            let mut events = vec![];
            if i >= 1 {
                events.push(Event::PointerMoved(at));
            }
            if i == 2 {
                if touch {
                    events.push(finger(TouchPhase::Start));
                }
                events.push(button(true));
            }
            if i == times.len() + 1 {
                if touch {
                    events.push(finger(TouchPhase::End));
                }
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
        assert!(held(&stalled, true, false));
        assert!(!held(&stalled, false, false), "egui alone keeps the click");
        // Frames at 60 a second throughout: a 0.3 s click, and a 1.2 s still hold, which
        // stays a long press.
        let steady = |secs: f64| -> Vec<f64> {
            (0..=(secs * 60.0) as usize)
                .map(|i| 10.0 + i as f64 / 60.0)
                .collect()
        };
        assert!(held(&steady(0.3), true, false));
        assert!(!held(&steady(1.2), true, false), "a still 1.2 s hold");
    }

    #[test]
    fn a_still_touch_is_a_long_press_at_egui_s_time_whatever_the_frames() {
        // Idle frames (egui's wake at 0.8 s): a 1.2 s touch is a long press, not a tap, with
        // the clock as without it; a 0.4 s one is a tap.
        let idle = [10.0, 10.016, 10.82, 11.2];
        assert!(!held(&idle, true, true));
        assert!(!held(&idle, false, true));
        assert!(held(&[10.0, 10.016, 10.4], true, true));
    }
}
