//! Edits as values: every change a user makes to the document is one of these, applied by
//! [`super::Document::apply`], which records it for undo and bumps the revision of the part of
//! the document it touched. Camera moves are not edits (views are not undone, as in Blender):
//! they go through [`super::Document::set_camera`].

use std::sync::Arc;

use super::{Animation, DrawingPlane, Ellipsoid, Lighting, ReferenceImage, RenderSettings, Scene};

/// One change to the document.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Replace the lighting.
    SetLight(Lighting),
    /// Replace the render settings.
    SetRender(RenderSettings),
    /// Replace the clock's frame rate and range.
    SetClock(super::Clock),
    /// Replace the ellipsoid list.
    SetEllipsoids(Vec<Arc<Ellipsoid>>),
    /// Replace the whole list of drawing planes.
    SetPlanes(Vec<Arc<DrawingPlane>>),
    /// Replace drawing plane `index` (a slider or a drag on one plane).
    SetPlane(usize, DrawingPlane),
    /// Insert a drawing plane at `index` (a new stroke, a duplicate).
    InsertPlane(usize, DrawingPlane),
    /// Remove drawing plane `index`.
    RemovePlane(usize),
    /// Remove atmospheric tier `index` with its keys (the keys of the tiers above it move
    /// down with them).
    RemoveTier(usize),
    /// Set, change or remove the reference image.
    SetReference(Option<ReferenceImage>),
    /// Turn the simulation on (with these settings), change it, or turn it off.
    SetSimulation(Option<super::SimulationSettings>),
    /// Set, move or remove the shot camera.
    SetShot(Option<super::OrbitCamera>),
    /// Replace the wind field that carries the moving ellipsoids (they move with it).
    SetWindField(super::WindField),
    /// Replace the key frames, said as the label ("insert keys", "retime keys"); the keyed
    /// values are posed again at the document's time.
    SetAnimation(Animation, &'static str),
    /// Replace the whole document (new, open, preset).
    Replace(Box<Scene>),
}

impl Edit {
    /// What the edit changes, in words ("Undid: …").
    pub fn label(&self) -> &'static str {
        match self {
            Edit::SetLight(_) => "lighting",
            Edit::SetRender(_) => "render settings",
            Edit::SetClock(_) => "frame rate and range",
            Edit::SetEllipsoids(_) => "ellipsoids",
            Edit::SetPlanes(_) => "drawing planes",
            Edit::SetPlane(..) => "drawing plane",
            Edit::InsertPlane(..) => "new drawing plane",
            Edit::RemovePlane(_) => "deleted drawing plane",
            Edit::RemoveTier(_) => "removed tier",
            Edit::SetReference(_) => "reference image",
            Edit::SetSimulation(_) => "simulation",
            Edit::SetShot(_) => "shot camera",
            Edit::SetWindField(_) => "wind field",
            Edit::SetAnimation(_, label) => label,
            Edit::Replace(_) => "new scene",
        }
    }
}

/// What changed from `from` to `to` in words for the undo notice ("move 3 ellipsoids", "add a
/// drawing plane", "hide an ellipsoid and a drawing plane"): the ellipsoids and drawing planes
/// counted by what changed in them; anything else by the edit's `label`.
pub fn describe_change(from: &Scene, to: &Scene, label: &str) -> String {
    let ellipsoids = list_change(
        &from.ellipsoids,
        &to.ellipsoids,
        ("an ellipsoid", "ellipsoids"),
        |a, b| {
            // Where a moving one starts follows a move (no change of its motion); where it
            // stands follows a change of its motion (no move).
            let motion = a.motion.map(|m| m.with_start_of(b)) != b.motion;
            [
                ("move", a.center != b.center && !motion),
                ("rotate", a.rotation != b.rotation),
                ("scale", a.radii != b.radii && !motion),
                ("change the strength of", a.strength != b.strength),
                ("change the billows of", a.billows != b.billows),
                ("change the motion of", motion),
                (if b.hidden { "hide" } else { "show" }, a.hidden != b.hidden),
            ]
        },
    );
    let planes = list_change(
        &from.planes,
        &to.planes,
        ("a drawing plane", "drawing planes"),
        |a, b| {
            [
                ("move", a.origin != b.origin),
                ("rotate", a.rotation != b.rotation),
                (
                    "redraw",
                    a.points != b.points || a.kind != b.kind || a.closed != b.closed,
                ),
                (
                    "change",
                    a.sketch != b.sketch || a.name != b.name || a.seed != b.seed,
                ),
                ("change the billows of", a.billows != b.billows),
                (if b.hidden { "hide" } else { "show" }, a.hidden != b.hidden),
            ]
        },
    );
    let others = from.light != to.light
        || from.render != to.render
        || from.reference != to.reference
        || from.simulation != to.simulation
        || from.clock != to.clock
        || from.shot != to.shot
        || from.wind_field != to.wind_field;
    let parts: Vec<String> = ellipsoids.into_iter().chain(planes).collect();
    // A key edit says what it did to the keys (a retime that moves an ellipsoid is no move);
    // an edit that auto-key recorded says it was keyed.
    if !from.animation.same_as(&to.animation) {
        if KEY_EDITS.contains(&label) || parts.is_empty() || others {
            return label.to_owned();
        }
        let what = describe_change(
            &Scene {
                animation: to.animation.clone(),
                ..from.clone()
            },
            to,
            label,
        );
        // Keys added with the edit: auto-key recorded it (keys gone with deleted items are
        // no keying).
        let keyed = to.animation.key_count() > from.animation.key_count();
        return if keyed {
            format!("{what}, keyed")
        } else {
            what
        };
    }
    match (parts.as_slice(), others) {
        ([], _) | (_, true) => label.to_owned(),
        ([one], false) => one.clone(),
        (many, false) => {
            // One verb for all when they share it: "move 2 ellipsoids and a drawing plane".
            let verbs: Vec<&str> = many.iter().filter_map(|p| p.split(' ').next()).collect();
            if verbs.windows(2).all(|w| w[0] == w[1]) {
                let verb = verbs[0];
                let objects: Vec<&str> = many.iter().map(|p| &p[verb.len() + 1..]).collect();
                format!("{verb} {}", objects.join(" and "))
            } else {
                many.join(", ")
            }
        }
    }
}

/// The labels of the timeline's key edits ([`Edit::SetAnimation`]).
pub const KEY_EDITS: [&str; 4] = [
    "insert keys",
    "delete keys",
    "retime keys",
    "change the ease of keys",
];

/// One list's change in words: items added, deleted, or changed (each changed item by the one
/// kind of change `kinds` finds in it, or "edit" when several).
fn list_change<T: PartialEq, const N: usize>(
    from: &[Arc<T>],
    to: &[Arc<T>],
    (one, many): (&str, &str),
    kinds: impl Fn(&T, &T) -> [(&'static str, bool); N],
) -> Option<String> {
    let count = |n: usize| {
        if n == 1 {
            one.to_owned()
        } else {
            format!("{n} {many}")
        }
    };
    if to.len() > from.len() {
        return Some(format!("add {}", count(to.len() - from.len())));
    }
    if to.len() < from.len() {
        return Some(format!("delete {}", count(from.len() - to.len())));
    }
    let mut verbs: Vec<&'static str> = Vec::new();
    let mut changed = 0;
    for (a, b) in from.iter().zip(to) {
        if Arc::ptr_eq(a, b) || **a == **b {
            continue;
        }
        changed += 1;
        let found: Vec<&'static str> = kinds(a, b)
            .into_iter()
            .filter_map(|(verb, yes)| yes.then_some(verb))
            .collect();
        verbs.push(if found.len() == 1 { found[0] } else { "edit" });
    }
    if changed == 0 {
        return None;
    }
    let verb = if verbs.windows(2).all(|w| w[0] == w[1]) {
        verbs[0]
    } else {
        "edit"
    };
    Some(format!("{verb} {}", count(changed)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Preset;

    #[test]
    fn a_change_is_said_by_what_it_did_and_to_how_many() {
        let before = Scene::preset(Preset::Cumulus);
        let mut after = before.clone();
        for e in after.ellipsoids.iter_mut().take(3) {
            Arc::make_mut(e).center.x += 1.0;
        }
        assert_eq!(
            describe_change(&before, &after, "ellipsoids"),
            "move 3 ellipsoids"
        );
        let mut one = before.clone();
        Arc::make_mut(&mut one.ellipsoids[0]).hidden = true;
        assert_eq!(
            describe_change(&before, &one, "ellipsoids"),
            "hide an ellipsoid"
        );
        let mut fewer = before.clone();
        fewer.ellipsoids.truncate(before.ellipsoids.len() - 2);
        assert_eq!(
            describe_change(&before, &fewer, "ellipsoids"),
            "delete 2 ellipsoids"
        );
        // Something else than shapes: the edit's own word.
        let mut lit = before.clone();
        lit.light.sun_intensity += 1.0;
        assert_eq!(describe_change(&before, &lit, "lighting"), "lighting");
        // Ellipsoids and a plane moved together.
        let mut with_plane = before.clone();
        with_plane.planes.push(Arc::new(DrawingPlane::default()));
        let mut moved = with_plane.clone();
        Arc::make_mut(&mut moved.ellipsoids[0]).center.y += 1.0;
        Arc::make_mut(&mut moved.ellipsoids[1]).center.y += 1.0;
        Arc::make_mut(&mut moved.planes[0]).origin.y += 1.0;
        assert_eq!(
            describe_change(&with_plane, &moved, "ellipsoids"),
            "move 2 ellipsoids and a drawing plane"
        );
    }
}
