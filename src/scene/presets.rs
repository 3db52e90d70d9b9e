//! Named starting points (`cloudsketch new --preset NAME`, `?preset=NAME`, the Scene group):
//! the paper's cloud types (Schpok et al. 2003, Figures 3–7), each a set of ellipsoids with the
//! media, light and camera that make it recognisable at first sight (those three kept as data,
//! in `presets.json`). Every random choice comes from a fixed seed, so a preset is the same
//! document everywhere.

use std::sync::{Arc, OnceLock};

use std::collections::BTreeMap;

use glam::{Quat, Vec3};
use serde::Deserialize;

use super::{Ellipsoid, Lighting, OrbitCamera, RenderSettings, SCENE_VERSION, Scene};
use crate::seeded::SplitMix;

/// Named starting points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// A fair-weather cumulus of a few blended ellipsoids (the default).
    Cumulus,
    /// A low layer far wider than tall, soft and even.
    Stratus,
    /// High, thin streaks of wispy noise drawn out by the wind.
    Cirrus,
    /// A towering storm cloud with a flat anvil on top, taller than wide.
    Cumulonimbus,
    /// Scattered clouds lit from just above the horizon: pink shadows, darker tops.
    Sunset,
    /// Nothing but sky: for sketching from scratch.
    Empty,
    /// Clouds grown by the cellular automaton (Dobashi et al. 2000) in three air parcels, wind
    /// stronger aloft, a low sun: press Play.
    Simulated,
    /// A developing cumulus (Schpok et al. 2003, Figure 5): over 20 s its puffs rise and grow,
    /// an anvil spreads downwind at the top, and the noise slows and scales out: press Play.
    Developing,
}

impl Preset {
    /// All presets with their names.
    pub const ALL: [(Preset, &'static str); 8] = [
        (Preset::Cumulus, "cumulus"),
        (Preset::Stratus, "stratus"),
        (Preset::Cirrus, "cirrus"),
        (Preset::Cumulonimbus, "cumulonimbus"),
        (Preset::Sunset, "sunset"),
        (Preset::Empty, "empty"),
        (Preset::Simulated, "simulated"),
        (Preset::Developing, "developing"),
    ];

    /// Looks a preset up by name.
    pub fn from_name(name: &str) -> Option<Preset> {
        Self::ALL
            .iter()
            .find(|(_, n)| n.eq_ignore_ascii_case(name))
            .map(|(p, _)| *p)
    }

    /// The preset's name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(p, _)| *p == self)
            .map(|(_, n)| *n)
            .unwrap_or("cumulus")
    }
}

fn cumulus() -> Vec<Ellipsoid> {
    vec![
        Ellipsoid::new(Vec3::new(0.0, 1.6, 0.0), Vec3::new(4.2, 1.5, 3.0)),
        Ellipsoid::new(Vec3::new(-2.0, 2.7, 0.3), Vec3::new(2.2, 1.9, 2.0)),
        Ellipsoid::new(Vec3::new(1.4, 3.2, -0.3), Vec3::new(2.5, 2.4, 2.2)),
        Ellipsoid::new(Vec3::new(0.1, 4.7, 0.1), Vec3::new(1.8, 1.7, 1.7)),
        Ellipsoid::new(Vec3::new(3.4, 2.3, 0.5), Vec3::new(1.5, 1.3, 1.4)),
        Ellipsoid::new(Vec3::new(-3.6, 2.0, -0.4), Vec3::new(1.3, 1.1, 1.2)),
    ]
}

/// `n` flattened puffs scattered over a `w` × `d` area at height `y` (seeded).
fn layer(n: usize, w: f32, d: f32, y: f32, radii: Vec3, seed: u64) -> Vec<Ellipsoid> {
    let mut rng = SplitMix::new(seed);
    let mut u = move || rng.next_f64() as f32;
    (0..n)
        .map(|_| {
            let c = Vec3::new((u() - 0.5) * w, y + (u() - 0.5) * radii.y, (u() - 0.5) * d);
            let s = 0.7 + 0.6 * u();
            Ellipsoid {
                rotation: Quat::from_rotation_y(u() * 3.0),
                ..Ellipsoid::new(c, radii * s)
            }
        })
        .collect()
}

fn cumulonimbus() -> Vec<Ellipsoid> {
    // The tower: rings of puffs rising and bulging out of one another, leaning downwind (+x)
    // as the wind aloft shears them; then the anvil, spreading flat on top far downwind,
    // thinning toward its edge, with a little overhang upwind (its staging's wind blows +x).
    let mut rng = SplitMix::new(51);
    let mut u = move || rng.next_f64() as f32;
    let mut v = Vec::new();
    for level in 0..7 {
        let y = 1.5 + level as f32 * 2.0;
        // The tower leans downwind, more the higher it is.
        let lean = 0.03 * (level * level) as f32;
        for k in 0..3 {
            let a = k as f32 * 2.1 + level as f32 * 0.9;
            let off = 1.3 + 0.5 * u();
            let c = Vec3::new(lean + a.cos() * off, y + u(), a.sin() * off * 0.8);
            let r = 2.0 + 0.8 * u() - level as f32 * 0.08;
            v.push(Ellipsoid::new(c, Vec3::new(r, r * 0.85, r)));
        }
    }
    // The anvil: thick over the crown, a wedge thinning far downwind, overhanging a little
    // upwind.
    for (c, r) in [
        (Vec3::new(2.0, 15.4, 0.0), Vec3::new(5.0, 1.6, 4.2)),
        (Vec3::new(-1.8, 15.2, 0.5), Vec3::new(3.2, 1.1, 3.2)),
        (Vec3::new(6.5, 16.0, -0.3), Vec3::new(4.2, 1.0, 3.6)),
        (Vec3::new(10.0, 16.4, 0.4), Vec3::new(3.0, 0.55, 2.8)),
    ] {
        v.push(Ellipsoid::new(c, r));
    }
    v
}

/// The simulated preset's range: two minutes at 24 frames a second.
const SIMULATED_END: u32 = 2880;

/// The developing cumulus's range: 20 s at 24 frames a second.
const DEVELOPING_END: u32 = 480;

/// The developing cumulus (Schpok et al. 2003 §6, Figure 5): simple ascending implicits model
/// the convection, puffs higher in the column rising faster and growing. The anvil grows out
/// of the column's crown: a flat ellipsoid keyed to ride on the crown, hidden inside it until
/// the tower has risen (8 s), then spreading downwind while the wind, stronger aloft, carries
/// the plume. Its keys: the anvil's centre and radii, and the noise slowing and scaling out as
/// the plume spreads. (Fading the anvil in by its strength floated a faint disc of noise
/// specks above the column: a weak field lies below the iso level, and only the noise's peaks
/// rise over it.)
fn developing() -> (Vec<Ellipsoid>, super::Animation, super::WindField) {
    use super::{Channel, EllipsoidProperty, Motion};
    let mut rng = SplitMix::new(83);
    let mut u = move || rng.next_f64() as f32;
    let moving = |center: Vec3, radii: Vec3, rise: f32, growth: f32, spread: f32| Ellipsoid {
        motion: Some(Motion {
            carried: true,
            rise,
            growth,
            spread,
            from: center,
            size: radii,
        }),
        ..Ellipsoid::new(center, radii).billowed()
    };
    let wind = super::WindField {
        velocity: [0.12, 0.0],
        shear: 0.06,
        turbulence: 0.25,
    };
    let mut v = Vec::new();
    // The base: broad puffs that barely move.
    for k in 0..4 {
        let a = k as f32 * 1.6 + u();
        let c = Vec3::new(a.cos() * 1.8, 1.6 + 0.3 * u(), a.sin() * 1.4);
        let r = 1.9 + 0.4 * u();
        v.push(moving(c, Vec3::new(r, r * 0.7, r), 0.02, 0.02, 0.0));
    }
    // The column: rings of puffs rising the faster the higher they start and growing at the
    // same rate, so the tower stretches upward without coming apart.
    const STRETCH: f32 = 0.05;
    for level in 1..6 {
        for k in 0..3 {
            let a = k as f32 * 2.1 + level as f32 * 0.8 + u();
            let off = 0.8 + 0.4 * u();
            let y = 1.6 + level as f32 * 1.2 + u() * 0.3;
            let c = Vec3::new(a.cos() * off, y, a.sin() * off);
            let r = 1.4 + 0.3 * u() - level as f32 * 0.06;
            let rise = STRETCH * (y - 1.6) + 0.01 * u();
            v.push(moving(c, Vec3::splat(r), rise, STRETCH, 0.0));
        }
    }
    // The anvil: keyed to ride on the crown (the top ring's centre, the wind's drift without
    // its turbulence), small enough to hide inside it until the tower has risen, then
    // spreading, its centre drifting downwind of the crown by a third of its growth.
    let crown: Vec<Motion> = v[v.len() - 3..].iter().filter_map(|e| e.motion).collect();
    let calm = super::WindField {
        turbulence: 0.0,
        ..wind
    };
    let crown_at = |t: f32| {
        let n = crown.len().max(1) as f32;
        let (c, r) = crown.iter().fold((Vec3::ZERO, 0.0), |(c, r), m| {
            let (centre, radii) = m.at(&calm, 0, t);
            (c + centre / n, r + radii.y / n)
        });
        c + Vec3::Y * (0.6 * r)
    };
    let hidden = Vec3::new(0.9, 0.6, 0.8);
    let spread = |t: f32| {
        // Piecewise linear through these sizes, spreading fast and then slowing.
        let sizes = [
            (0.0, hidden),
            (8.0, hidden),
            (14.0, Vec3::new(5.2, 1.0, 3.9)),
            (DEVELOPING_END as f32 / 24.0, Vec3::new(8.5, 1.3, 6.2)),
        ];
        let i = sizes.iter().rposition(|(k, _)| *k <= t).unwrap_or(0);
        match sizes.get(i + 1) {
            Some(&(t1, r1)) => {
                let (t0, r0) = sizes[i];
                r0.lerp(r1, (t - t0) / (t1 - t0))
            }
            None => sizes[i].1,
        }
    };
    let mut anvil = Ellipsoid::new(crown_at(0.0), hidden).billowed();
    anvil.id = 100;
    let mut keys = super::Animation::default();
    let channel = |property| Channel::Ellipsoid { id: 100, property };
    for second in 0..=DEVELOPING_END / 24 {
        let t = second as f32;
        let radii = spread(t);
        let downwind = Vec3::new(wind.velocity[0], 0.0, wind.velocity[1]).normalize_or_zero();
        let centre = crown_at(t) + downwind * ((radii.x - hidden.x) / 3.0);
        keys.key(
            channel(EllipsoidProperty::Center),
            t,
            centre.to_array().to_vec(),
        );
        if matches!(second, 0 | 8 | 14) || second == DEVELOPING_END / 24 {
            keys.key(
                channel(EllipsoidProperty::Radii),
                t,
                radii.to_array().to_vec(),
            );
        }
    }
    v.push(anvil);
    let media = |property| Channel::Media { property };
    use super::MediaProperty as M;
    // The rolling turbulence slows and the noise scales out as the plume spreads.
    for (property, start, end) in [
        (M::Wind, vec![0.5, 0.0], vec![0.1, 0.0]),
        (M::Torque, vec![24.0], vec![4.0]),
        (M::NoiseScale, vec![2.0], vec![4.0]),
    ] {
        keys.key(media(property), 0.0, start);
        keys.key(media(property), 20.0, end);
    }
    (v, keys, wind)
}

/// Each preset's camera, light and media by name: the values an artist tunes, kept as data
/// (what a preset leaves out keeps its default).
/// The presets of heaped clouds carry billows, as new ellipsoids do.
fn billowed(ellipsoids: Vec<Ellipsoid>) -> Vec<Ellipsoid> {
    ellipsoids.into_iter().map(Ellipsoid::billowed).collect()
}

const STAGING: &str = include_str!("presets.json");

/// A preset's camera, light and media, as [`STAGING`] gives them.
#[derive(Clone, Default, Deserialize)]
#[serde(default)]
struct Staging {
    camera: OrbitCamera,
    light: Lighting,
    render: RenderSettings,
}

/// Every preset's staging in [`STAGING`], by name.
fn all_staging() -> Result<BTreeMap<String, Staging>, serde_json::Error> {
    serde_json::from_str(STAGING)
}

/// `name`'s staging, read from [`STAGING`] once per process: `Scene::default` is the cumulus
/// preset, and every document read fills its missing fields from it.
fn staging(name: &str) -> Staging {
    static ALL: OnceLock<BTreeMap<String, Staging>> = OnceLock::new();
    // The file is checked by a test; a preset it lacks gets the defaults.
    ALL.get_or_init(|| all_staging().unwrap_or_default())
        .get(name)
        .cloned()
        .unwrap_or_default()
}

impl Scene {
    /// A new document from a preset.
    pub fn preset(preset: Preset) -> Self {
        let Staging {
            camera,
            light,
            render,
        } = staging(preset.name());
        let mut simulation = None;
        let mut time = 0.0;
        let mut clock = super::Clock::default();
        let mut animation = super::Animation::default();
        let mut wind_field = super::WindField::default();
        let ellipsoids = match preset {
            Preset::Cumulus => billowed(cumulus()),
            Preset::Stratus => layer(64, 56.0, 40.0, 4.0, Vec3::new(6.0, 1.0, 5.0), 11),
            Preset::Cirrus => layer(9, 22.0, 12.0, 9.0, Vec3::new(6.0, 0.35, 0.9), 23),
            Preset::Cumulonimbus => billowed(cumulonimbus()),
            Preset::Sunset => billowed(layer(14, 20.0, 8.0, 3.5, Vec3::new(2.6, 1.3, 2.2), 37)),
            Preset::Empty => Vec::new(),
            Preset::Developing => {
                clock.end = DEVELOPING_END;
                let (ellipsoids, keys, wind) = developing();
                animation = keys;
                wind_field = wind;
                ellipsoids
            }
            Preset::Simulated => {
                simulation = Some(Arc::new(super::SimulationSettings::default()));
                // Forty steps in: the parcels have clouds when the preset opens.
                time = 4.0;
                // Two minutes in which the wind carries the humid parcels across the grid:
                // one swells, one dries out, and their clouds form, grow and dissipate.
                clock.end = SIMULATED_END;
                wind_field = super::WindField {
                    velocity: [0.05, 0.02],
                    shear: 0.0,
                    turbulence: 0.5,
                };
                [
                    (Vec3::new(-7.0, 3.5, 0.0), Vec3::new(5.5, 2.5, 4.5), 0.0),
                    (Vec3::new(3.0, 4.0, 2.5), Vec3::new(6.0, 3.0, 5.0), -0.006),
                    (Vec3::new(1.0, 3.0, -7.0), Vec3::new(5.0, 2.2, 4.0), 0.004),
                ]
                .into_iter()
                .map(|(c, r, growth)| Ellipsoid {
                    motion: Some(super::Motion {
                        carried: true,
                        growth,
                        from: c,
                        size: r,
                        ..Default::default()
                    }),
                    ..Ellipsoid::new(c, r)
                })
                .collect()
            }
        };
        let mut scene = Scene {
            version: SCENE_VERSION,
            seed: 1,
            camera,
            light,
            render,
            ellipsoids: ellipsoids.into_iter().map(Arc::new).collect(),
            planes: Vec::new(),
            reference: None,
            time,
            clock,
            simulation,
            shot: None,
            animation,
            wind_field,
        };
        scene.settle();
        let t = scene.time;
        scene.pose(t);
        scene
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether every value `file` sets stands in `kept` (a misspelt or out-of-range value would
    /// be dropped or changed on the way in).
    fn sets_nothing_lost(file: &serde_json::Value, kept: &serde_json::Value, at: &str) {
        match (file, kept) {
            (serde_json::Value::Object(f), serde_json::Value::Object(k)) => {
                for (key, value) in f {
                    let inner = k.get(key).unwrap_or(&serde_json::Value::Null);
                    sets_nothing_lost(value, inner, &format!("{at}/{key}"));
                }
            }
            (serde_json::Value::Number(f), serde_json::Value::Number(k)) => {
                let (f, k) = (f.as_f64().unwrap(), k.as_f64().unwrap());
                assert!(
                    (f - k).abs() <= 1e-6 * f.abs().max(1.0),
                    "{at}: {f} became {k}"
                );
            }
            (serde_json::Value::Array(f), serde_json::Value::Array(k)) if f.len() == k.len() => {
                for (i, (f, k)) in f.iter().zip(k).enumerate() {
                    sets_nothing_lost(f, k, &format!("{at}/{i}"));
                }
            }
            _ => assert_eq!(file, kept, "{at}"),
        }
    }

    #[test]
    fn every_presets_staging_is_read_whole_and_names_a_preset() {
        let file: serde_json::Value = serde_json::from_str(STAGING).expect("presets.json parses");
        let all = all_staging().expect("presets.json reads as staging");
        for (name, staged) in file.as_object().expect("an object by name") {
            let preset = Preset::from_name(name).unwrap_or_else(|| panic!("no preset {name}"));
            let scene = serde_json::to_value(Scene::preset(preset)).unwrap();
            sets_nothing_lost(staged, &scene, name);
            assert!(all.contains_key(name));
        }
        // The looks that make each preset recognisable are there.
        for name in ["stratus", "cirrus", "cumulonimbus", "sunset", "simulated"] {
            assert!(all.contains_key(name), "{name} has no staging");
        }
    }

    /// The developing cumulus's anvil rides on the tower: at every second its centre stands
    /// above every puff's and over the crown (the highest ring), within the crown's reach plus
    /// its own downwind drift; until 8 s it is no wider than a crown puff, hidden inside it.
    /// An anvil keyed to the wrong ring, or left where the tower has not yet risen, fails it.
    #[test]
    fn the_developing_anvil_rides_on_the_crown_and_hides_in_it_until_the_tower_has_risen() {
        let scene = Scene::preset(Preset::Developing);
        for second in 0..=DEVELOPING_END / 24 {
            let posed = scene.posed_at(second as f32);
            let (anvil, puffs): (Vec<_>, Vec<_>) =
                posed.ellipsoids.iter().partition(|e| e.id == 100);
            let anvil = anvil.first().expect("the anvil is ellipsoid 100");
            let crown = puffs
                .iter()
                .max_by(|a, b| a.center.y.total_cmp(&b.center.y))
                .expect("a column");
            for p in &puffs {
                assert!(
                    anvil.center.y > p.center.y,
                    "at {second} s the anvil ({}) is not above puff {} ({})",
                    anvil.center,
                    p.id,
                    p.center
                );
            }
            let drift = (anvil.radii.x - 0.9) / 3.0;
            let apart = (anvil.center - crown.center).with_y(0.0).length();
            assert!(
                apart < 1.5 * crown.radii.x + drift,
                "at {second} s the anvil stands {apart} from the crown's top puff"
            );
            if second <= 8 {
                assert!(
                    anvil.radii.x <= crown.radii.x
                        && anvil.center.y < crown.center.y + crown.radii.y,
                    "at {second} s the anvil shows before the tower has risen: {} {}",
                    anvil.radii,
                    crown.radii
                );
            }
        }
    }
}
