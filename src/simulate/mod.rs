//! Cloud simulation by cellular automaton (Dobashi et al. 2000; pure): the bit-parallel
//! automaton, steered by ellipsoid parcels, its wind by height, and the smoothing of its cloud
//! bits into a density volume the renderer and the exporters take like any other.
//!
//! - `automaton`: the state, the growth rules, the random masks, the wind;
//! - `lanes`: a word of cells or two side by side (one SIMD register on the web build), as
//!   the rule takes them;
//! - `reference`: the same rules one byte per cell (the tests' reference, the bench's baseline);
//! - `smoothing`: the box counts of the cloud bits, eight cells a word in byte lanes (summed
//!   bit-sliced, 64 cells at a time, for boxes whose counts pass a byte);
//! - here: [`Settings`] → [`Simulation`] (parcels → per-cell probability levels), stepping,
//!   and [`Simulation::density`] (a box kernel over the cloud bits, interpolated between steps);
//!   the sharing of a step's or a smoothing's parts among threads.

mod automaton;
mod lanes;
pub mod reference;
mod smoothing;

pub use automaton::{Automaton, Kind, LEVELS, State, level_of, shift_row};

use glam::{Quat, UVec3, Vec3};

use crate::density::DensityVolume;

/// An air parcel: inside it vapour and activation are re-supplied and cloud persists; outside,
/// clouds dissolve. Its influence falls off toward its surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parcel {
    /// World centre.
    pub center: Vec3,
    /// Semi-axes.
    pub radii: Vec3,
    /// Orientation.
    pub rotation: Quat,
}

impl Parcel {
    /// The parcel an ellipsoid places (where it stands, its size and turn).
    pub fn of(e: &crate::scene::Ellipsoid) -> Self {
        Self {
            center: e.center,
            radii: e.radii,
            rotation: e.rotation,
        }
    }

    /// Half the sides of the smallest box along the world's axes that holds it (a little
    /// more, for rounding): where its weight can be above 0.
    pub fn reach(&self) -> Vec3 {
        let m = glam::Mat3::from_quat(self.rotation);
        let axes = [m.x_axis, m.y_axis, m.z_axis];
        let r = self.radii.max(Vec3::splat(1e-4));
        let side = |i: usize| {
            (0..3)
                .map(|j| (axes[j][i] * r[j]).powi(2))
                .sum::<f32>()
                .sqrt()
        };
        Vec3::new(side(0), side(1), side(2)) * 1.001 + Vec3::splat(1e-4)
    }

    /// The cells of row `(y, z)` of `settings`' grid, within `within` (a range of x), that it
    /// may weigh above 0: where the row's line crosses it, a cell wider each way for rounding
    /// (each cell is still weighed); `None` where the line misses it.
    fn cells_along_x(
        &self,
        settings: &Settings,
        y: usize,
        z: usize,
        within: (usize, usize),
    ) -> Option<(usize, usize)> {
        let h = settings.cell_size.max(1e-3);
        let inverse = self.rotation.inverse();
        let r = self.radii.max(Vec3::splat(1e-4));
        // local(t) = a + t b along the row, t the world x: inside where |local|² < 1.
        let on_row = settings.center(0, y, z);
        let a = inverse * (Vec3::new(0.0, on_row.y, on_row.z) - self.center) / r;
        let b = inverse * Vec3::X / r;
        let (bb, ab, aa) = (b.dot(b), a.dot(b), a.dot(a));
        let disc = ab * ab - bb * (aa - 1.0);
        if disc < 0.0 || bb <= 0.0 {
            return None;
        }
        let root = disc.sqrt();
        let (t0, t1) = ((-ab - root) / bb, (-ab + root) / bb);
        let x0 = settings.origin[0];
        let from = ((t0 - x0) / h - 0.5).floor() - 1.0;
        let to = ((t1 - x0) / h - 0.5).ceil() + 2.0;
        let from = (from.max(0.0) as usize).max(within.0);
        let to = (to.max(0.0) as usize).min(within.1);
        (from < to).then_some((from, to))
    }

    /// 1 at the centre, 0 at and beyond the surface (smoothly).
    pub fn weight(&self, p: Vec3) -> f32 {
        let local = self.rotation.inverse() * (p - self.center) / self.radii.max(Vec3::splat(1e-4));
        let s = (1.0 - local.length_squared()).clamp(0.0, 1.0);
        s * s * (3.0 - 2.0 * s)
    }
}

pub use crate::scene::{MAX_CELLS, SimulationSettings as Settings};

/// A simulation run: the automaton at its current step and the density of the step before.
#[derive(Clone, Debug)]
pub struct Simulation {
    settings: Settings,
    automaton: Automaton,
    /// Where the parcels stand over time.
    sources: Sources,
    /// The first step of the interval whose parcels the automaton's probabilities hold.
    steered_at: u64,
    /// Steps per interval of posing the moving parcels (a power of two, 1 to
    /// [`SOURCE_EVERY`]), from their sampled speed ([`interval`]).
    posing_every: u64,
}

/// Most steps between two posings of moving parcels: the automaton's probabilities follow
/// keyed or moving parcels in intervals of [`Simulation::posing_every`] steps, at most this
/// many (0.8 s at the default rate), each from where they stand at its first step, so a step's
/// probabilities depend on its number alone. (A power of two: intervals tile the player's
/// snapshots.)
pub const SOURCE_EVERY: u64 = 8;

/// How far, in cells, a parcel may move within one interval: parcels faster than this are
/// posed more often, down to every step, so a step's parcels stand within about a cell of
/// where they are at that step (by their motion sampled 128 times over the frame range: motion
/// faster than the samples, or past the range's end, is not seen). (The `simulated` preset's
/// turbulent breeze moves its parcels about 1.2 of its cells in 8 steps: posed every 4. A bound of a quarter cell would pose them every step,
/// which with today's whole-box re-steering costs about 6× the run.)
pub const SOURCE_DRIFT_CELLS: f32 = 1.0;

/// Points in time the parcels' speed is sampled at, over the scene's frame range.
const SPEED_SAMPLES: usize = 128;

/// The parcels of a run over time: fixed, or posed from the scene's keys and motion at the
/// first step of each interval of [`Simulation::posing_every`] steps.
#[derive(Clone, Debug)]
pub struct Sources {
    /// Where they stand at time 0.
    start: Vec<Parcel>,
    /// What poses them (the scene's ellipsoids posed at 0, their keys, the wind field and the
    /// seed), when any of them is keyed or moves.
    moving: Option<Box<crate::scene::Scene>>,
    /// The end of the scene's frame range in seconds: what the parcels' speed is sampled over.
    end: f32,
}

impl PartialEq for Sources {
    fn eq(&self, other: &Self) -> bool {
        self.start == other.start
            && self.end == other.end
            && match (&self.moving, &other.moving) {
                (None, None) => true,
                (Some(a), Some(b)) => {
                    a.ellipsoids == b.ellipsoids
                        && a.animation.same_as(&b.animation)
                        && a.wind_field == b.wind_field
                        && a.seed == b.seed
                }
                _ => false,
            }
    }
}

impl Sources {
    /// Parcels that never move.
    pub fn fixed(parcels: Vec<Parcel>) -> Self {
        Self {
            start: parcels,
            moving: None,
            end: 1.0,
        }
    }

    /// The parcels of `scene` (its visible ellipsoids) as its keys and motion move them from
    /// time 0 on, whatever its time.
    pub fn of(scene: &crate::scene::Scene) -> Self {
        use crate::scene::{Channel, EllipsoidProperty};
        if !scene.is_animated() {
            return Self::fixed(parcels(scene));
        }
        let start = scene.posed_at(0.0);
        let keyed: Vec<_> = start
            .animation
            .tracks
            .iter()
            // What places a parcel: where it stands, its size, turn and visibility.
            .filter(|t| {
                matches!(
                    t.channel,
                    Channel::Ellipsoid {
                        property: EllipsoidProperty::Center
                            | EllipsoidProperty::Radii
                            | EllipsoidProperty::Rotation
                            | EllipsoidProperty::Visible,
                        ..
                    }
                )
            })
            .cloned()
            .collect();
        let moves = !keyed.is_empty() || start.ellipsoids.iter().any(|e| e.motion.is_some());
        if !moves {
            return Self::fixed(parcels(&start));
        }
        static BLANK: std::sync::OnceLock<crate::scene::Scene> = std::sync::OnceLock::new();
        let blank = BLANK.get_or_init(|| crate::scene::Scene::preset(crate::scene::Preset::Empty));
        let moving = crate::scene::Scene {
            ellipsoids: start.ellipsoids.clone(),
            animation: crate::scene::Animation { tracks: keyed },
            wind_field: start.wind_field,
            seed: start.seed,
            time: 0.0,
            ..blank.clone()
        };
        Self {
            start: parcels(&start),
            moving: Some(Box::new(moving)),
            end: scene.clock.seconds(scene.clock.end).max(1.0),
        }
    }

    /// Whether they move.
    pub fn moves(&self) -> bool {
        self.moving.is_some()
    }

    /// Where every one of the scene's ellipsoids stands at `seconds`, hidden ones included, in
    /// the scene's order (so two times' lists pair up one by one, whatever shows or hides).
    fn all_at(&self, seconds: f32) -> Vec<Parcel> {
        match &self.moving {
            Some(scene) => scene
                .posed_at(seconds)
                .ellipsoids
                .iter()
                .map(|e| Parcel::of(e))
                .collect(),
            None => self.start.clone(),
        }
    }

    /// Where they stand at `seconds`.
    pub fn at(&self, seconds: f32) -> Vec<Parcel> {
        match &self.moving {
            Some(scene) => parcels(&scene.posed_at(seconds)),
            None => self.start.clone(),
        }
    }
}

impl Simulation {
    /// A fresh run of `settings` steered by `parcels`: empty sky, vapour and activation then
    /// re-supplied inside the parcels each step.
    pub fn new(settings: &Settings, parcels: &[Parcel]) -> Self {
        Self::steered(settings, Sources::fixed(parcels.to_vec()))
    }

    /// A fresh run of `settings` steered by `sources`: the parcels as they stand at each
    /// interval of [`Simulation::posing_every`] steps (at the settings' rate).
    pub fn steered(settings: &Settings, sources: Sources) -> Self {
        let posing_every = if sources.moves() {
            interval(settings, sources.end, |t| sources.all_at(t))
        } else {
            SOURCE_EVERY
        };
        let dims = settings.dims();
        let mut automaton = Automaton::new(dims, settings.seed);
        steer(&mut automaton, settings, &sources.start);
        let ny = dims[1].max(2);
        let [bottom, top] = settings.wind;
        automaton.set_wind(|y| bottom + (top - bottom) * y as f32 / (ny - 1) as f32);
        Self {
            settings: settings.clone(),
            automaton,
            sources,
            steered_at: 0,
            posing_every,
        }
    }

    /// A snapshot of the run's state.
    pub fn state(&self) -> State {
        self.automaton.state()
    }

    /// Goes back (or forward) to a snapshot of this run.
    pub fn restore(&mut self, state: &State) {
        // (The next step sets the probabilities of its interval if they are another's.)
        self.automaton.restore(state);
    }

    /// The settings it runs.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Uses at most `n` threads per step (`None`: every core; see [`Automaton::set_threads`]).
    pub fn set_threads(&mut self, n: Option<usize>) {
        self.automaton.set_threads(n);
    }

    /// Runs the rule on pairs of words or a word at a time (see [`Automaton::set_paired`]).
    pub fn set_paired(&mut self, paired: bool) {
        self.automaton.set_paired(paired);
    }

    /// The automaton.
    pub fn automaton(&self) -> &Automaton {
        &self.automaton
    }

    /// Steps per posing of its moving parcels: [`SOURCE_EVERY`], or fewer where a parcel moves
    /// more than [`SOURCE_DRIFT_CELLS`] in that many steps somewhere in the scene's range.
    pub fn posing_every(&self) -> u64 {
        self.posing_every
    }

    /// Steps taken.
    pub fn step(&self) -> u64 {
        self.automaton.step
    }

    /// Advances `n` steps (moving parcels posed at each interval's first step).
    pub fn advance(&mut self, n: u64) {
        for _ in 0..n {
            if self.sources.moves() {
                let step = self.automaton.step;
                let first = step - step % self.posing_every;
                if self.steered_at != first {
                    let seconds = first as f32 / self.settings.rate.max(1e-3);
                    steer(
                        &mut self.automaton,
                        &self.settings,
                        &self.sources.at(seconds),
                    );
                    self.steered_at = first;
                }
            }
            self.automaton.advance();
        }
    }

    /// The cloud bits smoothed by a box kernel of half-width `smoothing` cells: each cell's
    /// count of cloud cells around it ([`Smoothed::shares`] gives the share in [0, 1]), in a
    /// density volume's order (x fastest, then y, then z).
    pub fn smoothed(&self) -> Smoothed {
        self.smoothed_over(Smoothed::default())
    }

    /// The same, written over `old` (a smoothed step no longer needed, whose memory it reuses).
    pub fn smoothed_over(&self, old: Smoothed) -> Smoothed {
        smoothing::smooth(
            &self.automaton,
            self.settings.smoothing as usize,
            old.counts,
        )
    }

    /// The density volume of the current step (`previous`: the last step's smoothed cloud,
    /// blended with weight `1 − t`, so playback between steps is smooth).
    pub fn density(&self, previous: Option<&Smoothed>, t: f32) -> DensityVolume {
        let now = self.smoothed();
        let values = match previous.filter(|p| p.counts.len() == now.counts.len()) {
            Some(p) => p.blend(&now, t),
            None => now.shares(),
        };
        volume(&self.settings, self.automaton.dims, values)
    }
}

/// Steps per posing of parcels that `pose` places at a time in seconds (every ellipsoid, hidden
/// ones too, in one order), for a run of `settings` over `[0, end]` s: the largest power of two
/// up to [`SOURCE_EVERY`] in which no parcel's box (its centre, and its reach as it grows or
/// turns) moves more than [`SOURCE_DRIFT_CELLS`], by the fastest motion sampled over the range.
fn interval(settings: &Settings, end: f32, pose: impl Fn(f32) -> Vec<Parcel>) -> u64 {
    let dt = end / SPEED_SAMPLES as f32;
    let steps_per_sample = (dt * settings.rate.max(1e-3)).max(1e-6);
    let mut fastest = 0.0f32; // world units per step
    let mut before = pose(0.0);
    for k in 1..=SPEED_SAMPLES {
        let now = pose(dt * k as f32);
        for (a, b) in before.iter().zip(&now) {
            let moved = (b.center - a.center).abs().max_element()
                + (b.reach() - a.reach()).abs().max_element();
            fastest = fastest.max(moved / steps_per_sample);
        }
        before = now;
    }
    let drift = SOURCE_DRIFT_CELLS * settings.cell_size.max(1e-3);
    let mut every = SOURCE_EVERY;
    while every > 1 && fastest * every as f32 > drift {
        every /= 2;
    }
    every
}

/// Sets the automaton's re-supply and extinction probabilities from `parcels` (Dobashi et al.
/// 2000: vapour and activation re-supplied inside them, cloud dissolving outside).
fn steer(automaton: &mut Automaton, settings: &Settings, parcels: &[Parcel]) {
    let dims = automaton.dims;
    let origin = Vec3::from(settings.origin);
    let h = settings.cell_size.max(1e-3);
    // Each parcel's box of cells (the rows it may cross).
    let boxes: Vec<([usize; 3], [usize; 3])> = parcels
        .iter()
        .map(|q| {
            let reach = q.reach();
            let cell = |v: Vec3, up: bool| {
                let c = (v - origin) / h - 0.5;
                let c = if up { c.ceil() } else { c.floor() };
                [0, 1, 2].map(|i| (c[i].max(0.0) as usize).min(dims[i]))
            };
            (cell(q.center - reach, false), cell(q.center + reach, true))
        })
        .collect();
    // Per row (y, z), the span of cells some parcel weighs above 0 and their weights (the
    // largest where parcels overlap); every cell outside the spans is outside every parcel.
    let rows = dims[1] * dims[2];
    let mut spans: Vec<Option<(usize, usize)>> = vec![None; rows];
    let mut starts = vec![0usize; rows];
    let mut weights: Vec<f32> = Vec::new();
    let mut row_weights = vec![0.0f32; dims[0]];
    let mut crossing: Vec<(usize, (usize, usize))> = Vec::with_capacity(parcels.len());
    for y in 0..dims[1] {
        for z in 0..dims[2] {
            // The parcels whose surface this row's line crosses, and where.
            crossing.clear();
            for (i, (q, (lo, hi))) in parcels.iter().zip(&boxes).enumerate() {
                let inside = |k: usize, v: usize| lo[k] <= v && v <= hi[k];
                if inside(1, y)
                    && inside(2, z)
                    && let Some(cells) =
                        q.cells_along_x(settings, y, z, (lo[0], (hi[0] + 1).min(dims[0])))
                {
                    crossing.push((i, cells));
                }
            }
            let row = y * dims[2] + z;
            let Some(span) = crossing
                .iter()
                .map(|&(_, c)| c)
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
            else {
                continue;
            };
            row_weights[span.0..span.1].fill(0.0);
            for &(i, (from, to)) in &crossing {
                let q = &parcels[i];
                for x in from..to {
                    let w = q.weight(settings.center(x, y, z));
                    row_weights[x] = row_weights[x].max(w);
                }
            }
            starts[row] = weights.len();
            weights.extend_from_slice(&row_weights[span.0..span.1]);
            spans[row] = Some(span);
        }
    }
    let at = |x: usize, y: usize, z: usize| {
        let row = y * dims[2] + z;
        let from = spans[row].map_or(0, |s| s.0);
        weights[starts[row] + x - from]
    };
    let span = |y: usize, z: usize| spans[y * dims[2] + z];
    let s = settings;
    automaton.set_levels_in_spans(Kind::Hum, level_of(0.0), span, |x, y, z| {
        level_of(s.p_hum * at(x, y, z))
    });
    automaton.set_levels_in_spans(Kind::Act, level_of(0.0), span, |x, y, z| {
        level_of(s.p_act * at(x, y, z))
    });
    automaton.set_levels_in_spans(Kind::Ext, level_of(s.p_ext_outside), span, |x, y, z| {
        let w = at(x, y, z);
        level_of(s.p_ext_inside * w + s.p_ext_outside * (1.0 - w))
    });
}

/// One step's cloud smoothed ([`Simulation::smoothed`]): each cell's count of cloud cells in
/// the box around it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Smoothed {
    /// Counts per cell, x fastest, then y, then z, brought into a byte where the box holds
    /// more than 255 cells (half-widths 3 and 4: halved or quartered, rounded).
    pub counts: Vec<u8>,
    /// A count's share of cloud: one over the box's cells (times the count's divisor).
    pub scale: f32,
}

impl Smoothed {
    /// Each cell's share of cloud around it, in [0, 1].
    pub fn shares(&self) -> Vec<f32> {
        self.counts.iter().map(|&c| c as f32 * self.scale).collect()
    }

    /// The shares blended toward `next`'s by `t` in [0, 1] (a frame between two steps).
    pub fn blend(&self, next: &Smoothed, t: f32) -> Vec<f32> {
        let t = t.clamp(0.0, 1.0);
        let (sa, sb) = (self.scale, next.scale);
        self.counts
            .iter()
            .zip(&next.counts)
            .map(|(&a, &b)| {
                let (x, y) = (a as f32 * sa, b as f32 * sb);
                x + (y - x) * t
            })
            .collect()
    }
}

/// The density volume of `values` on a run's grid of `dims` cells.
fn volume(settings: &Settings, dims: [usize; 3], values: Vec<f32>) -> DensityVolume {
    let [nx, ny, nz] = dims;
    DensityVolume {
        dims: UVec3::new(nx as u32, ny as u32, nz as u32),
        min: Vec3::from(settings.origin),
        size: Vec3::new(nx as f32, ny as f32, nz as f32) * settings.cell_size.max(1e-3),
        values,
    }
}

/// Runs `work(i, part)` for every part: with `threads` above one, each part but the first on
/// a scoped thread of its own and the first on this one (one spawn fewer); else all here.
fn run_parts<T: Send>(
    threads: usize,
    parts: impl IntoIterator<Item = T>,
    work: &(dyn Fn(usize, T) + Sync),
) {
    let mut parts = parts.into_iter().enumerate();
    if threads <= 1 {
        parts.for_each(|(i, p)| work(i, p));
        return;
    }
    std::thread::scope(|scope| {
        let first = parts.next();
        for (i, p) in parts {
            scope.spawn(move || work(i, p));
        }
        if let Some((i, p)) = first {
            work(i, p);
        }
    });
}

/// The benchmarks' simulation (`cloudsketch bench`'s `ca_` entries and the page's
/// `?bench=ca`): 256×64×256 cells (x, y up, z; [`MAX_CELLS`]) at a 0.125 cell under three
/// parcels, 30 steps in, so clouds have formed.
pub fn bench_simulation() -> Simulation {
    simulation_under_parcels([256, 64, 256], 0.125)
}

/// [`bench_simulation`]'s three parcels over `cells` of `cell_size`, 30 steps in.
pub fn simulation_under_parcels(cells: [u32; 3], cell_size: f32) -> Simulation {
    let settings = Settings {
        cells,
        cell_size,
        ..Settings::default()
    };
    let parcels: Vec<Parcel> = [(-6.0, 3.0, 0.0), (4.0, 4.0, 3.0), (0.0, 3.5, -7.0)]
        .iter()
        .map(|&(x, y, z)| Parcel {
            center: Vec3::new(x, y, z),
            radii: Vec3::new(6.0, 3.0, 5.0),
            rotation: Quat::IDENTITY,
        })
        .collect();
    let mut sim = Simulation::new(&settings, &parcels);
    sim.advance(30);
    sim
}

/// Seconds per step of `sim`: the median over 9 runs of 16 steps each, timed by `now`
/// (seconds; the platform's clock: the bench's and the page's differ, and the page's ticks only
/// every 0.1 ms, so a run spans enough steps, over 4 ms at the benchmarks' size, for that to be
/// about 2%).
pub fn time_steps(sim: &mut Simulation, now: &dyn Fn() -> f64) -> f64 {
    const RUNS: usize = 9;
    const STEPS: u64 = 16;
    let mut times: Vec<f64> = (0..RUNS)
        .map(|_| {
            let t = now();
            sim.advance(STEPS);
            (now() - t) / STEPS as f64
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[RUNS / 2]
}

/// The parcels of a scene: its visible ellipsoids.
pub fn parcels(scene: &crate::scene::Scene) -> Vec<Parcel> {
    scene
        .ellipsoids
        .iter()
        .filter(|e| !e.hidden)
        .map(|e| Parcel::of(e))
        .collect()
}

/// Steps a run keeps snapshots at (every this many steps), and how many at most.
const SNAPSHOT_EVERY: u64 = 32;
/// What a checkpoint file begins with (then the run's hash and its state).
const CHECKPOINT_MAGIC: &[u8; 8] = b"CSSIMCK1";
const MAX_SNAPSHOTS: usize = 64;
/// Bytes the snapshots of one run may hold (a 256×64×256 run's state is 1.5 MiB: 32 of them).
pub const SNAPSHOT_BYTES: usize = 48 << 20;
/// Steps one call may advance (a far jump catches up over several frames).
pub const MAX_STEPS_PER_CALL: u64 = 200;
/// The last step a scene's time reaches (later times show this step): about 6 s of stepping
/// natively at 128×32×128, and every run's cost bounded.
pub const MAX_STEP: u64 = 20_000;

/// A run that plays to any scene time: snapshots every few steps make scrubbing back cheap
/// (within a memory cap), the last smoothed steps are kept for the blend between steps.
pub struct Player {
    key: (Settings, Sources),
    run: Simulation,
    snapshots: Vec<State>,
    /// Bytes the snapshots may hold.
    snapshot_bytes: usize,
    /// Steps computed since it began.
    taken: u64,
    smoothed: Vec<(u64, std::sync::Arc<Smoothed>)>,
    /// The last step dropped from `smoothed`, if nothing else held it: the next one is
    /// written over it.
    spare: Smoothed,
}

impl Player {
    /// A run of `settings` steered by `sources`, at step 0.
    pub fn new(settings: &Settings, sources: Sources) -> Self {
        let run = Simulation::steered(settings, sources.clone());
        let snapshots = vec![run.state()];
        Self {
            key: (settings.clone(), sources),
            run,
            snapshots,
            snapshot_bytes: SNAPSHOT_BYTES,
            taken: 0,
            smoothed: Vec::new(),
            spare: Smoothed::default(),
        }
    }

    /// The same with at most `bytes` of snapshots (tests).
    pub fn with_snapshot_bytes(mut self, bytes: usize) -> Self {
        self.snapshot_bytes = bytes;
        self
    }

    /// Bytes the snapshots hold now.
    pub fn snapshot_bytes(&self) -> usize {
        self.snapshots.iter().map(State::bytes).sum()
    }

    /// A hash of what it runs (its settings and where its parcels stand over time), the same
    /// in every process: a checkpoint of another run is refused by it.
    pub fn run_key(&self) -> u64 {
        let (settings, sources) = &self.key;
        let moving = sources.moving.as_ref().map(|s| {
            serde_json::json!({
                "ellipsoids": s.ellipsoids,
                "animation": s.animation,
                "wind_field": s.wind_field,
                "seed": s.seed,
                // The range the parcels' speed is sampled over (how often they are posed).
                "end": sources.end,
            })
        });
        let text = serde_json::json!({
            // Another build may step differently: its checkpoints are another run's.
            "build": env!("CARGO_PKG_VERSION"),
            "settings": settings,
            "start": format!("{:?}", sources.start),
            "moving": moving,
        })
        .to_string();
        crate::seeded::stable_hash(text.as_bytes())
    }

    /// The furthest snapshot of the run (a step that is a multiple of 32) and its state as a
    /// checkpoint file holds it ([`Player::resume`] reads it back).
    pub fn checkpoint(&self) -> (u64, Vec<u8>) {
        let last = self.snapshots.iter().max_by_key(|s| s.step);
        let state = last.cloned().unwrap_or_else(|| self.run.state());
        let mut bytes = CHECKPOINT_MAGIC.to_vec();
        bytes.extend_from_slice(&self.run_key().to_le_bytes());
        bytes.extend_from_slice(&state.to_bytes());
        (state.step, bytes)
    }

    /// Takes a checkpoint of this run (written by any process that played it), so steps up
    /// to its own need not be played again; returns its step, or why it is refused (another
    /// run's, damaged, past step `at_most`).
    pub fn resume(&mut self, bytes: &[u8], at_most: u64) -> Result<u64, String> {
        let head = CHECKPOINT_MAGIC.len() + 8;
        if bytes.len() < head || !bytes.starts_with(CHECKPOINT_MAGIC) {
            return Err("not a cloudsketch simulation checkpoint".into());
        }
        let key = u64::from_le_bytes(
            bytes[CHECKPOINT_MAGIC.len()..head]
                .try_into()
                .unwrap_or_default(),
        );
        if key != self.run_key() {
            return Err("a checkpoint of another scene or simulation (its hash differs)".into());
        }
        let state = State::from_bytes(&bytes[head..], &self.snapshots[0])?;
        if state.step > at_most.min(MAX_STEP) || !state.step.is_multiple_of(SNAPSHOT_EVERY) {
            return Err(format!(
                "a checkpoint at step {}, not one this run makes",
                state.step
            ));
        }
        let step = state.step;
        if !self.snapshots.iter().any(|s| s.step == step) {
            let at = self.snapshots.partition_point(|s| s.step < step);
            self.snapshots.insert(at, state);
        }
        Ok(step)
    }

    /// Whether it runs these settings and sources.
    pub fn runs(&self, settings: &Settings, sources: &Sources) -> bool {
        self.key.0 == *settings && self.key.1 == *sources
    }

    /// Steps the run has taken since it began (every step a scrub or replay computed: a
    /// restored snapshot's steps are not taken again), for tests and benchmarks.
    pub fn steps_taken(&self) -> u64 {
        self.taken
    }

    /// The smoothed cloud at step `n`, or at the nearest step this call could reach.
    fn smoothed_at(&mut self, n: u64) -> (u64, std::sync::Arc<Smoothed>) {
        if let Some((s, v)) = self.smoothed.iter().find(|(s, _)| *s == n) {
            return (*s, v.clone());
        }
        // The nearest snapshot at or before `n`: back to it from past `n`, or on to it (one a
        // checkpoint gave) from before it.
        if let Some(snap) = self.snapshots.iter().rev().find(|s| s.step <= n)
            && (self.run.step() > n || snap.step > self.run.step())
        {
            self.run.restore(&snap.clone());
        }
        let mut budget = MAX_STEPS_PER_CALL;
        while self.run.step() < n && budget > 0 {
            self.run.advance(1);
            self.taken += 1;
            budget -= 1;
            let step = self.run.step();
            if step.is_multiple_of(SNAPSHOT_EVERY)
                && self.snapshots.last().is_none_or(|s| s.step < step)
            {
                self.snapshots.push(self.run.state());
                let each = self.snapshots[0].bytes().max(1);
                let cap = (self.snapshot_bytes / each).clamp(2, MAX_SNAPSHOTS);
                while self.snapshots.len() > cap {
                    // Thin out: every other snapshot after the first.
                    let mut i = 0;
                    self.snapshots.retain(|_| {
                        i += 1;
                        i == 1 || i % 2 == 0
                    });
                }
            }
        }
        let step = self.run.step();
        let v = std::sync::Arc::new(self.run.smoothed_over(std::mem::take(&mut self.spare)));
        self.smoothed.push((step, v.clone()));
        if self.smoothed.len() > 3 {
            let (_, dropped) = self.smoothed.remove(0);
            self.spare = std::sync::Arc::try_unwrap(dropped).unwrap_or_default();
        }
        (step, v)
    }

    /// The density at scene time `time` (steps at the settings' rate, blended between two
    /// steps); and whether the run is still catching up with that time.
    pub fn density(&mut self, time: f32) -> (DensityVolume, bool) {
        let target = crate::scene::step_position(time, self.key.0.rate).min(MAX_STEP as f64);
        let n = target.floor() as u64;
        let t = (target - n as f64) as f32;
        let (a, qa) = self.smoothed_at(n);
        if a < n {
            return (self.volume(qa.shares()), true);
        }
        let (_, qb) = self.smoothed_at(n + 1);
        (self.volume(qa.blend(&qb, t)), false)
    }

    fn volume(&self, values: Vec<f32>) -> DensityVolume {
        volume(&self.key.0, self.run.automaton().dims, values)
    }
}

#[cfg(test)]
mod tests;
