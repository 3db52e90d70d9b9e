//! Exports that other tools read (pure: no GPU): the cloud's density as an OpenVDB fog volume
//! or a Mitsuba 3 scene with its `.vol` grid, and its surface as glTF binary, OBJ or PLY. The
//! PNG of a view is the renderer's (`cli/export.rs`, the app's Export group).
//!
//! - `grid`: the scene sampled on a grid of the chosen resolution, with or without its media;
//! - `axes`: Y-up or Z-up and the unit scale;
//! - `vdb`: the OpenVDB writer; `mitsuba`: the Mitsuba scene; `formats`: glb, OBJ, PLY, `.vol`;
//! - `mesh`: the surface by marching cubes (closed, manifold, outward);
//! - `zip`: several files as one (stored) archive, for one browser download;
//! - `png`: an RGBA image as PNG, for Record's frames.

mod axes;
mod formats;
mod grid;
pub mod mesh;
mod mitsuba;
mod png;
mod vdb;
mod zip;

pub use axes::{Axes, Up};
pub use formats::{grid_box, write_glb, write_obj, write_ply, write_vol};
pub use grid::{DensityGrid, Sampling, sample};
pub use mesh::{Mesh, mesh};
pub use mitsuba::write_xml;
pub use png::encode_rgba as encode_png;
pub use vdb::write_vdb;
pub use zip::{zip, zip_pieces};

use crate::field::ISO;
use crate::scene::Scene;

/// What an export writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// OpenVDB fog volume (`.vdb`), a float grid named `density`.
    Vdb,
    /// Mitsuba 3 scene XML plus its `.vol` grid.
    Mitsuba,
    /// glTF 2.0 binary mesh.
    Glb,
    /// Wavefront OBJ mesh.
    Obj,
    /// Binary PLY mesh.
    Ply,
    /// The rendered view (by the renderer, not here).
    Png,
}

impl Format {
    /// Every format, with its name on the command line and in the panel.
    pub const ALL: [(Format, &'static str); 6] = [
        (Format::Vdb, "vdb"),
        (Format::Mitsuba, "mitsuba"),
        (Format::Glb, "glb"),
        (Format::Obj, "obj"),
        (Format::Ply, "ply"),
        (Format::Png, "png"),
    ];

    /// Looks a format up by name.
    pub fn from_name(name: &str) -> Option<Format> {
        Self::ALL
            .iter()
            .find(|(_, n)| n.eq_ignore_ascii_case(name))
            .map(|&(f, _)| f)
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(f, _)| *f == self)
            .map_or("?", |(_, n)| n)
    }

    /// The names of the files written beside the main one, `STEM.EXT` (Mitsuba's volume and
    /// its sky's environment map), in the order [`export`] returns them after the main one.
    pub fn companions(self, stem: &str) -> Vec<String> {
        match self {
            Format::Mitsuba => mitsuba_companions(stem).to_vec(),
            _ => Vec::new(),
        }
    }

    /// The file extension of its main file.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Mitsuba => "xml",
            f => f.name(),
        }
    }

    /// Whether it writes the surface (a mesh) rather than the density.
    pub fn is_mesh(self) -> bool {
        matches!(self, Format::Glb | Format::Obj | Format::Ply)
    }
}

/// Mitsuba's volume and its sky's environment map, named after `stem`.
fn mitsuba_companions(stem: &str) -> [String; 2] {
    [format!("{stem}.vol"), format!("{stem}.sky.pfm")]
}

/// How to export.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Options {
    /// Texels along the grid's longest side (density and mesh alike).
    pub resolution: u32,
    /// Up axis and unit scale of the file (VDB and meshes; Mitsuba keeps the app's axes).
    pub axes_up: Up,
    /// File length per world unit.
    pub scale: f32,
    /// The noise media as shown (density exports), or the surface they make (meshes); off:
    /// the plain blended field.
    pub noise: bool,
    /// Image size of the Mitsuba sensor (and of a PNG).
    pub image: [u32; 2],
    /// Mitsuba's samples per pixel.
    pub samples: u32,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            resolution: 128,
            axes_up: Up::Y,
            scale: 1.0,
            noise: true,
            image: [960, 540],
            samples: 64,
        }
    }
}

impl Options {
    /// The axes of a file.
    pub fn axes(&self) -> Axes {
        Axes {
            up: self.axes_up,
            scale: if self.scale.is_finite() && self.scale > 0.0 {
                self.scale
            } else {
                1.0
            },
        }
    }
}

/// One exported file: its name (relative to the export's main file) and bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct File {
    /// File name, `STEM.EXT`.
    pub name: String,
    /// Contents.
    pub bytes: Vec<u8>,
}

/// Why an export failed.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// The scene holds no cloud.
    #[error("the scene has no cloud to export")]
    Empty,
    /// The sampling would take too long.
    #[error("{0}")]
    TooLarge(String),
    /// A PNG must be rendered, not written here.
    #[error("a PNG is rendered by the renderer, not written by the exporter")]
    NeedsRenderer,
}

/// Writes `scene` as `format`; the first file is the main one, named `STEM.EXT`.
pub fn export(
    scene: &Scene,
    format: Format,
    options: &Options,
    stem: &str,
) -> Result<Vec<File>, ExportError> {
    exported(
        &mut crate::derive::Derived::default(),
        scene,
        format,
        options,
        stem,
        false,
    )
}

/// A sequence's frame of [`export`], through `derived` (see [`Sampling::start_in`]): a
/// simulated scene's run steps on from frame to frame, and a volume of a frame with no cloud
/// yet is written clear rather than refused.
pub fn export_frame(
    derived: &mut crate::derive::Derived,
    scene: &Scene,
    format: Format,
    options: &Options,
    stem: &str,
) -> Result<Vec<File>, ExportError> {
    exported(derived, scene, format, options, stem, true)
}

/// [`export`] and [`export_frame`]: sampled through `derived`, a clear volume allowed or not.
fn exported(
    derived: &mut crate::derive::Derived,
    scene: &Scene,
    format: Format,
    options: &Options,
    stem: &str,
    clear_ok: bool,
) -> Result<Vec<File>, ExportError> {
    if format == Format::Png {
        return Err(ExportError::NeedsRenderer);
    }
    let grid = Sampling::start_in(derived, scene, format, options, clear_ok)?.finish();
    Ok(write(scene, &grid, format, options, stem))
}

/// The surface of a sampled grid: the field's iso-surface, or with the media the surface
/// where their density reaches a half.
pub fn surface(grid: &DensityGrid, noise: bool) -> Mesh {
    let (values, iso) = if noise {
        (&grid.values, 0.5)
    } else {
        (&grid.field, ISO)
    };
    mesh(grid.dims, grid.min, grid.h, values, iso)
}

/// The files of `format` (not PNG: none) from a grid sampled with `options` (the last step
/// of [`export`]).
pub fn write(
    scene: &Scene,
    grid: &DensityGrid,
    format: Format,
    options: &Options,
    stem: &str,
) -> Vec<File> {
    let axes = options.axes();
    let file = |ext: &str, bytes: Vec<u8>| File {
        name: format!("{stem}.{ext}"),
        bytes,
    };
    match format {
        Format::Png => Vec::new(),
        Format::Vdb => vec![file(
            "vdb",
            write_vdb(grid, axes, "density", scene.seed ^ 0x5644_4220),
        )],
        Format::Mitsuba => {
            let [vol, sky] = mitsuba_companions(stem);
            let xml = write_xml(
                scene,
                grid,
                [&vol, &sky],
                options.image,
                options.samples.max(1),
            );
            vec![
                file("xml", xml.into_bytes()),
                file("vol", write_vol(grid)),
                file("sky.pfm", mitsuba::write_sky(scene)),
            ]
        }
        Format::Glb => vec![file(
            "glb",
            write_glb(&surface(grid, options.noise), axes, stem),
        )],
        Format::Obj => vec![file(
            "obj",
            write_obj(&surface(grid, options.noise), axes, stem),
        )],
        Format::Ply => vec![file("ply", write_ply(&surface(grid, options.noise), axes))],
    }
}
