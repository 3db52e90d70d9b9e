//! Particle motion (Schpok et al. 2003 §3.1 and §5.4): ellipsoids carried by a wind field
//! (uniform, stronger with height by a shear, plus a seeded turbulence), rising at a
//! convection speed and growing or spreading at a rate. Every position and size is a closed
//! form of the document and the time, so scrubbing backwards gives what playing forward gave
//! and a frame is the same wherever it is made.
//!
//! A moving ellipsoid keeps where it starts ([`Motion::from`], [`Motion::size`]: its centre
//! and radii at time 0); the document holds it posed at its own time, as keyed values are
//! ([`Scene::pose`]), so the tools edit what the user sees and an edit of a moving
//! ellipsoid's centre or radii moves its start to match ([`Scene::rebase_motion`]). Its
//! centre and radii are not keyed: the motion sets them.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::{Ellipsoid, Scene, as_linked};
use crate::limits;

/// Smallest share of its starting radii a shrinking ellipsoid keeps (it fades at its
/// strength's keys, not by vanishing to a point).
pub const MIN_SCALE: f32 = 0.05;

/// Largest magnitude of a start's coordinates and radii (world units), as keys allow.
const MAX_START: f32 = super::keys::MAX_MAGNITUDE;

/// How an ellipsoid moves with time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Motion {
    /// Carried by the scene's wind field ([`WindField`]).
    pub carried: bool,
    /// Rising speed (convection), world units per second (negative sinks).
    pub rise: f32,
    /// Growth of every radius per second, as a share of its starting size (negative shrinks).
    pub growth: f32,
    /// Further growth of its width and depth alone per second (an anvil spreading).
    pub spread: f32,
    /// Its centre at time 0 (missing in a file: the ellipsoid's own centre).
    #[serde(default = "unset")]
    pub from: Vec3,
    /// Its radii at time 0 (missing in a file: the ellipsoid's own radii).
    #[serde(default = "unset")]
    pub size: Vec3,
}

/// A start a file left out: [`Motion::sanitize`] gives it the ellipsoid's own.
fn unset() -> Vec3 {
    Vec3::NAN
}

impl Default for Motion {
    fn default() -> Self {
        Self {
            carried: true,
            rise: 0.0,
            growth: 0.0,
            spread: 0.0,
            from: Vec3::ZERO,
            size: Vec3::ONE,
        }
    }
}

/// The wind that carries the ellipsoids whose motion is [`Motion::carried`]: a uniform
/// velocity at height 0, faster by `shear` of itself per unit of height, and a seeded
/// turbulence that jostles each ellipsoid on its own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct WindField {
    /// Horizontal velocity at height 0 (x, z), world units per second.
    pub velocity: [f32; 2],
    /// Share of the velocity gained per unit of height (wind shear).
    pub shear: f32,
    /// How far each ellipsoid wanders from its path, in world units (at most twice this
    /// horizontally, once vertically).
    pub turbulence: f32,
}

impl WindField {
    /// Whether it is the default (no wind), left out of a file.
    pub fn is_calm(&self) -> bool {
        *self == Self::default()
    }

    /// Clamps every value into its range (documents and links may carry anything).
    pub fn sanitize(&mut self) {
        self.velocity = self.velocity.map(|v| limits::PARTICLE_WIND.fix_f32(v));
        self.shear = limits::PARTICLE_SHEAR.fix_f32(self.shear);
        self.turbulence = limits::PARTICLE_TURBULENCE.fix_f32(self.turbulence);
    }
}

impl Motion {
    /// Clamps every value into its range; a start or size that is missing or not finite (or a
    /// size ≤ 0) becomes the ellipsoid's own (`center`, `radii`), and each coordinate is kept
    /// within ±10⁶.
    pub fn sanitize(&mut self, center: Vec3, radii: Vec3) {
        self.rise = limits::RISE.fix_f32(self.rise);
        self.growth = limits::GROWTH.fix_f32(self.growth);
        self.spread = limits::SPREAD.fix_f32(self.spread);
        // Each coordinate on its own, into ±MAX_START (sizes above 0): a repair that holds on
        // the next reading, whatever the ellipsoid's own values are.
        let fix = |v: f32, own: f32, lo: f32| {
            let v = if v.is_finite() { v } else { own };
            if v.is_finite() {
                v.clamp(lo, MAX_START)
            } else {
                lo.max(0.0)
            }
        };
        self.from = Vec3::from_array([0, 1, 2].map(|i| fix(self.from[i], center[i], -MAX_START)));
        self.size = Vec3::from_array([0, 1, 2].map(|i| {
            let v = if self.size[i] > 0.0 {
                self.size[i]
            } else {
                f32::NAN
            };
            fix(v, radii[i], 1e-4)
        }));
    }

    /// How far it has gone from its start at time `t` (seconds), in `wind`; `seed` (the
    /// scene's and the ellipsoid's id) picks its turbulence.
    pub fn travelled(&self, wind: &WindField, seed: u64, t: f32) -> Vec3 {
        let t = f64::from(t.max(0.0));
        let rise = f64::from(self.rise);
        let mut d = glam::DVec3::new(0.0, rise * t, 0.0);
        if self.carried {
            // ∫₀ᵗ v·(1 + shear·y(s)) ds with y(s) = y₀ + rise·s.
            let y0 = f64::from(self.from.y);
            let along = t + f64::from(wind.shear) * (y0 * t + rise * t * t / 2.0);
            d.x += f64::from(wind.velocity[0]) * along;
            d.z += f64::from(wind.velocity[1]) * along;
            if wind.turbulence > 0.0 {
                d += turbulence(seed, t) * f64::from(wind.turbulence);
            }
        }
        d.as_vec3()
    }

    /// This motion starting where `other`'s does (if it has one): compares motions by how
    /// they move.
    pub fn with_start_of(self, other: &Ellipsoid) -> Self {
        match other.motion {
            Some(o) => Self {
                from: o.from,
                size: o.size,
                ..self
            },
            None => self,
        }
    }

    /// Its radii's scale at time `t` (x, y, z of its own axes).
    pub fn scale(&self, t: f32) -> Vec3 {
        let t = t.max(0.0);
        let all = (1.0 + self.growth * t).max(MIN_SCALE);
        let wide = (1.0 + (self.growth + self.spread) * t).max(MIN_SCALE);
        Vec3::new(wide, all, wide)
    }

    /// Its centre and radii at time `t`.
    pub fn at(&self, wind: &WindField, seed: u64, t: f32) -> (Vec3, Vec3) {
        (
            self.from + self.travelled(wind, seed, t),
            self.size * self.scale(t),
        )
    }

    /// This motion starting where an ellipsoid at `center` with `radii` at time `t` started
    /// (the inverse of [`Motion::at`]).
    pub fn rebased(&self, wind: &WindField, seed: u64, t: f32, center: Vec3, radii: Vec3) -> Self {
        let mut m = *self;
        // The height travelled does not depend on the start; the drift does, through the
        // start's height, so the height comes first.
        m.from.y = center.y - self.travelled(wind, seed, t).y;
        let d = m.travelled(wind, seed, t);
        m.from = Vec3::new(center.x - d.x, m.from.y, center.z - d.z);
        m.size = (radii / self.scale(t)).max(Vec3::splat(1e-4));
        m
    }
}

/// A smooth, seeded wander, 0 at time 0: two sines of different periods (a few seconds to
/// half a minute) per axis, each at most 1 away from its start, so at most 2 horizontally and
/// 1 vertically.
fn turbulence(seed: u64, t: f64) -> glam::DVec3 {
    let mut rng = crate::seeded::SplitMix::new(seed ^ 0x7475_7262_756c_656e);
    let mut axis = || {
        (0..2)
            .map(|_| {
                let omega = 0.2 + 0.8 * rng.next_f64();
                let phase = std::f64::consts::TAU * rng.next_f64();
                ((omega * t + phase).sin() - phase.sin()) / 2.0
            })
            .sum::<f64>()
    };
    glam::DVec3::new(axis(), axis() * 0.5, axis())
}

impl Ellipsoid {
    /// Its centre and radii at time `t` by its motion (as they are without one), in `wind`,
    /// with the scene's `seed`: a billowed ellipsoid's radii rounded as files hold them.
    pub fn moved_at(&self, wind: &WindField, seed: u64, t: f32) -> (Vec3, Vec3) {
        let Some(m) = &self.motion else {
            return (self.center, self.radii);
        };
        let (center, radii) = m.at(wind, motion_seed(seed, self.id), t);
        let radii = if self.billows.is_off() {
            radii
        } else {
            radii.map(as_linked)
        };
        (center, radii)
    }
}

/// The seed of one ellipsoid's turbulence.
fn motion_seed(scene: u64, id: u64) -> u64 {
    scene ^ id.wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

impl Scene {
    /// Whether anything changes with time besides the noise's drift: keys or moving
    /// ellipsoids.
    pub fn is_animated(&self) -> bool {
        !self.animation.is_empty() || self.ellipsoids.iter().any(|e| e.motion.is_some())
    }

    /// Poses every moving ellipsoid's centre and radii at `t`. Returns whether anything
    /// changed.
    pub(super) fn pose_motion(&mut self, t: f32) -> bool {
        let (wind, seed) = (self.wind_field, self.seed);
        let mut changed = false;
        for e in &mut self.ellipsoids {
            if e.motion.is_none() {
                continue;
            }
            let (center, radii) = e.moved_at(&wind, seed, t);
            if center.is_finite() && radii.is_finite() && (center, radii) != (e.center, e.radii) {
                let e = std::sync::Arc::make_mut(e);
                e.center = center;
                e.radii = radii;
                changed = true;
            }
        }
        changed
    }

    /// After an edit from `before` (both at this scene's time): a moving ellipsoid whose
    /// centre or radii the edit changed, or whose motion is new, starts where it must to
    /// stand where the edit put it; one whose motion the edit changed keeps its start and
    /// moves by its new motion. Then every moving ellipsoid is posed.
    pub(super) fn rebase_motion(&mut self, before: &Scene) {
        if !self.ellipsoids.iter().any(|e| e.motion.is_some()) {
            return;
        }
        let was: std::collections::HashMap<u64, &Ellipsoid> =
            before.ellipsoids.iter().map(|e| (e.id, &**e)).collect();
        let (wind, seed, t) = (self.wind_field, self.seed, self.time);
        // Keys on where a moving ellipsoid stands and its size are its motion's now.
        let moving: std::collections::HashSet<u64> = self
            .ellipsoids
            .iter()
            .filter(|e| e.motion.is_some())
            .map(|e| e.id)
            .collect();
        self.animation.tracks.retain(|tr| {
            !matches!(
                tr.channel,
                super::Channel::Ellipsoid {
                    id,
                    property: super::EllipsoidProperty::Center | super::EllipsoidProperty::Radii,
                } if moving.contains(&id)
            )
        });
        for e in &mut self.ellipsoids {
            let Some(m) = e.motion else { continue };
            let old = was.get(&e.id).copied();
            let rebase = match old {
                Some(old) if old.motion.is_some() && !std::ptr::eq(old, &**e) => {
                    old.motion == Some(m) && (old.center != e.center || old.radii != e.radii)
                }
                Some(old) => old.motion.is_none(),
                None => true,
            };
            if rebase {
                let s = motion_seed(seed, e.id);
                std::sync::Arc::make_mut(e).motion =
                    Some(m.rebased(&wind, s, t, e.center, e.radii));
            }
        }
        self.pose_motion(t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    fn moving(m: Motion) -> Scene {
        let mut scene = Scene::preset(super::super::Preset::Empty);
        let mut e = Ellipsoid::new(m.from, m.size);
        e.id = 1;
        e.motion = Some(m);
        scene.ellipsoids.push(Arc::new(e));
        scene
    }

    #[test]
    fn rising_sheared_drift_matches_its_integral() {
        let m = Motion {
            carried: true,
            rise: 0.5,
            from: Vec3::new(0.0, 2.0, 0.0),
            ..Default::default()
        };
        let wind = WindField {
            velocity: [1.0, 0.0],
            shear: 0.25,
            turbulence: 0.0,
        };
        // x(t) = ∫ 1·(1 + 0.25·(2 + 0.5 s)) ds = 1.5 t + 0.0625 t²; at 4 s: 6 + 1 = 7.
        let d = m.travelled(&wind, 7, 4.0);
        assert!((d - Vec3::new(7.0, 2.0, 0.0)).length() < 1e-5, "{d}");
        // A fine sum of the velocity along the path agrees (not a restatement of the form).
        let (mut x, mut y, dt) = (0.0f64, 2.0f64, 1e-4);
        for _ in 0..40_000 {
            x += (1.0 + 0.25 * (y + 0.5 * dt / 2.0)) * dt;
            y += 0.5 * dt;
        }
        assert!((x as f32 - d.x).abs() < 1e-3, "{x} vs {}", d.x);
        // Not carried: it only rises.
        let still = Motion {
            carried: false,
            ..m
        };
        assert_eq!(still.travelled(&wind, 7, 4.0), Vec3::new(0.0, 2.0, 0.0));
    }

    #[test]
    fn turbulence_is_smooth_seeded_and_zero_at_the_start() {
        let m = Motion::default();
        let wind = WindField {
            turbulence: 1.0,
            ..Default::default()
        };
        assert_eq!(m.travelled(&wind, 3, 0.0), Vec3::ZERO);
        let a = m.travelled(&wind, 3, 5.0);
        assert_eq!(a, m.travelled(&wind, 3, 5.0));
        assert_ne!(a, m.travelled(&wind, 4, 5.0));
        assert!(a.length() > 0.01 && a.abs().max_element() <= 2.0, "{a}");
        let b = m.travelled(&wind, 3, 5.01);
        assert!((a - b).length() < 0.05, "jumps: {a} → {b}");
    }

    #[test]
    fn growth_and_spread_scale_the_radii_and_stop_at_a_floor() {
        let m = Motion {
            growth: 0.1,
            spread: 0.2,
            size: Vec3::new(1.0, 2.0, 3.0),
            ..Default::default()
        };
        let (_, r) = m.at(&WindField::default(), 0, 5.0);
        assert!((r - Vec3::new(2.5, 3.0, 7.5)).length() < 1e-5, "{r}");
        let shrink = Motion { growth: -1.0, ..m };
        let (_, r) = shrink.at(&WindField::default(), 0, 10.0);
        assert!((r - m.size * MIN_SCALE).length() < 1e-6, "{r}");
    }

    #[test]
    fn rebasing_keeps_the_ellipsoid_where_it_stands() {
        let m = Motion {
            rise: 0.3,
            growth: 0.05,
            spread: 0.1,
            from: Vec3::new(1.0, 1.0, -1.0),
            size: Vec3::new(1.0, 0.5, 1.0),
            ..Default::default()
        };
        let wind = WindField {
            velocity: [0.7, -0.2],
            shear: 0.3,
            turbulence: 0.4,
        };
        let (c, r) = (Vec3::new(4.0, 5.0, 2.0), Vec3::new(2.0, 1.0, 1.5));
        let b = m.rebased(&wind, 9, 6.0, c, r);
        let (c2, r2) = b.at(&wind, 9, 6.0);
        assert!(
            (c2 - c).length() < 1e-4 && (r2 - r).length() < 1e-5,
            "{c2} {r2}"
        );
    }

    #[test]
    fn a_scene_poses_its_moving_ellipsoids_and_an_edit_moves_their_start() {
        let mut scene = moving(Motion {
            rise: 1.0,
            from: Vec3::new(0.0, 1.0, 0.0),
            ..Default::default()
        });
        assert!(scene.is_animated());
        let later = scene.posed_at(3.0);
        assert_eq!(later.ellipsoids[0].center, Vec3::new(0.0, 4.0, 0.0));
        // Back at 0 it is where it started: nothing is remembered from the way there.
        assert_eq!(
            later.posed_at(0.0).ellipsoids[0].center,
            Vec3::new(0.0, 1.0, 0.0)
        );
        // Moved by an edit at 3 s to x = 2: it now starts at x = 2, y = 1 … 4 − 3.
        let mut edited = later.clone();
        Arc::make_mut(&mut edited.ellipsoids[0]).center = Vec3::new(2.0, 5.0, 0.0);
        edited.rebase_motion(&later);
        assert_eq!(edited.ellipsoids[0].center, Vec3::new(2.0, 5.0, 0.0));
        assert_eq!(
            edited.ellipsoids[0].motion.unwrap().from,
            Vec3::new(2.0, 2.0, 0.0)
        );
        // A faster rise keeps the start and moves the ellipsoid.
        let mut faster = edited.clone();
        Arc::make_mut(&mut faster.ellipsoids[0])
            .motion
            .as_mut()
            .unwrap()
            .rise = 2.0;
        faster.rebase_motion(&edited);
        assert_eq!(faster.ellipsoids[0].center, Vec3::new(2.0, 8.0, 0.0));
        scene.ellipsoids.clear();
        assert!(!scene.is_animated());
    }

    #[test]
    fn a_document_edit_of_a_moving_ellipsoid_moves_its_start_and_undoes() {
        use super::super::{Document, Edit};
        let scene = moving(Motion {
            rise: 1.0,
            from: Vec3::new(0.0, 1.0, 0.0),
            ..Default::default()
        });
        let mut doc = Document::new(scene);
        doc.set_time(2.0);
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::new(0.0, 3.0, 0.0));
        // Dragged 1 to the right at 2 s: it stays where it was put, and started 1 to the right.
        let mut list = doc.scene().ellipsoids.clone();
        Arc::make_mut(&mut list[0]).center = Vec3::new(1.0, 3.0, 0.0);
        assert!(doc.apply(Edit::SetEllipsoids(list), None));
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::new(1.0, 3.0, 0.0));
        doc.set_time(0.0);
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::new(1.0, 1.0, 0.0));
        // A wind carries it; undo calms it again, at this time.
        doc.set_time(2.0);
        let wind = WindField {
            velocity: [1.0, 0.0],
            ..Default::default()
        };
        assert!(doc.apply(Edit::SetWindField(wind), None));
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::new(3.0, 3.0, 0.0));
        assert_eq!(doc.undo().as_deref(), Some("wind field"));
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::new(1.0, 3.0, 0.0));
        assert_eq!(doc.undo().as_deref(), Some("move an ellipsoid"));
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::new(0.0, 3.0, 0.0));
    }

    #[test]
    fn a_file_motion_missing_or_out_of_range_is_repaired_once_and_for_all() {
        // Only a rise: it starts where the ellipsoid stands, its own size.
        let mut scene = moving(Motion::default());
        scene.time = 2.0;
        let mut json: serde_json::Value = serde_json::from_str(&scene.to_json()).unwrap();
        json["ellipsoids"][0]["center"] = serde_json::json!([1.0, 2.0, 3.0]);
        json["ellipsoids"][0]["radii"] = serde_json::json!([2.0, 1.0, 2.0]);
        json["ellipsoids"][0]["motion"] = serde_json::json!({"rise": 1.0});
        let (read, _) = Scene::from_json(&json.to_string()).unwrap();
        let m = read.ellipsoids[0].motion.unwrap();
        assert_eq!(
            (m.from, m.size),
            (Vec3::new(1.0, 2.0, 3.0), Vec3::new(2.0, 1.0, 2.0))
        );
        assert_eq!(
            read.ellipsoids[0].center,
            Vec3::new(1.0, 4.0, 3.0),
            "posed at 2 s"
        );
        // Far out of range: clamped, and the second reading keeps what the first made.
        json["ellipsoids"][0]["radii"] = serde_json::json!([2e6, 1.0, 2.0]);
        json["ellipsoids"][0]["motion"] =
            serde_json::json!({"growth": 0.5, "from": [3e7, 0, 0], "size": [5e6, -1, 1]});
        let (once, _) = Scene::from_json(&json.to_string()).unwrap();
        let (twice, _) = Scene::from_json(&once.to_json()).unwrap();
        assert_eq!(once, twice);
        let m = once.ellipsoids[0].motion.unwrap();
        assert_eq!(m.from.x, MAX_START);
        assert_eq!(m.size, Vec3::new(MAX_START, 1.0, 1.0));
    }

    #[test]
    fn set_by_pointer_moves_a_moving_ellipsoids_start_and_reaches_a_calm_wind() {
        use super::super::set_by_pointer;
        let mut scene = moving(Motion {
            rise: 1.0,
            from: Vec3::new(0.0, 1.0, 0.0),
            ..Default::default()
        });
        scene = scene.posed_at(2.0);
        let (set, _) = set_by_pointer(&scene, "/ellipsoids/0/center/0=5").unwrap();
        assert_eq!(set.ellipsoids[0].center, Vec3::new(5.0, 3.0, 0.0));
        assert_eq!(
            set.ellipsoids[0].motion.unwrap().from,
            Vec3::new(5.0, 1.0, 0.0)
        );
        // What the command line sets, the file holds: read again, it stands there.
        let (read, _) = Scene::from_json(&set.to_json()).unwrap();
        assert_eq!(read.ellipsoids[0].center, Vec3::new(5.0, 3.0, 0.0));
        let (windy, _) = set_by_pointer(&set, "/wind_field/velocity/0=1").unwrap();
        assert_eq!(
            windy.ellipsoids[0].center,
            Vec3::new(7.0, 3.0, 0.0),
            "carried 2 s"
        );
    }

    #[test]
    fn giving_a_keyed_ellipsoid_a_motion_drops_its_centre_keys_and_keeps_its_others() {
        use super::super::{Channel, Document, Edit, EllipsoidProperty};
        let mut scene = moving(Motion::default());
        Arc::make_mut(&mut scene.ellipsoids[0]).motion = None;
        let key = |property| Channel::Ellipsoid { id: 1, property };
        scene
            .animation
            .key(key(EllipsoidProperty::Center), 0.0, vec![0.0, 1.0, 0.0]);
        scene
            .animation
            .key(key(EllipsoidProperty::Center), 2.0, vec![4.0, 1.0, 0.0]);
        scene
            .animation
            .key(key(EllipsoidProperty::Strength), 0.0, vec![0.5]);
        let mut doc = Document::new(scene);
        doc.set_time(1.0);
        assert_eq!(doc.scene().ellipsoids[0].center.x, 2.0);
        let mut list = doc.scene().ellipsoids.clone();
        Arc::make_mut(&mut list[0]).motion = Some(Motion {
            rise: 1.0,
            ..Default::default()
        });
        assert!(doc.apply(Edit::SetEllipsoids(list), None));
        let tracks: Vec<Channel> = doc
            .scene()
            .animation
            .tracks
            .iter()
            .map(|t| t.channel)
            .collect();
        assert_eq!(tracks, [key(EllipsoidProperty::Strength)]);
        // It starts where it stood and rises from there.
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::new(2.0, 1.0, 0.0));
        doc.set_time(2.0);
        assert_eq!(doc.scene().ellipsoids[0].center, Vec3::new(2.0, 2.0, 0.0));
    }
}
