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

/// What a field map shows besides its field: where the points are, which tool's contact
/// values (and faces) it shows, and the length unit of its axes.
#[derive(Clone, Debug, Default)]
pub struct MapView {
    pub configuration: Configuration,
    /// Only the nodes this tool has touched (in contact now, or with frictional work or
    /// slip against it) carry values; the rest of the face set is drawn grey.
    pub tool: Option<String>,
    /// Unit of x and y ("mm"); empty for none.
    pub length_unit: String,
    /// The curve and thresholds of the formability fields (`flc_margin`, `formability`).
    pub formability: super::formability::FormabilityOptions,
}

/// The colour map of field `field` on the boundary faces within node set `face_set`,
/// seen along -z (x right, y up), at the committed state of `sim`.
pub fn field_map(
    sim: &Simulation,
    face_set: &str,
    field: &str,
    view: &MapView,
) -> Result<FieldMap> {
    let mesh = &sim.model.mesh;
    let nodes = mesh.node_set(face_set)?;
    let quads = mesh.faces_within(nodes)?;
    if quads.is_empty() {
        return Err(Error::Input(format!(
            "node set '{face_set}' holds no boundary face to draw"
        )));
    }
    let tool = view
        .tool
        .as_deref()
        .map(|name| sim.model.tool_index(name))
        .transpose()?;
    let frame =
        super::blank_frame::frame_against(sim, Configuration::Reference, tool, &view.formability);
    let mut values = nodal_values(&frame, field)?;
    if let Some(c) = tool {
        let mut touched = vec![false; values.len()];
        for (k, s) in sim.contact_states(c).iter().enumerate() {
            touched[sim.model.contacts[c].candidates[k]] =
                s.status.is_active() || s.work > 0.0 || s.slip > 0.0;
        }
        for (v, t) in values.iter_mut().zip(&touched) {
            if !t {
                *v = f64::NAN;
            }
        }
    }
    let u = sim.displacements();
    let points = mesh
        .nodes
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let [x, y, _] = view.configuration.place(p, &u[3 * i..3 * i + 3]);
            [x, y]
        })
        .collect();
    let axis = |name: &str| match view.length_unit.as_str() {
        "" => name.to_string(),
        unit => format!("{name} [{unit}]"),
    };
    let on = match &view.tool {
        Some(t) => format!("{face_set} touched by {t}"),
        None => face_set.to_string(),
    };
    Ok(FieldMap {
        title: format!("{field} on {on}, t = {}", super::significant(sim.time(), 6)),
        label: field.to_string(),
        points,
        values,
        quads,
        range: None,
        x_label: axis("x"),
        y_label: axis("y"),
    })
}

/// The colour range a friction law gives `field`: for `mu`, from the smallest to the
/// largest control point of the Bernstein laws (mu_cut to mu_init for a decreasing law)
/// or the Coulomb coefficients, of tool `tool` or of every tool. Error for another field,
/// or when every law is external (a script function).
pub fn law_range(sim: &Simulation, field: &str, tool: Option<&str>) -> Result<(f64, f64)> {
    if field != "mu" {
        return Err(Error::Input(format!(
            "range \"law\" is defined for the field mu only, not '{field}'"
        )));
    }
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for c in &sim.model.contacts {
        if tool.is_some_and(|t| t != c.tool.name) {
            continue;
        }
        let mus: Vec<f64> = match &c.tool.friction {
            crate::contact::FrictionLaw::Coulomb { mu } => vec![*mu],
            crate::contact::FrictionLaw::Bernstein(law) => law.control_points().to_vec(),
            _ => Vec::new(),
        };
        for mu in mus {
            lo = lo.min(mu);
            hi = hi.max(mu);
        }
    }
    if let Some(t) = tool {
        sim.model.tool_index(t)?;
    }
    if lo > hi {
        return Err(Error::Input(
            "range \"law\": no Coulomb or Bernstein law to take the range from".into(),
        ));
    }
    if lo == hi {
        // One constant coefficient: centre it in a range of +-10 %.
        let pad = if lo == 0.0 { 0.01 } else { 0.1 * lo.abs() };
        return Ok((lo - pad, hi + pad));
    }
    Ok((lo, hi))
}
