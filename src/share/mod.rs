//! How a scene leaves the app and comes back (pure): share links (`#s=…`, [`link`]) and scene
//! files ([`file`]), both untrusted on the way in. The autosave's timing lives with the app
//! (`ui/autosave.rs`); what it writes is a scene file.
//!
//! docs/scene-format.md describes both formats and their versions.

pub mod file;
pub mod fixture;
pub mod link;

pub use file::{FileError, open_scene_file, scene_file_name};
pub use link::{
    DEFAULT_BASE, LINK_VERSION, LinkError, MAX_LINK_CHARS, decode_link, decode_payload,
    encode_link, link_url,
};
