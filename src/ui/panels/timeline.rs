//! The timeline strip under the view: play, pause and loop, the frame, a scrub bar whose one
//! drag covers the whole frame range, the range and the rate, and the keys of what is selected
//! as diamonds (drag to retime, Shift+click to select several, right-click for the ease,
//! Delete over the strip removes them). I keys the selection's changed values (the sun with
//! nothing selected); auto-key records every edit. The time lives in the document (renders
//! and links reproduce it) but, like the camera, changing it is not an undo step; playing is
//! view state.

use egui::{Color32, Pos2, Sense, Stroke, Ui, vec2};

use crate::scene::{
    Animation, Channel, Clock, Document, Ease, Edit, EllipsoidProperty, LightProperty, Scene,
};
use crate::ui::selection::{Item, Selection};
use crate::ui::widgets::mark;

/// Height of the scrub bar in points.
const BAR_HEIGHT: f32 = 28.0;
/// Height of the ruler at the bar's top: a press there always scrubs, even over a key.
const RULER: f32 = 12.0;
/// How near (points) a press must be to a diamond to take it.
const DIAMOND_REACH: f32 = 7.0;

/// A drag of selected keys along the bar, from where it began.
struct KeyDrag {
    /// The keys as they were when the drag began.
    from: Animation,
    /// The selected key times then.
    times: Vec<f32>,
    /// Where the press was (points).
    x0: f32,
    /// Frames moved so far.
    moved: i64,
}

/// The timeline's view state.
pub struct Timeline {
    /// The strip is shown (its button or the view's "timeline" button toggles it).
    pub open: bool,
    /// The scene time advances with the frames.
    pub playing: bool,
    /// Playing goes back to the range's first frame after its last (off: the clock runs on,
    /// as the noise's wind and torque need no range).
    pub looping: bool,
    /// Scene seconds per second.
    pub speed: f32,
    /// The selected keys' times (seconds), among the shown channels' keys.
    pub selected: Vec<f32>,
    /// The pointer is over the strip (Delete there removes keys, not items).
    pub hovered: bool,
    /// Two rows: the range and the rate under the bar ([`Timeline::fit`]).
    narrow: bool,
    /// The view looks through the shot camera: with nothing selected, the keys shown and
    /// made are the shot's.
    pub shot_view: bool,
    drag: Option<KeyDrag>,
    /// A box drawn along the keys' row from this x (points), over the selection it began
    /// with (Shift adds to it; otherwise it starts empty).
    boxing: Option<(f32, Vec<f32>)>,
    /// Where the shown keys were drawn this frame (time, x), for the page state.
    pub drawn: Vec<(f32, f32)>,
    /// The height the keys were drawn at.
    pub keys_y: f32,
    /// Cached playback's progress (frames done of the range's) while it caches.
    pub cache_progress: Option<(usize, usize)>,
    /// Frames cached.
    pub cache_kept: usize,
    /// Cache was pressed: cache the range.
    pub cache_asked: bool,
    /// Cancel was pressed while caching.
    pub cache_cancel: bool,
    /// A recording's progress (0–1) while Record runs (the Export group's job).
    pub record_progress: Option<f32>,
    /// Another export runs: Record waits for it.
    pub record_blocked: bool,
    /// Record was pressed: record the range.
    pub record_asked: bool,
    /// Stop was pressed while recording.
    pub record_cancel: bool,
    /// When Cache's and Record's jobs last ended (UI seconds), and whether each ran last
    /// frame: a click meant for "Stop" that lands in the frame its job ends must not start
    /// the job again ([`JUST_ENDED`]).
    ended: [Option<f64>; 2],
    ran: [bool; 2],
    /// The frame the buttons were last drawn in: a job that ended while the strip was hidden
    /// was not aimed at.
    drawn_frame: u64,
    /// Wall seconds ticked while playing, in all.
    pub ticked_s: f64,
    /// Of those, the seconds not played: a stalled frame's time past the half second it may
    /// advance the clock (the page state reports both, so a test on a busy machine can tell a
    /// stall from time lost in the clock).
    pub stalled_s: f64,
}

impl Default for Timeline {
    fn default() -> Self {
        Self {
            open: true,
            playing: false,
            looping: false,
            speed: 1.0,
            selected: Vec::new(),
            hovered: false,
            narrow: false,
            shot_view: false,
            drag: None,
            boxing: None,
            drawn: Vec::new(),
            keys_y: 0.0,
            cache_progress: None,
            cache_kept: 0,
            cache_asked: false,
            cache_cancel: false,
            record_progress: None,
            record_blocked: false,
            record_asked: false,
            record_cancel: false,
            ended: [None; 2],
            ran: [false; 2],
            drawn_frame: 0,
            ticked_s: 0.0,
            stalled_s: 0.0,
        }
    }
}

/// Seconds after Cache's or Record's job ends in which a click on its button starts nothing:
/// the click was aimed at "Stop" (a press, then the release, a frame or two later).
const JUST_ENDED: f64 = 0.5;

/// The channels the timeline shows and deletes keys of: every keyable value of the selected
/// ellipsoids and planes; with nothing selected, the shot camera's while the view looks
/// through it, else the light's, the media's and the tiers'.
pub fn shown_channels(scene: &Scene, selection: &Selection, shot_view: bool) -> Vec<Channel> {
    if selection.is_empty() {
        return Channel::all(scene)
            .filter(|c| {
                if shot_view {
                    matches!(c, Channel::Shot { .. })
                } else {
                    matches!(
                        c,
                        Channel::Light { .. } | Channel::Media { .. } | Channel::Tier { .. }
                    )
                }
            })
            .collect();
    }
    let ids = selected_ids(scene, selection);
    Channel::all(scene)
        .filter(|c| c.id().is_some_and(|id| ids.contains(&id)))
        .collect()
}

fn selected_ids(scene: &Scene, selection: &Selection) -> std::collections::HashSet<u64> {
    selection
        .items()
        .iter()
        .filter_map(|item| match *item {
            Item::Ellipsoid(i) => scene.ellipsoids.get(i).map(|e| e.id),
            Item::Plane(i) => scene.planes.get(i).map(|p| p.id),
        })
        .collect()
}

/// What I keys: the selected ellipsoids' centre, radii, rotation and strength (and any other
/// of their values already keyed) and every keyable value of the selected planes (placement,
/// inflation, soft blend, billows); with nothing selected, the shot camera's orbit while the view looks through it, else the sun's
/// azimuth, elevation and intensity (and any light or media value already keyed).
pub fn keyed_by_i(scene: &Scene, selection: &Selection, shot_view: bool) -> Vec<Channel> {
    let animation = &scene.animation;
    shown_channels(scene, selection, shot_view)
        .into_iter()
        .filter(|c| {
            animation.track(*c).is_some()
                || matches!(c, Channel::Shot { .. })
                || matches!(
                    c,
                    Channel::Ellipsoid {
                        property: EllipsoidProperty::Center
                            | EllipsoidProperty::Radii
                            | EllipsoidProperty::Rotation
                            | EllipsoidProperty::Strength,
                        ..
                    } | Channel::Plane { .. }
                        | Channel::Light {
                            property: LightProperty::SunAzimuth
                                | LightProperty::SunElevation
                                | LightProperty::SunIntensity
                        }
                )
        })
        .collect()
}

impl Timeline {
    /// Advances the scene time by `dt` seconds of wall time while playing (at most half a
    /// second: a stalled frame does not jump the clock); looping, the range's last frame lasts
    /// a frame like the others and the time past it carries on from the first, so a loop of
    /// 24 frames takes one second at 24 a second however the frames fall. Returns whether it
    /// moved (the caller asks for the next frame).
    pub fn tick(&mut self, doc: &mut Document, dt: f32) -> bool {
        if !self.playing {
            return false;
        }
        let clock = doc.scene().clock;
        let dt = dt.max(0.0);
        self.ticked_s += f64::from(dt);
        self.stalled_s += f64::from((dt - 0.5).max(0.0));
        let mut t = doc.scene().time + dt.min(0.5) * self.speed;
        if self.looping {
            let start = clock.seconds(clock.start);
            let period = clock.seconds(clock.end.saturating_add(1)) - start;
            if t < start || t >= start + period {
                t = start + (t - start).rem_euclid(period.max(1e-6));
            }
        }
        doc.set_time(t);
        true
    }

    /// I: keys the selection's changed values at the document's time (one undo step): of what
    /// [`keyed_by_i`] offers, a keyed value only where it differs from what its keys pose there
    /// (it was edited since), and a value without keys always (Blender's key with "only insert
    /// needed"). Returns what to tell the user.
    pub fn insert_keys(&mut self, doc: &mut Document, selection: &Selection) -> String {
        let scene = doc.scene();
        let offered = keyed_by_i(scene, selection, self.shot_view);
        let channels = scene.changed_from_keys(&offered);
        let mut animation = scene.animation.clone();
        let t = scene.time;
        let n = animation.key_all(scene, channels.iter().copied(), t);
        let frame = scene.clock.frame(t);
        let what = if selection.is_empty() && self.shot_view {
            "the shot camera".to_owned()
        } else if selection.is_empty() {
            // The sun's place and strength, and the light, media and tier values keyed before
            // that were changed since.
            let sun = |c: &&Channel| {
                matches!(
                    c,
                    Channel::Light {
                        property: LightProperty::SunAzimuth
                            | LightProperty::SunElevation
                            | LightProperty::SunIntensity
                    }
                )
            };
            let others = channels.iter().filter(|c| !sun(c)).count();
            let values = |k| match k {
                1 => "1 other keyed value".to_owned(),
                k => format!("{k} other keyed values"),
            };
            match (channels.iter().any(|c| sun(&c)), others) {
                (_, 0) => "the sun".to_owned(),
                (true, k) => format!("the sun and {}", values(k)),
                (false, k) => values(k).replacen(" other", "", 1),
            }
        } else {
            match selection.items().len() {
                1 => "the selection".to_owned(),
                k => format!("{k} items"),
            }
        };
        if n == 0 {
            if channels.is_empty() && !offered.is_empty() {
                return format!(
                    "Nothing keyed: {what} unchanged from the keys at frame {frame:.0}"
                );
            }
            return if channels.is_empty() {
                "Nothing to key".into()
            } else if channels.iter().any(|c| {
                animation.track(*c).is_some_and(|tr| {
                    tr.keys.len() >= crate::scene::MAX_KEYS && tr.key_at(t).is_none()
                })
            }) {
                format!(
                    "No more keys fit: at most {} on one value",
                    crate::scene::MAX_KEYS
                )
            } else if animation.tracks.len() >= crate::scene::MAX_TRACKS
                && channels.iter().any(|c| animation.track(*c).is_none())
            {
                format!(
                    "No more keys fit: at most {} keyed values",
                    crate::scene::MAX_TRACKS
                )
            } else {
                format!("{what} already keyed as it is at frame {frame:.0}")
            };
        }
        doc.apply(Edit::SetAnimation(animation, "insert keys"), None);
        self.selected = vec![t];
        let values = if n == 1 { "value" } else { "values" };
        format!("Keyed {what} at frame {frame:.0} ({n} {values})")
    }

    /// Alt+I, or Delete over the strip: removes the shown channels' selected keys, or those at
    /// the document's time when none is selected (one undo step). Returns what to tell the
    /// user.
    pub fn delete_keys(&mut self, doc: &mut Document, selection: &Selection) -> String {
        let scene = doc.scene();
        let channels = shown_channels(scene, selection, self.shot_view);
        let times = if self.selected.is_empty() {
            vec![scene.time]
        } else {
            std::mem::take(&mut self.selected)
        };
        let mut animation = scene.animation.clone();
        let removed: usize = times
            .iter()
            .map(|t| animation.remove_at(&channels, *t))
            .sum();
        if removed == 0 {
            return "No keys there to delete".into();
        }
        doc.apply(Edit::SetAnimation(animation, "delete keys"), None);
        format!("Deleted {removed} keys")
    }

    /// Up and Down: the time of the next (or previous) key of the shown channels.
    pub fn jump_to_key(&self, doc: &mut Document, selection: &Selection, forward: bool) {
        let scene = doc.scene();
        let channels = shown_channels(scene, selection, self.shot_view);
        let times = scene.animation.times(Some(&channels));
        let t = scene.time;
        let next = if forward {
            times.into_iter().find(|k| *k > t)
        } else {
            times.into_iter().rev().find(|k| *k < t)
        };
        if let Some(k) = next {
            doc.set_time(k);
        }
    }

    /// Left and Right: one frame back or on.
    pub fn step_frame(&self, doc: &mut Document, by: i64) {
        let clock = doc.scene().clock;
        let frame = (clock.frame(doc.scene().time).round() as i64 + by).max(0);
        doc.set_time(clock.seconds(frame.min(u32::MAX as i64) as u32));
    }

    /// The Record button's label: "Record", or "Stop N%" while a recording runs.
    pub fn record_label(&self) -> String {
        match self.record_progress {
            Some(p) => format!("Stop {:.0}%", 100.0 * p.clamp(0.0, 1.0)),
            None => "Record".to_owned(),
        }
    }

    /// Decides the strip's rows for a strip `width` points wide and returns its height, so
    /// the panel is laid out at its height from the first frame (egui sizes a panel from the
    /// frame before: the view's first frame was 38 points too tall under two rows).
    pub fn fit(&mut self, width: f32) -> f32 {
        // The controls left of the bar take about 550 points (Cache and Record 170 of them,
        // which go to the second row after the range and the rate), the range and rate 230,
        // the bar at least 160 (one row at 1280 px, as before Record).
        self.narrow = width < 550.0 + 160.0 + 230.0;
        if self.narrow { 63.0 } else { 36.0 }
    }

    /// Draws the strip: one row, or two where the view is narrow (the range and the rate on
    /// the second), so nothing runs past the strip into the side panel.
    pub fn ui(&mut self, ui: &mut Ui, doc: &mut Document, selection: &Selection) -> Option<String> {
        let mut said = None;
        self.hovered = ui.rect_contains_pointer(ui.max_rect());
        let narrow = self.narrow;
        ui.horizontal(|ui| {
            let hide = ui.small_button("hide").on_hover_text("Hide the timeline");
            mark(ui, "timeline:toggle", hide.rect);
            if hide.clicked() {
                self.open = false;
            }
            let play = ui
                .button(if self.playing { "Pause" } else { "Play" })
                .on_hover_text("Alt+A: play or pause (the wind and torque of the media move the noise)");
            mark(ui, "timeline:play", play.rect);
            if play.clicked() {
                self.playing = !self.playing;
            }
            let looping = ui
                .selectable_label(self.looping, "Loop")
                .on_hover_text("Loop: back to the first frame after the last");
            mark(ui, "timeline:loop", looping.rect);
            if looping.clicked() {
                self.looping = !self.looping;
            }
            let scene = doc.scene();
            let clock = scene.clock;
            let mut frame = clock.frame(scene.time).round().max(0.0) as u32;
            // Fixed width: a frame number growing a digit never shifts the bar under the
            // pointer.
            let r = ui
                .add_sized(
                    [84.0, 20.0],
                    egui::DragValue::new(&mut frame)
                        .range(0..=clock.last_frame())
                        .prefix("frame "),
                )
                .on_hover_text(format!(
                    "The frame at the scene time ({:.2} s); Left and Right step a frame, Up and Down go to the next or previous key",
                    scene.time
                ));
            mark(ui, "timeline:frame", r.rect);
            if r.changed() {
                doc.set_time(clock.seconds(frame));
            }
            let key = ui
                .button("Key")
                .on_hover_text("I: key the selection's place, size, turn and strength at this frame (the sun's with nothing selected); Alt+I deletes the keys here");
            mark(ui, "timeline:key", key.rect);
            if key.clicked() {
                said = Some(self.insert_keys(doc, selection));
            }
            let mut auto = doc.auto_key();
            let auto_r = ui
                .toggle_value(&mut auto, "Auto-key")
                .on_hover_text("Auto-key: every edit of a keyable value is keyed at this frame");
            mark(ui, "timeline:auto", auto_r.rect);
            if auto_r.changed() {
                doc.set_auto_key(auto);
            }
            if !narrow {
                self.jobs_ui(ui);
            }
            // The range and the rate at the right (or under it), the bar between.
            let right = if narrow { 0.0 } else { 230.0 };
            let bar_width = (ui.available_width() - right).max(60.0);
            said = self.bar(ui, doc, selection, bar_width).or(said.take());
            if !narrow {
                self.range_ui(ui, doc);
            }
        });
        if narrow {
            // The range first: the row's left corner keeps what was there (a click near the
            // view's corner must not start a job).
            ui.horizontal(|ui| {
                self.range_ui(ui, doc);
                ui.add_space(12.0);
                self.jobs_ui(ui);
            });
        }
        said
    }

    /// Cache and Record: the range rendered at full quality, for playback or to a file.
    fn jobs_ui(&mut self, ui: &mut Ui) {
        // A job that ended a moment ago: its button read "Stop" when the user aimed at it.
        let now = ui.input(|i| i.time);
        let frame = ui.ctx().cumulative_frame_nr();
        let shown_before = self.drawn_frame + 1 == frame;
        self.drawn_frame = frame;
        let running = [
            self.cache_progress.is_some(),
            self.record_progress.is_some(),
        ];
        let mut just_ended = [false; 2];
        for k in 0..2 {
            if self.ran[k] && !running[k] && shown_before {
                self.ended[k] = Some(now);
            }
            self.ran[k] = running[k];
            just_ended[k] = self.ended[k].is_some_and(|t| now - t < JUST_ENDED);
        }
        // Cached playback: the range rendered once at full quality, then played from it.
        let cache = match self.cache_progress {
            Some((done, of)) => ui
                .add_sized(
                    [84.0, 20.0],
                    egui::Button::new(format!("Stop {}%", 100 * done / of.max(1))),
                )
                .on_hover_text(format!("Caching the range: {done} of {of} frames; click to stop (the frames cached so far are kept)")),
            None => ui
                .add_sized([84.0, 20.0], egui::Button::new(if self.cache_kept > 0 {
                    format!("Cache ({})", self.cache_kept)
                } else {
                    "Cache".to_owned()
                }))
                .on_hover_text("Render every frame of the range at full quality once, then Play shows them at the frame rate (an edit re-renders only the frames it changes)"),
        };
        mark(ui, "timeline:cache", cache.rect);
        if cache.clicked() {
            if self.cache_progress.is_some() {
                self.cache_cancel = true;
            } else if !just_ended[0] {
                self.cache_asked = true;
            }
        }
        // Record: the range at full quality into a video (or PNGs), the Export group's job.
        let record = match self.record_progress {
            Some(_) => ui
                .add_sized([72.0, 20.0], egui::Button::new(self.record_label()))
                .on_hover_text("Recording the range; click to stop (nothing is saved)"),
            None => ui
                .add_enabled_ui(!self.record_blocked, |ui| {
                    ui.add_sized([72.0, 20.0], egui::Button::new(self.record_label()))
                })
                .inner
                .on_hover_text(crate::ui::platform::RECORD_HINT)
                .on_disabled_hover_text("An export is under way: record when it is done"),
        };
        mark(ui, "timeline:record", record.rect);
        if record.clicked() {
            if self.record_progress.is_some() {
                self.record_cancel = true;
            } else if !just_ended[1] {
                self.record_asked = true;
            }
        }
    }

    /// The frame range and the rate (one undo step each drag).
    fn range_ui(&mut self, ui: &mut Ui, doc: &mut Document) {
        let mut clock = doc.scene().clock;
        let last = clock.last_frame();
        let mut changed = ui
            .add(egui::DragValue::new(&mut clock.start).range(0..=last))
            .on_hover_text("First frame of the range")
            .changed();
        ui.label("–");
        changed |= ui
            .add(egui::DragValue::new(&mut clock.end).range(0..=last))
            .on_hover_text("Last frame of the range (inclusive)")
            .changed();
        let rate = crate::limits::FRAME_RATE;
        changed |= ui
            .add(
                egui::DragValue::new(&mut clock.fps)
                    .speed(0.1)
                    .suffix(" fps")
                    .range(rate.min as f32..=rate.max as f32),
            )
            .on_hover_text(rate.tip)
            .changed();
        if changed {
            if clock.end < clock.start {
                clock.end = clock.start;
            }
            doc.apply(Edit::SetClock(clock), Some("clock"));
        }
    }

    /// The scrub bar with its ticks, the playhead and the shown keys.
    fn bar(
        &mut self,
        ui: &mut Ui,
        doc: &mut Document,
        selection: &Selection,
        width: f32,
    ) -> Option<String> {
        let (rect, response) =
            ui.allocate_exact_size(vec2(width, BAR_HEIGHT), Sense::click_and_drag());
        mark(ui, "timeline:scrub", rect);
        let scene = doc.scene();
        let clock = scene.clock;
        let (start, end) = (clock.start as f32, clock.end.max(clock.start + 1) as f32);
        let inner = rect.shrink2(vec2(8.0, 0.0));
        let x_of = |frame: f32| inner.left() + (frame - start) / (end - start) * inner.width();
        let frame_of = |x: f32| start + (x - inner.left()) / inner.width() * (end - start);
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 3.0, Color32::from_gray(32));
        // Ticks at a step that keeps labels apart.
        let per_px = (end - start) / inner.width().max(1.0);
        let step = [
            1u32, 2, 5, 10, 12, 24, 48, 60, 120, 240, 600, 1200, 2400, 6000, 12000,
        ]
        .into_iter()
        .find(|s| *s as f32 / per_px >= 44.0)
        .unwrap_or(24_000);
        let font = egui::FontId::proportional(10.0);
        let mut f = clock.start.div_ceil(step) * step;
        while f as f32 <= end {
            let x = x_of(f as f32);
            painter.line_segment(
                [
                    Pos2::new(x, rect.bottom() - 6.0),
                    Pos2::new(x, rect.bottom()),
                ],
                Stroke::new(1.0, Color32::from_gray(110)),
            );
            // A label that would run past the bar's end is left out.
            if x + 24.0 < rect.right() {
                painter.text(
                    Pos2::new(x + 2.0, rect.top() + 1.0),
                    egui::Align2::LEFT_TOP,
                    f.to_string(),
                    font.clone(),
                    Color32::from_gray(140),
                );
            }
            f += step;
        }
        // The shown channels' keys.
        let channels = shown_channels(scene, selection, self.shot_view);
        let times = scene.animation.times(Some(&channels));
        self.selected.retain(|t| times.contains(t));
        self.keys_y = key_y(rect);
        self.drawn = times
            .iter()
            .map(|t| (*t, x_of(clock.frame(*t) as f32)))
            .collect();
        let mut said = None;
        // A press on a diamond takes it; anywhere else scrubs.
        if response.drag_started() || response.clicked() {
            let shift = ui.input(|i| i.modifiers.shift);
            // Where the press was: a drag starts once the pointer has gone a few points, by
            // then off a diamond 10 points wide.
            let origin = ui.input(|i| i.pointer.press_origin());
            if let Some(p) = origin.or(response.interact_pointer_pos()) {
                let on_keys = p.y >= rect.top() + RULER;
                let hit = self
                    .drawn
                    .iter()
                    .filter(|(_, x)| on_keys && (x - p.x).abs() <= DIAMOND_REACH)
                    .min_by(|a, b| (a.1 - p.x).abs().total_cmp(&(b.1 - p.x).abs()))
                    .map(|(t, _)| *t);
                match hit {
                    Some(t) => {
                        if shift {
                            if let Some(i) = self.selected.iter().position(|s| *s == t) {
                                self.selected.remove(i);
                            } else {
                                self.selected.push(t);
                            }
                        } else if !self.selected.contains(&t) {
                            self.selected = vec![t];
                        }
                        if response.drag_started() && self.selected.contains(&t) {
                            self.drag = Some(KeyDrag {
                                from: scene.animation.clone(),
                                times: self.selected.clone(),
                                x0: p.x,
                                moved: 0,
                            });
                        }
                    }
                    None => {
                        if !shift {
                            self.selected.clear();
                        }
                        // A drag from an empty place of the keys' row draws a box.
                        if on_keys && response.drag_started() {
                            self.boxing = Some((p.x, self.selected.clone()));
                        }
                    }
                }
            }
        }
        // The release's frame counts too: pointer events come faster than frames, and the
        // last move before a release often shares its frame.
        let moving = response.dragged() || response.drag_stopped();
        if let Some(drag) = &mut self.drag {
            if let Some(p) = response.interact_pointer_pos()
                && moving
            {
                let moved = ((p.x - drag.x0) * per_px).round() as i64;
                if moved != drag.moved {
                    drag.moved = moved;
                    let (animation, times) =
                        retimed(&drag.from, &drag.times, &channels, &clock, moved);
                    doc.apply(
                        Edit::SetAnimation(animation, "retime keys"),
                        Some("retime keys"),
                    );
                    self.selected = times;
                }
            }
            if response.drag_stopped() {
                self.drag = None;
                doc.end_merge();
            }
        } else if let Some((x0, base)) = &self.boxing {
            // The keys whose diamonds lie between the press and the pointer are selected.
            if let Some(p) = response.interact_pointer_pos() {
                let (lo, hi) = (x0.min(p.x), x0.max(p.x));
                let mut selected = base.clone();
                for (t, x) in &self.drawn {
                    if (lo - DIAMOND_REACH..=hi + DIAMOND_REACH).contains(x)
                        && !selected.contains(t)
                    {
                        selected.push(*t);
                    }
                }
                let top = rect.top() + RULER;
                painter.rect_filled(
                    egui::Rect::from_x_y_ranges(lo..=hi, top..=rect.bottom()),
                    0.0,
                    Color32::from_rgba_unmultiplied(120, 160, 255, 40),
                );
                self.selected = selected;
            }
            if response.drag_stopped() || !moving {
                self.boxing = None;
            }
        } else if (moving || response.clicked())
            && let Some(p) = response.interact_pointer_pos()
        {
            let frame = frame_of(p.x).round().clamp(start, end) as u32;
            doc.set_time(clock.seconds(frame));
        }
        // Ease of the selected keys by right-click.
        response.context_menu(|ui| {
            if self.selected.is_empty() {
                ui.label("Click a key first");
                return;
            }
            for ease in Ease::ALL {
                if ui.button(ease.label()).clicked() {
                    let mut animation = doc.scene().animation.clone();
                    let mut any = false;
                    for t in &self.selected {
                        any |= animation.set_ease(&channels, *t, ease);
                    }
                    if any {
                        doc.apply(
                            Edit::SetAnimation(animation, "change the ease of keys"),
                            None,
                        );
                    }
                    ui.close();
                }
            }
            if ui.button("Delete keys").clicked() {
                said = Some(self.delete_keys(doc, selection));
                ui.close();
            }
        });
        let painter = ui.painter_at(rect);
        for (t, x) in &self.drawn {
            let on = self.selected.contains(t);
            let c = Pos2::new(*x, key_y(rect));
            let r = 5.0;
            let diamond = vec![
                c + vec2(0.0, -r),
                c + vec2(r, 0.0),
                c + vec2(0.0, r),
                c + vec2(-r, 0.0),
            ];
            painter.add(egui::Shape::convex_polygon(
                diamond,
                if on {
                    Color32::from_rgb(255, 170, 40)
                } else {
                    Color32::from_gray(220)
                },
                Stroke::new(1.0, Color32::BLACK),
            ));
        }
        // The playhead.
        let now = doc.scene().clock.frame(doc.scene().time) as f32;
        let x = x_of(now.clamp(start, end));
        painter.line_segment(
            [Pos2::new(x, rect.top()), Pos2::new(x, rect.bottom())],
            Stroke::new(2.0, Color32::from_rgb(90, 160, 255)),
        );
        if response.hovered() && self.drag.is_none() {
            response.on_hover_text(
                "Drag to scrub the whole range (on the numbers even over a key); drag a key to retime it, Shift+click to select several, right-click for its ease, Delete here removes the selected keys",
            );
        }
        said
    }
}

/// The height the keys are drawn at on the bar `rect`, under its ruler.
fn key_y(rect: egui::Rect) -> f32 {
    rect.top() + RULER + (rect.height() - RULER) / 2.0
}

/// `from` with the keys of `channels` at `times` moved by `frames` (whole frames), and the
/// times they moved to. Keys go in the order that never lands one on another still to move.
fn retimed(
    from: &Animation,
    times: &[f32],
    channels: &[Channel],
    clock: &Clock,
    frames: i64,
) -> (Animation, Vec<f32>) {
    let mut animation = from.clone();
    // The whole selection moves by one amount, held within the clock's frames, so no key is
    // pushed onto another at an end.
    let frames_of: Vec<i64> = times
        .iter()
        .map(|t| clock.frame(*t).round() as i64)
        .collect();
    let (lo, hi) = (
        frames_of.iter().copied().min().unwrap_or(0),
        frames_of.iter().copied().max().unwrap_or(0),
    );
    let frames = frames.clamp(-lo, (clock.last_frame() as i64 - hi).max(-lo));
    let mut order: Vec<f32> = times.to_vec();
    order.sort_by(f32::total_cmp);
    if frames > 0 {
        order.reverse();
    }
    let mut moved = Vec::with_capacity(order.len());
    for t in order {
        let frame = (clock.frame(t).round() as i64 + frames).max(0);
        let to = clock.seconds(frame.min(u32::MAX as i64) as u32);
        animation.retime(channels, t, to);
        moved.push(to);
    }
    (animation, moved)
}

/// Where the strip's selected keys and drawn diamonds are, for the page state.
pub fn state(timeline: &Timeline, doc: &Document) -> serde_json::Value {
    serde_json::json!({
        "open": timeline.open,
        "playing": timeline.playing,
        "looping": timeline.looping,
        "auto_key": doc.auto_key(),
        "frame": doc.scene().clock.frame(doc.scene().time),
        "ticked_s": timeline.ticked_s,
        "stalled_s": timeline.stalled_s,
        "keys": timeline.drawn.iter().map(|(t, x)| serde_json::json!({"t": t, "x": x, "y": timeline.keys_y})).collect::<Vec<_>>(),
        "selected_keys": timeline.selected,
        "key_count": doc.scene().animation.key_count(),
        "record": timeline.record_label(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Ellipsoid, Preset};
    use glam::Vec3;
    use std::sync::Arc;

    #[test]
    fn playing_advances_the_time_without_undo_steps_and_loops_within_the_range() {
        let mut doc = Document::new(Scene::default());
        let mut timeline = Timeline::default();
        assert!(!timeline.tick(&mut doc, 0.1), "paused: nothing moves");
        timeline.playing = true;
        timeline.speed = 2.0;
        let time = doc.revisions().time;
        for _ in 0..10 {
            timeline.tick(&mut doc, 0.1);
        }
        assert!(
            (doc.scene().time - 2.0).abs() < 1e-5,
            "{}",
            doc.scene().time
        );
        assert_eq!(doc.undo_len(), 0);
        assert!(doc.revisions().time > time, "the image knows to change");
        // A stalled frame does not jump the clock.
        timeline.tick(&mut doc, 30.0);
        assert!(doc.scene().time < 3.1);
        assert!(
            (timeline.ticked_s - 31.0).abs() < 1e-4,
            "{}",
            timeline.ticked_s
        );
        assert!(
            (timeline.stalled_s - 29.5).abs() < 1e-4,
            "the stall is counted"
        );
        // Looping: the last frame lasts a frame, and the time past it carries on from the
        // first (none is lost at the wrap: a loop takes its frames' time exactly).
        timeline.looping = true;
        let clock = doc.scene().clock;
        let end = clock.seconds(clock.end);
        doc.set_time(end + 0.01);
        timeline.tick(&mut doc, 0.01);
        assert!(
            (doc.scene().time - (end + 0.03)).abs() < 1e-5,
            "still the last frame"
        );
        timeline.tick(&mut doc, 0.1);
        let past = end + 0.23 - clock.seconds(clock.end + 1);
        assert!(
            (doc.scene().time - (clock.seconds(clock.start) + past)).abs() < 1e-4,
            "{} s, not {past}",
            doc.scene().time
        );
    }

    #[test]
    fn a_click_aimed_at_stop_as_its_job_ends_starts_nothing() {
        let ctx = egui::Context::default();
        let mut doc = Document::new(Scene::default());
        let selection = Selection::default();
        let mut timeline = Timeline::default();
        let mut frame = |timeline: &mut Timeline, t: f64, events: Vec<egui::Event>| {
            let raw = egui::RawInput {
                time: Some(t),
                events,
                screen_rect: Some(egui::Rect::from_min_size(
                    egui::Pos2::ZERO,
                    egui::vec2(1280.0, 800.0),
                )),
                ..Default::default()
            };
            let mut out = ctx.run_ui(raw, |ui| {
                timeline.fit(1280.0);
                timeline.ui(ui, &mut doc, &selection);
            });
            out.textures_delta.clear();
            crate::ui::widgets::take_marks(&ctx)
        };
        let button = |at: egui::Pos2, pressed| egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        };
        for (name, job) in [("timeline:cache", 0), ("timeline:record", 1)] {
            let run = |timeline: &mut Timeline, on: bool| {
                if job == 0 {
                    timeline.cache_progress = on.then_some((7, 10));
                } else {
                    timeline.record_progress = on.then_some(0.7);
                }
            };
            let asked = |timeline: &Timeline| [timeline.cache_asked, timeline.record_asked][job];
            let t0 = 10.0 * job as f64;
            run(&mut timeline, true);
            let [x, y, w, h] = frame(&mut timeline, t0, Vec::new())[name];
            let at = egui::pos2(x + w / 2.0, y + h / 2.0);
            frame(
                &mut timeline,
                t0 + 0.05,
                vec![egui::Event::PointerMoved(at)],
            );
            // Pressed on "Stop"; the job ends before the release.
            frame(&mut timeline, t0 + 0.1, vec![button(at, true)]);
            run(&mut timeline, false);
            frame(&mut timeline, t0 + 0.15, vec![button(at, false)]);
            frame(&mut timeline, t0 + 0.2, Vec::new());
            assert!(!asked(&timeline), "{name}: the click meant Stop");
            // The same click a moment later starts the job (the baseline).
            frame(&mut timeline, t0 + 2.0, vec![button(at, true)]);
            frame(&mut timeline, t0 + 2.05, vec![button(at, false)]);
            assert!(
                asked(&timeline),
                "{name}: a click on the button's own label"
            );
        }
    }

    #[test]
    fn i_keys_the_selection_and_delete_removes_its_keys() {
        let mut scene = Scene::preset(Preset::Empty);
        scene
            .ellipsoids
            .push(Arc::new(Ellipsoid::new(Vec3::ZERO, Vec3::ONE)));
        scene.settle();
        let mut doc = Document::new(scene);
        let mut selection = Selection::default();
        selection.set(Item::Ellipsoid(0));
        let mut timeline = Timeline::default();
        let said = timeline.insert_keys(&mut doc, &selection);
        assert!(said.starts_with("Keyed the selection"), "{said}");
        assert_eq!(doc.scene().animation.key_count(), 4);
        // Again at the same values: nothing new, no undo step.
        let steps = doc.undo_len();
        timeline.insert_keys(&mut doc, &selection);
        assert_eq!(doc.undo_len(), steps);
        // Nothing selected: the sun.
        let said = timeline.insert_keys(&mut doc, &Selection::default());
        assert!(said.contains("the sun"), "{said}");
        assert_eq!(doc.scene().animation.key_count(), 7);
        // Retiming the ellipsoid's key by 24 frames moves its four keys, not the sun's.
        let channels = shown_channels(doc.scene(), &selection, false);
        let (a, times) = retimed(
            &doc.scene().animation,
            &[0.0],
            &channels,
            &doc.scene().clock,
            24,
        );
        assert_eq!(times, vec![doc.scene().clock.seconds(24)]);
        assert_eq!(a.times(Some(&channels)), times);
        assert_eq!(a.times(None).len(), 2);
        // Dragged left past frame 0, the selection stops there together: no key lands on
        // another.
        let (a, times) = retimed(&a, &times, &channels, &doc.scene().clock, -100);
        assert_eq!(times, vec![0.0]);
        assert_eq!(a.key_count(), 7);
        timeline.selected.clear();
        let said = timeline.delete_keys(&mut doc, &selection);
        assert_eq!(said, "Deleted 4 keys");
        assert_eq!(doc.scene().animation.key_count(), 3);
        // With a media value keyed, I with nothing selected keys what changed of it and of
        // the sun, and says so (it used to say "the sun" alone).
        let opacity = Channel::Media {
            property: crate::scene::MediaProperty::Opacity,
        };
        let mut animation = doc.scene().animation.clone();
        animation.key(opacity, 0.0, opacity.get(doc.scene()).unwrap());
        doc.apply(Edit::SetAnimation(animation, "key"), None);
        doc.set_time(doc.scene().clock.seconds(24));
        // Nothing changed since the keys: nothing to key, no undo step.
        let steps = doc.undo_len();
        let said = timeline.insert_keys(&mut doc, &Selection::default());
        assert!(
            said.starts_with("Nothing keyed: the sun unchanged"),
            "{said}"
        );
        assert_eq!(doc.undo_len(), steps);
        // The opacity and the sun's azimuth changed at frame 24: those two are keyed.
        let mut render = doc.scene().render.clone();
        render.opacity *= 0.5;
        doc.apply(Edit::SetRender(render), None);
        let mut light = doc.scene().light.clone();
        light.sun_azimuth_deg += 30.0;
        doc.apply(Edit::SetLight(light), None);
        let before = doc.scene().animation.key_count();
        let said = timeline.insert_keys(&mut doc, &Selection::default());
        assert!(
            said.starts_with("Keyed the sun and 1 other keyed value at frame 24 (2 values)"),
            "{said}"
        );
        assert_eq!(doc.scene().animation.key_count(), before + 2);
        // The ellipsoid, its keys deleted above, is keyed whole again; then moved, only its
        // centre is keyed.
        doc.set_time(doc.scene().clock.seconds(48));
        let said = timeline.insert_keys(&mut doc, &selection);
        assert!(said.ends_with("(4 values)"), "{said}");
        doc.set_time(doc.scene().clock.seconds(72));
        let mut moved = doc.scene().ellipsoids.clone();
        Arc::make_mut(&mut moved[0]).center.x += 2.0;
        doc.apply(Edit::SetEllipsoids(moved), None);
        let said = timeline.insert_keys(&mut doc, &selection);
        assert!(said.ends_with("(1 value)"), "{said}");
    }
}
