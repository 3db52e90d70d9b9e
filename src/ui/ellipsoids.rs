//! Ellipsoids in the view (Schpok et al. §3): adding one where the user clicks, picking the one
//! that shapes the cloud under the pointer, setting one. Every change is one undoable edit of
//! the document's ellipsoid list (duplicate and delete act on the selection: `selection`).

use std::sync::Arc;

use egui::{Pos2, Rect};
use glam::Vec3;

use super::projection::ray_at;
use super::selection::{Item, Selection};
use crate::derive::Derived;
use crate::field::Blob;
use crate::scene::{Document, Edit, Ellipsoid, MAX_ELLIPSOIDS};

/// Share of the view's height a new ellipsoid's vertical radius takes.
const NEW_SIZE: f32 = 0.12;

/// Where a click at `p` lands: the cloud's surface under it, or the plane through the focus
/// point facing the view.
fn landing(doc: &Document, derived: &mut Derived, rect: Rect, p: Pos2) -> Option<Vec3> {
    let scene = doc.scene();
    let camera = &scene.camera;
    let ray = ray_at(camera, rect, p);
    let field = derived.field(scene, Some(doc.revisions().geometry));
    let step = field
        .bounding_sphere()
        .map(|(_, r)| r / 200.0)
        .unwrap_or(0.05);
    field.raycast(&ray, step).or_else(|| {
        ray.hit_plane(camera.target, -camera.forward())
            .map(|t| ray.at(t))
    })
}

/// Adds an ellipsoid where a click at `p` lands, sized for the view; selects it. Returns what
/// was done.
pub fn add_at(
    doc: &mut Document,
    derived: &mut Derived,
    selection: &mut Selection,
    rect: Rect,
    p: Pos2,
) -> Option<String> {
    let scene = doc.scene();
    if scene.ellipsoids.len() >= MAX_ELLIPSOIDS {
        return Some(format!(
            "at most {MAX_ELLIPSOIDS} ellipsoids: delete one first"
        ));
    }
    let center = landing(doc, derived, rect, p)?;
    let camera = &doc.scene().camera;
    let depth = (center - camera.eye()).dot(camera.forward()).max(0.1);
    let r = camera.world_per_px(depth, rect.height()) * rect.height() * NEW_SIZE;
    // Wider than tall, as the puffs of a cumulus are.
    let e = Ellipsoid::new(center, Vec3::new(1.4 * r, r, 1.2 * r));
    let mut list = doc.scene().ellipsoids.clone();
    list.push(Arc::new(e));
    let index = list.len() - 1;
    doc.apply(Edit::SetEllipsoids(list), None).then(|| {
        selection.set(Item::Ellipsoid(index));
        format!("Added Ellipsoid {} (Ctrl+Z undoes)", index + 1)
    })
}

/// The ellipsoid that contributes most to the cloud where a click at `p` meets it, if the
/// click meets the cloud and an ellipsoid reaches there.
pub fn pick(doc: &Document, derived: &mut Derived, rect: Rect, p: Pos2) -> Option<usize> {
    let scene = doc.scene();
    let ray = ray_at(&scene.camera, rect, p);
    let field = derived.field(scene, Some(doc.revisions().geometry));
    let step = field
        .bounding_sphere()
        .map(|(_, r)| r / 200.0)
        .unwrap_or(0.05);
    let at = field.raycast(&ray, step)?;
    most_at(&scene.ellipsoids, at)
}

/// The ellipsoid with the largest field value at `at` (none when none reaches it).
pub fn most_at(ellipsoids: &[Arc<Ellipsoid>], at: Vec3) -> Option<usize> {
    ellipsoids
        .iter()
        .map(|e| {
            if e.hidden {
                0.0
            } else {
                Blob::ellipsoid(e).value(at)
            }
        })
        .enumerate()
        .filter(|&(_, v)| v > 0.0)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
}

/// Replaces ellipsoid `i` (one edit; `merge` folds a drag into one undo step).
pub fn set(doc: &mut Document, i: usize, e: Ellipsoid, merge: Option<&'static str>) -> bool {
    let mut list = doc.scene().ellipsoids.clone();
    let Some(slot) = list.get_mut(i) else {
        return false;
    };
    *slot = Arc::new(e);
    doc.apply(Edit::SetEllipsoids(list), merge)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Preset, Scene};

    use crate::ui::test_view as view;

    #[test]
    fn a_click_adds_an_ellipsoid_where_it_lands_and_picking_finds_it() {
        let mut doc = Document::new(Scene::preset(Preset::Empty));
        let mut derived = Derived::default();
        let mut selection = Selection::default();
        // Over the empty sky: on the focus plane, under the click.
        let at = Pos2::new(700.0, 380.0);
        add_at(&mut doc, &mut derived, &mut selection, view(), at).unwrap();
        let e = doc.scene().ellipsoids[0].clone();
        let camera = doc.scene().camera.clone();
        let ndc = camera.project(e.center, view().aspect_ratio()).unwrap();
        let screen = Pos2::new((ndc.x + 1.0) * 640.0, (1.0 - ndc.y) * 400.0);
        assert!(screen.distance(at) < 1.0, "{screen:?}");
        assert_eq!(selection.ellipsoid(), Some(0));
        // A second one clicked on the first lands on its surface, in front of its centre.
        add_at(&mut doc, &mut derived, &mut selection, view(), at).unwrap();
        let second = doc.scene().ellipsoids[1].center;
        let toward = (second - e.center).dot(-camera.forward());
        assert!(toward > 0.5 * e.radii.z, "{toward}");
        // Picking under the click finds one of them; away from both, none.
        assert!(pick(&doc, &mut derived, view(), at).is_some());
        assert_eq!(
            pick(&doc, &mut derived, view(), Pos2::new(20.0, 20.0)),
            None
        );
        // Undo takes the ellipsoids away one at a time.
        doc.undo();
        assert_eq!(doc.scene().ellipsoids.len(), 1);
    }

    #[test]
    fn the_ellipsoid_that_contributes_most_is_picked() {
        let list: Vec<Arc<Ellipsoid>> = [
            Ellipsoid::new(Vec3::ZERO, Vec3::ONE),
            Ellipsoid::new(Vec3::new(1.5, 0.0, 0.0), Vec3::ONE),
        ]
        .into_iter()
        .map(Arc::new)
        .collect();
        assert_eq!(most_at(&list, Vec3::new(0.2, 0.0, 0.0)), Some(0));
        assert_eq!(most_at(&list, Vec3::new(1.3, 0.0, 0.0)), Some(1));
        assert_eq!(most_at(&list, Vec3::new(9.0, 0.0, 0.0)), None);
    }
}
