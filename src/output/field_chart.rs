//! A frame's nodal field on a face set, ready for a top-view colour map
//! ([`super::svg::FieldMap`]).
//!
//! Field names are those of the VTK frames ([`super::blank_frame::frame`]): a scalar point field
//! (`frictional_work`, `mu`, `contact_status`, ...), one component of a vector point field
//! (`displacement_z`), or a scalar cell field (`von_mises`, ...), which is averaged onto the
//! nodes over the elements around each node (unweighted: the mean of the adjacent cells).

use super::svg::FieldMap;
use super::{Field, Frame};
use crate::solver::Simulation;
use crate::{Error, Result};

pub use super::blank_frame::Configuration;

/// One value per node of the field `name` of `frame`.
pub fn nodal_values(frame: &Frame, name: &str) -> Result<Vec<f64>> {
    let n = frame.points.len();
    let component = |f: &Field, c: usize| (0..n).map(|i| f.values[f.components * i + c]).collect();
    if let Some(f) = frame
        .point_data
        .iter()
        .find(|f| f.name == name && f.components == 1)
    {
        return Ok(component(f, 0));
    }
    for (suffix, c) in [("_x", 0), ("_y", 1), ("_z", 2)] {
        if let Some(base) = name.strip_suffix(suffix) {
            if let Some(f) = frame
                .point_data
                .iter()
                .find(|f| f.name == base && f.components == 3)
            {
                return Ok(component(f, c));
            }
        }
    }
    if let Some(f) = frame
        .cell_data
        .iter()
        .find(|f| f.name == name && f.components == 1)
    {
        let (mut sum, mut count) = (vec![0.0; n], vec![0usize; n]);
        for (e, hex) in frame.hexes.iter().enumerate() {
            for &node in hex {
                sum[node] += f.values[e];
                count[node] += 1;
            }
        }
        return Ok(sum
            .iter()
            .zip(&count)
            .map(|(s, &c)| if c > 0 { s / c as f64 } else { f64::NAN })
            .collect());
    }
    let mut known: Vec<String> = Vec::new();
    for f in &frame.point_data {
        if f.components == 3 {
            known.extend(["_x", "_y", "_z"].map(|s| format!("{}{s}", f.name)));
        } else if f.components == 1 {
            known.push(f.name.clone());
        }
    }
    known.extend(
        frame
            .cell_data
            .iter()
            .filter(|f| f.components == 1)
            .map(|f| f.name.clone()),
    );
    Err(Error::Input(format!(
        "no nodal field '{name}' (fields: {})",
        known.join(", ")
    )))
}

/// The colour map of field `field` on the boundary faces within node set `face_set`,
/// seen along -z (x right, y up), at the committed state of `sim`.
pub fn field_map(
    sim: &Simulation,
    face_set: &str,
    field: &str,
    configuration: Configuration,
) -> Result<FieldMap> {
    let mesh = &sim.model.mesh;
    let nodes = mesh.node_set(face_set)?;
    let quads = mesh.faces_within(nodes)?;
    if quads.is_empty() {
        return Err(Error::Input(format!(
            "node set '{face_set}' holds no boundary face to draw"
        )));
    }
    let frame = super::blank_frame::frame(sim, Configuration::Reference);
    let values = nodal_values(&frame, field)?;
    let u = sim.displacements();
    let points = mesh
        .nodes
        .iter()
        .enumerate()
        .map(|(i, p)| match configuration {
            Configuration::Reference => [p.x, p.y],
            Configuration::Current => [p.x + u[3 * i], p.y + u[3 * i + 1]],
        })
        .collect();
    Ok(FieldMap {
        title: format!("{field} on {face_set}, t = {}", super::fmt_f64(sim.time())),
        label: field.to_string(),
        points,
        values,
        quads,
        range: None,
    })
}
