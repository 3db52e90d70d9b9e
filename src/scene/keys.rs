//! Key frames (Schpok et al. 2003 §3.1, "animating the primitives"): tracks of keys on the
//! document's values, addressed by the stable ids of ellipsoids and drawing planes, and the one
//! pure pose of a scene at a time.
//!
//! The document holds every value as it stands at its own time: a keyed value is the pose of
//! its keys there ([`Scene::posed_at`], applied by [`super::Document::set_time`] whenever the
//! time moves). So the tools edit what the user sees, an edit of a keyed value shows until the
//! time moves (Blender's behaviour without auto-key), and [`Animation::key`] records a value as
//! it stands.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

use super::{Scene, capped};
use crate::limits;

/// Largest magnitude a key's value may have (world units, degrees, weights): far beyond any
/// cloud, and far enough inside f32's range that interpolating two keys stays finite.
pub const MAX_MAGNITUDE: f32 = 1e6;

/// Most tracks a document holds.
pub const MAX_TRACKS: usize = 4096;
/// Most keys on one track.
pub const MAX_KEYS: usize = 1000;

/// How a key's value goes on to the next key's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ease {
    /// A straight line.
    #[default]
    Linear,
    /// Slow out of this key and into the next (smoothstep).
    EaseInOut,
    /// Holds this key's value until the next key.
    Constant,
}

impl Ease {
    /// Every ease, as the timeline offers them.
    pub const ALL: [Ease; 3] = [Ease::Linear, Ease::EaseInOut, Ease::Constant];

    /// Its name in the timeline.
    pub fn label(self) -> &'static str {
        match self {
            Ease::Linear => "Linear",
            Ease::EaseInOut => "Ease in and out",
            Ease::Constant => "Constant",
        }
    }

    /// The share of the way to the next key at `u` ∈ [0, 1] of the segment.
    pub fn apply(self, u: f32) -> f32 {
        let u = u.clamp(0.0, 1.0);
        match self {
            Ease::Linear => u,
            Ease::EaseInOut => u * u * (3.0 - 2.0 * u),
            Ease::Constant => 0.0,
        }
    }

    fn is_linear(&self) -> bool {
        *self == Ease::Linear
    }
}

/// A keyed property of an ellipsoid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EllipsoidProperty {
    /// Centre (x, y, z).
    Center,
    /// Semi-axes (x, y, z).
    Radii,
    /// Orientation (a quaternion x, y, z, w; keys go the short way).
    Rotation,
    /// Field weight.
    Strength,
    /// Shown (1) or hidden (0); always held to the next key.
    Visible,
}

/// A keyed property of a drawing plane: where it stands (a moving plane re-interprets
/// nothing), and the controls of what its outline makes (the stroke itself is not keyed).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PlaneProperty {
    /// The plane's origin (x, y, z).
    Origin,
    /// The plane's orientation (a quaternion).
    Rotation,
    /// The outline's inflation slider (Wither et al.'s t; each new value re-interprets the
    /// stroke, which the plane cache keeps per value).
    Inflation,
    /// The soft blend between the outline's spheres.
    Blend,
    /// The billows' size ratio and coverage (their levels are a count, not keyed).
    Billows,
}

/// A drawing plane's keyable properties.
pub const PLANE: [PlaneProperty; 5] = [
    PlaneProperty::Origin,
    PlaneProperty::Rotation,
    PlaneProperty::Inflation,
    PlaneProperty::Blend,
    PlaneProperty::Billows,
];

/// A keyed property of the light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightProperty {
    /// Sun azimuth in degrees (keys go the short way round).
    SunAzimuth,
    /// Sun elevation in degrees.
    SunElevation,
    /// Sun intensity.
    SunIntensity,
    /// Sun colour (sRGB).
    SunColor,
    /// Ambient intensity.
    Ambient,
    /// Exposure in stops.
    Exposure,
    /// The sky's colour (sRGB): its light on the cloud, and the sky at the zenith with the
    /// gradient.
    SkyColor,
    /// The horizon's colour (sRGB) of the sky gradient.
    HorizonColor,
    /// The background colour (sRGB): the flat sky, or the gradient's zenith.
    Background,
}

/// A keyed property of the cloud's media (Schpok's Table 2 controls).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MediaProperty {
    /// Extinction of the densest cloud.
    Opacity,
    /// How far noise moves the surface.
    NoiseAmount,
    /// Lacunarity.
    Detail,
    /// Size of the largest noise puffs.
    NoiseScale,
    /// Alpha cut-off.
    Sharpness,
    /// Shadow magnitude.
    Dirtiness,
    /// Wind (x, z): what carries the noise is its integral over time.
    Wind,
    /// Torque: what turns the noise is its integral over time.
    Torque,
}

/// A keyed property of an atmospheric tier (Schpok et al. §5.4): where it begins and how its
/// noise moves. Its filter is a choice, not a value, and is not keyed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TierProperty {
    /// The altitude where the tier begins (a keyed floor posed past the next tier's takes that
    /// tier up with it: [`crate::scene::RenderSettings::tier_floors`]).
    Floor,
    /// The tier's wind (x, z): what carries its noise is the wind's integral over time.
    Wind,
    /// The tier's torque: what turns its noise is the torque's integral over time.
    Torque,
}

/// A tier's keyable properties.
pub const TIER: [TierProperty; 3] = [
    TierProperty::Floor,
    TierProperty::Wind,
    TierProperty::Torque,
];

/// A keyed property of the shot camera (its orbit).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShotProperty {
    /// The point it looks at (x, y, z).
    Target,
    /// Its turn about the vertical in degrees (keys go the short way round).
    Yaw,
    /// Its angle above the horizon in degrees.
    Pitch,
    /// Its distance from the target.
    Distance,
    /// Its vertical field of view in degrees.
    Fov,
}

/// The shot camera's keyable properties.
pub const SHOT: [ShotProperty; 5] = [
    ShotProperty::Target,
    ShotProperty::Yaw,
    ShotProperty::Pitch,
    ShotProperty::Distance,
    ShotProperty::Fov,
];

/// What a track keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "item", rename_all = "snake_case")]
pub enum Channel {
    /// A property of the ellipsoid with stable id `id`.
    Ellipsoid {
        /// The ellipsoid's stable id.
        id: u64,
        /// Which property.
        property: EllipsoidProperty,
    },
    /// A property of the drawing plane with stable id `id`.
    Plane {
        /// The plane's stable id.
        id: u64,
        /// Which property.
        property: PlaneProperty,
    },
    /// A property of the light.
    Light {
        /// Which property.
        property: LightProperty,
    },
    /// A property of the media.
    Media {
        /// Which property.
        property: MediaProperty,
    },
    /// A property of the shot camera.
    Shot {
        /// Which property.
        property: ShotProperty,
    },
    /// A property of atmospheric tier `tier` (0 is the lowest tier above the base media).
    /// Tiers have no ids: removing one moves the keys of those above it down with them
    /// ([`Animation::tier_removed`]).
    Tier {
        /// The tier's place, from the lowest.
        tier: u32,
        /// Which property.
        property: TierProperty,
    },
}

/// How a channel's values interpolate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Component by component.
    Plain,
    /// A unit quaternion, spherically the short way.
    Rotation,
    /// Degrees on a circle, the short way round.
    Angle,
    /// Held to the next key whatever the ease.
    Step,
}

impl Channel {
    /// Number of values a key of this channel holds.
    pub fn width(self) -> usize {
        match self {
            Channel::Ellipsoid { property, .. } => match property {
                EllipsoidProperty::Center | EllipsoidProperty::Radii => 3,
                EllipsoidProperty::Rotation => 4,
                EllipsoidProperty::Strength | EllipsoidProperty::Visible => 1,
            },
            Channel::Plane { property, .. } => match property {
                PlaneProperty::Origin => 3,
                PlaneProperty::Rotation => 4,
                PlaneProperty::Inflation | PlaneProperty::Blend => 1,
                PlaneProperty::Billows => 2,
            },
            Channel::Light { property } => match property {
                LightProperty::SunColor
                | LightProperty::SkyColor
                | LightProperty::HorizonColor
                | LightProperty::Background => 3,
                _ => 1,
            },
            Channel::Media {
                property: MediaProperty::Wind,
            } => 2,
            Channel::Media { .. } => 1,
            Channel::Shot { property } => match property {
                ShotProperty::Target => 3,
                _ => 1,
            },
            Channel::Tier { property, .. } => match property {
                TierProperty::Wind => 2,
                TierProperty::Floor | TierProperty::Torque => 1,
            },
        }
    }

    fn kind(self) -> Kind {
        match self {
            Channel::Ellipsoid {
                property: EllipsoidProperty::Rotation,
                ..
            }
            | Channel::Plane {
                property: PlaneProperty::Rotation,
                ..
            } => Kind::Rotation,
            Channel::Ellipsoid {
                property: EllipsoidProperty::Visible,
                ..
            } => Kind::Step,
            Channel::Light {
                property: LightProperty::SunAzimuth,
            }
            | Channel::Shot {
                property: ShotProperty::Yaw,
            } => Kind::Angle,
            _ => Kind::Plain,
        }
    }

    /// The item's stable id, for channels of an ellipsoid or a plane.
    pub fn id(self) -> Option<u64> {
        match self {
            Channel::Ellipsoid { id, .. } | Channel::Plane { id, .. } => Some(id),
            _ => None,
        }
    }

    /// The channel's name, as messages and the timeline say it.
    pub fn describe(self) -> String {
        match self {
            Channel::Ellipsoid { id, property } => format!("ellipsoid {id}'s {property:?}"),
            Channel::Plane { id, property } => format!("drawing plane {id}'s {property:?}"),
            Channel::Light { property } => format!("the light's {property:?}"),
            Channel::Media { property } => format!("the media's {property:?}"),
            Channel::Shot { property } => format!("the shot camera's {property:?}"),
            Channel::Tier { tier, property } => format!("tier {}'s {property:?}", tier + 1),
        }
        .to_lowercase()
    }

    /// The channel's value in `scene`, or `None` where its item is not there.
    pub fn get(self, scene: &Scene) -> Option<Vec<f32>> {
        self.get_in(scene, None)
    }

    /// [`Channel::get`], finding the item through `index` where given.
    fn get_in(self, scene: &Scene, index: Option<&Index>) -> Option<Vec<f32>> {
        let v3 = |v: Vec3| v.to_array().to_vec();
        let q = |q: Quat| q.to_array().to_vec();
        Some(match self {
            Channel::Ellipsoid { id, property } => {
                let e = &scene.ellipsoids[Index::ellipsoid(index, scene, id)?];
                match property {
                    EllipsoidProperty::Center => v3(e.center),
                    EllipsoidProperty::Radii => v3(e.radii),
                    EllipsoidProperty::Rotation => q(e.rotation),
                    EllipsoidProperty::Strength => vec![e.strength],
                    EllipsoidProperty::Visible => vec![if e.hidden { 0.0 } else { 1.0 }],
                }
            }
            Channel::Plane { id, property } => {
                let p = &scene.planes[Index::plane(index, scene, id)?];
                let outline = p.kind == super::StrokeKind::Outline;
                match property {
                    // A cut's line has no inflation, blend or billows.
                    PlaneProperty::Inflation | PlaneProperty::Blend | PlaneProperty::Billows
                        if !outline =>
                    {
                        return None;
                    }
                    PlaneProperty::Origin => v3(p.origin),
                    PlaneProperty::Rotation => q(p.rotation),
                    PlaneProperty::Inflation => vec![p.sketch.inflate as f32],
                    PlaneProperty::Blend => vec![p.sketch.blend as f32],
                    PlaneProperty::Billows => vec![p.billows.ratio, p.billows.coverage],
                }
            }
            Channel::Light { property } => {
                let l = &scene.light;
                match property {
                    LightProperty::SunAzimuth => vec![l.sun_azimuth_deg],
                    LightProperty::SunElevation => vec![l.sun_elevation_deg],
                    LightProperty::SunIntensity => vec![l.sun_intensity],
                    LightProperty::SunColor => l.sun_color.to_vec(),
                    LightProperty::Ambient => vec![l.ambient],
                    LightProperty::Exposure => vec![l.exposure],
                    LightProperty::SkyColor => l.sky_color.to_vec(),
                    LightProperty::HorizonColor => l.horizon_color.to_vec(),
                    LightProperty::Background => l.background.to_vec(),
                }
            }
            Channel::Media { property } => {
                let r = &scene.render;
                vec![match property {
                    MediaProperty::Opacity => r.opacity,
                    MediaProperty::NoiseAmount => r.noise_amount,
                    MediaProperty::Detail => r.detail,
                    MediaProperty::NoiseScale => r.noise_scale,
                    MediaProperty::Sharpness => r.sharpness,
                    MediaProperty::Dirtiness => r.dirtiness,
                    MediaProperty::Wind => return Some(r.wind.to_vec()),
                    MediaProperty::Torque => r.torque,
                }]
            }
            Channel::Shot { property } => {
                let c = scene.shot.as_ref()?;
                match property {
                    ShotProperty::Target => v3(c.target),
                    ShotProperty::Yaw => vec![c.yaw_deg],
                    ShotProperty::Pitch => vec![c.pitch_deg],
                    ShotProperty::Distance => vec![c.distance],
                    ShotProperty::Fov => vec![c.fov_y_deg],
                }
            }
            Channel::Tier { tier, property } => {
                let t = scene.render.tiers.get(tier as usize)?;
                match property {
                    TierProperty::Floor => vec![t.floor],
                    TierProperty::Wind => t.wind.to_vec(),
                    TierProperty::Torque => vec![t.torque],
                }
            }
        })
    }

    /// Sets the channel's value in `scene` (a value of the wrong width or an item not there
    /// changes nothing); an item whose value is already `value` is left shared. Returns
    /// whether it changed.
    fn set(self, scene: &mut Scene, index: &Index, value: &[f32]) -> bool {
        if value.len() != self.width()
            || !value.iter().all(|v| v.is_finite())
            || self.get_in(scene, Some(index)).as_deref() == Some(value)
        {
            return false;
        }
        let v3 = || Vec3::from_slice(value);
        let q = || Quat::from_slice(value).normalize();
        match self {
            Channel::Ellipsoid { id, property } => {
                let Some(i) = Index::ellipsoid(Some(index), scene, id) else {
                    return false;
                };
                let e = Arc::make_mut(&mut scene.ellipsoids[i]);
                match property {
                    EllipsoidProperty::Center => e.center = v3(),
                    // As `Scene::settle` rounds a billowed one's (a link carries them so).
                    EllipsoidProperty::Radii if !e.billows.is_off() => {
                        e.radii = v3().map(super::as_linked)
                    }
                    EllipsoidProperty::Radii => e.radii = v3(),
                    EllipsoidProperty::Rotation => e.rotation = q(),
                    EllipsoidProperty::Strength => e.strength = value[0],
                    EllipsoidProperty::Visible => e.hidden = value[0] < 0.5,
                }
            }
            Channel::Plane { id, property } => {
                let Some(i) = Index::plane(Some(index), scene, id) else {
                    return false;
                };
                let p = Arc::make_mut(&mut scene.planes[i]);
                match property {
                    PlaneProperty::Origin => p.origin = v3(),
                    PlaneProperty::Rotation => p.rotation = q(),
                    PlaneProperty::Inflation => p.sketch.inflate = f64::from(value[0]),
                    PlaneProperty::Blend => p.sketch.blend = f64::from(value[0]),
                    PlaneProperty::Billows => {
                        p.billows.ratio = value[0];
                        p.billows.coverage = value[1];
                    }
                }
            }
            Channel::Light { property } => {
                let l = &mut scene.light;
                match property {
                    LightProperty::SunAzimuth => l.sun_azimuth_deg = value[0],
                    LightProperty::SunElevation => l.sun_elevation_deg = value[0],
                    LightProperty::SunIntensity => l.sun_intensity = value[0],
                    LightProperty::SunColor => l.sun_color = [value[0], value[1], value[2]],
                    LightProperty::Ambient => l.ambient = value[0],
                    LightProperty::Exposure => l.exposure = value[0],
                    LightProperty::SkyColor => l.sky_color = [value[0], value[1], value[2]],
                    LightProperty::HorizonColor => l.horizon_color = [value[0], value[1], value[2]],
                    LightProperty::Background => l.background = [value[0], value[1], value[2]],
                }
            }
            Channel::Media { property } => {
                let r = &mut scene.render;
                if property == MediaProperty::Wind {
                    r.wind = [value[0], value[1]];
                    return true;
                }
                let slot = match property {
                    MediaProperty::Opacity => &mut r.opacity,
                    MediaProperty::NoiseAmount => &mut r.noise_amount,
                    MediaProperty::Detail => &mut r.detail,
                    MediaProperty::NoiseScale => &mut r.noise_scale,
                    MediaProperty::Sharpness => &mut r.sharpness,
                    MediaProperty::Dirtiness => &mut r.dirtiness,
                    MediaProperty::Torque => &mut r.torque,
                    MediaProperty::Wind => return false,
                };
                *slot = value[0];
            }
            Channel::Shot { property } => {
                let Some(c) = scene.shot.as_mut() else {
                    return false;
                };
                match property {
                    ShotProperty::Target => c.target = v3(),
                    ShotProperty::Yaw => c.yaw_deg = value[0],
                    ShotProperty::Pitch => c.pitch_deg = value[0],
                    ShotProperty::Distance => c.distance = value[0],
                    ShotProperty::Fov => c.fov_y_deg = value[0],
                }
            }
            Channel::Tier { tier, property } => {
                let Some(t) = scene.render.tiers.get_mut(tier as usize) else {
                    return false;
                };
                match property {
                    TierProperty::Floor => t.floor = value[0],
                    TierProperty::Wind => t.wind = [value[0], value[1]],
                    TierProperty::Torque => t.torque = value[0],
                }
            }
        }
        true
    }

    /// `value` brought within what the channel may hold (the sliders' ranges, radii above 0,
    /// unit rotations), or `None` where it cannot be (not finite, the wrong width).
    fn repaired(self, value: &[f32]) -> Option<Vec<f32>> {
        // Finite and within [`MAX_MAGNITUDE`]: keys between which the interpolation stays
        // finite.
        if value.len() != self.width() || !value.iter().all(|v| v.abs() <= MAX_MAGNITUDE) {
            return None;
        }
        let param = |v: f32, p: limits::Param| vec![p.fix_f32(v)];
        Some(match self {
            Channel::Ellipsoid { property, .. } => match property {
                EllipsoidProperty::Radii if value.iter().any(|r| *r <= 0.0) => return None,
                EllipsoidProperty::Rotation => unit_quaternion(value)?,
                EllipsoidProperty::Visible => vec![if value[0] < 0.5 { 0.0 } else { 1.0 }],
                _ => value.to_vec(),
            },
            Channel::Plane { property, .. } => match property {
                PlaneProperty::Origin => value.to_vec(),
                PlaneProperty::Rotation => unit_quaternion(value)?,
                PlaneProperty::Inflation => param(value[0], limits::INFLATE),
                PlaneProperty::Blend => param(value[0], limits::BLEND),
                PlaneProperty::Billows => vec![
                    limits::BILLOW_RATIO.fix_f32(value[0]),
                    limits::BILLOW_COVERAGE.fix_f32(value[1]),
                ],
            },
            Channel::Light { property } => match property {
                LightProperty::SunAzimuth => param(value[0], limits::SUN_AZIMUTH),
                LightProperty::SunElevation => param(value[0], limits::SUN_ELEVATION),
                LightProperty::SunIntensity => param(value[0], limits::SUN_INTENSITY),
                LightProperty::SunColor
                | LightProperty::SkyColor
                | LightProperty::HorizonColor
                | LightProperty::Background => value.iter().map(|c| c.clamp(0.0, 1.0)).collect(),
                LightProperty::Ambient => param(value[0], limits::AMBIENT),
                LightProperty::Exposure => param(value[0], limits::EXPOSURE),
            },
            Channel::Media { property } => match property {
                MediaProperty::Opacity => param(value[0], limits::OPACITY),
                MediaProperty::NoiseAmount => param(value[0], limits::NOISE_AMOUNT),
                MediaProperty::Detail => param(value[0], limits::DETAIL),
                MediaProperty::NoiseScale => param(value[0], limits::NOISE_SCALE),
                MediaProperty::Sharpness => param(value[0], limits::SHARPNESS),
                MediaProperty::Dirtiness => param(value[0], limits::DIRTINESS),
                MediaProperty::Wind => value.iter().map(|w| limits::WIND.fix_f32(*w)).collect(),
                MediaProperty::Torque => param(value[0], limits::TORQUE),
            },
            Channel::Shot { property } => {
                // Within what a camera may hold (`OrbitCamera::sanitize`'s ranges).
                let mut c = super::OrbitCamera::default();
                match property {
                    ShotProperty::Target => value.to_vec(),
                    ShotProperty::Yaw => vec![value[0].rem_euclid(360.0)],
                    ShotProperty::Pitch => {
                        c.pitch_deg = value[0];
                        c.sanitize();
                        vec![c.pitch_deg]
                    }
                    ShotProperty::Distance => {
                        c.distance = value[0];
                        c.sanitize();
                        vec![c.distance]
                    }
                    ShotProperty::Fov => {
                        c.fov_y_deg = value[0];
                        c.sanitize();
                        vec![c.fov_y_deg]
                    }
                }
            }
            Channel::Tier { property, .. } => match property {
                TierProperty::Floor => param(value[0], limits::TIER_FLOOR),
                TierProperty::Wind => value.iter().map(|w| limits::WIND.fix_f32(*w)).collect(),
                TierProperty::Torque => param(value[0], limits::TORQUE),
            },
        })
    }

    /// The keyable channels of `scene`: every property of every ellipsoid and plane, the
    /// light's, the media's, its tiers' and its shot camera's.
    pub fn all(scene: &Scene) -> impl Iterator<Item = Channel> + '_ {
        use EllipsoidProperty as E;
        // A moving ellipsoid's centre and radii are its motion's, not keys'.
        let ellipsoids = scene.ellipsoids.iter().flat_map(|e| {
            [E::Center, E::Radii, E::Rotation, E::Strength, E::Visible]
                .into_iter()
                .filter(|p| e.motion.is_none() || !matches!(p, E::Center | E::Radii))
                .map(|property| Channel::Ellipsoid { id: e.id, property })
        });
        // A cut's line has no inflation, blend or billows.
        let planes = scene.planes.iter().flat_map(|p| {
            let outline = p.kind == super::StrokeKind::Outline;
            PLANE
                .into_iter()
                .filter(move |property| {
                    outline || matches!(property, PlaneProperty::Origin | PlaneProperty::Rotation)
                })
                .map(|property| Channel::Plane { id: p.id, property })
        });
        let shot = scene
            .shot
            .is_some()
            .then_some(SHOT.map(|property| Channel::Shot { property }))
            .into_iter()
            .flatten();
        let tiers = (0..scene.render.tiers.len().min(limits::MAX_TIERS) as u32)
            .flat_map(|tier| TIER.map(|property| Channel::Tier { tier, property }));
        ellipsoids
            .chain(planes)
            .chain(LIGHT.map(|property| Channel::Light { property }))
            .chain(MEDIA.map(|property| Channel::Media { property }))
            .chain(tiers)
            .chain(shot)
    }
}

/// Where each ellipsoid and plane id stands in a scene's lists: finding a track's item once
/// per track, not once per track and item.
struct Index {
    ellipsoids: std::collections::HashMap<u64, usize>,
    planes: std::collections::HashMap<u64, usize>,
}

impl Index {
    fn of(scene: &Scene) -> Self {
        Self {
            ellipsoids: scene
                .ellipsoids
                .iter()
                .enumerate()
                .map(|(i, e)| (e.id, i))
                .collect(),
            planes: scene
                .planes
                .iter()
                .enumerate()
                .map(|(i, p)| (p.id, i))
                .collect(),
        }
    }

    fn ellipsoid(index: Option<&Index>, scene: &Scene, id: u64) -> Option<usize> {
        match index {
            Some(ix) => ix.ellipsoids.get(&id).copied(),
            None => scene.ellipsoids.iter().position(|e| e.id == id),
        }
    }

    fn plane(index: Option<&Index>, scene: &Scene, id: u64) -> Option<usize> {
        match index {
            Some(ix) => ix.planes.get(&id).copied(),
            None => scene.planes.iter().position(|p| p.id == id),
        }
    }
}

/// The light's keyable properties.
pub const LIGHT: [LightProperty; 9] = [
    LightProperty::SunAzimuth,
    LightProperty::SunElevation,
    LightProperty::SunIntensity,
    LightProperty::SunColor,
    LightProperty::Ambient,
    LightProperty::Exposure,
    LightProperty::SkyColor,
    LightProperty::HorizonColor,
    LightProperty::Background,
];

/// The media's keyable properties.
pub const MEDIA: [MediaProperty; 8] = [
    MediaProperty::Opacity,
    MediaProperty::NoiseAmount,
    MediaProperty::Detail,
    MediaProperty::NoiseScale,
    MediaProperty::Sharpness,
    MediaProperty::Dirtiness,
    MediaProperty::Wind,
    MediaProperty::Torque,
];

/// One key: a value at a time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Key {
    /// Scene time in seconds.
    pub t: f32,
    /// The value ([`Channel::width`] numbers).
    #[serde(rename = "v", deserialize_with = "capped::vec::<_, _, 4>")]
    pub value: Vec<f32>,
    /// How the value goes on to the next key's.
    #[serde(default, skip_serializing_if = "Ease::is_linear")]
    pub ease: Ease,
}

/// The keys of one channel, in time order, at most one a time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Track {
    /// What it keys.
    pub channel: Channel,
    /// Its keys, ascending in time.
    #[serde(deserialize_with = "capped::vec::<_, _, MAX_KEYS>")]
    pub keys: Vec<Key>,
}

impl Track {
    /// The track's value at time `t`: a key's own value at its time, the first key's before
    /// it, the last's after it, and between two keys the first one's ease of the way.
    pub fn sample(&self, t: f32) -> Option<Vec<f32>> {
        let keys = &self.keys;
        let first = keys.first()?;
        let after = keys.partition_point(|k| k.t <= t);
        if after == 0 {
            return Some(first.value.clone());
        }
        let a = &keys[after - 1];
        let Some(b) = keys.get(after) else {
            return Some(a.value.clone());
        };
        if a.t == t {
            return Some(a.value.clone());
        }
        let ease = if self.channel.kind() == Kind::Step {
            Ease::Constant
        } else {
            a.ease
        };
        let u = ease.apply((t - a.t) / (b.t - a.t));
        Some(interpolate(self.channel.kind(), &a.value, &b.value, u))
    }

    /// The integral of the track's value from time 0 to `t` (per component; the value before
    /// the first key is the first's, after the last the last's): how far a keyed wind has
    /// carried the noise by `t`. Exact for every ease. `None` without keys.
    pub fn integral(&self, t: f32) -> Option<Vec<f32>> {
        let keys = &self.keys;
        let first = keys.first()?;
        let t = t.max(0.0) as f64;
        let mut sum: Vec<f64> = vec![0.0; first.value.len()];
        let add = |sum: &mut Vec<f64>, v: &[f32], dt: f64| {
            for (s, v) in sum.iter_mut().zip(v) {
                *s += *v as f64 * dt;
            }
        };
        add(&mut sum, &first.value, t.min(first.t as f64));
        for pair in keys.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            let (t0, t1) = (a.t as f64, b.t as f64);
            if t <= t0 {
                break;
            }
            let span = t1 - t0;
            let u = ((t.min(t1) - t0) / span).clamp(0.0, 1.0);
            // ∫₀ᵘ ease: the area under the share of the way to the next key.
            let area = match a.ease {
                Ease::Linear => u * u / 2.0,
                Ease::EaseInOut => u * u * u - u * u * u * u / 2.0,
                Ease::Constant => 0.0,
            };
            for ((s, va), vb) in sum.iter_mut().zip(&a.value).zip(&b.value) {
                *s += *va as f64 * u * span + (*vb as f64 - *va as f64) * area * span;
            }
        }
        let last = keys.last()?;
        if t > last.t as f64 {
            add(&mut sum, &last.value, t - last.t as f64);
        }
        Some(sum.into_iter().map(|v| v as f32).collect())
    }

    /// The key at exactly `t`, if any.
    pub fn key_at(&self, t: f32) -> Option<&Key> {
        self.keys.iter().find(|k| k.t == t)
    }

    /// Sets the key at `t` to `value` (a new key keeps the ease of the key before it).
    fn put(&mut self, t: f32, value: Vec<f32>) {
        let i = self.keys.partition_point(|k| k.t < t);
        match self.keys.get_mut(i) {
            Some(k) if k.t == t => k.value = value,
            _ => {
                let ease = i
                    .checked_sub(1)
                    .map_or(Ease::default(), |j| self.keys[j].ease);
                self.keys.insert(i, Key { t, value, ease });
            }
        }
    }
}

fn interpolate(kind: Kind, a: &[f32], b: &[f32], u: f32) -> Vec<f32> {
    match kind {
        Kind::Step => a.to_vec(),
        Kind::Rotation => {
            let (qa, qb) = (Quat::from_slice(a), Quat::from_slice(b));
            // Quat::slerp takes the short way (it flips b when the dot is negative).
            qa.slerp(qb, u).normalize().to_array().to_vec()
        }
        Kind::Angle => {
            let d = (b[0] - a[0] + 180.0).rem_euclid(360.0) - 180.0;
            vec![(a[0] + d * u).rem_euclid(360.0)]
        }
        Kind::Plain => a
            .iter()
            .zip(b)
            .map(|(a, b)| (*a as f64 * (1.0 - u as f64) + *b as f64 * u as f64) as f32)
            .collect(),
    }
}

/// Every track of a document. Tracks are shared (`Arc`), so an undo step holds one copy of
/// the keys it did not change.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Animation {
    /// The tracks, at most one a channel.
    #[serde(deserialize_with = "capped::vec::<_, _, MAX_TRACKS>")]
    pub tracks: Vec<Arc<Track>>,
}

impl Animation {
    /// No keys at all (a document leaves it out then).
    pub fn is_empty(&self) -> bool {
        self.tracks.is_empty()
    }

    /// The track of `channel`, if it has one.
    pub fn track(&self, channel: Channel) -> Option<&Track> {
        self.tracks
            .iter()
            .find(|t| t.channel == channel)
            .map(|t| &**t)
    }

    /// Number of keys in all tracks.
    pub fn key_count(&self) -> usize {
        self.tracks.iter().map(|t| t.keys.len()).sum()
    }

    /// Keys `channel` at `t` with `value` (replacing a key at that very time). Returns
    /// whether a key was added or changed; a track already at [`MAX_KEYS`] takes no new one,
    /// nor a document at [`MAX_TRACKS`] a new track.
    pub fn key(&mut self, channel: Channel, t: f32, value: Vec<f32>) -> bool {
        let mut index = None;
        self.key_in(&mut index, channel, t, value)
    }

    /// [`Animation::key`], finding the track through `index` (built on first use, kept up to
    /// date): keying thousands of values is not a search of every track for each.
    fn key_in(
        &mut self,
        index: &mut Option<HashMap<Channel, usize>>,
        channel: Channel,
        t: f32,
        value: Vec<f32>,
    ) -> bool {
        let Some(value) = channel.repaired(&value) else {
            return false;
        };
        // A time that is no number keys nothing (not a key thrown to 0 s).
        if !t.is_finite() {
            return false;
        }
        let t = clamp_time(t);
        let at = match index {
            Some(ix) => ix.get(&channel).copied(),
            None if self.tracks.len() > 16 => {
                let ix: HashMap<Channel, usize> = self
                    .tracks
                    .iter()
                    .enumerate()
                    .map(|(i, tr)| (tr.channel, i))
                    .collect();
                let at = ix.get(&channel).copied();
                *index = Some(ix);
                at
            }
            None => self.tracks.iter().position(|tr| tr.channel == channel),
        };
        match at.map(|i| &mut self.tracks[i]) {
            Some(track) => {
                if track.key_at(t).is_some_and(|k| k.value == value) {
                    return false;
                }
                if track.key_at(t).is_none() && track.keys.len() >= MAX_KEYS {
                    return false;
                }
                Arc::make_mut(track).put(t, value);
            }
            None => {
                if self.tracks.len() >= MAX_TRACKS {
                    return false;
                }
                if let Some(ix) = index {
                    ix.insert(channel, self.tracks.len());
                }
                self.tracks.push(Arc::new(Track {
                    channel,
                    keys: vec![Key {
                        t,
                        value,
                        ease: Ease::default(),
                    }],
                }));
            }
        }
        true
    }

    /// Keys each of `channels` at `t` with its value in `scene`; returns how many keys were
    /// added or changed.
    pub fn key_all(
        &mut self,
        scene: &Scene,
        channels: impl IntoIterator<Item = Channel>,
        t: f32,
    ) -> usize {
        let items = Index::of(scene);
        let mut index = None;
        channels
            .into_iter()
            .filter_map(|c| Some((c, c.get_in(scene, Some(&items))?)))
            .filter(|(c, v)| self.key_in(&mut index, *c, t, v.clone()))
            .count()
    }

    /// Records every keyable value that differs between `before` and `after` as a key at `t`
    /// (auto-key); an item new in `after` is not keyed until it is changed. Returns how many
    /// keys it set.
    pub fn record_changes(&mut self, before: &Scene, after: &Scene, t: f32) -> usize {
        let (was, is) = (Index::of(before), Index::of(after));
        let same_e = |id: u64| match (was.ellipsoids.get(&id), is.ellipsoids.get(&id)) {
            (Some(&a), Some(&b)) => Arc::ptr_eq(&before.ellipsoids[a], &after.ellipsoids[b]),
            _ => true,
        };
        let same_p = |id: u64| match (was.planes.get(&id), is.planes.get(&id)) {
            (Some(&a), Some(&b)) => Arc::ptr_eq(&before.planes[a], &after.planes[b]),
            _ => true,
        };
        let changed: Vec<(Channel, Vec<f32>)> = Channel::all(after)
            .filter(|c| match *c {
                Channel::Ellipsoid { id, .. } => !same_e(id),
                Channel::Plane { id, .. } => !same_p(id),
                _ => true,
            })
            .filter_map(|c| {
                let old = c.get_in(before, Some(&was))?;
                let new = c.get_in(after, Some(&is))?;
                (old != new).then_some((c, new))
            })
            .collect();
        let mut index = None;
        changed
            .into_iter()
            .filter(|(c, v)| self.key_in(&mut index, *c, t, v.clone()))
            .count()
    }

    /// The times of the keys of `channels` (or of every channel with `None`), ascending and
    /// each once.
    pub fn times(&self, channels: Option<&[Channel]>) -> Vec<f32> {
        let channels: Option<HashSet<Channel>> = channels.map(|c| c.iter().copied().collect());
        let mut times: Vec<f32> = self
            .tracks
            .iter()
            .filter(|t| channels.as_ref().is_none_or(|c| c.contains(&t.channel)))
            .flat_map(|t| t.keys.iter().map(|k| k.t))
            .collect();
        times.sort_by(f32::total_cmp);
        times.dedup();
        times
    }

    /// Moves the keys of `channels` at time `from` to time `to` (a key already at `to` is
    /// replaced). Returns whether any moved.
    pub fn retime(&mut self, channels: &[Channel], from: f32, to: f32) -> bool {
        if !to.is_finite() {
            return false;
        }
        let to = clamp_time(to);
        if from == to {
            return false;
        }
        let channels: HashSet<Channel> = channels.iter().copied().collect();
        let mut moved = false;
        for track in &mut self.tracks {
            if !channels.contains(&track.channel) || track.key_at(from).is_none() {
                continue;
            }
            let track = Arc::make_mut(track);
            let i = track.keys.iter().position(|k| k.t == from).unwrap_or(0);
            let key = track.keys.remove(i);
            track.keys.retain(|k| k.t != to);
            let j = track.keys.partition_point(|k| k.t < to);
            track.keys.insert(j, Key { t: to, ..key });
            moved = true;
        }
        moved
    }

    /// Removes the keys of `channels` at time `t` (and tracks left without keys). Returns how
    /// many keys went.
    pub fn remove_at(&mut self, channels: &[Channel], t: f32) -> usize {
        let channels: HashSet<Channel> = channels.iter().copied().collect();
        let mut removed = 0;
        for track in &mut self.tracks {
            if channels.contains(&track.channel) && track.key_at(t).is_some() {
                Arc::make_mut(track).keys.retain(|k| k.t != t);
                removed += 1;
            }
        }
        self.tracks.retain(|t| !t.keys.is_empty());
        removed
    }

    /// Sets the ease of the keys of `channels` at time `t`. Returns whether any changed.
    pub fn set_ease(&mut self, channels: &[Channel], t: f32, ease: Ease) -> bool {
        let channels: HashSet<Channel> = channels.iter().copied().collect();
        let mut changed = false;
        for track in &mut self.tracks {
            if channels.contains(&track.channel) && track.key_at(t).is_some_and(|k| k.ease != ease)
            {
                let track = Arc::make_mut(track);
                if let Some(k) = track.keys.iter_mut().find(|k| k.t == t) {
                    k.ease = ease;
                    changed = true;
                }
            }
        }
        changed
    }

    /// The channels whose tracks differ between `self` and `other` (added, removed or with
    /// other keys; tracks compared by pointer first).
    pub fn changed_channels(&self, other: &Animation) -> HashSet<Channel> {
        let mine: HashMap<Channel, &Arc<Track>> =
            self.tracks.iter().map(|t| (t.channel, t)).collect();
        let theirs: HashMap<Channel, &Arc<Track>> =
            other.tracks.iter().map(|t| (t.channel, t)).collect();
        let mut out = HashSet::new();
        for (c, a) in &mine {
            match theirs.get(c) {
                Some(b) if Arc::ptr_eq(a, b) || a == b => {}
                _ => {
                    out.insert(*c);
                }
            }
        }
        out.extend(theirs.keys().filter(|c| !mine.contains_key(c)));
        out
    }

    /// Whether the tracks are the same ones (by pointer first, then by value).
    pub fn same_as(&self, other: &Animation) -> bool {
        self.tracks.len() == other.tracks.len()
            && self
                .tracks
                .iter()
                .zip(&other.tracks)
                .all(|(a, b)| Arc::ptr_eq(a, b) || a == b)
    }

    /// Drops the tracks of ellipsoids and planes `scene` no longer has (deleting an item
    /// deletes its keys). Returns how many went.
    pub fn forget_missing(&mut self, scene: &Scene) -> usize {
        if self.tracks.is_empty() {
            return 0;
        }
        let index = Index::of(scene);
        let before = self.tracks.len();
        self.tracks
            .retain(|t| t.channel.get_in(scene, Some(&index)).is_some());
        before - self.tracks.len()
    }

    /// Tier `removed` went: its keys go with it and the keys of the tiers above it move down
    /// one place, as the tiers did. Returns whether any track changed.
    pub fn tier_removed(&mut self, removed: usize) -> bool {
        let before = self.tracks.len();
        self.tracks.retain(
            |t| !matches!(t.channel, Channel::Tier { tier, .. } if tier as usize == removed),
        );
        let mut changed = self.tracks.len() != before;
        for track in &mut self.tracks {
            if let Channel::Tier { tier, property } = track.channel
                && tier as usize > removed
            {
                Arc::make_mut(track).channel = Channel::Tier {
                    tier: tier - 1,
                    property,
                };
                changed = true;
            }
        }
        changed
    }

    /// Repairs what a file or a link may hold, saying what it changed: keys whose value cannot
    /// be held are dropped, values brought within range, times that are not finite dropped
    /// and others brought within [0, [`limits::MAX_TIME`]], keys sorted, one key a time (the
    /// last), one track a channel (the first), tracks on items the scene does not have or
    /// left without keys dropped.
    pub fn repair(&mut self, scene: &Scene) -> Vec<String> {
        let mut said = Vec::new();
        let index = Index::of(scene);
        let mut seen = std::collections::HashSet::new();
        let mut kept = Vec::with_capacity(self.tracks.len());
        for (i, track) in std::mem::take(&mut self.tracks).into_iter().enumerate() {
            let path = format!("animation[{i}]");
            let channel = track.channel;
            if channel.get_in(scene, Some(&index)).is_none() {
                said.push(format!(
                    "{path}: keys on {} dropped: the scene has no such item",
                    channel.describe()
                ));
                continue;
            }
            if !seen.insert(channel) {
                said.push(format!(
                    "{path}: a second track on {} dropped",
                    channel.describe()
                ));
                continue;
            }
            let mut keys: Vec<Key> = Vec::with_capacity(track.keys.len());
            let (mut dropped, mut moved) = (0, 0);
            for key in &track.keys {
                let Some(value) = channel.repaired(&key.value) else {
                    dropped += 1;
                    continue;
                };
                if !key.t.is_finite() {
                    dropped += 1;
                    continue;
                }
                let t = clamp_time(key.t);
                if t != key.t || value != key.value {
                    moved += 1;
                }
                keys.push(Key {
                    t,
                    value,
                    ease: key.ease,
                });
            }
            let sorted = keys.is_sorted_by(|a, b| a.t < b.t);
            if !sorted {
                // Stable, so of keys at one time the last read is last.
                keys.sort_by(|a, b| a.t.total_cmp(&b.t));
                let n = keys.len();
                keys.reverse();
                keys.dedup_by(|later, earlier| later.t == earlier.t);
                keys.reverse();
                said.push(format!(
                    "{path}: keys on {} put in time order{}",
                    channel.describe(),
                    if keys.len() < n {
                        format!(", {} at a time already keyed dropped", n - keys.len())
                    } else {
                        String::new()
                    }
                ));
            }
            if dropped > 0 {
                said.push(format!(
                    "{path}: {dropped} keys on {} dropped (values that are not {} numbers within \
                     ±1e6, or times that are not finite)",
                    channel.describe(),
                    channel.width()
                ));
            }
            if moved > 0 {
                said.push(format!(
                    "{path}: {moved} keys on {} brought within range",
                    channel.describe()
                ));
            }
            if keys.is_empty() {
                continue;
            }
            kept.push(if *track.keys == *keys {
                track
            } else {
                Arc::new(Track { channel, keys })
            });
        }
        self.tracks = kept;
        said
    }
}

/// `value` as a unit quaternion, or `None` where it has no direction.
fn unit_quaternion(value: &[f32]) -> Option<Vec<f32>> {
    let q = Quat::from_slice(value);
    (q.length_squared() > 1e-12).then(|| q.normalize().to_array().to_vec())
}

fn clamp_time(t: f32) -> f32 {
    if t.is_finite() {
        t.clamp(0.0, limits::MAX_TIME)
    } else {
        0.0
    }
}

impl Scene {
    /// Poses every keyed value at time `t` in place (the scene's time is left as it is);
    /// unkeyed values and every item whose keyed values are already there stay as they are
    /// (shared). Returns whether anything changed.
    pub fn pose(&mut self, t: f32) -> bool {
        // Keys first, then the motion, which sets a moving ellipsoid's centre and radii. A time
        // that is no number poses as 0 s, as the clock takes it.
        let t = clamp_time(t);
        self.pose_where(t, |_| true) | self.pose_motion(t)
    }

    /// [`Scene::pose`] of `channels` alone (a key edit poses what it changed and leaves an
    /// unkeyed edit of another value as it is). Returns whether anything changed.
    pub fn pose_channels(&mut self, t: f32, channels: &HashSet<Channel>) -> bool {
        !channels.is_empty() && self.pose_where(clamp_time(t), |c| channels.contains(&c))
    }

    /// Poses the tracks whose channel `which` takes.
    fn pose_where(&mut self, t: f32, which: impl Fn(Channel) -> bool) -> bool {
        if self.animation.is_empty() {
            return false;
        }
        let animation = std::mem::take(&mut self.animation);
        let index = Index::of(self);
        let mut changed = false;
        for track in animation.tracks.iter().filter(|tr| which(tr.channel)) {
            if let Some(value) = track.sample(t) {
                changed |= track.channel.set(self, &index, &value);
            }
        }
        self.animation = animation;
        changed
    }

    /// Those of `channels` a key at the scene's time would change: a keyed value that differs
    /// from what its keys pose there (Blender's "only insert needed"), and every value without
    /// keys, which nothing poses. The keyed ones are posed once, through their own setters, so
    /// a value they wrap (a yaw) or normalise (a rotation) compares as it is held.
    pub fn changed_from_keys(&self, channels: &[Channel]) -> Vec<Channel> {
        let keyed: HashSet<Channel> = channels
            .iter()
            .copied()
            .filter(|c| self.animation.track(*c).is_some())
            .collect();
        let mut posed = self.clone();
        posed.pose_channels(self.time, &keyed);
        let (ours, theirs) = (Index::of(self), Index::of(&posed));
        channels
            .iter()
            .copied()
            .filter(|c| {
                if !keyed.contains(c) {
                    return true;
                }
                match (c.get_in(&posed, Some(&theirs)), c.get_in(self, Some(&ours))) {
                    (Some(a), Some(b)) => {
                        a.len() != b.len()
                            || a.iter()
                                .zip(&b)
                                .any(|(x, y)| (x - y).abs() > 1e-6 * x.abs().max(y.abs()).max(1.0))
                    }
                    _ => true,
                }
            })
            .collect()
    }

    /// The scene at time `t`: its clock set to `t` and every keyed value posed there. The one
    /// pure call the app, the renderer, the exporters and the command line take a time
    /// through.
    pub fn posed_at(&self, t: f32) -> Scene {
        let mut scene = self.clone();
        scene.time = clamp_time(t);
        let t = scene.time;
        scene.pose(t);
        scene
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Ellipsoid, Preset};

    fn track(channel: Channel, keys: &[(f32, &[f32], Ease)]) -> Track {
        Track {
            channel,
            keys: keys
                .iter()
                .map(|(t, v, ease)| Key {
                    t: *t,
                    value: v.to_vec(),
                    ease: *ease,
                })
                .collect(),
        }
    }

    const STRENGTH: Channel = Channel::Ellipsoid {
        id: 1,
        property: EllipsoidProperty::Strength,
    };

    #[test]
    fn each_ease_at_and_between_keys_matches_hand_computed_values() {
        for (ease, at_quarter, at_half) in [
            (Ease::Linear, 1.5, 2.0),
            // Smoothstep: 3u² − 2u³ at 0.25 is 0.15625, at 0.5 is 0.5.
            (Ease::EaseInOut, 1.3125, 2.0),
            (Ease::Constant, 1.0, 1.0),
        ] {
            let tr = track(
                STRENGTH,
                &[(2.0, &[1.0], ease), (4.0, &[3.0], Ease::Linear)],
            );
            assert_eq!(tr.sample(2.0), Some(vec![1.0]), "{ease:?} at its key");
            assert_eq!(tr.sample(4.0), Some(vec![3.0]), "{ease:?} at the next key");
            assert_eq!(tr.sample(2.5), Some(vec![at_quarter]), "{ease:?} a quarter");
            assert_eq!(tr.sample(3.0), Some(vec![at_half]), "{ease:?} half way");
            // Before the first key and after the last: the ends' values.
            assert_eq!(tr.sample(0.0), Some(vec![1.0]));
            assert_eq!(tr.sample(100.0), Some(vec![3.0]));
        }
    }

    #[test]
    fn keys_at_the_ends_of_time_hold_their_values() {
        let tr = track(
            STRENGTH,
            &[
                (0.0, &[2.0], Ease::Linear),
                (limits::MAX_TIME, &[4.0], Ease::Linear),
            ],
        );
        assert_eq!(tr.sample(0.0), Some(vec![2.0]));
        assert_eq!(tr.sample(limits::MAX_TIME), Some(vec![4.0]));
        assert_eq!(tr.sample(limits::MAX_TIME / 2.0), Some(vec![3.0]));
    }

    #[test]
    fn azimuth_and_rotation_take_the_short_way() {
        let az = Channel::Light {
            property: LightProperty::SunAzimuth,
        };
        let tr = track(
            az,
            &[
                (0.0, &[170.0], Ease::Linear),
                (1.0, &[-170.0], Ease::Linear),
            ],
        );
        // 170 → 190 (−170), through 180, not back through 0.
        assert!((tr.sample(0.5).unwrap()[0] - 180.0).abs() < 1e-3);
        let rot = Channel::Ellipsoid {
            id: 1,
            property: EllipsoidProperty::Rotation,
        };
        let a = Quat::from_rotation_y(170f32.to_radians());
        let b = Quat::from_rotation_y(-170f32.to_radians());
        let tr = track(
            rot,
            &[
                (0.0, &a.to_array(), Ease::Linear),
                (1.0, &b.to_array(), Ease::Linear),
            ],
        );
        let mid = Quat::from_slice(&tr.sample(0.5).unwrap());
        let want = Quat::from_rotation_y(180f32.to_radians());
        assert!(mid.dot(want).abs() > 0.9999, "{mid:?}");
    }

    #[test]
    fn visibility_holds_to_the_next_key_whatever_its_ease() {
        let vis = Channel::Ellipsoid {
            id: 1,
            property: EllipsoidProperty::Visible,
        };
        let tr = track(
            vis,
            &[(0.0, &[1.0], Ease::Linear), (1.0, &[0.0], Ease::Linear)],
        );
        assert_eq!(tr.sample(0.99), Some(vec![1.0]));
        assert_eq!(tr.sample(1.0), Some(vec![0.0]));
    }

    fn one_ellipsoid() -> Scene {
        let mut scene = Scene::preset(Preset::Empty);
        scene
            .ellipsoids
            .push(Arc::new(Ellipsoid::new(Vec3::ZERO, Vec3::ONE)));
        scene.settle();
        scene
    }

    #[test]
    fn retiming_keeps_the_values_and_posing_follows_the_keys() {
        let mut scene = one_ellipsoid();
        let id = scene.ellipsoids[0].id;
        let center = Channel::Ellipsoid {
            id,
            property: EllipsoidProperty::Center,
        };
        let mut anim = Animation::default();
        assert!(anim.key(center, 0.0, vec![0.0, 0.0, 0.0]));
        assert!(anim.key(center, 2.0, vec![4.0, 0.0, 0.0]));
        scene.animation = anim.clone();
        assert_eq!(
            scene.posed_at(1.0).ellipsoids[0].center,
            Vec3::new(2.0, 0.0, 0.0)
        );
        assert!(anim.retime(&[center], 2.0, 4.0));
        assert_eq!(
            anim.track(center).unwrap().keys[1].value,
            vec![4.0, 0.0, 0.0]
        );
        scene.animation = anim;
        assert_eq!(
            scene.posed_at(1.0).ellipsoids[0].center,
            Vec3::new(1.0, 0.0, 0.0)
        );
        assert_eq!(
            scene.posed_at(4.0).ellipsoids[0].center,
            Vec3::new(4.0, 0.0, 0.0)
        );
        // A pose leaves unkeyed items shared and changes nothing where the keys already are.
        let at_four = scene.posed_at(4.0);
        let mut again = at_four.clone();
        assert!(!again.pose(4.0));
        assert!(Arc::ptr_eq(&again.ellipsoids[0], &at_four.ellipsoids[0]));
    }

    #[test]
    fn recording_keys_only_what_changed() {
        let before = one_ellipsoid();
        let mut after = before.clone();
        Arc::make_mut(&mut after.ellipsoids[0]).center = Vec3::X;
        after.light.sun_elevation_deg = 10.0;
        let mut anim = Animation::default();
        assert_eq!(anim.record_changes(&before, &after, 1.5), 2);
        let channels: Vec<Channel> = anim.tracks.iter().map(|t| t.channel).collect();
        assert!(channels.contains(&Channel::Ellipsoid {
            id: before.ellipsoids[0].id,
            property: EllipsoidProperty::Center
        }));
        assert!(channels.contains(&Channel::Light {
            property: LightProperty::SunElevation
        }));
    }

    #[test]
    fn the_skys_horizons_and_backgrounds_colours_key_pose_and_record_like_the_suns() {
        use crate::scene::{Document, Edit};
        let mut doc = Document::new(one_ellipsoid());
        let mut anim = Animation::default();
        for (property, at_0, at_2) in [
            (LightProperty::SkyColor, [0.2, 0.4, 0.8], [0.8, 0.4, 0.2]),
            (
                LightProperty::HorizonColor,
                [1.0, 1.0, 1.0],
                [0.0, 0.5, 1.0],
            ),
            (LightProperty::Background, [0.0, 0.0, 0.0], [0.5, 1.0, 0.25]),
        ] {
            let channel = Channel::Light { property };
            assert_eq!(channel.width(), 3);
            assert!(anim.key(channel, 0.0, at_0.to_vec()));
            assert!(anim.key(channel, 2.0, at_2.to_vec()));
            // Out of range, a colour is brought within [0, 1], as the picker's.
            assert!(anim.key(channel, 4.0, vec![2.0, -1.0, 0.5]));
            assert_eq!(
                anim.track(channel).unwrap().keys[2].value,
                vec![1.0, 0.0, 0.5]
            );
        }
        doc.apply(Edit::SetAnimation(anim, "insert keys"), None);
        let light = doc.revisions().light;
        doc.set_time(1.0);
        assert!(doc.revisions().light > light, "the pose changed the light");
        let l = &doc.scene().light;
        assert_eq!(l.sky_color, [0.5, 0.4, 0.5]);
        assert_eq!(l.horizon_color, [0.5, 0.75, 1.0]);
        assert_eq!(l.background, [0.25, 0.5, 0.125]);
        // Auto-key records an edit of one: a picked background at 3 s is a key there, and
        // the other two colours are left as they are.
        let mut edited = doc.scene().clone();
        edited.light.background = [0.9, 0.1, 0.1];
        let mut anim = doc.scene().animation.clone();
        assert_eq!(anim.record_changes(doc.scene(), &edited, 3.0), 1);
        let background = Channel::Light {
            property: LightProperty::Background,
        };
        assert_eq!(
            anim.track(background).unwrap().key_at(3.0).unwrap().value,
            vec![0.9, 0.1, 0.1]
        );
        assert_eq!(anim.tracks.iter().map(|t| t.keys.len()).sum::<usize>(), 10);
    }

    #[test]
    fn times_that_are_not_numbers_key_nothing_move_nothing_and_pose_as_zero() {
        let mut scene = one_ellipsoid();
        let id = scene.ellipsoids[0].id;
        let strength = Channel::Ellipsoid {
            id,
            property: EllipsoidProperty::Strength,
        };
        let mut anim = Animation::default();
        assert!(anim.key(strength, 1.0, vec![0.25]));
        assert!(anim.key(strength, 3.0, vec![0.75]));
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            // No key at 0 s (nor at the cap) from a time that is no number...
            assert!(!anim.key(strength, bad, vec![0.5]), "{bad}");
            // ...nor a key dragged there.
            assert!(!anim.retime(&[strength], 3.0, bad), "{bad}");
            assert_eq!(anim.remove_at(&[strength], bad), 0, "{bad}");
        }
        assert_eq!(
            anim.tracks[0]
                .keys
                .iter()
                .map(|k| (k.t, k.value[0]))
                .collect::<Vec<_>>(),
            vec![(1.0, 0.25), (3.0, 0.75)]
        );
        // A document's keys at such times (a damaged file or link) are dropped, with a message.
        let mut damaged = anim.clone();
        let track = Arc::make_mut(&mut damaged.tracks[0]);
        track.keys.insert(
            0,
            Key {
                t: f32::NEG_INFINITY,
                value: vec![1.0],
                ease: Ease::default(),
            },
        );
        track.keys.push(Key {
            t: f32::NAN,
            value: vec![1.0],
            ease: Ease::default(),
        });
        let said = damaged.repair(&scene).join("\n");
        assert!(
            said.contains("2 keys") && said.contains("not finite"),
            "{said}"
        );
        assert_eq!(damaged, anim);
        // Posed at such a time, the scene is as at 0 s, every value a number.
        scene.animation = anim;
        let at_zero = scene.posed_at(0.0);
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let posed = scene.posed_at(bad);
            assert_eq!(posed.time, 0.0);
            assert_eq!(posed.ellipsoids[0].strength, at_zero.ellipsoids[0].strength);
            let mut in_place = scene.clone();
            in_place.pose(bad);
            assert_eq!(in_place.ellipsoids[0].strength, 0.25, "{bad}");
        }
    }

    #[test]
    fn bad_keys_are_repaired_with_a_message_naming_the_path() {
        let scene = one_ellipsoid();
        let id = scene.ellipsoids[0].id;
        let json = format!(
            r#"[
              {{"channel": {{"item": "ellipsoid", "id": {id}, "property": "strength"}},
                "keys": [{{"t": 5, "v": [2]}}, {{"t": -3, "v": [1]}}, {{"t": 5, "v": [3]}},
                         {{"t": 1, "v": [1, 2]}}]}},
              {{"channel": {{"item": "ellipsoid", "id": 999, "property": "center"}},
                "keys": [{{"t": 0, "v": [0, 0, 0]}}]}},
              {{"channel": {{"item": "light", "property": "sun_elevation"}},
                "keys": [{{"t": 0, "v": [500]}}]}}
            ]"#
        );
        let mut anim: Animation = serde_json::from_str(&json).unwrap();
        let said = anim.repair(&scene);
        let text = said.join("\n");
        assert!(
            text.contains("animation[1]") && text.contains("no such item"),
            "{text}"
        );
        assert!(
            text.contains("animation[0]") && text.contains("time order"),
            "{text}"
        );
        assert!(
            text.contains("1 keys") && text.contains("dropped"),
            "{text}"
        );
        assert_eq!(anim.tracks.len(), 2);
        let keys = &anim.tracks[0].keys;
        // −3 → 0, sorted, the later of the two keys at 5 kept.
        assert_eq!(
            keys.iter().map(|k| (k.t, k.value[0])).collect::<Vec<_>>(),
            vec![(0.0, 1.0), (5.0, 3.0)]
        );
        assert_eq!(
            anim.tracks[1].keys[0].value[0] as f64,
            limits::SUN_ELEVATION.max
        );
    }

    #[test]
    fn a_planes_outline_controls_key_within_their_ranges_and_a_cut_has_none() {
        let mut scene = Scene::preset(crate::scene::Preset::Empty);
        for kind in [
            super::super::StrokeKind::Outline,
            super::super::StrokeKind::Cut,
        ] {
            scene.planes.push(Arc::new(super::super::DrawingPlane {
                kind,
                ..Default::default()
            }));
        }
        scene.settle();
        let (outline, cut) = (scene.planes[0].id, scene.planes[1].id);
        let of = |id| Channel::all(&scene).filter(|c| c.id() == Some(id)).count();
        assert_eq!((of(outline), of(cut)), (5, 2));
        let json = format!(
            r#"[
              {{"channel": {{"item": "plane", "id": {outline}, "property": "inflation"}},
                "keys": [{{"t": 0, "v": [7]}}, {{"t": 1, "v": [0.5]}}]}},
              {{"channel": {{"item": "plane", "id": {outline}, "property": "billows"}},
                "keys": [{{"t": 0, "v": [-1, 3]}}]}},
              {{"channel": {{"item": "plane", "id": {cut}, "property": "blend"}},
                "keys": [{{"t": 0, "v": [0.2]}}]}}
            ]"#
        );
        let mut anim: Animation = serde_json::from_str(&json).unwrap();
        let said = anim.repair(&scene).join("\n");
        assert!(said.contains("animation[2]"), "{said}");
        assert_eq!(anim.tracks.len(), 2);
        assert_eq!(
            anim.tracks[0].keys[0].value,
            vec![limits::INFLATE.max as f32]
        );
        assert_eq!(
            anim.tracks[1].keys[0].value,
            vec![
                limits::BILLOW_RATIO.min as f32,
                limits::BILLOW_COVERAGE.max as f32
            ]
        );
        // Posed halfway, the plane's inflation is between its keys.
        scene.animation = anim;
        let posed = scene.posed_at(0.5);
        let t = posed.planes[0].sketch.inflate;
        assert!(t > 0.5 && t < limits::INFLATE.max, "{t}");
    }

    #[test]
    fn a_track_is_capped() {
        let mut anim = Animation::default();
        for i in 0..MAX_KEYS + 10 {
            anim.key(STRENGTH, i as f32, vec![1.0]);
        }
        assert_eq!(anim.key_count(), MAX_KEYS);
        let json = serde_json::to_string(&anim).unwrap();
        let mut too_many: serde_json::Value = serde_json::from_str(&json).unwrap();
        let keys = too_many[0]["keys"].as_array_mut().unwrap();
        keys.push(keys[0].clone());
        assert!(serde_json::from_value::<Animation>(too_many).is_err());
    }

    #[test]
    fn an_unkeyed_edit_shows_until_the_time_moves_and_auto_key_keeps_it() {
        use crate::scene::{Document, Edit};
        let mut doc = Document::new(one_ellipsoid());
        let id = doc.scene().ellipsoids[0].id;
        let center = Channel::Ellipsoid {
            id,
            property: EllipsoidProperty::Center,
        };
        let moved = |doc: &Document, to: Vec3| {
            let mut e = (*doc.scene().ellipsoids[0]).clone();
            e.center = to;
            Edit::SetEllipsoids(vec![Arc::new(e)])
        };
        let insert = |doc: &mut Document| {
            let mut a = doc.scene().animation.clone();
            a.key(center, doc.scene().time, center.get(doc.scene()).unwrap());
            doc.apply(Edit::SetAnimation(a, "insert keys"), None)
        };
        // A key at 0 s; at 2 s a move, keyed.
        assert!(insert(&mut doc));
        doc.set_time(2.0);
        assert!(doc.apply(moved(&doc, Vec3::X * 4.0), None));
        assert_eq!(
            doc.scene().ellipsoids[0].center,
            Vec3::X * 4.0,
            "the edit shows"
        );
        assert!(insert(&mut doc));
        doc.set_time(1.0);
        assert_eq!(
            doc.scene().ellipsoids[0].center,
            Vec3::X * 2.0,
            "between the keys"
        );
        // A move not keyed shows, then goes with the time.
        let geometry = doc.revisions().geometry;
        assert!(doc.apply(moved(&doc, Vec3::Y), None));
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::Y);
        doc.set_time(1.5);
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::X * 3.0);
        assert_ne!(
            doc.revisions().geometry,
            geometry,
            "the pose moved the geometry"
        );
        // Undo of the key at 2 s, made at another time, poses at this one: one key left.
        assert_eq!(doc.undo().as_deref(), Some("move an ellipsoid"));
        assert_eq!(doc.undo().as_deref(), Some("insert keys"));
        assert_eq!(doc.scene().animation.key_count(), 1);
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::ZERO);
        // Auto-key: a move is a key at the time, in the move's own undo step.
        doc.set_auto_key(true);
        doc.set_time(3.0);
        let steps = doc.undo_len();
        assert!(doc.apply(moved(&doc, Vec3::Z), None));
        assert_eq!(doc.undo_len(), steps + 1);
        assert_eq!(doc.scene().animation.key_count(), 2);
        doc.set_time(0.0);
        doc.set_time(3.0);
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::Z);
        assert_eq!(doc.undo().as_deref(), Some("move an ellipsoid, keyed"));
        assert_eq!(doc.scene().animation.key_count(), 1);
        // Deleting the ellipsoid deletes its keys.
        assert!(doc.apply(Edit::SetEllipsoids(Vec::new()), None));
        assert!(doc.scene().animation.is_empty());
    }

    #[test]
    fn a_new_time_on_a_scene_without_keys_moves_only_the_time_revision() {
        use crate::scene::Document;
        let mut doc = Document::new(one_ellipsoid());
        let before = doc.revisions();
        doc.set_time(5.0);
        let after = doc.revisions();
        assert_eq!(
            (before.geometry, before.light),
            (after.geometry, after.light)
        );
        assert_ne!(before.time, after.time);
    }

    #[test]
    fn the_shot_cameras_yaw_turns_the_short_way_and_its_keys_go_with_it() {
        let mut scene = one_ellipsoid();
        scene.shot = Some(crate::scene::OrbitCamera::default());
        let yaw = Channel::Shot {
            property: ShotProperty::Yaw,
        };
        scene.animation.key(yaw, 0.0, vec![350.0]);
        scene.animation.key(yaw, 2.0, vec![10.0]);
        let at = |t: f32| scene.posed_at(t).shot.unwrap().yaw_deg;
        assert_eq!(at(0.0), 350.0);
        assert!(
            at(1.0).abs() < 1e-3 || (at(1.0) - 360.0).abs() < 1e-3,
            "{}",
            at(1.0)
        );
        assert_eq!(at(2.0), 10.0);
        // Without a shot its keys have nothing to hold.
        scene.shot = None;
        let mut animation = scene.animation.clone();
        assert_eq!(animation.forget_missing(&scene), 1);
    }

    #[test]
    fn a_tiers_floor_wind_and_torque_key_pose_and_go_with_their_tier() {
        use crate::scene::{Document, Edit, Tier};
        let tier = |floor: f32| Tier {
            floor,
            ..Default::default()
        };
        let floor = |tier| Channel::Tier {
            tier,
            property: TierProperty::Floor,
        };
        let torque = |tier| Channel::Tier {
            tier,
            property: TierProperty::Torque,
        };
        let mut scene = one_ellipsoid();
        scene.render.tiers = vec![tier(2.0), tier(6.0)];
        assert_eq!(
            Channel::all(&scene)
                .filter(|c| matches!(c, Channel::Tier { .. }))
                .count(),
            6
        );
        // Auto-key records an edit of tier 2's torque at the document's time.
        let mut doc = Document::new(scene);
        doc.set_auto_key(true);
        doc.set_time(1.0);
        let mut r = doc.scene().render.clone();
        r.tiers[1].torque = 30.0;
        assert!(doc.apply(Edit::SetRender(r), None));
        let track = doc.scene().animation.track(torque(1)).expect("keyed");
        assert_eq!(track.keys[0].value, vec![30.0]);
        // Floors keyed across each other: tier 1's keys take it from 0 to 10, past tier 2's
        // floor of 6, which then begins with it; back at 0 s it is at 6 again (the pose is
        // the time's alone, not where the scrub has been).
        let mut a = doc.scene().animation.clone();
        a.key(floor(0), 0.0, vec![0.0]);
        a.key(floor(0), 2.0, vec![10.0]);
        a.key(floor(1), 0.0, vec![6.0]);
        doc.apply(Edit::SetAnimation(a, "insert keys"), None);
        doc.set_time(1.0);
        assert_eq!(doc.scene().render.tiers[0].floor, 5.0, "halfway");
        doc.set_time(2.0);
        assert_eq!(doc.scene().render.tier_floors(), vec![10.0, 10.0]);
        assert_eq!(
            doc.scene().render.tiers[1].torque,
            30.0,
            "the tiers kept their places"
        );
        doc.set_time(0.0);
        assert_eq!(doc.scene().render.tier_floors(), vec![0.0, 6.0]);
        doc.set_time(2.0);
        // Removing tier 1 (auto-key on) takes its keys; tier 2's move down with it and still
        // pose it, and nothing new is keyed.
        let keys = doc.scene().animation.key_count();
        assert!(doc.apply(Edit::RemoveTier(0), None));
        assert_eq!(doc.scene().animation.key_count(), keys - 2);
        doc.set_auto_key(false);
        let a = &doc.scene().animation;
        assert!(a.track(floor(1)).is_none() && a.track(torque(1)).is_none());
        assert_eq!(a.track(torque(0)).unwrap().keys[0].value, vec![30.0]);
        assert_eq!(
            a.track(floor(0)).unwrap().keys[0].value,
            vec![6.0],
            "tier 2's floor key"
        );
        doc.set_time(0.0);
        assert_eq!(doc.scene().render.tiers[0].floor, 6.0);
        assert_eq!(doc.scene().render.tiers[0].torque, 30.0);
        // Undo brings the tier and its keys back.
        doc.undo();
        assert_eq!(doc.scene().render.tiers.len(), 2);
        assert!(doc.scene().animation.track(floor(1)).is_some());
        // Keys on a tier the scene does not have are dropped on reading, naming it.
        let mut scene = one_ellipsoid();
        scene.render.tiers = vec![tier(2.0)];
        let json = r#"[{"channel": {"item": "tier", "tier": 1, "property": "wind"},
                        "keys": [{"t": 0, "v": [1, 0]}]},
                       {"channel": {"item": "tier", "tier": 0, "property": "floor"},
                        "keys": [{"t": 0, "v": [1e5]}]}]"#;
        let mut anim: Animation = serde_json::from_str(json).unwrap();
        let said = anim.repair(&scene).join("\n");
        assert!(
            said.contains("animation[0]: keys on tier 2's wind dropped"),
            "{said}"
        );
        assert_eq!(
            anim.track(floor(0)).unwrap().keys[0].value,
            vec![200.0],
            "{said}"
        );
    }

    #[test]
    fn a_keyed_winds_integral_matches_a_fine_sum_for_each_ease() {
        let wind = Channel::Media {
            property: MediaProperty::Wind,
        };
        for ease in Ease::ALL {
            let tr = track(
                wind,
                &[(1.0, &[2.0, 0.0], ease), (3.0, &[-1.0, 4.0], Ease::Linear)],
            );
            for t in [0.5, 1.0, 1.7, 3.0, 5.0] {
                // Midpoint sum at a millisecond's step.
                let n = (t * 10_000.0) as usize;
                let dt = t / n as f32;
                let mut want = [0.0f64; 2];
                for k in 0..n {
                    let v = tr.sample((k as f32 + 0.5) * dt).unwrap();
                    want[0] += (v[0] * dt) as f64;
                    want[1] += (v[1] * dt) as f64;
                }
                let got = tr.integral(t).unwrap();
                for c in 0..2 {
                    assert!(
                        (got[c] as f64 - want[c]).abs() < 2e-3,
                        "{ease:?} at {t}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn review_cases_huge_keys_set_values_and_wind_keys_that_redraw() {
        use crate::scene::{Document, Edit, set_by_pointer};
        let scene = one_ellipsoid();
        let id = scene.ellipsoids[0].id;
        // Keys far out are dropped on reading, so no pose can overflow to NaN.
        let json = format!(
            r#"[{{"channel": {{"item": "ellipsoid", "id": {id}, "property": "center"}},
                 "keys": [{{"t": 0, "v": [-3e38, 0, 0]}}, {{"t": 1, "v": [3e38, 0, 0]}},
                          {{"t": 2, "v": [1, 2, 3]}}]}}]"#
        );
        let mut anim: Animation = serde_json::from_str(&json).unwrap();
        let said = anim.repair(&scene).join("\n");
        assert!(said.contains("2 keys"), "{said}");
        assert_eq!(anim.key_count(), 1);
        // `--set` of a keyed value sets it; `--set /time` poses.
        let mut keyed = scene.clone();
        let center = Channel::Ellipsoid {
            id,
            property: EllipsoidProperty::Center,
        };
        keyed.animation.key(center, 0.0, vec![0.0, 0.0, 0.0]);
        keyed.animation.key(center, 2.0, vec![2.0, 0.0, 0.0]);
        let (set, _) = set_by_pointer(&keyed, "/ellipsoids/0/center=[5,5,5]").unwrap();
        assert_eq!(set.ellipsoids[0].center, Vec3::splat(5.0));
        let (later, _) = set_by_pointer(&set, "/time=1").unwrap();
        assert_eq!(later.ellipsoids[0].center, Vec3::X);
        // New keys on the wind redraw even where they pose the same wind at this time.
        let wind = Channel::Media {
            property: MediaProperty::Wind,
        };
        let mut doc = Document::new(scene);
        doc.set_time(5.0);
        let mut a = Animation::default();
        a.key(wind, 0.0, vec![0.0, 0.0]);
        a.key(wind, 4.0, vec![1.0, 0.0]);
        doc.apply(Edit::SetAnimation(a.clone(), "insert keys"), None);
        let render = doc.revisions().render;
        assert!(a.retime(&[wind], 0.0, 2.0));
        doc.apply(Edit::SetAnimation(a, "retime keys"), None);
        assert_eq!(doc.scene().render.wind, [1.0, 0.0], "the same wind at 5 s");
        assert_ne!(
            doc.revisions().render,
            render,
            "but it carried the noise elsewhere"
        );
    }
}
