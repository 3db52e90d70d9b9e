//! The blended implicit surface as a triangle mesh, by marching cubes with a table built from
//! the cube's faces: on each face the crossings are joined so that inside corners stay apart
//! (the same choice the neighbouring cube makes on that face, so ambiguous faces never open a
//! crack), the joined segments close into loops around each cube, and each loop is a fan of
//! triangles facing away from the inside. Corners are shared through the grid edge they lie
//! on (two rolling layers of edge indices, no hashing), and the grid is padded with outside
//! values, so the mesh is closed, every edge has exactly two triangles, and every triangle
//! faces outward.

use std::sync::OnceLock;

use glam::{IVec3, UVec3, Vec3};

/// A triangle mesh: positions, per-vertex normals (outward), triangles (counter-clockwise seen
/// from outside).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit outward normals per vertex.
    pub normals: Vec<Vec3>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// The enclosed volume (divergence theorem; positive for an outward-facing closed mesh).
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }
}

/// Cube edges as corner pairs, lower corner first (corner bits: x 1, y 2, z 4).
pub const EDGES: [(u8, u8); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

fn corner_offset(c: u8) -> IVec3 {
    IVec3::new((c & 1) as i32, ((c >> 1) & 1) as i32, (c >> 2) as i32)
}

fn edge_of(a: u8, b: u8) -> u8 {
    EDGES
        .iter()
        .position(|&(p, q)| (p, q) == (a, b) || (q, p) == (a, b))
        .expect("adjacent corners") as u8
}

/// The cube's faces, each as its corners in counter-clockwise order seen from outside.
fn faces() -> [[u8; 4]; 6] {
    let raw: [[u8; 4]; 6] = [
        [0, 2, 6, 4],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 5, 7, 6],
    ];
    raw.map(|f| {
        let p = f.map(|c| corner_offset(c).as_vec3());
        let normal = (p[1] - p[0]).cross(p[3] - p[0]);
        let outward = (p[0] + p[2]) * 0.5 - Vec3::splat(0.5);
        if normal.dot(outward) > 0.0 {
            f
        } else {
            [f[0], f[3], f[2], f[1]]
        }
    })
}

/// The surface inside one cube configuration: its loops (edge ids) and triangles, whose ids
/// are edges (0–11) or the centre of loop `id − 12`.
#[derive(Clone, Debug, Default)]
pub struct Case {
    /// The loops of crossing edges.
    pub loops: Vec<Vec<u8>>,
    /// Triangles facing away from the inside.
    pub triangles: Vec<[u8; 3]>,
}

/// Whether two cube edges lie on a common face.
fn share_face(faces: &[[u8; 4]; 6], a: u8, b: u8) -> bool {
    let on = |f: &[u8; 4], e: u8| {
        let (p, q) = EDGES[e as usize];
        f.contains(&p) && f.contains(&q)
    };
    faces.iter().any(|f| on(f, a) && on(f, b))
}

/// Triangulates a loop (turning counter-clockwise about the inside) so that no triangle side
/// other than the loop's own joins two points of one cube face (the cube across that face may
/// join them too, and the edge would then have four triangles): a fan from an apex whose
/// diagonals all cross the cube's inside, else a fan around the loop's centre.
fn triangulate(faces: &[[u8; 4]; 6], lp: &[u8], centre: u8) -> Vec<[u8; 3]> {
    let n = lp.len();
    if n == 3 {
        return vec![[lp[0], lp[2], lp[1]]];
    }
    let apex = (0..n).find(|&k| (2..n - 1).all(|j| !share_face(faces, lp[k], lp[(k + j) % n])));
    match apex {
        Some(k) => (1..n - 1)
            .map(|j| [lp[k], lp[(k + j + 1) % n], lp[(k + j) % n]])
            .collect(),
        None => (0..n).map(|j| [centre, lp[(j + 1) % n], lp[j]]).collect(),
    }
}

/// The surface of each of the 256 inside-corner masks.
pub fn table() -> &'static [Case] {
    static TABLE: OnceLock<Vec<Case>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let faces = faces();
        (0..256u32)
            .map(|case| {
                let inside = |c: u8| (case >> c) & 1 == 1;
                // Directed segments on each face, from the crossing where the boundary walk
                // leaves the inside to the one where it entered that run of inside corners:
                // the inside lies on the segment's left, seen from outside the cube.
                let mut segments: Vec<(u8, u8)> = Vec::new();
                for f in faces {
                    for k in 0..4 {
                        if inside(f[k]) && !inside(f[(k + 1) % 4]) {
                            let mut a = k;
                            while inside(f[(a + 3) % 4]) {
                                a = (a + 3) % 4;
                            }
                            let exit = edge_of(f[k], f[(k + 1) % 4]);
                            let entry = edge_of(f[(a + 3) % 4], f[a]);
                            segments.push((exit, entry));
                        }
                    }
                }
                let mut case = Case::default();
                while let Some((start, mut next)) = segments.pop() {
                    let mut lp = vec![start];
                    while next != start {
                        lp.push(next);
                        let i = segments
                            .iter()
                            .position(|&(a, _)| a == next)
                            .expect("the segments close into loops");
                        next = segments.swap_remove(i).1;
                    }
                    let centre = 12 + case.loops.len() as u8;
                    case.triangles.extend(triangulate(&faces, &lp, centre));
                    case.loops.push(lp);
                }
                case
            })
            .collect()
    })
}

/// Meshes the surface `value = iso` of `values` (on `dims` texels, x fastest) whose texel
/// `(x, y, z)` is at `min + (x, y, z)·h`; outside the grid the value is below `iso`.
///
/// The layers of cubes are cut into one run per core, meshed at once and joined: a run's
/// vertices on its first plane are the ones the run before made on its last, so the joined
/// mesh is the one a single pass makes (the same vertices in the same order, the same
/// triangles).
pub fn mesh(dims: UVec3, min: Vec3, h: f32, values: &[f32], iso: f32) -> Mesh {
    // Runs of at least 16 layers: a smaller grid is not worth a thread.
    let runs = crate::limits::cores().min(dims.z as usize / 16).max(1);
    mesh_in_runs(dims, min, h, values, iso, runs)
}

/// [`mesh`] with its layers cut into `runs` runs.
fn mesh_in_runs(dims: UVec3, min: Vec3, h: f32, values: &[f32], iso: f32, runs: usize) -> Mesh {
    let layers = dims.z as i32 + 1;
    let threads = (runs as i32).clamp(1, layers);
    let per = (layers + threads - 1) / threads;
    let ranges: Vec<std::ops::Range<i32>> = (0..threads)
        .map(|t| (-1 + t * per)..(-1 + (t + 1) * per).min(dims.z as i32))
        .filter(|r| !r.is_empty())
        .collect();
    let run = |z: std::ops::Range<i32>| mesh_layers(dims, min, h, values, iso, z);
    let runs: Vec<Run> = if ranges.len() == 1 {
        ranges.into_iter().map(run).collect()
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = ranges
                .iter()
                .map(|z| scope.spawn(move || run(z.clone())))
                .collect();
            handles
                .into_iter()
                .zip(&ranges)
                // A run whose thread failed is done again here.
                .map(|(h, z)| h.join().unwrap_or_else(|_| run(z.clone())))
                .collect()
        })
    };
    let mut mesh = Mesh::default();
    // The last plane's vertex ids (of the mesh so far) of the run before.
    let mut last: Vec<u32> = Vec::new();
    for run in runs {
        // A vertex of this run's first plane is the run before's; the others follow on.
        let mut ids = vec![u32::MAX; run.positions.len()];
        for (slot, &own) in run.first.iter().enumerate() {
            if let (Some(id), Some(&earlier)) = (ids.get_mut(own as usize), last.get(slot))
                && earlier != u32::MAX
            {
                *id = earlier;
            }
        }
        for (id, p) in ids.iter_mut().zip(&run.positions) {
            if *id == u32::MAX {
                *id = mesh.positions.len() as u32;
                mesh.positions.push(*p);
            }
        }
        mesh.triangles
            .extend(run.triangles.iter().map(|t| t.map(|v| ids[v as usize])));
        last = run
            .last
            .iter()
            .map(|&v| ids.get(v as usize).copied().unwrap_or(u32::MAX))
            .collect();
    }
    // Area-weighted normals.
    mesh.normals = vec![Vec3::ZERO; mesh.positions.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            mesh.normals[i as usize] += n;
        }
    }
    for n in &mut mesh.normals {
        *n = n.normalize_or(Vec3::Y);
    }
    mesh
}

/// The surface in a run of cube layers ([`mesh_layers`]): its vertices and triangles (ids of
/// its own vertices), and the vertex ids of the x and y grid edges of its first and last
/// planes (`u32::MAX` where none).
struct Run {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    first: Vec<u32>,
    last: Vec<u32>,
}

/// Meshes the cube layers `zs` (layer `z` lies between texel planes `z` and `z + 1`; `-1` and
/// `dims.z − 1` touch the padding).
fn mesh_layers(
    dims: UVec3,
    min: Vec3,
    h: f32,
    values: &[f32],
    iso: f32,
    layers: std::ops::Range<i32>,
) -> Run {
    let table = table();
    let d = dims.as_ivec3();
    let outside = iso - 1.0;
    // Two padded planes of values (z and z + 1) with a ring of outside values, and whether
    // each is inside, so the loop over cubes reads them without bounds tests.
    let w = (d.x + 2) as usize;
    let layer = w * (d.y + 2) as usize;
    let fill = |z: i32, plane: &mut Vec<f32>, inside: &mut Vec<u8>| {
        plane.fill(outside);
        if (0..d.z).contains(&z) {
            let (nx, ny) = (d.x as usize, d.y as usize);
            for y in 0..ny {
                let from = (z as usize * ny + y) * nx;
                let to = (y + 1) * w + 1;
                plane[to..to + nx].copy_from_slice(&values[from..from + nx]);
            }
        }
        for (b, &v) in inside.iter_mut().zip(plane.iter()) {
            *b = (v >= iso) as u8;
        }
    };
    let mut planes = [vec![outside; layer], vec![outside; layer]];
    let mut inside = [vec![0u8; layer], vec![0u8; layer]];
    // Vertex ids of grid edges by their lower point, in rolling layers: x and y edges of the
    // cube layer's bottom (0) and top (1) planes, z edges between them.
    let mut xy = [vec![u32::MAX; 2 * layer], vec![u32::MAX; 2 * layer]];
    let mut zs = vec![u32::MAX; layer];
    let mut mesh = Mesh::default();
    let mut first = Vec::new();
    for z in layers.clone() {
        xy[1].fill(u32::MAX);
        zs.fill(u32::MAX);
        {
            let [p0, p1] = &mut planes;
            let [i0, i1] = &mut inside;
            if z == layers.start {
                fill(z, p0, i0);
            } else {
                std::mem::swap(p0, p1);
                std::mem::swap(i0, i1);
            }
            fill(z + 1, p1, i1);
        }
        let (in0, in1) = (&inside[0], &inside[1]);
        // Eight bytes of insideness from `at` (0 past the end).
        let word = |v: &[u8], at: usize| {
            v.get(at..at + 8)
                .map_or(0, |b| u64::from_le_bytes(b.try_into().unwrap_or_default()))
        };
        for y in -1..d.y {
            let row = (y + 1) as usize * w;
            let mut x = -1;
            while x < d.x {
                let i = row + (x + 1) as usize;
                // Eight cubes at once whose corners are all outside or all inside: no surface.
                if x + 8 <= d.x && i + w + 9 <= layer {
                    let words =
                        [i, i + 1, i + w, i + w + 1].map(|at| (word(in0, at), word(in1, at)));
                    let any = words.iter().fold(0, |acc, (a, b)| acc | a | b);
                    let all = words.iter().fold(u64::MAX, |acc, (a, b)| acc & a & b);
                    if any == 0 || all == 0x0101_0101_0101_0101 {
                        x += 8;
                        continue;
                    }
                }
                let cube_x = x;
                x += 1;
                let case = (in0[i]
                    | in0[i + 1] << 1
                    | in0[i + w] << 2
                    | in0[i + w + 1] << 3
                    | in1[i] << 4
                    | in1[i + 1] << 5
                    | in1[i + w] << 6
                    | in1[i + w + 1] << 7) as usize;
                if case == 0 || case == 255 {
                    continue;
                }
                let base = IVec3::new(cube_x, y, z);
                let v: [f32; 8] =
                    std::array::from_fn(|c| planes[c >> 2][i + (c & 1) + ((c >> 1) & 1) * w]);
                let case = &table[case];
                // This cube's crossing edges: their shared vertices, made by whichever cube
                // meets them first.
                let mut ids = [u32::MAX; 12];
                for &e in case.loops.iter().flatten() {
                    let (a, b) = EDGES[e as usize];
                    let lo = base + corner_offset(a);
                    let at = (lo.y + 1) as usize * w + (lo.x + 1) as usize;
                    let slot = match b - a {
                        1 => &mut xy[corner_offset(a).z as usize][2 * at],
                        2 => &mut xy[corner_offset(a).z as usize][2 * at + 1],
                        _ => &mut zs[at],
                    };
                    if *slot == u32::MAX {
                        let (va, vb) = (v[a as usize], v[b as usize]);
                        let s = ((iso - va) / (vb - va)).clamp(0.0, 1.0);
                        let pa = min + lo.as_vec3() * h;
                        let pb = min + (base + corner_offset(b)).as_vec3() * h;
                        mesh.positions.push(pa + (pb - pa) * s);
                        *slot = (mesh.positions.len() - 1) as u32;
                    }
                    ids[e as usize] = *slot;
                }
                // Loop centres, where a loop needs one: the mean of its points.
                let mut centres = [u32::MAX; 4];
                for t in &case.triangles {
                    let tri = t.map(|e| {
                        if e < 12 {
                            return ids[e as usize];
                        }
                        let k = (e - 12) as usize;
                        if centres[k] == u32::MAX {
                            let lp = &case.loops[k];
                            let sum: Vec3 = lp
                                .iter()
                                .map(|&e| mesh.positions[ids[e as usize] as usize])
                                .sum();
                            mesh.positions.push(sum / lp.len() as f32);
                            centres[k] = (mesh.positions.len() - 1) as u32;
                        }
                        centres[k]
                    });
                    mesh.triangles.push(tri);
                }
            }
        }
        if z == layers.start {
            first = xy[0].clone();
        }
        xy.swap(0, 1);
    }
    let [last, _] = xy;
    Run {
        positions: mesh.positions,
        triangles: mesh.triangles,
        first,
        last,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use std::collections::HashMap;

    /// Every undirected edge is used by exactly two triangles, once in each direction.
    pub fn assert_closed_and_oriented(mesh: &Mesh) {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &mesh.triangles {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &directed {
            assert_eq!(n, 1, "edge {a}→{b} used {n} times in one direction");
            assert_eq!(
                directed.get(&(b, a)),
                Some(&1),
                "edge {a}→{b} has no opposite"
            );
        }
    }

    fn sphere_grid(n: u32, r: f32, h: f32) -> (UVec3, Vec3, Vec<f32>) {
        let dims = UVec3::splat(n);
        let min = Vec3::splat(-(n as f32 - 1.0) * 0.5 * h);
        let mut values = Vec::new();
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let p = min + UVec3::new(x, y, z).as_vec3() * h;
                    values.push(r - p.length());
                }
            }
        }
        (dims, min, values)
    }

    #[test]
    fn a_sphere_is_closed_outward_and_holds_its_volume() {
        let (dims, min, values) = sphere_grid(24, 1.0, 0.1);
        let m = mesh(dims, min, 0.1, &values, 0.0);
        assert_closed_and_oriented(&m);
        let exact = 4.0 / 3.0 * std::f64::consts::PI;
        assert!(
            (m.volume() - exact).abs() < 0.02 * exact,
            "{} vs {exact}",
            m.volume()
        );
        // Normals point away from the centre.
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(p.normalize().dot(*n) > 0.9);
        }
    }

    /// Runs meshed at once and joined give the single pass's mesh, vertex for vertex, on a
    /// lumpy field with wide empty and full stretches (the eight-cube skip) and noise.
    #[test]
    fn runs_joined_give_the_single_pass_mesh() {
        let dims = UVec3::new(37, 21, 45);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut u = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % 10_000) as f32 / 10_000.0
        };
        let blobs: Vec<(Vec3, f32)> = (0..12)
            .map(|_| {
                (
                    Vec3::new(u() * 36.0, u() * 20.0, u() * 44.0),
                    3.0 + u() * 6.0,
                )
            })
            .collect();
        let mut values = Vec::new();
        for z in 0..dims.z {
            for y in 0..dims.y {
                for x in 0..dims.x {
                    let p = UVec3::new(x, y, z).as_vec3();
                    let near = blobs
                        .iter()
                        .map(|(c, r)| r - p.distance(*c))
                        .fold(f32::MIN, f32::max);
                    values.push(near + (u() - 0.5) * 0.8);
                }
            }
        }
        let one = mesh_in_runs(dims, Vec3::ZERO, 1.0, &values, 0.0, 1);
        assert!(one.triangles.len() > 1000, "{}", one.triangles.len());
        assert_closed_and_oriented(&one);
        for runs in [2, 3, 7, 46, 100] {
            let joined = mesh_in_runs(dims, Vec3::ZERO, 1.0, &values, 0.0, runs);
            assert!(joined == one, "{runs} runs differ from one");
        }
    }

    #[test]
    fn random_fields_with_every_ambiguous_face_give_closed_oriented_meshes() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut cases = [false; 256];
        for _ in 0..300 {
            let values: Vec<f32> = (0..216)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    (state % 1000) as f32 / 500.0 - 1.0
                })
                .collect();
            for z in 0..5 {
                for y in 0..5 {
                    for x in 0..5 {
                        let case = (0..8).fold(0, |m, c| {
                            let p = UVec3::new(x, y, z).as_ivec3() + corner_offset(c);
                            let v = values[((p.z * 6 + p.y) * 6 + p.x) as usize];
                            m | (((v >= 0.0) as usize) << c)
                        });
                        cases[case] = true;
                    }
                }
            }
            let m = mesh(UVec3::splat(6), Vec3::ZERO, 1.0, &values, 0.0);
            assert_closed_and_oriented(&m);
            assert!(m.volume() > 0.0);
        }
        assert!(
            cases.iter().filter(|&&c| c).count() > 250,
            "most of the 256 cases met"
        );
    }

    #[test]
    fn surfaces_cut_by_the_grid_edge_and_values_on_the_iso_level_stay_closed() {
        // A sphere larger than its grid (the padding closes it) with exact iso values at
        // grid points, and two blobs touching at one point.
        let (dims, min, mut values) = sphere_grid(12, 0.8, 0.1);
        for v in &mut values {
            *v = (*v * 10.0).round() / 10.0;
        }
        assert_closed_and_oriented(&mesh(dims, min, 0.1, &values, 0.0));
        let mut saddle = vec![-1.0f32; 27];
        saddle[0] = 1.0;
        saddle[26] = 1.0;
        saddle[13] = 0.0;
        assert_closed_and_oriented(&mesh(UVec3::splat(3), Vec3::ZERO, 1.0, &saddle, 0.0));
        // Checkerboard faces (marching cubes' ambiguous case).
        let checker: Vec<f32> = (0..64)
            .map(|i| {
                if (i ^ (i >> 2) ^ (i >> 4)) & 1 == 0 {
                    1.0
                } else {
                    -1.0
                }
            })
            .collect();
        assert_closed_and_oriented(&mesh(UVec3::splat(4), Vec3::ZERO, 1.0, &checker, 0.0));
    }
}
