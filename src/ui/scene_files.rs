//! The document's way in and out of the app: Open (Ctrl+O), Save (Ctrl+S), Save as
//! (Ctrl+Shift+S), Copy link (Ctrl+L), the unsaved marker, the session kept aside at start, and links
//! pasted into the address bar of an open page. Opening is one undo step, so nothing is lost.

use super::notice::Notices;
use super::platform;
use super::selection::Selection;
use super::shortcuts::Shortcut;
use crate::scene::{Document, Edit, Scene};
use crate::share::{LinkError, decode_link, link_url, open_scene_file, scene_file_name};

/// The File group's state.
pub struct SceneFiles {
    /// What Save writes: a file name in the browser (the download's), a path natively.
    pub name: String,
    /// Content revision at the last open or save.
    saved: u64,
    /// The name field takes the keyboard on the next frame (Save as).
    focus_name: bool,
    /// A session was kept aside at start and can be opened again.
    previous: bool,
    /// The last link copied, for the page state.
    pub last_link: Option<String>,
}

/// A revision of everything a file holds except the view (camera moves do not make a scene
/// unsaved, as in Blender; the time, which the file holds, does).
fn content_revision(doc: &Document) -> u64 {
    let r = doc.revisions();
    r.geometry
        .max(r.light)
        .max(r.render)
        .max(r.reference)
        .max(r.clock)
        .max(r.time)
}

impl SceneFiles {
    /// The state for a session that opened `file` (or nothing: "untitled").
    pub fn new(doc: &Document, file: Option<String>) -> Self {
        Self {
            name: file.unwrap_or_else(|| "untitled.json".to_owned()),
            saved: content_revision(doc),
            focus_name: false,
            previous: platform::load_previous_autosave().is_some(),
            last_link: None,
        }
    }

    /// Whether the document changed since it was last opened or saved.
    pub fn unsaved(&self, doc: &Document) -> bool {
        content_revision(doc) != self.saved
    }

    /// Saves the document under [`Self::name`] (a download in the browser).
    pub fn save(&mut self, doc: &Document, notices: &mut Notices, now: f64) {
        let name = if platform::HAS_PICKER {
            scene_file_name(&self.name)
        } else {
            let name = self.name.trim().to_owned();
            if name.is_empty() {
                "untitled.json".to_owned()
            } else if std::path::Path::new(&name).extension().is_none() {
                format!("{name}.json")
            } else {
                name
            }
        };
        match platform::save_file(&name, &doc.scene().to_json()) {
            Ok(where_) => {
                self.name = name;
                self.saved = content_revision(doc);
                notices.note(now, format!("Saved {where_}"));
            }
            Err(e) => notices.error(now, format!("Could not save: {e}")),
        }
    }

    /// Replaces the document with `scene` as one undo step.
    fn replace(
        &mut self,
        doc: &mut Document,
        selection: &mut Selection,
        scene: Scene,
        file: Option<&str>,
    ) {
        doc.apply(Edit::Replace(Box::new(scene)), None);
        doc.end_merge();
        selection.retain_valid(doc.scene());
        if let Some(file) = file {
            self.name = file.to_owned();
        }
        self.saved = content_revision(doc);
    }

    /// Opens a scene file's bytes (from Open, a drop or a path); on failure the document
    /// stays as it was and the message says why.
    pub fn open(
        &mut self,
        cx: (&mut Document, &mut Selection, &mut Notices),
        now: f64,
        name: &str,
        bytes: &[u8],
    ) {
        let (doc, selection, notices) = cx;
        match open_scene_file(name, bytes) {
            Ok((scene, repairs)) => {
                self.replace(doc, selection, scene, Some(name));
                notices.note(
                    now,
                    with_repairs(format!("Opened {name} (Ctrl+Z goes back)"), &repairs),
                );
            }
            Err(e) => notices.error(now, format!("Nothing opened: {e}")),
        }
    }

    /// Opens a share link (pasted into an open page's address bar).
    pub fn open_link(
        &mut self,
        cx: (&mut Document, &mut Selection, &mut Notices),
        now: f64,
        url: &str,
    ) {
        let (doc, selection, notices) = cx;
        match decode_link(url) {
            Ok((scene, repairs)) => {
                self.replace(doc, selection, scene, None);
                notices.note(
                    now,
                    with_repairs(
                        "Opened the scene from the link (Ctrl+Z goes back)".into(),
                        &repairs,
                    ),
                );
            }
            Err(e) => notices.error(now, format!("Nothing opened: {e}")),
        }
    }

    /// Puts a link to the document on the clipboard, or says why there is none.
    pub fn copy_link(&mut self, ctx: &egui::Context, doc: &Document, notices: &mut Notices) {
        let now = ctx.input(|i| i.time);
        match link_url(&platform::page_base(), doc.scene()) {
            Ok(url) => {
                notices.note(now, format!("Link copied: {} characters", url.len()));
                ctx.copy_text(url.clone());
                self.last_link = Some(url);
            }
            Err(e @ LinkError::SceneTooLarge { .. }) => {
                notices.error(now, format!("No link: {e} (Ctrl+S)"))
            }
            Err(e) => notices.error(now, format!("No link: {e}")),
        }
    }

    /// Ctrl+S saves, Ctrl+Shift+S asks for a name first, Ctrl+O opens, Ctrl+L copies a link
    /// (Figma's key); other shortcuts are not the file's.
    pub fn shortcut(
        &mut self,
        ctx: &egui::Context,
        shortcut: Shortcut,
        doc: &Document,
        notices: &mut Notices,
    ) {
        let now = ctx.input(|i| i.time);
        match shortcut {
            Shortcut::CopyLink => self.copy_link(ctx, doc, notices),
            Shortcut::SaveAs => {
                self.focus_name = true;
                notices.note(now, "Save as: type the file's name, then Enter");
            }
            Shortcut::Save => self.save(doc, notices, now),
            Shortcut::Open => self.ask_to_open(notices, now),
            _ => {}
        }
    }

    fn ask_to_open(&mut self, notices: &mut Notices, now: f64) {
        if platform::KEY_OPENS_PICKER {
            // Opened already, in the key's own event.
            return;
        }
        if platform::HAS_PICKER {
            platform::open_scene_picker();
        } else {
            self.focus_name = true;
            notices.note(now, "Open: type the scene file's path, then press Open");
        }
    }

    /// The File group: the file's name (with • when unsaved), Open, Save and Copy link, and
    /// the session kept aside.
    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        doc: &mut Document,
        selection: &mut Selection,
        notices: &mut Notices,
    ) {
        let now = ui.input(|i| i.time);
        ui.horizontal(|ui| {
            let marker = if self.unsaved(doc) { "•" } else { " " };
            ui.label(marker)
                .on_hover_text("• changes since the file was opened or saved");
            let hint = if platform::HAS_PICKER {
                "the name Save downloads the scene as"
            } else {
                "the scene file's path: Save writes it, Open reads it"
            };
            let field = ui.add(
                egui::TextEdit::singleline(&mut self.name)
                    .desired_width(f32::INFINITY)
                    .hint_text("untitled.json"),
            );
            let field = field.on_hover_text(hint);
            if std::mem::take(&mut self.focus_name) {
                field.request_focus();
            }
            if field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                self.save(doc, notices, now);
            }
        });
        ui.horizontal(|ui| {
            if ui
                .button("Open…")
                .on_hover_text("Ctrl+O: open a scene file (or drop one on the view)")
                .clicked()
            {
                if platform::HAS_PICKER {
                    platform::open_scene_picker();
                } else {
                    let path = self.name.trim().to_owned();
                    match platform::read_path(&path) {
                        Ok((name, bytes)) => {
                            self.open((doc, selection, notices), now, &name, &bytes)
                        }
                        Err(e) => notices.error(now, format!("Nothing opened: {e}")),
                    }
                }
            }
            if ui
                .button("Save")
                .on_hover_text("Ctrl+S (Ctrl+Shift+S: under another name)")
                .clicked()
            {
                self.save(doc, notices, now);
            }
            if ui
                .button("Copy link")
                .on_hover_text("Ctrl+L: a URL that holds the whole scene, to share")
                .clicked()
            {
                self.copy_link(ui.ctx(), doc, notices);
            }
        });
        if self.previous
            && ui
                .small_button("Open the previous session")
                .on_hover_text(
                    "the session that was open before this link, preset or file, kept aside",
                )
                .clicked()
        {
            match platform::load_previous_autosave().map(|json| Scene::from_json(&json)) {
                Some(Ok((scene, _))) => {
                    self.replace(doc, selection, scene, None);
                    notices.note(now, "Opened the previous session (Ctrl+Z goes back)");
                }
                Some(Err(e)) => notices.error(now, format!("The previous session: {e}")),
                None => notices.error(now, "No previous session is kept"),
            }
        }
    }
}

/// `text`, and what validation repaired, if anything.
pub(super) fn with_repairs(text: String, repairs: &[String]) -> String {
    if repairs.is_empty() {
        text
    } else {
        format!("{text}; repaired {}", repairs.join(", "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Preset;

    #[test]
    fn open_is_one_undo_step_save_clears_the_marker_and_a_broken_file_changes_nothing() {
        let mut doc = Document::new(Scene::preset(Preset::Cumulus));
        let mut selection = Selection::default();
        let mut notices = Notices::default();
        let mut files = SceneFiles::new(&doc, None);
        assert!(!files.unsaved(&doc), "a fresh session has nothing unsaved");
        let mut camera = doc.scene().camera.clone();
        camera.yaw_deg += 30.0;
        doc.set_camera(camera);
        assert!(
            !files.unsaved(&doc),
            "a camera move is not an unsaved change"
        );

        let stratus = Scene::preset(Preset::Stratus);
        let bytes = stratus.to_json().into_bytes();
        files.open(
            (&mut doc, &mut selection, &mut notices),
            1.0,
            "s.json",
            &bytes,
        );
        assert_eq!(*doc.scene(), stratus);
        assert_eq!(files.name, "s.json");
        assert!(!files.unsaved(&doc));
        assert!(doc.undo().is_some());
        assert_eq!(
            doc.scene().ellipsoids,
            Scene::preset(Preset::Cumulus).ellipsoids
        );
        assert!(
            files.unsaved(&doc),
            "undoing the open is a change from the file"
        );
        doc.redo();

        let before = doc.scene().clone();
        files.open(
            (&mut doc, &mut selection, &mut notices),
            2.0,
            "bad.json",
            b"{\"planes\": 7}",
        );
        assert_eq!(*doc.scene(), before, "nothing opened");
        let notice = notices.latest.clone().unwrap();
        assert!(notice.error && notice.text.starts_with("Nothing opened: bad.json"));

        let mut light = doc.scene().light.clone();
        light.ambient = 0.9;
        doc.apply(Edit::SetLight(light), None);
        assert!(files.unsaved(&doc));
        let dir = std::env::temp_dir().join(format!("cloudsketch-save-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        files.name = dir.join("saved").display().to_string();
        files.save(&doc, &mut notices, 3.0);
        assert!(!files.unsaved(&doc), "{:?}", notices.latest);
        assert!(files.name.ends_with("saved.json"), "{}", files.name);
        let (saved, _) = Scene::from_json(&std::fs::read_to_string(&files.name).unwrap()).unwrap();
        assert_eq!(saved, *doc.scene());
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn a_link_opens_as_one_undo_step_and_a_broken_one_changes_nothing() {
        let mut doc = Document::new(Scene::preset(Preset::Cumulus));
        let (mut selection, mut notices) = (Selection::default(), Notices::default());
        let mut files = SceneFiles::new(&doc, None);
        let url = crate::share::link_url("http://x/", &Scene::preset(Preset::Cirrus)).unwrap();
        files.open_link((&mut doc, &mut selection, &mut notices), 1.0, &url);
        assert_eq!(
            doc.scene().render.noise_filter,
            Scene::preset(Preset::Cirrus).render.noise_filter
        );
        let before = doc.scene().clone();
        files.open_link(
            (&mut doc, &mut selection, &mut notices),
            2.0,
            &url[..url.len() - 9],
        );
        assert_eq!(*doc.scene(), before);
        assert!(notices.latest.unwrap().text.contains("damaged"));
        doc.undo();
        assert_eq!(
            doc.scene().ellipsoids,
            Scene::preset(Preset::Cumulus).ellipsoids
        );
    }
}
