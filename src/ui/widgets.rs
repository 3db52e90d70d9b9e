//! Small widgets shared by the panels.

use egui::{Slider, Ui};

use crate::limits::Param;

/// The UI's fonts: Ubuntu Light (egui's own text face) for all text — every glyph, without its
/// TrueType hinting, which egui's rasteriser does not need (`assets/fonts/ubuntu-light-unhinted.ttf`,
/// made by `scripts/subset_font.py`: 66 kB gzipped instead of 171 kB) — then egui's icon font, then `assets/fonts/icons.ttf` — a subset of emoji-icon-font (MIT) holding just
/// the icons the labels use (⟲⟳✏✂⬌). egui's default set adds a monospace face and two emoji
/// fonts (about 1 MB of the web build) and still lacks these icons natively, where the
/// browser's system-font fallback does not exist: with this set both targets show the same
/// glyphs.
fn font_definitions(with_icons: bool) -> egui::FontDefinitions {
    use egui::{FontData, FontFamily};
    let mut defs = egui::FontDefinitions::empty();
    let mut add = |name: &str, data: &'static [u8]| {
        defs.font_data.insert(
            name.to_owned(),
            std::sync::Arc::new(FontData::from_static(data)),
        );
        name.to_owned()
    };
    let mut chain = vec![
        add(
            "Ubuntu-Light",
            include_bytes!("../../assets/fonts/ubuntu-light-unhinted.ttf"),
        ),
        add("egui-icons", epaint_default_fonts::EGUI_ICONS),
    ];
    if with_icons {
        chain.push(add(
            "cloudsketch-icons",
            include_bytes!("../../assets/fonts/icons.ttf"),
        ));
    }
    for family in [FontFamily::Proportional, FontFamily::Monospace] {
        defs.families.insert(family, chain.clone());
    }
    defs
}

/// Installs the UI's fonts (see [`font_definitions`]).
pub fn install_fonts(ctx: &egui::Context) {
    ctx.set_fonts(font_definitions(true));
}

/// Where named widgets were drawn this frame (left, top, width, height in points), published
/// in the page state so the browser tests press the real widgets rather than guessed places.
type Marks = std::collections::BTreeMap<String, [f32; 4]>;

fn marks_id() -> egui::Id {
    egui::Id::unique("widget marks")
}

/// Records where the widget `name` was drawn this frame.
pub fn mark(ui: &Ui, name: &str, rect: egui::Rect) {
    ui.data_mut(|d| {
        d.get_temp_mut_or_default::<Marks>(marks_id()).insert(
            name.to_owned(),
            [rect.left(), rect.top(), rect.width(), rect.height()],
        );
    });
}

/// Takes the marks recorded since the last call (call once a frame, after the UI).
pub fn take_marks(ctx: &egui::Context) -> Marks {
    ctx.data_mut(|d| d.remove_temp::<Marks>(marks_id()))
        .unwrap_or_default()
}

/// Which side-panel groups are open, as the user last left them: kept with the app in the
/// platform's store (not the document), held in the egui context's data while it runs.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Groups {
    /// Each group's title and whether it is open.
    open: std::collections::BTreeMap<String, bool>,
    /// The user opened or closed one since the last [`take_changed_groups`].
    #[serde(skip)]
    changed: bool,
}

impl Groups {
    /// Reads the stored groups (nothing remembered when the text is not theirs).
    pub fn from_json(text: &str) -> Self {
        serde_json::from_str(text).unwrap_or_default()
    }

    /// The groups as stored.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }
}

fn groups_id() -> egui::Id {
    egui::Id::unique("cloudsketch side-panel groups")
}

/// Makes `groups` what the side panel opens its groups as (at start, from the store).
pub fn install_groups(ctx: &egui::Context, groups: Groups) {
    ctx.data_mut(|d| d.insert_temp(groups_id(), groups));
}

/// The groups as they are now, when the user opened or closed one since the last call.
pub fn take_changed_groups(ctx: &egui::Context) -> Option<Groups> {
    ctx.data_mut(|d| {
        let groups = d.get_temp_mut_or_default::<Groups>(groups_id());
        std::mem::take(&mut groups.changed).then(|| groups.clone())
    })
}

/// The titles of the groups open now (the page state's `groups_open`).
pub fn open_groups(ctx: &egui::Context) -> Vec<String> {
    ctx.data(|d| d.get_temp::<Groups>(groups_id()))
        .map(|g| {
            g.open
                .iter()
                .filter(|(_, open)| **open)
                .map(|(title, _)| title.clone())
                .collect()
        })
        .unwrap_or_default()
}

/// A side-panel group titled `title`: open as the user last left it (see [`Groups`]), else
/// as `default_open` says; its header is marked `group:TITLE` for the browser tests.
pub fn group<R>(
    ui: &mut Ui,
    title: &str,
    default_open: bool,
    body: impl FnOnce(&mut Ui) -> R,
) -> egui::CollapsingResponse<R> {
    let ctx = ui.ctx().clone();
    let remembered = ctx
        .data(|d| d.get_temp::<Groups>(groups_id()))
        .and_then(|g| g.open.get(title).copied());
    let response = egui::CollapsingHeader::new(title)
        .id_salt(("side-panel group", title))
        .default_open(remembered.unwrap_or(default_open))
        .show(ui, body);
    mark(ui, &format!("group:{title}"), response.header_response.rect);
    // Half open or more counts as open: a click starts an animation over several frames, and
    // the state is recorded once it passes halfway. Only a change from a state already known
    // is the user's (the first frame records the group as it opened).
    let open = response.openness > 0.5;
    if remembered != Some(open) {
        ctx.data_mut(|d| {
            let groups = d.get_temp_mut_or_default::<Groups>(groups_id());
            groups.open.insert(title.to_owned(), open);
            groups.changed |= remembered.is_some();
        });
    }
    response
}

/// A slider over a parameter's one range, with its label and tooltip (see [`crate::limits`]).
/// Its rail is marked as `param:LABEL` (see [`mark`]). Returns whether it changed.
pub fn param<T: egui::emath::Numeric>(ui: &mut Ui, value: &mut T, param: &Param) -> bool {
    param_as(ui, value, param, param.label)
}

/// [`param`] under another label (one range, several values: "wind x", "wind z").
pub fn param_as<T: egui::emath::Numeric>(
    ui: &mut Ui,
    value: &mut T,
    param: &Param,
    label: &str,
) -> bool {
    let response = ui
        .add(
            Slider::new(value, T::from_f64(param.min)..=T::from_f64(param.max))
                .logarithmic(param.logarithmic)
                .text(label),
        )
        .on_hover_text(param.tip);
    let rail = egui::Rect::from_min_size(
        response.rect.min,
        egui::vec2(ui.spacing().slider_width, response.rect.height()),
    );
    mark(ui, &format!("param:{label}"), rail);
    response.changed()
}

/// A colour button for an sRGB colour in [0, 1]. Returns whether it changed.
pub fn srgb_button(ui: &mut Ui, label: &str, color: &mut [f32; 3]) -> bool {
    let mut bytes = color.map(|v| (v * 255.0).round() as u8);
    let before = bytes;
    ui.horizontal(|ui| {
        ui.color_edit_button_srgb(&mut bytes);
        ui.label(label);
    });
    if bytes != before {
        *color = bytes.map(|v| v as f32 / 255.0);
        true
    } else {
        false
    }
}

/// Three drag fields (x, y, z) for a vector, on one labelled row.
pub fn vec3_fields(ui: &mut Ui, label: &str, v: &mut glam::Vec3, speed: f64) {
    ui.horizontal(|ui| {
        ui.label(label);
        for (axis, c) in ["x", "y", "z"].iter().zip(v.as_mut()) {
            ui.add_sized(
                [62.0, 18.0],
                egui::DragValue::new(c)
                    .speed(speed)
                    .fixed_decimals(2)
                    .prefix(format!("{axis} ")),
            );
        }
    });
}

/// A turn as yaw, pitch and roll in degrees (about y, then x, then z), on one row; the
/// quaternion is rebuilt only when a field changes, so reading it never alters it.
pub fn rotation_fields(ui: &mut Ui, rotation: &mut glam::Quat) {
    use glam::EulerRot;
    let (mut yaw, mut pitch, mut roll) = rotation.to_euler(EulerRot::YXZ);
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label("rotate");
        for (label, v) in [("y ", &mut yaw), ("p ", &mut pitch), ("r ", &mut roll)] {
            let mut deg = v.to_degrees();
            if ui
                .add_sized(
                    [62.0, 18.0],
                    egui::DragValue::new(&mut deg)
                        .speed(0.5)
                        .fixed_decimals(0)
                        .prefix(label)
                        .suffix("°"),
                )
                .changed()
            {
                *v = deg.to_radians();
                changed = true;
            }
        }
    });
    if changed {
        *rotation = glam::Quat::from_euler(EulerRot::YXZ, yaw, pitch, roll);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether the group `title` (closed by default) shows its body in a frame of `ctx`.
    fn shown(ctx: &egui::Context, title: &str) -> bool {
        let mut ran = false;
        let mut output = ctx.run_ui(Default::default(), |ui| {
            group(ui, title, false, |_| ran = true);
        });
        output.textures_delta.clear();
        ran
    }

    #[test]
    fn a_group_opens_as_the_user_left_it_and_else_as_its_default() {
        let ctx = egui::Context::default();
        assert!(!shown(&ctx, "View"), "closed by default");
        let kept = Groups::from_json(r#"{"open": {"View": true}}"#);
        let ctx = egui::Context::default();
        install_groups(&ctx, kept);
        assert!(shown(&ctx, "View"), "opened as it was left");
        assert_eq!(open_groups(&ctx), ["View"]);
        // Nothing the user did: nothing to store.
        assert!(take_changed_groups(&ctx).is_none());
        // A click on its header closes it: once the animation passes halfway, that is the
        // user's change, to be stored.
        let header = take_marks(&ctx)["group:View"];
        let at = egui::pos2(header[0] + 10.0, header[1] + header[3] / 2.0);
        let button = |pressed| egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        };
        let frames = [
            vec![egui::Event::PointerMoved(at)],
            vec![button(true)],
            vec![button(false)],
        ];
        for (k, events) in frames
            .into_iter()
            .chain((0..30).map(|_| Vec::new()))
            .enumerate()
        {
            let raw = egui::RawInput {
                time: Some(k as f64 * 0.05),
                events,
                ..Default::default()
            };
            let mut output = ctx.run_ui(raw, |ui| {
                group(ui, "View", false, |_| {});
            });
            output.textures_delta.clear();
        }
        let stored = take_changed_groups(&ctx).expect("the click was a change");
        assert_eq!(stored.open.get("View"), Some(&false));
        assert!(open_groups(&ctx).is_empty());
        assert_eq!(Groups::from_json("not json"), Groups::default());
    }

    /// The icon glyphs the UI's labels use (undo, redo, sketch, cut, move, rotate).
    const ICONS: &str = "⟲⟳✏✂⬌";

    #[test]
    fn text_and_icon_glyphs_are_there_only_with_the_icon_font() {
        let font = egui::FontId::proportional(14.0);
        let has = |with_icons: bool, text: &str| {
            let ctx = egui::Context::default();
            ctx.set_fonts(font_definitions(with_icons));
            let mut out = ctx.run_ui(Default::default(), |_| {});
            out.textures_delta.clear();
            ctx.fonts_mut(|f| f.has_glyphs(&font, text))
        };
        assert!(
            !has(false, ICONS),
            "egui's text face now has the icons: the icon font can go"
        );
        assert!(has(true, ICONS));
        // Every character the UI's code writes (comments aside) has a glyph.
        let mut used = String::new();
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/ui");
        let mut stack = vec![dir];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(d).unwrap() {
                let p = e.unwrap().path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|x| x == "rs") {
                    let text = std::fs::read_to_string(&p).unwrap();
                    for line in text.lines().filter(|l| !l.trim_start().starts_with("//")) {
                        used.extend(line.chars().filter(|c| !c.is_ascii()));
                    }
                }
            }
        }
        assert!(used.contains('✏'), "the scan finds the labels");
        let missing: String = used
            .chars()
            .filter(|&c| !has(true, &c.to_string()))
            .collect();
        assert!(missing.is_empty(), "no glyph for {missing:?}");
    }
}
