//! Share links: the whole scene in a URL's fragment, `BASE#s=TOKEN`.
//!
//! `TOKEN` is base64url (no padding) of one version byte ([`LINK_VERSION`]) followed by the
//! raw-deflate compression of the payload:
//!
//! - a varint length, then compact JSON of the scene's *difference from a fixed base* (the
//!   empty preset; each plane against a default plane, each ellipsoid against a default
//!   ellipsoid, as they were when the version was made: stored as data, `link/base_v1.json`), every number rounded to [`DIGITS`] significant digits, without the strokes'
//!   points and pressure and without the reference picture's bytes;
//! - then, for each drawing plane in order, its stroke: the point count, the stroke's grid
//!   (a step of 2^(e/8), at most [`STROKE_GRID`](crate::scene::STROKE_GRID) steps across its larger side; see
//!   [`crate::scene::grid_exponent`]), then each point in steps as its difference from a
//!   prediction (the last point plus the velocity over the last two steps), as zigzag
//!   varints; then the pen pressure, if any, in 1/255 steps as differences.
//!
//! Strokes drawn in the app are stored on that grid, so a link reproduces them exactly;
//! another stroke (an older file) moves by at most half a step, under 1/880 of its larger
//! side. A setting moves by at most 5 parts in 10⁵ of its value. Derived data (spheres, the field) is never stored.
//!
//! A link is untrusted: its length, the inflated size, the JSON's size and every count are
//! capped before anything is allocated for them, and nothing half-decoded is returned.

use std::sync::Arc;

use base64::Engine as _;
use serde_json::{Map, Value};

use crate::limits::{MAX_ELLIPSOIDS, MAX_PLANE_POINTS, MAX_PLANES};
use crate::scene::{
    DrawingPlane, MAX_GRID_EXPONENT as MAX_EXPONENT, MAX_GRID_STEPS as MAX_STEPS, SCENE_VERSION,
    Scene, SceneError, grid_exponent, grid_point, grid_points,
};

/// Format version written by this build; older ones keep opening (see docs/scene-format.md).
/// Version 2 is version 1 on a newer base (the ground's default height moved from 0 to -5):
/// the payload's layout is the same. Version 3 is the same again on the base of scene format 2
/// (billows and stable ids; a primitive's billows and id are written where it has them).
/// Version 4 moved the light volume's defaults. Version 5 carries key frames (scene format 4's
/// `animation`, written whole and unrounded where a scene has keys) on version 4's base: a build that reads
/// up to version 4 refuses such a link instead of opening it without its keys. Version 6
/// carries moving ellipsoids and the wind field that carries them (scene format 5's `motion`
/// and `wind_field`) on version 5's base. Version 7 carries the physical sky (scene format 6's
/// `light.physical_sky`) on a base that has it off: a build that reads up to version 6
/// refuses such a link instead of opening it with the picked colours. Version 8 is version 7
/// on a base with a fainter sun and sky light (sun intensity 1.6 → 0.8, ambient 0.45 → 0.25,
/// so the lit cloud's light sits below the tone curve's shoulder): the payload's layout is the
/// same.
pub const LINK_VERSION: u8 = 8;

/// Longest token accepted or written (characters after `#s=`). Browsers take URLs of
/// megabytes, but mail and chat tools cut them far sooner.
pub const MAX_LINK_CHARS: usize = 64 * 1024;

/// Largest payload after inflating (a deflate stream can expand a thousandfold).
pub const MAX_INFLATED: usize = 2 << 20;

/// Largest JSON part of the payload.
const MAX_JSON: usize = 1 << 20;

/// Significant digits kept of each setting.
pub const DIGITS: usize = crate::scene::LINK_DIGITS;

/// Where links point when no base is given: the app as `trunk serve` serves it.
pub const DEFAULT_BASE: &str = "http://127.0.0.1:8080/";

/// Why a link could not be made or opened.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// No `#s=` part.
    #[error("not a cloudsketch link: it has no \"#s=\" part")]
    NotALink,
    /// Longer than [`MAX_LINK_CHARS`] on the way in.
    #[error("the link is {chars} characters long; links of up to {MAX_LINK_CHARS} are opened")]
    TooLong {
        /// Length of the token.
        chars: usize,
    },
    /// The scene needs a longer link than [`MAX_LINK_CHARS`].
    #[error(
        "this scene needs a link of {chars} characters, more than the {MAX_LINK_CHARS} a link \
         may have: save it as a file instead"
    )]
    SceneTooLarge {
        /// Length the token would have.
        chars: usize,
    },
    /// Made by a newer build.
    #[error(
        "the link was made by a newer cloudsketch (link format {found}; this one reads up to \
         {LINK_VERSION})"
    )]
    Newer {
        /// Version byte found.
        found: u8,
    },
    /// Cut short, changed or not made by cloudsketch.
    #[error("the link is damaged ({0}): was it cut short or changed?")]
    Damaged(String),
    /// Decoded, but not a scene this build accepts.
    #[error("the link's scene cannot be opened: {0}")]
    Scene(#[from] SceneError),
    /// Decoded, but too costly to build.
    #[error("the link's scene cannot be opened: {0}")]
    TooCostly(String),
    /// The scene holds values a link cannot carry (they would not open again): it is refused
    /// rather than written as a link that says it is damaged.
    #[error("this scene cannot travel as a link ({0}): save it as a file instead")]
    Unfit(String),
}

fn damaged(what: impl Into<String>) -> LinkError {
    LinkError::Damaged(what.into())
}

/// The token (`TOKEN` in `#s=TOKEN`) holding `scene`.
pub fn encode_link(scene: &Scene) -> Result<String, LinkError> {
    let payload = encode_payload(scene);
    let mut bytes = vec![LINK_VERSION];
    bytes.extend(miniz_oxide::deflate::compress_to_vec(&payload, 10));
    let token = base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(bytes);
    if token.len() > MAX_LINK_CHARS {
        return Err(LinkError::SceneTooLarge { chars: token.len() });
    }
    // What is written must open: a value the link's grid cannot hold (a stroke point of 1e38)
    // would decode as damaged.
    decode_link(&format!("#s={token}")).map_err(|e| LinkError::Unfit(e.to_string()))?;
    Ok(token)
}

/// The URL that opens `scene`: `base` (its own fragment dropped) + `#s=` + the token.
pub fn link_url(base: &str, scene: &Scene) -> Result<String, LinkError> {
    let base = base.split('#').next().unwrap_or_default();
    Ok(format!("{base}#s={}", encode_link(scene)?))
}

/// The token inside a link: after `#s=` in a URL, or a bare `s=TOKEN` / `#s=TOKEN`.
fn token_of(text: &str) -> Option<&str> {
    let text = text.trim();
    if let Some(at) = text.find("#s=") {
        return Some(&text[at + 3..]);
    }
    text.strip_prefix("s=")
}

/// Opens a link (a whole URL, or its `#s=…` fragment): the scene and what validation repaired
/// in it, in words. Fails with a message a user can act on, never with half a scene.
pub fn decode_link(text: &str) -> Result<(Scene, Vec<String>), LinkError> {
    let token = token_of(text).ok_or(LinkError::NotALink)?;
    // Anything after the token (another fragment parameter) is not ours.
    let token = token.split('&').next().unwrap_or_default();
    if token.len() > MAX_LINK_CHARS {
        return Err(LinkError::TooLong { chars: token.len() });
    }
    let bytes = base64::engine::general_purpose::URL_SAFE_NO_PAD
        .decode(token.trim_end_matches('='))
        .map_err(|_| damaged("not base64url"))?;
    let (&version, deflated) = bytes.split_first().ok_or_else(|| damaged("empty"))?;
    match version {
        0 => return Err(damaged("unknown format 0")),
        v if v > LINK_VERSION => return Err(LinkError::Newer { found: v }),
        _ => {}
    }
    let payload = miniz_oxide::inflate::decompress_to_vec_with_limit(deflated, MAX_INFLATED)
        .map_err(|e| match e.status {
            miniz_oxide::inflate::TINFLStatus::HasMoreOutput => damaged(format!(
                "it inflates to more than {} MiB",
                MAX_INFLATED >> 20
            )),
            _ => damaged("not a deflate stream"),
        })?;
    decode_payload_of(version, &payload)
}

/// Decodes an inflated payload of the current version (public for the fuzz target).
pub fn decode_payload(payload: &[u8]) -> Result<(Scene, Vec<String>), LinkError> {
    decode_payload_of(LINK_VERSION, payload)
}

/// Decodes an inflated payload of link format `version` (1 or 2: the same layout, each on its
/// own base).
fn decode_payload_of(version: u8, payload: &[u8]) -> Result<(Scene, Vec<String>), LinkError> {
    let mut r = Reader {
        bytes: payload,
        at: 0,
    };
    let json_len = r.uvar()?;
    if json_len > MAX_JSON as u64 || json_len > r.left() as u64 {
        return Err(damaged("its settings are cut short"));
    }
    let json = r.take(json_len as usize)?;
    let diff: Value =
        serde_json::from_slice(json).map_err(|e| damaged(format!("settings: {e}")))?;
    let Value::Object(diff) = diff else {
        return Err(damaged("settings are not an object"));
    };
    let merged = merge_onto_base(bases(version), diff)?;
    let (mut scene, mut repairs) = Scene::from_value(merged)?;
    // A link never carries the reference picture's bytes (docs/scene-format.md): a crafted
    // one that does gets its name and placement only.
    if let Some(reference) = &mut scene.reference
        && !reference.data.is_empty()
    {
        Arc::make_mut(reference).data = Default::default();
    }
    for plane in &mut scene.planes {
        let (points, pressure) = read_stroke(&mut r)?;
        let plane = Arc::make_mut(plane);
        plane.points = points;
        plane.pressure = pressure;
    }
    if r.left() != 0 {
        return Err(damaged(format!("{} bytes too many", r.left())));
    }
    repairs.extend(scene.validate()?);
    if let Some(change) = crate::derive::check_cost(&mut scene).map_err(LinkError::TooCostly)? {
        repairs.push(change);
    }
    Ok((scene, repairs))
}

// --- the settings: JSON differences from a fixed base -------------------------------------

/// What a link's settings are the difference from, as a format version wrote and reads it:
/// the empty preset, a default drawing plane and a default ellipsoid as they serialised when
/// the version was made, kept as data (`src/share/link/base_vN.json`). Defaults may move (the
/// ground's height, the sun); a link still opens to the scene it was made of.
struct Bases {
    scene: Value,
    plane: Value,
    ellipsoid: Value,
}

impl Bases {
    fn parse(text: &str) -> Self {
        let mut all = as_object(serde_json::from_str(text).unwrap_or(Value::Null));
        let mut take = |key: &str| all.remove(key).unwrap_or(Value::Null);
        Bases {
            scene: take("scene"),
            plane: take("plane"),
            ellipsoid: take("ellipsoid"),
        }
    }
}

/// Each link format version's base: version 1's (the ground at 0), version 2's (at -5),
/// version 3's (billows and ids), version 4's (the light volume at 96 texels, 4 octaves),
/// version 5's (the same as 4's: key frames added no default); version 6's the same again;
/// version 7's with the physical sky off; version 8's with the sun at 0.8 and the ambient at
/// 0.25.
const BASES: [&str; LINK_VERSION as usize] = [
    include_str!("link/base_v1.json"),
    include_str!("link/base_v2.json"),
    include_str!("link/base_v3.json"),
    include_str!("link/base_v4.json"),
    include_str!("link/base_v5.json"),
    include_str!("link/base_v6.json"),
    include_str!("link/base_v7.json"),
    include_str!("link/base_v8.json"),
];

/// The base of link format `version` (1 to [`LINK_VERSION`]; others take the current one).
fn bases(version: u8) -> &'static Bases {
    static PARSED: [std::sync::OnceLock<Bases>; LINK_VERSION as usize] =
        [const { std::sync::OnceLock::new() }; LINK_VERSION as usize];
    let k = (version.clamp(1, LINK_VERSION) - 1) as usize;
    PARSED[k].get_or_init(|| Bases::parse(BASES[k]))
}

/// Today's defaults as [`Bases`] holds them (what `base_v1.json` was written from).
#[cfg(test)]
fn todays_bases() -> Value {
    serde_json::json!({
        "scene": serde_json::to_value(Scene::preset(crate::scene::Preset::Empty)).unwrap(),
        "plane": serde_json::to_value(DrawingPlane::default()).unwrap(),
        "ellipsoid": serde_json::to_value(crate::scene::Ellipsoid::default()).unwrap(),
    })
}

fn rounded(value: &Value) -> Value {
    let mut v = value.clone();
    round_numbers(&mut v);
    v
}

fn to_rounded_value<T: serde::Serialize>(value: &T) -> Value {
    let mut v = serde_json::to_value(value).unwrap_or(Value::Null);
    round_numbers(&mut v);
    v
}

/// Rounds every non-integer number to [`DIGITS`] significant digits (a whole result is
/// written as an integer: `0`, not `0.0`).
fn round_numbers(v: &mut Value) {
    match v {
        Value::Number(n) if !(n.is_u64() || n.is_i64()) => {
            if let Some(x) = n.as_f64() {
                let rounded: f64 = format!("{:.*e}", DIGITS - 1, x).parse().unwrap_or(x);
                let whole = rounded.fract() == 0.0 && rounded.abs() < 1e15;
                *n = if whole {
                    serde_json::Number::from(rounded as i64)
                } else {
                    serde_json::Number::from_f64(rounded).unwrap_or_else(|| n.clone())
                };
            }
        }
        Value::Array(a) => a.iter_mut().for_each(round_numbers),
        Value::Object(o) => o.values_mut().for_each(round_numbers),
        _ => {}
    }
}

/// The members of `value` that differ from `base` (recursively for objects); a member the
/// base has and `value` lacks is written as `null`.
fn diff(value: &Map<String, Value>, base: &Map<String, Value>) -> Map<String, Value> {
    let mut out = Map::new();
    for (key, v) in value {
        match (v, base.get(key)) {
            (v, Some(b)) if v == b => {}
            (Value::Object(v), Some(Value::Object(b))) => {
                out.insert(key.clone(), Value::Object(diff(v, b)));
            }
            _ => {
                out.insert(key.clone(), v.clone());
            }
        }
    }
    for key in base.keys() {
        if !value.contains_key(key) {
            out.insert(key.clone(), Value::Null);
        }
    }
    out
}

/// `patch` written over `target` (objects member by member, anything else replaced).
fn merge(target: &mut Value, patch: Value) {
    match (target, patch) {
        (Value::Object(t), Value::Object(p)) => {
            for (key, v) in p {
                merge(t.entry(key).or_insert(Value::Null), v);
            }
        }
        (t, p) => *t = p,
    }
}

fn as_object(v: Value) -> Map<String, Value> {
    match v {
        Value::Object(o) => o,
        _ => Map::new(),
    }
}

/// The JSON part of the payload for `scene`.
fn settings_json(scene: &Scene) -> Value {
    let mut value = as_object(to_rounded_value(scene));
    // Keys go unrounded: a key's time is a frame's (frame 7 at 24 fps is 0.29166666 s), and
    // rounded it would fall between frames.
    if !scene.animation.is_empty()
        && let Ok(keys) = serde_json::to_value(&scene.animation)
    {
        value.insert("animation".into(), keys);
    }
    let bases = bases(LINK_VERSION);
    let base = as_object(rounded(&bases.scene));
    let mut plane_base = as_object(rounded(&bases.plane));
    plane_base.remove("points");
    let ellipsoid_base = as_object(rounded(&bases.ellipsoid));
    let list = |value: &mut Map<String, Value>, key: &str, base: &Map<String, Value>| {
        let items = match value.remove(key) {
            Some(Value::Array(items)) => items,
            _ => Vec::new(),
        };
        let items = items
            .into_iter()
            .map(|item| {
                let mut item = as_object(item);
                item.remove("points");
                item.remove("pressure");
                Value::Object(diff(&item, base))
            })
            .collect();
        Value::Array(items)
    };
    let planes = list(&mut value, "planes", &plane_base);
    let ellipsoids = list(&mut value, "ellipsoids", &ellipsoid_base);
    if let Some(Value::Object(reference)) = value.get_mut("reference") {
        reference.remove("data");
    }
    value.remove("version");
    let mut out = diff(&value, &base);
    out.remove("version");
    out.insert("planes".into(), planes);
    out.insert("ellipsoids".into(), ellipsoids);
    Value::Object(out)
}

/// The scene JSON a settings object describes; counts checked before anything is built.
fn merge_onto_base(bases: &Bases, mut diff: Map<String, Value>) -> Result<Value, LinkError> {
    let mut list = |key: &str, cap: usize, base: Value| -> Result<Value, LinkError> {
        let items = match diff.remove(key) {
            Some(Value::Array(items)) => items,
            Some(_) => return Err(damaged(format!("\"{key}\" is not a list"))),
            None => Vec::new(),
        };
        if items.len() > cap {
            return Err(LinkError::Scene(SceneError::Invalid(format!(
                "{} {key} (at most {cap})",
                items.len()
            ))));
        }
        let mut out = Vec::with_capacity(items.len());
        for item in items {
            let mut full = base.clone();
            merge(&mut full, item);
            out.push(full);
        }
        Ok(Value::Array(out))
    };
    let planes = list("planes", MAX_PLANES, bases.plane.clone())?;
    let ellipsoids = list("ellipsoids", MAX_ELLIPSOIDS, bases.ellipsoid.clone())?;
    let mut scene = bases.scene.clone();
    merge(&mut scene, Value::Object(diff));
    if let Value::Object(o) = &mut scene {
        o.insert("planes".into(), planes);
        o.insert("ellipsoids".into(), ellipsoids);
        o.insert("version".into(), Value::from(SCENE_VERSION));
    }
    Ok(scene)
}

// --- the strokes: quantised points as second differences -----------------------------------

fn encode_payload(scene: &Scene) -> Vec<u8> {
    let json = serde_json::to_vec(&settings_json(scene)).unwrap_or_default();
    let mut w = Writer::default();
    w.uvar(json.len() as u64);
    w.0.extend_from_slice(&json);
    for plane in &scene.planes {
        write_stroke(&mut w, plane);
    }
    w.0
}

/// Predicted next quantised coordinate from the ones before (`k[i-1]`, `k[i-2]`, `k[i-3]`):
/// the last point plus the velocity over the last two steps, which averages out the
/// whole-pixel jitter of pointer samples better than a plain second difference.
fn predict(i: usize, q: &[[i64; 2]], axis: usize) -> Option<i64> {
    match i {
        0 => Some(0),
        1 => Some(q[0][axis]),
        2 => q[1][axis].checked_mul(2)?.checked_sub(q[0][axis]),
        _ => {
            let v = q[i - 1][axis].checked_sub(q[i - 3][axis])?.div_euclid(2);
            q[i - 1][axis].checked_add(v)
        }
    }
}

fn write_stroke(w: &mut Writer, plane: &DrawingPlane) {
    let points = &plane.points;
    w.uvar(points.len() as u64);
    if !points.is_empty() {
        let e = grid_exponent(points);
        w.ivar(e);
        let q = grid_points(points, e);
        for (i, k) in q.iter().enumerate() {
            for (axis, &v) in k.iter().enumerate() {
                w.ivar(v - predict(i, &q, axis).unwrap_or(0));
            }
        }
    }
    let pressure = if plane.pressure.len() == points.len() {
        &plane.pressure[..]
    } else {
        &[]
    };
    w.uvar(pressure.len() as u64);
    let mut last = 0i64;
    for p in pressure {
        let k = (p.clamp(0.0, 1.0) * 255.0).round() as i64;
        w.ivar(k - last);
        last = k;
    }
}

type Stroke = (Vec<glam::Vec2>, Vec<f32>);

fn read_stroke(r: &mut Reader) -> Result<Stroke, LinkError> {
    let n = r.uvar()?;
    // Each point takes at least two bytes, so a count beyond what is left is a lie.
    if n > MAX_PLANE_POINTS as u64 || n > r.left() as u64 {
        return Err(damaged(format!("a stroke of {n} points")));
    }
    let n = n as usize;
    let mut points = Vec::with_capacity(n);
    if n > 0 {
        let e = r.ivar()?;
        if !(-MAX_EXPONENT..=MAX_EXPONENT).contains(&e) {
            return Err(damaged("a stroke's grid is out of range"));
        }
        let mut q: Vec<[i64; 2]> = Vec::with_capacity(n);
        for i in 0..n {
            let mut k = [0i64; 2];
            for (axis, k) in k.iter_mut().enumerate() {
                let v = r.ivar()?;
                *k = predict(i, &q, axis)
                    .and_then(|p| p.checked_add(v))
                    .filter(|k| k.unsigned_abs() <= MAX_STEPS as u64)
                    .ok_or_else(|| damaged("a stroke runs off its grid"))?;
            }
            q.push(k);
            points.push(grid_point(k, e));
        }
        if points.iter().any(|p| !p.is_finite()) {
            return Err(damaged("a stroke point is not finite"));
        }
    }
    let np = r.uvar()?;
    if np != 0 && np != n as u64 {
        return Err(damaged("pressure does not match its stroke"));
    }
    let mut pressure = Vec::with_capacity(np as usize);
    let mut last = 0i64;
    for _ in 0..np {
        last = last
            .checked_add(r.ivar()?)
            .filter(|k| (0..=255).contains(k))
            .ok_or_else(|| damaged("pressure out of range"))?;
        pressure.push(last as f32 / 255.0);
    }
    Ok((points, pressure))
}

// --- varints -------------------------------------------------------------------------------

#[derive(Default)]
struct Writer(Vec<u8>);

impl Writer {
    fn uvar(&mut self, mut v: u64) {
        while v >= 0x80 {
            self.0.push((v as u8) | 0x80);
            v >>= 7;
        }
        self.0.push(v as u8);
    }

    /// Zigzag: small magnitudes of either sign take one byte.
    fn ivar(&mut self, v: i64) {
        self.uvar(((v << 1) ^ (v >> 63)) as u64);
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn left(&self) -> usize {
        self.bytes.len() - self.at
    }

    fn take(&mut self, n: usize) -> Result<&[u8], LinkError> {
        let out = self
            .bytes
            .get(self.at..self.at + n)
            .ok_or_else(|| damaged("cut short"))?;
        self.at += n;
        Ok(out)
    }

    fn uvar(&mut self) -> Result<u64, LinkError> {
        let mut v = 0u64;
        for shift in (0..64).step_by(7) {
            let &b = self
                .bytes
                .get(self.at)
                .ok_or_else(|| damaged("cut short"))?;
            self.at += 1;
            v |= ((b & 0x7f) as u64) << shift;
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        Err(damaged("a number is too long"))
    }

    fn ivar(&mut self) -> Result<i64, LinkError> {
        let u = self.uvar()?;
        Ok(((u >> 1) as i64) ^ -((u & 1) as i64))
    }
}

#[cfg(test)]
mod tests;
