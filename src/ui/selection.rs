//! What the user has selected: drawing planes and ellipsoids (one type for both, so tools, the
//! panel and the page state agree).

use crate::scene::Scene;

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

    /// Drops items the scene no longer has (after undo, delete, open).
    pub fn retain_valid(&mut self, scene: &Scene) {
        self.items.retain(|i| match i {
            Item::Plane(p) => *p < scene.planes.len(),
            Item::Ellipsoid(e) => *e < scene.ellipsoids.len(),
        });
    }
}
