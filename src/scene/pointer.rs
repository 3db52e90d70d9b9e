//! `--set PATH=VALUE`: overrides one value of a document by JSON Pointer into its JSON form.

use super::{Scene, SceneError};

/// Why an override was refused.
#[derive(Debug, thiserror::Error)]
pub enum SetError {
    /// Not of the form `PATH=VALUE`.
    #[error("expected PATH=VALUE (e.g. /render/slices=256), got {0:?}")]
    Syntax(String),
    /// The pointer names nothing in the document.
    #[error(
        "no value at {0} in the scene (paths look like /render/slices or /ellipsoids/0/center/1)"
    )]
    UnknownPath(String),
    /// The new value has the wrong type or is out of range.
    #[error("cannot set {path} to {value}: {reason}")]
    BadValue {
        /// The pointer.
        path: String,
        /// The value as given.
        value: String,
        /// What the document reader said.
        reason: String,
    },
}

/// Applies `PATH=VALUE`. VALUE is read as JSON (`256`, `true`, `[1,2,3]`); anything that is not
/// JSON is taken as a string.
pub fn set_by_pointer(scene: &Scene, assignment: &str) -> Result<(Scene, Vec<String>), SetError> {
    let (path, raw) = assignment
        .split_once('=')
        .ok_or_else(|| SetError::Syntax(assignment.to_string()))?;
    if !path.starts_with('/') {
        return Err(SetError::Syntax(assignment.to_string()));
    }
    let new_value: serde_json::Value =
        serde_json::from_str(raw).unwrap_or_else(|_| serde_json::Value::String(raw.to_string()));
    let mut doc = serde_json::to_value(scene).map_err(|e| SetError::BadValue {
        path: path.to_string(),
        value: raw.to_string(),
        reason: e.to_string(),
    })?;
    // A file leaves the default clock out; its values can still be set.
    if let (Some(map), Ok(clock)) = (doc.as_object_mut(), serde_json::to_value(scene.clock)) {
        map.entry("clock").or_insert(clock);
    }
    // So is a calm wind field's.
    if let (Some(map), Ok(wind)) = (doc.as_object_mut(), serde_json::to_value(scene.wind_field)) {
        map.entry("wind_field").or_insert(wind);
    }
    let slot = doc
        .pointer_mut(path)
        .ok_or_else(|| SetError::UnknownPath(path.to_string()))?;
    let same_kind = std::mem::discriminant(slot) == std::mem::discriminant(&new_value);
    if !same_kind && (!slot.is_number() || !new_value.is_number()) {
        return Err(SetError::BadValue {
            path: path.to_string(),
            value: raw.to_string(),
            reason: format!("expected {}", kind_name(slot)),
        });
    }
    *slot = new_value;
    let (mut set, repairs) = Scene::from_value_unposed(doc).map_err(|e| SetError::BadValue {
        path: path.to_string(),
        value: raw.to_string(),
        reason: match e {
            SceneError::Parse(p) => p.to_string(),
            other => other.to_string(),
        },
    })?;
    // A stroke set point by point lands on its grid, as one drawn in the app.
    set.snap_strokes();
    // A new time or new keys pose the keyed and moving values; any other value set stands as
    // set, as an edit in the app does: a moving ellipsoid set elsewhere starts where it must to
    // stand there, one given a new motion or wind moves by it.
    if path == "/time" || path.starts_with("/animation") {
        let t = set.time;
        set.pose(t);
    } else {
        set.rebase_motion(scene);
    }
    Ok((set, repairs))
}

fn kind_name(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "true or false",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::Object(_) => "an object",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_numbers_and_arrays() {
        let s = Scene::default();
        let (s, _) = set_by_pointer(&s, "/render/slices=256").unwrap();
        assert_eq!(s.render.slices, 256);
        let (s, _) = set_by_pointer(&s, "/ellipsoids/0/center=[1,2,3]").unwrap();
        assert_eq!(s.ellipsoids[0].center, glam::Vec3::new(1.0, 2.0, 3.0));
        let (s, _) = set_by_pointer(&s, "/light/sun_color/0=0.25").unwrap();
        assert_eq!(s.light.sun_color[0], 0.25);
    }

    #[test]
    fn unknown_paths_and_wrong_types_are_clear_errors() {
        let s = Scene::default();
        assert!(matches!(
            set_by_pointer(&s, "/render/nope=1"),
            Err(SetError::UnknownPath(_))
        ));
        assert!(matches!(
            set_by_pointer(&s, "/ellipsoids/99/center=1"),
            Err(SetError::UnknownPath(_))
        ));
        let e = set_by_pointer(&s, "/render/slices=many").unwrap_err();
        assert!(e.to_string().contains("expected a number"), "{e}");
        let e = set_by_pointer(&s, "/render/slices=-3").unwrap_err();
        assert!(matches!(e, SetError::BadValue { .. }), "{e}");
        assert!(matches!(
            set_by_pointer(&s, "render/slices"),
            Err(SetError::Syntax(_))
        ));
        assert!(matches!(
            set_by_pointer(&s, "nopath"),
            Err(SetError::Syntax(_))
        ));
    }
}
