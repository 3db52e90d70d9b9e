//! Autosave: the document goes to the platform's store (the browser's localStorage, a file in
//! the user's data folder natively) one second after it last changed, so a reload, a closed tab
//! or a crash loses at most that second. At start the saved document is opened again, unless
//! the page was opened on a preset (a link): then the saved one is kept aside as the previous
//! session, never silently replaced.

use crate::scene::{Document, Preset, Scene};

/// How long after the last change the document is written (seconds).
pub const DELAY: f64 = 1.0;

/// The document a session starts with, from the preset named in its link (if any) and the
/// last autosave (if any), with what to tell the user, and whether the autosave must be kept
/// aside before it is written over.
pub fn starting_scene(
    preset: Option<&str>,
    autosave: Option<&str>,
) -> (Scene, Option<String>, bool) {
    match (preset, autosave) {
        (Some(name), saved) => {
            let scene = Preset::from_name(name)
                .map(Scene::preset)
                .unwrap_or_default();
            let notice = Preset::from_name(name)
                .is_none()
                .then(|| format!("No preset called {name:?}: opened the default scene"));
            (scene, notice, saved.is_some())
        }
        (None, Some(json)) => match Scene::from_json(json) {
            Ok((scene, _)) => (
                scene,
                Some("Restored your last session (saved automatically)".to_owned()),
                false,
            ),
            Err(e) => (
                Scene::default(),
                Some(format!(
                    "The last session could not be restored ({e}); it is kept aside"
                )),
                true,
            ),
        },
        (None, None) => (Scene::default(), None, false),
    }
}

/// The document a session starts with ([`starting_scene`] over the platform's autosave), and
/// what to tell the user; keeps the autosave aside when the session will not continue it.
pub fn start_session(preset: Option<&str>) -> (Scene, Option<String>) {
    let saved = super::platform::load_autosave();
    let (scene, notice, keep) = starting_scene(preset, saved.as_deref());
    if keep {
        super::platform::keep_previous_autosave();
    }
    (scene, notice)
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
        let (scene, notice, keep) = starting_scene(None, Some(&json));
        assert_eq!(scene, edited);
        assert!(notice.unwrap().starts_with("Restored"));
        assert!(!keep);
        let (scene, _, keep) = starting_scene(Some("stratus"), Some(&json));
        assert_eq!(scene, Scene::preset(Preset::Stratus));
        assert!(keep, "the last session is kept aside");
        let (scene, notice, keep) = starting_scene(None, Some("{ truncated"));
        assert_eq!(scene, Scene::default());
        assert!(notice.unwrap().contains("kept aside") && keep);
        assert_eq!(starting_scene(None, None).0, Scene::default());
    }
}
