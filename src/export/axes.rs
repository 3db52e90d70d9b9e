//! The exported files' axes and units: the app is Y-up; Blender and Houdini users pick Z-up or
//! Y-up, and a unit scale (world units per exported unit of length).

use glam::{UVec3, Vec3};

use super::grid::DensityGrid;

/// Which world axis points up in an exported file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Up {
    /// The app's own axes (glTF's, Houdini's, Maya's).
    #[default]
    Y,
    /// Blender's: the app's (x, y, z) becomes (x, −z, y), a turn of 90° about x.
    Z,
}

impl Up {
    /// Its name on the command line and in the panel.
    pub fn name(self) -> &'static str {
        match self {
            Up::Y => "y",
            Up::Z => "z",
        }
    }
}

/// The axes and scale of one export.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axes {
    /// The up axis.
    pub up: Up,
    /// Exported length per world unit.
    pub scale: f32,
}

impl Default for Axes {
    fn default() -> Self {
        Self {
            up: Up::Y,
            scale: 1.0,
        }
    }
}

impl Axes {
    /// A direction (no scale) in the file's axes.
    pub fn direction(&self, v: Vec3) -> Vec3 {
        match self.up {
            Up::Y => v,
            Up::Z => Vec3::new(v.x, -v.z, v.y),
        }
    }

    /// A point in the file's axes and units.
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.direction(p) * self.scale
    }

    /// The grid seen in the file's axes: its dimensions, the position of its first texel's
    /// centre, and for each texel of the file (x fastest) the index of the app's texel.
    pub fn grid(&self, grid: &DensityGrid) -> (UVec3, Vec3, Vec<usize>) {
        let d = grid.dims;
        match self.up {
            Up::Y => (d, self.point(grid.min), (0..grid.values.len()).collect()),
            Up::Z => {
                // File (i, j, k) = app (x, dims.z − 1 − z, y) turned: i = x, j = d.z−1−z, k = y.
                let dims = UVec3::new(d.x, d.z, d.y);
                let first = self.point(grid.center(0, 0, d.z - 1));
                let mut order = Vec::with_capacity(grid.values.len());
                for k in 0..dims.z {
                    for j in 0..dims.y {
                        for i in 0..dims.x {
                            order.push(grid.index(i, k, d.z - 1 - j));
                        }
                    }
                }
                (dims, first, order)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_up_turns_the_grid_and_keeps_every_texel_where_it_was() {
        let grid = DensityGrid {
            dims: UVec3::new(3, 4, 5),
            min: Vec3::new(-1.0, 2.0, 0.5),
            h: 0.25,
            values: (0..60).map(|i| i as f32).collect(),
            field: vec![0.0; 60],
        };
        let axes = Axes {
            up: Up::Z,
            scale: 2.0,
        };
        let (dims, first, order) = axes.grid(&grid);
        assert_eq!(dims, UVec3::new(3, 5, 4));
        let h = grid.h * axes.scale;
        for k in 0..dims.z {
            for j in 0..dims.y {
                for i in 0..dims.x {
                    let file = first + UVec3::new(i, j, k).as_vec3() * h;
                    let app = order[((k * dims.y + j) * dims.x + i) as usize];
                    let (x, y, z) = (app as u32 % 3, app as u32 / 3 % 4, app as u32 / 12);
                    assert!(file.abs_diff_eq(axes.point(grid.center(x, y, z)), 1e-5));
                }
            }
        }
    }
}
