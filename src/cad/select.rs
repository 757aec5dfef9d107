//! Which faces of a CAD file form the tool: all (the default), those of given indices, those
//! answering to given names, those facing a given direction; the filters combine (a face is
//! kept when it passes every one given).
//!
//! **Facing**: a face faces the unit direction `d` within the angle `a` when
//! `n . d > cos a`, `n` the unit outward normal at the face's centre: the surface point at
//! the middle of its parameter box (for a STEP face on an analytic surface, the box of its
//! trimming loops), `n` along `S_u x S_v` there, reversed once for each of the face's own
//! flip (STEP `same_sense` false; an `ORIENTED_FACE` with orientation `.F.`, see
//! `step_topology.rs`) and the import's `flip` option: the normal the tool will have.
//! `S_u`, `S_v` are central differences of step `1e-6` of the box's width: their relative
//! error, O(h^2) of the curvature plus round-off 1e-16/1e-6, is far below any angle one
//! would choose (a threshold within 1e-6 rad of a face's normal is not meaningful).

use super::{Face, ImportOptions};
use crate::geometry::Vec3;
use crate::{Error, Result};

/// Keep faces whose centre normal is within `angle_deg` of `direction`.
#[derive(Debug, Clone, Copy)]
pub struct Facing {
    /// Unit direction.
    pub direction: Vec3,
    /// Half angle of the cone, in degrees, in (0, 180].
    pub angle_deg: f64,
}

impl Facing {
    /// Checks the direction (non-zero, finite) and the angle; `what` names the option.
    pub fn new(direction: Vec3, angle_deg: f64, what: &str) -> Result<Facing> {
        let n = direction.norm();
        if !(n.is_finite() && n > 0.0) {
            return Err(Error::Input(format!(
                "{what}: the direction must be a non-zero vector, got [{}, {}, {}]",
                direction.x, direction.y, direction.z
            )));
        }
        if !(angle_deg > 0.0 && angle_deg <= 180.0) {
            return Err(Error::Input(format!(
                "{what}: the angle must be in (0, 180] degrees, got {angle_deg}"
            )));
        }
        Ok(Facing {
            direction: direction / n,
            angle_deg,
        })
    }
}

/// The unit outward normal at the middle of the face's parameter box (module docs).
pub(super) fn centre_normal(face: &Face, flip: bool) -> Option<Vec3> {
    let [[u0, u1], [v0, v1]] = face.surface.domain();
    let (u, v) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let (hu, hv) = (1e-6 * (u1 - u0), 1e-6 * (v1 - v0));
    let su = (face.surface.point(u + hu, v) - face.surface.point(u - hu, v)) / (2.0 * hu);
    let sv = (face.surface.point(u, v + hv) - face.surface.point(u, v - hv)) / (2.0 * hv);
    let n = su.cross(&sv);
    let len = n.norm();
    (len.is_finite() && len > 0.0).then(|| if face.flip != flip { -n / len } else { n / len })
}

/// The faces `options` choose, in file order (module docs); an error names a face index,
/// or a name no face answers to, or a facing filter that keeps nothing.
pub fn choose_faces(source: &str, faces: Vec<Face>, options: &ImportOptions) -> Result<Vec<Face>> {
    let mut chosen: Vec<Face> = match &options.faces {
        None => faces,
        Some(list) => {
            let mut out = Vec::with_capacity(list.len());
            for &k in list {
                let face = faces.get(k).ok_or_else(|| {
                    Error::input(
                        &format!("{source}: face index"),
                        k,
                        &format!("must be < the file's face count {}", faces.len()),
                    )
                })?;
                out.push(face.clone());
            }
            out
        }
    };
    if let Some(names) = &options.names {
        for name in names {
            if !chosen.iter().any(|f| f.names.contains(name)) {
                return Err(no_such_name(source, name, &chosen));
            }
        }
        chosen.retain(|f| f.names.iter().any(|n| names.contains(n)));
    }
    if let Some(facing) = options.facing {
        let cos = facing.angle_deg.to_radians().cos();
        let before = chosen.len();
        chosen.retain(|f| {
            centre_normal(f, options.flip).is_some_and(|n| n.dot(&facing.direction) > cos)
        });
        if chosen.is_empty() {
            let d = facing.direction;
            return Err(Error::Input(format!(
                "{source}: none of the {before} faces faces [{}, {}, {}] within {} degrees \
                 (normal at the face centre, outward; option flip reverses it)",
                d.x, d.y, d.z, facing.angle_deg
            )));
        }
    }
    Ok(chosen)
}

fn no_such_name(source: &str, name: &str, faces: &[Face]) -> Error {
    let mut known: Vec<&str> = faces
        .iter()
        .flat_map(|f| f.names.iter().map(String::as_str))
        .collect();
    known.sort_unstable();
    known.dedup();
    let have = if known.is_empty() {
        "the file names none of its faces, shells or solids (STEP names are the first \
         string of ADVANCED_FACE, OPEN_SHELL, CLOSED_SHELL, MANIFOLD_SOLID_BREP)"
            .to_string()
    } else {
        format!("the names there are: {}", known.join(", "))
    };
    Error::Input(format!(
        "{source}: no face answers to the name '{name}'; {have}"
    ))
}
