//! `cloudsketch bench`: each figure is measured with its baseline in the same run and reported
//! as a ratio (how many times better than the baseline), never as an absolute pass/fail.

use serde::Serialize;

use crate::render::offscreen::Offscreen;
use crate::scene::Scene;

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

/// Offscreen frame time at 1280×720 with 128 slices (median of several frames), against the
/// plain slice shader on the same adapter.
fn render_frame(offscreen: &mut Offscreen) -> Result<BenchResult, String> {
    const FRAMES: usize = 5;
    let mut scene = Scene::default();
    scene.render.slices = 128;
    let (w, h) = (1280, 720);
    // Warm up (pipeline compilation, uploads), then measure both alternately.
    offscreen
        .time_frames(&scene, w, h, 1, false)
        .map_err(|e| e.to_string())?;
    offscreen
        .time_frames(&scene, w, h, 1, true)
        .map_err(|e| e.to_string())?;
    let ours = offscreen
        .time_frames(&scene, w, h, FRAMES, false)
        .map_err(|e| e.to_string())?;
    let plain = offscreen
        .time_frames(&scene, w, h, FRAMES, true)
        .map_err(|e| e.to_string())?;
    Ok(result(
        "render_frame_1280x720_128_slices",
        median(ours) * 1e3,
        "ms",
        "plain_slice_shader_1280x720_128_slices",
        median(plain) * 1e3,
    ))
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
    let time = |f: &mut dyn FnMut()| {
        f();
        let v: Vec<f64> = (0..RUNS)
            .map(|_| {
                let t = std::time::Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .collect();
        median(v)
    };
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

/// Runs the suite and prints it.
pub fn run(json: bool) -> Result<(), String> {
    let mut offscreen = Offscreen::new().map_err(|e| e.to_string())?;
    let machine = format!(
        "{} cores, {} {}; adapter {}",
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1),
        std::env::consts::OS,
        std::env::consts::ARCH,
        offscreen.adapter_name()
    );
    let results = vec![sketch_pipeline()?, render_frame(&mut offscreen)?];
    let report = BenchReport { machine, results };
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
        );
    } else {
        println!("machine: {}", report.machine);
        println!(
            "{:<40} {:>12} {:<5} {:<44} {:>12} {:>8}",
            "name", "value", "unit", "baseline", "baseline", "ratio"
        );
        for r in &report.results {
            println!(
                "{:<40} {:>12.3} {:<5} {:<44} {:>12.3} {:>7.2}×",
                r.name, r.value, r.unit, r.baseline, r.baseline_value, r.ratio
            );
        }
    }
    Ok(())
}
