//! From a raw pointer stroke to a clean simple polygon: drop bad points, close, repair
//! self-intersections (keep the largest simple piece), simplify (Douglas–Peucker with a
//! tolerance relative to the outline's size) and resample evenly, keeping the corners.

use glam::DVec2;

use super::SketchError;

pub use crate::limits::{
    MAX_CROSSING_TESTS, MAX_OUTLINE_POINTS, MAX_PLANE_POINTS as MAX_STROKE_POINTS,
};
/// Fewest vertices of the resampled outline.
const MIN_OUTLINE_POINTS: usize = 24;

/// A clean outline and what was repaired on the way.
#[derive(Clone, Debug)]
pub struct Outline {
    /// Simple polygon, counter-clockwise (positive area), no repeated closing point.
    pub points: Vec<DVec2>,
    /// Its area.
    pub area: f64,
    /// Repairs made, in words.
    pub warnings: Vec<String>,
    /// `points` indexed for distance queries; rebuild with [`Outline::translate`] when moving.
    pub boundary: Boundary,
}

impl Outline {
    /// Moves the outline (and its index) by `offset`.
    pub fn translate(&mut self, offset: DVec2) {
        for p in &mut self.points {
            *p += offset;
        }
        self.boundary = Boundary::new(&self.points);
    }
}

/// Signed area (shoelace), positive for counter-clockwise in a y-up frame.
pub fn signed_area(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>() * 0.5
}

/// Perimeter of a closed polygon.
pub fn perimeter(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].distance(p[(i + 1) % n])).sum()
}

/// Diagonal of the bounding box.
pub fn diagonal(p: &[DVec2]) -> f64 {
    let (lo, hi) = p.iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(a, b), &q| (a.min(q), b.max(q)),
    );
    (hi - lo).length()
}

/// Squared distance from `q` to the segment `a`–`b`.
#[inline]
pub fn segment_distance_squared(q: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let aq = q - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        (aq.dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (aq - ab * t).length_squared()
}

/// Distance from `q` to the segment `a`–`b`.
pub fn segment_distance(q: DVec2, a: DVec2, b: DVec2) -> f64 {
    segment_distance_squared(q, a, b).sqrt()
}

/// Distance from `q` to a closed polygon's boundary.
pub fn boundary_distance(q: DVec2, p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| segment_distance_squared(q, p[i], p[(i + 1) % n]))
        .fold(f64::INFINITY, f64::min)
        .sqrt()
}

/// A closed polygon with a uniform grid of its edges, for fast distance queries (the sketch
/// asks for the distance to the outline thousands of times).
#[derive(Clone, Debug)]
pub struct Boundary {
    points: Vec<DVec2>,
    lo: DVec2,
    cell: f64,
    dims: [usize; 2],
    /// Edge indices (edge i runs from point i to point i + 1) overlapping each cell.
    cells: Vec<Vec<u32>>,
}

impl std::ops::Deref for Boundary {
    type Target = [DVec2];
    fn deref(&self) -> &[DVec2] {
        &self.points
    }
}

impl Boundary {
    /// Indexes the edges of a closed polygon.
    pub fn new(points: &[DVec2]) -> Self {
        let n = points.len();
        let (lo, hi) = points.iter().fold(
            (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
            |(a, b), &q| (a.min(q), b.max(q)),
        );
        let size = (hi - lo).max(DVec2::splat(1e-12));
        let side = ((n as f64).sqrt().ceil() as usize).clamp(1, 64);
        let cell = size.max_element() / side as f64;
        let dims = [
            ((size.x / cell).ceil() as usize).clamp(1, 64),
            ((size.y / cell).ceil() as usize).clamp(1, 64),
        ];
        let mut cells = vec![Vec::new(); dims[0] * dims[1]];
        let cell_of = |q: DVec2| {
            let c = ((q - lo) / cell).floor();
            [
                (c.x.max(0.0) as usize).min(dims[0] - 1),
                (c.y.max(0.0) as usize).min(dims[1] - 1),
            ]
        };
        for i in 0..n {
            let (a, b) = (points[i], points[(i + 1) % n]);
            let (ca, cb) = (cell_of(a.min(b)), cell_of(a.max(b)));
            for y in ca[1]..=cb[1] {
                for x in ca[0]..=cb[0] {
                    cells[y * dims[0] + x].push(i as u32);
                }
            }
        }
        Self {
            points: points.to_vec(),
            lo,
            cell,
            dims,
            cells,
        }
    }

    /// Distance from `q` to the polygon's boundary (equal to [`boundary_distance`]).
    pub fn distance(&self, q: DVec2) -> f64 {
        let n = self.points.len();
        if n == 0 {
            return f64::INFINITY;
        }
        let c = ((q - self.lo) / self.cell).floor();
        let (cx, cy) = (c.x as i64, c.y as i64);
        let (w, h) = (self.dims[0] as i64, self.dims[1] as i64);
        let mut best = f64::INFINITY;
        let mut seen_all = false;
        let mut k = 0i64;
        while !seen_all {
            // Cells on ring k around (cx, cy), clamped to the grid.
            let (x0, x1, y0, y1) = (cx - k, cx + k, cy - k, cy + k);
            for y in y0.max(0)..=y1.min(h - 1) {
                for x in x0.max(0)..=x1.min(w - 1) {
                    if y != y0 && y != y1 && x != x0 && x != x1 {
                        continue; // inside the ring: searched already
                    }
                    for &e in &self.cells[(y * w + x) as usize] {
                        let e = e as usize;
                        best = best.min(segment_distance_squared(
                            q,
                            self.points[e],
                            self.points[(e + 1) % n],
                        ));
                    }
                }
            }
            seen_all = x0 <= 0 && y0 <= 0 && x1 >= w - 1 && y1 >= h - 1;
            // Every edge not yet seen lies outside the searched block of cells.
            let block_lo = self.lo + DVec2::new(x0 as f64, y0 as f64) * self.cell;
            let block_hi = self.lo + DVec2::new((x1 + 1) as f64, (y1 + 1) as f64) * self.cell;
            let margin = (q - block_lo).min(block_hi - q).min_element();
            if margin > 0.0 && best <= margin * margin {
                break;
            }
            k += 1;
        }
        best.sqrt()
    }
}

/// Even–odd point-in-polygon test.
pub fn contains(p: &[DVec2], q: DVec2) -> bool {
    let n = p.len();
    let mut inside = false;
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (p[i], p[j]);
        if (a.y > q.y) != (b.y > q.y) && q.x < (b.x - a.x) * (q.y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// Cleans a stroke into an outline. `simplify` is the Douglas–Peucker tolerance as a fraction
/// of the outline's bounding-box diagonal.
pub fn clean(raw: &[[f64; 2]], closed: bool, simplify: f64) -> Result<Outline, SketchError> {
    let mut warnings = Vec::new();
    let finite: Vec<DVec2> = raw
        .iter()
        .map(|&[x, y]| DVec2::new(x, y))
        .filter(|p| p.is_finite())
        .collect();
    if finite.len() < raw.len() {
        warnings.push(format!(
            "ignored {} points that were not numbers",
            raw.len() - finite.len()
        ));
    }
    let (mut points, thinned) = thin(&finite);
    warnings.extend(thinned);
    if points.len() < 3 {
        return Err(SketchError::TooFewPoints(points.len()));
    }
    // The stroke's extent, measured without squaring (a diagonal of 1e200 units overflows).
    let (lo, hi) = points
        .iter()
        .fold((DVec2::MAX, DVec2::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let extent = (hi - lo).max_element();
    if extent > 0.0 && !(super::MIN_EXTENT..=super::MAX_EXTENT).contains(&extent) {
        return Err(SketchError::OutOfRange(extent));
    }
    let size = diagonal(&points);
    if !size.is_finite() || size <= 0.0 {
        return Err(SketchError::NoArea);
    }
    // A coordinate far below the stroke's precision is zero (the triangulation refuses
    // magnitudes near the smallest doubles).
    for p in &mut points {
        for c in [&mut p.x, &mut p.y] {
            if c.abs() < size * 1e-12 {
                *c = 0.0;
            }
        }
    }
    // Coordinates far from the origin lose precision in the triangulation: work around the centre.
    let eps = size * 1e-7;
    dedup(&mut points, eps);
    if points.len() < 3 {
        return Err(SketchError::TooFewPoints(points.len()));
    }
    if !closed {
        let gap = points[0].distance(points[points.len() - 1]);
        if gap > 0.2 * size {
            warnings.push("the stroke was open; closed it by joining its ends".to_string());
        }
    }

    // Simplify first so the self-intersection repair works on few vertices. The outline keeps
    // at most MAX_OUTLINE_POINTS corners: past that the tolerance grows until it fits, so a long
    // stroke at simplify 0 is simplified a little more, never cut short.
    let mut tolerance = simplify.clamp(0.0, 0.2) * size;
    let mut simple = douglas_peucker_closed(&points, tolerance.max(eps * 10.0));
    let asked = tolerance;
    while simple.len() > MAX_OUTLINE_POINTS {
        tolerance = (tolerance * 1.5).max(size * 5e-4);
        simple = douglas_peucker_closed(&points, tolerance);
    }
    if tolerance > asked {
        warnings.push(format!(
            "the outline had more than {MAX_OUTLINE_POINTS} corners; simplified to within {:.2}% of its size",
            100.0 * tolerance / size
        ));
    }
    dedup(&mut simple, eps);
    // No test of the whole stroke's signed area here: a scribble's loops turn both ways and
    // cancel (a figure eight's is zero) while each encloses area; the loops decide below.
    if simple.len() < 3 {
        return Err(SketchError::NoArea);
    }

    let split = split_self_intersections(simple, MAX_CROSSING_TESTS);
    if split.exhausted {
        if split.loops.is_empty() {
            return Err(SketchError::TooTangled);
        }
        warnings.push("the stroke crosses itself very often; kept the largest loop found".into());
    }
    let mut loops = split.loops;
    for l in &mut loops {
        dedup(l, eps);
    }
    loops.retain(|l| l.len() >= 3);
    let total: f64 = loops.iter().map(|l| signed_area(l).abs()).sum();
    let best = loops
        .into_iter()
        .max_by(|a, b| signed_area(a).abs().total_cmp(&signed_area(b).abs()))
        .ok_or(SketchError::NoArea)?;
    let kept = signed_area(&best).abs();
    if kept < total * 0.99 {
        warnings.push(format!(
            "the stroke crossed itself; kept the largest enclosed part ({:.0}% of the drawn area)",
            100.0 * kept / total
        ));
    }
    let mut best = best;
    if signed_area(&best) < 0.0 {
        best.reverse();
    }
    if kept < size * size * 1e-4 {
        return Err(SketchError::NoArea);
    }

    let mut points = resample(&best, tolerance);
    dedup(&mut points, eps);
    // Resampling a simple polygon along its own edges keeps it simple.
    let area = signed_area(&points);
    if points.len() < 3 || area <= 0.0 {
        return Err(SketchError::NoArea);
    }
    let boundary = Boundary::new(&points);
    Ok(Outline {
        points,
        area,
        warnings,
        boundary,
    })
}

/// Removes consecutive points closer than `eps` (the polygon is closed: last vs first too).
fn dedup(points: &mut Vec<DVec2>, eps: f64) {
    points.dedup_by(|b, a| a.distance(*b) <= eps);
    while points.len() > 1 && points[0].distance(points[points.len() - 1]) <= eps {
        points.pop();
    }
}

/// Douglas–Peucker on a closed polygon: split at the two mutually far points, simplify each half.
fn douglas_peucker_closed(p: &[DVec2], tolerance: f64) -> Vec<DVec2> {
    let n = p.len();
    if n <= 4 {
        return p.to_vec();
    }
    let far = (1..n)
        .max_by(|&a, &b| {
            p[0].distance_squared(p[a])
                .total_cmp(&p[0].distance_squared(p[b]))
        })
        .unwrap_or(n / 2);
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[far] = true;
    let first: Vec<usize> = (0..=far).collect();
    let second: Vec<usize> = (far..n).chain(std::iter::once(0)).collect();
    for chain in [first, second] {
        let mut stack = vec![(0usize, chain.len() - 1)];
        while let Some((a, b)) = stack.pop() {
            if b <= a + 1 {
                continue;
            }
            let (pa, pb) = (p[chain[a]], p[chain[b]]);
            let (mut worst, mut at) = (0.0, a);
            for (i, &c) in chain.iter().enumerate().take(b).skip(a + 1) {
                let d = segment_distance(p[c], pa, pb);
                if d > worst {
                    worst = d;
                    at = i;
                }
            }
            if worst > tolerance {
                keep[chain[at]] = true;
                stack.push((a, at));
                stack.push((at, b));
            }
        }
    }
    (0..n).filter(|&i| keep[i]).map(|i| p[i]).collect()
}

/// Resamples a closed polygon evenly, keeping every vertex (the corners of the simplified outline).
/// With `p` of at most [`MAX_OUTLINE_POINTS`] corners the result has at most twice that many
/// points: each edge gets ⌊length / spacing⌋ pieces, at least one, and the whole of every edge.
fn resample(p: &[DVec2], tolerance: f64) -> Vec<DVec2> {
    let total = perimeter(p);
    let target =
        (total / (tolerance * 2.0).max(total / MAX_OUTLINE_POINTS as f64)).round() as usize;
    let count = target.clamp(MIN_OUTLINE_POINTS, MAX_OUTLINE_POINTS);
    let spacing = total / count as f64;
    let n = p.len();
    let mut out = Vec::with_capacity(count + n);
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        let pieces = ((a.distance(b) / spacing) as usize).max(1);
        for k in 0..pieces {
            out.push(a.lerp(b, k as f64 / pieces as f64));
        }
    }
    out
}

/// A stroke of more than [`MAX_STROKE_POINTS`] points thinned to that many, evenly by index,
/// with the repair in words. Whoever stores a stroke stores the thinned one, so a document
/// never holds a stroke its own validation would refuse.
pub fn thin<T: Copy>(points: &[T]) -> (Vec<T>, Option<String>) {
    if points.len() <= MAX_STROKE_POINTS {
        return (points.to_vec(), None);
    }
    let step = points.len() as f64 / MAX_STROKE_POINTS as f64;
    let kept = (0..MAX_STROKE_POINTS)
        .map(|i| points[(i as f64 * step) as usize])
        .collect();
    let why = format!(
        "the stroke had {} points; thinned to {MAX_STROKE_POINTS}",
        points.len()
    );
    (kept, Some(why))
}

fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Where segments `a`–`b` and `c`–`d` meet, touching and overlapping included.
fn intersection(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Option<DVec2> {
    let (d1, d2, d3, d4) = (
        orient(c, d, a),
        orient(c, d, b),
        orient(a, b, c),
        orient(a, b, d),
    );
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        let t = d1 / (d1 - d2);
        return Some(a + (b - a) * t);
    }
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        // r on segment p–q (collinear and within its box)
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    if d1 == 0.0 && on(c, d, a) {
        return Some(a);
    }
    if d2 == 0.0 && on(c, d, b) {
        return Some(b);
    }
    if d3 == 0.0 && on(a, b, c) {
        return Some(c);
    }
    if d4 == 0.0 && on(a, b, d) {
        return Some(d);
    }
    None
}

/// First pair of non-adjacent edges (i < j) that meet, with the meeting point; `Err` when the
/// search would pass `budget` pair tests (each test made is taken from it).
fn first_crossing(p: &[DVec2], budget: &mut u64) -> Result<Option<(usize, usize, DVec2)>, ()> {
    let n = p.len();
    for i in 0..n {
        let (a, b) = (p[i], p[(i + 1) % n]);
        let (lo, hi) = (a.min(b), a.max(b));
        let tests = n.saturating_sub(i + 2) as u64;
        *budget = budget.checked_sub(tests).ok_or(())?;
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the closing edge
            }
            let (c, d) = (p[j], p[(j + 1) % n]);
            if c.max(d).cmplt(lo).any() || c.min(d).cmpgt(hi).any() {
                continue;
            }
            if let Some(x) = intersection(a, b, c, d) {
                return Ok(Some((i, j, x)));
            }
        }
    }
    Ok(None)
}

/// What [`split_self_intersections`] found.
#[derive(Debug)]
pub struct Split {
    /// Loops proven simple.
    pub loops: Vec<Vec<DVec2>>,
    /// Segment-pair crossing tests made.
    pub tests: u64,
    /// Whether the test budget ran out before every loop was proven simple.
    pub exhausted: bool,
}

/// The simple loops a closed polygon splits into at its self-intersections, making at most
/// `budget` crossing tests. The search stops at [`MAX_CROSSING_TESTS`]: loops not yet proven simple then are
/// dropped (the caller keeps the largest simple one, and says how much of the area it kept).
pub fn split_self_intersections(polygon: Vec<DVec2>, budget: u64) -> Split {
    let limit = budget;
    let mut budget = budget;
    let mut out = Vec::new();
    let mut stack = vec![polygon];
    while let Some(p) = stack.pop() {
        if p.len() < 3 {
            continue;
        }
        let Ok(crossing) = first_crossing(&p, &mut budget) else {
            return Split {
                loops: out,
                tests: limit - budget,
                exhausted: true,
            };
        };
        match crossing {
            None => out.push(p),
            Some((i, j, x)) => {
                let mut a: Vec<DVec2> = p[..=i].to_vec();
                a.push(x);
                a.extend_from_slice(&p[j + 1..]);
                let mut b = vec![x];
                b.extend_from_slice(&p[i + 1..=j]);
                for l in [a, b] {
                    let mut l = l;
                    dedup(&mut l, 0.0);
                    if l.len() >= 3 && l.len() < p.len() + 1 {
                        stack.push(l);
                    }
                }
            }
        }
    }
    Split {
        loops: out,
        tests: limit - budget,
        exhausted: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(n: usize) -> Vec<[f64; 2]> {
        let mut v = Vec::new();
        for k in 0..4 {
            for i in 0..n {
                let t = i as f64 / n as f64;
                v.push(match k {
                    0 => [t, 0.0],
                    1 => [1.0, t],
                    2 => [1.0 - t, 1.0],
                    _ => [0.0, 1.0 - t],
                });
            }
        }
        v
    }

    #[test]
    fn indexed_distance_equals_brute_force() {
        let mut pts: Vec<DVec2> = Vec::new();
        for i in 0..300 {
            let a = i as f64 / 300.0 * std::f64::consts::TAU;
            let r = 3.0 + (a * 7.0).sin();
            pts.push(DVec2::new(r * a.cos() + 100.0, r * a.sin() - 50.0));
        }
        let b = Boundary::new(&pts);
        for i in 0..40 {
            for j in 0..40 {
                let q = DVec2::new(92.0 + i as f64 * 0.4, -58.0 + j as f64 * 0.4);
                assert!(
                    (b.distance(q) - boundary_distance(q, &pts)).abs() < 1e-12,
                    "{q}"
                );
            }
        }
    }

    #[test]
    fn square_stays_a_square() {
        let o = clean(&square(50), true, 0.01).unwrap();
        assert!((o.area - 1.0).abs() < 1e-9);
        assert!(o.warnings.is_empty(), "{:?}", o.warnings);
        assert!(o.points.len() >= MIN_OUTLINE_POINTS);
    }

    #[test]
    fn figure_eight_keeps_the_larger_lobe() {
        // Lemniscate of Gerono with one lobe scaled 3×: lobes of area 6 and 2/3 crossing at 0.
        let n = 400;
        let pts: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) / n as f64 * std::f64::consts::TAU;
                let k = if t < std::f64::consts::PI { 3.0 } else { 1.0 };
                [k * t.sin(), k * t.sin() * t.cos()]
            })
            .collect();
        let o = clean(&pts, true, 0.002).unwrap();
        assert!(o.area > 5.6 && o.area < 6.2, "{}", o.area);
        assert!(o.warnings.iter().any(|w| w.contains("crossed itself")));
        assert_eq!(first_crossing(&o.points, &mut u64::MAX.clone()), Ok(None));
    }

    #[test]
    fn a_scribble_whose_loops_turn_both_ways_keeps_its_largest_loop() {
        // A figure eight: two equal lobes, one turning each way, so the stroke's signed area
        // is zero; it was refused as enclosing no area. Now one lobe is kept, with a word.
        let eight: Vec<[f64; 2]> = (0..120)
            .map(|i| {
                let t = i as f64 / 120.0 * std::f64::consts::TAU;
                [2.0 * t.sin(), (2.0 * t).sin()]
            })
            .collect();
        let outline = clean(&eight, true, 0.01).expect("the larger lobe");
        assert!(outline.area > 0.5, "area {}", outline.area);
        assert!(
            outline
                .warnings
                .iter()
                .any(|w| w.contains("crossed itself")),
            "{:?}",
            outline.warnings
        );
    }

    #[test]
    fn degenerate_strokes_are_refused() {
        assert!(matches!(
            clean(&[], true, 0.01),
            Err(SketchError::TooFewPoints(0))
        ));
        assert!(matches!(
            clean(&[[1.0, 1.0], [2.0, 2.0]], true, 0.01),
            Err(SketchError::TooFewPoints(2))
        ));
        assert!(clean(&[[1.0, 1.0]; 50], true, 0.01).is_err());
        let line: Vec<[f64; 2]> = (0..50).map(|i| [i as f64, 2.0 * i as f64]).collect();
        assert!(matches!(
            clean(&line, false, 0.01),
            Err(SketchError::NoArea)
        ));
        assert!(
            clean(
                &[[f64::NAN, 0.0], [0.0, f64::INFINITY], [1.0, 1.0]],
                true,
                0.01
            )
            .is_err()
        );
    }
}
