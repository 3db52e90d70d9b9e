//! Scene files: the document's own JSON (docs/scene-format.md), opened with the same caps and
//! checks whichever way it comes in (Open, a dropped file, a path, the autosave).

use crate::limits::MAX_FILE_BYTES;
use crate::scene::{Scene, SceneError};

/// Why a scene file could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// Over [`MAX_FILE_BYTES`].
    #[error("{name}: {bytes} bytes is more than the {} MiB a scene file may have", MAX_FILE_BYTES >> 20)]
    TooLarge {
        /// File name.
        name: String,
        /// Its size.
        bytes: u64,
    },
    /// Not UTF-8 text.
    #[error("{0}: not a cloudsketch scene (not text)")]
    NotText(String),
    /// Not a scene this build accepts.
    #[error("{name}: {error}")]
    Scene {
        /// File name.
        name: String,
        /// What is wrong.
        error: SceneError,
    },
    /// Too costly to build.
    #[error("{name}: {error}")]
    TooCostly {
        /// File name.
        name: String,
        /// What it would cost.
        error: String,
    },
}

/// Opens a scene file's bytes: the scene and what validation repaired in it, in words.
pub fn open_scene_file(name: &str, bytes: &[u8]) -> Result<(Scene, Vec<String>), FileError> {
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(FileError::TooLarge {
            name: name.to_owned(),
            bytes: bytes.len() as u64,
        });
    }
    let text = std::str::from_utf8(bytes).map_err(|_| FileError::NotText(name.to_owned()))?;
    let (mut scene, mut repairs) =
        Scene::from_file_json(text).map_err(|error| FileError::Scene {
            name: name.to_owned(),
            error,
        })?;
    let cost = crate::derive::check_cost(&mut scene).map_err(|error| FileError::TooCostly {
        name: name.to_owned(),
        error,
    })?;
    repairs.extend(cost);
    // Strokes from elsewhere (an older build, a script) land on the grid the app draws on, so
    // the file's link is exact.
    let moved = scene.snap_strokes();
    if moved > 0 {
        repairs.push(format!(
            "/planes: {moved} stroke(s) off the stroke grid moved onto it (by at most half a step)"
        ));
    }
    Ok((scene, repairs))
}

/// Whether a dropped file is a scene rather than a picture: named `.json`, or text that
/// starts as a JSON object does (a picture starts with its format's signature).
pub fn is_scene_file(name: &str, bytes: &[u8]) -> bool {
    name.to_ascii_lowercase().ends_with(".json")
        || bytes
            .iter()
            .find(|b| !b.is_ascii_whitespace())
            .is_some_and(|&b| b == b'{')
}

/// A file name for saving: `name` made safe (no folders, no odd characters) and ending in
/// `.json`; `cloud.json` when nothing is left.
pub fn scene_file_name(name: &str) -> String {
    let stem = name
        .trim()
        .trim_end_matches(".json")
        .trim_end_matches(".JSON");
    let stem: String = stem
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, '-' | '_' | '.' | ' ') {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stem = stem.trim_matches(|c| c == '.' || c == ' ');
    if stem.is_empty() {
        "cloud.json".to_owned()
    } else {
        format!("{stem}.json")
    }
}
