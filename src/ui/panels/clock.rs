//! The scene clock's controls: play and pause, the time (drag to scrub), back to zero, and the
//! speed. The time lives in the document (renders and links reproduce it) but, like the
//! camera, changing it is not an undo step; playing is view state.

use egui::Ui;

use crate::scene::{Document, Edit};

/// The clock's view state.
pub struct ClockPanel {
    /// The scene time advances with the frames.
    pub playing: bool,
    /// Scene seconds per second.
    pub speed: f32,
}

impl Default for ClockPanel {
    fn default() -> Self {
        Self {
            playing: false,
            speed: 1.0,
        }
    }
}

impl ClockPanel {
    /// Advances the scene time by `dt` seconds of wall time while playing; returns whether it
    /// did (the caller asks for the next frame).
    pub fn tick(&mut self, doc: &mut Document, dt: f32) -> bool {
        if !self.playing {
            return false;
        }
        doc.set_time(doc.scene().time + dt.clamp(0.0, 0.25) * self.speed);
        true
    }

    /// Draws the controls on one row.
    pub fn ui(&mut self, ui: &mut Ui, doc: &mut Document) {
        ui.horizontal(|ui| {
            let label = if self.playing { "Pause" } else { "Play" };
            if ui
                .button(label)
                .on_hover_text(
                    "Alt+A: play the scene (the wind and torque of the media move the noise)",
                )
                .clicked()
            {
                self.playing = !self.playing;
            }
            let mut time = doc.scene().time;
            if ui
                .add(
                    egui::DragValue::new(&mut time)
                        .speed(0.05)
                        .suffix(" s")
                        .range(0.0..=crate::limits::MAX_TIME),
                )
                .on_hover_text("Scene time: drag to scrub")
                .changed()
            {
                doc.set_time(time);
            }
            if ui
                .small_button("to 0")
                .on_hover_text("Back to 0 s")
                .clicked()
            {
                doc.set_time(0.0);
            }
            ui.add(
                egui::DragValue::new(&mut self.speed)
                    .speed(0.05)
                    .prefix("×")
                    .range(0.0..=10.0),
            )
            .on_hover_text("Speed");
        });
        self.frames_ui(ui, doc);
    }

    /// The clock's frame at the scene time, its rate and its frame range (an undo step).
    fn frames_ui(&mut self, ui: &mut Ui, doc: &mut Document) {
        ui.horizontal(|ui| {
            let scene = doc.scene();
            let mut clock = scene.clock;
            ui.label(format!("frame {}", clock.frame(scene.time).floor()))
                .on_hover_text("The frame at the scene time (--frame on the command line)");
            let rate = crate::limits::FRAME_RATE;
            let mut changed = ui
                .add(
                    egui::DragValue::new(&mut clock.fps)
                        .speed(0.1)
                        .suffix(" fps")
                        .range(rate.min as f32..=rate.max as f32),
                )
                .on_hover_text(rate.tip)
                .changed();
            let last = clock.last_frame();
            ui.label("frames");
            changed |= ui
                .add(egui::DragValue::new(&mut clock.start).range(0..=last))
                .on_hover_text("First frame of the range")
                .changed();
            ui.label("–");
            changed |= ui
                .add(egui::DragValue::new(&mut clock.end).range(0..=last))
                .on_hover_text("Last frame of the range (inclusive)")
                .changed();
            if changed {
                if clock.end < clock.start {
                    clock.end = clock.start;
                }
                doc.apply(Edit::SetClock(clock), Some("clock"));
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    #[test]
    fn playing_advances_the_time_without_undo_steps() {
        let mut doc = Document::new(Scene::default());
        let mut clock = ClockPanel::default();
        assert!(!clock.tick(&mut doc, 0.1), "paused: nothing moves");
        clock.playing = true;
        clock.speed = 2.0;
        let render = doc.revisions().render;
        for _ in 0..10 {
            clock.tick(&mut doc, 0.1);
        }
        assert!(
            (doc.scene().time - 2.0).abs() < 1e-5,
            "{}",
            doc.scene().time
        );
        assert_eq!(doc.undo_len(), 0);
        assert!(doc.revisions().render > render, "the image knows to change");
        // A stalled frame does not jump the clock.
        clock.tick(&mut doc, 30.0);
        assert!(doc.scene().time < 2.6);
    }
}
