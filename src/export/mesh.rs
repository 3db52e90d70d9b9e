//! The blended implicit surface as a triangle mesh, by marching tetrahedra: every grid cube is
//! split into the six tetrahedra around its main diagonal (the same split in every cube, so
//! neighbouring cubes agree on their shared faces), and each tetrahedron the surface crosses
//! gives one or two triangles with their corners on its edges. Corners are shared through the
//! grid edge they lie on, and the grid is padded with outside values, so the mesh is closed,
//! every edge has exactly two triangles (no face ambiguity as in marching cubes' table), and
//! every triangle faces outward.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

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

/// A multiplicative hash for the edge keys (integers; SipHash is 3× slower here).
#[derive(Default)]
struct EdgeHasher(u64);

impl Hasher for EdgeHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, _: &[u8]) {
        unreachable!("only u64 keys")
    }
    fn write_u64(&mut self, k: u64) {
        self.0 = (k ^ (k >> 29)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    }
}

/// The six tetrahedra of a cube around its 0–7 diagonal (corner bits: x 1, y 2, z 4).
const TETS: [[u8; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// Meshes the surface `value = iso` of `values` (on `dims` texels, x fastest) whose texel
/// `(x, y, z)` is at `min + (x, y, z)·h`; outside the grid the value is below `iso`.
pub fn mesh(dims: UVec3, min: Vec3, h: f32, values: &[f32], iso: f32) -> Mesh {
    let d = dims.as_ivec3();
    let value = |p: IVec3| -> f32 {
        if p.cmplt(IVec3::ZERO).any() || p.cmpge(d).any() {
            f32::NEG_INFINITY
        } else {
            values[((p.z * d.y + p.y) * d.x + p.x) as usize]
        }
    };
    let inside = |v: f32| v >= iso;
    // Padded lattice index of a grid point (one layer of outside points on each side).
    let pd = d + IVec3::splat(2);
    let key = |p: IVec3, q: IVec3| -> u64 {
        let a = p + IVec3::ONE;
        let idx = ((a.z as i64 * pd.y as i64 + a.y as i64) * pd.x as i64 + a.x as i64) as u64;
        let t = q - p;
        idx * 8 + (t.x | (t.y << 1) | (t.z << 2)) as u64
    };
    let mut mesh = Mesh::default();
    let mut edges: HashMap<u64, u32, BuildHasherDefault<EdgeHasher>> = HashMap::default();
    let mut vertex = |mesh: &mut Mesh, p: IVec3, q: IVec3, vp: f32, vq: f32| -> u32 {
        let (p, q, vp, vq) = if (q - p).min_element() < 0 {
            (q, p, vq, vp)
        } else {
            (p, q, vp, vq)
        };
        *edges.entry(key(p, q)).or_insert_with(|| {
            // Outside the grid the value is −∞: the corner sits on the grid's boundary point.
            let t = if vp.is_finite() && vq.is_finite() {
                ((iso - vp) / (vq - vp)).clamp(0.0, 1.0)
            } else if vp.is_finite() {
                0.0
            } else {
                1.0
            };
            let a = min + p.as_vec3() * h;
            let b = min + q.as_vec3() * h;
            mesh.positions.push(a + (b - a) * t);
            mesh.normals.push(Vec3::ZERO);
            (mesh.positions.len() - 1) as u32
        })
    };
    for z in -1..d.z {
        for y in -1..d.y {
            for x in -1..d.x {
                let base = IVec3::new(x, y, z);
                let corner = |c: u8| {
                    base + IVec3::new((c & 1) as i32, ((c >> 1) & 1) as i32, (c >> 2) as i32)
                };
                let v: [f32; 8] = std::array::from_fn(|c| value(corner(c as u8)));
                let ins = v.iter().filter(|&&a| inside(a)).count();
                if ins == 0 || ins == 8 {
                    continue;
                }
                for tet in TETS {
                    let (i, o): (Vec<u8>, Vec<u8>) =
                        tet.iter().partition(|&&c| inside(v[c as usize]));
                    if i.is_empty() || o.is_empty() {
                        continue;
                    }
                    let centroid = |cs: &[u8]| {
                        cs.iter().map(|&c| corner(c).as_vec3()).sum::<Vec3>() / cs.len() as f32
                    };
                    let outward = centroid(&o) - centroid(&i);
                    let mut tri = |mesh: &mut Mesh, e: [(u8, u8); 3]| {
                        let ids = e.map(|(a, b)| {
                            vertex(mesh, corner(a), corner(b), v[a as usize], v[b as usize])
                        });
                        // Orientation from the edges' midpoints: never degenerate, and the same
                        // side as the true corners (they only slide along their edges).
                        let m = e.map(|(a, b)| (corner(a).as_vec3() + corner(b).as_vec3()) * 0.5);
                        let n = (m[1] - m[0]).cross(m[2] - m[0]);
                        let ids = if n.dot(outward) >= 0.0 {
                            ids
                        } else {
                            [ids[0], ids[2], ids[1]]
                        };
                        mesh.triangles.push(ids);
                    };
                    match (i.len(), o.len()) {
                        (1, 3) => tri(&mut mesh, [(i[0], o[0]), (i[0], o[1]), (i[0], o[2])]),
                        (3, 1) => tri(&mut mesh, [(i[0], o[0]), (i[1], o[0]), (i[2], o[0])]),
                        _ => {
                            // A quad around the tetrahedron: (i0,o0) (i0,o1) (i1,o1) (i1,o0).
                            let q = [(i[0], o[0]), (i[0], o[1]), (i[1], o[1]), (i[1], o[0])];
                            tri(&mut mesh, [q[0], q[1], q[2]]);
                            tri(&mut mesh, [q[0], q[2], q[3]]);
                        }
                    }
                }
            }
        }
    }
    // Area-weighted normals.
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

#[cfg(test)]
mod tests {
    use super::*;

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
