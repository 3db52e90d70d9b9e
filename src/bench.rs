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
    if v.is_empty() { f64::NAN } else { v[v.len() / 2] }
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
    offscreen.time_frames(&scene, w, h, 1, false).map_err(|e| e.to_string())?;
    offscreen.time_frames(&scene, w, h, 1, true).map_err(|e| e.to_string())?;
    let ours = offscreen.time_frames(&scene, w, h, FRAMES, false).map_err(|e| e.to_string())?;
    let plain = offscreen.time_frames(&scene, w, h, FRAMES, true).map_err(|e| e.to_string())?;
    Ok(result(
        "render_frame_1280x720_128_slices",
        median(ours) * 1e3,
        "ms",
        "plain_slice_shader_1280x720_128_slices",
        median(plain) * 1e3,
    ))
}

/// Runs the suite and prints it.
pub fn run(json: bool) -> Result<(), String> {
    let mut offscreen = Offscreen::new().map_err(|e| e.to_string())?;
    let machine = format!(
        "{} cores, {} {}; adapter {}",
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        std::env::consts::OS,
        std::env::consts::ARCH,
        offscreen.adapter_name()
    );
    let results = vec![render_frame(&mut offscreen)?];
    let report = BenchReport { machine, results };
    if json {
        println!("{}", serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?);
    } else {
        println!("machine: {}", report.machine);
        println!("{:<40} {:>12} {:<5} {:<44} {:>12} {:>8}", "name", "value", "unit", "baseline", "baseline", "ratio");
        for r in &report.results {
            println!(
                "{:<40} {:>12.3} {:<5} {:<44} {:>12.3} {:>7.2}×",
                r.name, r.value, r.unit, r.baseline, r.baseline_value, r.ratio
            );
        }
    }
    Ok(())
}
