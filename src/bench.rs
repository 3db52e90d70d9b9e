//! `cloudsketch bench`: each figure is measured with its baseline in the same run and reported
//! as a ratio (how many times better than the baseline), never as an absolute pass/fail.

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use crate::derive::{Derived, frame_of};
use crate::render::offscreen::{Clock, Drawing, Offscreen};
use crate::scene::{Document, DrawingPlane, Edit, Preset, Scene};

/// One measurement.
#[derive(Clone, Debug, Serialize)]
pub struct BenchResult {
    /// What was measured.
    pub name: String,
    /// The measurement.
    pub value: f64,
    /// Its unit (smaller is better for times).
    pub unit: String,
    /// What it is compared with.
    pub baseline: String,
    /// The baseline's measurement in the same run and unit.
    pub baseline_value: f64,
    /// `baseline_value / value`: how many times better than the baseline.
    pub ratio: f64,
}

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Machine and adapter description.
    pub machine: String,
    /// The measurements.
    pub results: Vec<BenchResult>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

fn result(name: &str, value: f64, unit: &str, baseline: &str, baseline_value: f64) -> BenchResult {
    BenchResult {
        name: name.into(),
        value,
        unit: unit.into(),
        baseline: baseline.into(),
        baseline_value,
        ratio: baseline_value / value,
    }
}

/// `frames` full-quality frames of `scene` at `w` × `h` timed by the host's clock (which every
/// adapter has), with the plain slice shader if `plain`.
fn wall_frames(
    offscreen: &mut Offscreen,
    scene: &Scene,
    (w, h): (u32, u32),
    frames: usize,
    plain: bool,
) -> Result<Vec<f64>, String> {
    offscreen
        .time_frames(
            &frame_of(scene, None),
            [w, h],
            frames,
            drawing(plain),
            Clock::Wall,
        )
        .map(Option::unwrap_or_default)
        .map_err(|e| e.to_string())
}

/// The whole view with the app's slice shader, or with the plain baseline shader.
fn drawing(plain: bool) -> Drawing {
    if plain {
        Drawing::Plain
    } else {
        Drawing::Whole
    }
}

/// Offscreen frame time at 1280×720 with 128 slices (median of several frames), against the
/// plain slice shader on the same adapter.
fn render_frame(offscreen: &mut Offscreen) -> Result<BenchResult, String> {
    const FRAMES: usize = 5;
    let mut scene = Scene::default();
    scene.render.slices = 128;
    let (w, h) = (1280, 720);
    // Warm up (pipeline compilation, uploads), then measure both alternately.
    wall_frames(offscreen, &scene, (w, h), 1, false)?;
    wall_frames(offscreen, &scene, (w, h), 1, true)?;
    let ours = wall_frames(offscreen, &scene, (w, h), FRAMES, false)?;
    let plain = wall_frames(offscreen, &scene, (w, h), FRAMES, true)?;
    Ok(result(
        "render_frame_1280x720_128_slices",
        median(ours) * 1e3,
        "ms",
        "plain_slice_shader_1280x720_128_slices",
        median(plain) * 1e3,
    ))
}

/// Offscreen frame at 1280×720 with 128 slices marched (compute) against the same rasterised,
/// by the host's clock; nothing where the adapter cannot march them.
fn marched_frame(offscreen: &mut Offscreen) -> Result<Vec<BenchResult>, String> {
    const FRAMES: usize = 5;
    let mut scene = Scene::default();
    scene.render.slices = 128;
    let (w, h) = (1280, 720);
    let was = offscreen.marching();
    let time = |o: &mut Offscreen, on: bool| -> Result<Option<f64>, String> {
        if o.set_marching(on).is_err() {
            return Ok(None);
        }
        wall_frames(o, &scene, (w, h), 1, false)?;
        Ok(Some(median(wall_frames(o, &scene, (w, h), FRAMES, false)?)))
    };
    let (marched, rasterised) = (time(offscreen, true)?, time(offscreen, false)?);
    offscreen.set_marching(was).map_err(|e| e.to_string())?;
    Ok(match (marched, rasterised) {
        (Some(m), Some(r)) => vec![result(
            "render_frame_marched_1280x720_128_slices",
            m * 1e3,
            "ms",
            "render_frame_rasterised_1280x720_128_slices",
            r * 1e3,
        )],
        _ => Vec::new(),
    })
}

/// Offscreen frames at 1280×720 for other qualities and octave counts (Table 2's Quality and
/// Detail), each against the plain slice shader at the same slice count.
fn render_frames_by_quality(offscreen: &mut Offscreen) -> Result<Vec<BenchResult>, String> {
    const FRAMES: usize = 3;
    let (w, h) = (1280, 720);
    let mut out = Vec::new();
    for (slices, octaves) in [(64, 4), (256, 4), (128, 8)] {
        let mut scene = Scene::default();
        scene.render.slices = slices;
        scene.render.noise_octaves = octaves;
        let time =
            |o: &mut Offscreen, plain| wall_frames(o, &scene, (w, h), FRAMES, plain).map(median);
        let ours = time(offscreen, false)?;
        let plain = time(offscreen, true)?;
        out.push(result(
            &format!("render_frame_1280x720_{slices}_slices_{octaves}_octaves"),
            ours * 1e3,
            "ms",
            &format!("plain_slice_shader_1280x720_{slices}_slices"),
            plain * 1e3,
        ));
    }
    Ok(out)
}

/// A 500-point cloud-like outline (flat base, bumpy top) for the sketch benchmark.
pub fn bench_outline() -> Vec<[f64; 2]> {
    let n = 500;
    (0..n)
        .map(|i| {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            let bumps = 1.0 + 0.15 * (a * 7.0).sin() + 0.07 * (a * 13.0).cos();
            let y = a.sin().max(-0.35) * 3.5 * bumps;
            [5.0 * a.cos() * bumps, -y]
        })
        .collect()
}

/// Stroke → spheres (clean, triangulate, chordal axis, spheres, 3D extension) for a 500-point
/// stroke, against spade's constrained Delaunay triangulation alone on the same polygon.
fn sketch_pipeline() -> Result<BenchResult, String> {
    use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation as _};
    const RUNS: usize = 31;
    let stroke = bench_outline();
    let params = crate::sketch::SketchParams::default();
    let time = |f: &mut dyn FnMut()| time_median(RUNS, f);
    let mut failed = None;
    let ours = time(&mut || {
        if let Err(e) = crate::sketch::interpret(&stroke, true, &params, 1) {
            failed = Some(e.to_string());
        }
    });
    if let Some(e) = failed {
        return Err(format!("sketch benchmark stroke refused: {e}"));
    }
    let n = stroke.len();
    let cdt = time(&mut || {
        let vertices: Vec<Point2<f64>> = stroke.iter().map(|&[x, y]| Point2::new(x, y)).collect();
        let edges: Vec<[usize; 2]> = (0..n).map(|i| [i, (i + 1) % n]).collect();
        let t = ConstrainedDelaunayTriangulation::<Point2<f64>>::try_bulk_load_cdt(
            vertices,
            edges,
            |_| {},
        );
        std::hint::black_box(t.map(|t| t.num_inner_faces()).unwrap_or(0));
    });
    Ok(result(
        "sketch_500_point_stroke_to_spheres",
        ours * 1e3,
        "ms",
        "spade_cdt_500_point_polygon",
        cdt * 1e3,
    ))
}

/// Median seconds of `runs` calls of `f`, after one warm-up call.
fn time_median(runs: usize, f: &mut dyn FnMut()) -> f64 {
    f();
    median(
        (0..runs)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

/// One of `n` cloud outlines side by side (plane units, y up), for the derivation benchmarks.
fn bench_plane(i: usize) -> DrawingPlane {
    DrawingPlane {
        name: format!("Outline {}", i + 1),
        points: bench_outline()
            .iter()
            .map(|&[x, y]| glam::Vec2::new(x as f32 * 0.5, -y as f32 * 0.5))
            .collect(),
        origin: glam::Vec3::new(i as f32 * 1.5 - 7.0, 3.0, (i % 3) as f32 - 1.0),
        seed: i as u64 + 1,
        ..Default::default()
    }
}

/// A scene of `n` sketched outlines.
pub fn sketched_scene(n: usize) -> Scene {
    let mut scene = Scene::preset(Preset::Empty);
    scene.planes = (0..n).map(|i| Arc::new(bench_plane(i))).collect();
    scene
}

/// A light-slider tick (the sun's azimuth, which makes the GPU rebuild its light volume: that
/// pass is timed by the `light_volume_gpu_*` rows) on a 10-stroke scene, until the next
/// frame's volumes are ready, against deriving everything.
fn light_tick() -> Vec<BenchResult> {
    let mut doc = Document::new(sketched_scene(10));
    let mut derived = Derived::default();
    derived.update(doc.scene(), doc.revisions());
    let mut azimuth = 0.0;
    let tick = time_median(9, &mut || {
        let mut l = doc.scene().light.clone();
        azimuth += 7.0;
        l.sun_azimuth_deg = azimuth % 360.0;
        doc.apply(Edit::SetLight(l), Some("light"));
        std::hint::black_box(derived.update(doc.scene(), doc.revisions()));
    });
    let ambient = time_median(9, &mut || {
        let mut l = doc.scene().light.clone();
        l.ambient = if l.ambient > 0.5 { 0.4 } else { 0.6 };
        doc.apply(Edit::SetLight(l), Some("light"));
        std::hint::black_box(derived.update(doc.scene(), doc.revisions()));
    });
    let full = time_median(5, &mut || {
        std::hint::black_box(Derived::default().update(doc.scene(), doc.revisions()));
    });
    vec![
        result(
            "derive_sun_slider_tick_10_strokes",
            tick * 1e3,
            "ms",
            "derive_everything_10_strokes",
            full * 1e3,
        ),
        result(
            "derive_ambient_slider_tick_10_strokes",
            ambient * 1e3,
            "ms",
            "derive_everything_10_strokes",
            full * 1e3,
        ),
    ]
}

/// An 11th stroke added to a 10-stroke scene: stroke interpretation (with field assembly)
/// against interpreting all 11, and the bake of the 11-stroke field apart.
fn eleventh_stroke() -> Vec<BenchResult> {
    let ten = sketched_scene(10);
    let mut eleven = ten.clone();
    eleven.planes.push(Arc::new(bench_plane(10)));
    let mut incremental = Vec::new();
    let mut fresh = Vec::new();
    let mut bakes = Vec::new();
    for _ in 0..5 {
        let mut derived = Derived::default();
        derived.field(&ten, None);
        let t = Instant::now();
        let field = derived.field(&eleven, None);
        incremental.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        std::hint::black_box(Derived::default().field(&eleven, None));
        fresh.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        std::hint::black_box(crate::field::bake(&field, eleven.render.field_resolution));
        bakes.push(t.elapsed().as_secs_f64());
    }
    let (inc, all) = (median(incremental), median(fresh));
    vec![
        result(
            "derive_11th_stroke_interpretation",
            inc * 1e3,
            "ms",
            "derive_all_11_strokes_interpretation",
            all * 1e3,
        ),
        result(
            "bake_11_stroke_field",
            median(bakes) * 1e3,
            "ms",
            "derive_all_11_strokes_interpretation",
            all * 1e3,
        ),
    ]
}

/// Billows: a new billowed stroke (interpretation, its puffs and the field) against the same
/// stroke smooth, and the default cumulus's whole derivation (field and bake) with its
/// billows against without.
fn billows_cost() -> Vec<BenchResult> {
    let mut smooth = sketched_scene(1);
    smooth.render.field_resolution = crate::limits::FIELD_RESOLUTION.default as u32;
    let mut billowed = smooth.clone();
    Arc::make_mut(&mut billowed.planes[0]).billows = crate::scene::Billows::NEW;
    let derive = |scene: &Scene| {
        time_median(5, &mut || {
            let field = Derived::default().field(scene, None);
            std::hint::black_box(crate::field::bake(&field, scene.render.field_resolution));
        })
    };
    let cumulus = Scene::preset(Preset::Cumulus);
    let mut plain = cumulus.clone();
    for e in &mut plain.ellipsoids {
        Arc::make_mut(e).billows.levels = 0;
    }
    vec![
        result(
            "derive_and_bake_billowed_stroke",
            derive(&billowed) * 1e3,
            "ms",
            "derive_and_bake_smooth_stroke",
            derive(&smooth) * 1e3,
        ),
        result(
            "derive_and_bake_billowed_cumulus",
            derive(&cumulus) * 1e3,
            "ms",
            "derive_and_bake_smooth_cumulus",
            derive(&plain) * 1e3,
        ),
    ]
}

/// A bank of `n` ellipsoids (seeded), 24 × 5 × 24 world units, as a modeller using thousands of
/// primitives builds one.
pub fn ellipsoid_bank(n: usize) -> Scene {
    use crate::scene::Ellipsoid;
    let mut rng = crate::seeded::SplitMix::new(n as u64);
    let mut u = || rng.next_f64() as f32;
    let mut scene = Scene::preset(Preset::Empty);
    scene.ellipsoids = (0..n)
        .map(|_| {
            let center = glam::Vec3::new(u() * 24.0 - 12.0, u() * 5.0, u() * 24.0 - 12.0);
            let radii = glam::Vec3::new(0.5 + u(), 0.3 + u() * 0.5, 0.5 + u());
            Arc::new(Ellipsoid {
                rotation: glam::Quat::from_rotation_y(u() * 6.0),
                ..Ellipsoid::new(center, radii)
            })
        })
        .collect();
    scene
}

/// The field's density volume for 100 and 2,000 ellipsoids: a full rebuild, and one primitive
/// moved (the partial update), each against brute force (every primitive at every texel).
fn field_at_scale() -> Vec<BenchResult> {
    let mut out = Vec::new();
    for n in [100, 2_000] {
        let mut doc = Document::new(ellipsoid_bank(n));
        let res = doc.scene().render.field_resolution;
        let full = time_median(5, &mut || {
            std::hint::black_box(Derived::default().density(doc.scene(), doc.revisions()));
        });
        let (moved, _) = one_ellipsoid_moved(&mut doc);
        let field = crate::derive::field_of(doc.scene());
        let brute = time_median(1, &mut || {
            std::hint::black_box(crate::field::bake_brute_force(&field, res));
        });
        let brute_name = format!("field_brute_force_{n}_ellipsoids");
        out.push(result(
            &format!("field_full_rebuild_{n}_ellipsoids"),
            full * 1e3,
            "ms",
            &brute_name,
            brute * 1e3,
        ));
        out.push(result(
            &format!("field_one_of_{n}_ellipsoids_moved"),
            moved * 1e3,
            "ms",
            &brute_name,
            brute * 1e3,
        ));
        out.push(result(
            &format!("field_one_of_{n}_moved_vs_rebuild"),
            moved * 1e3,
            "ms",
            &format!("field_full_rebuild_{n}_ellipsoids"),
            full * 1e3,
        ));
    }
    out
}

/// The median time of the density update after one ellipsoid of `doc` moved (a different
/// one each time), and the derivation cache it leaves.
fn one_ellipsoid_moved(doc: &mut Document) -> (f64, Derived) {
    let mut derived = Derived::default();
    derived.density(doc.scene(), doc.revisions());
    let mut step = 0usize;
    let moved = time_median(15, &mut || {
        step += 1;
        let mut es = doc.scene().ellipsoids.clone();
        let i = (step * 7919) % es.len();
        let mut e = (*es[i]).clone();
        e.center.x += if step.is_multiple_of(2) { 0.4 } else { -0.4 };
        es[i] = Arc::new(e);
        doc.apply(Edit::SetEllipsoids(es), None);
        std::hint::black_box(derived.density(doc.scene(), doc.revisions()));
    });
    (moved, derived)
}

/// A new time for the viewport (pose, then the density): on the default scene with nothing
/// keyed (it must derive nothing; the work counted is printed as a check), and with one of
/// 2,000 ellipsoids keyed (a partial update), each against a full derivation of that scene.
fn time_moves() -> Vec<BenchResult> {
    use crate::scene::{Channel, EllipsoidProperty};
    let mut out = Vec::new();
    // Nothing keyed.
    let mut doc = Document::new(Scene::default());
    let mut derived = Derived::default();
    derived.density(doc.scene(), doc.revisions());
    let work = derived.work();
    let mut t = 0.0;
    let still = time_median(15, &mut || {
        t += 0.5;
        doc.set_time(t);
        std::hint::black_box(derived.density(doc.scene(), doc.revisions()));
    });
    let full = time_median(3, &mut || {
        std::hint::black_box(Derived::default().density(doc.scene(), doc.revisions()));
    });
    if derived.work() != work {
        eprintln!("warning: a new time derived work on a scene with nothing keyed");
    }
    out.push(result(
        "time_new_t_nothing_keyed",
        still * 1e3,
        "ms",
        "time_full_derive_default_scene",
        full * 1e3,
    ));
    // One of 2,000 keyed.
    let mut scene = ellipsoid_bank(2_000);
    scene.settle();
    let e = scene.ellipsoids[1234].clone();
    let center = Channel::Ellipsoid {
        id: e.id,
        property: EllipsoidProperty::Center,
    };
    scene
        .animation
        .key(center, 0.0, e.center.to_array().to_vec());
    scene.animation.key(
        center,
        10.0,
        (e.center + glam::Vec3::X * 3.0).to_array().to_vec(),
    );
    let mut doc = Document::new(scene);
    let mut derived = Derived::default();
    derived.density(doc.scene(), doc.revisions());
    let mut t = 0.0;
    let keyed = time_median(15, &mut || {
        t += 0.37;
        doc.set_time(t);
        std::hint::black_box(derived.density(doc.scene(), doc.revisions()));
    });
    let full = time_median(3, &mut || {
        std::hint::black_box(Derived::default().density(doc.scene(), doc.revisions()));
    });
    out.push(result(
        "time_new_t_one_of_2000_keyed",
        keyed * 1e3,
        "ms",
        "time_full_derive_2000_ellipsoids",
        full * 1e3,
    ));
    out.push(simulated_scrub());
    out
}

/// The next full-quality image after a new time on the default scene, nothing keyed (the
/// time's own revision derives nothing; the light is swept again as the noise moves), against
/// the image after a full derivation of the same scene: each derived, uploaded and drawn whole
/// at 640×360, the device waited for (wall clock; the first draw, which compiles, left out).
fn time_to_image(offscreen: &mut Offscreen) -> Result<BenchResult, String> {
    const SIZE: [u32; 2] = [640, 360];
    let mut doc = Document::new(Scene::default());
    let mut derived = Derived::default();
    let volumes = derived.caught_up(doc.scene(), doc.revisions());
    offscreen
        .draw_and_wait(doc.scene(), &volumes, SIZE)
        .map_err(|e| e.to_string())?;
    let work = derived.work();
    let mut t = 0.0;
    let mut new_time = Vec::new();
    for _ in 0..5 {
        t += 0.5;
        let start = Instant::now();
        doc.set_time(t);
        let volumes = derived.caught_up(doc.scene(), doc.revisions());
        offscreen
            .draw_and_wait(doc.scene(), &volumes, SIZE)
            .map_err(|e| e.to_string())?;
        new_time.push(start.elapsed().as_secs_f64());
    }
    if derived.work() != work {
        eprintln!("warning: a new time derived work on a scene with nothing keyed");
    }
    let mut afresh = Vec::new();
    for _ in 0..3 {
        let start = Instant::now();
        let frame = Derived::default().frame(doc.scene(), None);
        offscreen
            .draw_and_wait(&frame.scene, &frame.volumes, SIZE)
            .map_err(|e| e.to_string())?;
        afresh.push(start.elapsed().as_secs_f64());
    }
    Ok(result(
        "time_next_image_new_t_nothing_keyed_640x360",
        median(new_time) * 1e3,
        "ms",
        "time_next_image_full_derive_640x360",
        median(afresh) * 1e3,
    ))
}

/// The `simulated` preset (its parcels moving with the wind) at step 2,000: scrubbed back 100
/// steps (a snapshot and at most 32 steps) against replayed from step 0 by a fresh
/// derivation, each to the frame's density.
fn simulated_scrub() -> BenchResult {
    let rate = crate::simulate::Settings::default().rate;
    let (at, back) = (2_000.0 / rate, 1_900.0 / rate);
    let mut doc = Document::new(Scene::preset(crate::scene::Preset::Simulated));
    let settle = |derived: &mut Derived, doc: &Document| {
        while {
            std::hint::black_box(derived.density(doc.scene(), doc.revisions()));
            derived.catching_up
        } {}
    };
    let mut derived = Derived::default();
    doc.set_time(at);
    settle(&mut derived, &doc);
    let scrub = median(
        (0..7)
            .map(|_| {
                let t = Instant::now();
                doc.set_time(back);
                settle(&mut derived, &doc);
                let took = t.elapsed().as_secs_f64();
                // Forward again, untimed.
                doc.set_time(at);
                settle(&mut derived, &doc);
                took
            })
            .collect(),
    );
    let replay = time_median(3, &mut || {
        settle(&mut Derived::default(), &doc);
    });
    result(
        "time_simulated_scrub_back_100_steps_at_2000",
        scrub * 1e3,
        "ms",
        "time_simulated_replay_2000_steps",
        replay * 1e3,
    )
}

/// Sequences of the `simulated` preset at one frame a second (10 steps a frame), as
/// `export --frames` writes them: 48 frames as VDB through one derivation cache, against the
/// parts it cannot do without (the 470 steps played once, plus 48 exports of a frame whose run
/// is already there) and against 48 single-frame exports, each replaying its run from step 0;
/// and a chunk of 4 frames from step 5,000 started from a checkpoint file's state, against the
/// same chunk played from step 0.
fn sequences() -> Vec<BenchResult> {
    use crate::export::{Format, Options, export, export_frame};
    let mut scene = Scene::preset(Preset::Simulated);
    scene.clock.fps = 1.0;
    let options = Options {
        resolution: 64,
        ..Options::default()
    };
    let at = |frame: u32| scene.posed_at(scene.clock.seconds(frame));
    let write = |derived: &mut Derived, frame: u32| {
        std::hint::black_box(export_frame(
            derived,
            &at(frame),
            Format::Vdb,
            &options,
            "cloud",
        ))
        .map(|_| ())
        .map_err(|e| e.to_string())
    };
    let frames = 0..48u32;
    let t = Instant::now();
    let mut derived = Derived::default();
    for f in frames.clone() {
        if write(&mut derived, f).is_err() {
            return Vec::new();
        }
    }
    let sequence = t.elapsed().as_secs_f64();
    // The parts: the steps alone, then one frame's export with its run already there.
    let t = Instant::now();
    let mut steps = Derived::default();
    std::hint::black_box(steps.density_afresh(&at(47)));
    let stepping = t.elapsed().as_secs_f64();
    let one = time_median(3, &mut || {
        let _ = write(&mut steps, 47);
    });
    let t = Instant::now();
    for f in frames {
        let _ = std::hint::black_box(export(&at(f), Format::Vdb, &options, "cloud"));
    }
    let replays = t.elapsed().as_secs_f64();

    // A checkpoint at step 4,992 (frame 499 and a bit), made untimed; then frames 500–503.
    let mut made = Derived::default();
    let _ = write(&mut made, 500);
    let settings = scene.simulation.clone().unwrap_or_default();
    let checkpoint = made
        .player_for(&settings, &at(500))
        .map(|p| p.checkpoint().1)
        .unwrap_or_default();
    let chunk = |from_checkpoint: bool| {
        let t = Instant::now();
        let mut d = Derived::default();
        if from_checkpoint && let Some(p) = d.player_for(&settings, &at(500)) {
            let _ = p.resume(&checkpoint, u64::MAX);
        }
        for f in 500..504 {
            let _ = write(&mut d, f);
        }
        t.elapsed().as_secs_f64()
    };
    let (resumed, replayed) = (chunk(true), chunk(false));
    vec![
        result(
            "sequence_simulated_48_vdb_frames",
            sequence * 1e3,
            "ms",
            "sequence_steps_once_plus_48_warm_frame_exports",
            (stepping + 48.0 * one) * 1e3,
        ),
        result(
            "sequence_simulated_48_vdb_frames_vs_replays",
            sequence * 1e3,
            "ms",
            "sequence_48_single_frame_exports_each_replaying",
            replays * 1e3,
        ),
        result(
            "sequence_chunk_4_frames_at_step_5000_from_checkpoint",
            resumed * 1e3,
            "ms",
            "sequence_chunk_4_frames_at_step_5000_from_step_0",
            replayed * 1e3,
        ),
    ]
}

/// The other way to build the field (ARCHITECTURE.md, "The field at scale"): every texel
/// evaluated on the GPU, one render pass per slice, against the CPU's full bake on the same
/// grid and the CPU's partial update after one primitive moved (which the app uses).
fn field_gpu_baseline(offscreen: &mut Offscreen) -> Result<Vec<BenchResult>, String> {
    let mut out = Vec::new();
    for n in [100, 2_000] {
        let mut doc = Document::new(ellipsoid_bank(n));
        let res = doc.scene().render.field_resolution;
        let field = crate::derive::field_of(doc.scene());
        let gpu = median(
            offscreen
                .time_field_on_gpu(&field, res, 4)
                .map_err(|e| e.to_string())?
                .split_off(1),
        );
        let cpu = time_median(5, &mut || {
            std::hint::black_box(crate::field::bake(&field, res));
        });
        let (moved, _) = one_ellipsoid_moved(&mut doc);
        let gpu_name = format!("field_gpu_full_{n}_ellipsoids");
        out.push(result(
            &gpu_name,
            gpu * 1e3,
            "ms",
            &format!("field_cpu_full_bake_{n}_ellipsoids"),
            cpu * 1e3,
        ));
        out.push(result(
            &format!("field_cpu_one_of_{n}_moved_vs_gpu"),
            moved * 1e3,
            "ms",
            &gpu_name,
            gpu * 1e3,
        ));
    }
    Ok(out)
}

/// Deriving each of [`worst_documents`] from scratch, against deriving a 10-stroke scene.
fn worst_documents_bench() -> Vec<BenchResult> {
    let derive = |scene: &Scene| {
        let doc = crate::scene::Document::new(scene.clone());
        time_median(1, &mut || {
            std::hint::black_box(Derived::default().update(scene, doc.revisions()));
        })
    };
    let typical = derive(&sketched_scene(10));
    crate::share::fixture::worst_documents()
        .into_iter()
        .map(|(name, scene)| {
            result(
                &format!("derive_worst_document_{name}"),
                derive(&scene) * 1e3,
                "ms",
                "derive_everything_10_strokes",
                typical * 1e3,
            )
        })
        .collect()
}

/// The GPU light volume of the default cloud at the default light resolution with its noise
/// (2 and 4 octaves), against the same pass without noise.
fn light_volume(offscreen: &mut Offscreen) -> Result<Vec<BenchResult>, String> {
    let scene = Scene::default();
    let mut time = |octaves: u32| -> Result<f64, String> {
        let mut s = scene.clone();
        s.render.light_octaves = octaves;
        Ok(median(
            offscreen
                .time_light_volume(&frame_of(&s, None), 4, Clock::Wall)
                .map_err(|e| e.to_string())?
                .unwrap_or_default()
                .split_off(1),
        ))
    };
    let plain = time(0)?;
    let mut out = Vec::new();
    for octaves in [2u32, 4] {
        out.push(result(
            &format!("light_volume_gpu_{octaves}_octaves"),
            time(octaves)? * 1e3,
            "ms",
            "light_volume_gpu_no_noise",
            plain * 1e3,
        ));
    }
    Ok(out)
}

/// Frames and passes timed by the device's own clock (timestamp queries): the 1080p frame
/// at 128 slices and 4 octaves (issue 11's GPU figure), other qualities, the ground and shafts,
/// and the light volume, each against its baseline on the same device. Empty, with a note on
/// stderr, where the adapter has no timestamp queries.
fn device_timed(offscreen: &mut Offscreen) -> Result<Vec<BenchResult>, String> {
    // A software adapter (lavapipe) takes seconds a frame at these sizes: fewer frames, and
    // only the 1080p row of issue 11.
    let cpu = offscreen.on_cpu();
    let frames = if cpu { 2 } else { 9 };
    let skipped = || {
        eprintln!("gpu: the adapter has no timestamp queries; its rows are left out");
        Ok(Vec::new())
    };
    let mut out = Vec::new();
    // The first frame compiles and uploads; the median of the rest.
    let frame = |o: &mut Offscreen, scene: &Scene, (w, h): (u32, u32), plain: bool| {
        o.time_frames(
            &frame_of(scene, None),
            [w, h],
            frames + 1,
            drawing(plain),
            Clock::Device,
        )
        .map(|t| t.map(|mut t| median(t.split_off(1))))
        .map_err(|e| e.to_string())
    };
    let sizes = [
        ((1920, 1080), 128, 4),
        ((1920, 1080), 256, 8),
        ((1280, 720), 64, 4),
        ((3840, 2160), 128, 4),
    ];
    for ((w, h), slices, octaves) in sizes.into_iter().take(if cpu { 1 } else { sizes.len() }) {
        let mut scene = Scene::default();
        scene.render.slices = slices;
        scene.render.noise_octaves = octaves;
        let (Some(ours), Some(plain)) = (
            frame(offscreen, &scene, (w, h), false)?,
            frame(offscreen, &scene, (w, h), true)?,
        ) else {
            return skipped();
        };
        out.push(result(
            &format!("gpu_frame_{w}x{h}_{slices}_slices_{octaves}_octaves"),
            ours * 1e3,
            "ms",
            &format!("gpu_plain_slice_shader_{w}x{h}_{slices}_slices"),
            plain * 1e3,
        ));
    }
    let mut bare = Scene::default();
    bare.render.slices = 128;
    bare.render.noise_octaves = 4;
    // The same frame with the slices marched (compute) and rasterised, where the adapter can
    // march them (the default frame above is marched on a GPU, rasterised on a CPU adapter).
    let was = offscreen.marching();
    let mut by_method = [None, None];
    for (i, on) in [true, false].into_iter().enumerate() {
        if offscreen.set_marching(on).is_ok() {
            by_method[i] = frame(offscreen, &bare, (1920, 1080), false)?;
        }
    }
    offscreen.set_marching(was).map_err(|e| e.to_string())?;
    if let [Some(marched), Some(rasterised)] = by_method {
        out.push(result(
            "gpu_marched_slices_1920x1080_128_slices",
            marched * 1e3,
            "ms",
            "gpu_rasterised_slices_1920x1080_128_slices",
            rasterised * 1e3,
        ));
    }
    let mut shafts = bare.clone();
    shafts.light.ground = true;
    shafts.light.ground_height = -2.0;
    shafts.light.shafts = true;
    if let (Some(with), Some(without)) = (
        frame(offscreen, &shafts, (1920, 1080), false)?,
        frame(offscreen, &bare, (1920, 1080), false)?,
    ) {
        out.push(result(
            "gpu_ground_and_shafts_frame_1920x1080",
            with * 1e3,
            "ms",
            "gpu_frame_1920x1080_128_slices_4_octaves",
            without * 1e3,
        ));
        // As the viewport draws it: the cloud's box sliced, the shafts around it apart.
        let cropped = offscreen
            .time_frames(
                &frame_of(&shafts, None),
                [1920, 1080],
                frames + 1,
                Drawing::Cropped,
                Clock::Device,
            )
            .map(|t| t.map(|mut t| median(t.split_off(1))))
            .map_err(|e| e.to_string())?;
        if let Some(cropped) = cropped {
            out.push(result(
                "gpu_ground_and_shafts_viewport_1920x1080",
                cropped * 1e3,
                "ms",
                "gpu_ground_and_shafts_frame_1920x1080",
                with * 1e3,
            ));
        }
    }
    let mut light = |octaves: u32| {
        let mut s = Scene::default();
        s.render.light_octaves = octaves;
        offscreen
            .time_light_volume(&frame_of(&s, None), frames + 1, Clock::Device)
            .map(|t| t.map(|mut t| median(t.split_off(1))))
            .map_err(|e| e.to_string())
    };
    if let (Some(noisy), Some(plain)) = (light(4)?, light(0)?) {
        out.push(result(
            "gpu_light_volume_4_octaves",
            noisy * 1e3,
            "ms",
            "gpu_light_volume_no_noise",
            plain * 1e3,
        ));
    }
    // The document's light volume at its default resolution against the old default (24).
    let default_texels = Scene::default().render.light_resolution;
    let mut light_at = |texels: u32| {
        let mut s = Scene::default();
        s.render.light_resolution = texels;
        s.render.light_octaves = 4;
        offscreen
            .time_light_volume(&frame_of(&s, None), frames + 1, Clock::Device)
            .map(|t| t.map(|mut t| median(t.split_off(1))))
            .map_err(|e| e.to_string())
    };
    if let (Some(fine), Some(coarse)) = (light_at(default_texels)?, light_at(24)?) {
        out.push(result(
            &format!("gpu_light_volume_{default_texels}_texels_4_octaves"),
            fine * 1e3,
            "ms",
            "gpu_light_volume_24_texels_4_octaves",
            coarse * 1e3,
        ));
    }
    if !cpu {
        out.extend(live_playback(offscreen)?);
    }
    Ok(out)
}

/// Plays `doc` as the app plays it live: for each of `times`, the document moved to that time
/// (posed), derived through `derived` (only what moved), uploaded and drawn whole at full
/// quality over 1920×1080 (no read-back). Each frame's wall-clock seconds, from setting the time
/// to the device being done.
fn playback(
    offscreen: &mut Offscreen,
    derived: &mut Derived,
    doc: &mut Document,
    times: &[f32],
) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(times.len());
    for &t in times {
        let start = std::time::Instant::now();
        doc.set_time(t);
        let volumes = derived.caught_up(doc.scene(), doc.revisions());
        offscreen
            .draw_and_wait(doc.scene(), &volumes, [1920, 1080])
            .map_err(|e| e.to_string())?;
        out.push(start.elapsed().as_secs_f64());
    }
    Ok(out)
}

/// Live playback at full quality, as the app plays on a GPU adapter: the `developing` and
/// `simulated` presets at 24 frames a second over 1920×1080, each frame posed, derived through
/// the cache, uploaded and drawn (wall clock, the device waited for), against the same frame
/// drawn again with nothing moved (the drawing alone). A frame has 41.7 ms at 24 a second.
fn live_playback(offscreen: &mut Offscreen) -> Result<Vec<BenchResult>, String> {
    let mut out = Vec::new();
    for (preset, name) in [
        (Preset::Developing, "developing"),
        (Preset::Simulated, "simulated"),
    ] {
        let scene = Scene::preset(preset);
        let fps = scene.clock.fps.max(1.0);
        let times: Vec<f32> = (0..49).map(|k| k as f32 / fps).collect();
        let mut doc = Document::new(scene);
        let mut derived = Derived::default();
        // The first frame derives everything and compiles; left out of both.
        let mut played = playback(offscreen, &mut derived, &mut doc, &times)?;
        let last = times[times.len() - 1];
        let mut still = playback(offscreen, &mut derived, &mut doc, &[last; 25])?;
        out.push(result(
            &format!("gpu_live_playback_{name}_1920x1080_per_frame"),
            median(played.split_off(1)) * 1e3,
            "ms",
            &format!("gpu_still_frame_{name}_1920x1080_wall"),
            median(still.split_off(1)) * 1e3,
        ));
    }
    Ok(out)
}

/// Share links for every preset and for five hand-drawn strokes: the URL's length against the
/// scene file's, and encoding and opening times against writing and opening the scene file
/// (opening either includes the cost check that derives the field).
fn links() -> Vec<BenchResult> {
    use crate::share::{DEFAULT_BASE, decode_link, fixture, link_url, open_scene_file};
    let mut scenes: Vec<(&str, Scene)> = Preset::ALL
        .iter()
        .map(|&(p, name)| (name, Scene::preset(p)))
        .collect();
    scenes.push(("sketched_5x200", fixture::hand_drawn()));
    let mut out = Vec::new();
    for (name, scene) in scenes {
        let Ok(url) = link_url(DEFAULT_BASE, &scene) else {
            continue;
        };
        let json = scene.to_json();
        out.push(result(
            &format!("link_chars_{name}"),
            url.len() as f64,
            "chars",
            "scene_file_bytes",
            json.len() as f64,
        ));
        let encode = time_median(9, &mut || {
            std::hint::black_box(link_url(DEFAULT_BASE, &scene).ok());
        });
        let write = time_median(9, &mut || {
            std::hint::black_box(scene.to_json());
        });
        out.push(result(
            &format!("link_encode_{name}"),
            encode * 1e3,
            "ms",
            "scene_file_write",
            write * 1e3,
        ));
        let decode = time_median(5, &mut || {
            std::hint::black_box(decode_link(&url).ok());
        });
        let open = time_median(5, &mut || {
            std::hint::black_box(open_scene_file("bench.json", json.as_bytes()).ok());
        });
        out.push(result(
            &format!("link_open_{name}"),
            decode * 1e3,
            "ms",
            "scene_file_open",
            open * 1e3,
        ));
    }
    out
}

/// The groups `--only` may name.
pub const GROUPS: [&str; 17] = [
    "sketch", "light", "stroke", "worst", "field", "time", "sequence", "link", "mesh", "simulate",
    "ca", "shafts", "render", "march", "quality", "gpu", "all",
];

/// Runs the suite (or only the groups named in `only`, comma-separated) and prints it. A group
/// name it does not know is an error, before anything runs.
pub fn run(json: bool, only: Option<&str>) -> Result<(), String> {
    if let Some(only) = only {
        let unknown: Vec<&str> = only
            .split(',')
            .map(str::trim)
            .filter(|g| !GROUPS.contains(g))
            .collect();
        if !unknown.is_empty() {
            return Err(format!(
                "--only: no bench group {} (the groups: {})",
                unknown.join(", "),
                GROUPS[..GROUPS.len() - 1].join(", ")
            ));
        }
    }
    let only = only.filter(|o| !o.split(',').any(|g| g.trim() == "all"));
    let mut offscreen = Offscreen::new().map_err(|e| e.to_string())?;
    let machine = format!(
        "{} cores, {} {}; adapter {}",
        crate::limits::cores(),
        std::env::consts::OS,
        std::env::consts::ARCH,
        offscreen.adapter_name()
    );
    let wanted = |group: &str| only.is_none_or(|o| o.split(',').any(|g| g.trim() == group));
    let mut results = Vec::new();
    if wanted("sketch") {
        results.push(sketch_pipeline()?);
    }
    if wanted("light") {
        results.extend(light_tick());
    }
    if wanted("stroke") {
        results.extend(eleventh_stroke());
        results.extend(billows_cost());
    }
    if wanted("worst") {
        results.extend(worst_documents_bench());
    }
    if wanted("field") {
        results.extend(field_at_scale());
        results.extend(field_gpu_baseline(&mut offscreen)?);
    }
    if wanted("time") {
        results.extend(time_moves());
        results.push(time_to_image(&mut offscreen)?);
    }
    if wanted("sequence") {
        results.extend(sequences());
    }
    if wanted("link") {
        results.extend(links());
    }
    if wanted("mesh") {
        results.extend(meshing());
    }
    // `ca` is every `ca_` entry: the automaton (`simulate`) and the shadow and shaft passes.
    if wanted("simulate") || wanted("ca") {
        results.extend(simulation());
    }
    if wanted("shafts") || wanted("ca") {
        results.extend(shadow_and_shaft_passes(&mut offscreen)?);
    }
    if wanted("render") {
        results.push(render_frame(&mut offscreen)?);
    }
    if wanted("march") {
        results.extend(marched_frame(&mut offscreen)?);
    }
    if wanted("quality") {
        results.extend(render_frames_by_quality(&mut offscreen)?);
    }
    if wanted("light") {
        results.extend(light_volume(&mut offscreen)?);
    }
    if wanted("gpu") {
        results.extend(device_timed(&mut offscreen)?);
    }
    let report = BenchReport { machine, results };
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
        );
    } else {
        println!("machine: {}", report.machine);
        println!(
            "{:<42} {:>12} {:<5} {:<44} {:>12} {:>8}",
            "name", "value", "unit", "baseline", "baseline", "ratio"
        );
        for r in &report.results {
            println!(
                "{:<42} {:>12.3} {:<5} {:<44} {:>12.3} {:>7.2}×",
                r.name, r.value, r.unit, r.baseline, r.baseline_value, r.ratio
            );
        }
    }
    Ok(())
}

/// Meshing the surface of 1,900 spheres at 128³, field sampling included (the bricks the
/// surface can cross), against plain marching cubes (the same per-cube table, every triangle
/// with its own corners, no normals) on the whole grid baked; the sampling reported apart,
/// against the whole bake.
fn meshing() -> Vec<BenchResult> {
    use crate::export::{Format, sample, surface};
    let mut scene = Scene::preset(Preset::Empty);
    let mut rng = crate::seeded::SplitMix::new(1900);
    let mut u = || rng.next_f64() as f32;
    scene.ellipsoids = (0..1_900)
        .map(|_| {
            // A cumulus-like heap: wide at the base, rounded on top.
            let (a, r) = (u() * std::f32::consts::TAU, u().sqrt() * 9.0);
            let top = 4.5 * (1.0 - (r / 9.0).powi(2)).max(0.0);
            let center = glam::Vec3::new(a.cos() * r, u() * top, a.sin() * r);
            Arc::new(crate::scene::Ellipsoid::new(
                center,
                glam::Vec3::splat(0.7 + u() * 0.6),
            ))
        })
        .collect();
    let options = crate::export::Options {
        resolution: 128,
        noise: false,
        ..Default::default()
    };
    let sampling = time_median(3, &mut || {
        std::hint::black_box(sample(&scene, Format::Glb, &options).ok());
    });
    let mut triangles = 0;
    let ours = time_median(3, &mut || {
        let g = sample(&scene, Format::Glb, &options).expect("a cloud");
        triangles = surface(&g, false).triangles.len();
    });
    let field = crate::derive::field_of(&scene);
    let whole = time_median(3, &mut || {
        std::hint::black_box(crate::field::bake_fine(&field, 128));
    });
    let share = crate::field::bake_for_surface(&field, 128, crate::field::ISO).1;
    let mut plain_triangles = 0;
    let table = crate::export::mesh::table();
    let plain = time_median(3, &mut || {
        let g = crate::field::bake_fine(&field, 128);
        let (min, h) = (g.center(0, 0, 0), g.texel_size().x);
        plain_triangles = plain_mc::mesh(table, g.dims, min, h, &g.values, crate::field::ISO);
    });
    log::info!(
        "meshing: {triangles} triangles (shared corners), {plain_triangles} (plain); {:.0} % of \
         the bricks baked for the surface",
        share * 100.0
    );
    vec![
        result(
            "mesh_1900_spheres_128_with_sampling",
            ours * 1e3,
            "ms",
            "plain_marching_cubes_whole_bake",
            plain * 1e3,
        ),
        result(
            "mesh_sampling_alone_1900_spheres_128",
            sampling * 1e3,
            "ms",
            "whole_bake_128",
            whole * 1e3,
        ),
    ]
}

/// Plain marching cubes, the meshing baseline: the same per-cube table, every triangle with
/// its own three vertices (no shared corners, no normals). Returns the triangle count.
mod plain_mc {
    use glam::{IVec3, UVec3, Vec3};

    use crate::export::mesh::{Case, EDGES};

    fn corner(c: u8) -> IVec3 {
        IVec3::new((c & 1) as i32, ((c >> 1) & 1) as i32, (c >> 2) as i32)
    }

    /// Marches every cube of the grid (outside it, below the iso level).
    pub fn mesh(table: &[Case], dims: UVec3, min: Vec3, h: f32, values: &[f32], iso: f32) -> usize {
        let d = dims.as_ivec3();
        let value = |p: IVec3| {
            if p.cmplt(IVec3::ZERO).any() || p.cmpge(d).any() {
                iso - 1.0
            } else {
                values[((p.z * d.y + p.y) * d.x + p.x) as usize]
            }
        };
        let mut positions: Vec<Vec3> = Vec::new();
        for z in -1..d.z {
            for y in -1..d.y {
                for x in -1..d.x {
                    let base = IVec3::new(x, y, z);
                    let v: [f32; 8] = std::array::from_fn(|c| value(base + corner(c as u8)));
                    let case = (0..8).fold(0usize, |m, c| m | (((v[c] >= iso) as usize) << c));
                    for t in &table[case].triangles {
                        for &e in t {
                            // (Loop centres, rare, are placed at the cube's centre here.)
                            let p = match EDGES.get(e as usize) {
                                Some(&(a, b)) => {
                                    let s = ((iso - v[a as usize])
                                        / (v[b as usize] - v[a as usize]))
                                        .clamp(0.0, 1.0);
                                    let pa = min + (base + corner(a)).as_vec3() * h;
                                    let pb = min + (base + corner(b)).as_vec3() * h;
                                    pa + (pb - pa) * s
                                }
                                None => min + (base.as_vec3() + 0.5) * h,
                            };
                            positions.push(p);
                        }
                    }
                }
            }
        }
        std::hint::black_box(&positions);
        positions.len() / 3
    }
}

/// The cellular automaton (Dobashi et al. 2000): one step of the benchmarks' 256×64×256
/// simulation (three parcels, random terms), bit-parallel on every core and on one (as the
/// page runs it), against the plain byte-per-cell step with the same random words built into
/// the same binary; the step's rate in cells per second; the smoothing of a step into cloud
/// counts and a frame's blend of two smoothed steps into the density volume, against the
/// step.
fn simulation() -> Vec<BenchResult> {
    use crate::simulate::{bench_simulation, reference::Reference, time_steps};
    let mut sim = bench_simulation();
    let clock = Instant::now();
    let now = || clock.elapsed().as_secs_f64();
    sim.advance(1);
    let step = time_steps(&mut sim, &now);
    let cells = sim.automaton().dims.iter().product::<usize>() as f64;
    sim.set_threads(Some(1));
    let one_thread = time_steps(&mut sim, &now);
    sim.set_threads(None);
    let wind = |_y: usize| 0.0;
    let mut plain = Reference::of(sim.automaton());
    let automaton = sim.automaton().clone();
    let reference = time_median(3, &mut || plain.step(&automaton, &wind));
    // Each step is smoothed once (byte counts), over a dropped step's counts as the player
    // does; each frame blends two smoothed steps into the density volume the renderer uploads.
    let mut old = sim.smoothed();
    let smooth = time_median(5, &mut || {
        old = std::hint::black_box(sim.smoothed_over(std::mem::take(&mut old)));
    });
    let (a, b) = (sim.smoothed(), {
        let mut next = sim.clone();
        next.advance(1);
        next.smoothed()
    });
    let blend = time_median(5, &mut || {
        std::hint::black_box(a.blend(&b, 0.5));
    });
    vec![
        result(
            "ca_step_256x64x256",
            step * 1e3,
            "ms",
            "ca_plain_byte_per_cell_step",
            reference * 1e3,
        ),
        result(
            "ca_step_256x64x256_one_thread",
            one_thread * 1e3,
            "ms",
            "ca_plain_byte_per_cell_step",
            reference * 1e3,
        ),
        // Higher is better: the ratio column reads baseline / value, so list the rates the
        // other way round (plain first) to keep "× faster" above 1.
        BenchResult {
            name: "ca_step_rate_256x64x256".into(),
            value: cells / step / 1e9,
            unit: "Gc/s".into(),
            baseline: "ca_plain_byte_per_cell_rate".into(),
            baseline_value: cells / reference / 1e9,
            ratio: reference / step,
        },
        result(
            "ca_smoothing_256x64x256",
            smooth * 1e3,
            "ms",
            "ca_step_256x64x256",
            step * 1e3,
        ),
        result(
            "ca_frame_blend_256x64x256",
            blend * 1e3,
            "ms",
            "ca_step_256x64x256",
            step * 1e3,
        ),
    ]
}

/// Cloud shadows and shafts of light at 1280×720 (128 slices) over the simulated preset's
/// ground: a frame with the ground (shaded through the light volume) against the same frame
/// without it, and a frame with shafts of light against the same frame without them.
fn shadow_and_shaft_passes(offscreen: &mut Offscreen) -> Result<Vec<BenchResult>, String> {
    const FRAMES: usize = 3;
    let (w, h) = (1280, 720);
    let mut ground = Scene::default();
    ground.render.slices = 128;
    ground.light.ground = true;
    ground.light.ground_height = -2.0;
    let mut bare = ground.clone();
    bare.light.ground = false;
    let mut shafts = ground.clone();
    shafts.light.shafts = true;
    let mut time = |scene: &Scene| {
        wall_frames(offscreen, scene, (w, h), 1, false)?;
        wall_frames(offscreen, scene, (w, h), FRAMES, false).map(median)
    };
    let (with_ground, without, with_shafts) = (time(&ground)?, time(&bare)?, time(&shafts)?);
    Ok(vec![
        result(
            "ca_ground_shadow_frame_1280x720",
            with_ground * 1e3,
            "ms",
            "frame_without_ground_1280x720",
            without * 1e3,
        ),
        result(
            "ca_shafts_frame_1280x720",
            with_shafts * 1e3,
            "ms",
            "ca_ground_shadow_frame_1280x720",
            with_ground * 1e3,
        ),
    ])
}
