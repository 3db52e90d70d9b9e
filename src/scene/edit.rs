//! Edits as values: every change a user makes to the document is one of these, applied by
//! [`super::Document::apply`], which records it for undo and bumps the revision of the part of
//! the document it touched. Camera moves are not edits (views are not undone, as in Blender):
//! they go through [`super::Document::set_camera`].

use std::sync::Arc;

use super::{DrawingPlane, Ellipsoid, Lighting, ReferenceImage, RenderSettings, Scene};

/// One change to the document.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Replace the lighting.
    SetLight(Lighting),
    /// Replace the render settings.
    SetRender(RenderSettings),
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
    /// Set, change or remove the reference image.
    SetReference(Option<ReferenceImage>),
    /// Turn the simulation on (with these settings), change it, or turn it off.
    SetSimulation(Option<crate::simulate::Settings>),
    /// Replace the whole document (new, open, preset).
    Replace(Box<Scene>),
}

impl Edit {
    /// What the edit changes, in words ("Undid: …").
    pub fn label(&self) -> &'static str {
        match self {
            Edit::SetLight(_) => "lighting",
            Edit::SetRender(_) => "render settings",
            Edit::SetEllipsoids(_) => "ellipsoids",
            Edit::SetPlanes(_) => "drawing planes",
            Edit::SetPlane(..) => "drawing plane",
            Edit::InsertPlane(..) => "new drawing plane",
            Edit::RemovePlane(_) => "deleted drawing plane",
            Edit::SetReference(_) => "reference image",
            Edit::SetSimulation(_) => "simulation",
            Edit::Replace(_) => "new scene",
        }
    }
}
