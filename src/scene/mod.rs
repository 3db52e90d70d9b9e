//! The scene document: the only state a user makes.
//!
//! Plain serde data, versioned, with no GPU or UI types. Everything the app shows (the
//! blended field, sphere primitives, GPU buffers) is derived from it deterministically.

mod billows;
mod camera;
mod capped;
mod clock;
mod document;
mod edit;
mod keys;
mod looks;
mod motion;
mod plane;
mod pointer;
mod presets;
mod reference;
mod simulation;

pub use crate::limits::{MAX_ELLIPSOIDS, MAX_PLANE_POINTS, MAX_PLANES};
pub use billows::Billows;
pub use camera::{OrbitCamera, Ray, StandardView};
pub use clock::{Clock, Moment, step_position, steps_at};
pub use document::{Document, Revisions};
pub use edit::Edit;
pub use keys::{
    Animation, Channel, Ease, EllipsoidProperty, Key, LightProperty, MAX_KEYS, MAX_TRACKS,
    MediaProperty, PlaneProperty, ShotProperty, TierProperty, Track,
};
pub use looks::{Look, Looks};
pub use motion::{Motion, WindField};
pub use plane::{
    DrawingPlane, MAX_GRID_EXPONENT, MAX_GRID_STEPS, STROKE_GRID, StrokeKind, centre_of,
    grid_exponent, grid_point, grid_points, grid_step,
};
pub use pointer::{SetError, set_by_pointer};
pub use presets::Preset;
pub use reference::ReferenceImage;
pub use simulation::{MAX_CELLS, Settings as SimulationSettings};

use std::sync::Arc;

use crate::limits;

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// Significant digits a share link keeps of every setting (`share::link`).
pub const LINK_DIGITS: usize = 5;

/// `v` as a share link writes it and reads it back: rounded to [`LINK_DIGITS`] significant
/// digits (of its value as a double, as the link's JSON holds it).
pub fn as_linked(v: f32) -> f32 {
    if !v.is_finite() {
        return v;
    }
    format!("{:.*e}", LINK_DIGITS - 1, v as f64)
        .parse::<f64>()
        .map_or(v, |x| x as f32)
}

/// Version written by this build. Older documents are upgraded on load; newer ones are refused.
/// Version 2 added billows and stable ids to ellipsoids and drawing planes (a version 1
/// document has no billows, and its primitives get ids in order when it is read). Version 3
/// added the clock's frame rate and range (a document without them has the default clock).
/// Version 4 added key frames (a document without them has none). Version 5 added moving
/// ellipsoids and the wind field. Version 6 added the physical sky (a document without it
/// shows its picked colours).
pub const SCENE_VERSION: u32 = 6;

/// Errors when reading a scene document.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// Not JSON, or JSON of the wrong shape.
    #[error("not a cloudsketch scene: {0}")]
    Parse(#[from] serde_json::Error),
    /// Written by a newer build.
    #[error("scene version {found} is newer than this build supports (up to {SCENE_VERSION})")]
    TooNew {
        /// Version found in the document.
        found: u32,
    },
    /// Values outside the allowed ranges.
    #[error("invalid scene: {0}")]
    Invalid(String),
    /// A JSON object with none of a scene's members (`{}`, a stroke file).
    #[error("not a cloudsketch scene: it holds none of a scene's members ({})", capped::MEMBERS.join(", "))]
    NoScene,
}

/// Refuses a document written by a newer build (a missing version is this build's).
fn check_version(found: Option<u64>) -> Result<(), SceneError> {
    match found {
        Some(found) if found > SCENE_VERSION as u64 => Err(SceneError::TooNew {
            found: found.min(u32::MAX as u64) as u32,
        }),
        _ => Ok(()),
    }
}

/// The whole document.
///
/// Ellipsoids and drawing planes are each behind an [`Arc`]: cloning a scene (an undo step, a
/// snapshot for the renderer) shares every primitive it did not change, and derived caches can
/// tell an unchanged primitive by pointer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Scene {
    /// Document format version ([`SCENE_VERSION`] when written by this build).
    pub version: u32,
    /// Seed for every random choice derived from the document (noise, 3D extension).
    pub seed: u64,
    /// The view the document opens with.
    pub camera: OrbitCamera,
    /// Sun, sky and background.
    pub light: Lighting,
    /// Render quality and cloud media settings.
    pub render: RenderSettings,
    /// Implicit ellipsoids blended into the cloud field.
    #[serde(deserialize_with = "capped::vec::<_, _, MAX_ELLIPSOIDS>")]
    pub ellipsoids: Vec<Arc<Ellipsoid>>,
    /// Drawing planes, each holding one sketched stroke (outline or cut).
    #[serde(deserialize_with = "capped::vec::<_, _, MAX_PLANES>")]
    pub planes: Vec<Arc<DrawingPlane>>,
    /// The picture to trace, placed in the scene.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference: Option<Arc<ReferenceImage>>,
    /// The scene clock in seconds: where the media's wind and torque have carried the noise.
    /// Playing advances it; like the camera it is not an undo step.
    pub time: f32,
    /// Frames per second and the frame range (left out of a file while it is the default).
    #[serde(default, skip_serializing_if = "Clock::is_default")]
    pub clock: Clock,
    /// A cloud simulation (Dobashi et al. 2000): when present, the cloud is the automaton's
    /// smoothed cloud at the scene's time, and the ellipsoids are its parcels.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simulation: Option<Arc<SimulationSettings>>,
    /// The shot camera: the view a shot is rendered from (`render --shot`), keyable, apart
    /// from the free view the artist orbits with (`camera`); the view looks through it on
    /// demand (numpad 0). Left out of a file while there is none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shot: Option<OrbitCamera>,
    /// Key frames on the document's values (left out of a file while there are none). Every
    /// keyed value above is its keys' pose at [`Scene::time`].
    #[serde(default, skip_serializing_if = "Animation::is_empty")]
    pub animation: Animation,
    /// The wind that carries the moving ellipsoids (left out of a file while calm).
    #[serde(default, skip_serializing_if = "WindField::is_calm")]
    pub wind_field: WindField,
}

impl Default for Scene {
    fn default() -> Self {
        Self::preset(Preset::Cumulus)
    }
}

impl Scene {
    /// Parses a document, upgrading older versions and checking every limit. Returns the scene
    /// and what validation repaired in it, in words (see [`Scene::validate`]): tell the user.
    ///
    /// A leading byte-order mark is dropped. The text is read twice and never built into a
    /// JSON tree: first its outline (the version; every value skipped), then the document
    /// itself, its unknown members skipped and its lists stopped at their caps, so memory stays
    /// a small multiple of the text.
    pub fn from_json(text: &str) -> Result<(Self, Vec<String>), SceneError> {
        Self::parse(text, false)
    }

    /// Like [`Scene::from_json`] for a file: a JSON object without any of a scene's members
    /// (`{}`, a stroke file) holds no scene, and says so instead of opening the default one.
    pub fn from_file_json(text: &str) -> Result<(Self, Vec<String>), SceneError> {
        Self::parse(text, true)
    }

    /// [`Scene::from_json`], refusing with `needs_members` a document that has none of a
    /// scene's members. The outline is read once.
    fn parse(text: &str, needs_members: bool) -> Result<(Self, Vec<String>), SceneError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let outline: capped::Outline = serde_json::from_str(text)?;
        if needs_members && outline.members == 0 {
            return Err(SceneError::NoScene);
        }
        check_version(outline.version)?;
        let mut scene: Scene = serde_json::from_str(text)?;
        scene.version = SCENE_VERSION;
        let repairs = scene.validate()?;
        // A document read holds its keyed values posed at its time.
        scene.pose(scene.time);
        Ok((scene, repairs))
    }

    /// Like [`Scene::from_json`] for an already parsed value.
    pub fn from_value(value: serde_json::Value) -> Result<(Self, Vec<String>), SceneError> {
        let (mut scene, repairs) = Self::from_value_unposed(value)?;
        scene.pose(scene.time);
        Ok((scene, repairs))
    }

    /// [`Scene::from_value`] leaving every value as the JSON holds it, keyed or not (`--set`
    /// of a keyed value sets it, as an edit in the app does, until the time moves).
    pub(crate) fn from_value_unposed(
        value: serde_json::Value,
    ) -> Result<(Self, Vec<String>), SceneError> {
        if !value.is_object() {
            return Err(SceneError::Invalid(
                "a scene document is a JSON object".into(),
            ));
        }
        check_version(value.get("version").and_then(|v| v.as_u64()))?;
        let mut scene: Scene = serde_json::from_value(value)?;
        scene.version = SCENE_VERSION;
        let repairs = scene.validate()?;
        Ok((scene, repairs))
    }

    /// Moves every stroke that is off its grid onto it ([`DrawingPlane::snap_to_grid`]: by at
    /// most half a step), as the app does when a stroke is made, so files and links hold it
    /// exactly. Returns how many strokes moved.
    pub fn snap_strokes(&mut self) -> usize {
        let mut moved = 0;
        for plane in &mut self.planes {
            let mut snapped = (**plane).clone();
            snapped.snap_to_grid();
            if snapped.points != plane.points {
                *plane = Arc::new(snapped);
                moved += 1;
            }
        }
        moved
    }

    /// Pretty JSON of the document.
    pub fn to_json(&self) -> String {
        // Serializing plain data with string keys cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Checks sizes and ranges; repairs what can be repaired (a value out of range is clamped,
    /// a non-finite setting takes its default, a zero rotation becomes none) and refuses what
    /// cannot (too many primitives or points, non-finite geometry). Returns each repair in
    /// words, as `/path: old → new`, so nothing is changed silently.
    pub fn validate(&mut self) -> Result<Vec<String>, SceneError> {
        let before = serde_json::to_value(&*self).ok();
        self.check_and_repair()?;
        let mut repairs = Vec::new();
        if let (Some(before), Ok(after)) = (before, serde_json::to_value(&*self)) {
            describe_repairs("", &before, &after, &mut repairs);
        }
        // Ids are given, not repaired: a document from before them gets them silently.
        self.settle_ids();
        let mut animation = std::mem::take(&mut self.animation);
        repairs.extend(animation.repair(self));
        self.animation = animation;
        const SHOWN: usize = 12;
        if repairs.len() > SHOWN {
            let more = repairs.len() - SHOWN;
            repairs.truncate(SHOWN);
            repairs.push(format!("and {more} more values repaired"));
        }
        Ok(repairs)
    }

    /// Settles what the derivation keys on: gives every ellipsoid and drawing plane without an
    /// id (0), or with one an earlier primitive already holds, a fresh id (one more than the
    /// largest in the document, in document order, ellipsoids first, so the same document
    /// always gets the same ids); and rounds a billowed ellipsoid's radii as a share link
    /// writes them ([`as_linked`]: billows make many all-or-nothing choices from the radii, so a
    /// link must carry them exactly for its cloud to be the sender's).
    pub fn settle(&mut self) {
        self.settle_ids();
        let mut animation = std::mem::take(&mut self.animation);
        animation.forget_missing(self);
        self.animation = animation;
    }

    /// [`Scene::settle`] but for the keys: ids given and billowed radii rounded.
    fn settle_ids(&mut self) {
        for e in &mut self.ellipsoids {
            let radii = e.radii.map(as_linked);
            if !e.billows.is_off() && radii != e.radii && radii.min_element() > 0.0 {
                Arc::make_mut(e).radii = radii;
            }
        }
        let mut next = self
            .ellipsoids
            .iter()
            .map(|e| e.id)
            .chain(self.planes.iter().map(|p| p.id))
            .max()
            .unwrap_or(0);
        let mut seen = std::collections::HashSet::new();
        let mut fresh = |id: u64| {
            if id != 0 && seen.insert(id) {
                None
            } else {
                next += 1;
                seen.insert(next);
                Some(next)
            }
        };
        for e in &mut self.ellipsoids {
            if let Some(id) = fresh(e.id) {
                Arc::make_mut(e).id = id;
            }
        }
        for p in &mut self.planes {
            if let Some(id) = fresh(p.id) {
                Arc::make_mut(p).id = id;
            }
        }
    }

    fn check_and_repair(&mut self) -> Result<(), SceneError> {
        if self.ellipsoids.len() > MAX_ELLIPSOIDS {
            return Err(SceneError::Invalid(format!(
                "{} ellipsoids (at most {MAX_ELLIPSOIDS})",
                self.ellipsoids.len()
            )));
        }
        for (i, e) in self.ellipsoids.iter().enumerate() {
            if !(e.center.is_finite()
                && e.radii.is_finite()
                && e.rotation.is_finite()
                && e.strength.is_finite())
            {
                return Err(SceneError::Invalid(format!(
                    "ellipsoid {i} has a non-finite value"
                )));
            }
            if e.radii.min_element() <= 0.0 {
                return Err(SceneError::Invalid(format!(
                    "ellipsoid {i} has a radius ≤ 0"
                )));
            }
        }
        self.clock.sanitize();
        for e in &mut self.ellipsoids {
            if let Some(r) = unit_rotation(e.rotation) {
                Arc::make_mut(e).rotation = r;
            }
            let mut billows = e.billows;
            billows.sanitize();
            if billows != e.billows {
                Arc::make_mut(e).billows = billows;
            }
            if let Some(m) = e.motion {
                let mut fixed = m;
                fixed.sanitize(e.center, e.radii);
                if fixed != m {
                    Arc::make_mut(e).motion = Some(fixed);
                }
            }
        }
        self.wind_field.sanitize();
        if self.planes.len() > MAX_PLANES {
            return Err(SceneError::Invalid(format!(
                "{} drawing planes (at most {MAX_PLANES})",
                self.planes.len()
            )));
        }
        for (i, plane) in self.planes.iter_mut().enumerate() {
            // Freshly read planes are not shared, so this copies nothing.
            Arc::make_mut(plane)
                .validate(i)
                .map_err(SceneError::Invalid)?;
        }
        if let Some(r) = &mut self.reference {
            Arc::make_mut(r).validate().map_err(SceneError::Invalid)?;
        }
        self.camera.sanitize();
        if let Some(shot) = &mut self.shot {
            shot.sanitize();
        }
        self.light.sanitize();
        self.render.sanitize();
        if let Some(sim) = &mut self.simulation {
            Arc::make_mut(sim).sanitize();
        }
        if !self.time.is_finite() || !(0.0..=limits::MAX_TIME).contains(&self.time) {
            self.time = if self.time.is_finite() {
                self.time.clamp(0.0, limits::MAX_TIME)
            } else {
                0.0
            };
        }
        Ok(())
    }
}

/// An implicit ellipsoid: Wyvill's kernel on the ellipsoid-normalised distance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Ellipsoid {
    /// Centre in world units (y up).
    pub center: Vec3,
    /// Semi-axes of the visible surface of the ellipsoid alone.
    pub radii: Vec3,
    /// Orientation of the semi-axes.
    pub rotation: Quat,
    /// Field weight; 1 is a plain primitive.
    pub strength: f32,
    /// Hidden: kept in the document, left out of the cloud.
    pub hidden: bool,
    /// Stable id, unique among the document's ellipsoids and planes (0: not yet given one;
    /// [`Scene::settle`]). Seeds the billows, so a primitive keeps its puffs when others
    /// are added or removed.
    #[serde(skip_serializing_if = "is_zero")]
    pub id: u64,
    /// Puffs on its surface.
    #[serde(skip_serializing_if = "Billows::is_unset")]
    pub billows: Billows,
    /// How it moves with time (Schpok et al. 2003 §3.1's particles): its centre and radii
    /// above are this motion's pose at the scene's time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<Motion>,
}

fn is_zero(v: &u64) -> bool {
    *v == 0
}

impl Default for Ellipsoid {
    fn default() -> Self {
        Self::new(Vec3::ZERO, Vec3::ONE)
    }
}

impl Ellipsoid {
    /// An axis-aligned ellipsoid of unit strength.
    pub fn new(center: Vec3, radii: Vec3) -> Self {
        Self {
            center,
            radii,
            rotation: Quat::IDENTITY,
            strength: 1.0,
            hidden: false,
            id: 0,
            billows: Billows::default(),
            motion: None,
        }
    }

    /// This ellipsoid with billows as a new one gets ([`Billows::NEW`]).
    pub fn billowed(self) -> Self {
        Self {
            billows: Billows::NEW,
            ..self
        }
    }
}

/// Sun, sky and background. Colours are sRGB-encoded in [0, 1], as artists pick them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Lighting {
    /// Sun azimuth in degrees: 0 = +x (right in the default view), 90 = +z (toward the viewer).
    pub sun_azimuth_deg: f32,
    /// Sun elevation above the horizon in degrees.
    pub sun_elevation_deg: f32,
    /// Sun colour.
    pub sun_color: [f32; 3],
    /// Sun intensity multiplier.
    pub sun_intensity: f32,
    /// Ambient sky light colour (fills the shadowed side).
    pub sky_color: [f32; 3],
    /// Ambient intensity multiplier.
    pub ambient: f32,
    /// Background colour behind the cloud.
    pub background: [f32; 3],
    /// Henyey–Greenstein asymmetry of the phase function (0: isotropic; toward 1: light goes
    /// on along the sun's direction, the silver lining seen toward the sun).
    pub forward_scattering: f32,
    /// Weight of the approximated multiple scattering (octaves of light scattered again with
    /// less extinction, after Wrenninge 2013): bright insides of thick clouds.
    pub multiple_scattering: f32,
    /// A sky gradient behind the cloud: `background` at the zenith, `horizon_color` at eye
    /// level, a haze below; off, the background is one flat colour.
    pub sky_gradient: bool,
    /// The sky's colour at the horizon (with `sky_gradient`).
    pub horizon_color: [f32; 3],
    /// The physical sky (Hillaire 2020, [`crate::atmosphere`]): the sky behind the cloud with
    /// the sun's disk, the sun's colour and the sky light's, all from the sun's elevation
    /// through the air. The picked sun, sky, background and horizon colours are not used.
    pub physical_sky: bool,
    /// Exposure in stops: sun and sky light times 2^EV before tone mapping.
    pub exposure: f32,
    /// A ground plane below the sky, darkened where the clouds shade it from the sun.
    pub ground: bool,
    /// The ground's height (world y).
    pub ground_height: f32,
    /// The ground's colour in full sun (sRGB).
    pub ground_color: [f32; 3],
    /// Shafts of light (Dobashi et al. 2000): sunlight scattered by the air, dark where the
    /// clouds shade the air from the sun, so light shows in shafts through their gaps.
    pub shafts: bool,
    /// How bright the shafts are.
    pub shaft_intensity: f32,
    /// The air's extinction per world unit.
    pub shaft_density: f32,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            sun_azimuth_deg: limits::SUN_AZIMUTH.default as f32,
            sun_elevation_deg: limits::SUN_ELEVATION.default as f32,
            sun_color: [1.0, 0.97, 0.9],
            sun_intensity: limits::SUN_INTENSITY.default as f32,
            sky_color: [0.55, 0.66, 0.85],
            ambient: limits::AMBIENT.default as f32,
            background: [0.33, 0.52, 0.78],
            forward_scattering: limits::FORWARD_SCATTERING.default as f32,
            multiple_scattering: limits::MULTIPLE_SCATTERING.default as f32,
            sky_gradient: false,
            horizon_color: [0.78, 0.84, 0.9],
            physical_sky: false,
            exposure: limits::EXPOSURE.default as f32,
            ground: false,
            ground_height: limits::GROUND_HEIGHT.default as f32,
            ground_color: [0.36, 0.42, 0.3],
            shafts: false,
            shaft_intensity: limits::SHAFT_INTENSITY.default as f32,
            shaft_density: limits::SHAFT_DENSITY.default as f32,
        }
    }
}

/// sRGB-encoded colour → linear.
pub fn srgb_to_linear(c: [f32; 3]) -> Vec3 {
    let f = |v: f32| {
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    Vec3::new(f(c[0]), f(c[1]), f(c[2]))
}

impl Lighting {
    /// What one unit of the physical sky's light ([`crate::atmosphere`]: per unit of the
    /// sun's irradiance) is in the app's light: 4π × the sun's intensity (the app's phase
    /// function is normalised so that isotropic scattering is 1, see docs/export-formats.md).
    pub fn physical_scale(&self) -> f32 {
        4.0 * std::f32::consts::PI * self.sun_intensity
    }

    /// The sunlight on the clouds (linear, before exposure): the picked colour × intensity,
    /// or with the physical sky, the intensity × the air's transmittance toward the sun from
    /// the clouds' height (reddened and dimmed as the sun sets, none below the horizon).
    pub fn sun_light(&self) -> Vec3 {
        if self.physical_sky {
            crate::atmosphere::transmittance(
                crate::atmosphere::CLOUD_ALTITUDE,
                self.sun_elevation_deg.to_radians(),
            ) * self.sun_intensity
        } else {
            srgb_to_linear(self.sun_color) * self.sun_intensity
        }
    }

    /// The sky light that fills the clouds' shadowed side (linear, before exposure): the
    /// picked colour × ambient, or with the physical sky, ambient × the mean radiance of the
    /// sky above the horizon.
    pub fn sky_light(&self) -> Vec3 {
        if self.physical_sky {
            crate::atmosphere::sky(self.sun_elevation_deg).sky_mean
                * (self.physical_scale() * self.ambient)
        } else {
            srgb_to_linear(self.sky_color) * self.ambient
        }
    }

    /// Unit vector pointing from the scene toward the sun.
    pub fn sun_direction(&self) -> Vec3 {
        let (az, el) = (
            self.sun_azimuth_deg.to_radians(),
            self.sun_elevation_deg.to_radians(),
        );
        Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin()).normalize_or(Vec3::Y)
    }

    fn sanitize(&mut self) {
        self.sun_elevation_deg = limits::SUN_ELEVATION.fix_f32(self.sun_elevation_deg);
        self.sun_azimuth_deg =
            finite_or(self.sun_azimuth_deg, limits::SUN_AZIMUTH.default as f32).rem_euclid(360.0);
        self.sun_intensity = limits::SUN_INTENSITY.fix_f32(self.sun_intensity);
        self.ambient = limits::AMBIENT.fix_f32(self.ambient);
        self.forward_scattering = limits::FORWARD_SCATTERING.fix_f32(self.forward_scattering);
        self.multiple_scattering = limits::MULTIPLE_SCATTERING.fix_f32(self.multiple_scattering);
        self.exposure = limits::EXPOSURE.fix_f32(self.exposure);
        self.ground_height = limits::GROUND_HEIGHT.fix_f32(self.ground_height);
        self.shaft_intensity = limits::SHAFT_INTENSITY.fix_f32(self.shaft_intensity);
        self.shaft_density = limits::SHAFT_DENSITY.fix_f32(self.shaft_density);
        for c in [
            &mut self.ground_color,
            &mut self.sun_color,
            &mut self.sky_color,
            &mut self.background,
            &mut self.horizon_color,
        ] {
            for v in c.iter_mut() {
                *v = finite_or(*v, 0.5).clamp(0.0, 1.0);
            }
        }
    }
}

/// Table 2's noise filters (Schpok et al. 2003), applied to each octave's signed noise n in
/// [−1, 1]; each gives values in [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseFilter {
    /// (n + 1) / 2: soft, even variation (the paper's "stratus = noise").
    #[default]
    Stratus,
    /// |n|: billows with creases between them ("cumulus = |noise|").
    Cumulus,
    /// 1 − |2n|: thin ridges, wisps ("wispy").
    Wispy,
    /// (1 + |10n|)⁻¹: sharp bright veins on a dark body (the table's second cumulus filter).
    Veined,
}

impl NoiseFilter {
    /// Every filter, in the order the panel lists them.
    pub const ALL: [NoiseFilter; 4] = [Self::Stratus, Self::Cumulus, Self::Wispy, Self::Veined];

    /// Name for the panel.
    pub fn label(self) -> &'static str {
        match self {
            Self::Stratus => "stratus (n)",
            Self::Cumulus => "cumulus (|n|)",
            Self::Wispy => "wispy (1 - |2n|)",
            Self::Veined => "veined (1 / (1 + |10n|))",
        }
    }
}

/// The periodic noise the octaves sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseBasis {
    /// Gradient noise.
    #[default]
    Perlin,
    /// Cellular noise (one minus the distance to the nearest feature point): round puffs.
    Worley,
}

/// Render quality and cloud media (Schpok et al.'s Table 2 controls).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RenderSettings {
    /// Quality: number of view-aligned slices at full quality.
    pub slices: u32,
    /// Opacity: extinction per world unit of the densest cloud.
    pub opacity: f32,
    /// Resolution of the baked field grid along its longest side.
    pub field_resolution: u32,
    /// How far noise moves the cloud's surface (0 = smooth blobs).
    pub noise_amount: f32,
    /// Size of the first noise octave in world units.
    pub noise_scale: f32,
    /// Octaves of noise summed per sample.
    pub noise_octaves: u32,
    /// Lacunarity: frequency step between octaves (the Detail control).
    pub detail: f32,
    /// Width of the soft edge around the surface, in field units.
    pub softness: f32,
    /// Table 2's filter applied to each octave.
    pub noise_filter: NoiseFilter,
    /// The noise the octaves sample.
    pub noise_basis: NoiseBasis,
    /// Sharpness: the alpha cut-off, as a share of one slice's opacity (Table 2), so edges
    /// sharpen without the cloud shrinking when the opacity changes.
    pub sharpness: f32,
    /// Dirtiness: how fast the cloud darkens away from the sun (Table 2's shadow magnitude; it
    /// multiplies the optical depth toward the sun, which is already per world unit, so the
    /// slice count does not change it). 1 is physical.
    pub dirtiness: f32,
    /// Wind: how fast the noise drifts (world units per second of scene time, x and z).
    pub wind: [f32; 2],
    /// Torque: how fast the noise turns about the vertical (degrees per second).
    pub torque: f32,
    /// Atmospheric tiers above these base media, floors ascending (at most
    /// [`limits::MAX_TIERS`]): each its own filter, wind and torque (Schpok et al. §5.2).
    /// The first octave moves with the base wind and torque everywhere (the paper's Base tier),
    /// which keeps the tiers one cloud.
    #[serde(deserialize_with = "capped::vec::<_, _, 64>")]
    pub tiers: Vec<Tier>,
    /// Height over which one tier blends into the next around a floor.
    pub tier_blend: f32,
    /// Texels along the longest side of the light volume (the shadows' resolution).
    pub light_resolution: u32,
    /// Noise octaves the light volume sees (0: shadows of the smooth shape).
    pub light_octaves: u32,
}

/// An atmospheric tier: from `floor` up, the noise has its own character and motion.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Tier {
    /// Altitude (world y) where the tier begins.
    pub floor: f32,
    /// Table 2's filter in this tier.
    pub filter: NoiseFilter,
    /// Wind in this tier (world units per second, x and z).
    pub wind: [f32; 2],
    /// Torque in this tier (degrees per second).
    pub torque: f32,
}

impl Default for Tier {
    fn default() -> Self {
        Self {
            floor: limits::TIER_FLOOR.default as f32,
            filter: NoiseFilter::Wispy,
            wind: [1.0, 0.0],
            torque: 0.0,
        }
    }
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            slices: limits::SLICES.default as u32,
            opacity: limits::OPACITY.default as f32,
            field_resolution: limits::FIELD_RESOLUTION.default as u32,
            noise_amount: limits::NOISE_AMOUNT.default as f32,
            noise_scale: limits::NOISE_SCALE.default as f32,
            noise_octaves: limits::OCTAVES.default as u32,
            detail: limits::DETAIL.default as f32,
            softness: limits::SOFTNESS.default as f32,
            noise_filter: NoiseFilter::default(),
            noise_basis: NoiseBasis::default(),
            sharpness: limits::SHARPNESS.default as f32,
            dirtiness: limits::DIRTINESS.default as f32,
            wind: [0.0; 2],
            torque: 0.0,
            tiers: Vec::new(),
            tier_blend: limits::TIER_BLEND.default as f32,
            light_resolution: limits::LIGHT_RESOLUTION.default as u32,
            light_octaves: limits::LIGHT_OCTAVES.default as u32,
        }
    }
}

impl RenderSettings {
    /// These settings with the light previewed at no more than `cap` (light grid, light
    /// octaves; [`limits::CPU_PREVIEW_LIGHT`]): what the viewport draws on a slow adapter. It
    /// never goes above the document's.
    pub fn with_light_at_most(&self, [resolution, octaves]: [u32; 2]) -> Self {
        Self {
            light_resolution: self.light_resolution.min(resolution),
            light_octaves: self.light_octaves.min(octaves),
            ..self.clone()
        }
    }

    /// The floors the tiers take effect at, from the lowest: each at or above the one below
    /// (keys may pose a floor past the next tier's, which then begins with it).
    pub fn tier_floors(&self) -> Vec<f32> {
        let mut floors: Vec<f32> = self
            .tiers
            .iter()
            .take(limits::MAX_TIERS)
            .map(|t| t.floor)
            .collect();
        for k in 1..floors.len() {
            floors[k] = floors[k].max(floors[k - 1]);
        }
        floors
    }

    fn sanitize(&mut self) {
        self.slices = limits::SLICES.fix_u32(self.slices);
        self.field_resolution = limits::FIELD_RESOLUTION.fix_u32(self.field_resolution);
        self.noise_octaves = limits::OCTAVES.fix_u32(self.noise_octaves);
        self.opacity = limits::OPACITY.fix_f32(self.opacity);
        self.noise_amount = limits::NOISE_AMOUNT.fix_f32(self.noise_amount);
        self.noise_scale = limits::NOISE_SCALE.fix_f32(self.noise_scale);
        self.detail = limits::DETAIL.fix_f32(self.detail);
        self.softness = limits::SOFTNESS.fix_f32(self.softness);
        self.sharpness = limits::SHARPNESS.fix_f32(self.sharpness);
        self.dirtiness = limits::DIRTINESS.fix_f32(self.dirtiness);
        self.wind = self.wind.map(|w| limits::WIND.fix_f32(w));
        self.torque = limits::TORQUE.fix_f32(self.torque);
        self.tiers.truncate(limits::MAX_TIERS);
        for t in &mut self.tiers {
            t.floor = limits::TIER_FLOOR.fix_f32(t.floor);
            t.wind = t.wind.map(|w| limits::WIND.fix_f32(w));
            t.torque = limits::TORQUE.fix_f32(t.torque);
        }
        // Not sorted: keys address tiers by place ([`RenderSettings::tier_floors`] orders the
        // floors where they are used).
        self.tier_blend = limits::TIER_BLEND.fix_f32(self.tier_blend);
        self.light_resolution = limits::LIGHT_RESOLUTION.fix_u32(self.light_resolution);
        self.light_octaves = limits::LIGHT_OCTAVES.fix_u32(self.light_octaves);
    }
}

/// `q` made a unit rotation when it is not one already (a zero quaternion, or one with an
/// infinite component, becomes none). Scaled by its largest component first, so a quaternion of
/// huge components (`[1e30; 4]`, whose squared length overflows) normalises without overflow.
pub(crate) fn unit_rotation(q: Quat) -> Option<Quat> {
    if q.is_normalized() {
        return None;
    }
    let v = glam::Vec4::from(q);
    let largest = v.abs().max_element();
    if !largest.is_finite() || largest < 1e-6 {
        return Some(Quat::IDENTITY);
    }
    let unit = (v / largest).normalize();
    Some(Quat::from_vec4(unit))
}

/// Lists the leaves of `after` that differ from `before` (the same document before and after
/// repair), as `/path: old → new`; short arrays (vectors, rotations, colours) as a whole.
fn describe_repairs(path: &str, before: &Value, after: &Value, out: &mut Vec<String>) {
    let same = |a: &Value, b: &Value| match (a.as_f64(), b.as_f64()) {
        (Some(x), Some(y)) => (x - y).abs() <= 1e-5 * x.abs().max(1.0),
        _ => a == b,
    };
    // A setting that serialises as null held a number beyond what it can store (JSON has no
    // NaN, and a null in the file would not have parsed): `1e308` read into an `f32` is ∞.
    let show = |v: &Value| match v {
        Value::Null => "a number beyond ±3.4e38".to_owned(),
        Value::String(text) if text.len() > 60 => format!("{} characters of data", text.len()),
        Value::Number(n) => n.as_f64().map_or_else(|| n.to_string(), |f| format!("{f}")),
        Value::Array(items) if items.len() > 4 => format!("{} values", items.len()),
        Value::Array(items) => {
            let parts: Vec<String> = items
                .iter()
                .map(|x| x.as_f64().map_or("±∞".to_owned(), |f| format!("{f}")))
                .collect();
            format!("[{}]", parts.join(", "))
        }
        other => other.to_string(),
    };
    match (before, after) {
        (Value::Object(a), Value::Object(b)) => {
            for (key, vb) in b {
                let va = a.get(key).unwrap_or(&Value::Null);
                describe_repairs(&format!("{path}/{key}"), va, vb, out);
            }
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => {
            let short = b.len() <= 4 && b.iter().all(Value::is_number);
            if short {
                if a.iter().zip(b).any(|(x, y)| !same(x, y)) {
                    out.push(format!("{path}: {} → {}", show(before), show(after)));
                }
            } else {
                for (i, (x, y)) in a.iter().zip(b).enumerate() {
                    describe_repairs(&format!("{path}/{i}"), x, y, out);
                }
            }
        }
        _ if same(before, after) => {}
        _ => out.push(format!("{path}: {} → {}", show(before), show(after))),
    }
}

pub(crate) fn finite_or(v: f32, fallback: f32) -> f32 {
    if v.is_finite() { v } else { fallback }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_round_trip_is_lossless() {
        let scene = Scene::default();
        let (back, repairs) = Scene::from_json(&scene.to_json()).expect("round trip");
        assert!(repairs.is_empty(), "{repairs:?}");
        assert_eq!(scene, back);
    }

    #[test]
    fn missing_fields_take_defaults() {
        let (s, _) = Scene::from_json(r#"{"version":1,"ellipsoids":[]}"#).unwrap();
        assert_eq!(s.render, RenderSettings::default());
        assert!(s.ellipsoids.is_empty());
    }

    #[test]
    fn newer_versions_are_refused() {
        let err = Scene::from_json(r#"{"version":99}"#).unwrap_err();
        assert!(err.to_string().contains("newer"), "{err}");
    }

    #[test]
    fn malformed_documents_give_errors_not_panics() {
        for text in [
            "",
            "[]",
            "{",
            r#"{"ellipsoids": 3}"#,
            r#"{"ellipsoids":[{"radii":[0,1,1]}]}"#,
        ] {
            assert!(Scene::from_json(text).is_err(), "{text:?} accepted");
        }
    }

    #[test]
    fn out_of_range_settings_are_clamped() {
        let (s, repairs) =
            Scene::from_json(r#"{"render":{"slices":100000,"field_resolution":3}}"#).unwrap();
        assert_eq!(s.render.slices, limits::SLICES.max as u32);
        assert_eq!(
            s.render.field_resolution,
            limits::FIELD_RESOLUTION.min as u32
        );
        assert_eq!(
            repairs,
            [
                "/render/field_resolution: 3 → 16",
                "/render/slices: 100000 → 512"
            ],
        );
    }

    #[test]
    fn the_default_ground_lies_well_below_every_presets_cloud() {
        // It sat at the cumulus's base (the cloud stood on the lawn when the ground was on).
        for (preset, name) in Preset::ALL {
            let scene = Scene::preset(preset);
            let Some((lo, _)) = crate::derive::field_of(&scene).bounds() else {
                continue;
            };
            assert!(
                lo.y >= scene.light.ground_height + 3.0,
                "{name}: cloud from {} with the ground at {}",
                lo.y,
                scene.light.ground_height
            );
        }
    }

    #[test]
    fn degenerate_values_are_repaired_with_a_word_or_refused() {
        // A zero rotation used to pass and turn the field, bounds and framing into NaN.
        let text = r#"{
            "ellipsoids": [{"center": [0, 2, 0], "radii": [1, 1, 1], "rotation": [0, 0, 0, 0]}],
            "planes": [{"points": [[0, 0], [1, 0], [0, 1]], "rotation": [0, 0, 0, 0]},
                       {"points": [[0, 0], [1, 0], [0, 1]], "rotation": [0, 2, 0, 0]},
                       {"points": [[0, 0], [1, 0], [0, 1]], "rotation": [1e30, 1e30, 1e30, 1e30]}],
            "camera": {"distance": 1e300, "fov_y_deg": 1e39},
            "light": {"sun_intensity": -4},
            "render": {"tiers": [{"floor": 6, "wind": [1e39, -1e39]}]}
        }"#;
        let (s, repairs) = Scene::from_json(text).unwrap();
        assert_eq!(s.ellipsoids[0].rotation, Quat::IDENTITY);
        assert_eq!(s.planes[0].rotation, Quat::IDENTITY);
        assert_eq!(s.planes[1].rotation, Quat::from_xyzw(0.0, 1.0, 0.0, 0.0));
        for needle in [
            "/ellipsoids/0/rotation: [0, 0, 0, 0] → [0, 0, 0, 1]",
            "/planes/0/rotation: [0, 0, 0, 0] → [0, 0, 0, 1]",
            "/planes/1/rotation: [0, 2, 0, 0] → [0, 1, 0, 0]",
            "/camera/distance: a number beyond ±3.4e38 →",
            "/camera/fov_y_deg: a number beyond ±3.4e38 →",
            "/light/sun_intensity: -4 → 0",
            // An out-of-range pair says so (it read "[NaN, NaN]").
            "/render/tiers/0/wind: [±∞, ±∞] → [0, 0]",
        ] {
            assert!(
                repairs.iter().any(|r| r.starts_with(needle)),
                "{needle} not in {repairs:#?}"
            );
        }
        // Huge components normalise without overflow (they became [0, 0, 0, 0]).
        assert_eq!(s.planes[2].rotation, Quat::from_xyzw(0.5, 0.5, 0.5, 0.5));
        assert!(
            repairs
                .iter()
                .any(|r| r.starts_with("/planes/2/rotation: [")
                    && r.ends_with("→ [0.5, 0.5, 0.5, 0.5]")),
            "{repairs:#?}"
        );
        let (lo, hi) = crate::derive::field_of(&s).bounds().expect("a field");
        assert!(lo.is_finite() && hi.is_finite(), "{lo} {hi}");
        // Geometry that cannot be repaired is refused with a message.
        let err = Scene::from_json(
            r#"{"planes": [{"points": [[0, 0], [1, 0], [0, 1]], "origin": [0, 1e39, 0]}]}"#,
        )
        .unwrap_err();
        assert!(
            err.to_string().contains("plane 0 has a non-finite value"),
            "{err}"
        );
    }

    #[test]
    fn the_reference_image_is_saved_with_the_document_within_the_cap() {
        let camera = OrbitCamera::default();
        let bytes: Vec<u8> = (0..5000u32).map(|i| (i * 7 % 251) as u8).collect();
        let mut scene = Scene::default();
        let image = ReferenceImage::facing(
            "photo.png".into(),
            Arc::new(bytes.clone()),
            [40, 30],
            &camera,
            0.8,
        );
        // Facing the view: its normal points at the camera, centred on the focus point.
        let normal = image.rotation * Vec3::Z;
        assert!(normal.abs_diff_eq(-camera.forward(), 1e-5));
        assert!(image.at([0.5, 0.5]).abs_diff_eq(camera.target, 1e-5));
        scene.reference = Some(Arc::new(image));
        let (back, repairs) = Scene::from_json(&scene.to_json()).unwrap();
        assert!(repairs.is_empty(), "{repairs:?}");
        assert_eq!(back, scene);
        assert_eq!(*back.reference.unwrap().data, bytes);
        // Too large to embed: shown, but the document keeps its name only.
        let big = vec![0u8; limits::MAX_EMBEDDED_IMAGE_BYTES + 1];
        let image =
            ReferenceImage::facing("huge.jpg".into(), Arc::new(big), [40, 30], &camera, 0.8);
        assert!(!image.embedded());
        // A document holding more than the cap (written by hand) is repaired, with a word.
        let mut text: Value = serde_json::from_str(&scene.to_json()).unwrap();
        text["reference"]["data"] =
            Value::String("A".repeat((limits::MAX_EMBEDDED_IMAGE_BYTES + 3) / 3 * 4 + 4));
        let (s, repairs) = Scene::from_value(text).unwrap();
        assert!(!s.reference.unwrap().embedded());
        assert!(
            repairs
                .iter()
                .any(|r| r.starts_with("/reference/data:") && r.contains("characters of data")),
            "{repairs:?}"
        );
        let err = Scene::from_json(r#"{"reference": {"data": "not base64!"}}"#).unwrap_err();
        assert!(err.to_string().contains("base64"), "{err}");
    }

    #[test]
    fn sun_direction_follows_angles() {
        let mut l = Lighting {
            sun_azimuth_deg: 0.0,
            sun_elevation_deg: 0.0,
            ..Default::default()
        };
        assert!(l.sun_direction().abs_diff_eq(Vec3::X, 1e-6));
        l.sun_elevation_deg = 90.0;
        assert!(l.sun_direction().abs_diff_eq(Vec3::Y, 1e-6));
    }

    #[test]
    fn presets_by_name() {
        assert_eq!(Preset::from_name("EMPTY"), Some(Preset::Empty));
        assert!(Scene::preset(Preset::Empty).ellipsoids.is_empty());
        assert_eq!(Preset::from_name("nope"), None);
    }
}
