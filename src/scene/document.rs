//! The document: the scene, its undo history and revision counters per part.
//!
//! Every change goes through [`Document::apply`] (undoable edits) or
//! [`Document::set_camera`] (views, not undone). Each part of the scene — geometry (ellipsoids,
//! drawing planes, seed), lighting, render settings, camera — carries a revision that changes
//! exactly when that part does, so derived state asks "did the geometry change since revision
//! N?" instead of comparing scenes. Undo steps are whole scenes, cheap to keep because a
//! scene's primitives are shared through `Arc`: 200 steps of one slider on a scene at the caps
//! hold one copy of its strokes, not 200.

use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use super::{Edit, OrbitCamera, Scene};
use crate::limits::MAX_PLANES;

pub use crate::limits::MAX_UNDO;

/// Source of revision numbers, shared by every document in the process: a revision never
/// repeats, even across documents, so a cache keyed on one can never confuse two documents.
static NEXT_REVISION: AtomicU64 = AtomicU64::new(1);

fn next_revision() -> u64 {
    NEXT_REVISION.fetch_add(1, Ordering::Relaxed)
}

/// Revision of each part of the document. A part's revision changes whenever the part does
/// (and only then); revisions never repeat, so a cached value keyed on one stays valid exactly
/// as long as the part is unchanged.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Revisions {
    /// Ellipsoids, drawing planes and the seed: what the field is made of.
    pub geometry: u64,
    /// Sun, sky and background.
    pub light: u64,
    /// Render quality and cloud media settings.
    pub render: u64,
    /// The camera.
    pub camera: u64,
    /// The reference image.
    pub reference: u64,
    /// The clock's frame rate and range, the key frames and the shot camera (no image depends
    /// on them alone: a keyed value's pose changes the part it belongs to, keys on the wind or
    /// the torque change the render part too, and the view looking through the shot moves the
    /// camera).
    pub clock: u64,
    /// The scene's time: the noise's motion and a simulation's step follow it. Moving it on a
    /// scene with nothing animated changes no other part; where keys or motion pose values
    /// there, the parts they moved change too.
    pub time: u64,
}

impl Revisions {
    /// Revisions no earlier value had: whatever is derived at them is derived afresh.
    pub fn fresh() -> Self {
        let n = next_revision();
        Self {
            geometry: n,
            light: n,
            render: n,
            camera: n,
            reference: n,
            clock: n,
            time: n,
        }
    }

    /// Changes whenever any part of the document does (camera and time included).
    pub fn any(&self) -> u64 {
        self.geometry
            .max(self.light)
            .max(self.render)
            .max(self.camera)
            .max(self.reference)
            .max(self.clock)
            .max(self.time)
    }
}

/// Which parts an edit or an undo step changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Changed {
    geometry: bool,
    light: bool,
    render: bool,
    camera: bool,
    reference: bool,
    clock: bool,
    time: bool,
}

impl Changed {
    fn any(&self) -> bool {
        self.geometry
            || self.light
            || self.render
            || self.camera
            || self.reference
            || self.clock
            || self.time
    }
}

/// The same primitives, compared by pointer first (shared `Arc`s are equal at once).
fn same<T: PartialEq>(a: &[Arc<T>], b: &[Arc<T>]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| Arc::ptr_eq(x, y) || **x == **y)
}

/// The keys on the wind and torque of the base media and the tiers (what
/// [`crate::field::media::Drifts`] integrates), by pointer.
fn drift_keys(scene: &Scene) -> Vec<*const super::Track> {
    use super::{Channel, MediaProperty, TierProperty};
    scene
        .animation
        .tracks
        .iter()
        .filter(|t| {
            matches!(
                t.channel,
                Channel::Media {
                    property: MediaProperty::Wind | MediaProperty::Torque
                } | Channel::Tier {
                    property: TierProperty::Wind | TierProperty::Torque,
                    ..
                }
            )
        })
        .map(Arc::as_ptr)
        .collect()
}

fn diff(a: &Scene, b: &Scene) -> Changed {
    Changed {
        geometry: a.seed != b.seed
            || !same(&a.ellipsoids, &b.ellipsoids)
            || !same(&a.planes, &b.planes)
            || a.simulation != b.simulation
            || a.wind_field != b.wind_field,
        light: a.light != b.light,
        // A keyed wind or torque moves the noise by its integral: new keys there redraw.
        render: a.render != b.render || drift_keys(a) != drift_keys(b),
        time: a.time != b.time,
        camera: a.camera != b.camera,
        reference: a.reference != b.reference,
        clock: a.clock != b.clock || !a.animation.same_as(&b.animation) || a.shot != b.shot,
    }
}

struct Step {
    scene: Scene,
    label: &'static str,
}

/// The scene, its history and its revisions.
pub struct Document {
    scene: Scene,
    undo: VecDeque<Step>,
    redo: Vec<Step>,
    /// Merge key of the last recorded edit; an edit with the same key folds into its step.
    last_key: Option<&'static str>,
    revisions: Revisions,
    /// Every edit of a keyable value is recorded as a key at the document's time (auto-key).
    auto_key: bool,
}

impl Default for Document {
    fn default() -> Self {
        Self::new(Scene::default())
    }
}

impl Document {
    /// A document holding `scene`, with an empty history.
    pub fn new(scene: Scene) -> Self {
        Self {
            scene,
            undo: VecDeque::new(),
            redo: Vec::new(),
            last_key: None,
            revisions: Revisions::fresh(),
            auto_key: false,
        }
    }

    /// Whether edits are keyed as they are made (auto-key).
    pub fn auto_key(&self) -> bool {
        self.auto_key
    }

    /// Turns auto-key on or off (view state, not an undo step).
    pub fn set_auto_key(&mut self, on: bool) {
        self.auto_key = on;
    }

    /// The scene as it stands.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The revision of each part.
    pub fn revisions(&self) -> Revisions {
        self.revisions
    }

    fn bump(&mut self, changed: Changed) {
        if !changed.any() {
            return;
        }
        let n = next_revision();
        let r = &mut self.revisions;
        for (flag, rev) in [
            (changed.geometry, &mut r.geometry),
            (changed.light, &mut r.light),
            (changed.render, &mut r.render),
            (changed.camera, &mut r.camera),
            (changed.reference, &mut r.reference),
            (changed.clock, &mut r.clock),
            (changed.time, &mut r.time),
        ] {
            if flag {
                *rev = n;
            }
        }
    }

    /// Applies `edit` and records an undo step. Edits that share a `merge_key` with the
    /// previous one (the same slider being dragged) fold into one step. Returns whether the
    /// document changed (an edit that changes nothing or cannot apply records nothing).
    pub fn apply(&mut self, edit: Edit, merge_key: Option<&'static str>) -> bool {
        let label = edit.label();
        let keys_edit = matches!(edit, Edit::SetAnimation(..));
        let moves = matches!(edit, Edit::SetEllipsoids(_) | Edit::SetWindField(_));
        // What auto-key records: the user's edits of values, not whole documents, the clock,
        // the picture or the simulation.
        let records = matches!(
            edit,
            Edit::SetLight(_)
                | Edit::SetRender(_)
                | Edit::SetEllipsoids(_)
                | Edit::SetPlanes(_)
                | Edit::SetPlane(..)
                | Edit::SetShot(_)
        );
        let s = &self.scene;
        let mut changed = Changed::default();
        match &edit {
            Edit::SetLight(l) => changed.light = *l != s.light,
            Edit::SetSimulation(sim) => {
                changed.geometry = sim.as_ref() != s.simulation.as_deref();
            }
            Edit::SetRender(r) => changed.render = *r != s.render,
            Edit::SetClock(c) => {
                let mut c = *c;
                c.sanitize();
                changed.clock = c != s.clock;
            }
            Edit::SetEllipsoids(e) => changed.geometry = !same(e, &s.ellipsoids),
            Edit::SetPlanes(p) => {
                changed.geometry = p.len() <= MAX_PLANES && !same(p, &s.planes);
            }
            Edit::SetPlane(i, p) => {
                changed.geometry = s.planes.get(*i).is_some_and(|old| **old != *p);
            }
            Edit::InsertPlane(i, _) => {
                changed.geometry = *i <= s.planes.len() && s.planes.len() < MAX_PLANES;
            }
            Edit::RemovePlane(i) => changed.geometry = *i < s.planes.len(),
            Edit::RemoveTier(i) => changed.render = *i < s.render.tiers.len(),
            Edit::SetReference(r) => changed.reference = r.as_ref() != s.reference.as_deref(),
            Edit::SetAnimation(a, _) => changed.clock = !a.same_as(&s.animation),
            Edit::SetShot(c) => changed.clock = *c != s.shot,
            Edit::SetWindField(w) => {
                let mut w = *w;
                w.sanitize();
                changed.geometry = w != s.wind_field;
            }
            Edit::Replace(new) => changed = diff(s, new),
        }
        if !changed.any() {
            return false;
        }
        let before = self.scene.clone();
        let s = &mut self.scene;
        match edit {
            Edit::SetLight(l) => s.light = l,
            Edit::SetSimulation(sim) => s.simulation = sim.map(Arc::new),
            Edit::SetRender(r) => s.render = r,
            Edit::RemoveTier(i) => {
                s.render.tiers.remove(i);
                let mut animation = s.animation.clone();
                if animation.tier_removed(i) {
                    s.animation = animation;
                    changed.clock = true;
                }
            }
            Edit::SetClock(mut c) => {
                c.sanitize();
                s.clock = c;
            }
            Edit::SetEllipsoids(e) => s.ellipsoids = e,
            Edit::SetPlanes(p) => s.planes = p,
            Edit::SetPlane(i, p) => s.planes[i] = Arc::new(p),
            Edit::InsertPlane(i, p) => s.planes.insert(i, Arc::new(p)),
            Edit::RemovePlane(i) => {
                s.planes.remove(i);
            }
            Edit::SetReference(r) => s.reference = r.map(Arc::new),
            Edit::SetAnimation(a, _) => s.animation = a,
            Edit::SetShot(c) => s.shot = c,
            Edit::SetWindField(mut w) => {
                w.sanitize();
                s.wind_field = w;
            }
            Edit::Replace(new) => *s = *new,
        }
        s.settle();
        // Moving ellipsoids: an edit of where one stands moves its start; a change of its
        // motion or of the wind moves it.
        if moves {
            s.rebase_motion(&before);
        }
        if keys_edit {
            // Keys moved or removed: the values they key follow at the document's time (an
            // unkeyed edit of another value stays).
            let t = s.time;
            let keyed = before.animation.changed_channels(&s.animation);
            s.pose_channels(t, &keyed);
            s.pose_motion(t);
            changed = diff(&before, s);
        } else if self.auto_key && records {
            let mut animation = s.animation.clone();
            if animation.record_changes(&before, s, s.time) > 0 {
                s.animation = animation;
                changed.clock = true;
            }
        }
        let merge = merge_key.is_some() && merge_key == self.last_key;
        if !merge {
            self.undo.push_back(Step {
                scene: before,
                label,
            });
            if self.undo.len() > MAX_UNDO {
                self.undo.pop_front();
            }
        }
        self.redo.clear();
        self.last_key = merge_key;
        self.bump(changed);
        true
    }

    /// Moves the camera. Not an undo step; bumps only the camera's revision.
    pub fn set_camera(&mut self, camera: OrbitCamera) {
        if camera != self.scene.camera {
            self.scene.camera = camera;
            self.bump(Changed {
                camera: true,
                ..Default::default()
            });
        }
    }

    /// Sets the scene clock (playing, scrubbing) and poses every keyed value there, which
    /// drops an edit of a keyed value not keyed (as Blender does). Not an undo step; bumps the
    /// time revision and those of the parts the pose moved (none where nothing is animated).
    pub fn set_time(&mut self, time: f32) {
        let time = if time.is_finite() {
            time.clamp(0.0, crate::limits::MAX_TIME)
        } else {
            0.0
        };
        if time != self.scene.time && !self.scene.is_animated() {
            // Nothing keyed or moving (every frame while playing): only the noise's motion
            // changes.
            self.scene.time = time;
            self.bump(Changed {
                time: true,
                ..Default::default()
            });
        } else if time != self.scene.time {
            let posed = self.scene.posed_at(time);
            let changed = diff(&self.scene, &posed);
            self.scene = posed;
            self.bump(Changed {
                time: true,
                ..changed
            });
        }
    }

    /// Ends the current merge run (pointer released), so the next edit is a new step.
    pub fn end_merge(&mut self) {
        self.last_key = None;
    }

    /// Takes back the merge run `key` under way (a drag cancelled with Esc): the document
    /// returns to where the run began and no undo or redo step remains of it. Returns whether
    /// there was such a run.
    pub fn revert_merge(&mut self, key: &'static str) -> bool {
        if self.last_key != Some(key) {
            return false;
        }
        let Some(step) = self.undo.pop_back() else {
            return false;
        };
        self.restore(step);
        true
    }

    /// Steps back; the camera stays where the user put it. Returns what was undone, or `None`
    /// when there is nothing to undo.
    pub fn undo(&mut self) -> Option<String> {
        self.step(true)
    }

    /// Steps forward again. Returns what was redone, or `None` when there is nothing to redo.
    pub fn redo(&mut self) -> Option<String> {
        self.step(false)
    }

    /// Undoes or redoes one step; returns what it did in words (what changed between the two
    /// scenes: "move 3 ellipsoids"), undoing and redoing alike said as the change was made.
    fn step(&mut self, back: bool) -> Option<String> {
        let step = if back {
            self.undo.pop_back()
        } else {
            self.redo.pop()
        }?;
        // Said of the step's scene as it stands at this time (its keyed values posed here), so
        // motion between the two times is not taken for an edit.
        let then = if step.scene.time == self.scene.time {
            step.scene.clone()
        } else {
            step.scene.posed_at(self.scene.time)
        };
        let say = |then: &Scene| {
            if back {
                super::edit::describe_change(then, &self.scene, step.label)
            } else {
                super::edit::describe_change(&self.scene, then, step.label)
            }
        };
        // An edit whose change the time has since taken away is said as it was made.
        let label = match say(&then) {
            bare if bare == step.label => say(&step.scene),
            said => said,
        };
        let done = self.restore(step);
        if back {
            self.redo.push(done);
        } else {
            self.undo.push_back(done);
        }
        Some(label)
    }

    /// Puts a step's scene in place (keeping the camera); returns the step that goes back to
    /// the scene it replaced.
    fn restore(&mut self, step: Step) -> Step {
        let mut scene = step.scene;
        scene.camera = self.scene.camera.clone();
        if scene.time != self.scene.time {
            // The step was made at another time: its keyed values are posed at this one.
            scene = scene.posed_at(self.scene.time);
        }
        let changed = diff(&self.scene, &scene);
        self.last_key = None;
        let previous = std::mem::replace(&mut self.scene, scene);
        self.bump(changed);
        Step {
            scene: previous,
            label: step.label,
        }
    }

    /// Number of undo steps available.
    pub fn undo_len(&self) -> usize {
        self.undo.len()
    }

    /// Number of redo steps available.
    pub fn redo_len(&self) -> usize {
        self.redo.len()
    }

    /// Every plane stroke held by the history and the scene, counted once per allocation
    /// (how much the undo history really holds).
    pub fn distinct_planes_held(&self) -> usize {
        let mut seen = std::collections::HashSet::new();
        let scenes = self
            .undo
            .iter()
            .chain(&self.redo)
            .map(|s| &s.scene)
            .chain(std::iter::once(&self.scene));
        for scene in scenes {
            for p in &scene.planes {
                seen.insert(Arc::as_ptr(p));
            }
        }
        seen.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{DrawingPlane, Ellipsoid};
    use glam::{Vec2, Vec3};

    #[test]
    fn undo_redo_round_trip() {
        let mut doc = Document::default();
        let original = doc.scene().clone();
        let mut r = doc.scene().render.clone();
        r.slices = 64;
        assert!(doc.apply(Edit::SetRender(r), None));
        assert_eq!(doc.scene().render.slices, 64);
        assert_eq!(doc.undo().as_deref(), Some("render settings"));
        assert_eq!(*doc.scene(), original);
        assert!(doc.redo().is_some());
        assert_eq!(doc.scene().render.slices, 64);
        assert!(doc.redo().is_none());
    }

    #[test]
    fn a_cancelled_drag_leaves_no_step_and_no_change() {
        let mut doc = Document::new(Scene::default());
        let before = doc.scene().clone();
        let undo = doc.undo_len();
        let mut l = doc.scene().light.clone();
        for az in [10.0, 20.0, 30.0] {
            l.sun_azimuth_deg = az;
            doc.apply(Edit::SetLight(l.clone()), Some("drag"));
        }
        assert!(!doc.revert_merge("other"), "only the run under way");
        assert!(doc.revert_merge("drag"));
        assert_eq!(*doc.scene(), before);
        assert_eq!((doc.undo_len(), doc.redo_len()), (undo, 0));
        assert!(!doc.revert_merge("drag"), "once");
    }

    #[test]
    fn slider_drags_merge_into_one_step() {
        let mut doc = Document::default();
        for s in [20, 30, 40] {
            let mut r = doc.scene().render.clone();
            r.slices = s;
            doc.apply(Edit::SetRender(r), Some("slices"));
        }
        assert_eq!(doc.undo_len(), 1);
        doc.end_merge();
        let mut r = doc.scene().render.clone();
        r.slices = 50;
        doc.apply(Edit::SetRender(r), Some("slices"));
        assert_eq!(doc.undo_len(), 2);
        doc.undo();
        assert_eq!(doc.scene().render.slices, 40);
    }

    #[test]
    fn no_op_and_invalid_edits_record_nothing() {
        let mut doc = Document::default();
        let revs = doc.revisions();
        let same = doc.scene().render.clone();
        assert!(!doc.apply(Edit::SetRender(same), None));
        assert!(!doc.apply(Edit::RemovePlane(3), None));
        assert!(!doc.apply(Edit::SetPlane(0, DrawingPlane::default()), None));
        assert_eq!(doc.undo_len(), 0);
        assert_eq!(doc.revisions(), revs);
    }

    #[test]
    fn camera_moves_are_not_undone_and_touch_only_the_camera_revision() {
        let mut doc = Document::default();
        doc.apply(Edit::SetEllipsoids(vec![]), None);
        let before = doc.revisions();
        let mut cam = doc.scene().camera.clone();
        cam.yaw_deg = 90.0;
        doc.set_camera(cam);
        let after = doc.revisions();
        assert!(after.camera > before.camera);
        assert_eq!(
            (after.geometry, after.light, after.render),
            (before.geometry, before.light, before.render)
        );
        assert_eq!(doc.undo_len(), 1, "a camera move is no undo step");
        doc.undo();
        assert_eq!(doc.scene().camera.yaw_deg, 90.0);
        assert!(!doc.scene().ellipsoids.is_empty());
    }

    #[test]
    fn the_clock_is_an_undo_step_that_touches_no_image() {
        let mut doc = Document::default();
        let r0 = doc.revisions();
        let clock = crate::scene::Clock {
            fps: 30.0,
            start: 100,
            end: 10,
        };
        assert!(doc.apply(Edit::SetClock(clock), Some("clock")));
        let r1 = doc.revisions();
        assert!(
            r1.clock > r0.clock && r1.any() > r0.any(),
            "the document changed"
        );
        assert_eq!(
            (r1.geometry, r1.light, r1.render, r1.camera),
            (r0.geometry, r0.light, r0.render, r0.camera),
            "no image depends on the frame rate"
        );
        assert_eq!((doc.scene().clock.start, doc.scene().clock.end), (100, 100));
        let said = doc.undo().unwrap();
        assert!(said.contains("frame rate"), "{said}");
        assert!(doc.scene().clock.is_default());
    }

    #[test]
    fn each_edit_bumps_only_its_part() {
        let mut doc = Document::default();
        let r0 = doc.revisions();
        let mut l = doc.scene().light.clone();
        l.sun_azimuth_deg += 10.0;
        doc.apply(Edit::SetLight(l), None);
        let r1 = doc.revisions();
        assert!(r1.light > r0.light);
        assert_eq!(
            (r1.geometry, r1.render, r1.camera),
            (r0.geometry, r0.render, r0.camera)
        );
        doc.apply(
            Edit::InsertPlane(
                0,
                DrawingPlane {
                    points: vec![Vec2::ZERO, Vec2::X, Vec2::Y],
                    ..Default::default()
                },
            ),
            None,
        );
        let r2 = doc.revisions();
        assert!(r2.geometry > r1.geometry);
        assert_eq!((r2.light, r2.render), (r1.light, r1.render));
        // Undoing the plane changes the geometry back, not the light.
        doc.undo();
        let r3 = doc.revisions();
        assert!(r3.geometry > r2.geometry);
        assert_eq!(r3.light, r2.light);
        // Undoing the light changes the light only.
        doc.undo();
        let r4 = doc.revisions();
        assert!(r4.light > r3.light);
        assert_eq!(r4.geometry, r3.geometry);
    }

    #[test]
    fn history_shares_unchanged_primitives() {
        // A scene at the plane cap with long strokes, then 200 slider steps and 50 single-plane
        // edits: the history holds one copy of each unchanged plane.
        let mut scene = Scene::preset(crate::scene::Preset::Empty);
        let points: Vec<Vec2> = (0..2000)
            .map(|i| Vec2::from_angle(i as f32 * 0.00314).rotate(Vec2::X))
            .collect();
        for i in 0..MAX_PLANES {
            scene.planes.push(Arc::new(DrawingPlane {
                name: format!("p{i}"),
                points: points.clone(),
                ..Default::default()
            }));
        }
        scene
            .ellipsoids
            .push(Arc::new(Ellipsoid::new(Vec3::ZERO, Vec3::ONE)));
        let mut doc = Document::new(scene);
        for i in 0..200 {
            let mut l = doc.scene().light.clone();
            l.ambient = i as f32 * 0.01;
            doc.apply(Edit::SetLight(l), None);
        }
        for i in 0..50 {
            let mut p = (*doc.scene().planes[i]).clone();
            p.origin.x += 1.0;
            doc.apply(Edit::SetPlane(i, p), None);
        }
        assert_eq!(doc.undo_len(), MAX_UNDO);
        assert_eq!(doc.distinct_planes_held(), MAX_PLANES + 50);
    }
}

#[cfg(test)]
mod reference_tests {
    use super::*;
    use crate::scene::ReferenceImage;

    #[test]
    fn reference_edits_undo_and_bump_only_their_revision() {
        let mut doc = Document::new(Scene::default());
        let before = doc.revisions();
        let image = ReferenceImage::facing(
            "a.png".into(),
            Arc::new(vec![1, 2, 3]),
            [4, 3],
            &doc.scene().camera,
            0.8,
        );
        assert!(doc.apply(Edit::SetReference(Some(image.clone())), None));
        let mut faded = image.clone();
        faded.opacity = 0.2;
        assert!(doc.apply(Edit::SetReference(Some(faded)), Some("reference")));
        let after = doc.revisions();
        assert_ne!(after.reference, before.reference);
        assert_eq!(
            (after.geometry, after.light, after.render, after.camera),
            (before.geometry, before.light, before.render, before.camera),
            "a reference edit re-derives nothing"
        );
        assert_eq!(doc.undo().as_deref(), Some("reference image"));
        assert_eq!(doc.scene().reference.as_deref(), Some(&image));
        doc.undo();
        assert!(doc.scene().reference.is_none());
    }
}
