//! Reading a document without building more than its caps allow: lists stop at their cap (an
//! error, not a truncation: the file is not what this build reads), and a first pass reads only
//! the document's outline, skipping every value it does not need with `IgnoredAny`. Memory while
//! opening a file is then a small multiple of its text, whatever the text holds.

use std::fmt;
use std::marker::PhantomData;

use serde::Deserialize;
use serde::de::{Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};

/// Deserializes a list of at most `N` items: the `N + 1`th is an error, and no more than `N`
/// are allocated for, whatever the list's length.
pub fn vec<'de, D, T, const N: usize>(d: D) -> Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    struct Capped<T, const N: usize>(PhantomData<T>);
    impl<'de, T: Deserialize<'de>, const N: usize> Visitor<'de> for Capped<T, N> {
        type Value = Vec<T>;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            write!(f, "a list of at most {N}")
        }
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
            let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(N).min(4096));
            while let Some(item) = seq.next_element()? {
                if out.len() == N {
                    return Err(serde::de::Error::custom(format!(
                        "more than {N} items in a list of at most {N}"
                    )));
                }
                out.push(item);
            }
            Ok(out)
        }
    }
    d.deserialize_seq(Capped::<T, N>(PhantomData))
}

/// The members a scene document may have at its top level.
pub const MEMBERS: [&str; 14] = [
    "version",
    "seed",
    "camera",
    "light",
    "render",
    "ellipsoids",
    "planes",
    "reference",
    "time",
    "clock",
    "simulation",
    "shot",
    "animation",
    "wind_field",
];

/// What a first pass over a document finds without building any of it: the version it says
/// it has, and how many of its members are a scene's.
#[derive(Debug, Default)]
pub struct Outline {
    /// The `version` member, if there is one.
    pub version: Option<u64>,
    /// How many top-level members are among [`MEMBERS`].
    pub members: usize,
}

impl<'de> Deserialize<'de> for Outline {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct OutlineVisitor;
        impl<'de> Visitor<'de> for OutlineVisitor {
            type Value = Outline;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a scene document (a JSON object)")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Outline, A::Error> {
                let mut outline = Outline::default();
                while let Some(key) = map.next_key::<Key>()? {
                    match key {
                        Key::Version => {
                            outline.version = Some(map.next_value()?);
                            outline.members += 1;
                        }
                        Key::Member => {
                            map.next_value::<IgnoredAny>()?;
                            outline.members += 1;
                        }
                        Key::Other => {
                            map.next_value::<IgnoredAny>()?;
                        }
                    }
                }
                Ok(outline)
            }
        }
        d.deserialize_map(OutlineVisitor)
    }
}

/// A top-level member's name, classified as it is read (its text is not kept).
enum Key {
    Version,
    Member,
    Other,
}

impl<'de> Deserialize<'de> for Key {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct KeyVisitor;
        impl Visitor<'_> for KeyVisitor {
            type Value = Key;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a member name")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Key, E> {
                Ok(match v {
                    "version" => Key::Version,
                    v if MEMBERS.contains(&v) => Key::Member,
                    _ => Key::Other,
                })
            }
        }
        d.deserialize_identifier(KeyVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize, Debug)]
    struct Three {
        #[serde(deserialize_with = "vec::<_, _, 3>")]
        items: Vec<u8>,
    }

    #[test]
    fn a_list_past_its_cap_is_refused_and_one_at_it_read() {
        let ok: Three = serde_json::from_str(r#"{"items": [1, 2, 3]}"#).unwrap();
        assert_eq!(ok.items, [1, 2, 3]);
        let err = serde_json::from_str::<Three>(r#"{"items": [1, 2, 3, 4]}"#).unwrap_err();
        assert!(err.to_string().contains("at most 3"), "{err}");
    }

    #[test]
    fn the_outline_counts_a_scenes_members_and_skips_the_rest() {
        let o: Outline =
            serde_json::from_str(r#"{"version": 1, "planes": [], "junk": {"a": [1, {}]}}"#)
                .unwrap();
        assert_eq!((o.version, o.members), (Some(1), 2));
        let o: Outline = serde_json::from_str(r#"{"points": [[0, 1]]}"#).unwrap();
        assert_eq!((o.version, o.members), (None, 0));
        let err = serde_json::from_str::<Outline>("[1]").unwrap_err();
        assert!(err.to_string().contains("a JSON object"), "{err}");
    }

    #[test]
    fn every_member_a_scene_writes_is_known() {
        // Every member set: the fixture that sets every field, simulated too.
        let mut scene = crate::share::fixture::every_part();
        scene.simulation = crate::scene::Scene::preset(crate::scene::Preset::Simulated).simulation;
        assert!(scene.reference.is_some() && scene.shot.is_some() && !scene.wind_field.is_calm());
        let value = serde_json::to_value(&scene).unwrap();
        for key in value.as_object().unwrap().keys() {
            assert!(MEMBERS.contains(&key.as_str()), "{key} is not in MEMBERS");
        }
    }
}
