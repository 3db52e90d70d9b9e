//! Edits as values, and the undo history.
//!
//! Every change a user makes to the document goes through [`History::apply`]; camera moves are
//! the exception (views are not undone, as in Blender) and go through [`Edit::SetCamera`] with
//! `record = false`.

use super::{DrawingPlane, Ellipsoid, Lighting, OrbitCamera, RenderSettings, Scene};

/// Most undo steps kept.
pub const MAX_UNDO: usize = 200;

/// One change to the document.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Replace the camera.
    SetCamera(OrbitCamera),
    /// Replace the lighting.
    SetLight(Lighting),
    /// Replace the render settings.
    SetRender(RenderSettings),
    /// Replace the ellipsoid list.
    SetEllipsoids(Vec<Ellipsoid>),
    /// Replace the drawing planes (add, change, duplicate or delete a sketched stroke).
    SetPlanes(Vec<DrawingPlane>),
    /// Replace the whole document (open, new, preset).
    Replace(Box<Scene>),
}

impl Edit {
    /// Applies the edit; returns false when it could not apply (the document is unchanged).
    pub fn apply_to(self, scene: &mut Scene) -> bool {
        match self {
            Edit::SetCamera(c) => scene.camera = c,
            Edit::SetLight(l) => scene.light = l,
            Edit::SetRender(r) => scene.render = r,
            Edit::SetEllipsoids(e) => scene.ellipsoids = e,
            Edit::SetPlanes(p) => {
                if p.len() > super::MAX_PLANES {
                    return false;
                }
                scene.planes = p
            }
            Edit::Replace(s) => *scene = *s,
        }
        true
    }
}

/// Snapshot-based undo/redo with merging of continuous edits (slider drags).
#[derive(Default)]
pub struct History {
    undo: Vec<Scene>,
    redo: Vec<Scene>,
    /// Key of the last recorded edit; an edit with the same key replaces it instead of adding a step.
    last_key: Option<&'static str>,
}

impl History {
    /// Applies `edit` to `scene` and records an undo step. Edits that share a `merge_key` with
    /// the previous one (the same slider being dragged) fold into one step. Returns whether the
    /// document changed.
    pub fn apply(
        &mut self,
        scene: &mut Scene,
        edit: Edit,
        merge_key: Option<&'static str>,
    ) -> bool {
        let before = scene.clone();
        if !edit.apply_to(scene) || *scene == before {
            return false;
        }
        let merge = merge_key.is_some() && merge_key == self.last_key;
        if !merge {
            self.undo.push(before);
            if self.undo.len() > MAX_UNDO {
                self.undo.remove(0);
            }
        }
        self.redo.clear();
        self.last_key = merge_key;
        true
    }

    /// Ends the current merge run (pointer released), so the next edit is a new step.
    pub fn end_merge(&mut self) {
        self.last_key = None;
    }

    /// Steps back; the camera stays where the user put it. Returns false when nothing to undo.
    pub fn undo(&mut self, scene: &mut Scene) -> bool {
        self.step(scene, true)
    }

    /// Steps forward again. Returns false when nothing to redo.
    pub fn redo(&mut self, scene: &mut Scene) -> bool {
        self.step(scene, false)
    }

    fn step(&mut self, scene: &mut Scene, back: bool) -> bool {
        let (from, to) = if back {
            (&mut self.undo, &mut self.redo)
        } else {
            (&mut self.redo, &mut self.undo)
        };
        let Some(mut prev) = from.pop() else {
            return false;
        };
        prev.camera = scene.camera.clone();
        to.push(std::mem::replace(scene, prev));
        self.last_key = None;
        true
    }

    /// Number of undo steps available.
    pub fn undo_len(&self) -> usize {
        self.undo.len()
    }

    /// Number of redo steps available.
    pub fn redo_len(&self) -> usize {
        self.redo.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undo_redo_round_trip() {
        let mut scene = Scene::default();
        let original = scene.clone();
        let mut h = History::default();
        let mut r = scene.render.clone();
        r.slices = 64;
        assert!(h.apply(&mut scene, Edit::SetRender(r), None));
        assert_eq!(scene.render.slices, 64);
        assert!(h.undo(&mut scene));
        assert_eq!(scene, original);
        assert!(h.redo(&mut scene));
        assert_eq!(scene.render.slices, 64);
        assert!(!h.redo(&mut scene));
    }

    #[test]
    fn slider_drags_merge_into_one_step() {
        let mut scene = Scene::default();
        let mut h = History::default();
        for s in [20, 30, 40] {
            let mut r = scene.render.clone();
            r.slices = s;
            h.apply(&mut scene, Edit::SetRender(r), Some("slices"));
        }
        assert_eq!(h.undo_len(), 1);
        h.end_merge();
        let mut r = scene.render.clone();
        r.slices = 50;
        h.apply(&mut scene, Edit::SetRender(r), Some("slices"));
        assert_eq!(h.undo_len(), 2);
        h.undo(&mut scene);
        assert_eq!(scene.render.slices, 40);
    }

    #[test]
    fn no_op_and_invalid_edits_record_nothing() {
        let mut scene = Scene::default();
        let mut h = History::default();
        let same = scene.render.clone();
        assert!(!h.apply(&mut scene, Edit::SetRender(same), None));
        assert_eq!(h.undo_len(), 0);
    }

    #[test]
    fn undo_keeps_the_camera() {
        let mut scene = Scene::default();
        let mut h = History::default();
        h.apply(&mut scene, Edit::SetEllipsoids(vec![]), None);
        scene.camera.yaw_deg = 90.0;
        h.undo(&mut scene);
        assert_eq!(scene.camera.yaw_deg, 90.0);
        assert!(!scene.ellipsoids.is_empty());
    }
}
