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

/// A new puff's radius as a share of the local scale of what it lands on (half the size of
/// the part under it: a smaller puff on a larger one, as cumulus build up).
const PUFF_SHARE: f32 = 0.5;

/// Where a click at `p` lands: the cloud's surface under it, with the local scale there (the
/// mean radius of the ellipsoid that shapes the cloud there, or for a sketched part half the
/// cloud's depth along the ray from the hit), or the plane through the focus point facing the
/// view, with no scale.
fn landing(
    doc: &Document,
    derived: &mut Derived,
    rect: Rect,
    p: Pos2,
) -> Option<(Vec3, Option<f32>)> {
    let scene = doc.scene();
    let camera = &scene.camera;
    let ray = ray_at(camera, rect, p);
    let field = derived.field(scene, Some(doc.revisions().geometry));
    let step = field
        .bounding_sphere()
        .map(|(_, r)| r / 200.0)
        .unwrap_or(0.05);
    if let Some(hit) = field.raycast(&ray, step) {
        let scale = match most_at(&scene.ellipsoids, hit) {
            Some(i) => {
                let r = scene.ellipsoids[i].radii;
                (r.x * r.y * r.z).cbrt()
            }
            None => {
                // How far the ray stays inside past the hit (at most 400 steps).
                let inside = (1..=400)
                    .take_while(|k| {
                        field.inside(ray.at((hit - ray.origin).length() + *k as f32 * step))
                    })
                    .count();
                0.5 * (inside as f32 + 1.0) * step
            }
        };
        return Some((hit, Some(scale)));
    }
    ray.hit_plane(camera.target, -camera.forward())
        .map(|t| (ray.at(t), None))
}

/// Adds an ellipsoid where a click at `p` lands, sized for what it lands on (half the local
/// scale of the cloud there; over the sky, for the view); selects it. Returns what was done.
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
    let (center, scale) = landing(doc, derived, rect, p)?;
    let camera = &doc.scene().camera;
    let depth = (center - camera.eye()).dot(camera.forward()).max(0.1);
    let view_size = camera.world_per_px(depth, rect.height()) * rect.height() * NEW_SIZE;
    // Sized for what it lands on, within a twentieth and twice the view's size.
    let r = scale.map_or(view_size, |s| {
        (PUFF_SHARE * s).clamp(0.05 * view_size, 2.0 * view_size)
    });
    // Wider than tall, as the puffs of a cumulus are.
    let e = Ellipsoid::new(center, Vec3::new(1.4 * r, r, 1.2 * r)).billowed();
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
    fn a_new_ellipsoid_is_sized_for_what_it_lands_on() {
        // A big ellipsoid and a small one side by side: a click on each adds a puff about
        // half its size (one size for the view before, whatever it landed on).
        let mut scene = Scene::preset(Preset::Empty);
        scene.ellipsoids = vec![
            Arc::new(Ellipsoid::new(Vec3::new(-3.0, 3.0, 0.0), Vec3::splat(2.5))),
            Arc::new(Ellipsoid::new(Vec3::new(3.0, 3.0, 0.0), Vec3::splat(0.6))),
        ];
        let camera = scene.camera.clone();
        let mut doc = Document::new(scene);
        let mut derived = Derived::default();
        let mut selection = Selection::default();
        let mut added = Vec::new();
        for centre in [Vec3::new(-3.0, 3.0, 0.0), Vec3::new(3.0, 3.0, 0.0)] {
            let at = crate::ui::projection::project(&camera, view(), centre).unwrap();
            add_at(&mut doc, &mut derived, &mut selection, view(), at).unwrap();
            added.push(doc.scene().ellipsoids.last().unwrap().radii.y);
        }
        let (on_big, on_small) = (added[0], added[1]);
        assert!((on_big - 1.25).abs() < 0.2, "{on_big} on the big one");
        assert!((on_small - 0.3).abs() < 0.1, "{on_small} on the small one");
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
