//! The physical sky (pure): Hillaire 2020's atmosphere ("A Scalable and Production Ready Sky
//! and Atmosphere Rendering Technique"). Rayleigh and Mie scattering with ozone absorption over
//! a spherical planet, precomputed as three tables:
//!
//! - the transmittance from a height toward a direction to the top of the atmosphere
//!   ([`transmittance`]);
//! - the light scattered any number of times, as the isotropic source Ψ of §5.5 (Hillaire's
//!   multiple-scattering table: the second order of scattering over the sphere of directions,
//!   divided by 1 − f_ms);
//! - the sky as seen from the eye ([`SkyTables::view`]): every direction's radiance, by its
//!   azimuth from the sun and its elevation (spaced finely near the horizon).
//!
//! Light is per unit of the sun's irradiance (radiance in 1/sr). The first two tables do not
//! depend on the sun and are made once; the sky as seen is made per sun elevation and kept for
//! the last one asked ([`sky`]). The renderer draws the sky from the view table, and the
//! document's light takes the sun's colour (through the air to the clouds' height) and the sky
//! light's (the mean of the sky above the horizon) from it ([`crate::scene::Lighting`]).
//! Distances are kilometres.

use std::f32::consts::{FRAC_PI_2, PI};
use std::sync::{Arc, Mutex, OnceLock};

use glam::Vec3;

/// The planet's radius.
const BOTTOM: f32 = 6360.0;
/// The top of the atmosphere's radius.
const TOP: f32 = 6460.0;
/// Rayleigh scattering at sea level, per km (Hillaire's table 1).
const RAYLEIGH: Vec3 = Vec3::new(5.802e-3, 13.558e-3, 33.1e-3);
const RAYLEIGH_HEIGHT: f32 = 8.0;
/// Mie scattering and extinction at sea level, per km.
const MIE_SCATTERING: f32 = 3.996e-3;
const MIE_EXTINCTION: f32 = 4.44e-3;
const MIE_HEIGHT: f32 = 1.2;
const MIE_G: f32 = 0.8;
/// Ozone's absorption at its peak, 25 km up, falling to nothing 15 km either side.
const OZONE: Vec3 = Vec3::new(0.650e-3, 1.881e-3, 0.085e-3);
const GROUND_ALBEDO: f32 = 0.3;

/// The eye's height above the ground.
pub const EYE_ALTITUDE: f32 = 0.5;
/// The clouds' height: where the sun's light that lights them is taken.
pub const CLOUD_ALTITUDE: f32 = 1.5;
/// The sun's angular radius (radians).
pub const SUN_RADIUS: f32 = 0.004_65;

/// Kilometres per world unit (a world unit is 100 m: the default cumulus is about a kilometre
/// across): the aerial perspective's scale.
pub const KM_PER_UNIT: f32 = 0.1;

/// The air's extinction per kilometre at the eye's height (what aerial perspective takes out of
/// a far cloud's light).
pub fn air_extinction() -> Vec3 {
    medium(EYE_ALTITUDE).extinction
}

/// The view table's size: azimuth from the sun (0 to π) × elevation (−π/2 to π/2).
pub const VIEW_SIZE: [usize; 2] = [64, 256];

const TRANSMITTANCE_SIZE: [usize; 2] = [128, 48];
const MULTIPLE_SIZE: [usize; 2] = [32, 32];

/// The scattering and extinction coefficients at height `h`.
struct Medium {
    rayleigh: Vec3,
    mie: f32,
    extinction: Vec3,
}

fn medium(h: f32) -> Medium {
    let h = h.max(0.0);
    let rayleigh = RAYLEIGH * (-h / RAYLEIGH_HEIGHT).exp();
    let m = (-h / MIE_HEIGHT).exp();
    let ozone = (1.0 - (h - 25.0).abs() / 15.0).max(0.0);
    Medium {
        rayleigh,
        mie: MIE_SCATTERING * m,
        extinction: rayleigh + Vec3::splat(MIE_EXTINCTION * m) + OZONE * ozone,
    }
}

fn rayleigh_phase(nu: f32) -> f32 {
    3.0 / (16.0 * PI) * (1.0 + nu * nu)
}

/// Cornette–Shanks.
fn mie_phase(nu: f32) -> f32 {
    let g2 = MIE_G * MIE_G;
    3.0 / (8.0 * PI) * (1.0 - g2) * (1.0 + nu * nu)
        / ((2.0 + g2) * (1.0 + g2 - 2.0 * MIE_G * nu).max(1e-6).powf(1.5))
}

/// Where the ray from `p` along unit `d` leaves the atmosphere, and where it meets the ground
/// first, if it does.
fn ray_ends(p: Vec3, d: Vec3) -> (f32, Option<f32>) {
    let b = p.dot(d);
    let c = p.length_squared();
    let top = -b + (b * b - (c - TOP * TOP)).max(0.0).sqrt();
    let disc = b * b - (c - BOTTOM * BOTTOM);
    let ground = (disc >= 0.0).then(|| -b - disc.sqrt()).filter(|&t| t > 0.0);
    (top, ground)
}

/// A table of colours over [0, 1]², its nodes at i / (w − 1), read bilinearly.
struct Table {
    size: [usize; 2],
    texels: Vec<Vec3>,
}

impl Table {
    /// The table of `f` at every node, its rows dealt out in turn among the machine's cores
    /// (rows below the horizon cost less than rows above; each node is computed alone, so the
    /// table is the same however many cores there are; one in the browser).
    fn make(size: [usize; 2], f: impl Fn(f32, f32) -> Vec3 + Sync) -> Self {
        let [w, h] = size;
        let row = |j: usize| {
            (0..w)
                .map(move |i| (i, j))
                .map(|(i, j)| f(i as f32 / (w - 1) as f32, j as f32 / (h - 1) as f32))
        };
        let threads = crate::limits::cores().min(h);
        let texels = if threads <= 1 {
            (0..h).flat_map(row).collect()
        } else {
            // Thread t makes rows t, t + threads, t + 2·threads, …
            let parts: Option<Vec<Vec<Vec3>>> = std::thread::scope(|scope| {
                let handles: Vec<_> = (0..threads)
                    .map(|t| {
                        let row = &row;
                        scope.spawn(move || (t..h).step_by(threads).flat_map(row).collect())
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().ok()).collect()
            });
            match parts {
                Some(parts) => (0..h)
                    .flat_map(|j| {
                        let at = (j / threads) * w;
                        parts[j % threads][at..at + w].iter().copied()
                    })
                    .collect(),
                None => (0..h).flat_map(row).collect(),
            }
        };
        Self { size, texels }
    }

    fn sample(&self, u: f32, v: f32) -> Vec3 {
        bilinear(self.size, |k| self.texels[k], u, v)
    }
}

/// The bilinear reading at (u, v) of a table of `size` nodes, node k (row-major) being `at(k)`.
fn bilinear(size: [usize; 2], at: impl Fn(usize) -> Vec3, u: f32, v: f32) -> Vec3 {
    let [w, h] = size;
    let x = u.clamp(0.0, 1.0) * (w - 1) as f32;
    let y = v.clamp(0.0, 1.0) * (h - 1) as f32;
    let (i, j) = ((x as usize).min(w - 2), (y as usize).min(h - 2));
    let (fx, fy) = (x - i as f32, y - j as f32);
    let node = |i: usize, j: usize| at(j * w + i);
    node(i, j)
        .lerp(node(i + 1, j), fx)
        .lerp(node(i, j + 1).lerp(node(i + 1, j + 1), fx), fy)
}

/// Height → table coordinate (finer near the ground).
fn height_to_v(h: f32) -> f32 {
    (h / (TOP - BOTTOM)).clamp(0.0, 1.0).sqrt()
}

fn v_to_height(v: f32) -> f32 {
    v * v * (TOP - BOTTOM)
}

/// Cosine from the zenith → table coordinate (finer near the horizon).
fn mu_to_u(mu: f32) -> f32 {
    0.5 + 0.5 * mu.signum() * mu.abs().sqrt()
}

fn u_to_mu(u: f32) -> f32 {
    let x = 2.0 * u - 1.0;
    x.signum() * x * x
}

/// The point `h` above the ground and a direction whose cosine from its zenith is `mu`.
fn point_and_direction(h: f32, mu: f32) -> (Vec3, Vec3) {
    let mu = mu.clamp(-1.0, 1.0);
    (
        Vec3::new(0.0, BOTTOM + h, 0.0),
        Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), mu, 0.0),
    )
}

/// The optical depth from `p` along `d` to the top of the atmosphere, by `steps` midpoints.
fn optical_depth(p: Vec3, d: Vec3, steps: usize) -> Vec3 {
    let (top, _) = ray_ends(p, d);
    let dt = top / steps as f32;
    (0..steps).fold(Vec3::ZERO, |sum, i| {
        let x = p + d * ((i as f32 + 0.5) * dt);
        sum + medium(x.length() - BOTTOM).extinction * dt
    })
}

fn transmittance_table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        Table::make(TRANSMITTANCE_SIZE, |u, v| {
            let (p, d) = point_and_direction(v_to_height(v), u_to_mu(u));
            (-optical_depth(p, d, 40)).exp()
        })
    })
}

/// The transmittance from point `p` (planet-centred) toward unit `d`, up to the top of the
/// atmosphere: nothing where the ground is in the way.
fn toward(p: Vec3, d: Vec3) -> Vec3 {
    let r = p.length();
    if ray_ends(p, d).1.is_some() {
        return Vec3::ZERO;
    }
    transmittance_table().sample(mu_to_u(p.dot(d) / r), height_to_v(r - BOTTOM))
}

/// The transmittance from height `h` (km) toward a direction `elevation` radians above the
/// horizon, to the top of the atmosphere (nothing below the planet's horizon).
pub fn transmittance(h: f32, elevation: f32) -> Vec3 {
    let (p, d) = point_and_direction(h, elevation.sin());
    toward(p, d)
}

/// Segment boundaries along a ray of `length`: squared spacing, finer near its start.
fn boundaries(length: f32, steps: usize) -> impl Iterator<Item = (f32, f32)> {
    (0..steps).map(move |i| {
        let t = |k: usize| length * (k as f32 / steps as f32).powi(2);
        (t(i), t(i + 1))
    })
}

/// Directions spread evenly over the sphere (a Fibonacci lattice).
fn sphere_directions(n: usize) -> impl Iterator<Item = Vec3> {
    let golden = PI * (3.0 - 5f32.sqrt());
    (0..n).map(move |i| {
        let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let r = (1.0 - y * y).max(0.0).sqrt();
        let a = golden * i as f32;
        Vec3::new(r * a.cos(), y, r * a.sin())
    })
}

/// Ψ_ms: the light scattered two or more times, per unit of sun, as an isotropic source
/// (Hillaire §5.5), by height and the sun's cosine from the zenith.
fn multiple_table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        Table::make(MULTIPLE_SIZE, |u, v| {
            let (p, sun) = point_and_direction(v_to_height(v), 2.0 * u - 1.0);
            let (mut second, mut f_ms) = (Vec3::ZERO, Vec3::ZERO);
            const DIRECTIONS: usize = 64;
            for d in sphere_directions(DIRECTIONS) {
                let (top, ground) = ray_ends(p, d);
                let length = ground.unwrap_or(top);
                let mut seen = Vec3::ONE;
                for (t0, t1) in boundaries(length, 20) {
                    let x = p + d * (0.5 * (t0 + t1));
                    let m = medium(x.length() - BOTTOM);
                    let scattering = m.rayleigh + Vec3::splat(m.mie);
                    let step = (-m.extinction * (t1 - t0)).exp();
                    let through = (seen - seen * step) / m.extinction.max(Vec3::splat(1e-9));
                    second += through * scattering * toward(x, sun) / (4.0 * PI);
                    f_ms += through * scattering;
                    seen *= step;
                }
                if let Some(t) = ground {
                    let x = p + d * t;
                    let cos = (x.normalize().dot(sun)).max(0.0);
                    second += seen * toward(x, sun) * (GROUND_ALBEDO / PI * cos);
                }
            }
            second /= DIRECTIONS as f32;
            f_ms /= DIRECTIONS as f32;
            second / (Vec3::ONE - f_ms).max(Vec3::splat(1e-3))
        })
    })
}

fn multiple(x: Vec3, sun: Vec3) -> Vec3 {
    let r = x.length();
    multiple_table().sample(0.5 + 0.5 * x.dot(sun) / r, height_to_v(r - BOTTOM))
}

/// The sky's radiance seen from the eye along unit `d`, the sun along unit `sun` (y up),
/// marched in `steps`; `with_multiple`: the light scattered more than once too.
fn march_view(d: Vec3, sun: Vec3, steps: usize, with_multiple: bool) -> Vec3 {
    let p = Vec3::new(0.0, BOTTOM + EYE_ALTITUDE, 0.0);
    let (top, ground) = ray_ends(p, d);
    let nu = d.dot(sun);
    let (pr, pm) = (rayleigh_phase(nu), mie_phase(nu));
    let mut seen = Vec3::ONE;
    let mut light = Vec3::ZERO;
    for (t0, t1) in boundaries(ground.unwrap_or(top), steps) {
        let x = p + d * (0.5 * (t0 + t1));
        let m = medium(x.length() - BOTTOM);
        let mut source = (m.rayleigh * pr + Vec3::splat(m.mie * pm)) * toward(x, sun);
        if with_multiple {
            source += (m.rayleigh + Vec3::splat(m.mie)) * multiple(x, sun);
        }
        let step = (-m.extinction * (t1 - t0)).exp();
        light += (seen - seen * step) * source / m.extinction.max(Vec3::splat(1e-9));
        seen *= step;
    }
    if let Some(t) = ground {
        let x = p + d * t;
        let cos = x.normalize().dot(sun).max(0.0);
        light += seen * toward(x, sun) * (GROUND_ALBEDO / PI * cos);
    }
    light
}

/// The view table's elevation coordinate of `elevation` (radians): finer near the horizon.
pub fn elevation_to_v(elevation: f32) -> f32 {
    let l = (elevation / FRAC_PI_2).clamp(-1.0, 1.0);
    0.5 + 0.5 * l.signum() * l.abs().sqrt()
}

fn v_to_elevation(v: f32) -> f32 {
    let x = 2.0 * v - 1.0;
    x.signum() * x * x * FRAC_PI_2
}

/// The direction `elevation` up from the horizon, `azimuth` round from the sun's side.
fn view_direction(azimuth: f32, elevation: f32) -> Vec3 {
    Vec3::new(
        elevation.cos() * azimuth.cos(),
        elevation.sin(),
        elevation.cos() * azimuth.sin(),
    )
}

/// The sky for one sun elevation.
pub struct SkyTables {
    /// The sun's elevation (radians) these are for.
    pub sun_elevation: f32,
    /// The sky's radiance seen from the eye, [`VIEW_SIZE`] texels, row-major, by azimuth from
    /// the sun (u = azimuth / π) and elevation ([`elevation_to_v`]); texel (i, j) is at
    /// u = i / (w − 1), v = j / (h − 1).
    pub view: Vec<[f32; 3]>,
    /// The sun's transmittance down to the eye (the sun disk's colour).
    pub sun_at_eye: Vec3,
    /// The sun's transmittance down to the clouds' height (the colour of their sunlight).
    pub sun_at_clouds: Vec3,
    /// The mean radiance of the sky above the horizon (the clouds' sky light).
    pub sky_mean: Vec3,
    /// The sky's light on level ground, as the one radiance from the whole sky that would
    /// light it as much (its irradiance / π: the mean weighted by each direction's cosine).
    pub sky_on_ground: Vec3,
}

impl SkyTables {
    /// Made by marching every view texel (cost: [`VIEW_SIZE`] × 32 steps).
    pub fn new(sun_elevation: f32) -> Self {
        let sun = view_direction(0.0, sun_elevation);
        let table = Table::make(VIEW_SIZE, |u, v| {
            march_view(view_direction(u * PI, v_to_elevation(v)), sun, 32, true)
        });
        // The upper hemisphere's mean, each direction weighted by its solid angle; and as it
        // lights the ground, weighted by its cosine from the zenith too.
        let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
        let (mut on_ground, mut ground_weight) = (Vec3::ZERO, 0.0);
        for j in 0..24 {
            let elevation = (j as f32 + 0.5) / 24.0 * FRAC_PI_2;
            for i in 0..32 {
                let azimuth = (i as f32 + 0.5) / 32.0 * PI;
                let w = elevation.cos();
                let l = table.sample(azimuth / PI, elevation_to_v(elevation));
                sum += l * w;
                weight += w;
                on_ground += l * (w * elevation.sin());
                ground_weight += w * elevation.sin();
            }
        }
        Self {
            sun_elevation,
            view: table.texels.iter().map(|c| c.to_array()).collect(),
            sun_at_eye: transmittance(EYE_ALTITUDE, sun_elevation),
            sun_at_clouds: transmittance(CLOUD_ALTITUDE, sun_elevation),
            sky_mean: sum / weight,
            sky_on_ground: on_ground / ground_weight,
        }
    }

    /// The sky's radiance along unit `d` (y up) with the sun at `azimuth` (radians, from +x
    /// toward +z, as [`crate::scene::Lighting::sun_direction`]), from the view table.
    pub fn radiance(&self, d: Vec3, sun_azimuth: f32) -> Vec3 {
        let elevation = d.y.clamp(-1.0, 1.0).asin();
        let horizontal = Vec3::new(d.x, 0.0, d.z).normalize_or(Vec3::X);
        let sun = Vec3::new(sun_azimuth.cos(), 0.0, sun_azimuth.sin());
        let azimuth = horizontal.dot(sun).clamp(-1.0, 1.0).acos();
        bilinear(
            VIEW_SIZE,
            |k| Vec3::from(self.view[k]),
            azimuth / PI,
            elevation_to_v(elevation),
        )
    }
}

/// The skies made last, by sun elevation (its bits), the most recently asked first.
pub struct SkyCache {
    kept: Mutex<Vec<(u32, Arc<SkyTables>)>>,
}

impl SkyCache {
    /// How many skies are kept: a slider's few last positions, or an image and the viewport
    /// posed at two elevations, each made once.
    pub const KEPT: usize = 4;

    /// An empty cache.
    pub const fn new() -> Self {
        Self {
            kept: Mutex::new(Vec::new()),
        }
    }

    /// The sky for the sun `elevation_deg` degrees up, made if it is not kept.
    pub fn get(&self, elevation_deg: f32) -> Arc<SkyTables> {
        let key = elevation_deg.to_bits();
        let mut kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(i) = kept.iter().position(|(k, _)| *k == key) {
            let hit = kept.remove(i);
            kept.insert(0, hit.clone());
            return hit.1;
        }
        let tables = Arc::new(SkyTables::new(elevation_deg.to_radians()));
        kept.insert(0, (key, tables.clone()));
        kept.truncate(Self::KEPT);
        tables
    }
}

impl Default for SkyCache {
    fn default() -> Self {
        Self::new()
    }
}

/// The sky for the sun `elevation_deg` degrees up, from the one cache every caller shares (a
/// scene drawn frame after frame makes it once).
pub fn sky(elevation_deg: f32) -> Arc<SkyTables> {
    static CACHE: SkyCache = SkyCache::new();
    CACHE.get(elevation_deg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// However its rows are dealt out among the cores, each node holds `f` at its own (u, v):
    /// against the plain evaluation of every node, for an odd number of rows.
    #[test]
    fn a_table_made_on_many_cores_is_the_table_made_on_one() {
        let size = [5, 37];
        let f = |u: f32, v: f32| Vec3::new(u, v, u * v + 1.0);
        let table = Table::make(size, f);
        assert_eq!(table.texels.len(), 5 * 37);
        for j in 0..37 {
            for i in 0..5 {
                let want = f(i as f32 / 4.0, j as f32 / 36.0);
                assert_eq!(table.texels[j * 5 + i], want, "node ({i}, {j})");
            }
        }
    }

    fn luminance(c: Vec3) -> f32 {
        c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
    }

    #[test]
    fn the_noon_sky_is_blue_and_brighter_toward_the_horizon() {
        let sky = SkyTables::new(60f32.to_radians());
        let zenith = sky.radiance(Vec3::Y, PI);
        let horizon = sky.radiance(view_direction(FRAC_PI_2, 0.05), 0.0);
        assert!(zenith.z > 1.5 * zenith.x && zenith.z > zenith.y, "{zenith}");
        assert!(
            luminance(horizon) > luminance(zenith),
            "{horizon} vs {zenith}"
        );
        // Whiter near the horizon: its blue-to-red ratio is smaller.
        assert!(horizon.z / horizon.x < zenith.z / zenith.x);
    }

    #[test]
    fn a_low_sun_is_reddened_and_the_sky_beside_it_warm() {
        let noon = SkyTables::new(60f32.to_radians());
        let low = SkyTables::new(2f32.to_radians());
        let ratio = |c: Vec3| c.x / c.z;
        assert!(ratio(low.sun_at_clouds) > 3.0 * ratio(noon.sun_at_clouds));
        assert!(luminance(low.sun_at_clouds) < luminance(noon.sun_at_clouds));
        let beside = low.radiance(view_direction(0.0, 0.03), 0.0);
        let away = low.radiance(view_direction(PI, 0.03), 0.0);
        assert!(ratio(beside) > ratio(away), "{beside} vs {away}");
        assert!(luminance(beside) > 2.0 * luminance(away));
        // And the sky dims as the sun sets.
        assert!(luminance(low.sky_mean) < 0.5 * luminance(noon.sky_mean));
        // Below the horizon, still a glow from light scattered over the edge.
        let dusk = SkyTables::new(-4f32.to_radians());
        assert_eq!(dusk.sun_at_clouds, Vec3::ZERO);
        assert!(luminance(dusk.sky_mean) > 0.0);
        assert!(luminance(dusk.sky_mean) < 0.2 * luminance(low.sky_mean));
    }

    #[test]
    fn the_tables_agree_with_a_brute_force_march() {
        // Single scattering, every sun transmittance integrated exactly instead of read from
        // the table, 400 steps: the table's reading may differ by a few percent.
        let sun = view_direction(0.0, 20f32.to_radians());
        for (azimuth, elevation) in [(0.3, 0.02), (2.0, 0.3), (1.0, 1.2), (3.0, 0.01)] {
            let d = view_direction(azimuth, elevation);
            let table = march_view(d, sun, 32, false);
            let p = Vec3::new(0.0, BOTTOM + EYE_ALTITUDE, 0.0);
            let (top, _) = ray_ends(p, d);
            let nu = d.dot(sun);
            let steps = 400;
            let dt = top / steps as f32;
            let (mut seen_depth, mut light) = (Vec3::ZERO, Vec3::ZERO);
            for i in 0..steps {
                let x = p + d * ((i as f32 + 0.5) * dt);
                let m = medium(x.length() - BOTTOM);
                let depth = seen_depth + m.extinction * (0.5 * dt);
                let sun_t = (-optical_depth(x, sun, 200)).exp();
                light += (-depth).exp()
                    * (m.rayleigh * rayleigh_phase(nu) + Vec3::splat(m.mie * mie_phase(nu)))
                    * sun_t
                    * dt;
                seen_depth += m.extinction * dt;
            }
            let error = ((table - light) / light).abs().max_element();
            assert!(error < 0.06, "{azimuth},{elevation}: {table} vs {light}");
        }
    }

    #[test]
    fn multiple_scattering_adds_light_most_where_the_sky_is_dim() {
        let sun = view_direction(0.0, 30f32.to_radians());
        let d = view_direction(PI, 1.2);
        let single = march_view(d, sun, 32, false);
        let all = march_view(d, sun, 32, true);
        assert!(all.min_element() > 0.0 && (all - single).min_element() > 0.0);
        // A few tens of percent, not a multiple.
        assert!(
            luminance(all) < 2.0 * luminance(single),
            "{all} vs {single}"
        );
    }

    #[test]
    fn the_sun_at_the_sliders_ends_gives_a_finite_sky() {
        // The elevation slider's ends (±89°) and the horizon: every texel finite and not
        // negative, no light from a sun under the ground, and a sky that still glows from
        // above a sun just below the horizon's edge.
        for e in [-89.0f32, -0.5, 0.0, 89.0] {
            let sky = SkyTables::new(e.to_radians());
            assert!(
                sky.view
                    .iter()
                    .flatten()
                    .all(|v| v.is_finite() && *v >= 0.0),
                "{e}°"
            );
            for v in [
                sky.sun_at_eye,
                sky.sun_at_clouds,
                sky.sky_mean,
                sky.sky_on_ground,
            ] {
                assert!(v.is_finite() && v.min_element() >= 0.0, "{e}°: {v}");
            }
        }
        assert_eq!(
            SkyTables::new(-89f32.to_radians()).sun_at_clouds,
            Vec3::ZERO
        );
        assert!(luminance(SkyTables::new(89f32.to_radians()).sky_mean) > 0.0);
    }

    #[test]
    fn the_skies_asked_last_are_kept() {
        // A cache of the test's own: others' tests ask the shared one meanwhile.
        let cache = SkyCache::new();
        let a = cache.get(12.5);
        assert!(Arc::ptr_eq(&a, &cache.get(12.5)));
        let b = cache.get(13.0);
        assert!(!Arc::ptr_eq(&a, &b) && a.sun_elevation != b.sun_elevation);
        // Up to KEPT elevations stay; the one asked longest ago goes first.
        for e in [14.0, 15.0, 16.0] {
            cache.get(e);
        }
        assert!(Arc::ptr_eq(&b, &cache.get(13.0)));
        assert!(!Arc::ptr_eq(&a, &cache.get(12.5)));
    }
}
