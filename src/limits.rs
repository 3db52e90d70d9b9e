//! Every cap and every parameter range, defined once (pure). Validation of documents, the CLI and the
//! UI's sliders all read these, so opening a scene never clamps a value the panel could set, and
//! every way a file comes in (open, drop, CLI, reference image) has the same size limit.

/// Largest file read from any source: scene documents, stroke files, reference images.
pub const MAX_FILE_BYTES: u64 = 64 << 20;
/// Most ellipsoids a document may hold.
pub const MAX_ELLIPSOIDS: usize = 4096;
/// Most drawing planes in a document.
pub const MAX_PLANES: usize = 256;
/// Most points a stored stroke may have (longer strokes are thinned to this).
pub const MAX_PLANE_POINTS: usize = 20_000;
/// Most vertices an outline keeps after simplification and resampling.
pub const MAX_OUTLINE_POINTS: usize = 320;
/// Most spheres one stroke makes (copies from the 3D extension included).
pub const MAX_SPHERES: usize = 3000;
/// Most primitives in one field (sketches make many spheres; the cap keeps baking bounded).
pub const MAX_PRIMITIVES: usize = 20_000;
/// Latest scene time (seconds): a day of playing.
pub const MAX_TIME: f32 = 86_400.0;
/// Most frames one `render`/`export --frames` run writes (a longer range is split into
/// chunks, which any number of processes can run).
pub const MAX_SEQUENCE_FRAMES: u32 = 10_000;
/// Most texels along one side of the density volume.
pub const MAX_GRID_RESOLUTION: u32 = 128;
/// Most texels along one side of an exported grid (VDB, Mitsuba, meshes).
pub const MAX_EXPORT_RESOLUTION: u32 = 256;
/// Most work (as [`MAX_BAKE_WORK`]) an export's sampling may do: a few seconds natively.
pub const MAX_EXPORT_WORK: u64 = 1_200_000_000;
/// Most work one bake of the density volume may do (kernel evaluations plus clip tests; about
/// half a second natively). A document over it loads with a coarser field grid, or is refused
/// when even a coarse grid is over; an edit that goes over bakes a coarser grid.
pub const MAX_BAKE_WORK: u64 = 150_000_000;
/// Coarsest field grid a loaded document is brought down to before it is refused.
pub const MIN_LOADED_GRID: u32 = 32;
/// Most segment-pair crossing tests the self-intersection repair of one stroke may make.
pub const MAX_CROSSING_TESTS: u64 = 4_000_000;
/// Largest image side rendered offscreen.
pub const MAX_RENDER_SIDE: u32 = 8192;
/// Largest image side decoded at all (reference images).
pub const MAX_DECODE_SIDE: u32 = 16_384;
/// Largest reference-image file the document embeds (base64 in the JSON); a larger file is
/// shown but the document keeps only its name (load it again after reopening).
pub const MAX_EMBEDDED_IMAGE_BYTES: usize = 4 << 20;
/// Largest reference-image texture side (larger pictures are scaled down, with a smooth filter,
/// before upload): about the height it fills in a 1920×1080 view, so it is never shrunk much
/// on screen, where a texture without mipmaps would alias.
pub const MAX_GUIDE_SIDE: u32 = 1024;
/// A user's own presets (media and lighting saved under a name).
pub const MAX_LOOKS: usize = 32;
/// Characters of a user preset's name.
pub const MAX_LOOK_NAME: usize = 40;
/// Most undo steps kept.
pub const MAX_UNDO: usize = 200;
/// Atmospheric tiers above the base media (Schpok et al. 2003, §5.2).
pub const MAX_TIERS: usize = 2;
/// Noise octaves the media composite at most.
pub const MAX_OCTAVES: usize = 8;

/// A numeric parameter: its range, default, the way its slider moves, and its name and
/// meaning in an artist's words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Param {
    /// Label of its slider.
    pub label: &'static str,
    /// What it does, for the slider's tooltip.
    pub tip: &'static str,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Value of a new document, and of a non-finite one in a loaded document.
    pub default: f64,
    /// Whether its slider is logarithmic.
    pub logarithmic: bool,
}

impl Param {
    const fn new(text: [&'static str; 2], range: [f64; 3], logarithmic: bool) -> Self {
        let [label, tip] = text;
        let [min, max, default] = range;
        Self {
            label,
            tip,
            min,
            max,
            default,
            logarithmic,
        }
    }

    const fn linear(label: &'static str, tip: &'static str, min: f64, max: f64, d: f64) -> Self {
        Self::new([label, tip], [min, max, d], false)
    }

    const fn log(label: &'static str, tip: &'static str, min: f64, max: f64, d: f64) -> Self {
        Self::new([label, tip], [min, max, d], true)
    }

    /// `v` clamped into range; the default when it is not finite.
    pub fn fix(&self, v: f64) -> f64 {
        if v.is_finite() {
            v.clamp(self.min, self.max)
        } else {
            self.default
        }
    }

    /// [`Param::fix`] for `f32` values.
    pub fn fix_f32(&self, v: f32) -> f32 {
        self.fix(v as f64) as f32
    }

    /// [`Param::fix`] for integer values.
    pub fn fix_u32(&self, v: u32) -> u32 {
        (v as f64).clamp(self.min, self.max) as u32
    }
}

/// Quality: slices at full quality.
pub const SLICES: Param = Param::log(
    "quality (slices)",
    "Slices through the cloud at full quality: more is smoother and slower",
    8.0,
    512.0,
    128.0,
);
/// Resolution of the baked field grid along its longest side.
pub const FIELD_RESOLUTION: Param = Param::linear(
    "field grid",
    "Resolution of the grid the cloud's shape is sampled on: finer shows smaller features, costs more after each edit",
    16.0,
    128.0,
    64.0,
);
/// Noise octaves.
pub const OCTAVES: Param =
    Param::linear("octaves", "Layers of finer and finer noise", 0.0, 8.0, 3.0);
/// Sharpness: the alpha cut-off as a share of one slice's opacity (Schpok et al., Table 2).
pub const SHARPNESS: Param = Param::linear(
    "sharpness",
    "Cut the faint fringe off the cloud's edges (it does not shrink the cloud when opacity changes)",
    0.0,
    0.9,
    0.0,
);
/// Dirtiness: multiplies the optical depth toward the sun (Schpok et al., Table 2).
pub const DIRTINESS: Param = Param::linear(
    "dirtiness",
    "How fast the cloud darkens away from the sun (1 is physical)",
    0.0,
    4.0,
    1.0,
);
/// Wind: drift of the noise per second of scene time, per horizontal axis (world units).
pub const WIND: Param = Param::linear(
    "wind",
    "How fast the noise drifts while the scene plays (world units per second)",
    -5.0,
    5.0,
    0.0,
);
/// Torque: turn of the noise about the vertical per second of scene time (degrees).
pub const TORQUE: Param = Param::linear(
    "torque",
    "How fast the noise turns while the scene plays (degrees per second)",
    -90.0,
    90.0,
    0.0,
);
/// Particle wind: the velocity, per horizontal axis, of the wind field that carries moving
/// ellipsoids (Schpok et al. 2003 §5.4).
pub const PARTICLE_WIND: Param = Param::linear(
    "carrying wind",
    "How fast the wind carries the moving ellipsoids (world units per second, at height 0)",
    -5.0,
    5.0,
    0.0,
);
/// Particle wind shear: the share of the velocity gained per unit of height.
pub const PARTICLE_SHEAR: Param = Param::linear(
    "shear",
    "How much faster the wind blows per unit of height: tops run ahead of bases",
    0.0,
    1.0,
    0.0,
);
/// Particle turbulence: how far each moving ellipsoid wanders from its path.
pub const PARTICLE_TURBULENCE: Param = Param::linear(
    "turbulence",
    "How far each moving ellipsoid wanders off its path (world units)",
    0.0,
    2.0,
    0.0,
);
/// Rise: convection speed of a moving ellipsoid.
pub const RISE: Param = Param::linear(
    "rise",
    "How fast the ellipsoid rises (world units per second; below 0 sinks)",
    -2.0,
    2.0,
    0.0,
);
/// Growth of a moving ellipsoid's radii per second.
pub const GROWTH: Param = Param::linear(
    "growth",
    "How fast the ellipsoid grows, as a share of its size per second (below 0 shrinks)",
    -0.5,
    0.5,
    0.0,
);
/// Spread: growth of a moving ellipsoid's width and depth alone.
pub const SPREAD: Param = Param::linear(
    "spread",
    "How fast the ellipsoid widens and deepens but does not thicken (an anvil), per second",
    0.0,
    0.5,
    0.0,
);
/// Texels along the longest side of the light volume (transmittance toward the sun and the
/// sky's light let through from above), up to the light pass's
/// 128 slices (`MAX_LIGHT_SLICES` in `render::passes`).
pub const LIGHT_RESOLUTION: Param = Param::linear(
    "light grid",
    "Resolution of the light volume the shadows and the sky's light come from: finer shows smaller shadow detail, costs more whenever the light, the shape or the moving noise changes (the view previews at most 24 on a CPU adapter; renders and exports use this)",
    8.0,
    128.0,
    96.0,
);
/// Noise octaves the light volume sees.
pub const LIGHT_OCTAVES: Param = Param::linear(
    "light octaves",
    "Octaves of noise the shadows see (0: shadows of the smooth shape only; the view previews at most 2 on a CPU adapter; renders and exports use this)",
    0.0,
    8.0,
    4.0,
);
/// The light the viewport previews at most on a CPU adapter (lavapipe, SwiftShader): light
/// grid and light octaves. The light volume is recomputed whenever the light, the shape or
/// the moving noise changes, and on a CPU it holds up the frame; renders and exports keep the
/// document's.
pub const CPU_PREVIEW_LIGHT: [u32; 2] = [24, 2];
/// Altitude (world y) where an atmospheric tier begins.
pub const TIER_FLOOR: Param = Param::linear(
    "floor",
    "Altitude where this tier's noise takes over from the one below",
    -50.0,
    200.0,
    6.0,
);
/// Height over which two tiers blend at a floor.
pub const TIER_BLEND: Param = Param::linear(
    "tier blend",
    "Height over which one tier's noise turns into the next, so no seam shows",
    0.0,
    20.0,
    1.5,
);
/// Opacity: extinction per world unit of the densest cloud.
pub const OPACITY: Param = Param::log(
    "opacity",
    "How much light the cloud's body stops",
    0.01,
    50.0,
    2.5,
);
/// Width of the soft edge around the surface, in field units.
pub const SOFTNESS: Param = Param::linear(
    "edge softness",
    "Width of the cloud's soft edge",
    0.005,
    0.5,
    0.12,
);
/// How far noise moves the surface.
pub const NOISE_AMOUNT: Param = Param::linear(
    "noise amount",
    "How far the noise breaks up the cloud's surface",
    0.0,
    1.0,
    0.35,
);
/// Size of the first noise octave in world units.
pub const NOISE_SCALE: Param = Param::log(
    "noise size",
    "Size of the largest noise puffs, in world units",
    0.1,
    100.0,
    3.0,
);
/// Lacunarity: frequency step between octaves.
pub const DETAIL: Param = Param::linear(
    "detail (lacunarity)",
    "How much finer each noise layer is than the one before",
    1.1,
    4.0,
    2.2,
);
/// Sun azimuth in degrees.
pub const SUN_AZIMUTH: Param = Param::linear(
    "sun azimuth °",
    "Compass direction the sunlight comes from",
    0.0,
    360.0,
    20.0,
);
/// Sun elevation in degrees.
pub const SUN_ELEVATION: Param = Param::linear(
    "sun elevation °",
    "Height of the sun above the horizon",
    -89.0,
    89.0,
    35.0,
);
/// Sun intensity multiplier.
pub const SUN_INTENSITY: Param = Param::linear(
    "sun intensity",
    "Brightness of direct sunlight",
    0.0,
    10.0,
    0.8,
);
/// Ambient sky light multiplier.
pub const AMBIENT: Param = Param::linear(
    "ambient",
    "Brightness of the sky light that fills the shadowed side",
    0.0,
    3.0,
    0.25,
);
/// Forward scattering: the Henyey–Greenstein asymmetry g of the cloud's phase function.
pub const FORWARD_SCATTERING: Param = Param::linear(
    "forward scattering",
    "How much more light the cloud sends on along the sun's direction: its edges glow when you look toward the sun (0: the same every way)",
    0.0,
    0.9,
    0.5,
);
/// Multiple scattering: the weight of the light scattered more than once.
pub const MULTIPLE_SCATTERING: Param = Param::linear(
    "multiple scattering",
    "Light that bounces inside the cloud: thick clouds stay bright inside instead of going black (0: single scattering only; 0.5, the default, is calibrated against a path trace)",
    0.0,
    1.0,
    0.5,
);
/// Exposure in stops: all the light (the cloud's, the sky's, the shafts') times 2^EV before the
/// one tone map.
pub const EXPOSURE: Param = Param::linear(
    "exposure (EV)",
    "Brightens or darkens all the light before tone mapping, the sky's and the cloud's alike, in photographic stops; at 0 the background shows as picked",
    -4.0,
    4.0,
    0.0,
);
/// The document clock's frames per second ([`crate::scene::Clock`]).
pub const FRAME_RATE: Param = Param::linear(
    "frame rate",
    "Frames per second of the scene's clock: what --frame and the frame range count in",
    1.0,
    120.0,
    24.0,
);
/// The ground plane's height (world y).
pub const GROUND_HEIGHT: Param = Param::linear(
    "ground height",
    "Where the ground lies (world height); the clouds' shadows fall on it",
    -50.0,
    50.0,
    // Well below the presets' lowest cloud bases (the cumulus's is at 0.1: it stood on the
    // ground at 0), about a cloud's height under them.
    -5.0,
);
/// Shafts of light: how bright the sunlight the air scatters toward the eye is.
pub const SHAFT_INTENSITY: Param = Param::linear(
    "shaft intensity",
    "How bright the shafts of light are: sunlight scattered toward you by the air between the clouds",
    0.0,
    4.0,
    1.0,
);
/// Shafts of light: the air's extinction per world unit (haze).
pub const SHAFT_DENSITY: Param = Param::linear(
    "air density",
    "How hazy the air is: denser air shows brighter, shorter shafts and veils what lies far away",
    0.0,
    0.05,
    0.005,
);
/// Sketch: simplification tolerance as a fraction of the outline's size.
pub const SIMPLIFY: Param = Param::linear(
    "simplify",
    "Smooth away small wiggles of the stroke before building the cloud",
    0.0,
    0.2,
    0.01,
);
/// Sketch: branches adding less than this fraction of the outline's area are pruned.
pub const PRUNE: Param = Param::linear(
    "prune branches",
    "Bumps of the outline smaller than this share of its area get no limb of their own: raise it for a simpler cloud",
    0.0,
    0.5,
    0.02,
);
/// Sketch: the inflation (deflate) slider t.
pub const INFLATE: Param = Param::linear(
    "deflate (t)",
    "Thin the cloud's body toward its smallest features (0 keeps it as drawn)",
    0.0,
    1.0,
    0.0,
);
/// Sketch: copies of each terminal branch made by the 3D extension.
pub const COPIES: Param = Param::linear(
    "branch copies",
    "Copies of each bump placed around the cloud's body",
    0.0,
    6.0,
    2.0,
);
/// Sketch: width of the smooth blend between an outline's spheres, inside the outline.
pub const BLEND: Param = Param::linear(
    "soft blend",
    "Smooth the creases where the cloud's spheres meet (inside the outline: its silhouette stays as drawn); 0 is the plain union. Under billows it acts at a quarter of its width, so the puffs keep their scallops",
    0.0,
    1.0,
    0.4,
);

/// Billows: levels of puffs on puffs (Bouthors & Neyret 2004).
pub const BILLOW_LEVELS: Param = Param::linear(
    "billow levels",
    "Levels of smaller puffs on the surface of larger ones: the cauliflower of a cumulus (0: a smooth body)",
    0.0,
    4.0,
    3.0,
);
/// Billows: each level's puff size over the size of what it sits on.
pub const BILLOW_RATIO: Param = Param::linear(
    "billow size",
    "How large each level's puffs are next to the puff they sit on",
    0.25,
    0.6,
    0.45,
);
/// Billows: the share of each puff's surface the next level covers.
pub const BILLOW_COVERAGE: Param = Param::linear(
    "billow coverage",
    "How densely the next, smaller puffs cover each puff (1: twice over, as they overlap)",
    0.0,
    1.5,
    1.0,
);
/// Most puffs the billows of one document make; a document asking for more gets fewer levels
/// (and a message).
pub const MAX_PUFFS: usize = 16_000;

/// The cores work may be shared out among: the machine's (1 where threads are not available,
/// as in the browser). Asked once: on Linux the answer reads cgroup files, tens of µs, which
/// is a few percent of an automaton step.
pub fn cores() -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_lie_in_range_and_non_finite_values_take_them() {
        for p in [
            SLICES,
            FIELD_RESOLUTION,
            OCTAVES,
            OPACITY,
            SOFTNESS,
            NOISE_AMOUNT,
            NOISE_SCALE,
            DETAIL,
            SUN_AZIMUTH,
            SUN_ELEVATION,
            SUN_INTENSITY,
            AMBIENT,
            SIMPLIFY,
            PRUNE,
            INFLATE,
            COPIES,
            BLEND,
            BILLOW_LEVELS,
            BILLOW_RATIO,
            BILLOW_COVERAGE,
            SHARPNESS,
            DIRTINESS,
            WIND,
            TORQUE,
            TIER_FLOOR,
            TIER_BLEND,
            LIGHT_RESOLUTION,
            LIGHT_OCTAVES,
            FORWARD_SCATTERING,
            MULTIPLE_SCATTERING,
            EXPOSURE,
            GROUND_HEIGHT,
            SHAFT_INTENSITY,
            SHAFT_DENSITY,
            FRAME_RATE,
        ] {
            assert!(
                p.min < p.max && (p.min..=p.max).contains(&p.default),
                "{p:?}"
            );
            assert_eq!(p.fix(f64::NAN), p.default);
            assert_eq!(p.fix(p.max * 10.0 + 1.0), p.max);
            assert!(!p.logarithmic || p.min > 0.0, "log slider from 0: {p:?}");
        }
    }
}
