//! Mesh files: glTF binary (.glb), Wavefront OBJ and binary PLY, and Mitsuba's `.vol` grid.

use glam::Vec3;

use super::axes::Axes;
use super::grid::DensityGrid;
use super::mesh::Mesh;

/// The mesh's positions and normals in the file's axes and units.
fn placed(mesh: &Mesh, axes: Axes) -> (Vec<Vec3>, Vec<Vec3>) {
    (
        mesh.positions.iter().map(|&p| axes.point(p)).collect(),
        mesh.normals.iter().map(|&n| axes.direction(n)).collect(),
    )
}

/// glTF 2.0 binary: one mesh of one indexed triangle primitive (POSITION, NORMAL, u32
/// indices), in a scene of one node. glTF is Y-up by definition; `axes.up` is honoured anyway.
pub fn write_glb(mesh: &Mesh, axes: Axes, name: &str) -> Vec<u8> {
    let (positions, normals) = placed(mesh, axes);
    let mut bin: Vec<u8> = Vec::new();
    for p in &positions {
        bin.extend(p.to_array().iter().flat_map(|c| c.to_le_bytes()));
    }
    let normals_at = bin.len();
    for n in &normals {
        bin.extend(n.to_array().iter().flat_map(|c| c.to_le_bytes()));
    }
    let indices_at = bin.len();
    for t in &mesh.triangles {
        bin.extend(t.iter().flat_map(|i| i.to_le_bytes()));
    }
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let (lo, hi) = if positions.is_empty() {
        (Vec3::ZERO, Vec3::ZERO)
    } else {
        (lo, hi)
    };
    let count = positions.len();
    let json = serde_json::json!({
        "asset": { "version": "2.0", "generator": "cloudsketch" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0, "name": name }],
        "meshes": [{
            "name": name,
            "primitives": [{
                "attributes": { "POSITION": 0, "NORMAL": 1 },
                "indices": 2,
                "mode": 4
            }]
        }],
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": normals_at, "target": 34962 },
            { "buffer": 0, "byteOffset": normals_at, "byteLength": indices_at - normals_at, "target": 34962 },
            { "buffer": 0, "byteOffset": indices_at, "byteLength": bin.len() - indices_at, "target": 34963 }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
              "min": lo.to_array(), "max": hi.to_array() },
            { "bufferView": 1, "componentType": 5126, "count": count, "type": "VEC3" },
            { "bufferView": 2, "componentType": 5125, "count": mesh.triangles.len() * 3, "type": "SCALAR" }
        ]
    });
    let mut json = serde_json::to_vec(&json).unwrap_or_default();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// Wavefront OBJ: `v`, `vn` and `f v//vn` lines (1-based).
pub fn write_obj(mesh: &Mesh, axes: Axes, name: &str) -> Vec<u8> {
    use std::fmt::Write as _;
    let (positions, normals) = placed(mesh, axes);
    let mut s = String::with_capacity(mesh.triangles.len() * 64);
    let _ = writeln!(s, "# cloudsketch: the cloud's surface\no {name}");
    for p in &positions {
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for n in &normals {
        let _ = writeln!(s, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        let _ = writeln!(s, "f {a}//{a} {b}//{b} {c}//{c}");
    }
    s.into_bytes()
}

/// Binary little-endian PLY: float positions and normals, u8-counted int index lists.
pub fn write_ply(mesh: &Mesh, axes: Axes) -> Vec<u8> {
    let (positions, normals) = placed(mesh, axes);
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment cloudsketch: the cloud's surface\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        positions.len(),
        mesh.triangles.len()
    );
    let mut out = header.into_bytes();
    for (p, n) in positions.iter().zip(&normals) {
        for c in p.to_array().into_iter().chain(n.to_array()) {
            out.extend(c.to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for &i in t {
            out.extend((i as i32).to_le_bytes());
        }
    }
    out
}

/// Mitsuba's binary grid volume (`.vol`, version 3): float32, one channel, the texel box
/// (the grid's outer faces) as its bounds, x fastest. Always in the app's (Y-up) axes.
pub fn write_vol(grid: &DensityGrid) -> Vec<u8> {
    let mut out = Vec::with_capacity(48 + grid.values.len() * 4);
    out.extend(b"VOL");
    out.push(3);
    out.extend(1i32.to_le_bytes());
    for d in grid.dims.to_array() {
        out.extend((d as i32).to_le_bytes());
    }
    out.extend(1i32.to_le_bytes());
    let (lo, hi) = grid_box(grid);
    for c in lo.to_array().into_iter().chain(hi.to_array()) {
        out.extend(c.to_le_bytes());
    }
    for v in &grid.values {
        out.extend(v.to_le_bytes());
    }
    out
}

/// The box the grid's texels fill (their outer faces).
pub fn grid_box(grid: &DensityGrid) -> (Vec3, Vec3) {
    let lo = grid.min - Vec3::splat(0.5 * grid.h);
    (lo, lo + grid.dims.as_vec3() * grid.h)
}
