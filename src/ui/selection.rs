//! What the user has selected: drawing planes and ellipsoids (one type for both, so tools, the
//! panel and the page state agree), and the edits that act on the whole selection: delete,
//! duplicate, hide and show (each one undo step).

use std::sync::Arc;

use crate::scene::{Document, Edit, MAX_ELLIPSOIDS, MAX_PLANES, Scene};
use crate::seeded::hash64;

/// One selectable thing in the document.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Item {
    /// Drawing plane by index.
    Plane(usize),
    /// Ellipsoid by index.
    Ellipsoid(usize),
}

impl Item {
    /// The plane index, if this is a plane.
    pub fn plane(&self) -> Option<usize> {
        match self {
            Item::Plane(p) => Some(*p),
            Item::Ellipsoid(_) => None,
        }
    }

    /// The ellipsoid index, if this is an ellipsoid.
    pub fn ellipsoid(&self) -> Option<usize> {
        match self {
            Item::Ellipsoid(e) => Some(*e),
            Item::Plane(_) => None,
        }
    }
}

/// The selection; the last item added is the active one.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Selection {
    items: Vec<Item>,
}

impl Selection {
    /// Selects only `item`.
    pub fn set(&mut self, item: Item) {
        self.items = vec![item];
    }

    /// Selects nothing.
    pub fn clear(&mut self) {
        self.items.clear();
    }

    /// Adds `item` (as the active one), or takes it out when it is selected (Shift+click).
    pub fn toggle(&mut self, item: Item) {
        match self.items.iter().position(|&i| i == item) {
            Some(at) => {
                self.items.remove(at);
            }
            None => self.items.push(item),
        }
    }

    /// Selects `items` (the last one active), or adds them to the selection.
    pub fn select_all(&mut self, items: impl IntoIterator<Item = Item>, add: bool) {
        if !add {
            self.items.clear();
        }
        for item in items {
            if !self.items.contains(&item) {
                self.items.push(item);
            }
        }
    }

    /// Every selected item, the active one last.
    pub fn items(&self) -> &[Item] {
        &self.items
    }

    /// The item Move, Rotate and Scale place their gizmo on (the last one selected).
    pub fn active(&self) -> Option<Item> {
        self.items.last().copied()
    }

    /// Whether nothing is selected.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The active drawing plane, if one is selected.
    pub fn plane(&self) -> Option<usize> {
        self.items.iter().rev().find_map(Item::plane)
    }

    /// The active ellipsoid, if one is selected.
    pub fn ellipsoid(&self) -> Option<usize> {
        self.items.iter().rev().find_map(Item::ellipsoid)
    }

    /// Selects plane `index` alone, or nothing for `None`.
    pub fn set_plane(&mut self, index: Option<usize>) {
        match index {
            Some(i) => self.set(Item::Plane(i)),
            None => self.clear(),
        }
    }

    /// Whether `item` is selected.
    pub fn contains(&self, item: Item) -> bool {
        self.items.contains(&item)
    }

    /// A sphere (centre, radius) holding every selected item: an ellipsoid's radii, a plane's
    /// stroke. `None` for an empty selection.
    pub fn bounds(&self, scene: &Scene) -> Option<(glam::Vec3, f32)> {
        let mut lo = glam::Vec3::splat(f32::INFINITY);
        let mut hi = -lo;
        for item in &self.items {
            match *item {
                Item::Ellipsoid(e) => {
                    let Some(e) = scene.ellipsoids.get(e) else {
                        continue;
                    };
                    let r = e.radii.max_element();
                    lo = lo.min(e.center - r);
                    hi = hi.max(e.center + r);
                }
                Item::Plane(p) => {
                    let Some(p) = scene.planes.get(p) else {
                        continue;
                    };
                    for q in &p.points {
                        let w = p.to_world(q.extend(0.0));
                        lo = lo.min(w);
                        hi = hi.max(w);
                    }
                }
            }
        }
        lo.cmple(hi)
            .all()
            .then(|| ((lo + hi) * 0.5, ((hi - lo).length() * 0.5).max(0.05)))
    }

    /// Drops items the scene no longer has (after undo, delete, open).
    pub fn retain_valid(&mut self, scene: &Scene) {
        self.items.retain(|i| match i {
            Item::Plane(p) => *p < scene.planes.len(),
            Item::Ellipsoid(e) => *e < scene.ellipsoids.len(),
        });
    }
}

/// The selected plane and ellipsoid indices that exist, each sorted.
fn indices(scene: &Scene, selection: &Selection) -> (Vec<usize>, Vec<usize>) {
    let mut planes: Vec<usize> = selection.items.iter().filter_map(Item::plane).collect();
    let mut ellipsoids: Vec<usize> = selection.items.iter().filter_map(Item::ellipsoid).collect();
    planes.retain(|&i| i < scene.planes.len());
    ellipsoids.retain(|&i| i < scene.ellipsoids.len());
    planes.sort_unstable();
    ellipsoids.sort_unstable();
    (planes, ellipsoids)
}

/// Applies a new plane list and a new ellipsoid list as one undo step.
fn apply_lists(
    doc: &mut Document,
    planes: Vec<Arc<crate::scene::DrawingPlane>>,
    ellipsoids: Vec<Arc<crate::scene::Ellipsoid>>,
) -> bool {
    doc.end_merge();
    let a = doc.apply(Edit::SetPlanes(planes), Some("selection"));
    let b = doc.apply(Edit::SetEllipsoids(ellipsoids), Some("selection"));
    doc.end_merge();
    a || b
}

/// Deletes every selected plane and ellipsoid, as one undo step; returns what was done.
pub fn delete(doc: &mut Document, selection: &mut Selection) -> Option<String> {
    let scene = doc.scene();
    let (planes, ellipsoids) = indices(scene, selection);
    let text = match (planes.as_slice(), ellipsoids.as_slice()) {
        ([], []) => return None,
        ([p], []) => format!("Deleted {} (Ctrl+Z undoes)", scene.planes[*p].name),
        ([], [e]) => format!("Deleted Ellipsoid {} (Ctrl+Z undoes)", e + 1),
        _ => format!(
            "Deleted {} items (Ctrl+Z undoes)",
            planes.len() + ellipsoids.len()
        ),
    };
    let keep = |list: &[usize], i: usize| list.binary_search(&i).is_err();
    let new_planes = (scene.planes.iter().enumerate())
        .filter(|(i, _)| keep(&planes, *i))
        .map(|(_, p)| p.clone())
        .collect();
    let new_ellipsoids = (scene.ellipsoids.iter().enumerate())
        .filter(|(i, _)| keep(&ellipsoids, *i))
        .map(|(_, e)| e.clone())
        .collect();
    apply_lists(doc, new_planes, new_ellipsoids).then(|| {
        selection.clear();
        text
    })
}

/// Duplicates every selected item, as one undo step, and selects the copies: a plane's copy
/// goes right after it in the list, behind it by a third of its width (so it thickens the
/// cloud); an ellipsoid's copy to the view's right by its radius. Returns what was done.
pub fn duplicate(doc: &mut Document, selection: &mut Selection) -> Option<String> {
    let scene = doc.scene();
    let (planes, ellipsoids) = indices(scene, selection);
    if planes.is_empty() && ellipsoids.is_empty() {
        return None;
    }
    if scene.planes.len() + planes.len() > MAX_PLANES {
        return Some(format!(
            "at most {MAX_PLANES} drawing planes: delete some first"
        ));
    }
    if scene.ellipsoids.len() + ellipsoids.len() > MAX_ELLIPSOIDS {
        return Some(format!(
            "at most {MAX_ELLIPSOIDS} ellipsoids: delete some first"
        ));
    }
    let mut new_planes = scene.planes.clone();
    let mut copies = Vec::new();
    for (k, &i) in planes.iter().enumerate() {
        let mut copy = (*scene.planes[i]).clone();
        let (lo, hi) = copy
            .points
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), p| (a.min(p.x), b.max(p.x)));
        copy.origin -= copy.normal() * ((hi - lo).max(0.1) / 3.0);
        copy.name = format!("{} copy", copy.name);
        copy.seed = hash64(copy.seed);
        // Earlier copies shifted this one's original by k places.
        new_planes.insert(i + k + 1, Arc::new(copy));
        copies.push(Item::Plane(i + k + 1));
    }
    let mut new_ellipsoids = scene.ellipsoids.clone();
    for &i in &ellipsoids {
        let mut copy = (*scene.ellipsoids[i]).clone();
        copy.center += scene.camera.right() * copy.radii.x;
        new_ellipsoids.push(Arc::new(copy));
        copies.push(Item::Ellipsoid(new_ellipsoids.len() - 1));
    }
    let text = match copies.as_slice() {
        [Item::Plane(p)] => format!("Added {}", new_planes[*p].name),
        [Item::Ellipsoid(e)] => format!("Added Ellipsoid {} (a copy)", e + 1),
        _ => format!("Duplicated {} items", copies.len()),
    };
    apply_lists(doc, new_planes, new_ellipsoids).then(|| {
        selection.select_all(copies, false);
        text
    })
}

/// Hides the selected plane or ellipsoid (kept in the document, left out of the cloud), or
/// shows it again (Shift+H); one undo step. Returns what was done.
pub fn toggle_hidden(doc: &mut Document, selection: &Selection) -> Option<String> {
    let scene = doc.scene();
    if let Some(i) = selection.plane() {
        let mut p = (**scene.planes.get(i)?).clone();
        p.hidden = !p.hidden;
        let text = format!("{} {}", if p.hidden { "Hid" } else { "Showed" }, p.name);
        return doc.apply(Edit::SetPlane(i, p), None).then_some(text);
    }
    let i = selection.ellipsoid()?;
    let mut list = scene.ellipsoids.clone();
    let mut e = (**list.get(i)?).clone();
    e.hidden = !e.hidden;
    let text = format!(
        "{} Ellipsoid {}",
        if e.hidden { "Hid" } else { "Showed" },
        i + 1
    );
    list[i] = Arc::new(e);
    doc.apply(Edit::SetEllipsoids(list), None).then_some(text)
}

/// Shows every hidden plane and ellipsoid (Alt+H), as one undo step. Returns what was done.
pub fn show_all(doc: &mut Document) -> Option<String> {
    let scene = doc.scene();
    let count = scene.planes.iter().filter(|p| p.hidden).count()
        + scene.ellipsoids.iter().filter(|e| e.hidden).count();
    if count == 0 {
        return None;
    }
    // Each hidden item replaced by a shown copy; the others shared as they are.
    fn shown<T: Clone>(items: &[Arc<T>], hidden: fn(&T) -> bool, show: fn(&mut T)) -> Vec<Arc<T>> {
        items
            .iter()
            .map(|item| match hidden(item) {
                true => {
                    let mut copy = (**item).clone();
                    show(&mut copy);
                    Arc::new(copy)
                }
                false => item.clone(),
            })
            .collect()
    }
    let planes = shown(&scene.planes, |p| p.hidden, |p| p.hidden = false);
    let ellipsoids = shown(&scene.ellipsoids, |e| e.hidden, |e| e.hidden = false);
    // Two edits folded into one undo step.
    doc.end_merge();
    doc.apply(Edit::SetPlanes(planes), Some("show-all"));
    doc.apply(Edit::SetEllipsoids(ellipsoids), Some("show-all"));
    doc.end_merge();
    Some(format!(
        "Showed {count} hidden item{}",
        if count == 1 { "" } else { "s" }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Preset;

    #[test]
    fn duplicate_and_delete_act_on_the_whole_selection_in_one_step() {
        let mut doc = Document::new(Scene::preset(Preset::Cumulus));
        let planes = doc.scene().planes.len();
        let n = doc.scene().ellipsoids.len();
        let mut selection = Selection::default();
        selection.set(Item::Ellipsoid(1));
        assert_eq!(
            duplicate(&mut doc, &mut selection).unwrap(),
            format!("Added Ellipsoid {} (a copy)", n + 1)
        );
        assert_eq!(selection.items(), &[Item::Ellipsoid(n)]);
        // Three at once, with Shift: one step each way.
        selection.toggle(Item::Ellipsoid(0));
        selection.toggle(Item::Ellipsoid(3));
        let undo = doc.undo_len();
        assert_eq!(
            duplicate(&mut doc, &mut selection).unwrap(),
            "Duplicated 3 items"
        );
        assert_eq!(doc.scene().ellipsoids.len(), n + 4);
        assert_eq!(doc.undo_len(), undo + 1);
        let copies: Vec<_> = selection.items().to_vec();
        assert_eq!(
            delete(&mut doc, &mut selection).unwrap(),
            "Deleted 3 items (Ctrl+Z undoes)"
        );
        assert_eq!(doc.scene().ellipsoids.len(), n + 1);
        assert!(selection.is_empty());
        doc.undo();
        assert_eq!(doc.scene().ellipsoids.len(), n + 4);
        assert_eq!(copies.len(), 3);
        assert_eq!(doc.scene().planes.len(), planes);
    }

    #[test]
    fn a_plane_s_copy_goes_right_after_it_behind_it() {
        let mut scene = Scene::preset(Preset::Empty);
        for name in ["A", "B"] {
            scene.planes.push(Arc::new(crate::scene::DrawingPlane {
                name: name.into(),
                points: vec![
                    glam::Vec2::ZERO,
                    glam::Vec2::new(3.0, 0.0),
                    glam::Vec2::new(0.0, 2.0),
                ],
                ..Default::default()
            }));
        }
        let mut doc = Document::new(scene);
        let mut selection = Selection::default();
        selection.select_all([Item::Plane(0), Item::Plane(1)], false);
        duplicate(&mut doc, &mut selection).unwrap();
        let names: Vec<_> = doc.scene().planes.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["A", "A copy", "B", "B copy"]);
        assert_eq!(selection.items(), &[Item::Plane(1), Item::Plane(3)]);
        let behind = doc.scene().planes[1].origin - doc.scene().planes[0].origin;
        assert!(
            (behind + doc.scene().planes[0].normal()).length() < 1e-5,
            "{behind}"
        );
    }

    #[test]
    fn hiding_leaves_the_item_out_of_the_cloud_and_undoes_in_one_step() {
        let mut doc = Document::new(Scene::preset(Preset::Cumulus));
        let full = crate::derive::field_of(doc.scene());
        let mut selection = Selection::default();
        selection.set(Item::Ellipsoid(0));
        let centre = doc.scene().ellipsoids[0].center;
        toggle_hidden(&mut doc, &selection).unwrap();
        assert!(doc.scene().ellipsoids[0].hidden);
        let hidden = crate::derive::field_of(doc.scene());
        // A billowed ellipsoid is a group of its core and puffs.
        let sources = |f: &crate::field::Field| f.blobs.len() + f.groups.len();
        assert_eq!(sources(&hidden), sources(&full) - 1);
        assert!(hidden.value(centre) < full.value(centre));
        selection.set(Item::Ellipsoid(2));
        toggle_hidden(&mut doc, &selection).unwrap();
        let undo = doc.undo_len();
        assert_eq!(show_all(&mut doc).unwrap(), "Showed 2 hidden items");
        assert_eq!(doc.undo_len(), undo + 1, "one step");
        assert_eq!(crate::derive::field_of(doc.scene()), full);
        assert!(show_all(&mut doc).is_none(), "nothing hidden");
        doc.undo();
        assert!(doc.scene().ellipsoids[0].hidden && doc.scene().ellipsoids[2].hidden);
    }
}
