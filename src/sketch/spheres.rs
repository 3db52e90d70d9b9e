//! Spheres along the skeleton (Wither et al. §3.1), the minimal feature radius r_f and the
//! inflation slider, and the automatic 3D extension (§3.2).
//!
//! Coordinates: the outline's plane is z = 0, z points toward the viewer.

use glam::{DQuat, DVec2, DVec3};

use super::outline::{Boundary, Outline, contains};
use super::skeleton::{BranchKind, Skeleton};
use crate::seeded::SplitMix;

pub use crate::limits::MAX_SPHERES;
/// Spacing of spheres along the skeleton as a fraction of the smaller neighbouring radius:
/// well below 1, so neighbours overlap deeply and the body never splits.
const SPACING: f64 = 0.4;

/// How far (in the radius of the branch's root sphere) a copy may slide along its trunk from
/// the original: enough to stagger copies, little enough that a thin feature's copy still
/// projects inside its own outline.
const COPY_SLIDE: f64 = 0.5;

/// A sphere primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: DVec3,
    /// Radius.
    pub radius: f64,
    /// Maximal-ball radius before inflation (equal to `radius` at t = 0).
    pub max_radius: f64,
    /// Index of the skeleton branch it belongs to.
    pub branch: usize,
    /// Whether this branch is terminal (a feature).
    pub terminal: bool,
    /// Fraction along its branch from its root (0) to its free end (1).
    pub along: f64,
}

/// Spheres sampled densely along every branch, radius = distance to the outline.
pub fn sample(outline: &Outline, skeleton: &Skeleton) -> Vec<Sphere> {
    let p = &outline.boundary;
    let total_len: f64 = skeleton
        .segments
        .iter()
        .map(|s| skeleton.nodes[s[0]].pos.distance(skeleton.nodes[s[1]].pos))
        .sum();
    let min_radius = skeleton.nodes.iter().map(|n| n.radius).fold(0.0, f64::max) * 1e-4;
    // Keep within the cap: the step never falls below total length / budget.
    let floor = total_len / (MAX_SPHERES as f64 * 0.3);
    let mut out = Vec::new();
    // A skeleton that is one path has both ends free: its features are its two outer halves.
    let lone = skeleton.branches.len() == 1;
    for (b, branch) in skeleton.branches.iter().enumerate() {
        let terminal = branch.kind == BranchKind::Terminal;
        let pts: Vec<DVec2> = branch
            .nodes
            .iter()
            .map(|&i| skeleton.nodes[i].pos)
            .collect();
        let length: f64 = pts.windows(2).map(|w| w[0].distance(w[1])).sum();
        let mut along = 0.0;
        // Places a sphere at `q` (when usable); returns the distance to the outline there.
        let push = |q: DVec2, along: f64, out: &mut Vec<Sphere>| -> f64 {
            let r = p.distance(q);
            if r > min_radius && contains(p, q) {
                let f = if length > 0.0 { along / length } else { 0.0 };
                let f = if lone { 1.0 - 2.0 * f.min(1.0 - f) } else { f };
                out.push(Sphere {
                    center: q.extend(0.0),
                    radius: r,
                    max_radius: r,
                    branch: b,
                    terminal,
                    along: f,
                });
            }
            r
        };
        // Each segment starts where the previous one ended, at the distance found there.
        let mut r = push(pts[0], 0.0, &mut out);
        for w in pts.windows(2) {
            let (a, c) = (w[0], w[1]);
            let len = a.distance(c);
            let mut t = 0.0;
            while t < len {
                t += (SPACING * r.max(min_radius)).max(floor).max(len * 1e-3);
                r = push(a.lerp(c, (t / len).min(1.0)), along + t.min(len), &mut out);
            }
            along += len;
        }
    }
    bridge(p, &mut out, |r| r);
    out
}

/// Which spheres are joined to the first one through a chain of overlapping spheres.
pub fn body_of_first(spheres: &[Sphere]) -> Vec<bool> {
    joined_to_first(spheres, 1.0)
}

/// Which spheres are joined to the first one through neighbours closer than `overlap` × the
/// sum of their radii.
fn joined_to_first(spheres: &[Sphere], overlap: f64) -> Vec<bool> {
    let n = spheres.len();
    let mut seen = vec![false; n];
    let mut stack = Vec::new();
    if n > 0 {
        seen[0] = true;
        stack.push(0);
    }
    while let Some(i) = stack.pop() {
        for j in 0..n {
            if !seen[j]
                && spheres[i].center.distance(spheres[j].center)
                    < overlap * (spheres[i].radius + spheres[j].radius)
            {
                seen[j] = true;
                stack.push(j);
            }
        }
    }
    seen
}

/// Joins spheres that do not overlap the main body firmly to it with spheres along the
/// shortest link inside the outline, so the cloud's body never splits; `radius` maps a maximal
/// ball's radius to the radius the link's spheres get.
fn bridge(p: &Boundary, spheres: &mut Vec<Sphere>, radius: impl Fn(f64) -> f64) {
    for _ in 0..64 {
        let n = spheres.len();
        if n < 2 {
            return;
        }
        let seen = joined_to_first(spheres, FIRM_OVERLAP);
        if seen.iter().all(|&s| s) {
            return;
        }
        // Closest pair between the body and the rest.
        let mut best = (f64::INFINITY, 0, 0);
        for i in (0..n).filter(|&i| seen[i]) {
            for j in (0..n).filter(|&j| !seen[j]) {
                let d = spheres[i].center.distance(spheres[j].center)
                    - spheres[i].radius
                    - spheres[j].radius;
                if d < best.0 {
                    best = (d, i, j);
                }
            }
        }
        let (a, b) = (spheres[best.1], spheres[best.2]);
        let (qa, qb) = (a.center.truncate(), b.center.truncate());
        let len = qa.distance(qb);
        let mut t = 0.0;
        let mut added = false;
        while t < len && spheres.len() < MAX_SPHERES {
            let q = qa.lerp(qb, t / len);
            let r_max = p.distance(q);
            if r_max <= 0.0 || !contains(p, q) {
                break;
            }
            let r = radius(r_max);
            spheres.push(Sphere {
                center: q.extend(0.0),
                radius: r,
                max_radius: r_max,
                ..b
            });
            added = true;
            t += (SPACING * r).max(len * 1e-3);
        }
        if !added {
            // Cannot link it inside the outline: drop the stray piece.
            let mut k = 0;
            spheres.retain(|_| {
                k += 1;
                seen[k - 1]
            });
        }
    }
}

/// The minimal feature radius r_f: the largest radius over the last 50% (toward the free end)
/// of the terminal branches' spheres. Falls back to the largest radius when there are none.
pub fn feature_radius(spheres: &[Sphere]) -> f64 {
    let tips = spheres
        .iter()
        .filter(|s| s.terminal && s.along >= 0.5)
        .map(|s| s.max_radius)
        .fold(0.0, f64::max);
    if tips > 0.0 {
        tips
    } else {
        spheres.iter().map(|s| s.max_radius).fold(0.0, f64::max)
    }
}

/// The radius a maximal ball of radius `r` gets at inflation `t` (see [`inflate`]).
fn deflated(r: f64, r_f: f64, t: f64) -> f64 {
    if r > r_f { r + (r_f - r) * t } else { r }
}

/// Inflation slider: t = 0 keeps the maximal balls, t = 1 shrinks every sphere above r_f to
/// r_f; spheres at or below r_f never change. Then neighbours along a branch that no longer
/// overlap firmly (the body was sampled for its full radii: at t = 1 fat parts would fall
/// into beads) get spheres in between, at the deflated radius of their own maximal ball, and
/// any piece still apart is bridged to the body: at every t the body stays one piece.
pub fn inflate(outline: &Boundary, spheres: &mut Vec<Sphere>, r_f: f64, t: f64) {
    let t = t.clamp(0.0, 1.0);
    for s in spheres.iter_mut() {
        s.radius = deflated(s.max_radius, r_f, t);
    }
    if t > 0.0 {
        let fill = fill_gaps(outline, spheres, |r| deflated(r, r_f, t));
        spheres.extend(fill);
        bridge(outline, spheres, |r| deflated(r, r_f, t));
    }
}

/// Neighbours closer than this fraction of their radii's sum count as one piece: enough overlap
/// that a grid of a few cells per sphere still sees them joined.
const FIRM_OVERLAP: f64 = 0.8;

/// Spheres between consecutive spheres of one branch that do not overlap firmly.
fn fill_gaps(p: &Boundary, spheres: &[Sphere], radius: impl Fn(f64) -> f64) -> Vec<Sphere> {
    let mut fill = Vec::new();
    for w in spheres.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (qa, qb) = (a.center.truncate(), b.center.truncate());
        let len = qa.distance(qb);
        if a.branch != b.branch || len <= FIRM_OVERLAP * (a.radius + b.radius) {
            continue;
        }
        let mut t = 0.0;
        let mut r = a.radius;
        loop {
            t += SPACING * r.max(len * 1e-3);
            if t >= len || spheres.len() + fill.len() >= MAX_SPHERES {
                break;
            }
            let q = qa.lerp(qb, t / len);
            let r_max = p.distance(q);
            if r_max <= 0.0 || !contains(p, q) {
                break;
            }
            r = radius(r_max);
            fill.push(Sphere {
                center: q.extend(0.0),
                radius: r,
                max_radius: r_max,
                along: a.along + (b.along - a.along) * t / len,
                ..a
            });
        }
    }
    fill
}

/// The trunk: the longest chain of body branches, or the longest path of the skeleton when it
/// has too few junctions for a body. Returned as a polyline of points.
pub fn trunk(skeleton: &Skeleton) -> Vec<DVec2> {
    let n = skeleton.nodes.len();
    let mut adj: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
    let body: Vec<bool> =
        {
            let mut v = vec![false; skeleton.segments.len()];
            for b in skeleton
                .branches
                .iter()
                .filter(|b| b.kind == BranchKind::Body)
            {
                for w in b.nodes.windows(2) {
                    if let Some(i) = skeleton.segments.iter().position(|s| {
                        (s[0] == w[0] && s[1] == w[1]) || (s[0] == w[1] && s[1] == w[0])
                    }) {
                        v[i] = true;
                    }
                }
            }
            v
        };
    let any_body = body.iter().any(|&b| b);
    for (i, s) in skeleton.segments.iter().enumerate() {
        if s[0] != s[1] && (!any_body || body[i]) {
            let d = skeleton.nodes[s[0]].pos.distance(skeleton.nodes[s[1]].pos);
            adj[s[0]].push((s[1], d));
            adj[s[1]].push((s[0], d));
        }
    }
    // Longest path in a forest: farthest node from any node, then farthest from that.
    let farthest = |from: usize| {
        let mut dist = vec![f64::NAN; n];
        let mut parent = vec![usize::MAX; n];
        dist[from] = 0.0;
        let mut stack = vec![from];
        while let Some(u) = stack.pop() {
            for &(v, d) in &adj[u] {
                if dist[v].is_nan() {
                    dist[v] = dist[u] + d;
                    parent[v] = u;
                    stack.push(v);
                }
            }
        }
        let end = (0..n)
            .filter(|&i| !dist[i].is_nan())
            .max_by(|&a, &b| dist[a].total_cmp(&dist[b]))
            .unwrap_or(from);
        (end, parent)
    };
    let Some(seed) = (0..n).find(|&i| !adj[i].is_empty()) else {
        return skeleton
            .nodes
            .first()
            .map(|n| vec![n.pos])
            .unwrap_or_default();
    };
    let (a, _) = farthest(seed);
    let (b, parent) = farthest(a);
    let mut path = vec![skeleton.nodes[b].pos];
    let mut cur = b;
    while cur != a && parent[cur] != usize::MAX {
        cur = parent[cur];
        path.push(skeleton.nodes[cur].pos);
    }
    path
}

/// Nearest point on a polyline and the polyline's unit direction there.
/// The trunks (Wither et al. §3.2): the body branches joined into chains, split wherever three
/// or more body branches meet. A skeleton without body branches has one trunk, its longest
/// path ([`trunk`]).
pub fn trunks(skeleton: &Skeleton) -> Vec<Vec<DVec2>> {
    let body: Vec<&super::skeleton::Branch> = skeleton
        .branches
        .iter()
        .filter(|b| b.kind == BranchKind::Body && b.nodes.len() >= 2)
        .collect();
    if body.is_empty() {
        return vec![trunk(skeleton)];
    }
    let mut incident = std::collections::HashMap::<usize, Vec<usize>>::new();
    for (i, b) in body.iter().enumerate() {
        for end in [b.nodes[0], b.nodes[b.nodes.len() - 1]] {
            incident.entry(end).or_default().push(i);
        }
    }
    let mut used = vec![false; body.len()];
    let mut out = Vec::new();
    for start in 0..body.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let mut chain: std::collections::VecDeque<usize> =
            body[start].nodes.iter().copied().collect();
        // Grow the chain at each end through nodes where exactly two body branches meet.
        for forward in [true, false] {
            loop {
                let end = if forward {
                    chain[chain.len() - 1]
                } else {
                    chain[0]
                };
                let next = match incident.get(&end).map(Vec::as_slice) {
                    Some(&[a, b]) => [a, b].into_iter().find(|&i| !used[i]),
                    _ => None,
                };
                let Some(next) = next else { break };
                used[next] = true;
                let mut nodes = body[next].nodes.clone();
                if nodes[0] != end {
                    nodes.reverse();
                }
                for &n in &nodes[1..] {
                    if forward {
                        chain.push_back(n);
                    } else {
                        chain.push_front(n);
                    }
                }
            }
        }
        out.push(chain.into_iter().map(|n| skeleton.nodes[n].pos).collect());
    }
    out
}

/// The point at arclength `s` along a polyline (clamped to its ends) and the unit direction
/// there.
fn point_at(polyline: &[DVec2], s: f64) -> (DVec2, DVec2) {
    let mut left = s.max(0.0);
    let mut last = (polyline[0], DVec2::X);
    for w in polyline.windows(2) {
        let len = w[0].distance(w[1]);
        if len <= 0.0 {
            continue;
        }
        let dir = (w[1] - w[0]) / len;
        if left <= len {
            return (w[0] + dir * left, dir);
        }
        left -= len;
        last = (w[1], dir);
    }
    last
}

/// Arclength along a polyline of its point nearest to `q`.
fn arclength_of(polyline: &[DVec2], q: DVec2) -> f64 {
    let (mut best, mut at, mut run) = (f64::INFINITY, 0.0, 0.0);
    for w in polyline.windows(2) {
        let ab = w[1] - w[0];
        let len = ab.length();
        if len <= 0.0 {
            continue;
        }
        let t = ((q - w[0]).dot(ab) / (len * len)).clamp(0.0, 1.0);
        let d = (w[0] + ab * t).distance_squared(q);
        if d < best {
            (best, at) = (d, run + t * len);
        }
        run += len;
    }
    at
}

fn nearest_on(polyline: &[DVec2], q: DVec2) -> (DVec2, DVec2) {
    if polyline.len() < 2 {
        return (polyline.first().copied().unwrap_or(q), DVec2::X);
    }
    let mut best = (f64::INFINITY, polyline[0], DVec2::X);
    for w in polyline.windows(2) {
        let (a, b) = (w[0], w[1]);
        let ab = b - a;
        let len2 = ab.length_squared();
        if len2 <= 0.0 {
            continue;
        }
        let t = ((q - a).dot(ab) / len2).clamp(0.0, 1.0);
        let x = a + ab * t;
        let d = x.distance_squared(q);
        if d < best.0 {
            best = (d, x, ab / len2.sqrt());
        }
    }
    (best.1, best.2)
}

/// The automatic 3D extension (Wither et al. §3.2): each terminal branch gets `copies` copies
/// placed around its trunk — the nearest of [`trunks`] to the branch's root — like branches
/// around a tree: spread evenly over the half-turn on the side the branch grows from (−90° to
/// 90° out of the drawing plane, toward and away from the viewer, with seeded variation), each
/// slid a little along the trunk and scaled to the trunk's local radius there. The original
/// keeps its place but for a small jitter out of the plane, so the outline seen from the
/// drawing view is unchanged; every copy is trimmed to stay inside it.
pub fn extend(
    outline: &Outline,
    skeleton: &Skeleton,
    spheres: &[Sphere],
    seed: u64,
    copies: usize,
) -> Vec<Sphere> {
    let trunks = trunks(skeleton);
    let mut rng = SplitMix::new(seed ^ 0xC10D_5CE7);
    let mut out: Vec<Sphere> = Vec::with_capacity(spheres.len() * (copies + 1));
    let budget_copies = if spheres.len() * (copies + 1) > MAX_SPHERES {
        (MAX_SPHERES / spheres.len().max(1)).saturating_sub(1)
    } else {
        copies
    };
    let p = &outline.boundary;

    for (b, branch) in skeleton.branches.iter().enumerate() {
        let mut members: Vec<Sphere> = spheres.iter().filter(|s| s.branch == b).copied().collect();
        if members.is_empty() {
            continue;
        }
        if skeleton.branches.len() == 1 {
            // One path: its own spheres are the trunk. Copies hug it toward and away from the
            // viewer, inside each sphere's silhouette (smaller, offset along z only), so the
            // outline stays exact and the cloud gains lobes in depth.
            out.extend(members.iter().copied());
            for k in 0..budget_copies {
                let side = if k % 2 == 0 { 1.0 } else { -1.0 };
                for s in &members {
                    let shift = s.radius * (0.35 + 0.25 * rng.next_f64());
                    let radius = s.radius * (0.55 + 0.15 * rng.next_f64());
                    out.push(Sphere {
                        center: s.center + DVec3::Z * (side * shift),
                        radius,
                        ..*s
                    });
                }
            }
            continue;
        }
        let root = skeleton.nodes[branch.nodes[0]].pos;
        let trunk = trunks.iter().filter(|t| t.len() >= 2).min_by(|a, b| {
            let d = |t: &Vec<DVec2>| nearest_on(t, root).0.distance_squared(root);
            d(a).total_cmp(&d(b))
        });
        let Some(trunk) = trunk.filter(|_| branch.kind == BranchKind::Terminal) else {
            out.extend(members);
            continue;
        };
        members.sort_by(|a, b| a.along.total_cmp(&b.along));
        let at = arclength_of(trunk, root);
        let (pivot, _) = point_at(trunk, at);
        let radius_at = |q: DVec2| p.distance(q).max(1e-9);
        let r0 = radius_at(pivot);
        // The trunk's direction around the pivot, over a stretch as long as its radius (the
        // chordal axis zig-zags from node to node).
        let (behind, _) = point_at(trunk, at - r0);
        let (ahead, _) = point_at(trunk, at + r0);
        let axis = (ahead - behind)
            .try_normalize()
            .unwrap_or(DVec2::X)
            .extend(0.0);
        // A copy at `angle` out of the plane about the trunk, its root slid by `slide` along
        // it and scaled to the trunk's radius there.
        let place = |angle: f64, slide: f64| -> Vec<Sphere> {
            let (to, _) = point_at(trunk, at + slide);
            let scale = (radius_at(to) / r0).clamp(0.5, 1.5);
            let q = DQuat::from_axis_angle(axis, angle);
            members
                .iter()
                .map(|s| Sphere {
                    center: to.extend(0.0) + q * ((s.center - pivot.extend(0.0)) * scale),
                    radius: s.radius * scale,
                    max_radius: s.max_radius * scale,
                    ..*s
                })
                .collect()
        };
        // The original: a small jitter out of the plane.
        let jitter = (rng.next_f64() - 0.5) * 0.5;
        out.extend(fit_branch(outline, place(jitter, 0.0)));
        // Copies in the other slots of `copies + 1` even slots over the half-turn (the one
        // nearest the drawing plane is the original's), with seeded variation.
        let m = budget_copies + 1;
        let slot = |j: usize| {
            -std::f64::consts::FRAC_PI_2 + std::f64::consts::PI * (j as f64 + 0.5) / m as f64
        };
        // The middle slot; with an even count, one of the two middle ones, seeded.
        let original = if m % 2 == 1 || rng.next_f64() < 0.5 {
            m / 2
        } else {
            m / 2 - 1
        };
        for j in (0..m).filter(|&j| j != original) {
            let vary = (rng.next_f64() - 0.5) * (std::f64::consts::PI / m as f64) * 0.4;
            let slide = (rng.next_f64() * 2.0 - 1.0) * COPY_SLIDE * members[0].radius;
            out.extend(fit_branch(outline, place(slot(j) + vary, slide)));
        }
    }
    thicken(outline, &mut out);
    out
}

fn thicken(outline: &Outline, spheres: &mut Vec<Sphere>) {
    let (lo, hi) = outline
        .points
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), q| (a.min(q.y), b.max(q.y)));
    let target = 0.5 * (hi - lo);
    let depth = |s: &[Sphere]| {
        let (a, b) = s.iter().fold((f64::MAX, f64::MIN), |(a, b), q| {
            (a.min(q.center.z - q.radius), b.max(q.center.z + q.radius))
        });
        b - a
    };
    if spheres.is_empty() || depth(spheres) >= target || spheres.len() * 3 > MAX_SPHERES {
        return;
    }
    let flat: Vec<Sphere> = spheres
        .iter()
        .filter(|s| s.center.z.abs() < 1e-9)
        .copied()
        .collect();
    for s in flat {
        let dz = (0.9 * s.radius).min((target * 0.5 - s.radius).max(0.0));
        if dz > 0.0 {
            for sign in [-1.0, 1.0] {
                let mut c = s;
                c.center.z += sign * dz;
                spheres.push(c);
            }
        }
    }
}

/// Fits a branch's spheres (root first) so each one's disc, projected to the drawing plane,
/// lies inside the outline; the branch ends at the first sphere that cannot fit or no longer
/// overlaps the previous one, so it stays attached to the body.
fn fit_branch(outline: &Outline, branch: Vec<Sphere>) -> Vec<Sphere> {
    let p = &outline.boundary;
    let mut kept: Vec<Sphere> = Vec::with_capacity(branch.len());
    for mut s in branch {
        let q = s.center.truncate();
        if !contains(p, q) {
            break;
        }
        let room = p.distance(q);
        s.radius = s.radius.min(room);
        s.max_radius = s.max_radius.min(room);
        if s.radius <= 1e-9
            || kept
                .last()
                .is_some_and(|prev| prev.center.distance(s.center) >= prev.radius + s.radius)
        {
            break;
        }
        kept.push(s);
    }
    kept
}
