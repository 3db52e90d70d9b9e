use std::f64::consts::{PI, TAU};

use glam::DVec2;
use proptest::prelude::*;

use super::outline::{boundary_distance, contains};
use super::*;

fn rect(w: f64, h: f64, per_side: usize) -> Vec<[f64; 2]> {
    let corners = [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]];
    let mut v = Vec::new();
    for k in 0..4 {
        let (a, b) = (corners[k], corners[(k + 1) % 4]);
        for i in 0..per_side {
            let t = i as f64 / per_side as f64;
            v.push([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]);
        }
    }
    v
}

fn disc(r: f64, n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|i| i as f64 / n as f64 * TAU)
        .map(|a| [r * a.cos(), r * a.sin()])
        .collect()
}

fn star(points: usize, outer: f64, inner: f64) -> Vec<[f64; 2]> {
    let mut v = Vec::new();
    for i in 0..points * 2 {
        let a = PI / 2.0 + i as f64 * PI / points as f64;
        let r = if i % 2 == 0 { outer } else { inner };
        let next_a = PI / 2.0 + (i + 1) as f64 * PI / points as f64;
        let next_r = if i % 2 == 0 { inner } else { outer };
        for k in 0..20 {
            let t = k as f64 / 20.0;
            let (p, q) = (DVec2::from_angle(a) * r, DVec2::from_angle(next_a) * next_r);
            let m = p.lerp(q, t);
            v.push([m.x, m.y]);
        }
    }
    v
}

fn l_shape() -> Vec<[f64; 2]> {
    let c = [
        [0.0, 0.0],
        [6.0, 0.0],
        [6.0, 2.0],
        [2.0, 2.0],
        [2.0, 6.0],
        [0.0, 6.0],
    ];
    let mut v = Vec::new();
    for k in 0..c.len() {
        let (a, b) = (DVec2::from(c[k]), DVec2::from(c[(k + 1) % c.len()]));
        let n = (a.distance(b) * 8.0) as usize;
        for i in 0..n {
            let m = a.lerp(b, i as f64 / n as f64);
            v.push([m.x, m.y]);
        }
    }
    v
}

/// A cumulus-like outline: flat base, bumpy top.
fn cumulus() -> Vec<[f64; 2]> {
    let mut v = Vec::new();
    for i in 0..=80 {
        v.push([i as f64 / 80.0 * 10.0, 0.0]);
    }
    for i in 1..200 {
        let t = i as f64 / 200.0;
        let a = t * PI;
        let bumps = 1.0 + 0.35 * (a * 5.0).sin().abs();
        v.push([5.0 + 5.0 * a.cos() * bumps.min(1.05), 3.5 * a.sin() * bumps]);
    }
    v
}

fn no_extend() -> SketchParams {
    SketchParams {
        extend: false,
        ..Default::default()
    }
}

/// Intersection over union of the outline and the union of the spheres' projected discs.
fn iou(sketch: &Sketch) -> f64 {
    let p = &sketch.outline.points;
    let (lo, hi) = p.iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(a, b), &q| (a.min(q), b.max(q)),
    );
    let (lo, hi) = (lo - (hi - lo) * 0.1, hi + (hi - lo) * 0.1);
    let n = 160;
    let (mut inter, mut union) = (0, 0);
    for j in 0..n {
        for i in 0..n {
            let q = lo
                + (hi - lo) * DVec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            let a = contains(p, q);
            let b = sketch
                .spheres
                .iter()
                .any(|s| s.center.truncate().distance_squared(q) <= s.radius * s.radius);
            inter += (a && b) as usize;
            union += (a || b) as usize;
        }
    }
    inter as f64 / union as f64
}

fn height(sketch: &Sketch) -> f64 {
    let ys = sketch.outline.points.iter().map(|p| p.y);
    ys.clone().fold(f64::MIN, f64::max) - ys.fold(f64::MAX, f64::min)
}

/// Whether the spheres form one connected body (overlapping neighbours).
fn connected(spheres: &[Sphere]) -> bool {
    spheres::body_of_first(spheres).into_iter().all(|s| s)
}

#[test]
fn rectangle_has_two_ends_and_no_junction() {
    let s = interpret(&rect(12.0, 3.0, 40), true, &no_extend(), 1).unwrap();
    assert_eq!(s.skeleton.terminal_count(), 2, "{:?}", s.skeleton.branches);
    assert_eq!(s.skeleton.junction_count(), 0);
}

#[test]
fn star_has_five_terminals() {
    let s = interpret(&star(5, 5.0, 2.0), true, &no_extend(), 1).unwrap();
    assert_eq!(s.skeleton.terminal_count(), 5);
    assert!(s.skeleton.junction_count() >= 1);
}

#[test]
fn skeleton_lies_inside_with_maximal_ball_radii() {
    for shape in [
        rect(9.0, 3.0, 40),
        disc(4.0, 120),
        star(5, 5.0, 2.0),
        l_shape(),
        cumulus(),
    ] {
        let s = interpret(&shape, true, &no_extend(), 1).unwrap();
        let p = &s.outline.points;
        for n in &s.skeleton.nodes {
            assert!(contains(p, n.pos), "node {} outside", n.pos);
            assert!((n.radius - boundary_distance(n.pos, p)).abs() < 1e-9);
            assert!(n.radius > 0.0);
        }
        assert_eq!(s.skeleton.edge_to_segment.len(), p.len());
        assert!(
            s.skeleton
                .edge_to_segment
                .iter()
                .all(|&i| i < s.skeleton.segments.len())
        );
    }
}

#[test]
fn sphere_discs_match_simple_outlines() {
    for (name, shape) in [
        ("rect", rect(9.0, 3.0, 40)),
        ("disc", disc(4.0, 120)),
        ("L", l_shape()),
        ("cumulus", cumulus()),
    ] {
        let s = interpret(&shape, true, &no_extend(), 1).unwrap();
        let v = iou(&s);
        assert!(v >= 0.9, "{name}: IoU {v:.3}");
        assert!(connected(&s.spheres), "{name}: body split");
    }
}

#[test]
fn extension_gives_depth_and_keeps_the_silhouette() {
    for (name, shape) in [
        ("cumulus", cumulus()),
        ("star", star(5, 5.0, 2.0)),
        ("L", l_shape()),
    ] {
        let flat = interpret(&shape, true, &no_extend(), 7).unwrap();
        let s = interpret(&shape, true, &SketchParams::default(), 7).unwrap();
        let depth = |sk: &Sketch| {
            let (zmin, zmax) = sk.spheres.iter().fold((f64::MAX, f64::MIN), |(a, b), q| {
                (a.min(q.center.z - q.radius), b.max(q.center.z + q.radius))
            });
            zmax - zmin
        };
        // Against the same outline without the extension (its depth is its widest sphere's):
        // the copies toward and away from the viewer make it deeper (cumulus 4.39 against 4.00).
        assert!(
            depth(&s) >= 1.05 * depth(&flat),
            "{name}: depth {:.2} with the extension, {:.2} without",
            depth(&s),
            depth(&flat)
        );
        assert!(s.spheres.len() > flat.spheres.len(), "{name}: no copies");
        // Every projected disc stays inside the outline, and the silhouette is still the outline.
        for q in &s.spheres {
            assert!(boundary_distance(q.center.truncate(), &s.outline.points) >= q.radius - 1e-9);
        }
        assert!(iou(&s) >= 0.85, "{name}: silhouette IoU {:.3}", iou(&s));
        assert!(connected(&s.spheres), "{name}: body split");
    }
}

#[test]
fn same_seed_same_spheres() {
    let a = interpret(&cumulus(), true, &SketchParams::default(), 42).unwrap();
    let b = interpret(&cumulus(), true, &SketchParams::default(), 42).unwrap();
    let c = interpret(&cumulus(), true, &SketchParams::default(), 43).unwrap();
    assert_eq!(a.spheres, b.spheres);
    assert_ne!(a.spheres, c.spheres);
}

#[test]
fn inflation_shrinks_only_spheres_above_the_feature_radius() {
    let shape = star(5, 5.0, 2.0);
    let base = interpret(&shape, true, &no_extend(), 1).unwrap();
    let full = interpret(
        &shape,
        true,
        &SketchParams {
            inflate: 1.0,
            ..no_extend()
        },
        1,
    )
    .unwrap();
    let half = interpret(
        &shape,
        true,
        &SketchParams {
            inflate: 0.5,
            ..no_extend()
        },
        1,
    )
    .unwrap();
    let r_f = base.feature_radius;
    assert!(r_f > 0.0);
    assert!(
        base.spheres.iter().any(|s| s.radius > r_f * 1.05),
        "nothing to deflate"
    );
    for ((a, b), c) in base.spheres.iter().zip(&full.spheres).zip(&half.spheres) {
        assert_eq!(a.radius, a.max_radius, "t = 0 keeps the maximal balls");
        if a.max_radius <= r_f {
            assert_eq!(b.radius, a.radius);
            assert_eq!(c.radius, a.radius);
        } else {
            assert!((b.radius - r_f).abs() < 1e-12);
            assert!(c.radius <= a.radius && c.radius >= r_f);
        }
    }
}

#[test]
fn far_off_and_huge_coordinates_work() {
    let shifted: Vec<[f64; 2]> = cumulus()
        .iter()
        .map(|p| [p[0] * 1000.0 + 1e6, p[1] * 1000.0 - 5e5])
        .collect();
    let s = interpret(&shifted, true, &no_extend(), 1).unwrap();
    assert!(iou(&s) > 0.9);
}

#[test]
fn messy_strokes_are_repaired_with_warnings() {
    // Ends overlapping: the pen went past the start.
    let mut over = cumulus();
    over.extend(cumulus().into_iter().take(30).map(|p| [p[0], p[1] - 0.05]));
    let s = interpret(&over, false, &SketchParams::default(), 1).unwrap();
    assert!(s.spheres.len() > 10);
    // An open stroke is closed by joining its ends.
    let arc: Vec<[f64; 2]> = disc(3.0, 100).into_iter().take(70).collect();
    let s = interpret(&arc, false, &SketchParams::default(), 1).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("open")),
        "{:?}",
        s.warnings
    );
    // Very many points are thinned, not refused.
    let many: Vec<[f64; 2]> = disc(3.0, 50_000);
    let s = interpret(&many, true, &SketchParams::default(), 1).unwrap();
    assert!(s.warnings.iter().any(|w| w.contains("thinned")));
}

#[test]
fn cut_line_is_monotone() {
    let l = cut_line(&[[3.0, 1.0], [0.0, 0.0], [1.0, 2.0], [1.0, 4.0]]).unwrap();
    assert_eq!(l.len(), 3);
    assert!(l.windows(2).all(|w| w[0].x < w[1].x));
    assert_eq!(l[1], DVec2::new(1.0, 3.0));
    assert!(cut_line(&[[1.0, 1.0]]).is_err());
    assert!(cut_line(&[[1.0, 1.0], [1.0, 5.0]]).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, .. ProptestConfig::default() })]

    /// Random polygons, self-intersecting ones included: never a panic, never a hang; either
    /// spheres inside the outline or a clear refusal.
    #[test]
    fn random_strokes_never_panic(points in prop::collection::vec((-100.0f64..100.0, -100.0f64..100.0), 0..120), closed: bool, extend: bool, seed: u64) {
        let pts: Vec<[f64; 2]> = points.into_iter().map(|(x, y)| [x, y]).collect();
        let params = SketchParams { extend, ..Default::default() };
        if let Ok(s) = interpret(&pts, closed, &params, seed) {
            prop_assert!(!s.spheres.is_empty());
            prop_assert!(s.spheres.len() <= spheres::MAX_SPHERES);
            for q in &s.spheres {
                prop_assert!(q.center.is_finite() && q.radius.is_finite() && q.radius > 0.0);
                prop_assert!(contains(&s.outline.points, q.center.truncate()));
            }
        }
    }

    /// Star-shaped random outlines (simple by construction) always give a connected body.
    #[test]
    fn random_simple_outlines_give_one_body(radii in prop::collection::vec(2.0f64..6.0, 5..40)) {
        let n = radii.len();
        let pts: Vec<[f64; 2]> = radii.iter().enumerate().map(|(i, r)| {
            let a = i as f64 / n as f64 * TAU;
            [r * a.cos(), r * a.sin()]
        }).collect();
        let s = interpret(&pts, true, &no_extend(), 1).unwrap();
        prop_assert!(connected(&s.spheres));
    }
}

/// A circle with bumps at several scales, `n` samples.
fn wobbly(n: usize) -> Vec<[f64; 2]> {
    (0..n)
        .map(|i| i as f64 / n as f64 * TAU)
        .map(|a| {
            let r =
                3.0 + 0.25 * (7.0 * a).sin() + 0.08 * (41.0 * a).sin() + 0.02 * (173.0 * a).cos();
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}

/// Intersection over union of two polygons, by sampling a grid over both.
fn polygon_iou(a: &[DVec2], b: &[DVec2]) -> f64 {
    let (lo, hi) = a.iter().chain(b).fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(l, h), &q| (l.min(q), h.max(q)),
    );
    let n = 200;
    let (mut inter, mut union) = (0, 0);
    for j in 0..n {
        for i in 0..n {
            let q = lo
                + (hi - lo) * DVec2::new((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            let (x, y) = (contains(a, q), contains(b, q));
            inter += (x && y) as usize;
            union += (x || y) as usize;
        }
    }
    inter as f64 / union as f64
}

#[test]
fn long_strokes_keep_their_whole_outline_at_any_simplify() {
    // The resampler used to stop at 640 points and close the rest with a chord: a 1,200-point
    // stroke at simplify 0 kept about half its area.
    for (n, simplify) in [(1_200, 0.0), (1_200, 0.002), (4_096, 0.0), (30_000, 0.0)] {
        let raw = wobbly(n);
        let drawn: Vec<DVec2> = raw.iter().map(|&p| DVec2::from(p)).collect();
        let o = outline::clean(&raw, true, simplify).unwrap();
        assert!(
            o.points.len() <= 2 * outline::MAX_OUTLINE_POINTS,
            "{}",
            o.points.len()
        );
        let iou = polygon_iou(&drawn, &o.points);
        assert!(
            iou > 0.97,
            "{n} points at simplify {simplify}: IoU {iou:.3} with the stroke as drawn"
        );
        if n >= 1_200 && simplify < 0.001 {
            assert!(
                o.warnings.iter().any(|w| w.contains("corners")),
                "{:?}",
                o.warnings
            );
        }
    }
}

/// The paper's sheep: a fat body (an ellipse 6 × 4.4) on four thin legs (0.4 wide, about 4.5 long).
fn sheep() -> Vec<[f64; 2]> {
    let below = |x: f64| -2.2 * (1.0 - (x / 3.0) * (x / 3.0)).max(0.0).sqrt();
    let mut v = Vec::new();
    // The underside, left to right, with the legs.
    let legs = [-2.0, -1.0, 0.6, 1.6];
    let mut x = -3.0;
    while x < 3.0 {
        if let Some(&l) = legs.iter().find(|&&l| x <= l && l < x + 0.1) {
            v.extend([
                [l, below(l)],
                [l, -6.5],
                [l + 0.4, -6.5],
                [l + 0.4, below(l + 0.4)],
            ]);
            x = l + 0.5;
            continue;
        }
        v.push([x, below(x)]);
        x += 0.1;
    }
    // The back, right to left.
    for i in 0..60 {
        let a = i as f64 / 60.0 * PI;
        v.push([3.0 * a.cos(), 2.2 * a.sin()]);
    }
    v
}

/// Pieces of the union of the spheres' discs on a raster of about 6 cells per smallest radius
/// (spheres that barely touch fall apart at this resolution, as they would on the grid).
fn pieces(spheres: &[Sphere]) -> usize {
    let (lo, hi) = spheres.iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(l, h), s| {
            let c = s.center.truncate();
            (l.min(c - s.radius), h.max(c + s.radius))
        },
    );
    let r_min = spheres.iter().map(|s| s.radius).fold(f64::MAX, f64::min);
    let cell = (r_min / 6.0).max((hi - lo).max_element() / 1500.0);
    let (w, h) = (
        ((hi.x - lo.x) / cell) as usize + 1,
        ((hi.y - lo.y) / cell) as usize + 1,
    );
    let mut inside = vec![false; w * h];
    for s in spheres {
        let c = s.center.truncate();
        let (x0, x1) = (
            ((c.x - s.radius - lo.x) / cell) as usize,
            ((c.x + s.radius - lo.x) / cell) as usize,
        );
        let (y0, y1) = (
            ((c.y - s.radius - lo.y) / cell) as usize,
            ((c.y + s.radius - lo.y) / cell) as usize,
        );
        for y in y0..=y1.min(h - 1) {
            for x in x0..=x1.min(w - 1) {
                let q = lo + DVec2::new(x as f64 + 0.5, y as f64 + 0.5) * cell;
                if q.distance_squared(c) <= s.radius * s.radius {
                    inside[y * w + x] = true;
                }
            }
        }
    }
    let mut count = 0;
    let mut stack = Vec::new();
    for start in 0..w * h {
        if !inside[start] {
            continue;
        }
        count += 1;
        inside[start] = false;
        stack.push(start);
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            for (nx, ny) in [
                (x.wrapping_sub(1), y),
                (x + 1, y),
                (x, y.wrapping_sub(1)),
                (x, y + 1),
            ] {
                if nx < w && ny < h && inside[ny * w + nx] {
                    inside[ny * w + nx] = false;
                    stack.push(ny * w + nx);
                }
            }
        }
    }
    count
}

#[test]
fn the_body_stays_one_piece_at_every_inflation() {
    // Spheres are spaced for their full radii; at t = 1 the sheep's fat body shrank to the
    // legs' radius and fell into beads.
    for (name, shape) in [
        ("sheep", sheep()),
        ("star", star(5, 5.0, 1.2)),
        ("cumulus", cumulus()),
    ] {
        if name == "sheep" {
            // Fatter than 4 r_f, the body's spheres (spaced 0.4 r) part at t = 1 unless filled.
            let base = interpret(&shape, true, &no_extend(), 1).unwrap();
            let fattest = base
                .spheres
                .iter()
                .map(|s| s.max_radius)
                .fold(0.0, f64::max);
            assert!(
                fattest > 8.0 * base.feature_radius,
                "{fattest} vs r_f {}",
                base.feature_radius
            );
        }
        for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let params = SketchParams {
                inflate: t,
                ..no_extend()
            };
            let s = interpret(&shape, true, &params, 1).unwrap();
            assert_eq!(pieces(&s.spheres), 1, "{name} at t = {t}");
            assert!(s.spheres.len() <= spheres::MAX_SPHERES);
        }
    }
}

#[test]
fn the_self_intersection_repair_stops_at_its_budget() {
    // A star polygon {320/157}: every edge crosses most others, so the repair splits again and
    // again; it used to go on searching after its budget ran out.
    let n = 320;
    let star: Vec<DVec2> = (0..n)
        .map(|i| DVec2::from_angle((i * 157 % n) as f64 / n as f64 * TAU) * 3.0)
        .collect();
    let full = outline::split_self_intersections(star.clone(), u64::MAX);
    assert!(
        !full.exhausted && full.loops.len() > 100,
        "{} loops",
        full.loops.len()
    );
    for budget in [full.tests / 2, full.tests / 10, 1_000] {
        let split = outline::split_self_intersections(star.clone(), budget);
        assert!(split.exhausted, "{budget}");
        assert!(
            split.tests <= budget,
            "{} tests for a budget of {budget}",
            split.tests
        );
    }
    let split = outline::split_self_intersections(star.clone(), outline::MAX_CROSSING_TESTS);
    assert!(split.tests <= outline::MAX_CROSSING_TESTS);
    // As a stroke, it is refused or repaired with a word, within the same budget.
    let raw: Vec<[f64; 2]> = star.iter().map(|p| [p.x, p.y]).collect();
    match outline::clean(&raw, true, 0.0) {
        Ok(o) => assert!(!o.warnings.is_empty()),
        Err(e) => assert!(
            matches!(e, SketchError::TooTangled | SketchError::NoArea),
            "{e}"
        ),
    }
}

/// An outline of exactly these vertices (no cleaning, no resampling).
fn raw_outline(v: &[[f64; 2]]) -> Outline {
    let points: Vec<DVec2> = v.iter().map(|&p| DVec2::from(p)).collect();
    Outline {
        area: outline::signed_area(&points),
        warnings: Vec::new(),
        boundary: outline::Boundary::new(&points),
        points,
    }
}

fn kinds(skeleton: &Skeleton, kind: skeleton::TriangleKind) -> usize {
    skeleton.kinds.iter().filter(|&&k| k == kind).count()
}

#[test]
fn chordal_axis_of_raw_polygons_classifies_triangles() {
    use skeleton::TriangleKind::{Junction, Terminal};
    // A 4-vertex rectangle: two triangles, each with one internal edge.
    let r = skeleton::chordal_axis(
        &raw_outline(&[[0.0, 0.0], [8.0, 0.0], [8.0, 2.0], [0.0, 2.0]]),
        0.0,
    )
    .unwrap();
    assert_eq!((kinds(&r, Terminal), kinds(&r, Junction)), (2, 0));
    // A 10-vertex five-point star: five tips, and the inner pentagon's three triangles all
    // have three internal edges.
    let star10: Vec<[f64; 2]> = (0..10)
        .map(|i| {
            let a = PI / 2.0 + i as f64 * PI / 5.0;
            let r = if i % 2 == 0 { 5.0 } else { 2.0 };
            [r * a.cos(), r * a.sin()]
        })
        .collect();
    let s = skeleton::chordal_axis(&raw_outline(&star10), 0.0).unwrap();
    assert_eq!(s.triangles.len(), 8);
    assert_eq!((kinds(&s, Terminal), kinds(&s, Junction)), (5, 3));
}

#[test]
fn spheres_are_maximal_balls_by_brute_force() {
    // Each ball (t = 0, no extension) is centred inside the outline, touches it, and holds no
    // outline point: checked against every point of a dense resampling of the outline, not the
    // distance index the code uses.
    for shape in [rect(9.0, 3.0, 40), star(5, 5.0, 2.0), l_shape(), cumulus()] {
        let s = interpret(&shape, true, &no_extend(), 1).unwrap();
        let p = &s.outline.points;
        let dense: Vec<DVec2> = (0..p.len())
            .flat_map(|i| {
                let (a, b) = (p[i], p[(i + 1) % p.len()]);
                (0..50).map(move |k| a.lerp(b, k as f64 / 50.0))
            })
            .collect();
        let scale = height(&s);
        for q in &s.spheres {
            let c = q.center.truncate();
            assert!(contains(p, c));
            let nearest = dense.iter().map(|d| d.distance(c)).fold(f64::MAX, f64::min);
            assert!(
                nearest >= q.radius - 1e-6 * scale,
                "an outline point inside a ball"
            );
            assert!(
                nearest <= q.radius + 0.01 * scale,
                "a ball that does not touch: {nearest} vs {}",
                q.radius
            );
        }
    }
}

#[test]
fn the_cloud_is_thick_along_the_planes_normal() {
    // Over the central half of the outline's box, the field (spheres blended as the renderer's
    // field blends one outline) is at least 0.4 × the outline's height thick along z (median of
    // a 7 × 7 grid of points inside the outline), and the
    // 3D extension spreads sphere centres along z by at least 0.3 × the height, including on
    // outlines whose pruned skeleton is a single path.
    use crate::field::{Blob, Field};
    for (name, shape) in [
        ("cumulus", cumulus()),
        ("star", star(5, 5.0, 2.0)),
        ("sheep", sheep()),
        ("rectangle (one path)", rect(12.0, 3.0, 40)),
        (
            "ellipse (one path)",
            disc(1.0, 200)
                .iter()
                .map(|p| [p[0] * 6.0, p[1] * 2.0])
                .collect(),
        ),
    ] {
        let s = interpret(&shape, true, &SketchParams::default(), 3).unwrap();
        let flat = interpret(&shape, true, &no_extend(), 3).unwrap();
        let h = height(&s);
        let field = Field {
            groups: vec![crate::field::Group::hard(
                s.spheres
                    .iter()
                    .map(|q| Blob::sphere(q.center.as_vec3(), q.radius as f32))
                    .collect(),
            )],
            ..Default::default()
        };
        let p = &s.outline.points;
        let (lo, hi) = p
            .iter()
            .fold((DVec2::MAX, DVec2::MIN), |(a, b), &q| (a.min(q), b.max(q)));
        let (c, half) = ((lo + hi) * 0.5, (hi - lo) * 0.25);
        let mut thickness = Vec::new();
        for j in 0..7 {
            for i in 0..7 {
                let q = c - half + half * 2.0 * DVec2::new(i as f64 / 6.0, j as f64 / 6.0);
                if outline::boundary_distance(q, p) < 0.1 * h || !contains(p, q) {
                    continue;
                }
                let inside = (0..400)
                    .filter(|k| {
                        let z = -2.0 * h + 4.0 * h * (*k as f64 + 0.5) / 400.0;
                        field.inside(q.extend(z).as_vec3())
                    })
                    .count();
                thickness.push(inside as f64 * 4.0 * h / 400.0);
            }
        }
        thickness.sort_by(f64::total_cmp);
        let median = thickness[thickness.len() / 2];
        assert!(
            median >= 0.4 * h,
            "{name}: {median:.2} thick (median) for a height of {h:.2}"
        );
        let spread = |sk: &Sketch| {
            let z = sk.spheres.iter().map(|q| q.center.z);
            z.clone().fold(f64::MIN, f64::max) - z.fold(f64::MAX, f64::min)
        };
        assert!(spread(&flat) == 0.0);
        assert!(
            spread(&s) >= 0.3 * h,
            "{name}: centres spread {:.2} along z for a height of {h:.2}",
            spread(&s)
        );
    }
}

/// Three bumpy arms from a small centre: body branches along each arm (between the bumps'
/// junctions) meeting at the centre.
fn tripod() -> Vec<[f64; 2]> {
    (0..720)
        .map(|i| i as f64 / 720.0 * TAU)
        .map(|a| {
            let arm = (1.5 * a).cos().abs().powi(6);
            let r = 1.5 + 5.0 * arm + 0.7 * (21.0 * a).sin().max(0.0).powi(2) * arm.sqrt();
            [r * a.cos(), r * a.sin()]
        })
        .collect()
}

#[test]
fn several_trunks_where_body_branches_meet_and_copies_follow_them() {
    // Pruned lightly, so the bumps along the arms keep their branches: each arm's skeleton is
    // then a body branch, and the three meet at the centre.
    let params = SketchParams {
        prune: 0.001,
        ..Default::default()
    };
    let s = interpret(
        &tripod(),
        true,
        &SketchParams {
            extend: false,
            ..params.clone()
        },
        1,
    )
    .unwrap();
    let trunks = spheres::trunks(&s.skeleton);
    assert_eq!(trunks.len(), 3, "{:?}", s.skeleton.branches);
    // Copies are placed around each bump's own trunk, so they stay inside the outline's
    // projection and are kept (a copy about a far-off axis would be trimmed away).
    let with = interpret(&tripod(), true, &params, 1).unwrap();
    let originals = s.spheres.iter().filter(|q| q.terminal).count();
    let copies = with
        .spheres
        .iter()
        .filter(|q| q.terminal && q.center.z.abs() > 1e-6)
        .count();
    assert!(
        copies as f64 >= 0.6 * originals as f64 * 2.0,
        "{copies} copy spheres for {originals} originals"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2, .. ProptestConfig::default() })]

    /// Strokes at the point cap and past it — long random walks that cross themselves again
    /// and again, and dense spirals — finish within every budget: thinned to the cap, at most
    /// 320 corners, the repair within its crossing tests, at most MAX_SPHERES spheres (the 3D
    /// extension included), or a clear refusal.
    #[test]
    fn strokes_at_the_caps_stay_within_their_budgets(seed: u64, spiral: bool, over in 0usize..3000) {
        let n = outline::MAX_STROKE_POINTS + over;
        let mut rng = crate::seeded::SplitMix::new(seed);
        let mut at = DVec2::ZERO;
        let pts: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                if spiral {
                    let a = i as f64 * 0.05;
                    [a.cos() * (1.0 + 0.002 * i as f64), a.sin() * (1.0 + 0.002 * i as f64)]
                } else {
                    at += DVec2::new(rng.next_f64() - 0.5, rng.next_f64() - 0.5);
                    [at.x, at.y]
                }
            })
            .collect();
        match outline::clean(&pts, true, 0.0) {
            Ok(o) => {
                prop_assert!(o.points.len() <= 2 * outline::MAX_OUTLINE_POINTS);
                if over > 0 {
                    prop_assert!(o.warnings.iter().any(|w| w.contains("thinned")));
                }
            }
            Err(e) => prop_assert!(matches!(e, SketchError::NoArea | SketchError::TooTangled), "{e}"),
        }
        if let Ok(s) = interpret(&pts, true, &SketchParams::default(), seed) {
            prop_assert!(!s.spheres.is_empty() && s.spheres.len() <= spheres::MAX_SPHERES);
        }
    }
}
