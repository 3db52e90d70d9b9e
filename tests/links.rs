//! Share links keep opening as the format evolves: `tests/fixtures/link_vN.txt` is the link
//! of `share::fixture::every_part()` as format N wrote it, and `link_vN.json` the scene it
//! opens to. A format change without a version bump fails here; so does a change that makes
//! an old link open differently.
//!
//! After a deliberate format change: bump `LINK_VERSION`, keep decoding the old versions, and
//! write the new fixtures with
//! `CLOUDSKETCH_WRITE_LINK_FIXTURE=1 cargo test --test links` (old ones stay as they are).

use std::path::PathBuf;

use base64::Engine as _;
use cloudsketch::scene::Scene;
use cloudsketch::share::{LINK_VERSION, decode_link, encode_link, fixture};

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// The version byte and the inflated payload of a link (the compressed bytes may differ
/// between compressor versions without any change of format).
fn payload(link: &str) -> (u8, Vec<u8>) {
    let token = &link[link.find("#s=").map_or(0, |i| i + 3)..];
    let bytes = base64::engine::general_purpose::URL_SAFE_NO_PAD
        .decode(token.trim())
        .unwrap();
    (
        bytes[0],
        miniz_oxide::inflate::decompress_to_vec(&bytes[1..]).unwrap(),
    )
}

#[test]
fn every_stored_link_version_still_opens_to_its_scene() {
    if std::env::var_os("CLOUDSKETCH_WRITE_LINK_FIXTURE").is_some() {
        let link = format!(
            "http://127.0.0.1:8080/#s={}\n",
            encode_link(&fixture::every_part()).unwrap()
        );
        let (scene, _) = decode_link(&link).unwrap();
        let dir = fixtures();
        std::fs::write(dir.join(format!("link_v{LINK_VERSION}.txt")), &link).unwrap();
        std::fs::write(
            dir.join(format!("link_v{LINK_VERSION}.json")),
            scene.to_json(),
        )
        .unwrap();
    }
    for version in 1..=LINK_VERSION {
        assert!(
            fixtures().join(format!("link_v{version}.txt")).exists(),
            "no fixture of link format {version}"
        );
    }
    // Every stored link: each version's, and older links of a version kept when its fixture
    // scene grew (`link_v1_before_every_field`: made before the fixture set every field).
    let mut stored: Vec<PathBuf> = std::fs::read_dir(fixtures())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension().is_some_and(|e| e == "txt")
                && p.file_name()
                    .unwrap()
                    .to_string_lossy()
                    .starts_with("link_v")
        })
        .collect();
    stored.sort();
    for path in stored {
        let link = std::fs::read_to_string(&path).unwrap();
        let json = std::fs::read_to_string(path.with_extension("json")).unwrap();
        let (expected, _) = Scene::from_json(&json).unwrap();
        let (opened, repairs) = decode_link(&link).unwrap();
        assert!(repairs.is_empty(), "{}: {repairs:?}", path.display());
        assert_eq!(
            opened,
            expected,
            "{} opens to a different scene than it did",
            path.display()
        );
    }
}

#[test]
fn the_link_format_changes_only_with_its_version() {
    let stored =
        std::fs::read_to_string(fixtures().join(format!("link_v{LINK_VERSION}.txt"))).unwrap();
    let now = encode_link(&fixture::every_part()).unwrap();
    assert_eq!(payload(&stored).0, LINK_VERSION);
    assert!(
        payload(&stored) == payload(&now),
        "the link of the fixture scene changed without a new LINK_VERSION: bump it, keep \
         reading the old format, and add its fixtures (see this file's header)"
    );
}

#[test]
fn the_stored_links_do_not_carry_the_reference_picture() {
    let link = std::fs::read_to_string(fixtures().join("link_v1.txt")).unwrap();
    let (scene, _) = decode_link(&link).unwrap();
    let reference = scene.reference.unwrap();
    assert_eq!(reference.name, "sky.jpg");
    assert!(reference.data.is_empty());
}

/// The CI's short fuzz run (the long one is `cargo +nightly fuzz run link_decode`, see
/// docs/scene-format.md): every input of the checked-in corpus, and seeded mutations of each
/// (bytes changed, cut, doubled), through the decoders' contract.
#[test]
fn the_fuzz_corpus_and_its_mutations_decode_safely() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/link_decode");
    let mut inputs: Vec<Vec<u8>> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| std::fs::read(e.unwrap().path()).unwrap())
        .collect();
    assert!(inputs.len() >= 10, "the corpus is checked in");
    let mut rng = cloudsketch::seeded::SplitMix::new(12);
    let seeds = inputs.clone();
    for seed in &seeds {
        for round in 0..40 {
            let mut m = seed.clone();
            let at = 1 + (rng.next_u64() as usize) % (m.len() - 1).max(1);
            let last = at.min(m.len() - 1);
            match round % 4 {
                0 => m[last] ^= 1 << (rng.next_u64() % 8),
                1 => m.truncate(at),
                2 => {
                    let tail = m[last..].to_vec();
                    m.extend(tail);
                }
                _ => m[last] = (rng.next_u64() & 0xff) as u8,
            }
            inputs.push(m);
        }
    }
    for input in &inputs {
        cloudsketch::share::check_untrusted(input);
    }
}

/// Billows make many all-or-nothing choices from an ellipsoid's radii (how many puffs, which
/// are hidden), so a link carries the radii of a billowed ellipsoid exactly: the documents
/// settle them to the link's digits. The presets' puffs come back one for one.
#[test]
fn a_billowed_scene_comes_back_from_its_link_with_the_same_puffs() {
    use cloudsketch::scene::Preset;
    for preset in [Preset::Cumulus, Preset::Cumulonimbus, Preset::Sunset] {
        let scene = Scene::preset(preset);
        let (back, _) = decode_link(&format!("#s={}", encode_link(&scene).unwrap())).unwrap();
        let radii = |s: &Scene| s.ellipsoids.iter().map(|e| e.radii).collect::<Vec<_>>();
        assert_eq!(radii(&back), radii(&scene), "{preset:?}");
        let (a, b) = (
            cloudsketch::derive::field_of(&scene),
            cloudsketch::derive::field_of(&back),
        );
        let puffs =
            |f: &cloudsketch::field::Field| f.groups.iter().map(|g| g.puffs.len()).sum::<usize>();
        assert!(puffs(&a) > 1000, "{preset:?}: {} puffs", puffs(&a));
        assert_eq!(puffs(&a), puffs(&b), "{preset:?}");
    }
}
