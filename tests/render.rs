//! Offscreen rendering with the app's renderer and shaders (lavapipe on CPU-only machines):
//! the default cloud is on screen, lit from the sun's side, over an untouched background, and
//! the same document always gives the same image.

use std::sync::{Mutex, OnceLock};

use cloudsketch::derive::frame_of;
use cloudsketch::render::offscreen::{Backdrop, Image, LinearImage, Offscreen, Output};
use cloudsketch::scene::{Channel, Preset, Scene, set_by_pointer};

const W: u32 = 200;
const H: u32 = 150;

/// The tests' one offscreen device (lavapipe on CPU-only machines).
fn offscreen() -> std::sync::MutexGuard<'static, Offscreen> {
    static DEVICE: OnceLock<Mutex<Offscreen>> = OnceLock::new();
    DEVICE
        .get_or_init(|| Mutex::new(Offscreen::new().expect("an offscreen wgpu adapter (lavapipe)")))
        .lock()
        .unwrap_or_else(|e| e.into_inner())
}

fn render(scene: &Scene) -> Image {
    offscreen()
        .render(&frame_of(scene, None), W, H, Backdrop::Sky)
        .expect("render")
}

fn with(scene: &Scene, sets: &[&str]) -> Scene {
    sets.iter()
        .fold(scene.clone(), |s, a| set_by_pointer(&s, a).unwrap().0)
}

/// The default cumulus without its billows: the shape the light, media and ground tests were
/// calibrated on (billows change the cloud's size and add structure of their own; their own
/// test is `billows_make_the_outline_rough_at_every_scale`).
fn smooth_cumulus() -> Scene {
    let mut scene = Scene::default();
    for e in &mut scene.ellipsoids {
        std::sync::Arc::make_mut(e).billows.levels = 0;
    }
    scene
}

fn background(scene: &Scene) -> [u8; 3] {
    scene.light.background.map(|v| (v * 255.0).round() as u8)
}

fn differs(p: [u8; 4], bg: [u8; 3]) -> bool {
    (0..3).any(|i| (p[i] as i32 - bg[i] as i32).abs() > 6)
}

fn luminance(p: [u8; 4]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// Mean luminance of cloud pixels in the left and right halves of the cloud's screen extent.
fn half_brightness(image: &Image, bg: [u8; 3]) -> (f64, f64) {
    let cloud: Vec<(u32, u32)> = (0..image.height)
        .flat_map(|y| (0..image.width).map(move |x| (x, y)))
        .filter(|&(x, y)| differs(image.pixel(x, y), bg))
        .collect();
    let (min_x, max_x) = cloud
        .iter()
        .fold((u32::MAX, 0), |(a, b), &(x, _)| (a.min(x), b.max(x)));
    let mid = (min_x + max_x) / 2;
    let mean = |f: &dyn Fn(u32) -> bool| {
        let v: Vec<f64> = cloud
            .iter()
            .filter(|(x, _)| f(*x))
            .map(|&(x, y)| luminance(image.pixel(x, y)))
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    (mean(&|x| x < mid), mean(&|x| x > mid))
}

#[test]
fn default_cloud_covers_the_middle_of_the_frame() {
    let scene = Scene::default();
    let image = render(&scene);
    let bg = background(&scene);
    let covered = image
        .rgba
        .chunks(4)
        .filter(|p| differs([p[0], p[1], p[2], p[3]], bg))
        .count();
    let fraction = covered as f64 / (W * H) as f64;
    assert!(
        (0.05..0.8).contains(&fraction),
        "cloud covers {:.1}% of the frame",
        fraction * 100.0
    );
    assert!(
        differs(image.pixel(W / 2, H / 2), bg),
        "no cloud at the centre"
    );
    for (x, y) in [(0, 0), (W - 1, 0), (0, H - 1), (W - 1, H - 1)] {
        let p = image.pixel(x, y);
        assert_eq!([p[0], p[1], p[2]], bg, "corner ({x},{y}) is not background");
    }
    // The cloud is brighter than the sky behind it somewhere (it is lit, not a dark hole).
    assert!(
        image
            .rgba
            .chunks(4)
            .any(|p| luminance([p[0], p[1], p[2], 255])
                > luminance([bg[0], bg[1], bg[2], 255]) + 40.0)
    );
}

#[test]
fn the_sun_side_is_brighter() {
    let scene = Scene::default();
    let bg = background(&scene);
    // Sun low on the right (+x), then low on the left.
    let right = render(&with(
        &scene,
        &["/light/sun_azimuth_deg=0", "/light/sun_elevation_deg=5"],
    ));
    let left = render(&with(
        &scene,
        &["/light/sun_azimuth_deg=180", "/light/sun_elevation_deg=5"],
    ));
    let (rl, rr) = half_brightness(&right, bg);
    let (ll, lr) = half_brightness(&left, bg);
    assert!(
        rr > rl + 8.0,
        "sun on the right: left {rl:.1}, right {rr:.1}"
    );
    assert!(
        ll > lr + 8.0,
        "sun on the left: left {ll:.1}, right {lr:.1}"
    );
}

#[test]
fn same_document_same_image() {
    let scene = with(&Scene::default(), &["/render/slices=64"]);
    assert_eq!(render(&scene), render(&scene));
}

#[test]
fn empty_scene_is_all_background() {
    let scene = Scene::preset(Preset::Empty);
    let image = render(&scene);
    let bg = background(&scene);
    assert!(image.rgba.chunks(4).all(|p| [p[0], p[1], p[2]] == bg));
}

#[test]
fn more_opacity_more_cover() {
    let scene = Scene::default();
    let bg = background(&scene);
    let cover = |s: &Scene| {
        render(s)
            .rgba
            .chunks(4)
            .filter(|p| differs([p[0], p[1], p[2], p[3]], bg))
            .count()
    };
    let thin = cover(&with(&scene, &["/render/opacity=0.2"]));
    let thick = cover(&with(&scene, &["/render/opacity=6"]));
    assert!(
        thick > thin,
        "opacity 6 covers {thick} px, 0.2 covers {thin} px"
    );
}

/// Pixels whose colour differs by more than 24/255 (summed) between two images.
fn changed(
    a: &cloudsketch::render::offscreen::Image,
    b: &cloudsketch::render::offscreen::Image,
) -> usize {
    a.rgba
        .chunks(4)
        .zip(b.rgba.chunks(4))
        .filter(|(p, q)| {
            (0..3)
                .map(|i| (p[i] as i32 - q[i] as i32).abs())
                .sum::<i32>()
                > 24
        })
        .count()
}

#[test]
fn table_2_filters_and_the_worley_basis_each_change_the_media() {
    // Each filter changes a tenth of the cloud's pixels or more against every other filter,
    // and the other basis a twentieth of its coverage (the same document always gives the
    // same image, so any difference comes from the media).
    let base = with(
        &Scene::default(),
        &[
            "/render/slices=64",
            "/render/noise_amount=0.6",
            // Half the sun: the cloud in the tone map's middle, not its shoulder near white.
            "/light/sun_intensity=0.8",
        ],
    );
    let images: Vec<_> = ["stratus", "cumulus", "wispy", "veined"]
        .iter()
        .map(|f| render(&with(&base, &[&format!("/render/noise_filter=\"{f}\"")])))
        .collect();
    let cloud = images[0]
        .rgba
        .chunks(4)
        .filter(|p| differs([p[0], p[1], p[2], p[3]], background(&base)))
        .count();
    for i in 0..images.len() {
        for j in i + 1..images.len() {
            let d = changed(&images[i], &images[j]);
            assert!(
                d > cloud / 10,
                "filters {i} and {j}: {d} of {cloud} cloud px differ"
            );
        }
    }
    // The basis changes the noise's cells, not its scale, so it is measured where the light
    // model cannot smooth it away: in the cloud's coverage (alpha, over a transparent
    // background), which it changes by more than 24 levels at a twentieth of the covered
    // pixels or more (315 of 4,189 here; none if the basis were ignored).
    let coverage = |s: &Scene| {
        offscreen()
            .render(&frame_of(s, None), W, H, Backdrop::Transparent)
            .expect("render")
    };
    let (perlin, worley) = (
        coverage(&base),
        coverage(&with(&base, &["/render/noise_basis=\"worley\""])),
    );
    let alpha = |i: &Image| i.rgba.chunks(4).map(|p| p[3]).collect::<Vec<_>>();
    let (a, b) = (alpha(&perlin), alpha(&worley));
    let covered = a.iter().filter(|&&v| v > 0).count();
    let d = a
        .iter()
        .zip(&b)
        .filter(|(p, q)| (**p as i32 - **q as i32).abs() > 24)
        .count();
    eprintln!("Worley vs Perlin: coverage changed at {d} of {covered} px");
    assert!(
        d > covered / 20,
        "Worley vs Perlin: coverage changed at {d} of {covered} px"
    );
}

#[test]
fn sharpness_trims_the_fringe_without_shrinking_the_core() {
    let base = with(&Scene::default(), &["/render/slices=64"]);
    let bg = background(&base);
    // Fringe: pixels off the sky by 7–60 (summed over channels); core: more than 60.
    let measure = |s: &Scene| {
        let image = render(s);
        let mut fringe = 0;
        let mut core = 0;
        for p in image.rgba.chunks(4) {
            let d: i32 = (0..3).map(|i| (p[i] as i32 - bg[i] as i32).abs()).sum();
            if d > 60 {
                core += 1;
            } else if d > 6 {
                fringe += 1;
            }
        }
        (fringe, core)
    };
    let (soft_fringe, soft_core) = measure(&base);
    let (sharp_fringe, sharp_core) = measure(&with(&base, &["/render/sharpness=0.8"]));
    assert!(
        (sharp_fringe as f64) < 0.8 * soft_fringe as f64,
        "fringe {soft_fringe} → {sharp_fringe} px"
    );
    assert!(
        sharp_core as f64 > 0.85 * soft_core as f64,
        "core {soft_core} → {sharp_core} px"
    );
}

#[test]
fn wind_moves_the_media_over_scene_time_and_calm_air_does_not() {
    let base = with(
        &smooth_cumulus(),
        &["/render/slices=64", "/render/noise_amount=0.6"],
    );
    let at = |s: &Scene, t: f32| {
        let mut s = s.clone();
        s.time = t;
        render(&s)
    };
    assert_eq!(
        at(&base, 0.0),
        at(&base, 3.0),
        "no wind, no torque: time changes nothing"
    );
    let windy = with(&base, &["/render/wind=[1.5,0]"]);
    let d = changed(&at(&windy, 0.0), &at(&windy, 1.0));
    assert!(d > 500, "the wind moved the noise: {d} px changed");
    let turning = with(&base, &["/render/torque=30"]);
    let d = changed(&at(&turning, 0.0), &at(&turning, 1.0));
    assert!(d > 500, "the torque turned the noise: {d} px changed");
}

/// Mean luminance of the opaque cloud pixels (far from the sky's colour, so the sky showing
/// through a thin edge does not count) in each quarter of their screen extent, left to right.
fn quarter_brightness(image: &cloudsketch::render::offscreen::Image, bg: [u8; 3]) -> [f64; 4] {
    let opaque = |p: [u8; 4]| {
        (0..3)
            .map(|i| (p[i] as i32 - bg[i] as i32).abs())
            .sum::<i32>()
            > 90
    };
    let cloud: Vec<(u32, u32)> = (0..image.height)
        .flat_map(|y| (0..image.width).map(move |x| (x, y)))
        .filter(|&(x, y)| opaque(image.pixel(x, y)))
        .collect();
    let (lo, hi) = cloud
        .iter()
        .fold((u32::MAX, 0), |(a, b), &(x, _)| (a.min(x), b.max(x)));
    let width = (hi - lo + 1) as f64;
    let mut sum = [0.0; 4];
    let mut count = [0usize; 4];
    for &(x, y) in &cloud {
        let q = (((x - lo) as f64 / width) * 4.0) as usize;
        sum[q.min(3)] += luminance(image.pixel(x, y));
        count[q.min(3)] += 1;
    }
    std::array::from_fn(|i| sum[i] / count[i].max(1) as f64)
}

#[test]
fn dirtiness_makes_the_cloud_darken_faster_away_from_the_sun() {
    // Sun low on the right. Table 2's Dirtiness sets how fast the cloud darkens with depth:
    // from a clean cloud (0.25) to the default (1), the brightness a quarter of the cloud in
    // from the sunlit edge falls further behind the edge's own. (Dirtier still, the edge
    // quarter darkens too, toward the ambient light alone, so the ratio does not keep falling:
    // it stays below the clean cloud's.)
    let scene = with(
        &Scene::default(),
        &[
            "/light/sun_azimuth_deg=0",
            "/light/sun_elevation_deg=5",
            "/render/slices=64",
            // Half the sun: the cloud in the tone map's middle, not its shoulder near white.
            "/light/sun_intensity=0.8",
        ],
    );
    let bg = background(&scene);
    let falloff = |d: &str| {
        let q = quarter_brightness(
            &render(&with(&scene, &[&format!("/render/dirtiness={d}")])),
            bg,
        );
        q[2] / q[3]
    };
    let (clean, default, dirty) = (falloff("0.25"), falloff("1"), falloff("3"));
    assert!(
        clean > default + 0.03 && clean > dirty + 0.01,
        "inner/edge brightness: clean {clean:.3}, default {default:.3}, dirty {dirty:.3}"
    );
}

/// Screen bounding box (width, height) of the pixels that differ from the sky.
fn cloud_box(image: &cloudsketch::render::offscreen::Image, bg: [u8; 3]) -> (u32, u32) {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for y in 0..image.height {
        for x in 0..image.width {
            if differs(image.pixel(x, y), bg) {
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            }
        }
    }
    (x1.saturating_sub(x0) + 1, y1.saturating_sub(y0) + 1)
}

#[test]
fn presets_are_each_recognisable() {
    let names = ["cumulus", "stratus", "cirrus", "cumulonimbus", "sunset"];
    let scenes: Vec<Scene> = names
        .iter()
        .map(|n| {
            with(
                &Scene::preset(Preset::from_name(n).unwrap()),
                &["/render/slices=64"],
            )
        })
        .collect();
    let images: Vec<_> = scenes.iter().map(render).collect();
    // The baseline: the same preset with another seed (other noise) differs this much.
    for (i, scene) in scenes.iter().enumerate() {
        let reseeded = render(&with(scene, &["/seed=2"]));
        let noise = changed(&images[i], &reseeded).max(50);
        for j in (0..images.len()).filter(|&j| j != i) {
            let d = changed(&images[i], &images[j]);
            assert!(
                d >= 3 * noise,
                "{} vs {}: {d} px, two seeds of {}: {noise} px",
                names[i],
                names[j],
                names[i]
            );
        }
    }
    // The stratus is a layer seen from below: a sheet wider than the view, over open sky. The
    // camera stands beyond its near edge, under its height, looking up: the image's top rows
    // show that edge's side, lit (the sun is to the right, a little in front), and its bottom
    // rows the base toward its far edge, seen from below through the layer's shadow: greyer.
    // (A cloud seen whole, as the sausage it was, fits inside the frame.)
    let bg = background(&scenes[1]);
    let (w, h) = cloud_box(&images[1], bg);
    assert!(
        w == W && (h as f64) <= 0.8 * H as f64,
        "stratus is a layer overhead: {w}×{h} px of {W}×{H}"
    );
    let widths = row_widths(&images[1], bg);
    let first = widths.iter().position(|&n| n > 0).unwrap_or(0) as u32;
    let rows_mean = |rows: std::ops::Range<u32>| {
        let v: Vec<f64> = rows
            .flat_map(|y| (0..W).map(move |x| (x, y)))
            .map(|(x, y)| images[1].pixel(x, y))
            .filter(|&p| differs(p, bg))
            .map(luminance)
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    let (edge, base) = (
        rows_mean(first..first + h / 5),
        rows_mean(first + h - h / 5..first + h),
    );
    assert!(
        base < 0.85 * edge,
        "stratus: its base {base:.1}, its near edge {edge:.1}"
    );
    // The cumulonimbus towers, and its anvil spreads on top: the widest row of its top fifth
    // is far wider than the tower at half its height (a column, or a dome, is not).
    let bg = background(&scenes[3]);
    let (w, h) = cloud_box(&images[3], bg);
    assert!(
        h as f64 >= 0.9 * w as f64,
        "cumulonimbus towers: {w}×{h} px"
    );
    let widths = row_widths(&images[3], bg);
    let rows: Vec<usize> = (0..widths.len()).filter(|&y| widths[y] > 0).collect();
    let (top, bottom) = (rows[0], rows[rows.len() - 1]);
    let anvil = widths[top..=top + (bottom - top) / 5]
        .iter()
        .max()
        .copied()
        .unwrap_or(0);
    let waist = widths[(top + bottom) / 2];
    assert!(
        anvil as f64 >= 1.8 * waist as f64,
        "cumulonimbus anvil: {anvil} px wide, the tower at half height {waist} px"
    );
    // It spreads downwind (+x, to the right from the preset's camera): past the tower's middle
    // it reaches at least twice as far right as left (the symmetric mushroom it was: 1.4×).
    let image = &images[3];
    let xs = |y: u32| (0..image.width).filter(move |&x| differs(image.pixel(x, y), bg));
    let middle = {
        let row: Vec<u32> = xs(((top + bottom) / 2) as u32).collect();
        row.iter().sum::<u32>() as f64 / row.len().max(1) as f64
    };
    let (left, right) = (top..=top + (bottom - top) / 5)
        .flat_map(|y| xs(y as u32))
        .fold((f64::MAX, 0f64), |(l, r), x| {
            (l.min(x as f64), r.max(x as f64))
        });
    assert!(
        right - middle >= 2.0 * (middle - left),
        "cumulonimbus anvil downwind: {:.0} px right of the tower, {:.0} px left",
        right - middle,
        middle - left
    );
}

/// Each row's count of pixels that differ from the sky.
fn row_widths(image: &cloudsketch::render::offscreen::Image, bg: [u8; 3]) -> Vec<u32> {
    (0..image.height)
        .map(|y| {
            (0..image.width)
                .filter(|&x| differs(image.pixel(x, y), bg))
                .count() as u32
        })
        .collect()
}

#[test]
fn quality_changes_smoothness_not_the_cloud() {
    // Table 2's Quality is the slice count: 64 and 256 slices give the same coverage and mean
    // brightness within 5% (the extinction is per world unit), for a round cloud and for a flat
    // layer (whose slices span only its box's depth, not its bounding sphere's).
    for name in ["cumulus", "stratus"] {
        let scene = Scene::preset(Preset::from_name(name).unwrap());
        let bg = background(&scene);
        let measure = |slices: u32| {
            let image = render(&with(&scene, &[&format!("/render/slices={slices}")]));
            let cloud: Vec<[u8; 4]> = image
                .rgba
                .chunks(4)
                .map(|p| [p[0], p[1], p[2], p[3]])
                .filter(|&p| differs(p, bg))
                .collect();
            let mean = cloud.iter().map(|&p| luminance(p)).sum::<f64>() / cloud.len().max(1) as f64;
            (cloud.len() as f64, mean)
        };
        let ((c64, b64), (c256, b256)) = (measure(64), measure(256));
        assert!(c64 > 500.0, "{name}: a cloud");
        assert!(
            (c256 / c64 - 1.0).abs() < 0.05,
            "{name}: coverage {c64} → {c256}"
        );
        assert!(
            (b256 / b64 - 1.0).abs() < 0.05,
            "{name}: brightness {b64:.1} → {b256:.1}"
        );
    }
}

/// High-frequency energy of an image: the mean squared Laplacian of its luminance over the
/// pixels where the cloud is.
fn detail_energy(image: &cloudsketch::render::offscreen::Image, bg: [u8; 3]) -> f64 {
    let l = |x: u32, y: u32| luminance(image.pixel(x, y));
    let (mut sum, mut n) = (0.0, 0);
    for y in 1..image.height - 1 {
        for x in 1..image.width - 1 {
            if differs(image.pixel(x, y), bg) {
                let lap = 4.0 * l(x, y) - l(x - 1, y) - l(x + 1, y) - l(x, y - 1) - l(x, y + 1);
                sum += lap * lap;
                n += 1;
            }
        }
    }
    sum / n.max(1) as f64
}

#[test]
fn more_detail_more_fine_structure_and_opacity_keeps_the_cloud_in_place() {
    let scene = with(
        &smooth_cumulus(),
        // Single scattering: the structure Detail makes, not the multiple scattering's smooth
        // light over it (which the seed's other noise moves as much as Detail moves the rest).
        &[
            "/render/slices=64",
            "/render/noise_octaves=5",
            "/light/multiple_scattering=0",
        ],
    );
    let bg = background(&scene);
    // Detail is the lacunarity: a larger step between octaves puts the finer octaves finer.
    let smooth = detail_energy(&render(&with(&scene, &["/render/detail=1.6"])), bg);
    let rough = detail_energy(&render(&with(&scene, &["/render/detail=3.2"])), bg);
    // The baseline: how far the measure moves for a change that is not Detail (the same
    // Detail, the noise moved by another seed). Detail must move it three times as far (or
    // 3% of it, if the seed moved it less than 1%). Measured on lavapipe: 93.5 → 112.4
    // for Detail; a Detail that changed nothing gives no change at all.
    let moved = detail_energy(
        &render(&with(&scene, &["/render/detail=1.6", "/seed=99"])),
        bg,
    );
    let baseline = (moved - smooth).abs().max(0.01 * smooth);
    assert!(
        rough - smooth > 3.0 * baseline,
        "high-frequency energy {smooth:.1} → {rough:.1} with Detail, {smooth:.1} → {moved:.1} \
         with another seed"
    );
    // Opacity covers more but does not move the cloud: its centroid stays within a pixel.
    let centroid = |s: &Scene| {
        let image = render(s);
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
        for y in 0..image.height {
            for x in 0..image.width {
                if differs(image.pixel(x, y), bg) {
                    (sx, sy, n) = (sx + x as f64, sy + y as f64, n + 1.0);
                }
            }
        }
        (sx / n, sy / n, n)
    };
    let (x1, y1, n1) = centroid(&with(&scene, &["/render/opacity=1"]));
    let (x2, y2, n2) = centroid(&with(&scene, &["/render/opacity=4"]));
    assert!(n2 > n1, "opacity 4 covers more: {n1} → {n2}");
    assert!(
        (x2 - x1).hypot(y2 - y1) <= 1.0,
        "centroid ({x1:.1},{y1:.1}) → ({x2:.1},{y2:.1})"
    );
}

/// Mean and largest difference of two images' colour channels (0–255).
fn image_difference(a: &Image, b: &Image) -> (f64, u8) {
    let (mut sum, mut worst, mut n) = (0.0, 0u8, 0usize);
    for y in 0..a.height {
        for x in 0..a.width {
            let (p, q) = (a.pixel(x, y), b.pixel(x, y));
            for i in 0..3 {
                let d = p[i].abs_diff(q[i]);
                sum += d as f64;
                worst = worst.max(d);
                n += 1;
            }
        }
    }
    (sum / n as f64, worst)
}

#[test]
fn a_scene_opened_from_its_link_renders_as_the_scene() {
    use cloudsketch::share::{decode_link, encode_link, fixture};
    let through_link = |s: &Scene| {
        decode_link(&format!("#s={}", encode_link(s).unwrap()))
            .unwrap()
            .0
    };
    let mut scenes: Vec<(&str, Scene)> = Preset::ALL
        .iter()
        .map(|&(p, name)| (name, Scene::preset(p)))
        .collect();
    scenes.push(("five hand-drawn strokes", fixture::hand_drawn()));
    let mut largest = 0.0f64;
    for (name, scene) in &scenes {
        let (a, b) = (render(scene), render(&through_link(scene)));
        let (mean, worst) = image_difference(&a, &b);
        largest = largest.max(mean);
        // Settings are rounded to 5 digits; strokes made in the app come back exactly. Within 3
        // levels but at a speck or two of the noise at the cloud's edge, which the rounding
        // tips over the iso level (the stratus: one pixel of 30,000, 5 levels).
        let specks = a
            .rgba
            .chunks(4)
            .zip(b.rgba.chunks(4))
            .filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 3))
            .count();
        assert!(
            mean < 0.01 && specks <= 2 && worst <= 8,
            "{name}: mean {mean:.3}, worst {worst}, {specks} pixels over 3"
        );
    }
    // The measure sees a change a user would barely notice: one stroke moved by 2.5% of its
    // size gives a difference far above the link's.
    let sketched = fixture::hand_drawn();
    let mut moved = sketched.clone();
    let plane = std::sync::Arc::make_mut(&mut moved.planes[0]);
    plane.origin.y += 0.15;
    let (mean, _) = image_difference(&render(&sketched), &render(&moved));
    assert!(
        mean > 10.0 * largest,
        "moved {mean:.3} vs the link's {largest:.3}"
    );
}

/// The bench's GPU baseline evaluates the same field as the CPU: every texel of 300 rotated,
/// carving and overlapping ellipsoids on the CPU's grid, against the brute-force CPU bake.
#[test]
fn the_gpu_field_evaluation_matches_the_cpu_bake() {
    static DEVICE: OnceLock<Mutex<Offscreen>> = OnceLock::new();
    let mut device = DEVICE
        .get_or_init(|| Mutex::new(Offscreen::new().expect("an offscreen wgpu adapter")))
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let mut scene = cloudsketch::bench::ellipsoid_bank(300);
    let e = std::sync::Arc::make_mut(&mut scene.ellipsoids[7]);
    e.strength = -0.7;
    e.rotation = glam::Quat::from_rotation_z(0.6);
    let field = cloudsketch::derive::field_of(&scene);
    let cpu = cloudsketch::field::bake_brute_force(&field, 40);
    let gpu = device.field_on_gpu(&field, 40).unwrap();
    assert_eq!(gpu.dims, cpu.dims);
    assert!((gpu.min - cpu.min).abs().max_element() < 1e-4);
    let worst = cpu
        .values
        .iter()
        .zip(&gpu.values)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    let peak = cpu.values.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert!(peak > 0.5, "the bank reaches the surface level: {peak}");
    assert!(
        worst < 1e-4 * peak.max(1.0),
        "GPU and CPU differ by {worst}"
    );
    // A plausible wrong version (the primitives unrotated) is far off, so the match means
    // something.
    let mut unrotated = field.clone();
    for b in &mut unrotated.blobs {
        b.to_unit = glam::Mat3::from_diagonal(b.to_unit.row(0).length() * glam::Vec3::ONE);
    }
    let wrong = device.field_on_gpu(&unrotated, 40).unwrap();
    let off = cpu
        .values
        .iter()
        .zip(&wrong.values)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(off > 100.0 * worst.max(1e-6), "{off} vs {worst}");
}

/// The luminance below which `share` of the cloud's pixels lie (0.5: the median).
fn cloud_percentile(image: &Image, bg: [u8; 3], share: f64) -> f64 {
    let mut v: Vec<f64> = (0..image.height)
        .flat_map(|y| (0..image.width).map(move |x| (x, y)))
        .map(|(x, y)| image.pixel(x, y))
        .filter(|&p| differs(p, bg))
        .map(luminance)
        .collect();
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(((v.len() as f64 * share) as usize).min(v.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0.0)
}

#[test]
fn forward_scattering_brightens_the_cloud_toward_the_sun_and_dims_it_with_the_sun_behind() {
    let scene = with(
        &Scene::default(),
        &[
            "/light/multiple_scattering=0",
            "/light/sun_elevation_deg=10",
        ],
    );
    let bg = background(&scene);
    // The brightest tenth of the cloud: where light gets through (the silver lining when the
    // sun is behind the cloud, the lit face when it is behind the viewer).
    let mean = |sets: &[&str]| cloud_percentile(&render(&with(&scene, sets)), bg, 0.9);
    // The camera looks toward −z: the sun at azimuth 270° is behind the cloud, at 90° behind
    // the viewer.
    let toward_iso = mean(&["/light/sun_azimuth_deg=270", "/light/forward_scattering=0"]);
    let toward = mean(&[
        "/light/sun_azimuth_deg=270",
        "/light/forward_scattering=0.8",
    ]);
    let behind_iso = mean(&["/light/sun_azimuth_deg=90", "/light/forward_scattering=0"]);
    let behind = mean(&["/light/sun_azimuth_deg=90", "/light/forward_scattering=0.8"]);
    assert!(
        toward > toward_iso * 1.2,
        "toward the sun: {toward:.1} vs isotropic {toward_iso:.1}"
    );
    assert!(
        behind < behind_iso * 0.9,
        "sun behind the viewer: {behind:.1} vs isotropic {behind_iso:.1}"
    );
}

#[test]
fn multiple_scattering_lights_the_shadowed_side_more_than_the_lit_side() {
    // Thick clouds stay bright inside: the darkest tenth of the cloud (deep in its shadow)
    // gains more, relatively, than the brightest tenth (in full sun); a plain brightening
    // would do the opposite, the ambient sky being most of the shadow's light.
    let scene = with(
        &Scene::default(),
        &[
            "/light/sun_azimuth_deg=0",
            "/light/sun_elevation_deg=5",
            "/light/forward_scattering=0",
            "/render/opacity=6",
        ],
    );
    let bg = background(&scene);
    let single = render(&with(&scene, &["/light/multiple_scattering=0"]));
    let multiple = render(&with(&scene, &["/light/multiple_scattering=1"]));
    let (dark0, dark1) = (
        cloud_percentile(&single, bg, 0.1),
        cloud_percentile(&multiple, bg, 0.1),
    );
    let (lit0, lit1) = (
        cloud_percentile(&single, bg, 0.9),
        cloud_percentile(&multiple, bg, 0.9),
    );
    assert!(
        dark1 > dark0 + 15.0,
        "darkest tenth {dark0:.1} → {dark1:.1}"
    );
    assert!(
        dark1 / dark0 > lit1 / lit0,
        "relative gain: shadowed {:.3}, lit {:.3}",
        dark1 / dark0,
        lit1 / lit0
    );
}

/// Per row, the mean luminance of the cloud's pixels (NaN where the row has none).
fn row_means(image: &Image, bg: [u8; 3]) -> Vec<f64> {
    (0..image.height)
        .map(|y| {
            let v: Vec<f64> = (0..image.width)
                .map(|x| image.pixel(x, y))
                .filter(|&p| differs(p, bg))
                .map(luminance)
                .collect();
            if v.len() < 10 {
                f64::NAN
            } else {
                v.iter().sum::<f64>() / v.len() as f64
            }
        })
        .collect()
}

/// The screen row of world height `y` at the scene's focus (the camera's target column).
fn row_of_height(scene: &Scene, y: f32) -> u32 {
    let c = &scene.camera;
    let p = glam::Vec3::new(c.target.x, y, c.target.z);
    let clip = c.view_projection(W as f32 / H as f32) * p.extend(1.0);
    ((1.0 - clip.y / clip.w) * 0.5 * H as f32).round() as u32
}

#[test]
fn an_upper_tier_moves_with_its_own_wind_and_its_floor_shows_no_step() {
    let scene = with(
        &smooth_cumulus(),
        &[
            "/render/noise_amount=0.6",
            "/render/noise_octaves=4",
            "/render/slices=192",
            "/render/tiers=[{\"floor\":3.5,\"filter\":\"veined\",\"wind\":[3,0],\"torque\":0}]",
            "/render/light_resolution=40",
            // Single scattering: the step is in the noise's structure across the floor, which
            // the multiple scattering's smooth light (ample at the default) covers.
            "/light/multiple_scattering=0",
        ],
    );
    let bg = background(&scene);
    let floor_row = row_of_height(&scene, 3.5) as usize;
    // Wind aloft only: after two seconds the image changes above the floor, not below.
    let t0 = render(&scene);
    let t2 = render(&with(&scene, &["/time=2"]));
    let changed = |rows: std::ops::Range<usize>| {
        rows.map(|y| {
            (0..W)
                .filter(|&x| {
                    let (p, q) = (t0.pixel(x, y as u32), t2.pixel(x, y as u32));
                    (0..3).any(|i| p[i].abs_diff(q[i]) > 8)
                })
                .count()
        })
        .sum::<usize>()
    };
    let above = changed(floor_row.saturating_sub(30)..floor_row.saturating_sub(6));
    let below = changed(floor_row + 6..(floor_row + 30).min(H as usize));
    assert!(
        above > 80 && above > 5 * below,
        "changed pixels above the floor {above}, below {below}"
    );
    // Blended over the floor, the rows' brightness changes no more there than across the
    // image; with a hard floor (no blend) it steps.
    let step_at_floor = |blend: &str| {
        let rows = row_means(&render(&with(&scene, &[blend])), bg);
        let jump = |y: usize| (rows[y + 1] - rows[y]).abs();
        let near = (floor_row - 3..floor_row + 3)
            .map(jump)
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let mut elsewhere: Vec<f64> = (0..rows.len() - 1)
            .filter(|y| y.abs_diff(floor_row) > 8)
            .map(jump)
            .filter(|v| v.is_finite())
            .collect();
        elsewhere.sort_by(|a, b| a.total_cmp(b));
        (near, elsewhere[elsewhere.len() * 9 / 10])
    };
    let (hard, typical_hard) = step_at_floor("/render/tier_blend=0");
    let (soft, typical) = step_at_floor("/render/tier_blend=2");
    eprintln!(
        "hard {hard:.2} (typical {typical_hard:.2}), blended {soft:.2} (typical {typical:.2})"
    );
    // 2.0× under the old tone map (`1 − exp(−x)`); 1.8× under ACES's, whose toe shows the
    // rows' darker light with more contrast. Without the blend the two are the same.
    assert!(
        hard > 1.5 * soft,
        "hard floor {hard:.2} vs blended {soft:.2}"
    );
    assert!(
        soft <= 1.5 * typical.max(0.5),
        "blended {soft:.2} vs typical {typical:.2}"
    );
}

#[test]
fn a_broken_layer_casts_a_dappled_shadow_when_the_light_volume_sees_the_noise() {
    // The sun behind the camera lights the face in view (so its own relief casts little
    // shadow there); a thin, weak layer between the sun and that face, out of view above and
    // behind the camera, shades it. The noise breaks the layer into puffs and gaps, so the
    // shadow has sunlit gaps in it, if the light volume sees the noise. No sky light: it
    // comes through the cloud above too, and its own detail (the relief the noise gives the
    // face, lit from above) would be in both images.
    let scene = with(
        &Scene::preset(Preset::Empty),
        &[
            "/ellipsoids=[{\"center\":[0,2,0],\"radii\":[4.0,2.2,1.6]},\
              {\"center\":[0,6.6,6.6],\"radii\":[7.0,0.5,5.0],\"strength\":0.6}]",
            "/camera/target=[0,2,0]",
            "/camera/pitch_deg=0",
            "/camera/yaw_deg=0",
            "/camera/distance=9",
            "/light/sun_azimuth_deg=90",
            "/light/sun_elevation_deg=35",
            "/light/ambient=0",
            "/light/multiple_scattering=0",
            "/render/noise_amount=1",
            "/render/noise_octaves=4",
            "/render/opacity=6",
            "/render/light_resolution=96",
        ],
    );
    let bg = background(&scene);
    let lit = render(&with(&scene, &["/ellipsoids/1/hidden=true"]));
    let shadowed = render(&scene);
    // The baseline: the same slices, a light volume without the noise (a smooth shadow).
    let smooth = render(&with(&scene, &["/render/light_octaves=0"]));
    // The shadowed region: where the smooth shadow takes at least half of what it takes at
    // most, four pixels in from its edge (the edge itself is structure of any shadow).
    let l = |img: &Image, x: u32, y: u32| luminance(img.pixel(x, y));
    let darkened = |x: u32, y: u32| {
        if differs(lit.pixel(x, y), bg) {
            l(&lit, x, y) - l(&smooth, x, y)
        } else {
            0.0
        }
    };
    let most = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .map(|(x, y)| darkened(x, y))
        .fold(0.0, f64::max);
    let deep = |x: u32, y: u32| darkened(x, y) > 0.5 * most;
    const IN: u32 = 4;
    let region: Vec<(u32, u32)> = (IN..H - IN)
        .flat_map(|y| (IN..W - IN).map(move |x| (x, y)))
        .filter(|&(x, y)| (y - IN..=y + IN).all(|v| (x - IN..=x + IN).all(|u| deep(u, v))))
        .collect();
    assert!(region.len() > 500, "a shadow of {} pixels", region.len());
    let mean =
        |img: &Image| region.iter().map(|&(x, y)| l(img, x, y)).sum::<f64>() / region.len() as f64;
    let (bright, dark) = (mean(&lit), mean(&shadowed));
    assert!(
        dark < bright - 30.0,
        "in the shadow {dark:.1}, in the sun {bright:.1}"
    );
    // High-frequency energy there: the mean squared Laplacian of the luminance.
    let energy = |img: &Image| {
        let sum: f64 = region
            .iter()
            .map(|&(x, y)| {
                4.0 * l(img, x, y)
                    - l(img, x - 1, y)
                    - l(img, x + 1, y)
                    - l(img, x, y - 1)
                    - l(img, x, y + 1)
            })
            .map(|lap| lap * lap)
            .sum();
        sum / region.len() as f64
    };
    let (dappled, plain) = (energy(&shadowed), energy(&smooth));
    eprintln!(
        "shadow: {} px, {bright:.1} lit → {dark:.1}; high-frequency energy {plain:.2} without \
         the noise in the light volume, {dappled:.2} with it",
        region.len()
    );
    assert!(
        dappled >= 3.0 * plain,
        "high-frequency energy in the shadow: {dappled:.2} with the light volume's noise, \
         {plain:.2} without"
    );
}

/// Exposure scales all the light before the one tone map: the cloud's and the sky's alike. At
/// exposure 0 the flat background shows as picked; the old renderer, which tone-mapped the
/// cloud alone, left the sky as picked at every exposure and fails it.
#[test]
fn exposure_brightens_the_cloud_and_the_sky_by_stops_and_the_sky_shows_as_picked_at_0() {
    let scene = Scene::default();
    let bg = background(&scene);
    let stats = |s: &Scene| {
        let image = render(s);
        let corner = image.pixel(2, 2);
        let (mut sum, mut n) = (0.0, 0usize);
        for y in 0..image.height {
            for x in 0..image.width {
                let p = image.pixel(x, y);
                if differs(p, [corner[0], corner[1], corner[2]]) {
                    sum += luminance(p);
                    n += 1;
                }
            }
        }
        (sum / n.max(1) as f64, corner)
    };
    let (dark, corner_dark) = stats(&with(&scene, &["/light/exposure=-1.5"]));
    let (plain, corner) = stats(&scene);
    let (bright, corner_bright) = stats(&with(&scene, &["/light/exposure=1.5"]));
    assert!(
        dark + 10.0 < plain && plain + 10.0 < bright,
        "mean cloud luminance at −1.5 / 0 / +1.5 EV: {dark:.1} / {plain:.1} / {bright:.1}"
    );
    for c in 0..3 {
        assert!(
            (corner[c] as i32 - bg[c] as i32).abs() <= 1,
            "the sky at exposure 0 is {corner:?}, picked {bg:?}"
        );
    }
    let (l_dark, l, l_bright) = (
        luminance(corner_dark),
        luminance(corner),
        luminance(corner_bright),
    );
    assert!(
        l_dark + 10.0 < l && l + 10.0 < l_bright,
        "the sky's luminance at −1.5 / 0 / +1.5 EV: {l_dark:.1} / {l:.1} / {l_bright:.1}"
    );
}

#[test]
fn the_ground_under_a_cloud_is_darker_than_open_ground() {
    // Looking down on the default cloud over a ground plane, the sun high: the same view with
    // a cloud too thin to stop light (and so to cast a shadow) is the baseline.
    let scene = with(
        &smooth_cumulus(),
        &[
            "/light/ground=true",
            "/light/ground_height=-1.5",
            "/light/sun_elevation_deg=60",
            "/camera/pitch_deg=35",
            "/camera/distance=30",
        ],
    );
    let shaded = render(&scene);
    let clear = render(&with(&scene, &["/render/opacity=0.01"]));
    let (mut darker, mut lighter_ground) = (0, 0);
    for (a, b) in shaded.rgba.chunks(4).zip(clear.rgba.chunks(4)) {
        let (la, lb) = (
            luminance([a[0], a[1], a[2], 255]),
            luminance([b[0], b[1], b[2], 255]),
        );
        if la + 12.0 < lb {
            darker += 1;
        }
        // Open ground far from the cloud is the same in both (only its shadow differs).
        if (la - lb).abs() <= 1.0 {
            lighter_ground += 1;
        }
    }
    let total = (W * H) as usize;
    assert!(
        darker > total / 50,
        "{darker} of {total} pixels darker with the cloud's shadow"
    );
    assert!(
        lighter_ground > total / 4,
        "{lighter_ground} pixels unchanged"
    );
    // The ground is drawn (below the horizon the image is not the flat sky).
    let bg = background(&scene);
    let bottom = clear.pixel(W / 2, H - 3);
    assert!(differs(bottom, bg), "ground at the bottom: {bottom:?}");
}

/// A broken layer of three flat clouds over the ground, seen from below its edge looking
/// toward a low sun behind it: the shadows of the clouds fall toward the camera.
fn broken_layer() -> Scene {
    use cloudsketch::scene::Ellipsoid;
    use glam::Vec3;
    let mut scene = with(
        &Scene::default(),
        &[
            "/light/ground=true",
            "/light/ground_height=0",
            "/light/sun_azimuth_deg=270",
            "/light/sun_elevation_deg=30",
            "/camera/yaw_deg=0",
            "/camera/pitch_deg=4",
            "/camera/distance=34",
            "/camera/target=[0,5,0]",
        ],
    );
    scene.planes.clear();
    scene.ellipsoids = [-11.0f32, 0.0, 11.0]
        .map(|x| {
            std::sync::Arc::new(Ellipsoid::new(
                Vec3::new(x, 8.0, 0.0),
                Vec3::new(3.2, 1.3, 3.5),
            ))
        })
        .to_vec();
    scene
}

/// The light the shafts add, pixel by pixel: the linear image of `on` less that of `off` (over
/// the sky, the same scene with and without shafts: exactly the shafts' light where they lie
/// in front), as the luminance of `1 − exp(−light)` in levels (0–255), the scale these tests
/// were calibrated on. Measured as light, not as the display's difference: under the one tone
/// map the same light shows more over a dark pixel than over a bright one.
fn shaft_term(on: &Scene, off: &Scene) -> Vec<f64> {
    let (on, off) = (
        render_linear(on, Backdrop::Sky),
        render_linear(off, Backdrop::Sky),
    );
    on.rgba
        .chunks(4)
        .zip(off.rgba.chunks(4))
        .map(|(a, b)| {
            let m = |c: usize| 255.0 * (1.0 - (-f64::from(a[c] - b[c])).exp());
            0.2126 * m(0) + 0.7152 * m(1) + 0.0722 * m(2)
        })
        .collect()
}

#[test]
fn shafts_of_light_brighten_the_air_in_the_gaps_and_add_nothing_when_off() {
    let layer = broken_layer();
    let off = render(&layer);
    // Off, the shafts' own settings change nothing.
    let strong = ["/light/shaft_intensity=4", "/light/shaft_density=0.05"];
    assert_eq!(off.rgba, render(&with(&layer, &strong)).rgba);
    let on_sets = ["/light/shafts=true", "/light/shaft_density=0.003"];
    let on = render(&with(&layer, &on_sets));
    // The baseline: the same clouds too thin to shade the air (and so to cast shafts).
    let thin = with(&layer, &["/render/opacity=0.01"]);
    let thin_term = shaft_term(&with(&thin, &on_sets), &thin);
    let term = shaft_term(&with(&layer, &on_sets), &layer);
    if let Ok(dir) = std::env::var("CLOUDSKETCH_TEST_IMAGES") {
        std::fs::write(format!("{dir}/shafts_on.png"), on.to_png().unwrap()).unwrap();
        std::fs::write(format!("{dir}/shafts_off.png"), off.to_png().unwrap()).unwrap();
    }
    // Shafts only add light, and they light the air over most of the view.
    assert!(term.iter().all(|&t| t > -1.5), "shafts darkened a pixel");
    let lit = term.iter().filter(|&&t| t > 2.0).count();
    assert!(
        lit > term.len() / 2,
        "{lit} of {} pixels lit by the air",
        term.len()
    );
    // Below the layer, along a row through the air between it and the ground, against the
    // baseline pixel by pixel: the gaps are as bright as unshaded air, the clouds' shadows
    // darker, and the two alternate (two gaps, three shadows).
    let y = H * 53 / 100;
    let ratio: Vec<f64> = (0..W)
        .map(|x| {
            let i = (y * W + x) as usize;
            term[i] / thin_term[i].max(1.0)
        })
        .collect();
    let (lo, hi) = ratio
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(
        thin_term[(y * W) as usize] > 20.0,
        "the baseline's air is dark"
    );
    assert!(hi > 0.97, "the gaps are dim: {hi:.2} of the unshaded air");
    assert!(
        lo < 0.85,
        "no shadow in the air: {lo:.2} of the unshaded air"
    );
    let mid = 0.5 * (lo + hi);
    let crossings = ratio
        .windows(2)
        .filter(|w| (w[0] > mid) != (w[1] > mid))
        .count();
    assert!(
        crossings >= 4,
        "{crossings} changes between shaft and shadow"
    );
}

#[test]
fn a_transparent_image_keeps_the_shafts_light() {
    // Over no background the shafts' light has nothing to be added to: it needs alpha of its
    // own, or a straight-alpha image drops it (as this renderer once did). Open air,
    // transparent without shafts, carries with them the display of their light (what they
    // show over black: the one tone map of the light alone, sRGB-encoded).
    let layer = broken_layer();
    let lit_layer = with(
        &layer,
        &["/light/shafts=true", "/light/shaft_density=0.003"],
    );
    let transparent = |s: &Scene| {
        offscreen()
            .render(&frame_of(s, None), W, H, Backdrop::Transparent)
            .expect("render")
    };
    let clear = transparent(&layer);
    let glowing = transparent(&lit_layer);
    let (on, off) = (
        render_linear(&lit_layer, Backdrop::Sky),
        render_linear(&layer, Backdrop::Sky),
    );
    let shows = |i: usize| {
        let c = |k: usize| shown(f64::from(on.rgba[4 * i + k] - off.rgba[4 * i + k]));
        0.2126 * c(0) + 0.7152 * c(1) + 0.0722 * c(2)
    };
    let air: Vec<usize> = (0..(W * H) as usize)
        .filter(|&i| clear.rgba[4 * i + 3] == 0 && shows(i) > 10.0)
        .collect();
    assert!(
        air.len() > (W * H / 4) as usize,
        "{} pixels of lit air",
        air.len()
    );
    let kept = air
        .iter()
        .filter(|&&i| {
            let p = &glowing.rgba[4 * i..4 * i + 4];
            let light = luminance([p[0], p[1], p[2], 255]) * p[3] as f64 / 255.0;
            (light - shows(i)).abs() < 3.0 + 0.1 * shows(i)
        })
        .count();
    assert!(
        kept * 10 > air.len() * 9,
        "{kept} of {} pixels of lit air keep the shafts' light",
        air.len()
    );
}

/// Close to the default cloud, the sun to the side, shafts off: most of the lit air along a
/// view ray lies behind the cloud.
fn shafts_behind_a_cloud() -> Scene {
    with(
        &Scene::default(),
        &[
            "/camera/distance=14",
            "/light/sun_azimuth_deg=270",
            "/light/sun_elevation_deg=20",
            "/light/ambient=0",
            "/light/multiple_scattering=0",
            "/light/ground=true",
            "/light/ground_height=-40",
        ],
    )
}

#[test]
fn a_cloud_hides_the_shafts_behind_it_and_not_those_in_front() {
    // Shells merged with the slices add to an opaque pixel only the air in front of it; drawn
    // after every slice they would add all of it, before every slice none.
    let scene = shafts_behind_a_cloud();
    let off = render(&scene);
    let term = shaft_term(
        &with(
            &scene,
            &["/light/shafts=true", "/light/shaft_density=0.004"],
        ),
        &scene,
    );
    let bg = background(&scene);
    let x = W / 2;
    let cloud_rows: Vec<u32> = (0..H).filter(|&y| differs(off.pixel(x, y), bg)).collect();
    let (top, bottom) = (cloud_rows[0], *cloud_rows.last().unwrap());
    assert!(top > 8, "the cloud's top is out of view");
    let core = term[(((top + bottom) / 2) * W + x) as usize];
    let sky = term[((top - 6) * W + x) as usize];
    assert!(sky > 10.0, "the open sky's air adds {sky:.1}");
    assert!(
        core > 0.03 * sky && core < 0.5 * sky,
        "an opaque pixel gets {core:.1} of the air's light, the open sky {sky:.1}"
    );
}

#[test]
fn a_thin_layer_above_casts_a_shadow_without_bands() {
    // A thin, wide layer high above (out of view) between a high sun and the cloud in view,
    // the noise off so only the march shows: when the layer falls between a
    // number of march steps that changes with height, its shadow on the cloud shows bands.
    let scene = with(
        &Scene::preset(Preset::Empty),
        &[
            "/ellipsoids=[{\"center\":[0,2,0],\"radii\":[4.0,2.0,3.0]},{\"center\":[0,9.5,0],\"radii\":[7.0,0.6,7.0]}]",
            "/camera/target=[0,2,0]",
            "/camera/pitch_deg=0",
            "/camera/yaw_deg=0",
            "/camera/distance=10",
            "/light/sun_azimuth_deg=30",
            "/light/sun_elevation_deg=75",
            "/light/multiple_scattering=0",
            "/render/noise_octaves=0",
            "/render/light_octaves=0",
            "/render/light_resolution=96",
        ],
    );
    let bg = background(&scene);
    let lit = render(&with(&scene, &["/ellipsoids/1/hidden=true"]));
    let shadowed = render(&scene);
    // Rows through the middle of the cloud in view: each row's mean over its middle half.
    let cloud = |x: u32, y: u32| differs(lit.pixel(x, y), bg);
    let rows: Vec<u32> = (0..H)
        .filter(|&y| (W / 4..3 * W / 4).all(|x| cloud(x, y)))
        .collect();
    assert!(rows.len() > 20, "{} rows through the cloud", rows.len());
    let means = |img: &Image| -> Vec<f64> {
        rows.iter()
            .map(|&y| {
                (W / 4..3 * W / 4)
                    .map(|x| luminance(img.pixel(x, y)))
                    .sum::<f64>()
                    / (W / 2) as f64
            })
            .collect()
    };
    // Bands: the rows' means bending up and down from row to row (second differences).
    let banding = |m: &[f64]| {
        let d: Vec<f64> = m
            .windows(3)
            .map(|w| (w[0] - 2.0 * w[1] + w[2]).powi(2))
            .collect();
        d.iter().sum::<f64>() / d.len() as f64
    };
    let (dark, bright) = (means(&shadowed), means(&lit));
    let avg = |m: &[f64]| m.iter().sum::<f64>() / m.len() as f64;
    let (b_shadow, b_sun) = (banding(&dark), banding(&bright));
    eprintln!(
        "mean {:.1} in the shadow, {:.1} in the sun; banding {b_shadow:.3} vs {b_sun:.3}",
        avg(&dark),
        avg(&bright)
    );
    assert!(
        avg(&dark) < avg(&bright) - 15.0,
        "the layer above casts no shadow"
    );
    // The shadow dims the rows' own variation, so without bands it bends no more than the
    // sunlit cloud's rows do.
    assert!(
        b_shadow < 1.5 * b_sun,
        "the rows in the shadow bend {b_shadow:.3} (squared second differences), in the sun {b_sun:.3}"
    );
}

#[test]
fn the_slices_cover_the_whole_cloud_from_every_side() {
    // Each slice is drawn only over the rectangle around where its plane cuts the cloud's
    // box: from views all round, every pixel onto which a texel deep inside the cloud projects
    // (the CPU's bake of the same field, a brute-force reference) must show cloud.
    let base = Scene::default();
    let bg = background(&base);
    let field = cloudsketch::derive::field_of(&base);
    let volume = cloudsketch::field::bake(&field, 48);
    let texel = volume.size / volume.dims.as_vec3();
    let deep: Vec<glam::Vec3> = (0..volume.values.len())
        .filter(|&i| volume.values[i] > 0.85)
        .map(|i| {
            let (nx, ny) = (volume.dims.x as usize, volume.dims.y as usize);
            let at = glam::UVec3::new(
                (i % nx) as u32,
                ((i / nx) % ny) as u32,
                (i / (nx * ny)) as u32,
            );
            volume.min + (at.as_vec3() + 0.5) * texel
        })
        .collect();
    assert!(deep.len() > 100, "{} texels deep inside", deep.len());
    for (yaw, pitch, distance) in [
        (0.0, 0.0, 14.0),
        (35.0, 50.0, 12.0),
        (120.0, -30.0, 10.0),
        (200.0, 15.0, 9.0),
        (290.0, 80.0, 14.0),
        (60.0, -75.0, 12.0),
    ] {
        let scene = with(
            &base,
            &[
                &format!("/camera/yaw_deg={yaw}"),
                &format!("/camera/pitch_deg={pitch}"),
                &format!("/camera/distance={distance}"),
            ],
        );
        let image = render(&scene);
        let view_proj = scene.camera.view_projection(W as f32 / H as f32);
        let (mut seen, mut shown) = (0usize, 0usize);
        for p in &deep {
            let clip = view_proj * p.extend(1.0);
            if clip.w <= 0.0 {
                continue;
            }
            let (x, y) = (clip.x / clip.w, clip.y / clip.w);
            let (px, py) = ((x + 1.0) * 0.5 * W as f32, (1.0 - y) * 0.5 * H as f32);
            if (1.0..W as f32 - 1.0).contains(&px) && (1.0..H as f32 - 1.0).contains(&py) {
                seen += 1;
                shown += differs(image.pixel(px as u32, py as u32), bg) as usize;
            }
        }
        assert!(
            seen > 100,
            "yaw {yaw}, pitch {pitch}: {seen} deep texels in view"
        );
        assert!(
            shown == seen,
            "yaw {yaw}, pitch {pitch}: {} of {seen} deep texels project onto sky",
            seen - shown
        );
    }
}

#[test]
fn the_noise_octaves_stop_early_only_where_the_rest_cannot_matter() {
    // The slices stop summing noise octaves once the ones left cannot move the value across
    // the soft edge. A tier far above the cloud takes the other path, which sums every octave
    // (its weight there is 0): the two images must be the same to the bit.
    for preset in ["cumulus", "cumulonimbus", "stratus"] {
        let scene = with(
            &Scene::preset(Preset::from_name(preset).unwrap()),
            &["/render/noise_octaves=6", "/render/tiers=[]"],
        );
        let tiered = with(
            &scene,
            &["/render/tiers=[{\"floor\":1000,\"filter\":\"wispy\",\"wind\":[3,0],\"torque\":0}]"],
        );
        let (early, every) = (render(&scene), render(&tiered));
        let (mean, max) = image_difference(&early, &every);
        assert!(
            max == 0,
            "{preset}: the early stop changed the image (mean {mean:.4}, max {max})"
        );
    }
}

/// `scene` rendered with the slices marched (compute) and with them rasterised, each in
/// `chunks` draws.
fn marched_and_rasterised(scene: &Scene, chunks: u32) -> [Image; 2] {
    let mut o = offscreen();
    let was = o.marching();
    let images = [true, false].map(|on| {
        o.set_marching(on).expect("lavapipe marches the slices");
        o.render_in_chunks(&frame_of(scene, None), [W, H], Backdrop::Sky, chunks)
            .expect("render")
    });
    o.set_marching(was).unwrap();
    images
}

#[test]
fn marched_slices_give_the_rasterised_slices_image() {
    // GPUs march the slices in a compute pass (each pixel's ray through the same planes, front
    // to back, stopping behind opaque cloud); CPU adapters and browsers rasterise them. Both
    // must give one image, whole or in refinement's chunks: within rounding (the rasterised
    // slices round to the 16-bit target at every slice, the march once). A march whose planes
    // sit a quarter of a slice off differs by up to 88 (cirrus); one whose shafts ignore the
    // cloud in front of them by 19. An empty scene must be the background both ways.
    let presets = ["cumulus", "stratus", "cirrus", "cumulonimbus", "sunset"];
    let mut scenes: Vec<(String, Scene)> = presets
        .iter()
        .map(|p| (p.to_string(), Scene::preset(Preset::from_name(p).unwrap())))
        .collect();
    scenes.push((
        "orthographic".into(),
        with(&Scene::default(), &["/camera/orthographic=true"]),
    ));
    scenes.push((
        "shafts behind a cloud".into(),
        with(
            &shafts_behind_a_cloud(),
            &["/light/shafts=true", "/light/shaft_density=0.004"],
        ),
    ));
    scenes.push(("empty".into(), Scene::preset(Preset::Empty)));
    let mut identical = true;
    for (name, scene) in &scenes {
        // Whole, in three chunks, and asked for more chunks than one submission holds (8).
        for chunks in [1, 3, 20] {
            let [marched, raster] = marched_and_rasterised(scene, chunks);
            let (mean, max) = image_difference(&marched, &raster);
            let over = marched
                .rgba
                .iter()
                .zip(&raster.rgba)
                .filter(|(a, b)| a.abs_diff(**b) > 5)
                .count();
            eprintln!(
                "{name} in {chunks} draws: mean {mean:.3}, max {max}, {over} channels over 5"
            );
            // Within 5 levels but at a few pixels of thin, bright wisps (the cirrus: 131 of
            // 90,000 channels, 25 levels at most), where the one tone map shows the two
            // accumulations' rounding more than mapping the cloud alone did.
            assert!(
                mean <= 0.5 && over * 500 <= marched.rgba.len() && max <= 32,
                "{name} in {chunks} draws: marched and rasterised differ by {mean:.3} on average, {max} at most ({over} channels over 5)"
            );
            identical &= marched.rgba == raster.rgba;
            if name == "empty" {
                let bg = background(scene);
                let drawn = marched
                    .rgba
                    .chunks(4)
                    .filter(|p| differs([p[0], p[1], p[2], p[3]], bg));
                assert_eq!(drawn.count(), 0, "an empty scene marched draws something");
            }
        }
    }
    // Both paths ran: they round differently somewhere.
    assert!(!identical, "marching changed no pixel of any image");
}

/// Means of `image`'s 8×8 blocks (red, green, blue): what the eye sees of the shafts' light
/// once their fine grain is averaged.
fn block_means(image: &Image) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for by in 0..image.height / 8 {
        for bx in 0..image.width / 8 {
            let mut m = [0.0; 3];
            for y in by * 8..by * 8 + 8 {
                for x in bx * 8..bx * 8 + 8 {
                    let p = image.pixel(x, y);
                    for i in 0..3 {
                        m[i] += p[i] as f64 / 64.0;
                    }
                }
            }
            out.push(m);
        }
    }
    out
}

#[test]
fn the_viewport_draws_shafts_around_the_clouds_box_as_the_whole_view_draws_them() {
    // The viewport slices only the cloud's box on screen and draws the shafts of light over
    // the rest of the view apart, at a quarter of the size: the same image as the whole view
    // drawn with every shell among the slices, within the shafts' grain. The baseline: the
    // shafts off, which the split image must not resemble where the air is lit.
    // With a sky (the ground) its pass lays the shafts around the box; over a flat background
    // the strips' own composites do.
    for (name, scene, ground) in [
        ("behind", shafts_behind_a_cloud(), true),
        ("default", Scene::default(), true),
        ("flat", Scene::default(), false),
    ] {
        let on = with(
            &scene,
            &[
                "/light/shafts=true",
                "/light/shaft_density=0.004",
                &format!("/light/ground={ground}"),
            ],
        );
        let whole = render(&on);
        let split = offscreen()
            .render_cropped(&frame_of(&on, None), W, H)
            .expect("render");
        let off = render(&with(&on, &["/light/shafts=false"]));
        if let Ok(dir) = std::env::var("CLOUDSKETCH_TEST_IMAGES") {
            std::fs::write(
                format!("{dir}/shafts_{name}_whole.png"),
                whole.to_png().unwrap(),
            )
            .unwrap();
            std::fs::write(
                format!("{dir}/shafts_{name}_split.png"),
                split.to_png().unwrap(),
            )
            .unwrap();
        }
        let (a, b, c) = (block_means(&whole), block_means(&split), block_means(&off));
        let worst = |u: &[[f64; 3]], v: &[[f64; 3]]| {
            u.iter()
                .zip(v)
                .flat_map(|(p, q)| (0..3).map(move |i| (p[i] - q[i]).abs()))
                .fold(0.0f64, f64::max)
        };
        let (agree, shafts) = (worst(&a, &b), worst(&a, &c));
        let (mean, _) = image_difference(&whole, &split);
        assert!(
            shafts > 12.0,
            "{name}: the shafts show ({shafts:.1} at most off)"
        );
        assert!(
            agree < 4.0 && mean < 2.0,
            "{name}: the split image's 8×8 means differ by {agree:.1} at most, {mean:.2} on average (the shafts add up to {shafts:.1})"
        );
    }
}

/// Mean luminance of the nearly opaque pixels of a transparent `image` in the top and the
/// bottom quarter of their rows.
fn top_and_base(image: &Image) -> (f64, f64) {
    let opaque: Vec<(u32, u32)> = (0..image.height)
        .flat_map(|y| (0..image.width).map(move |x| (x, y)))
        .filter(|&(x, y)| image.pixel(x, y)[3] >= 250)
        .collect();
    let (y0, y1) = opaque
        .iter()
        .fold((u32::MAX, 0), |(a, b), &(_, y)| (a.min(y), b.max(y)));
    let quarter = (y1 - y0) / 4;
    let mean = |rows: std::ops::RangeInclusive<u32>| {
        let v: Vec<f64> = opaque
            .iter()
            .filter(|(_, y)| rows.contains(y))
            .map(|&(x, y)| luminance(image.pixel(x, y)))
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    (mean(y0..=y0 + quarter), mean(y1 - quarter..=y1))
}

#[test]
fn the_sky_lights_the_clouds_top_and_the_cloud_hides_it_from_its_base() {
    // The sky's light alone (no sun): it comes from above, through the cloud, so the base of
    // a cumulus gets far less of it than its top. An ambient term added everywhere alike (as
    // this renderer had) lights both the same. With the sun too, the base stays the darker.
    let transparent = |s: &Scene| {
        offscreen()
            .render(&frame_of(s, None), W, H, Backdrop::Transparent)
            .expect("render")
    };
    let scene = smooth_cumulus();
    let sky_only = with(&scene, &["/light/sun_intensity=0", "/light/ambient=1.5"]);
    let (top, base) = top_and_base(&transparent(&sky_only));
    assert!(top > 40.0, "the sky lights the top: {top:.1}");
    assert!(
        base < 0.8 * top,
        "under the sky alone the base ({base:.1}) is far darker than the top ({top:.1})"
    );
    let (top, base) = top_and_base(&transparent(&scene));
    eprintln!(
        "default light: base {base:.1}, top {top:.1}, ratio {:.2}",
        base / top
    );
    assert!(base < top, "default light: base {base:.1}, top {top:.1}");
}

/// The box-counting dimension of a rendered cloud's outline (its alpha at half, at 1920×1080),
/// fitted over boxes from 1/64 to 1/4 of the cloud's extent in half-octave steps, with the fit's
/// R².
fn outline_dimension(image: &Image) -> (f64, f64) {
    let (w, h) = (image.width as i64, image.height as i64);
    let inside = |x: i64, y: i64| {
        (0..w).contains(&x) && (0..h).contains(&y) && image.pixel(x as u32, y as u32)[3] >= 128
    };
    let edge: Vec<(i64, i64)> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            inside(x, y)
                && [(1, 0), (-1, 0), (0, 1), (0, -1)]
                    .iter()
                    .any(|(dx, dy)| !inside(x + dx, y + dy))
        })
        .collect();
    let (lo, hi) = edge
        .iter()
        .fold(((i64::MAX, i64::MAX), (0, 0)), |(a, b), &(x, y)| {
            ((a.0.min(x), a.1.min(y)), (b.0.max(x), b.1.max(y)))
        });
    let extent = (hi.0 - lo.0).max(hi.1 - lo.1) as f64;
    let points: Vec<(f64, f64)> = (0..=8)
        .map(|k| {
            let side = (extent / 64.0 * 2f64.powf(k as f64 / 2.0)).round().max(1.0) as i64;
            let boxes: std::collections::HashSet<(i64, i64)> = edge
                .iter()
                .map(|&(x, y)| ((x - lo.0) / side, (y - lo.1) / side))
                .collect();
            ((1.0 / side as f64).ln(), (boxes.len() as f64).ln())
        })
        .collect();
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (sxy, sxx, syy) = points.iter().fold((0.0, 0.0, 0.0), |(a, b, c), (x, y)| {
        (
            a + (x - mx) * (y - my),
            b + (x - mx).powi(2),
            c + (y - my).powi(2),
        )
    });
    (sxy / sxx, sxy * sxy / (sxx * syy))
}

/// Billows make an outline rough at every scale, as real clouds' are (a fractal dimension near
/// 1.35, Lovejoy 1982), where the smooth blend of ellipsoids gives a curve's 1.0. Measured with
/// noise amount 0, so a noise fringe cannot move the figure.
#[test]
fn billows_make_the_outline_rough_at_every_scale() {
    for preset in [Preset::Cumulus, Preset::Cumulonimbus] {
        let on = with(
            &Scene::preset(preset),
            &["/render/noise_amount=0", "/render/field_resolution=128"],
        );
        let mut off = on.clone();
        for e in &mut off.ellipsoids {
            std::sync::Arc::make_mut(e).billows.levels = 0;
        }
        let dimension = |scene: &Scene| {
            let image = offscreen()
                .render(&frame_of(scene, None), 1920, 1080, Backdrop::Transparent)
                .expect("render");
            outline_dimension(&image)
        };
        let ((d_on, r2_on), (d_off, r2_off)) = (dimension(&on), dimension(&off));
        eprintln!(
            "{preset:?}: billows on D {d_on:.3} (R² {r2_on:.4}), off D {d_off:.3} (R² {r2_off:.4})"
        );
        assert!(
            d_on >= d_off + 0.04 && r2_on >= 0.98,
            "{preset:?} with billows: D {d_on:.3}, R² {r2_on:.4}"
        );
        assert!(d_off <= 1.12, "{preset:?} without billows: D {d_off:.3}");
    }
}

/// A new document's light volume is the finer one (96 texels, 4 octaves) that renders and
/// exports use; the viewport on a CPU adapter previews it at `CPU_PREVIEW_LIGHT`, never above
/// the document's, and the preview's shadows differ from the document's; the document's light
/// drawn again after the preview is as it was. (Each offscreen render derives its volumes
/// afresh, so the renderer's kept light volume is not reused here: `export.test.mjs` covers
/// it, where the view's preview and the PNG export's light alternate.)
#[test]
fn the_previewed_light_and_the_documents_each_draw_their_own_shadows() {
    let scene = Scene::default();
    assert_eq!(
        [scene.render.light_resolution, scene.render.light_octaves],
        [96, 4]
    );
    let mut preview = scene.clone();
    preview.render = scene
        .render
        .with_light_at_most(cloudsketch::limits::CPU_PREVIEW_LIGHT);
    assert_eq!(
        [
            preview.render.light_resolution,
            preview.render.light_octaves
        ],
        cloudsketch::limits::CPU_PREVIEW_LIGHT
    );
    // Never above the document's.
    let coarse = with(
        &scene,
        &["/render/light_resolution=16", "/render/light_octaves=1"],
    );
    let capped = coarse
        .render
        .with_light_at_most(cloudsketch::limits::CPU_PREVIEW_LIGHT);
    assert_eq!([capped.light_resolution, capped.light_octaves], [16, 1]);

    let mut o = offscreen();
    let mut draw = |s: &Scene| {
        o.render(&frame_of(s, None), W, H, Backdrop::Transparent)
            .expect("render")
    };
    let (first, previewed, again) = (draw(&scene), draw(&preview), draw(&scene));
    let differing = first
        .rgba
        .chunks(4)
        .zip(previewed.rgba.chunks(4))
        .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    // (179 pixels on lavapipe: the multiple scattering's smooth light, the same from either
    // volume, covers much of the shadows' difference; the same light drawn twice differs by 0.)
    assert!(
        differing > 100,
        "the preview's coarser light changes the shading: {differing} pixels"
    );
    assert!(
        first.rgba == again.rgba,
        "the document's light, drawn again, is as it was"
    );
}

/// Horizontal centroid of the cloud's pixels.
fn centroid_x(image: &Image, bg: [u8; 3]) -> f64 {
    let (mut n, mut sx) = (0.0, 0.0);
    for y in 0..image.height {
        for x in 0..image.width {
            if differs(image.pixel(x, y), bg) {
                n += 1.0;
                sx += x as f64;
            }
        }
    }
    assert!(n > 100.0, "a cloud: {n} px");
    sx / n
}

#[test]
fn a_keyed_ellipsoid_moves_the_rendered_cloud_the_way_its_keys_say() {
    use cloudsketch::scene::{Animation, Channel, Ease, Ellipsoid, EllipsoidProperty};
    use glam::Vec3;
    let mut scene = with(
        &Scene::preset(Preset::Empty),
        &["/render/noise_amount=0", "/render/slices=64"],
    );
    scene.ellipsoids.push(std::sync::Arc::new(Ellipsoid::new(
        Vec3::new(-4.0, 3.0, 0.0),
        Vec3::new(2.0, 1.5, 1.5),
    )));
    scene.settle();
    let center = Channel::Ellipsoid {
        id: scene.ellipsoids[0].id,
        property: EllipsoidProperty::Center,
    };
    let mut keys = Animation::default();
    keys.key(center, 0.0, vec![-4.0, 3.0, 0.0]);
    keys.key(center, 2.0, vec![4.0, 3.0, 0.0]);
    scene.animation = keys.clone();
    let bg = background(&scene);
    let x_at = |s: &Scene, t: f32| centroid_x(&render(&s.posed_at(t)), bg);
    let (x0, x1, x2) = (x_at(&scene, 0.0), x_at(&scene, 1.0), x_at(&scene, 2.0));
    assert!(
        x2 > x0 + 40.0,
        "the keys move it across the view: {x0} → {x2}"
    );
    // Linear: half way in time, half way across (the view is nearly affine this far out).
    let half = (x0 + x2) / 2.0;
    assert!((x1 - half).abs() < 3.0, "at 1 s: {x1}, half way {half}");
    // Ease in and out: a quarter of the time in, under a sixth of the way (smoothstep gives
    // 0.156 where linear gives 0.25).
    keys.set_ease(&[center], 0.0, Ease::EaseInOut);
    scene.animation = keys;
    let eased = x_at(&scene, 0.5);
    let share = (eased - x0) / (x2 - x0);
    assert!(
        (0.1..0.21).contains(&share),
        "eased a quarter in: {share:.3} of the way"
    );
    // Past the last key the cloud stays where that key holds it.
    assert_eq!(render(&scene.posed_at(2.0)), render(&scene.posed_at(5.0)));
}

/// Keys `channel` (a wind) from calm at 0 s to 2 units/s at 2 s in `base` and renders it at
/// 2 s: by then it has carried the noise 2 units, as a steady wind of 1 does (set by `steady`,
/// a `--set` pointer with `{w}` for the wind's x), where its value times the time would be 4.
fn assert_a_keyed_wind_carries_by_its_integral(
    base: &Scene,
    channel: cloudsketch::scene::Channel,
    steady: &str,
) {
    let mut keyed = base.clone();
    keyed.animation.key(channel, 0.0, vec![0.0, 0.0]);
    keyed.animation.key(channel, 2.0, vec![2.0, 0.0]);
    let keyed = keyed.posed_at(2.0);
    assert_eq!(channel.get(&keyed), Some(vec![2.0, 0.0]));
    let steady = |w: f32| {
        let mut s = with(base, &[&steady.replace("{w}", &w.to_string())]);
        s.time = 2.0;
        render(&s)
    };
    let image = render(&keyed);
    assert_eq!(
        image,
        steady(1.0),
        "the integral: as far as a steady wind of 1"
    );
    let d = changed(&image, &steady(2.0));
    assert!(
        d > 300,
        "value × time would carry it twice as far: {d} px differ"
    );
}

#[test]
fn a_keyed_wind_carries_the_noise_by_its_integral_not_its_value_times_the_time() {
    use cloudsketch::scene::{Channel, MediaProperty};
    let base = with(
        &smooth_cumulus(),
        &["/render/slices=64", "/render/noise_amount=0.6"],
    );
    let wind = Channel::Media {
        property: MediaProperty::Wind,
    };
    assert_a_keyed_wind_carries_by_its_integral(&base, wind, "/render/wind=[{w},0]");
}

#[test]
fn a_tiers_keyed_wind_carries_its_noise_by_its_integral_on_the_gpu() {
    // The same for an atmospheric tier covering the whole cloud, the base media calm: the
    // slices' tier transforms take the tier's integrated wind, as the CPU media do.
    use cloudsketch::scene::{Channel, TierProperty};
    let base = with(
        &smooth_cumulus(),
        &[
            "/render/slices=64",
            "/render/noise_amount=0.6",
            "/render/wind=[0,0]",
            "/render/tiers=[{\"floor\": -50}]",
        ],
    );
    let wind = Channel::Tier {
        tier: 0,
        property: TierProperty::Wind,
    };
    assert_a_keyed_wind_carries_by_its_integral(&base, wind, "/render/tiers/0/wind=[{w},0]");
}

/// The topmost row of cloud pixels and the cloud's width on screen.
fn top_and_width(image: &Image, bg: [u8; 3]) -> (u32, u32) {
    let top = (0..image.height)
        .find(|&y| (0..image.width).any(|x| differs(image.pixel(x, y), bg)))
        .unwrap_or(image.height);
    (top, cloud_box(image, bg).0)
}

#[test]
fn the_developing_cumulus_rises_and_widens_frame_over_frame_by_its_motion() {
    // Schpok et al. 2003, Figure 5. Without noise, so only the shape can change the outline.
    let scene = with(
        &Scene::preset(Preset::Developing),
        &["/render/noise_amount=0", "/render/slices=64"],
    );
    let bg = background(&scene);
    // The baseline: the same document with every motion and the anvil's keys taken off (the
    // noise's keys stay).
    let mut still = scene.clone();
    for e in &mut still.ellipsoids {
        std::sync::Arc::make_mut(e).motion = None;
    }
    still
        .animation
        .tracks
        .retain(|tr| !matches!(tr.channel, Channel::Ellipsoid { .. }));
    let at = |s: &Scene, t: f32| top_and_width(&render(&s.posed_at(t)), bg);
    let [a, b, c] = [0.0, 10.0, 20.0].map(|t| at(&scene, t));
    assert!(
        b.0 + 8 < a.0 && c.0 + 8 < b.0,
        "the top rises frame over frame (rows from the top): {a:?} {b:?} {c:?}"
    );
    assert!(
        b.1 > a.1 && c.1 > b.1 + 20,
        "it widens frame over frame, most as the anvil spreads: {a:?} {b:?} {c:?}"
    );
    let (s10, s20) = (at(&still, 10.0), at(&still, 20.0));
    assert!(
        b.0 + 8 < s10.0 && c.0 + 8 < s20.0 && c.1 > s20.1 + 20,
        "the motion and the anvil's keys, not the noise's keys, do it: moving {b:?} {c:?}, \
         still {s10:?} {s20:?}"
    );
    // Scrubbing back gives what playing forward gave: the frame is a function of the time.
    let played = render(&scene.posed_at(10.0).posed_at(20.0).posed_at(10.0));
    assert_eq!(played, render(&scene.posed_at(10.0)));
}

/// The share of `image`'s cloud pixels (those that differ from `bg`) outside its largest
/// 8-connected piece.
fn detached_share(image: &Image, bg: [u8; 3]) -> f64 {
    let (w, h) = (image.width as usize, image.height as usize);
    let cloud: Vec<bool> = (0..w * h)
        .map(|i| differs(image.pixel((i % w) as u32, (i / w) as u32), bg))
        .collect();
    let mut seen = vec![false; w * h];
    let (mut total, mut largest) = (0usize, 0usize);
    for start in 0..w * h {
        if !cloud[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        let (mut stack, mut size) = (vec![start], 0usize);
        while let Some(i) = stack.pop() {
            size += 1;
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            for (dx, dy) in [
                (-1, -1),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if cloud[j] && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
        total += size;
        largest = largest.max(size);
    }
    (total - largest) as f64 / total.max(1) as f64
}

/// The developing cumulus's anvil grows out of the column, with its noise: at no time while
/// it forms does a faint disc of specks float apart from the tower (as when the anvil faded in
/// by its strength above the crown, a weak field that only the noise's peaks lifted over the
/// iso level). The baseline: the same anvil faded in by its strength where it ends up, which
/// this measure must catch.
#[test]
fn the_developing_anvil_grows_out_of_the_column_in_one_piece() {
    let scene = Scene::preset(Preset::Developing);
    let bg = background(&scene);
    let size = [400, 300];
    let shot = |s: &Scene, t: f32| {
        offscreen()
            .render(&frame_of(s, Some(t)), size[0], size[1], Backdrop::Sky)
            .expect("render")
    };
    let anvil = scene
        .ellipsoids
        .iter()
        .position(|e| e.id == 100)
        .expect("the anvil is ellipsoid 100");
    // The baseline: the anvil standing where it is at 20 s from the start, faded in from 8 to
    // 16 s by its strength.
    let mut faded = scene.clone();
    faded
        .animation
        .tracks
        .retain(|tr| !matches!(tr.channel, Channel::Ellipsoid { id: 100, .. }));
    {
        let end = scene.posed_at(20.0);
        let e = std::sync::Arc::make_mut(&mut faded.ellipsoids[anvil]);
        (e.center, e.radii) = (end.ellipsoids[anvil].center, end.ellipsoids[anvil].radii);
    }
    let strength = Channel::Ellipsoid {
        id: 100,
        property: cloudsketch::scene::EllipsoidProperty::Strength,
    };
    for (t, v) in [(0.0, 0.0), (8.0, 0.0), (16.0, 1.0)] {
        faded.animation.key(strength, t, vec![v]);
    }
    let baseline = detached_share(&shot(&faded, 12.0), bg);
    assert!(
        baseline > 0.02,
        "the measure sees the faded anvil's specks: {baseline:.4} of the cloud apart"
    );
    for t in [6.0, 10.0, 12.0, 14.0, 17.0, 20.0] {
        let apart = detached_share(&shot(&scene, t), bg);
        assert!(
            apart < 0.004,
            "at {t} s, {apart:.4} of the cloud's pixels lie apart from it (the faded anvil: \
             {baseline:.4})"
        );
    }
}

/// The tests' one offscreen device making linear images (what an EXR holds).
fn linear_offscreen() -> std::sync::MutexGuard<'static, Offscreen> {
    static DEVICE: OnceLock<Mutex<Offscreen>> = OnceLock::new();
    DEVICE
        .get_or_init(|| {
            Mutex::new(Offscreen::with_output(Output::Linear).expect("an offscreen wgpu adapter"))
        })
        .lock()
        .unwrap_or_else(|e| e.into_inner())
}

fn render_linear(scene: &Scene, backdrop: Backdrop) -> LinearImage {
    linear_offscreen()
        .render_linear(&frame_of(scene, None), [W, H], backdrop, 1, None)
        .expect("linear render")
}

/// The display level (0–255) of linear `light`: the one tone map, sRGB-encoded.
fn shown(light: f64) -> f64 {
    use cloudsketch::render::tone::{linear_to_srgb, tone_map};
    255.0 * linear_to_srgb(tone_map(light as f32)) as f64
}

/// The linear image (an EXR's) is the display image before its tone map: the display's
/// colour is the one tone map of the linear image's light, sRGB-encoded, with the same
/// alpha. Writing display values, or tone-mapping twice, fails it. Exposure scales the linear
/// light by its stops, and the flat background is the light that shows as its picked colour.
#[test]
fn the_linear_image_is_the_display_image_before_its_tone_map() {
    let mut scene = smooth_cumulus();
    scene.light.sky_gradient = false;
    scene.light.ground = false;
    scene.light.shafts = false;
    let display = offscreen()
        .render(&frame_of(&scene, None), W, H, Backdrop::Transparent)
        .expect("render");
    let linear = render_linear(&scene, Backdrop::Transparent);
    assert_eq!((linear.width, linear.height), (W, H));
    let (mut compared, mut worst, mut sum, mut bright) = (0usize, 0.0f64, 0.0f64, 0usize);
    for y in 0..H {
        for x in 0..W {
            let d = display.pixel(x, y);
            let l = linear.pixel(x, y);
            assert!(
                (l[3] as f64 * 255.0 - d[3] as f64).abs() <= 1.5,
                "alpha at ({x}, {y}): linear {} display {}",
                l[3],
                d[3]
            );
            if d[3] < 96 {
                continue;
            }
            for c in 0..3 {
                let light = l[c] as f64 / l[3] as f64;
                bright += usize::from(light > 1.0);
                let expected = shown(light);
                let error = (expected - d[c] as f64).abs();
                worst = worst.max(error);
                sum += error;
                compared += 1;
            }
        }
    }
    assert!(compared > 1500, "only {compared} cloud channels compared");
    assert!(
        worst <= 4.0 && sum / compared as f64 <= 1.0,
        "display vs the tone-mapped linear light: worst {worst:.2}, mean {:.2} levels",
        sum / compared as f64
    );
    assert!(
        bright > 0,
        "no light above 1: the linear image looks tone-mapped already"
    );
    // Exposure: +1 stop doubles the cloud's light.
    let brighter = render_linear(&with(&scene, &["/light/exposure=1"]), Backdrop::Transparent);
    let mut ratios: Vec<f64> = (0..W * H)
        .map(|i| (linear.pixel(i % W, i / W), brighter.pixel(i % W, i / W)))
        .filter(|(a, b)| a[3] > 0.5 && (a[3] - b[3]).abs() < 1e-3 && a[1] > 0.01)
        .map(|(a, b)| b[1] as f64 / a[1] as f64)
        .collect();
    assert!(
        ratios.len() > 100,
        "only {} opaque cloud pixels",
        ratios.len()
    );
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    assert!(
        (median - 2.0).abs() < 0.03,
        "+1 EV scaled the light by {median:.3}"
    );
    // Over the sky: every pixel opaque, the corner the background decoded.
    let over = render_linear(&scene, Backdrop::Sky);
    let corner = over.pixel(1, 1);
    let bg = cloudsketch::render::tone::light_of(scene.light.background);
    for (c, want) in bg.to_array().into_iter().enumerate() {
        assert!(
            (corner[c] - want).abs() < 2e-3 * want.max(1.0),
            "corner {corner:?}, background {bg:?}"
        );
    }
    assert!(over.rgba.chunks_exact(4).all(|p| (p[3] - 1.0).abs() < 1e-3));
}

/// One tone map, once: with the sky gradient, the ground, the shafts of light and the cloud
/// all on, and over a flat background, every display pixel is the tone map of the linear image's light there (the sky,
/// the ground, the cloud over them and the shafts added up first), the sky at exposure 0 its
/// picked colour. The renderer before mapped the cloud alone, laid it over the sky as picked
/// and added the shafts' light mapped on its own: it fails by tens of levels at the cloud's
/// thin edges, at the sky and where shafts cross the cloud. The shafts light the air.
#[test]
fn one_tone_map_maps_the_sky_the_cloud_and_the_shafts_together() {
    let sky = with(
        &broken_layer(),
        &["/light/sky_gradient=true", "/light/exposure=0.5"],
    );
    let shafts = with(&sky, &["/light/shafts=true", "/light/shaft_density=0.003"]);
    // A flat background, which images and the viewport take as their clear colour (no sky
    // pass): the composite maps the cloud's light with the light that shows as it.
    let flat = with(&smooth_cumulus(), &["/light/exposure=0.7"]);
    for (name, scene) in [
        ("sky and ground", &sky),
        ("with shafts", &shafts),
        ("flat background", &flat),
    ] {
        let display = render(scene);
        let linear = render_linear(scene, Backdrop::Sky);
        let cloud = render_linear(scene, Backdrop::Transparent);
        let (mut worst, mut sum, mut n, mut edge) = (0.0f64, 0.0f64, 0usize, 0usize);
        for y in 0..H {
            for x in 0..W {
                let (d, l) = (display.pixel(x, y), linear.pixel(x, y));
                let a = cloud.pixel(x, y)[3];
                edge += usize::from(a > 0.05 && a < 0.95);
                for c in 0..3 {
                    let error = (shown(l[c] as f64) - d[c] as f64).abs();
                    worst = worst.max(error);
                    sum += error;
                    n += 1;
                }
            }
        }
        let mean = sum / n as f64;
        eprintln!(
            "{name}: display vs the tone-mapped linear light: worst {worst:.2}, mean {mean:.3} levels, {edge} edge pixels"
        );
        assert!(
            edge > 100,
            "{name}: only {edge} pixels of the cloud's thin edge"
        );
        assert!(
            worst <= 4.0 && mean <= 0.5,
            "{name}: display vs the tone-mapped linear light: worst {worst:.2}, mean {mean:.3} levels"
        );
    }
    // The shafts light the clear air.
    let (off, on) = (render(&sky), render(&shafts));
    let cloud = render_linear(&sky, Backdrop::Transparent);
    let (mut lit, mut clear) = (0usize, 0usize);
    for y in 0..H {
        for x in 0..W {
            if cloud.pixel(x, y)[3] > 0.0 {
                continue;
            }
            clear += 1;
            lit += usize::from(luminance(on.pixel(x, y)) > luminance(off.pixel(x, y)) + 1.0);
        }
    }
    assert!(clear > (W * H / 2) as usize, "only {clear} clear pixels");
    assert!(
        lit > clear / 3,
        "the shafts lit only {lit} of {clear} clear pixels"
    );
}

/// The unit view ray through the centre of pixel (x, y) of a W × H image of `scene`.
fn pixel_ray(scene: &Scene, x: u32, y: u32) -> glam::Vec3 {
    let c = &scene.camera;
    let t = (c.fov_y_deg.to_radians() * 0.5).tan();
    let aspect = W as f32 / H as f32;
    let nx = 2.0 * (x as f32 + 0.5) / W as f32 - 1.0;
    let ny = 1.0 - 2.0 * (y as f32 + 0.5) / H as f32;
    (c.forward() + c.right() * (nx * t * aspect) + c.up() * (ny * t)).normalize()
}

/// The mean colour of the pixels the cloud covers (alpha over a half) of a transparent image,
/// its straight colour.
fn cloud_colour(image: &Image) -> [f64; 3] {
    let (mut sum, mut n) = ([0.0; 3], 0.0_f64);
    for p in image.rgba.chunks(4).filter(|p| p[3] > 128) {
        for c in 0..3 {
            sum[c] += p[c] as f64;
        }
        n += 1.0;
    }
    sum.map(|s| s / n.max(1.0))
}

#[test]
fn the_physical_sky_is_the_atmospheres_light_and_a_low_sun_reddens_the_sky_and_the_cloud() {
    // The default cumulus seen level, the sun to the back left and in view.
    let base = with(
        &smooth_cumulus(),
        &["/camera/pitch_deg=-4", "/light/sun_azimuth_deg=245"],
    );
    let physical = |elevation: &str| {
        with(
            &base,
            &[
                "/light/physical_sky=true",
                &format!("/light/sun_elevation_deg={elevation}"),
            ],
        )
    };
    // The sky's linear light is the atmosphere's (src/atmosphere.rs) along each pixel's ray, in
    // the app's units: a plausible wrong version (the table read transposed, the azimuth from
    // the wrong side, the wrong units) misses by far more than the half floats' and the
    // table's interpolation.
    let noon = physical("60");
    let linear = render_linear(&noon, Backdrop::Sky);
    let tables = cloudsketch::atmosphere::sky(60.0);
    let scale = noon.light.physical_scale();
    let mut worst: f32 = 0.0;
    for (x, y) in [(2, 2), (100, 3), (197, 10), (5, 70), (190, 60)] {
        let expected = tables.radiance(pixel_ray(&noon, x, y), 245f32.to_radians()) * scale;
        let p = linear.pixel(x, y);
        for c in 0..3 {
            worst = worst.max((p[c] - expected[c]).abs() / expected[c]);
        }
    }
    assert!(
        worst < 0.04,
        "the sky's light against the atmosphere's: worst {worst:.3}"
    );

    // At noon the sky is blue; at sunset the horizon toward the sun glows warm.
    let high = render(&noon);
    let low = render(&physical("3"));
    let top = high.pixel(100, 3);
    assert!(
        top[2] as i32 > top[0] as i32 + 40,
        "the noon sky at the top: {top:?}"
    );
    let sun_side = low.pixel(8, 70);
    let away = low.pixel(192, 70);
    assert!(
        sun_side[0] as i32 > sun_side[2] as i32 + 20
            && sun_side[0] as f64 / sun_side[2] as f64 > away[0] as f64 / away[2].max(1) as f64,
        "the sunset horizon: toward the sun {sun_side:?}, away {away:?}"
    );
    // The sun's disk: the brightest sky pixel lies on the sun's direction and shows white.
    let low_scene = physical("3");
    let sun_low = low_scene.light.sun_direction();
    let (mut best, mut at) = (0.0, (0, 0));
    for y in 0..H {
        for x in 0..W {
            let l = luminance(low.pixel(x, y));
            if l > best {
                (best, at) = (l, (x, y));
            }
        }
    }
    let off = pixel_ray(&low_scene, at.0, at.1)
        .angle_between(sun_low)
        .to_degrees();
    assert!(
        best > 250.0 && off < 0.6,
        "the brightest pixel {best:.0} is {off:.2}° from the sun"
    );

    // The cloud's sunlight reddens as the sun sets with the physical sky, and only with it: the
    // picked sun colour stays as picked whatever the elevation.
    let redness = |scene: &Scene| {
        let c = cloud_colour(
            &offscreen()
                .render(&frame_of(scene, None), W, H, Backdrop::Transparent)
                .unwrap(),
        );
        c[0] / c[2].max(1.0)
    };
    let (noon_red, sunset_red) = (redness(&noon), redness(&low_scene));
    let picked = |e: &str| with(&base, &[&format!("/light/sun_elevation_deg={e}")]);
    let (picked_noon, picked_low) = (redness(&picked("60")), redness(&picked("3")));
    assert!(
        sunset_red > 1.4 * noon_red,
        "the cloud's red over blue: {noon_red:.2} at noon, {sunset_red:.2} at sunset"
    );
    assert!(
        (picked_low / picked_noon - 1.0).abs() < 0.1,
        "with picked colours: {picked_noon:.2} and {picked_low:.2}"
    );
}

#[test]
fn a_far_cloud_fades_into_the_physical_skys_colour_and_a_near_one_barely() {
    // Orthographic views of one size from 30 and 280 world units (3 and 28 km): the cloud
    // covers the same pixels, only the air between differs. With the physical sky the far
    // cloud's light moves toward the sky's colour (bluer, and its contrast with the sky drops);
    // with picked colours the distance changes nothing (the baseline).
    let half = 30.0 * (22.5f32).to_radians().tan();
    let at = |scene: &Scene, distance: f32| {
        let fov = 2.0 * (half / distance).atan().to_degrees();
        let s = with(
            scene,
            &[
                "/camera/orthographic=true",
                &format!("/camera/distance={distance}"),
                &format!("/camera/fov_y_deg={fov}"),
            ],
        );
        let image = render_linear(&s, Backdrop::Transparent);
        let (mut sum, mut n) = (glam::DVec3::ZERO, 0.0);
        for p in image.rgba.chunks(4).filter(|p| p[3] > 0.9) {
            sum += glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) / p[3] as f64;
            n += 1.0;
        }
        (sum / f64::max(n, 1.0), n)
    };
    let blueness = |c: glam::DVec3| c.z / c.x;
    let picked = smooth_cumulus();
    let physical = with(&picked, &["/light/physical_sky=true"]);
    let ((near, n_near), (far, n_far)) = (at(&physical, 30.0), at(&physical, 280.0));
    assert!(
        n_near > 500.0 && (n_far / n_near - 1.0).abs() < 0.05,
        "{n_near} vs {n_far} px"
    );
    let ((p_near, _), (p_far, _)) = (at(&picked, 30.0), at(&picked, 280.0));
    let (shift, baseline) = (
        blueness(far) / blueness(near),
        blueness(p_far) / blueness(p_near),
    );
    eprintln!(
        "blue over red, far against near: {shift:.3} (picked colours {baseline:.3}); near {near:?}, far {far:?}"
    );
    assert!(
        // (1.041 on lavapipe: the cloud's calibrated light is over twice the air's; 1.37 under
        // the light before. Without the haze, 1.000.)
        shift > 1.02 && (baseline - 1.0).abs() < 0.01,
        "blue over red, far against near: {shift:.3} with the physical sky, {baseline:.3} without"
    );
    // The far cloud's light is the near one's through 25 km more air, plus the air's own light
    // (the physical sky's, looking level toward the cloud): from the near image, the cloud's
    // own light C = (near − L·(1 − T₃)) / T₃, then far = C·T₂₈ + L·(1 − T₂₈), each T the air's
    // transmittance over 3 and 28 km. Within 2% (0.1% measured on lavapipe; each sample's own
    // distance is used, not the centre's).
    let light = &physical.light;
    let toward = physical.camera.forward();
    let level = glam::Vec3::new(toward.x, toward.y.max(0.0), toward.z).normalize();
    let air = cloudsketch::atmosphere::sky(light.sun_elevation_deg)
        .radiance(level, light.sun_azimuth_deg.to_radians())
        .as_dvec3()
        * f64::from(light.physical_scale() * light.exposure.exp2());
    let sigma = cloudsketch::atmosphere::air_extinction().as_dvec3();
    let through = |km: f64| (-sigma * km).exp();
    let own = (near - air * (glam::DVec3::ONE - through(3.0))) / through(3.0);
    let predicted = own * through(28.0) + air * (glam::DVec3::ONE - through(28.0));
    let error = ((far - predicted) / predicted).abs().max_element();
    assert!(
        error < 0.02,
        "far {far:?}, predicted {predicted:?} from near {near:?} (error {error:.3})"
    );
}

/// A browser without float targets (plain WebGL2) accumulates the slices and keeps the light
/// volume in 8 bits: its image is the float path's within the 8 bits' rounding (mean 0.04–0.38
/// levels, the cloud's brightness within 0.4), for every preset: a thick cloud, a layer seen
/// from below, wisps, a tower and a low sun. The accumulated light is scaled by a half to fit:
/// unscaled, 8 bits clip the calibrated sunlit cloud's light at 1 (at the earlier sun of 1.6,
/// the cumulus 225 → 208 levels); a diffusion read back unhalved brightens it as far. The
/// cloud alone (straight alpha, its faint fringe's colour divided by its alpha) is within 0.6
/// levels, the stratus's wide fringe the most.
#[test]
fn the_eight_bit_path_draws_the_float_paths_image_within_rounding() {
    let mut o = offscreen();
    o.set_marching(false).unwrap();
    for name in ["cumulus", "stratus", "cirrus", "sunset", "cumulonimbus"] {
        let scene = with(
            &Scene::preset(Preset::from_name(name).unwrap()),
            &["/render/slices=64"],
        );
        // Derived once: every drawing below is of the same volumes.
        let frame = frame_of(&scene, None);
        let float = o.render(&frame, W, H, Backdrop::Sky).expect("render");
        let float_alone = o
            .render(&frame, W, H, Backdrop::Transparent)
            .expect("render");
        o.set_eight_bit(true).unwrap();
        let eight = o.render(&frame, W, H, Backdrop::Sky).expect("render");
        let eight_alone = o
            .render(&frame, W, H, Backdrop::Transparent)
            .expect("render");
        o.set_eight_bit(false).unwrap();
        // The cloud alone (a transparent PNG) too: nothing behind it to carry the scale back.
        let (mean_alone, _) = image_difference(&float_alone, &eight_alone);
        assert!(
            mean_alone < 0.75,
            "{name} alone: 8 bits against half floats: mean {mean_alone:.2}"
        );
        let (mean, worst) = image_difference(&float, &eight);
        let bg = background(&scene);
        let brightness = |image: &Image| {
            let v: Vec<f64> = image
                .rgba
                .chunks(4)
                .map(|p| [p[0], p[1], p[2], p[3]])
                .filter(|&p| differs(p, bg))
                .map(luminance)
                .collect();
            v.iter().sum::<f64>() / v.len().max(1) as f64
        };
        // As the viewport draws it (the cloud's box sliced, the shafts around it apart), with
        // shafts of light.
        let shafts = frame_of(&with(&scene, &["/light/shafts=true"]), None);
        let float_cropped = o.render_cropped(&shafts, W, H).expect("render");
        o.set_eight_bit(true).unwrap();
        let eight_cropped = o.render_cropped(&shafts, W, H).expect("render");
        o.set_eight_bit(false).unwrap();
        let (mean_cropped, _) = image_difference(&float_cropped, &eight_cropped);
        // The shafts' light is added shell by shell, each rounded to 8 bits unscaled: the
        // fainter the sun, the more of each shell's light rounds away (the cumulus 0.32 levels
        // at a sun of 1.6, 0.53 at today's default 0.8; the sunset 0.71).
        assert!(
            mean_cropped < 0.85,
            "{name} cropped, with shafts: 8 bits against half floats: mean {mean_cropped:.2}"
        );
        // Marched slices (where an adapter marches yet cannot accumulate in floats) are laid
        // into the 8-bit accumulation at its scale too.
        if name == "cumulus" {
            o.set_eight_bit(true).unwrap();
            o.set_marching(true).expect("lavapipe marches the slices");
            let marched = o.render(&frame, W, H, Backdrop::Sky).expect("render");
            o.set_eight_bit(false).unwrap();
            let (mean_marched, _) = image_difference(&float, &marched);
            assert!(
                mean_marched < 1.0,
                "{name} marched: 8 bits against half floats: mean {mean_marched:.2}"
            );
        }
        let (b_float, b_eight) = (brightness(&float), brightness(&eight));
        eprintln!(
            "{name}: 8 bits against half floats: mean {mean:.2}, worst {worst}; cloud brightness {b_float:.1} → {b_eight:.1}"
        );
        assert!(
            mean < 0.5 && (b_eight - b_float).abs() < 1.5,
            "{name}: 8 bits against half floats: mean {mean:.2}, worst {worst}; cloud brightness {b_float:.1} → {b_eight:.1}"
        );
    }
}

/// An 8-bit sky is dithered, not banded: a slow gradient (the picked gradient, the physical
/// sky) rounded to 8 bits leaves bands of one level with a contour line between them (seen
/// at 1920×1080). Against the exact display levels of the same sky (the linear image through
/// the one tone map): no pixel is more than a level off, and along each row the error averaged
/// over 16 pixels (what the eye sees from a step back) is under 0.4× plain rounding's, which
/// keeps each band's error whole (0.25 levels on average, the undithered sky's 1.0×).
#[test]
fn an_eight_bit_sky_is_dithered_not_banded() {
    let (w, h) = (640u32, 360u32);
    for (what, sets) in [
        (
            "gradient",
            ["/light/sky_gradient=true", "/light/physical_sky=false"],
        ),
        (
            "physical sky",
            ["/light/sky_gradient=false", "/light/physical_sky=true"],
        ),
    ] {
        let mut all = vec!["/light/ground=false", "/light/shafts=false"];
        all.extend(sets);
        let scene = with(&Scene::preset(Preset::Empty), &all);
        let frame = frame_of(&scene, None);
        let eight = offscreen()
            .render(&frame, w, h, Backdrop::Sky)
            .expect("render");
        let linear = linear_offscreen()
            .render_linear(&frame, [w, h], Backdrop::Sky, 1, None)
            .expect("linear render");
        let at = |x: u32, y: u32, c: usize| ((y * w + x) * 4) as usize + c;
        let exact = |x: u32, y: u32, c: usize| shown(linear.rgba[at(x, y, c)] as f64);
        let (mut worst, mut dithered, mut rounded, mut runs) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for y in 0..h {
            for x0 in (0..w - 15).step_by(16) {
                for c in 0..3 {
                    let (mut d, mut r) = (0.0, 0.0);
                    for x in x0..x0 + 16 {
                        let e = exact(x, y, c);
                        let got = eight.rgba[at(x, y, c)] as f64;
                        worst = worst.max((got - e).abs());
                        d += got - e;
                        r += e.round() - e;
                    }
                    dithered += (d / 16.0).abs();
                    rounded += (r / 16.0).abs();
                    runs += 1;
                }
            }
        }
        let (dithered, rounded) = (dithered / runs as f64, rounded / runs as f64);
        let mut levels: Vec<u8> = (0..h).map(|y| eight.rgba[at(w / 2, y, 2)]).collect();
        levels.sort_unstable();
        levels.dedup();
        eprintln!(
            "{what}: {} levels of blue down the middle; error over 16 px {dithered:.3} levels, \
             plain rounding's {rounded:.3}; worst pixel {worst:.2} levels off",
            levels.len()
        );
        assert!(
            levels.len() >= 8,
            "{what}: a gradient of {} levels",
            levels.len()
        );
        assert!(worst <= 1.1, "{what}: a pixel {worst:.2} levels off");
        assert!(
            dithered < 0.4 * rounded,
            "{what}: banded: {dithered:.3} levels off over 16 px, plain rounding {rounded:.3}"
        );
    }
}
