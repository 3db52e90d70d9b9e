//! Which tool the viewport's primary drag serves (its key, its name in the page state), and
//! which modal transform G, R or S started.

/// What a primary drag in the viewport does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tool {
    /// Drag orbits (Blender-like camera).
    #[default]
    Navigate,
    /// Drag draws a cloud outline.
    Sketch,
    /// Drag draws a cut line (flat base).
    Cut,
    /// A click adds an ellipsoid where it lands (a drag orbits).
    Ellipsoid,
    /// Drag moves the selected drawing plane or ellipsoid parallel to the view (Shift: toward
    /// or away).
    Move,
    /// Drag turns the selected drawing plane or ellipsoid (sideways: about the vertical;
    /// up/down: tilt).
    Rotate,
    /// Drag scales the selected ellipsoid (right or up grows it).
    Scale,
}

impl Tool {
    /// Name for the UI and the page state.
    pub fn name(self) -> &'static str {
        match self {
            Tool::Navigate => "navigate",
            Tool::Sketch => "sketch",
            Tool::Cut => "cut",
            Tool::Ellipsoid => "ellipsoid",
            Tool::Move => "move",
            Tool::Rotate => "rotate",
            Tool::Scale => "scale",
        }
    }
}

/// Which modal transform.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModalKind {
    /// G: move.
    Grab,
    /// R: turn.
    Rotate,
    /// S: scale.
    Scale,
}

impl ModalKind {
    /// Its name in the page state.
    pub fn name(self) -> &'static str {
        match self {
            ModalKind::Grab => "grab",
            ModalKind::Rotate => "rotate",
            ModalKind::Scale => "scale",
        }
    }

    /// What it does to the selection, as a noun ("Cancelled: the move …").
    pub fn verb(self) -> &'static str {
        match self {
            ModalKind::Grab => "the move is",
            ModalKind::Rotate => "the turn is",
            ModalKind::Scale => "the scale is",
        }
    }
}
