//! The chordal axis transform (Prasad 1997) of a simple polygon, as Wither et al. §3.1 use it:
//! constrained Delaunay triangulation (spade), triangles classified by their internal edges
//! (terminal: 1, sleeve: 2, junction: 3), pruning of insignificant terminal branches by area,
//! the skeleton as polylines with maximal-ball radii, and the map from outline edges to
//! skeleton segments.

use glam::DVec2;
use spade::{ConstrainedDelaunayTriangulation, HasPosition, Point2, Triangulation};

use super::SketchError;
use super::outline::{Boundary, Outline, contains};

#[derive(Clone, Copy, Debug)]
struct Vertex {
    pos: Point2<f64>,
    index: usize,
}

impl HasPosition for Vertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// A triangle of the outline's constrained Delaunay triangulation (vertex indices into the outline).
#[derive(Clone, Debug, PartialEq)]
pub struct Triangle {
    /// Outline vertex indices, counter-clockwise.
    pub v: [usize; 3],
    /// Area.
    pub area: f64,
}

/// Kind of a triangle by its number of internal (non-outline) edges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriangleKind {
    /// The whole outline is one triangle.
    Isolated,
    /// One internal edge: the tip of a feature.
    Terminal,
    /// Two internal edges: along a limb.
    Sleeve,
    /// Three internal edges: where limbs meet.
    Junction,
}

/// A skeleton node: a point on the chordal axis with its maximal-ball radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node {
    /// Position in the outline's plane.
    pub pos: DVec2,
    /// Distance to the outline (radius of the largest disc centred here inside the outline).
    pub radius: f64,
}

/// Whether a branch ends freely or joins others at both ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BranchKind {
    /// Connected at one end only (a feature: points toward a curvature maximum).
    Terminal,
    /// Connected at both ends.
    Body,
}

/// A skeleton polyline between two nodes of degree ≠ 2.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    /// Node indices in order. For terminal branches the free end comes last.
    pub nodes: Vec<usize>,
    /// Terminal or body.
    pub kind: BranchKind,
}

/// The pruned chordal axis of an outline.
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    /// The triangulation of the outline's inside.
    pub triangles: Vec<Triangle>,
    /// Kind of each triangle before pruning.
    pub kinds: Vec<TriangleKind>,
    /// Nodes of the skeleton graph.
    pub nodes: Vec<Node>,
    /// Segments (node index pairs) of the skeleton graph, a tree.
    pub segments: Vec<[usize; 2]>,
    /// Polylines between branching points and free ends.
    pub branches: Vec<Branch>,
    /// For each outline edge `i` (vertex `i` to `i + 1`), the skeleton segment it maps to.
    pub edge_to_segment: Vec<usize>,
}

impl Skeleton {
    /// Free ends of the pruned skeleton (each is the tip of a terminal branch).
    pub fn terminal_count(&self) -> usize {
        self.degrees().iter().filter(|&&d| d == 1).count()
    }

    /// Branching points of the pruned skeleton.
    pub fn junction_count(&self) -> usize {
        self.degrees().iter().filter(|&&d| d >= 3).count()
    }

    fn degrees(&self) -> Vec<usize> {
        let mut deg = vec![0; self.nodes.len()];
        for s in &self.segments {
            deg[s[0]] += 1;
            deg[s[1]] += 1;
        }
        deg
    }
}

/// Key of an undirected edge.
fn key(a: usize, b: usize) -> (usize, usize) {
    (a.min(b), a.max(b))
}

/// Triangulates `outline` and computes its pruned chordal axis. A terminal branch is removed
/// when it adds less than `prune` × the outline's area (Wither et al. use 2%) beyond the
/// maximal discs of the body around the junction it hangs from (so a rectangle's corners go,
/// a star's arms stay).
pub fn chordal_axis(outline: &Outline, prune: f64) -> Result<Skeleton, SketchError> {
    let p = &outline.boundary;
    let triangles = triangulate(outline)?;
    let dual = Dual::new(&triangles, p.len());
    let kinds = dual
        .adj
        .iter()
        .map(|a| match a.len() {
            0 => TriangleKind::Isolated,
            1 => TriangleKind::Terminal,
            2 => TriangleKind::Sleeve,
            _ => TriangleKind::Junction,
        })
        .collect();
    let pruned = Pruned::new(&triangles, &dual, p, prune.max(0.0) * outline.area);
    let graph = Graph::new(&triangles, &dual, &pruned, p);
    let edge_to_segment = graph.map_outline_edges(&triangles, &pruned, p);
    let branches = branches(&graph.nodes, &graph.segments);
    Ok(Skeleton {
        triangles,
        kinds,
        nodes: graph.nodes,
        segments: graph.segments,
        branches,
        edge_to_segment,
    })
}

/// The constrained Delaunay triangles inside the outline (spade; conflicts are refused, never
/// a panic).
fn triangulate(outline: &Outline) -> Result<Vec<Triangle>, SketchError> {
    let p = &outline.boundary;
    let n = p.len();
    let vertices: Vec<Vertex> = p
        .iter()
        .enumerate()
        .map(|(index, q)| Vertex {
            pos: Point2::new(q.x, q.y),
            index,
        })
        .collect();
    let edges: Vec<[usize; 2]> = (0..n).map(|i| [i, (i + 1) % n]).collect();
    let mut conflicts = 0usize;
    let cdt =
        ConstrainedDelaunayTriangulation::<Vertex>::try_bulk_load_cdt(vertices, edges, |_| {
            conflicts += 1
        })
        .map_err(|e| SketchError::Triangulation(e.to_string()))?;
    if conflicts > 0 || cdt.num_vertices() != n {
        return Err(SketchError::Triangulation(format!(
            "{conflicts} crossing edges, {} of {n} vertices",
            cdt.num_vertices()
        )));
    }

    let mut triangles = Vec::new();
    for face in cdt.inner_faces() {
        let v = face.vertices().map(|h| h.data().index);
        let [a, b, c] = v.map(|i| p[i]);
        let area = 0.5 * (b - a).perp_dot(c - a);
        // Slivers of collinear outline points carry no inside (and their long edge lies on the outline).
        if area.abs() <= outline.area * 1e-9 || !contains(p, (a + b + c) / 3.0) {
            continue;
        }
        let v = if area > 0.0 { v } else { [v[0], v[2], v[1]] };
        triangles.push(Triangle {
            v,
            area: area.abs(),
        });
    }
    if triangles.is_empty() {
        return Err(SketchError::NoArea);
    }
    Ok(triangles)
}

/// The dual tree: triangles adjacent across internal (non-outline) edges.
struct Dual {
    /// Internal edge (sorted vertex pair) → the triangles sharing it.
    by_edge: std::collections::BTreeMap<(usize, usize), Vec<usize>>,
    /// Per triangle: (neighbour, shared edge).
    adj: Vec<Vec<(usize, (usize, usize))>>,
}

impl Dual {
    fn new(triangles: &[Triangle], n: usize) -> Self {
        let is_boundary = |a: usize, b: usize| (a + 1) % n == b || (b + 1) % n == a;
        let mut by_edge: std::collections::BTreeMap<(usize, usize), Vec<usize>> =
            Default::default();
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri.v[k], tri.v[(k + 1) % 3]);
                if !is_boundary(a, b) {
                    by_edge.entry(key(a, b)).or_default().push(t);
                }
            }
        }
        let mut adj: Vec<Vec<(usize, (usize, usize))>> = vec![Vec::new(); triangles.len()];
        for (&e, ts) in &by_edge {
            if let [s, t] = ts[..] {
                adj[s].push((t, e));
                adj[t].push((s, e));
            }
        }
        Self { by_edge, adj }
    }
}

/// Pruning: repeatedly removes the least significant terminal branches below `threshold`.
struct Pruned {
    /// Triangles still in the skeleton.
    alive: Vec<bool>,
    /// Pruned triangle → the triangle that absorbed it (itself when alive).
    owner: Vec<usize>,
    /// Triangles that absorbed pruned branches.
    absorbed: Vec<bool>,
    /// Largest discs found per triangle.
    discs: std::collections::BTreeMap<usize, (DVec2, f64)>,
}

impl Pruned {
    fn new(triangles: &[Triangle], dual: &Dual, p: &Boundary, threshold: f64) -> Self {
        let mut alive = vec![true; triangles.len()];
        let mut owner: Vec<usize> = (0..triangles.len()).collect(); // pruned triangle → absorbing triangle
        let mut disc_cache: std::collections::BTreeMap<usize, (DVec2, f64)> = Default::default();
        let mut absorbed = vec![false; triangles.len()];
        // A branch's significance changes only when its chain or junction does.
        let mut significance_cache: std::collections::BTreeMap<(usize, usize, usize), f64> =
            Default::default();
        loop {
            let degree =
                |t: usize, alive: &[bool]| dual.adj[t].iter().filter(|(s, _)| alive[*s]).count();
            if !(0..triangles.len()).any(|t| alive[t] && degree(t, &alive) >= 3) {
                break;
            }
            // Candidates below the threshold; per pass, each junction loses at most its smallest
            // branch (pruning one turns the junction into a sleeve and lengthens its other chains).
            let mut candidates: Vec<(f64, Vec<usize>, usize)> = Vec::new();
            for start in 0..triangles.len() {
                if !alive[start] || degree(start, &alive) != 1 {
                    continue;
                }
                let (mut chain, mut prev, mut cur) = (vec![start], usize::MAX, start);
                let end = loop {
                    let next = dual.adj[cur]
                        .iter()
                        .map(|(s, _)| *s)
                        .find(|&s| alive[s] && s != prev);
                    let Some(next) = next else { break None };
                    if degree(next, &alive) >= 3 {
                        break Some(next);
                    }
                    chain.push(next);
                    prev = cur;
                    cur = next;
                };
                // Significance: the branch's area outside the junction's maximal disc, i.e. what
                // the feature adds to the shape beyond the body it hangs from.
                let significance = end.map(|j| {
                    let key = (start, j, chain.len());
                    if let Some(&v) = significance_cache.get(&key) {
                        return v;
                    }
                    let v = significance_of(
                        j,
                        &chain,
                        &dual.adj,
                        &alive,
                        triangles,
                        p,
                        &mut disc_cache,
                    );
                    significance_cache.insert(key, v);
                    v
                });
                if let (Some(junction), Some(area)) = (end, significance)
                    && area < threshold
                {
                    candidates.push((area, chain, junction));
                }
            }
            if candidates.is_empty() {
                break;
            }
            candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
            let mut touched = std::collections::BTreeSet::new();
            for (_, chain, junction) in candidates {
                // A junction of degree 3 that already lost a branch this pass is now a sleeve.
                if !touched.insert(junction) {
                    continue;
                }
                for t in chain {
                    alive[t] = false;
                    owner[t] = junction;
                }
                absorbed[junction] = true;
            }
        }
        Self {
            alive,
            owner,
            absorbed,
            discs: disc_cache,
        }
    }

    /// The live triangle a (possibly pruned) triangle belongs to.
    fn resolve(&self, mut t: usize) -> usize {
        while self.owner[t] != t {
            t = self.owner[t];
        }
        t
    }
}

/// The skeleton graph: midpoints of live internal edges, discs of live junctions, tips of
/// terminals.
struct Graph {
    nodes: Vec<Node>,
    segments: Vec<[usize; 2]>,
    /// Segments made by each triangle.
    segments_of_triangle: Vec<Vec<usize>>,
}

impl Graph {
    fn new(triangles: &[Triangle], dual: &Dual, pruned: &Pruned, p: &Boundary) -> Self {
        let mut nodes: Vec<Node> = Vec::new();
        let mut node_of_edge: std::collections::BTreeMap<(usize, usize), usize> =
            Default::default();
        let node = |nodes: &mut Vec<Node>, pos: DVec2| {
            nodes.push(Node {
                pos,
                radius: p.distance(pos),
            });
            nodes.len() - 1
        };
        for (&e, ts) in &dual.by_edge {
            if ts.len() == 2 && pruned.alive[ts[0]] && pruned.alive[ts[1]] {
                let id = node(&mut nodes, (p[e.0] + p[e.1]) * 0.5);
                node_of_edge.insert(e, id);
            }
        }
        let mut segments = Vec::new();
        let mut segments_of_triangle: Vec<Vec<usize>> = vec![Vec::new(); triangles.len()];
        // Visit triangles in a fixed order so the result does not depend on hash order.
        let live_edges_of = |t: usize| -> Vec<usize> {
            let mut v: Vec<((usize, usize), usize)> = dual.adj[t]
                .iter()
                .filter(|(s, _)| pruned.alive[*s])
                .map(|(_, e)| (*e, node_of_edge[e]))
                .collect();
            v.sort();
            v.into_iter().map(|(_, id)| id).collect()
        };
        for t in 0..triangles.len() {
            if !pruned.alive[t] {
                continue;
            }
            let tri = &triangles[t];
            let [a, b, c] = tri.v.map(|i| p[i]);
            let mids = live_edges_of(t);
            let mut add = |segments: &mut Vec<[usize; 2]>, s: [usize; 2]| {
                segments.push(s);
                segments_of_triangle[t].push(segments.len() - 1);
            };
            match mids.len() {
                0 => {
                    // A lone triangle: its incentre is the skeleton.
                    let (la, lb, lc) = (b.distance(c), c.distance(a), a.distance(b));
                    let centre = (a * la + b * lb + c * lc) / (la + lb + lc);
                    let id = node(&mut nodes, centre);
                    add(&mut segments, [id, id]);
                }
                1 => {
                    // Terminal: from the chord's midpoint halfway toward the opposite vertex.
                    let m = nodes[mids[0]].pos;
                    let apex = tri
                        .v
                        .iter()
                        .map(|&i| p[i])
                        .max_by(|x, y| x.distance_squared(m).total_cmp(&y.distance_squared(m)))
                        .unwrap_or(a);
                    let tip = node(&mut nodes, m.lerp(apex, 0.5));
                    add(&mut segments, [mids[0], tip]);
                }
                2 if !pruned.absorbed[t] => add(&mut segments, [mids[0], mids[1]]),
                _ => {
                    // Junctions (and former junctions whose small branches were pruned) pass through
                    // their largest inscribed disc, which covers what the pruned branches held.
                    let refined = pruned
                        .discs
                        .get(&t)
                        .copied()
                        .unwrap_or_else(|| largest_disc(tri, p))
                        .0;
                    // Only where the way from each chord to it stays well inside the outline.
                    let r_refined = p.distance(refined);
                    // Samples at least `floor` from the outline and closer together than `floor`
                    // cannot have the outline between them, so the whole way stays inside.
                    let inside = |q: DVec2| {
                        let floor = 0.5 * p.distance(q).min(r_refined);
                        floor > q.distance(refined) / 8.0
                            && (1..8).all(|k| p.distance(q.lerp(refined, k as f64 / 8.0)) >= floor)
                    };
                    // Inside the (convex) triangle the way to each chord is inside it: no check needed.
                    let in_triangle = {
                        let o = |u: DVec2, v: DVec2| (v - u).perp_dot(refined - u) >= 0.0;
                        o(a, b) && o(b, c) && o(c, a)
                    };
                    let centre = if in_triangle || mids.iter().all(|&m| inside(nodes[m].pos)) {
                        refined
                    } else {
                        sampled_disc(tri, p, true, 5).0
                    };
                    let centre = node(&mut nodes, centre);
                    for &m in &mids {
                        add(&mut segments, [centre, m]);
                    }
                }
            }
        }
        segments.retain(|s| s[0] != s[1] || nodes.len() == 1);
        Self {
            nodes,
            segments,
            segments_of_triangle,
        }
    }

    /// For each outline edge, the nearest segment of the (absorbing) triangle it borders.
    fn map_outline_edges(
        &self,
        triangles: &[Triangle],
        pruned: &Pruned,
        p: &Boundary,
    ) -> Vec<usize> {
        let n = p.len();
        let mut triangle_of_edge = vec![usize::MAX; n];
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri.v[k], tri.v[(k + 1) % 3]);
                if (a + 1) % n == b {
                    triangle_of_edge[a] = t;
                }
            }
        }
        let (nodes, segments, segments_of_triangle) =
            (&self.nodes, &self.segments, &self.segments_of_triangle);
        (0..n)
            .map(|i| {
                let mid = (p[i] + p[(i + 1) % n]) * 0.5;
                let t = triangle_of_edge[i];
                let candidates: Vec<usize> =
                    if t != usize::MAX && !segments_of_triangle[pruned.resolve(t)].is_empty() {
                        segments_of_triangle[pruned.resolve(t)].clone()
                    } else {
                        (0..segments.len()).collect()
                    };
                candidates
                    .into_iter()
                    .min_by(|&x, &y| {
                        seg_dist(mid, nodes, segments[x]).total_cmp(&seg_dist(
                            mid,
                            nodes,
                            segments[y],
                        ))
                    })
                    .unwrap_or(0)
            })
            .collect()
    }
}

/// What a terminal branch (`chain`, hanging from junction triangle `junction`) adds to the
/// shape: its triangles' area outside the maximal discs of the live body within two steps of
/// the junction.
fn significance_of(
    junction: usize,
    chain: &[usize],
    adj: &[Vec<(usize, (usize, usize))>],
    alive: &[bool],
    triangles: &[Triangle],
    p: &Boundary,
    disc_cache: &mut std::collections::BTreeMap<usize, (DVec2, f64)>,
) -> f64 {
    let mut near = vec![junction];
    let mut frontier = vec![junction];
    for _ in 0..2 {
        let mut next = Vec::new();
        for &u in &frontier {
            for &(v, _) in &adj[u] {
                if alive[v] && !chain.contains(&v) && !near.contains(&v) {
                    near.push(v);
                    next.push(v);
                }
            }
        }
        frontier = next;
    }
    let discs: Vec<(DVec2, f64)> = near
        .iter()
        .map(|&t| {
            *disc_cache
                .entry(t)
                .or_insert_with(|| largest_disc(&triangles[t], p))
        })
        .collect();
    chain
        .iter()
        .map(|&t| triangles[t].area * outside_fraction(&triangles[t], p, &discs))
        .sum()
}

/// The largest disc centred at one of a fixed set of samples of triangle `t` (strictly inside
/// it when `interior`, so segments from it to the triangle's edges stay in the triangle).
fn sampled_disc(t: &Triangle, p: &Boundary, interior: bool, steps: usize) -> (DVec2, f64) {
    let [a, b, c] = t.v.map(|i| p[i]);
    let mut best = ((a + b + c) / 3.0, p.distance((a + b + c) / 3.0));
    for i in 0..=steps {
        for j in 0..=steps - i {
            if interior && (i == 0 || j == 0 || i + j == steps) {
                continue;
            }
            let q = a + (b - a) * (i as f64 / steps as f64) + (c - a) * (j as f64 / steps as f64);
            let r = p.distance(q);
            if r > best.1 {
                best = (q, r);
            }
        }
    }
    best
}

/// The largest disc inside the outline centred near triangle `t`: the best of its circumcentre
/// (a Voronoi vertex of the outline's samples, so close to the medial axis), its centroid and
/// its edge midpoints.
fn largest_disc(t: &Triangle, p: &Boundary) -> (DVec2, f64) {
    let [a, b, c] = t.v.map(|i| p[i]);
    let mut candidates = vec![
        (a + b + c) / 3.0,
        (a + b) * 0.5,
        (b + c) * 0.5,
        (c + a) * 0.5,
    ];
    let d = 2.0 * (a.x * (b.y - c.y) + b.x * (c.y - a.y) + c.x * (a.y - b.y));
    if d.abs() > 1e-300 {
        let (a2, b2, c2) = (a.length_squared(), b.length_squared(), c.length_squared());
        let centre = DVec2::new(
            (a2 * (b.y - c.y) + b2 * (c.y - a.y) + c2 * (a.y - b.y)) / d,
            (a2 * (c.x - b.x) + b2 * (a.x - c.x) + c2 * (b.x - a.x)) / d,
        );
        if centre.is_finite() && contains(p, centre) {
            candidates.push(centre);
        }
    }
    candidates
        .into_iter()
        .map(|q| (q, p.distance(q)))
        .fold((a, 0.0), |best, x| if x.1 > best.1 { x } else { best })
}

/// Fraction of a triangle lying outside every disc, from a fixed set of samples.
fn outside_fraction(t: &Triangle, p: &Boundary, discs: &[(DVec2, f64)]) -> f64 {
    const N: usize = 6;
    let [a, b, c] = t.v.map(|i| p[i]);
    let (mut outside, mut total) = (0usize, 0usize);
    for i in 0..N {
        for j in 0..N - i {
            let (u, v) = (
                (i as f64 + 1.0 / 3.0) / N as f64,
                (j as f64 + 1.0 / 3.0) / N as f64,
            );
            let q = a + (b - a) * u + (c - a) * v;
            total += 1;
            outside += discs.iter().all(|(c, r)| q.distance_squared(*c) > r * r) as usize;
        }
    }
    outside as f64 / total.max(1) as f64
}

fn seg_dist(q: DVec2, nodes: &[Node], s: [usize; 2]) -> f64 {
    super::outline::segment_distance(q, nodes[s[0]].pos, nodes[s[1]].pos)
}

/// Splits the skeleton tree into polylines between nodes of degree ≠ 2.
fn branches(nodes: &[Node], segments: &[[usize; 2]]) -> Vec<Branch> {
    let mut adj: Vec<Vec<(usize, usize)>> = vec![Vec::new(); nodes.len()];
    for (i, s) in segments.iter().enumerate() {
        if s[0] != s[1] {
            adj[s[0]].push((s[1], i));
            adj[s[1]].push((s[0], i));
        }
    }
    let mut used = vec![false; segments.len()];
    let mut out = Vec::new();
    for start in 0..nodes.len() {
        if adj[start].len() == 2 {
            continue;
        }
        for &(first, seg) in &adj[start] {
            if used[seg] {
                continue;
            }
            used[seg] = true;
            let mut chain = vec![start, first];
            let (mut prev, mut cur) = (start, first);
            while adj[cur].len() == 2 {
                let &(next, s) = adj[cur]
                    .iter()
                    .find(|(m, _)| *m != prev)
                    .unwrap_or(&adj[cur][0]);
                if used[s] {
                    break;
                }
                used[s] = true;
                chain.push(next);
                prev = cur;
                cur = next;
            }
            let (a, b) = (
                adj[chain[0]].len(),
                adj[*chain.last().unwrap_or(&start)].len(),
            );
            let kind = if a == 1 || b == 1 {
                BranchKind::Terminal
            } else {
                BranchKind::Body
            };
            if a == 1 && b != 1 {
                chain.reverse(); // free end last
            }
            out.push(Branch { nodes: chain, kind });
        }
    }
    if out.is_empty() && !nodes.is_empty() {
        out.push(Branch {
            nodes: vec![0],
            kind: BranchKind::Terminal,
        });
    }
    out
}
