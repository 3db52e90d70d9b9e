//! Which tool the viewport's primary drag serves (its key, its name in the page state).

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
