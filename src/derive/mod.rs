//! The one pure derivation layer: document → spheres per plane (cached per plane) → field →
//! density volume, keyed on the geometry's revision alone (a light or media slider
//! re-interprets no stroke and re-bakes no geometry; the light toward the sun is the
//! renderer's GPU light volume). Everything here is a deterministic function of the document;
//! the renderer, the CLI, the exporters and the app all consume [`Volumes`].

mod billows;
mod planes;

use std::sync::Arc;

pub use billows::{PuffCache, min_radius};
pub use planes::{PlaneCache, Shape};

use crate::field::{
    Baker, Blob, Clip, DensityVolume, Field, Group, MAX_PRIMITIVES, PlacedInside, bake_work,
    resolution_within,
};
use crate::limits::{MAX_BAKE_WORK, MIN_LOADED_GRID};
use crate::scene::{DrawingPlane, Revisions, Scene};

/// A derived value with a generation that changes whenever the value does.
#[derive(Debug)]
pub struct Versioned<T> {
    /// New on every change, and never repeated by any cache in the process (two caches feeding
    /// one renderer cannot confuse their volumes); consumers (GPU uploads) compare it instead
    /// of the data.
    pub generation: u64,
    /// The value.
    pub data: Arc<T>,
}

/// The source of [`Versioned::generation`]s: shared by every cache, so none repeats.
static NEXT_GENERATION: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

impl<T> Versioned<T> {
    /// `data` as a new generation.
    pub fn new(data: Arc<T>) -> Self {
        Self {
            generation: NEXT_GENERATION.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            data,
        }
    }
}

impl<T> Clone for Versioned<T> {
    fn clone(&self) -> Self {
        Self {
            generation: self.generation,
            data: self.data.clone(),
        }
    }
}

/// One moment of a document as [`Derived::frame`] makes it: what every image and export of
/// that moment is drawn from.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The scene, every animated value posed at the moment.
    pub scene: Scene,
    /// Its volumes.
    pub volumes: Volumes,
}

/// [`Derived::frame`] with a cache of its own: `scene` at `at` seconds (`None`: as it stands).
pub fn frame_of(scene: &Scene, at: Option<f32>) -> Frame {
    Derived::default().frame(scene, at)
}

/// What the renderer draws: the density volume and the noise seed.
#[derive(Clone, Debug)]
pub struct Volumes {
    /// Field values on a grid.
    pub density: Versioned<DensityVolume>,
    /// Seed of the noise media.
    pub noise_seed: u64,
}

/// Counts of the work done, for tests and benchmarks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    /// Strokes interpreted (stroke → spheres).
    pub interpretations: u64,
    /// Fields assembled and baked into a density volume.
    pub bakes: u64,
    /// Kernel evaluations and clip tests of all bakes (at most [`bake_work`] for a full one; a
    /// partial update counts what it re-evaluated).
    pub bake_work: u64,
    /// Texels re-evaluated by all bakes (a partial update copies the others).
    pub baked_texels: u64,
    /// Primitives whose billows were grown (a billowed primitive whose shape and billows did
    /// not change keeps its puffs).
    pub puff_growths: u64,
    /// Times a simulated scene's outlines were resampled onto the grid they share with the
    /// simulation (when the outlines or that grid change, not at each of its steps).
    pub outline_resamples: u64,
}

/// The planes' drawing-plane placement applied to their shapes: the field of a document.
fn assemble(scene: &Scene, shapes: &[Arc<Shape>]) -> Field {
    let mut field = Field {
        blobs: scene
            .ellipsoids
            .iter()
            .filter(|e| !e.hidden)
            .map(|e| Blob::ellipsoid(e))
            .collect(),
        groups: Vec::new(),
        clips: Vec::new(),
        puffs_left_out: 0,
    };
    field.blobs.truncate(MAX_PRIMITIVES);
    let mut budget = MAX_PRIMITIVES.saturating_sub(field.blobs.len());
    for (plane, shape) in scene.planes.iter().zip(shapes) {
        if plane.hidden {
            continue;
        }
        match &**shape {
            Shape::Outline {
                spheres, inside, ..
            } => {
                let blobs: Vec<Blob> = spheres
                    .iter()
                    .take(budget)
                    .map(|s| Blob::sphere(plane.to_world(s.center.as_vec3()), s.radius as f32))
                    .collect();
                budget -= blobs.len();
                field.groups.push(Group {
                    blobs,
                    puffs: Vec::new(),
                    blend: plane.sketch.blend as f32,
                    inside: inside.clone().map(|map| PlacedInside {
                        map,
                        origin: plane.origin,
                        to_plane: plane.rotation.inverse(),
                    }),
                });
            }
            Shape::Cut(line) => field.clips.push(clip(plane, line.clone())),
            Shape::Unusable(_) => {}
        }
    }
    field
}

fn clip(plane: &DrawingPlane, line: Vec<glam::Vec2>) -> Clip {
    Clip {
        origin: plane.origin,
        right: plane.right(),
        up: plane.up(),
        line,
    }
}

/// How a message says that billows went over [`crate::limits::MAX_PUFFS`] (words the viewport
/// looks for, so an opened document's notice is not said twice).
pub const PUFFS_OVER_CAP: &str = "puffs over the cap";

/// What of `scene` is baked into cloud: all of it, or for a simulated scene its outlines alone
/// (its ellipsoids are the simulation's parcels, not cloud).
fn baked_part(scene: &Scene) -> std::borrow::Cow<'_, Scene> {
    if scene.simulation.is_some() {
        std::borrow::Cow::Owned(Scene {
            ellipsoids: Vec::new(),
            simulation: None,
            ..scene.clone()
        })
    } else {
        std::borrow::Cow::Borrowed(scene)
    }
}

/// Checks what deriving a loaded document would cost, before anything is built: over
/// [`MAX_BAKE_WORK`] at its field grid, the grid is made coarser (down to [`MIN_LOADED_GRID`])
/// and the change returned in words; when even that is over, the document is refused.
pub fn check_cost(scene: &mut Scene) -> Result<Option<String>, String> {
    let field = field_of(&baked_part(scene));
    let left_out = (field.puffs_left_out > 0).then(|| {
        format!(
            "billows: the finest level of puffs is left out ({} {PUFFS_OVER_CAP} of {})",
            field.puffs_left_out,
            crate::limits::MAX_PUFFS
        )
    });
    let wanted = scene.render.field_resolution;
    let work = bake_work(&field, wanted);
    if work <= MAX_BAKE_WORK {
        return Ok(left_out);
    }
    let (fits, fitted_work) = resolution_within(&field, wanted, MAX_BAKE_WORK);
    if fits < MIN_LOADED_GRID.min(wanted) || fitted_work > MAX_BAKE_WORK {
        return Err(format!(
            "this scene would take {:.0} million field evaluations to build (at most {:.0} \
             million), even on a {MIN_LOADED_GRID}³ grid: it has too many or too large \
             primitives ({} ellipsoids, {} drawing planes)",
            work as f64 / 1e6,
            MAX_BAKE_WORK as f64 / 1e6,
            scene.ellipsoids.len(),
            scene.planes.len()
        ));
    }
    scene.render.field_resolution = fits;
    let coarser = format!(
        "/render/field_resolution: {wanted} → {fits}, so the scene builds in about a second"
    );
    Ok(Some(match left_out {
        Some(puffs) => format!("{coarser}; {puffs}"),
        None => coarser,
    }))
}

/// The density volume a document describes at its time, derived from scratch: a simulation
/// played all the way to the time (the app spreads that over frames), with the outlines
/// sketched in it.
pub fn density_of(scene: &Scene) -> Arc<DensityVolume> {
    Derived::default().density_afresh(scene)
}

/// The field a document describes, derived from scratch (no cache).
pub fn field_of(scene: &Scene) -> Field {
    Arc::unwrap_or_clone(Derived::default().field(scene, None))
}

#[derive(Clone, Copy, PartialEq)]
struct GeometryKey {
    geometry: u64,
    resolution: u32,
}

/// What a simulated scene's outlines are baked from: its planes (held, compared by pointer)
/// and the field grid's resolution. Not the geometry revision, which parcels moving with the
/// time bump at every frame.
struct OutlinesKey {
    planes: Vec<Arc<DrawingPlane>>,
    resolution: u32,
}

impl OutlinesKey {
    fn of(scene: &Scene) -> Self {
        Self {
            planes: scene.planes.clone(),
            resolution: scene.render.field_resolution,
        }
    }

    fn same(&self, other: &Self) -> bool {
        self.resolution == other.resolution
            && self.planes.len() == other.planes.len()
            && self
                .planes
                .iter()
                .zip(&other.planes)
                .all(|(a, b)| Arc::ptr_eq(a, b))
    }
}

/// The derivation cache of one document (keep one per viewport, or per sequence of frames).
#[derive(Default)]
pub struct Derived {
    planes: PlaneCache,
    puffs: PuffCache,
    /// The last field, keyed on the geometry revision and the field grid's resolution (the
    /// smallest puff billows grow is a fraction of a texel).
    field: Option<((u64, u32), Arc<Field>)>,
    density: Option<(GeometryKey, Versioned<DensityVolume>)>,
    baker: Baker,
    /// The simulation run of a simulated scene, and its last density (keyed on the geometry
    /// revision and the time).
    player: Option<crate::simulate::Player>,
    simulated: Option<((u64, u32), Versioned<DensityVolume>)>,
    /// A simulated scene's outlines, baked apart (its ellipsoids are the simulation's parcels,
    /// not cloud), keyed on its planes ([`OutlinesKey`]); and the simulated density united with them, keyed on
    /// both generations.
    strokes: Option<(OutlinesKey, Versioned<DensityVolume>)>,
    stroke_baker: Baker,
    united: Option<((u64, u64), Versioned<DensityVolume>)>,
    /// The outlines resampled onto the grid they share with the simulation: the outlines'
    /// generation, that grid (its shape) and the values.
    outlines_on_grid: Option<(u64, DensityVolume, Arc<Vec<f32>>)>,
    /// Puffs the field of the last density left out for the cap.
    left_out: usize,
    /// The run has not yet reached the scene's time (a far jump catches up over frames).
    pub catching_up: bool,
    work: Work,
}

impl Derived {
    /// The field of `scene` at geometry revision `revision` (`None`: derive it afresh).
    pub fn field(&mut self, scene: &Scene, revision: Option<u64>) -> Arc<Field> {
        let key = revision.map(|rev| (rev, scene.render.field_resolution));
        if let (Some(key), Some((cached, field))) = (key, &self.field)
            && key == *cached
        {
            return field.clone();
        }
        let shapes = self.planes.shapes(&scene.planes);
        self.work.interpretations = self.planes.interpretations();
        let mut field = assemble(scene, &shapes);
        self.puffs.add(scene, &shapes, &mut field);
        self.work.puff_growths = self.puffs.grown_count;
        let field = Arc::new(field);
        if let Some(key) = key {
            self.field = Some((key, field.clone()));
        }
        field
    }

    /// Puffs the field of the last density left out for [`crate::limits::MAX_PUFFS`] (0
    /// before any).
    pub fn puffs_left_out(&self) -> usize {
        self.left_out
    }

    /// The density volume of `scene`'s geometry at `revisions` (the geometry alone, without
    /// its light); re-evaluates only what changed since the last call.
    pub fn density(&mut self, scene: &Scene, revisions: Revisions) -> Versioned<DensityVolume> {
        if let Some(settings) = &scene.simulation {
            let simulated = self.simulated(settings, scene, revisions);
            return self.with_outlines(scene, simulated);
        }
        self.strokes = None;
        self.united = None;
        self.outlines_on_grid = None;
        self.player = None;
        self.catching_up = false;
        let gkey = GeometryKey {
            geometry: revisions.geometry,
            resolution: scene.render.field_resolution,
        };
        match &self.density {
            Some((k, v)) if *k == gkey => v.clone(),
            _ => {
                let field = self.field(scene, Some(revisions.geometry));
                self.left_out = field.puffs_left_out;
                // Only what the edit changed is re-evaluated; an edit that would bake for
                // seconds bakes a coarser grid instead.
                let baked = self.baker.update(&field, gkey.resolution, MAX_BAKE_WORK);
                let v = self.counted(baked);
                self.density = Some((gkey, v.clone()));
                v
            }
        }
    }

    /// The simulation run of `scene`, which `settings` simulates (made afresh where this
    /// cache holds another run or none); the CLI writes checkpoints from it and reads them
    /// into it.
    pub fn player_for(
        &mut self,
        settings: &crate::simulate::Settings,
        scene: &Scene,
    ) -> Option<&mut crate::simulate::Player> {
        // The run follows the parcels as their keys and motion move them from time 0 on (a
        // new time is no change of the run; an edit of a parcel, its keys or its motion is).
        let sources = crate::simulate::Sources::of(scene);
        if self
            .player
            .as_ref()
            .is_none_or(|p| !p.runs(settings, &sources))
        {
            self.player = Some(crate::simulate::Player::new(settings, sources));
        }
        self.player.as_mut()
    }

    /// The density of a simulated scene: the run's smoothed cloud at the scene's time.
    fn simulated(
        &mut self,
        settings: &crate::simulate::Settings,
        scene: &Scene,
        revisions: Revisions,
    ) -> Versioned<DensityVolume> {
        let key = (revisions.geometry, scene.time.to_bits());
        if let Some((k, v)) = &self.simulated
            && *k == key
            && !self.catching_up
        {
            return v.clone();
        }
        let Some(player) = self.player_for(settings, scene) else {
            return Versioned {
                generation: 0,
                data: Arc::new(DensityVolume::default()),
            };
        };
        let (volume, behind) = player.density(scene.time);
        self.catching_up = behind;
        self.work.bakes += 1;
        let v = Versioned::new(Arc::new(volume));
        self.simulated = Some((key, v.clone()));
        v
    }

    /// A simulated scene's cloud with its sketched outlines: one density volume holding both
    /// (a stroke drawn in a simulated scene is cloud too). The outlines are baked apart, only
    /// when the geometry changes; the union is redone when either side changes.
    fn with_outlines(
        &mut self,
        scene: &Scene,
        simulated: Versioned<DensityVolume>,
    ) -> Versioned<DensityVolume> {
        let drawn = scene
            .planes
            .iter()
            .any(|p| !p.hidden && p.kind == crate::scene::StrokeKind::Outline);
        if !drawn {
            self.strokes = None;
            self.united = None;
            self.outlines_on_grid = None;
            self.left_out = 0;
            return simulated;
        }
        let okey = OutlinesKey::of(scene);
        let strokes = match &self.strokes {
            Some((k, v)) if k.same(&okey) => v.clone(),
            _ => {
                let outlines = baked_part(scene);
                let shapes = self.planes.shapes(&outlines.planes);
                self.work.interpretations = self.planes.interpretations();
                let mut field = assemble(&outlines, &shapes);
                self.puffs.add(&outlines, &shapes, &mut field);
                self.work.puff_growths = self.puffs.grown_count;
                self.left_out = field.puffs_left_out;
                let baked =
                    self.stroke_baker
                        .update(&Arc::new(field), okey.resolution, MAX_BAKE_WORK);
                let v = self.counted(baked);
                self.strokes = Some((okey, v.clone()));
                v
            }
        };
        let key = (simulated.generation, strokes.generation);
        if let Some((k, v)) = &self.united
            && *k == key
        {
            return v.clone();
        }
        let (ours, theirs) = (&simulated.data, &strokes.data);
        let united = if ours.is_empty() || theirs.is_empty() {
            ours.union(theirs, crate::limits::MAX_GRID_RESOLUTION)
        } else {
            // The outlines keep their resampling while only the simulation steps.
            let grid = ours.union_grid(theirs, crate::limits::MAX_GRID_RESOLUTION);
            let kept = self.outlines_on_grid.as_ref().filter(|(g, on, _)| {
                *g == strokes.generation
                    && (on.dims, on.min, on.size) == (grid.dims, grid.min, grid.size)
            });
            let resampled = match kept {
                Some((_, _, values)) => values.clone(),
                None => {
                    self.work.outline_resamples += 1;
                    let values = Arc::new(theirs.resampled_onto(&grid));
                    self.outlines_on_grid =
                        Some((strokes.generation, grid.clone(), values.clone()));
                    values
                }
            };
            ours.union_with(&grid, &resampled)
        };
        let v = Versioned::new(Arc::new(united));
        self.united = Some((key, v.clone()));
        v
    }

    /// A bake as a new generation of a density volume, its work counted.
    fn counted(&mut self, baked: crate::field::Baked) -> Versioned<DensityVolume> {
        self.work.bakes += 1;
        self.work.bake_work += baked.work;
        self.work.baked_texels += baked.texels;
        Versioned::new(baked.volume)
    }

    /// The volumes of `scene` whose parts are at `revisions`; derives only what changed.
    pub fn update(&mut self, scene: &Scene, revisions: Revisions) -> Volumes {
        Volumes {
            density: self.density(scene, revisions),
            noise_seed: scene.seed,
        }
    }

    /// The shape of a plane (not yet in the document, say), interpreted through the plane
    /// cache so deriving a document that holds it later costs nothing more.
    pub fn shape_of(&mut self, plane: &DrawingPlane) -> Arc<Shape> {
        let shape = self.planes.shape(plane);
        self.work.interpretations = self.planes.interpretations();
        shape
    }

    /// The shape last derived for a plane of the document (see [`PlaneCache::derived`]).
    pub fn derived_shape(&self, plane: &Arc<DrawingPlane>) -> Option<Arc<Shape>> {
        self.planes.derived(plane)
    }

    /// Forgets the last bakes and the volumes, keeping the per-plane shapes: the next
    /// derivation bakes whole (the grid is the document's either way), so an offscreen render
    /// reuses nothing an earlier frame left.
    pub fn forget_grid(&mut self) {
        self.baker = Baker::default();
        self.density = None;
        self.simulated = None;
        self.stroke_baker = Baker::default();
        self.strokes = None;
        self.united = None;
        self.outlines_on_grid = None;
    }

    /// The volumes of `scene` at `revisions` as [`Derived::update`] derives them, a simulation
    /// far from its start played all the way to the scene's time (the app spreads that over
    /// frames; a render or an export waits for it).
    pub fn caught_up(&mut self, scene: &Scene, revisions: Revisions) -> Volumes {
        let mut volumes = self.update(scene, revisions);
        while self.catching_up {
            volumes = self.update(scene, revisions);
        }
        volumes
    }

    /// The document at one moment, ready to draw or export: `scene` with every animated value
    /// (keys, motion, growth) posed at `at` seconds (`None`: the scene as it stands, so a value
    /// set over its keys shows), and its volumes derived as a fresh load derives them, on the
    /// grid the document chooses and not the one an earlier frame left, so a frame is the same
    /// wherever and in whatever order it is made. The plane shapes and a simulation run carry
    /// over from earlier frames: frame after frame of a sequence steps a simulation on from the
    /// last instead of replaying it (a frame reached so equals the frame played from step 0).
    ///
    /// Every standalone image (offscreen renders, the CLI's images and PNG frames) is drawn
    /// from one; the exporters, which sample the field at their own resolution, take the scene
    /// posed at the same time (`Scene::posed_at`), and the app's viewport derives incrementally
    /// with [`Derived::update`] from the document its clock posed.
    pub fn frame(&mut self, scene: &Scene, at: Option<f32>) -> Frame {
        let scene = match at {
            Some(t) => scene.posed_at(t),
            None => scene.clone(),
        };
        self.forget_grid();
        let volumes = self.caught_up(&scene, Revisions::fresh());
        Frame { scene, volumes }
    }

    /// The density volume `scene` describes at its time: [`Derived::frame`]'s, unposed.
    pub fn density_afresh(&mut self, scene: &Scene) -> Arc<DensityVolume> {
        self.frame(scene, None).volumes.density.data
    }

    /// The work done so far.
    pub fn work(&self) -> Work {
        self.work
    }
}

#[cfg(test)]
mod tests;
