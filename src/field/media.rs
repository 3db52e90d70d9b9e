//! The cloud's noise media on the CPU (Schpok et al. 2003, §4 and Table 2): the octave
//! transforms the renderer's shaders use (`shaders/volume_noise.wgsl`), and the same media
//! evaluated here for exports that must hold the cloud as shown (Mitsuba, VDB). Sampling the
//! same periodic noise volume through the same transforms, filters and tiers, it agrees with
//! the GPU up to the filtering hardware's rounding.

use glam::{Mat4, Quat, Vec3};

use super::noise::{NOISE_SIZE, noise_volume};
use super::{ISO, density};
use crate::limits::{MAX_OCTAVES, MAX_TIERS};
use crate::scene::{NoiseBasis, NoiseFilter, RenderSettings, Scene};

/// How far the base media's wind has carried the noise (world units, x and z) and its torque
/// turned it (degrees) by a scene time: the wind's and the torque's integrals over time, so
/// keyed ones speed the noise up and slow it down without a jump.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Drift {
    /// World units travelled along x and z.
    pub travelled: [f32; 2],
    /// Degrees turned about the vertical.
    pub turned: f32,
}

impl Drift {
    /// The drift of `scene`'s base media at its own time (its keys on wind and torque
    /// integrated; without keys, the settings times the time).
    pub fn of(scene: &Scene) -> Self {
        let t = scene.time;
        let r = &scene.render;
        let keyed = |property| {
            scene
                .animation
                .track(crate::scene::Channel::Media { property })
                .and_then(|track| track.integral(t))
        };
        let travelled = keyed(crate::scene::MediaProperty::Wind)
            .map_or([r.wind[0] * t, r.wind[1] * t], |v| [v[0], v[1]]);
        let turned = keyed(crate::scene::MediaProperty::Torque).map_or(r.torque * t, |v| v[0]);
        Self { travelled, turned }
    }

    /// The drift of `scene`'s tier `tier` (0-based) at its own time: its keys on wind and
    /// torque integrated, or its settings times the time; none where the tier is not there.
    pub fn of_tier(scene: &Scene, tier: usize) -> Self {
        let Some(settings) = scene.render.tiers.get(tier) else {
            return Self::default();
        };
        let t = scene.time;
        let keyed = |property| {
            scene
                .animation
                .track(crate::scene::Channel::Tier {
                    tier: tier as u32,
                    property,
                })
                .and_then(|track| track.integral(t))
        };
        let steady = Self::steady(settings.wind, settings.torque, t);
        Self {
            travelled: keyed(crate::scene::TierProperty::Wind)
                .map_or(steady.travelled, |v| [v[0], v[1]]),
            turned: keyed(crate::scene::TierProperty::Torque).map_or(steady.turned, |v| v[0]),
        }
    }

    /// A steady `wind` and `torque` for `time` seconds.
    pub fn steady(wind: [f32; 2], torque: f32, time: f32) -> Self {
        Self {
            travelled: [wind[0] * time, wind[1] * time],
            turned: torque * time,
        }
    }
}

/// How far the wind and torque of the base media and of each tier have carried the noise by a
/// scene time ([`Drift::of`], [`Drift::of_tier`]): what the noise's motion needs of the time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Drifts {
    /// The base media's.
    pub base: Drift,
    /// Each tier's, from the lowest (none past the scene's tiers).
    pub tiers: [Drift; MAX_TIERS],
}

impl Drifts {
    /// The drifts of `scene` at its own time.
    pub fn of(scene: &Scene) -> Self {
        Self {
            base: Drift::of(scene),
            tiers: std::array::from_fn(|k| Drift::of_tier(scene, k)),
        }
    }

    /// Every number they hold, for hashing.
    pub fn values(&self) -> impl Iterator<Item = f32> + '_ {
        std::iter::once(&self.base)
            .chain(&self.tiers)
            .flat_map(|d| [d.travelled[0], d.travelled[1], d.turned])
    }
}

/// Transform of octave `i` with the base media carried by `drift`: world → noise-texture
/// coordinates, scale × rotate × translate with frequency `base × lacunarity^i`. Octaves are
/// turned against each other so their lattices do not line up. The wind carries the noise
/// along and the torque turns it about the vertical through the origin, each octave `1 + i/2`
/// times as far as the first (finer detail moves faster, as turbulence does).
pub fn octave_transform(render: &RenderSettings, i: usize, drift: Drift) -> Mat4 {
    moving_octave(render, drift, i)
}

/// [`octave_transform`] in atmospheric tier `tier` (1-based; 0 is the base media), carried
/// by `drifts`: its own wind and torque, except octave 0, which moves with the base
/// everywhere (the paper's Base tier, which keeps the tiers one cloud).
pub fn tier_octave_transform(
    render: &RenderSettings,
    tier: usize,
    i: usize,
    drifts: &Drifts,
) -> Mat4 {
    let k = tier.wrapping_sub(1);
    match drifts.tiers.get(k) {
        Some(drift) if i > 0 && k < render.tiers.len() => moving_octave(render, *drift, i),
        _ => octave_transform(render, i, drifts.base),
    }
}

fn moving_octave(render: &RenderSettings, drift: Drift, i: usize) -> Mat4 {
    let freq = render.detail.powi(i as i32) / render.noise_scale.max(1e-3);
    let turn = Quat::from_axis_angle(Vec3::new(0.3, 1.0, 0.2).normalize(), i as f32 * 0.9);
    let shift = Vec3::new(0.37, 0.11, 0.73) * i as f32;
    let speed = 1.0 + 0.5 * i as f32;
    let [wx, wz] = drift.travelled;
    let drift = Mat4::from_rotation_y(-(drift.turned * speed).to_radians())
        * Mat4::from_translation(-Vec3::new(wx, 0.0, wz) * speed);
    Mat4::from_translation(shift)
        * Mat4::from_quat(turn)
        * Mat4::from_scale(Vec3::splat(freq))
        * drift
}

/// Table 2's filters of one octave's noise `t` in [0, 1] (signed `n = 2t − 1`).
fn filtered(t: f32, filter: NoiseFilter) -> f32 {
    let n = 2.0 * t - 1.0;
    match filter {
        NoiseFilter::Stratus => t,
        NoiseFilter::Cumulus => n.abs(),
        NoiseFilter::Wispy => (1.0 - (2.0 * n).abs()).clamp(0.0, 1.0),
        NoiseFilter::Veined => 1.0 / (1.0 + (10.0 * n).abs()),
    }
}

/// The mean of each basis's noise through each of Table 2's filters over one noise volume:
/// what the noise adds on average is `amount · (mean − 0.5)` (every octave has the same mean,
/// so their normalised sum has it too). The light pass blurs the field shifted by it rather than
/// look the noise up at each of its points (`surrounding_density`, `shaders/light_march.wgsl`):
/// |n| and the veined filter average far below a half, and a blur that ignored it would see more
/// cloud around a point than the noise leaves. Taken over the texels; the shader filters after
/// interpolating between them, which for the convex |n| gives slightly less (4 texels a lattice
/// cell: a small bias). Atmospheric tiers above the base take the base's mean.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseMeans([[f32; 4]; 2]);

impl Default for NoiseMeans {
    /// A half for every filter: no shift (before any noise is made).
    fn default() -> Self {
        Self([[0.5; 4]; 2])
    }
}

impl NoiseMeans {
    /// The means over [`noise_volume`]'s bytes (Perlin red, Worley green).
    pub fn of(bytes: &[u8]) -> Self {
        Self(std::array::from_fn(|channel| {
            NoiseFilter::ALL.map(|filter| {
                let texels = bytes.iter().skip(channel).step_by(2);
                let sum: f64 = texels
                    .map(|&b| filtered(b as f32 / 255.0, filter) as f64)
                    .sum();
                (sum / (bytes.len() / 2).max(1) as f64) as f32
            })
        }))
    }

    /// The mean of `basis` through `filter`.
    pub fn get(&self, basis: NoiseBasis, filter: NoiseFilter) -> f32 {
        let f = NoiseFilter::ALL
            .iter()
            .position(|&f| f == filter)
            .unwrap_or(0);
        self.0[basis_channel(basis)][f]
    }
}

/// The noise volume's channel holding `basis` (Perlin red, Worley green).
fn basis_channel(basis: NoiseBasis) -> usize {
    match basis {
        NoiseBasis::Perlin => 0,
        NoiseBasis::Worley => 1,
    }
}

fn smoothstep(lo: f32, hi: f32, x: f32) -> f32 {
    let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A scene's noise media at one time: density at any point, as the slice shader computes it.
pub struct Media {
    /// One channel of the noise volume (the basis in use), `NOISE_SIZE³` values in [0, 1].
    texels: Vec<f32>,
    octaves: usize,
    amount: f32,
    softness: f32,
    filter: NoiseFilter,
    /// Tier floors, filters and octave transforms (octave 0 always the base's).
    tiers: Vec<(f32, NoiseFilter, [Mat4; MAX_OCTAVES])>,
    base: [Mat4; MAX_OCTAVES],
    blend: f32,
}

impl Media {
    /// The media of `scene` at its clock's time.
    pub fn new(scene: &Scene) -> Self {
        let r = &scene.render;
        let bytes = noise_volume(scene.seed);
        let channel = basis_channel(r.noise_basis);
        let texels = bytes
            .iter()
            .skip(channel)
            .step_by(2)
            .map(|&b| b as f32 / 255.0)
            .collect();
        let drifts = Drifts::of(scene);
        let floors = r.tier_floors();
        let tiers = r
            .tiers
            .iter()
            .take(MAX_TIERS)
            .zip(floors)
            .enumerate()
            .map(|(k, (t, floor))| {
                let m = std::array::from_fn(|i| tier_octave_transform(r, k + 1, i, &drifts));
                (floor, t.filter, m)
            })
            .collect();
        let octaves = (r.noise_octaves as usize).min(MAX_OCTAVES);
        Self {
            texels,
            octaves,
            amount: if octaves == 0 { 0.0 } else { r.noise_amount },
            softness: r.softness,
            filter: r.noise_filter,
            tiers,
            base: std::array::from_fn(|i| octave_transform(r, i, drifts.base)),
            blend: r.tier_blend,
        }
    }

    /// The noise volume at texture coordinates `q` (period 1), trilinear with wrapping as the
    /// GPU's repeating sampler does (texel centres at `(i + ½)/N`).
    fn sample(&self, q: Vec3) -> f32 {
        let n = NOISE_SIZE as i64;
        let p = q * NOISE_SIZE as f32 - Vec3::splat(0.5);
        let f = p - p.floor();
        let c = p.floor().as_i64vec3();
        let at = |dx: i64, dy: i64, dz: i64| {
            let x = (c.x + dx).rem_euclid(n);
            let y = (c.y + dy).rem_euclid(n);
            let z = (c.z + dz).rem_euclid(n);
            self.texels[((z * n + y) * n + x) as usize]
        };
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let x00 = lerp(at(0, 0, 0), at(1, 0, 0), f.x);
        let x10 = lerp(at(0, 1, 0), at(1, 1, 0), f.x);
        let x01 = lerp(at(0, 0, 1), at(1, 0, 1), f.x);
        let x11 = lerp(at(0, 1, 1), at(1, 1, 1), f.x);
        lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z)
    }

    /// The filtered octaves summed in [0, 1] in tier `tier` (0: the base media).
    fn fbm(&self, p: Vec3, tier: usize) -> f32 {
        let (filter, transforms) = match tier {
            0 => (self.filter, &self.base),
            k => (self.tiers[k - 1].1, &self.tiers[k - 1].2),
        };
        let (mut amp, mut sum, mut norm) = (1.0, 0.0, 0.0);
        for (i, m) in transforms.iter().enumerate().take(self.octaves) {
            let m = if i == 0 { &self.base[0] } else { m };
            sum += amp * filtered(self.sample(m.transform_point3(p)), filter);
            norm += amp;
            amp *= 0.5;
        }
        if norm > 0.0 { sum / norm } else { 0.5 }
    }

    /// The noise at `p` across the atmospheric tiers, blended around each floor.
    pub fn noise(&self, p: Vec3) -> f32 {
        if self.tiers.is_empty() {
            return self.fbm(p, 0);
        }
        let half = (self.blend * 0.5).max(1e-4);
        let (mut total, mut below) = (0.0, 1.0);
        for k in 0..=self.tiers.len() {
            let above = self
                .tiers
                .get(k)
                .map_or(0.0, |t| smoothstep(t.0 - half, t.0 + half, p.y));
            let w = below - above;
            if w > 1e-3 {
                total += w * self.fbm(p, k);
            }
            below = above;
        }
        total
    }

    /// Cloud density in [0, 1] at `p` where the field's value is `field`: the noise moves the
    /// field before the soft iso-surface step (`volume.wgsl`).
    pub fn density(&self, field: f32, p: Vec3) -> f32 {
        if self.amount == 0.0 {
            return density(field, self.softness);
        }
        if field < ISO - self.softness - 0.5 * self.amount {
            return 0.0;
        }
        let v = field + self.amount * (self.noise(p) - 0.5);
        smoothstep(ISO - self.softness, ISO + self.softness, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |n| and the veined filter average far below a half, plain and wispy noise near a half
    /// (so the default media's blur is nearly the field's own), for either basis and a few
    /// seeds.
    #[test]
    fn filtered_means_are_the_filters() {
        for seed in [0, 1, 42] {
            let means = NoiseMeans::of(&noise_volume(seed));
            for basis in [NoiseBasis::Perlin, NoiseBasis::Worley] {
                let mean = |f| means.get(basis, f);
                let plain = mean(NoiseFilter::Stratus);
                assert!((plain - 0.5).abs() < 0.08, "{seed} {basis:?}: {plain}");
                assert!((mean(NoiseFilter::Wispy) - 0.5).abs() < 0.08);
                assert!(mean(NoiseFilter::Cumulus) < 0.32, "{seed} {basis:?}");
                assert!(mean(NoiseFilter::Veined) < 0.42, "{seed} {basis:?}");
            }
        }
    }

    #[test]
    fn a_tiers_keyed_wind_and_torque_carry_its_noise_by_their_integrals() {
        use crate::scene::{Channel, Tier, TierProperty};
        let mut scene = Scene::default();
        scene.render.noise_amount = 0.6;
        scene.render.wind = [0.0, 0.0];
        scene.render.tiers = vec![Tier {
            floor: -50.0,
            ..Default::default()
        }];
        let key = |s: &mut Scene, property, a: Vec<f32>, b: Vec<f32>| {
            let c = Channel::Tier { tier: 0, property };
            s.animation.key(c, 0.0, a);
            s.animation.key(c, 2.0, b);
        };
        // Wind from calm to 2 units/s and torque from 0 to 40°/s over 2 s: by then they have
        // carried the tier's noise as far as a steady 1 and 20 would; value × time twice as far.
        let mut keyed = scene.clone();
        key(
            &mut keyed,
            TierProperty::Wind,
            vec![0.0, 0.0],
            vec![2.0, 0.0],
        );
        key(&mut keyed, TierProperty::Torque, vec![0.0], vec![40.0]);
        let keyed = keyed.posed_at(2.0);
        assert_eq!(keyed.render.tiers[0].wind, [2.0, 0.0]);
        let steady = |w: f32, torque: f32| {
            let mut s = scene.clone();
            s.render.tiers[0].wind = [w, 0.0];
            s.render.tiers[0].torque = torque;
            s.time = 2.0;
            Media::new(&s)
        };
        let drift = Drifts::of(&keyed).tiers[0];
        assert!((drift.travelled[0] - 2.0).abs() < 1e-4 && (drift.turned - 40.0).abs() < 1e-3);
        let points: Vec<Vec3> = (0..400)
            .map(|i| Vec3::new((i % 20) as f32 * 0.2 - 2.0, (i / 20) as f32 * 0.15, 0.3))
            .collect();
        let sample = |m: &Media| {
            points
                .iter()
                .map(|&p| m.density(ISO, p))
                .collect::<Vec<_>>()
        };
        let got = sample(&Media::new(&keyed));
        let same = sample(&steady(1.0, 20.0));
        let far = sample(&steady(2.0, 40.0));
        let gap = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f32>();
        assert!(
            gap(&got, &same) < 1e-3,
            "as a steady wind: {}",
            gap(&got, &same)
        );
        assert!(gap(&got, &far) > 1.0, "value × time: {}", gap(&got, &far));
    }

    #[test]
    fn the_media_move_the_surface_and_off_they_leave_the_plain_density() {
        let mut scene = Scene::default();
        let media = Media::new(&scene);
        let points: Vec<Vec3> = (0..200)
            .map(|i| {
                Vec3::new(
                    i as f32 * 0.037,
                    (i % 7) as f32 * 0.11,
                    (i % 13) as f32 * 0.05,
                )
            })
            .collect();
        let moved = points
            .iter()
            .filter(|&&p| {
                (media.density(ISO, p) - density(ISO, scene.render.softness)).abs() > 0.05
            })
            .count();
        assert!(
            moved > 100,
            "the noise moves the surface at {moved} of 200 points"
        );
        scene.render.noise_octaves = 0;
        let plain = Media::new(&scene);
        for p in points {
            assert_eq!(plain.density(0.47, p), density(0.47, scene.render.softness));
        }
    }

    #[test]
    fn sampling_wraps_and_hits_texel_centres() {
        let media = Media::new(&Scene::default());
        let n = NOISE_SIZE as f32;
        let centre = Vec3::new(3.5, 7.5, 1.5) / n;
        assert!(
            (media.sample(centre)
                - media.texels[(NOISE_SIZE * NOISE_SIZE + 7 * NOISE_SIZE + 3) as usize])
                .abs()
                < 1e-6
        );
        assert!(
            (media.sample(centre) - media.sample(centre + Vec3::new(1.0, -2.0, 3.0))).abs() < 1e-4
        );
    }
}
