//! Tools from CAD: NURBS faces (with their trimming loops) read from IGES files or from a
//! JSON table, made into exact rational Bézier patch surfaces.
//!
//! Reading ([`iges`], [`nurbs_json`]) gives [`Face`]s in millimetres; [`tool_surface`]
//! splits each face's surface into Bézier pieces by knot insertion (exact), keeps the
//! face's trim with every piece (the projection then refuses feet outside the trim), and
//! builds the [`PatchSurface`], which runs the seam, fold and orientation checks.

pub mod iges;
mod iges_analytic;
mod iges_brep;
pub mod nurbs_json;
mod select;
pub mod step;
mod step_analytic;
mod step_assembly;
mod step_curves;
mod step_topology;

use crate::geometry::nurbs::NurbsSurface;
use crate::geometry::trim::{PieceTrim, TrimRegion};
use crate::geometry::{PatchSurface, Vec3};
use crate::{Error, Result};
use std::sync::Arc;

/// A face as read from a file: its surface and, if trimmed, the region of its parameter
/// plane that belongs to the face.
#[derive(Debug, Clone)]
pub struct Face {
    pub surface: NurbsSurface,
    pub trim: Option<TrimRegion>,
    /// Where it came from, for messages ("IGES entity 144 at D line 3").
    pub origin: String,
    /// The face's outward side is that of `-S_u x S_v` (a STEP face with `same_sense`
    /// false).
    pub flip: bool,
    /// Along `u`, `v`: the half angle of every knot span if the surface runs that way by
    /// circular arcs in normal form while the trim is given in (an affine function of) the
    /// angle, as on an IGES surface of revolution; `None`: the trim uses the surface's own
    /// parameter.
    pub arcs: [Option<f64>; 2],
    /// The names the face answers to (a STEP face's own, its shell's and solid's: see
    /// `step_topology.rs`); empty for IGES and JSON faces.
    pub names: Vec<String>,
}

/// What to make of the faces of a file.
#[derive(Debug, Clone, Default)]
pub struct ImportOptions {
    /// Indices (in file order, from 0) of the faces to keep; `None`: all.
    pub faces: Option<Vec<usize>>,
    /// Keep the faces answering to one of these names ([`Face::names`]); `None`: all.
    pub names: Option<Vec<String>>,
    /// Keep the faces whose normal at their centre points within this cone ([`Facing`]).
    pub facing: Option<Facing>,
    /// Reverse every face's normal (a tool whose faces point into it).
    pub flip: bool,
    /// Moved by this after reading (mm).
    pub translate: Vec3,
}

pub use select::{choose_faces, Facing};

/// The tool surface of the chosen faces (see the module docs). Errs naming the face whose
/// surface is degenerate, and as [`PatchSurface::with_trims`] for inconsistent normals.
pub fn tool_surface(
    source: &str,
    faces: Vec<Face>,
    options: &ImportOptions,
) -> Result<PatchSurface> {
    let chosen = choose_faces(source, faces, options)?;
    if chosen.is_empty() {
        return Err(Error::Input(format!("{source}: no face to make a tool of")));
    }
    let identity = crate::geometry::Mat3::identity();
    let mut patches = Vec::new();
    let mut trims = Vec::new();
    for face in chosen {
        let [u, v] = face.surface.domain();
        let pieces = face
            .surface
            .to_bezier()
            .map_err(|e| Error::Input(format!("{source}: {}: {}", face.origin, strip(e))))?;
        let region = face.trim.filter(|t| !t.is_rectangle(u, v)).map(Arc::new);
        for piece in pieces {
            let mut patch = piece.patch.transformed(&identity, &options.translate);
            if options.flip != face.flip {
                patch = patch.flipped();
            }
            patches.push(patch);
            trims.push(region.as_ref().map(|r| PieceTrim {
                region: r.clone(),
                u: piece.u,
                v: piece.v,
                arcs: face.arcs,
            }));
        }
    }
    PatchSurface::with_trims(patches, trims)
        .map_err(|e| Error::Input(format!("{source}: {}", strip(e))))
}

/// The message of an input error without its "invalid input: " prefix.
fn strip(e: Error) -> String {
    match e {
        Error::Input(m) => m,
        other => other.to_string(),
    }
}
