//! Blender-like camera controls for the viewport: drag orbits, Shift/right/middle drag pans,
//! wheel and pinch zoom, F frames the cloud. Mouse, pen and touch all arrive as pointer events.

use egui::{PointerButton, Response};
use glam::Vec2;

use crate::scene::OrbitCamera;

/// Applies this frame's camera input. `orbit_with_primary` is false while a drawing tool owns
/// the primary button (then Alt+drag or two fingers still orbit); `quick` says whose a drag is
/// that egui never saw, one pressed and released within one long frame (or with the press's
/// frame moving too little for a drag): `None`, not the camera's; `Some(primary)`, the
/// camera's, the primary button's too where `primary` ([`crate::ui::tools::Toolbox::quick_drags`]).
/// Returns whether the camera moved.
///
/// A drag moves the camera by the pointer's whole path, however few frames it spans: egui
/// recognises a drag a few pixels after its press and reports no motion in the frame of its
/// release, so on a slow adapter (frames of 0.3 s) a drag over three frames used to move the
/// camera a third of the way, and one within a frame not at all. The motion is taken from the
/// press, and up to the release, from this frame's events.
pub fn handle(
    ui: &egui::Ui,
    response: &Response,
    camera: &mut OrbitCamera,
    orbit_with_primary: bool,
    quick: Option<bool>,
) -> bool {
    let before = camera.clone();
    let rect = response.rect;
    let (modifiers, multi_touch, scroll, zoom, origin, latest, presses) = ui.input(|i| {
        (
            i.modifiers,
            i.multi_touch(),
            i.smooth_scroll_delta,
            i.zoom_delta(),
            i.pointer.press_origin(),
            i.pointer.latest_pos(),
            presses(&i.events),
        )
    });
    // Where the camera's drag under way was last accounted.
    let memory = response.id.with("camera drag");
    let last: Option<egui::Pos2> = ui.ctx().data(|d| d.get_temp(memory)).flatten();
    // A press over the view in an earlier frame that egui had not yet taken for a drag.
    let pressed_memory = response.id.with("camera press");
    let pending: Option<(PointerButton, egui::Pos2)> =
        ui.ctx().data(|d| d.get_temp(pressed_memory)).flatten();
    let over_view = |at: egui::Pos2| {
        rect.contains(at)
            && ui.ctx().layer_id_at(at) == Some(response.layer_id)
            && !super::sun_handle::orb_area(rect).is_some_and(|area| area.contains(at))
    };
    let rules = Rules {
        modifiers,
        orbit_with_primary,
    };
    // (Of two buttons held, a pan wins, as it always did.)
    let dragged = [
        PointerButton::Secondary,
        PointerButton::Middle,
        PointerButton::Primary,
    ]
    .into_iter()
    .find(|&b| response.dragged_by(b) && rules.mode(b).is_some());
    let stopped = [
        PointerButton::Secondary,
        PointerButton::Middle,
        PointerButton::Primary,
    ]
    .into_iter()
    .find(|&b| response.drag_stopped_by(b));
    let mut next = None;
    let gesture: Option<(Mode, Vec2)> = if let Some(button) = dragged {
        // From where the last frame left it; in the frame egui takes it for a drag, from the
        // press (the pixels before egui knew it for one); else (a drag that becomes the
        // camera's midway, as Alt is pressed) this frame's motion alone.
        let from = if response.drag_started_by(button) {
            pending.map(|p| p.1).or(origin)
        } else {
            last.or_else(|| latest.map(|l| l - ui.input(|i| i.pointer.delta())))
        };
        let to = latest;
        // (The pointer gone from the page mid-drag keeps where it was last seen.)
        next = to.or(last);
        match (from, to) {
            (Some(a), Some(b)) => rules
                .mode(button)
                .map(|m| (m, Vec2::new(b.x - a.x, b.y - a.y))),
            _ => None,
        }
    } else if let (Some(button), Some(from)) = (stopped, last) {
        // Released this frame: the way from the last frame's position to the release.
        let to = presses
            .iter()
            .rev()
            .find(|p| p.button == button && p.released.is_some())
            .and_then(|p| p.released)
            .or(latest);
        to.zip(rules.mode(button))
            .map(|(to, m)| (m, Vec2::new(to.x - from.x, to.y - from.y)))
    } else if last.is_none() {
        // Released within this frame, pressed over the view in it or the frame before, and
        // never a drag to egui.
        presses
            .iter()
            .map(|p| match (p.earlier, pending) {
                (true, Some((button, at))) if button == p.button => Press { pressed: at, ..*p },
                _ => *p,
            })
            .find(|p| over_view(p.pressed))
            .and_then(|p| {
                let to = p.released?;
                let primary = quick?;
                let rules = Rules {
                    modifiers: p.modifiers,
                    ..rules
                };
                if p.button == PointerButton::Primary
                    && !(primary && orbit_with_primary)
                    && !p.modifiers.alt
                {
                    return None;
                }
                let mode = rules.mode(p.button)?;
                let d = Vec2::new(to.x - p.pressed.x, to.y - p.pressed.y);
                (d.length() > 6.0).then_some((mode, d))
            })
    } else {
        None
    };
    // A press over the view still down at the frame's end, which egui may not take for a
    // drag before its release.
    let still_down = presses
        .iter()
        .rev()
        .find(|p| p.released.is_none() && over_view(p.pressed))
        .map(|p| (p.button, p.pressed));
    ui.ctx().data_mut(|d| {
        d.insert_temp(memory, next);
        d.insert_temp(pressed_memory, still_down.filter(|_| next.is_none()));
    });

    if let Some(touch) =
        multi_touch.filter(|_| response.hovered() || response.is_pointer_button_down_on())
    {
        // Two fingers: orbit with their common motion; pinch arrives as zoom below.
        let t = touch.translation_delta;
        camera.orbit(Vec2::new(t.x, t.y));
    } else if let Some((mode, delta)) = gesture {
        match mode {
            Mode::Pan => camera.pan(delta, rect.height()),
            Mode::Orbit => camera.orbit(delta),
        }
    }
    if response.hovered() {
        if scroll.y != 0.0 {
            camera.zoom((-scroll.y * 0.0025).exp());
        }
        if zoom != 1.0 {
            camera.zoom(1.0 / zoom);
        }
    }
    *camera != before
}

/// What a drag does to the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Orbit,
    Pan,
}

/// Which button drags what: the primary orbits (Shift: pans) where no drawing tool owns it,
/// Alt+primary orbits always, the secondary pans, the middle orbits while a drawing tool owns
/// the primary (else it pans).
#[derive(Clone, Copy)]
struct Rules {
    modifiers: egui::Modifiers,
    orbit_with_primary: bool,
}

impl Rules {
    fn mode(self, button: PointerButton) -> Option<Mode> {
        let shift = self.modifiers.shift;
        let middle_orbits = !self.orbit_with_primary && !shift;
        match button {
            PointerButton::Secondary => Some(Mode::Pan),
            PointerButton::Middle if middle_orbits => Some(Mode::Orbit),
            PointerButton::Middle => Some(Mode::Pan),
            PointerButton::Primary if self.orbit_with_primary && shift => Some(Mode::Pan),
            PointerButton::Primary if self.orbit_with_primary || self.modifiers.alt => {
                Some(Mode::Orbit)
            }
            _ => None,
        }
    }
}

/// A press in this frame's events: where, which button, and where it was released in the same
/// frame (if it was); or a release whose press came in an earlier frame (`earlier`).
#[derive(Clone, Copy)]
struct Press {
    button: PointerButton,
    modifiers: egui::Modifiers,
    pressed: egui::Pos2,
    released: Option<egui::Pos2>,
    earlier: bool,
}

/// The presses of this frame's events, in order, or, for a release whose press came in an
/// earlier frame, a press at the release with that release.
fn presses(events: &[egui::Event]) -> Vec<Press> {
    let mut out: Vec<Press> = Vec::new();
    for e in events {
        if let egui::Event::PointerButton {
            pos,
            button,
            pressed,
            modifiers,
        } = *e
        {
            if pressed {
                out.push(Press {
                    button,
                    modifiers,
                    pressed: pos,
                    released: None,
                    earlier: false,
                });
            } else if let Some(p) = out
                .iter_mut()
                .rev()
                .find(|p| p.button == button && p.released.is_none())
            {
                p.released = Some(pos);
            } else {
                out.push(Press {
                    button,
                    modifiers,
                    pressed: pos,
                    released: Some(pos),
                    earlier: true,
                });
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::{Event, Modifiers, RawInput, Sense, pos2};

    /// The default camera after a drag by `button` from `from`, 160 px right and 60 px down:
    /// its press, 40 moves and release, split into frames of `sizes` events 0.3 s apart (a slow
    /// adapter's), with a frame with the pointer over the view first and two idle after.
    fn dragged_in(
        button: PointerButton,
        from: egui::Pos2,
        sizes: &[usize],
        primary_at_rest: bool,
    ) -> OrbitCamera {
        dragged_in_with(button, from, sizes, primary_at_rest, None)
    }

    /// [`dragged_in`], the pointer leaving the page at the end of frame `gone` (of the drag's)
    /// and coming back where it left.
    fn dragged_in_with(
        button: PointerButton,
        from: egui::Pos2,
        sizes: &[usize],
        primary_at_rest: bool,
        gone: Option<usize>,
    ) -> OrbitCamera {
        let rect = crate::ui::test_view();
        let at = |i: usize| from + egui::vec2(4.0 * i as f32, 1.5 * i as f32);
        let press = |pressed, i| Event::PointerButton {
            pos: at(i),
            button,
            pressed,
            modifiers: Modifiers::NONE,
        };
        let mut events = vec![press(true, 0)];
        events.extend((1..=40).map(|i| Event::PointerMoved(at(i))));
        events.push(press(false, 40));
        let mut chunks = vec![vec![Event::PointerMoved(at(0))]];
        let mut rest = &events[..];
        for (k, &n) in sizes.iter().enumerate() {
            let (chunk, after) = rest.split_at(n.min(rest.len()));
            let mut chunk = chunk.to_vec();
            if gone == Some(k) {
                chunk.push(Event::PointerGone);
            }
            chunks.push(chunk);
            rest = after;
        }
        assert!(rest.is_empty());
        chunks.extend([Vec::new(), Vec::new()]);
        let ctx = egui::Context::default();
        let mut camera = OrbitCamera::default();
        for (frame, events) in chunks.into_iter().enumerate() {
            let raw = RawInput {
                screen_rect: Some(rect),
                time: Some(frame as f64 * 0.3),
                events,
                ..Default::default()
            };
            let mut output = ctx.run_ui(raw, |ui| {
                let response = ui.allocate_rect(rect, Sense::click_and_drag());
                handle(ui, &response, &mut camera, true, Some(primary_at_rest));
            });
            output.textures_delta.clear();
        }
        camera
    }

    /// [`dragged_in`] from the view's centre, over `frames` frames of equal share.
    fn dragged(button: PointerButton, frames: usize) -> OrbitCamera {
        let n = 42usize.div_ceil(frames);
        let mut sizes = vec![n; 42 / n];
        if 42 % n > 0 {
            sizes.push(42 % n);
        }
        dragged_in(button, pos2(640.0, 400.0), &sizes, true)
    }

    #[test]
    fn a_drag_moves_the_camera_as_far_however_few_frames_it_spans() {
        // The baseline: the camera orbited by the whole drag, 160 × 60 px.
        let mut whole = OrbitCamera::default();
        whole.orbit(Vec2::new(160.0, 60.0));
        let mut panned = OrbitCamera::default();
        panned.pan(Vec2::new(160.0, 60.0), 800.0);
        let orbited_as_whole = |c: &OrbitCamera| {
            (c.yaw_deg - whole.yaw_deg).abs() < 1e-3 && (c.pitch_deg - whole.pitch_deg).abs() < 1e-3
        };
        let mut wrong = Vec::new();
        for frames in [42, 10, 3, 2, 1] {
            let orbited = dragged(PointerButton::Primary, frames);
            if !orbited_as_whole(&orbited) {
                wrong.push(format!(
                    "orbit over {frames} frames: yaw {} pitch {}, not {} {}",
                    orbited.yaw_deg, orbited.pitch_deg, whole.yaw_deg, whole.pitch_deg
                ));
            }
            let moved = dragged(PointerButton::Secondary, frames);
            if !moved.target.abs_diff_eq(panned.target, 1e-4) {
                wrong.push(format!(
                    "pan over {frames} frames: {} not {}",
                    moved.target, panned.target
                ));
            }
        }
        // Pressed with a pixel of motion in one frame, the rest and the release in the next
        // (egui never takes it for a drag).
        let centre = pos2(640.0, 400.0);
        let late = dragged_in(PointerButton::Primary, centre, &[2, 40], true);
        if !orbited_as_whole(&late) {
            wrong.push(format!(
                "press, then the rest: yaw {} pitch {}",
                late.yaw_deg, late.pitch_deg
            ));
        }
        // The pointer gone from the page midway (dragged off the canvas and back): the camera
        // goes on from where it was, no jump by the path so far.
        let gone = dragged_in_with(
            PointerButton::Primary,
            centre,
            &[10, 10, 10, 12],
            true,
            Some(2),
        );
        if !orbited_as_whole(&gone) {
            wrong.push(format!(
                "pointer gone: yaw {} pitch {}",
                gone.yaw_deg, gone.pitch_deg
            ));
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
        // Where a tool owns the primary button's drags (a box selection in Move), a drag within
        // one frame is not the camera's; nor is one begun on the sun's orb.
        let rest = OrbitCamera::default();
        assert_eq!(
            dragged_in(PointerButton::Primary, centre, &[42], false),
            rest
        );
        let (orb, _) = crate::ui::sun_handle::orb(crate::ui::test_view()).unwrap();
        assert_eq!(dragged_in(PointerButton::Primary, orb, &[42], true), rest);
    }
}
