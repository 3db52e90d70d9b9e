//! Keyboard shortcuts, taken from a frame's events in the order they were pressed.
//!
//! On a slow frame several key presses arrive together (Ctrl+Z then Ctrl+S, say). Asking egui
//! "was Ctrl+S pressed?" for each shortcut in turn would act on them in the order the code asks,
//! not the order the person pressed them, and would count two presses of one key as one. Here
//! the frame's key events are walked once, in order, and each press becomes one [`Shortcut`].
//! Presses that came after a pointer button in the same frame are kept for the end of the frame
//! ([`Pressed::after_pointer`]), after the view has taken that button: a stroke released and
//! saved within one frame is saved with the stroke.

use egui::{Event, Key, Modifiers};

use super::tool::Tool;
use super::transform::Axis;
use crate::scene::StandardView;

/// What one key press asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shortcut {
    /// Ctrl+Z.
    Undo,
    /// Ctrl+Shift+Z or Ctrl+Y.
    Redo,
    /// Ctrl+S.
    Save,
    /// Ctrl+Shift+S: the name field first.
    SaveAs,
    /// Ctrl+O.
    Open,
    /// Ctrl+L.
    CopyLink,
    /// Ctrl+E: export with the Export group's settings.
    Export,
    /// F: frame the selection (or the cloud).
    Frame,
    /// N: hide or show the side panel.
    TogglePanel,
    /// Alt+A: play or pause.
    PlayPause,
    /// 1, 3, 7 (Ctrl: the opposite side).
    View(StandardView),
    /// 5: orthographic on or off.
    Orthographic,
    /// V, D, C, E, G, R, S: pick a tool.
    Tool(Tool),
    /// Ctrl+D: duplicate the selection.
    Duplicate,
    /// Shift+H: hide the selected item.
    HideSelected,
    /// Alt+H: show every hidden item.
    ShowAll,
    /// H: hide or show strokes and grids.
    ToggleGuides,
    /// K: show or hide the selected outline's skeleton.
    ToggleSkeleton,
    /// Q: new outlines behind the cloud, or in front again.
    ToggleBehind,
    /// Esc: cancel a drag or stroke, or clear the selection.
    Escape,
    /// Delete: delete the selection.
    Delete,
    /// B: the next drag draws a selection box.
    BoxSelect,
    /// X, Y, Z: lock the Move, Rotate or Scale tool to that axis (again: free).
    Lock(Axis),
}

/// Every shortcut with its key, most specific first: egui matches modifiers logically (an extra
/// Shift or Alt still matches), so Ctrl+Shift+Z must be tried before Ctrl+Z and Shift+H before H.
const TABLE: &[(Modifiers, Key, Shortcut)] = {
    use Shortcut as S;
    const CMD: Modifiers = Modifiers::COMMAND;
    const CMD_SHIFT: Modifiers = Modifiers::COMMAND.plus(Modifiers::SHIFT);
    const NONE: Modifiers = Modifiers::NONE;
    &[
        (CMD_SHIFT, Key::Z, S::Redo),
        (CMD, Key::Y, S::Redo),
        (CMD, Key::Z, S::Undo),
        (CMD_SHIFT, Key::S, S::SaveAs),
        (CMD, Key::S, S::Save),
        (CMD, Key::O, S::Open),
        (CMD, Key::L, S::CopyLink),
        (CMD, Key::E, S::Export),
        (CMD, Key::D, S::Duplicate),
        (CMD, Key::Num1, S::View(StandardView::Back)),
        (CMD, Key::Num3, S::View(StandardView::Left)),
        (CMD, Key::Num7, S::View(StandardView::Bottom)),
        (Modifiers::ALT, Key::A, S::PlayPause),
        (Modifiers::SHIFT, Key::H, S::HideSelected),
        (Modifiers::ALT, Key::H, S::ShowAll),
        (NONE, Key::F, S::Frame),
        (NONE, Key::N, S::TogglePanel),
        (NONE, Key::Num1, S::View(StandardView::Front)),
        (NONE, Key::Num3, S::View(StandardView::Right)),
        (NONE, Key::Num7, S::View(StandardView::Top)),
        (NONE, Key::Num5, S::Orthographic),
        (NONE, Key::V, S::Tool(Tool::Navigate)),
        (NONE, Key::D, S::Tool(Tool::Sketch)),
        (NONE, Key::C, S::Tool(Tool::Cut)),
        (NONE, Key::E, S::Tool(Tool::Ellipsoid)),
        (NONE, Key::G, S::Tool(Tool::Move)),
        (NONE, Key::R, S::Tool(Tool::Rotate)),
        (NONE, Key::S, S::Tool(Tool::Scale)),
        (NONE, Key::H, S::ToggleGuides),
        (NONE, Key::K, S::ToggleSkeleton),
        (NONE, Key::Q, S::ToggleBehind),
        (NONE, Key::Escape, S::Escape),
        (NONE, Key::Delete, S::Delete),
        (NONE, Key::B, S::BoxSelect),
        (NONE, Key::X, S::Lock(Axis::X)),
        (NONE, Key::Y, S::Lock(Axis::Y)),
        (NONE, Key::Z, S::Lock(Axis::Z)),
    ]
};

/// The shortcut a key press with these modifiers asks for, if any.
pub fn lookup(key: Key, modifiers: Modifiers) -> Option<Shortcut> {
    TABLE
        .iter()
        .find(|(m, k, _)| *k == key && modifiers.matches_logically(*m))
        .map(|(_, _, s)| *s)
}

/// A frame's shortcuts in the order they were pressed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Pressed {
    /// Pressed before any pointer button changed in this frame: they act first.
    pub before_pointer: Vec<Shortcut>,
    /// Pressed after a pointer button changed: they act once the view has taken the pointer.
    pub after_pointer: Vec<Shortcut>,
}

/// Takes the frame's shortcut presses (key repeats included, as egui's `consume_key`) out of
/// its events, in order, leaving every other event. Nothing is taken while a text field has
/// the keyboard.
pub fn take(ctx: &egui::Context) -> Pressed {
    let mut pressed = Pressed::default();
    if ctx.egui_wants_keyboard_input() {
        return pressed;
    }
    ctx.input_mut(|i| {
        let mut pointer_seen = false;
        i.events.retain(|event| match event {
            Event::PointerButton { .. } => {
                pointer_seen = true;
                true
            }
            Event::Key {
                key,
                modifiers,
                pressed: true,
                ..
            } => match lookup(*key, *modifiers) {
                Some(s) => {
                    if pointer_seen {
                        pressed.after_pointer.push(s);
                    } else {
                        pressed.before_pointer.push(s);
                    }
                    false
                }
                None => true,
            },
            _ => true,
        });
    });
    pressed
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::{Event, PointerButton, RawInput, pos2};

    fn key(key: Key, modifiers: Modifiers) -> Event {
        Event::Key {
            key,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers,
        }
    }

    fn taken(events: Vec<Event>) -> Pressed {
        let ctx = egui::Context::default();
        let mut out = Pressed::default();
        let raw = RawInput {
            events,
            ..Default::default()
        };
        let mut output = ctx.run_ui(raw, |ui| out = take(ui.ctx()));
        // No painter here: the font atlas's first upload is dropped on purpose.
        output.textures_delta.clear();
        out
    }

    #[test]
    fn presses_come_out_in_the_order_they_were_made_each_one_counted() {
        let (z, s) = (
            key(Key::Z, Modifiers::COMMAND),
            key(Key::S, Modifiers::COMMAND),
        );
        use Shortcut::*;
        assert_eq!(
            taken(vec![z.clone(), s.clone()]).before_pointer,
            [Undo, Save]
        );
        assert_eq!(
            taken(vec![s.clone(), z.clone()]).before_pointer,
            [Save, Undo]
        );
        assert_eq!(
            taken(vec![z.clone(), z.clone()]).before_pointer,
            [Undo, Undo]
        );
        // The most specific pattern wins: Ctrl+Shift+Z redoes, Shift+H hides, plain S scales.
        let shift_z = key(Key::Z, Modifiers::COMMAND | Modifiers::SHIFT);
        let shift_h = key(Key::H, Modifiers::SHIFT);
        assert_eq!(
            taken(vec![shift_z, shift_h, key(Key::S, Modifiers::NONE)]).before_pointer,
            [Redo, HideSelected, Tool(super::Tool::Scale)]
        );
    }

    #[test]
    fn presses_after_a_pointer_button_wait_for_the_view() {
        let release = Event::PointerButton {
            pos: pos2(10.0, 10.0),
            button: PointerButton::Primary,
            pressed: false,
            modifiers: Modifiers::NONE,
        };
        let pressed = taken(vec![
            key(Key::D, Modifiers::NONE),
            release,
            key(Key::S, Modifiers::COMMAND),
        ]);
        assert_eq!(pressed.before_pointer, [Shortcut::Tool(Tool::Sketch)]);
        assert_eq!(pressed.after_pointer, [Shortcut::Save]);
    }
}
