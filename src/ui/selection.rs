//! What the user has selected: drawing planes and ellipsoids (one type for both, so tools, the
//! panel and the page state agree).

use std::sync::Arc;

use crate::scene::{Document, Edit, Scene};

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
                    let Some(e) = scene.ellipsoids.get(e) else { continue };
                    let r = e.radii.max_element();
                    lo = lo.min(e.center - r);
                    hi = hi.max(e.center + r);
                }
                Item::Plane(p) => {
                    let Some(p) = scene.planes.get(p) else { continue };
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
    let text = format!("{} Ellipsoid {}", if e.hidden { "Hid" } else { "Showed" }, i + 1);
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
    let planes = scene
        .planes
        .iter()
        .map(|p| match p.hidden {
            true => Arc::new(crate::scene::DrawingPlane {
                hidden: false,
                ..(**p).clone()
            }),
            false => p.clone(),
        })
        .collect();
    let ellipsoids = scene
        .ellipsoids
        .iter()
        .map(|e| match e.hidden {
            true => Arc::new(crate::scene::Ellipsoid {
                hidden: false,
                ..(**e).clone()
            }),
            false => e.clone(),
        })
        .collect();
    // Two edits folded into one undo step.
    doc.end_merge();
    doc.apply(Edit::SetPlanes(planes), Some("show-all"));
    doc.apply(Edit::SetEllipsoids(ellipsoids), Some("show-all"));
    doc.end_merge();
    Some(format!("Showed {count} hidden item{}", if count == 1 { "" } else { "s" }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Preset;

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
        assert_eq!(hidden.blobs.len(), full.blobs.len() - 1);
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
