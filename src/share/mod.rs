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
    DEFAULT_BASE, LINK_VERSION, LinkError, MAX_INFLATED, MAX_LINK_CHARS, decode_link,
    decode_payload, encode_link, link_url,
};

/// The decoders' contract on any bytes (the fuzz target's body, and the CI's smoke run over
/// the checked-in corpus): `data[0]` even takes the rest as a link's text, odd as an inflated
/// payload (random text rarely gets through the base64 and deflate layers). Decoding never
/// panics and never allocates beyond its caps; a scene it returns is valid, encodes again, and
/// one more encode and decode of it changes nothing.
/// Panics when that contract is broken.
pub fn check_untrusted(data: &[u8]) {
    let Some((&way, rest)) = data.split_first() else {
        return;
    };
    let decoded = if way & 1 == 0 {
        match std::str::from_utf8(rest) {
            Ok(text) => decode_link(text),
            Err(_) => return,
        }
    } else {
        decode_payload(rest)
    };
    if let Ok((scene, _)) = decoded {
        let mut again = scene.clone();
        assert!(again.validate().is_ok(), "a decoded scene is valid");
        // It encodes, and what it encodes to is settled: one more encode and decode changes
        // nothing (the first may still round a value that validation clamped).
        let again = match encode_link(&scene) {
            Ok(token) => {
                decode_link(&format!("#s={token}"))
                    .unwrap_or_else(|e| panic!("a decoded scene's link does not decode: {e}"))
                    .0
            }
            Err(LinkError::SceneTooLarge { .. }) => return,
            Err(e) => panic!("a decoded scene does not encode: {e}"),
        };
        let token = encode_link(&again)
            .unwrap_or_else(|e| panic!("a scene decoded twice does not encode: {e}"));
        let (third, _) = decode_link(&format!("#s={token}"))
            .unwrap_or_else(|e| panic!("a scene decoded twice does not decode: {e}"));
        assert!(
            third == again,
            "one more encode and decode changed the scene"
        );
    }
}
