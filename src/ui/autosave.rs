//! Autosave: the document goes to the platform's store (the browser's localStorage, a file in
//! the user's data folder natively) one second after it last changed, so a reload, a closed tab
//! or a crash loses at most that second. At start the saved document is opened again, unless
//! the page was opened on a preset, a share link or a file: then the saved one is kept aside as
//! the previous session (the File group can open it), never silently replaced.

use crate::scene::{Document, Preset, Scene};

/// How long after the last change the document is written (seconds).
pub const DELAY: f64 = 1.0;

/// What a session was asked to open (from its URL or command line).
#[derive(Clone, Copy, Debug)]
pub enum Opening<'a> {
    /// A plain visit: continue the last session.
    Nothing,
    /// `?preset=NAME`.
    Preset(&'a str),
    /// A share link (`#s=…`).
    Link(&'a str),
    /// A scene file's name and bytes (the desktop app's path argument).
    File(&'a str, &'a [u8]),
}

/// How a session starts.
#[derive(Debug)]
pub struct Start {
    /// The document.
    pub scene: Scene,
    /// What to tell the user, and whether it reports a failure.
    pub notice: Option<(String, bool)>,
    /// The autosave must be kept aside before it is written over.
    pub keep_previous: bool,
    /// The file the document came from (what Save writes).
    pub file: Option<String>,
}

/// The document a session starts with, from what it was asked to open and the last autosave
/// (if any). Whatever was asked for opens and the last session is kept aside; when it cannot
/// be opened, the last session continues and the message says why.
pub fn starting_scene(opening: Opening, autosave: Option<&str>) -> Start {
    let opened = |scene: Scene, notice: Option<(String, bool)>, file: Option<String>| Start {
        scene,
        notice,
        keep_previous: autosave.is_some(),
        file,
    };
    let failed = |message: String| {
        let mut start = starting_scene(Opening::Nothing, autosave);
        start.notice = Some((message, true));
        start
    };
    let repaired =
        |what: String, repairs: Vec<String>| super::scene_files::with_repairs(what, &repairs);
    match opening {
        Opening::Preset(name) => match Preset::from_name(name) {
            Some(preset) => opened(Scene::preset(preset), None, None),
            None => opened(
                Scene::default(),
                Some((
                    format!("No preset called {name:?}: opened the default scene"),
                    false,
                )),
                None,
            ),
        },
        Opening::Link(text) => match crate::share::decode_link(text) {
            Ok((scene, repairs)) => opened(
                scene,
                Some((
                    repaired("Opened the scene from the link".into(), repairs),
                    false,
                )),
                None,
            ),
            Err(e) => failed(format!("{e}; your last session is open instead")),
        },
        Opening::File(name, bytes) => match crate::share::open_scene_file(name, bytes) {
            Ok((scene, repairs)) => opened(
                scene,
                Some((repaired(format!("Opened {name}"), repairs), false)),
                Some(name.to_owned()),
            ),
            Err(e) => failed(format!("{e}; your last session is open instead")),
        },
        Opening::Nothing => match autosave.map(Scene::from_json) {
            Some(Ok((scene, _))) => Start {
                scene,
                notice: Some((
                    "Restored your last session (saved automatically)".to_owned(),
                    false,
                )),
                keep_previous: false,
                file: None,
            },
            Some(Err(e)) => Start {
                scene: Scene::default(),
                notice: Some((
                    format!("The last session could not be restored ({e}); it is kept aside"),
                    true,
                )),
                keep_previous: true,
                file: None,
            },
            None => Start {
                scene: Scene::default(),
                notice: None,
                keep_previous: false,
                file: None,
            },
        },
    }
}

/// How a session starts ([`starting_scene`] over the platform's autosave); keeps the autosave
/// aside when the session will not continue it and `autosaving` (it will write its own; a
/// desktop `--screenshot` run writes none and leaves the user's files as they are).
pub fn start_session(opening: Opening, autosaving: bool) -> Start {
    let saved = super::platform::load_autosave();
    let start = starting_scene(opening, saved.as_deref());
    if start.keep_previous && autosaving {
        super::platform::keep_previous_autosave();
    }
    start
}

/// When to write the document.
#[derive(Default)]
pub struct Autosave {
    /// The revision last written (or found at start: an untouched document is not written).
    saved: Option<u64>,
    /// When the document was first seen changed since then.
    changed_at: Option<f64>,
    /// The last write failed (reported once until one succeeds).
    failed: bool,
}

impl Autosave {
    /// An autosave that counts `doc` as already saved (nothing to write until it changes).
    pub fn new(doc: &Document) -> Self {
        Self {
            saved: Some(doc.revisions().any()),
            ..Default::default()
        }
    }

    /// Called every frame: returns the document's JSON when it is time to write it.
    pub fn due(&mut self, doc: &Document, now: f64) -> Option<String> {
        let revision = doc.revisions().any();
        if self.saved == Some(revision) {
            self.changed_at = None;
            return None;
        }
        let since = *self.changed_at.get_or_insert(now);
        if now - since < DELAY {
            return None;
        }
        self.saved = Some(revision);
        self.changed_at = None;
        Some(doc.scene().to_json())
    }

    /// Seconds until the pending write, for scheduling the next frame.
    pub fn pending(&self, now: f64) -> Option<f64> {
        self.changed_at.map(|t| (t + DELAY - now).max(0.0))
    }

    /// Records how a write went; returns the message to show once for a failure.
    pub fn written(&mut self, result: Result<(), String>) -> Option<String> {
        match result {
            Ok(()) => {
                self.failed = false;
                None
            }
            Err(e) if !self.failed => {
                self.failed = true;
                Some(format!(
                    "Autosave failed: {e} (save the scene to a file to keep it)"
                ))
            }
            Err(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Edit;

    #[test]
    fn writes_a_second_after_the_last_change_and_not_before() {
        let mut doc = Document::new(Scene::default());
        let mut autosave = Autosave::new(&doc);
        assert!(
            autosave.due(&doc, 0.0).is_none(),
            "untouched: nothing to write"
        );
        let mut l = doc.scene().light.clone();
        l.ambient = 0.9;
        doc.apply(Edit::SetLight(l), None);
        assert!(autosave.due(&doc, 10.0).is_none(), "just changed");
        assert_eq!(autosave.pending(10.5), Some(0.5));
        let json = autosave.due(&doc, 11.0).expect("a second later");
        assert_eq!(Scene::from_json(&json).unwrap().0, *doc.scene());
        assert!(autosave.due(&doc, 20.0).is_none(), "written once");
        assert_eq!(
            autosave
                .written(Err("quota".into()))
                .as_deref()
                .map(|m| m.starts_with("Autosave failed")),
            Some(true)
        );
        assert!(autosave.written(Err("quota".into())).is_none(), "said once");
    }

    #[test]
    fn a_link_never_replaces_the_last_session_and_a_plain_visit_restores_it() {
        let mut edited = Scene::default();
        edited.ellipsoids.truncate(2);
        let json = edited.to_json();
        let start = starting_scene(Opening::Nothing, Some(&json));
        assert_eq!(start.scene, edited);
        assert!(start.notice.unwrap().0.starts_with("Restored"));
        assert!(!start.keep_previous);
        let start = starting_scene(Opening::Preset("stratus"), Some(&json));
        assert_eq!(start.scene, Scene::preset(Preset::Stratus));
        assert!(start.keep_previous, "the last session is kept aside");
        let start = starting_scene(Opening::Nothing, Some("{ truncated"));
        assert_eq!(start.scene, Scene::default());
        let (text, error) = start.notice.unwrap();
        assert!(text.contains("kept aside") && error && start.keep_previous);
        assert_eq!(
            starting_scene(Opening::Nothing, None).scene,
            Scene::default()
        );
    }

    #[test]
    fn a_link_or_file_opens_and_keeps_the_last_session_a_broken_one_continues_it() {
        let mut edited = Scene::default();
        edited.ellipsoids.truncate(2);
        let json = edited.to_json();
        let stratus = Scene::preset(Preset::Stratus);
        let url = crate::share::link_url("http://x/", &stratus).unwrap();
        let start = starting_scene(Opening::Link(&url), Some(&json));
        assert_eq!(start.scene.ellipsoids.len(), stratus.ellipsoids.len());
        assert!(start.keep_previous);
        assert!(!start.notice.unwrap().1);
        let start = starting_scene(Opening::Link("http://x/#s=AQ-broken"), Some(&json));
        assert_eq!(start.scene, edited, "the last session continues");
        assert!(!start.keep_previous, "and is not set aside");
        let (text, error) = start.notice.unwrap();
        assert!(error && text.contains("damaged"), "{text}");
        let file = stratus.to_json();
        let start = starting_scene(Opening::File("s.json", file.as_bytes()), Some(&json));
        assert_eq!(start.scene, stratus);
        assert_eq!(start.file.as_deref(), Some("s.json"));
        assert!(start.keep_previous);
        let start = starting_scene(Opening::File("bad.json", b"\xff"), None);
        assert_eq!(start.scene, Scene::default());
        assert!(
            start
                .notice
                .unwrap()
                .0
                .starts_with("bad.json: not a cloudsketch scene")
        );
    }
}
