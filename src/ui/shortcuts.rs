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

use super::tool::{ModalKind, Tool};
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
    /// I: key the selection (the sun with nothing selected) at the current frame.
    InsertKey,
    /// Alt+I: delete the shown keys at the current frame.
    DeleteKeys,
    /// ← and →: a frame back or on.
    StepFrame(i8),
    /// ↑ and ↓: the next or the previous key.
    JumpKey(bool),
    /// 1, 3, 7 (Ctrl: the opposite side).
    View(StandardView),
    /// 5: orthographic on or off.
    Orthographic,
    /// 0: look through the shot camera, or back to the free view.
    ShotView,
    /// V, D, C, E, Shift+G, Shift+R, Shift+S: pick a tool.
    Tool(Tool),
    /// G, R, S: a modal grab, rotate or scale of the selection.
    Modal(ModalKind),
    /// A digit, a point or a minus typed during a modal transform.
    Typed(char),
    /// Backspace during a modal transform: the last typed character goes.
    Erase,
    /// Enter during a modal transform: confirm it.
    Confirm,
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
    /// X, Y, Z: lock the Move, Rotate or Scale tool, or the modal transform, to that axis
    /// (again: free).
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
        (Modifiers::ALT, Key::I, S::DeleteKeys),
        (NONE, Key::I, S::InsertKey),
        (NONE, Key::ArrowLeft, S::StepFrame(-1)),
        (NONE, Key::ArrowRight, S::StepFrame(1)),
        (NONE, Key::ArrowUp, S::JumpKey(true)),
        (NONE, Key::ArrowDown, S::JumpKey(false)),
        (Modifiers::SHIFT, Key::H, S::HideSelected),
        (Modifiers::ALT, Key::H, S::ShowAll),
        (NONE, Key::F, S::Frame),
        (NONE, Key::N, S::TogglePanel),
        (NONE, Key::Num1, S::View(StandardView::Front)),
        (NONE, Key::Num3, S::View(StandardView::Right)),
        (NONE, Key::Num7, S::View(StandardView::Top)),
        (NONE, Key::Num5, S::Orthographic),
        (NONE, Key::Num0, S::ShotView),
        (NONE, Key::V, S::Tool(Tool::Navigate)),
        (NONE, Key::D, S::Tool(Tool::Sketch)),
        (NONE, Key::C, S::Tool(Tool::Cut)),
        (NONE, Key::E, S::Tool(Tool::Ellipsoid)),
        (Modifiers::SHIFT, Key::G, S::Tool(Tool::Move)),
        (Modifiers::SHIFT, Key::R, S::Tool(Tool::Rotate)),
        (Modifiers::SHIFT, Key::S, S::Tool(Tool::Scale)),
        (NONE, Key::G, S::Modal(ModalKind::Grab)),
        (NONE, Key::R, S::Modal(ModalKind::Rotate)),
        (NONE, Key::S, S::Modal(ModalKind::Scale)),
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

/// What a key types during a modal transform: digits, a point, a minus, Backspace and Enter
/// (the number row's and the keypad's alike: egui names both the same).
fn modal_key(key: Key) -> Option<Shortcut> {
    let digit = match key {
        Key::Num0 => '0',
        Key::Num1 => '1',
        Key::Num2 => '2',
        Key::Num3 => '3',
        Key::Num4 => '4',
        Key::Num5 => '5',
        Key::Num6 => '6',
        Key::Num7 => '7',
        Key::Num8 => '8',
        Key::Num9 => '9',
        Key::Period | Key::Comma => '.',
        Key::Minus => '-',
        Key::Backspace => return Some(Shortcut::Erase),
        Key::Enter => return Some(Shortcut::Confirm),
        _ => return None,
    };
    Some(Shortcut::Typed(digit))
}

/// The shortcut a key press with these modifiers asks for, if any; during a modal transform
/// (`modal`) digits, the point, the minus, Backspace and Enter are its.
pub fn lookup(key: Key, modifiers: Modifiers, modal: bool) -> Option<Shortcut> {
    if modal
        && modifiers.is_none()
        && let Some(s) = modal_key(key)
    {
        return Some(s);
    }
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
/// the keyboard. During a modal transform (`modal`) the keys that type a number are its.
pub fn take(ctx: &egui::Context, modal: bool) -> Pressed {
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
            } => match lookup(*key, *modifiers, modal) {
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
        let mut output = ctx.run_ui(raw, |ui| out = take(ui.ctx(), false));
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
        // The most specific pattern wins: Ctrl+Shift+Z redoes, Shift+H hides, Shift+S picks
        // the Scale tool, plain S scales modally.
        let shift_z = key(Key::Z, Modifiers::COMMAND | Modifiers::SHIFT);
        let shift_h = key(Key::H, Modifiers::SHIFT);
        let shift_s = key(Key::S, Modifiers::SHIFT);
        assert_eq!(
            taken(vec![
                shift_z,
                shift_h,
                shift_s,
                key(Key::S, Modifiers::NONE)
            ])
            .before_pointer,
            [
                Redo,
                HideSelected,
                Tool(super::Tool::Scale),
                Modal(ModalKind::Scale)
            ]
        );
    }

    #[test]
    fn during_a_modal_transform_digits_type_and_enter_confirms() {
        assert_eq!(
            lookup(Key::Num1, Modifiers::NONE, false),
            Some(Shortcut::View(StandardView::Front))
        );
        assert_eq!(
            lookup(Key::Num1, Modifiers::NONE, true),
            Some(Shortcut::Typed('1'))
        );
        assert_eq!(
            lookup(Key::Minus, Modifiers::NONE, true),
            Some(Shortcut::Typed('-'))
        );
        assert_eq!(
            lookup(Key::Enter, Modifiers::NONE, true),
            Some(Shortcut::Confirm)
        );
        assert_eq!(lookup(Key::Enter, Modifiers::NONE, false), None);
        assert_eq!(
            lookup(Key::X, Modifiers::NONE, true),
            Some(Shortcut::Lock(Axis::X))
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
