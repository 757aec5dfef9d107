//! STEP assemblies: the pose of each part's faces.
//!
//! A part's faces hang from its shape representation (`ADVANCED_BREP_SHAPE_REPRESENTATION`
//! and the like: items -> `MANIFOLD_SOLID_BREP` / `BREP_WITH_VOIDS` /
//! `SHELL_BASED_SURFACE_MODEL` -> `CLOSED_SHELL` / `OPEN_SHELL` -> `ADVANCED_FACE`). An
//! assembly places it by a `REPRESENTATION_RELATIONSHIP` from the part's representation
//! (`rep_1`) to the assembly's (`rep_2`) `WITH_TRANSFORMATION` an
//! `ITEM_DEFINED_TRANSFORMATION(item_1, item_2)` of two `AXIS2_PLACEMENT_3D`s, the
//! complex instance a `CONTEXT_DEPENDENT_SHAPE_REPRESENTATION` names. With `A(p)` the map
//! of a placement `p` (`x -> location + [x_dir y_dir axis] x`), the part goes into the
//! assembly by `A(item_2) A(item_1)^-1`; a relationship without a transformation is the
//! identity. A face's poses are the products along every chain of relationships up to a
//! representation no relationship places (the root), so a part used twice gives its faces
//! twice. `MAPPED_ITEM` placements are refused, naming the instance.
//! Cost: O(instances + faces x chains).

use super::step::{Step, Value};
use crate::geometry::{Mat3, Vec3};
use crate::Result;
use std::collections::HashMap;

/// A rigid map `x -> R x + t` (`t` in the file's length unit).
type Pose = (Mat3, Vec3);

/// Deepest chain of relationships followed (a loop is refused beyond it).
const MAX_DEPTH: usize = 32;

impl Step<'_> {
    /// The poses of every face that some shape representation holds and some relationship
    /// places (faces absent from the map are at the identity).
    pub(super) fn face_placements(&self) -> Result<HashMap<usize, Vec<Pose>>> {
        let mut parents: HashMap<usize, Vec<(usize, Pose)>> = HashMap::new();
        for (&id, inst) in &self.instances {
            if inst.parts.iter().any(|(n, _)| n == "MAPPED_ITEM") {
                return Err(self.fail(
                    id,
                    "a MAPPED_ITEM placement is not read (export the assembly with \
                     CONTEXT_DEPENDENT_SHAPE_REPRESENTATION, or the parts at their place)"
                        .into(),
                ));
            }
            let Some(rel) = self.part(id, "REPRESENTATION_RELATIONSHIP") else {
                continue;
            };
            let rep1 = self.reference(id, rel.get(2), "rep_1")?;
            let rep2 = self.reference(id, rel.get(3), "rep_2")?;
            let pose = match self.part(id, "REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION") {
                None => (Mat3::identity(), Vec3::zeros()),
                Some(t) => {
                    let t = self.reference(id, t.first(), "transformation")?;
                    let p = self.part(t, "ITEM_DEFINED_TRANSFORMATION").ok_or_else(|| {
                        self.fail(
                            id,
                            format!(
                                "its transformation #{t} is not an ITEM_DEFINED_TRANSFORMATION"
                            ),
                        )
                    })?;
                    let from = self.axis_placement(self.reference(t, p.get(2), "item_1")?, t)?;
                    let to = self.axis_placement(self.reference(t, p.get(3), "item_2")?, t)?;
                    // A(to) A(from)^-1: x -> R_to R_from^T (x - o_from) + o_to.
                    let r = to.0 * from.0.transpose();
                    (r, to.1 - r * from.1)
                }
            };
            parents.entry(rep1).or_default().push((rep2, pose));
        }
        let mut out = HashMap::new();
        if parents.is_empty() {
            return Ok(out);
        }
        for (&id, inst) in &self.instances {
            let holds_shape = inst.parts.iter().any(|(n, _)| {
                n.ends_with("SHAPE_REPRESENTATION") && n != "CONTEXT_DEPENDENT_SHAPE_REPRESENTATION"
            });
            if !holds_shape || !parents.contains_key(&id) {
                continue;
            }
            let poses = self.poses(id, &parents, 0)?;
            let items = inst
                .parts
                .iter()
                .find_map(|(_, p)| match p.get(1) {
                    Some(Value::List(l)) => Some(l.clone()),
                    _ => None,
                })
                .unwrap_or_default();
            let mut faces = Vec::new();
            for item in &items {
                if let Value::Ref(r) = item {
                    self.collect_faces(*r, &mut faces, 0);
                }
            }
            for f in faces {
                out.entry(f)
                    .or_insert_with(Vec::new)
                    .extend(poses.iter().copied());
            }
        }
        Ok(out)
    }

    /// Every pose of representation `rep` in the root's frame.
    fn poses(
        &self,
        rep: usize,
        parents: &HashMap<usize, Vec<(usize, Pose)>>,
        depth: usize,
    ) -> Result<Vec<Pose>> {
        let Some(up) = parents.get(&rep) else {
            return Ok(vec![(Mat3::identity(), Vec3::zeros())]);
        };
        if depth > MAX_DEPTH {
            return Err(self.fail(rep, "its assembly relationships form a loop".into()));
        }
        let mut out = Vec::new();
        for (parent, (r, t)) in up {
            for (pr, pt) in self.poses(*parent, parents, depth + 1)? {
                out.push((pr * r, pr * t + pt));
            }
        }
        Ok(out)
    }

    /// The `ADVANCED_FACE`s below a representation item (solids, shells).
    fn collect_faces(&self, id: usize, out: &mut Vec<usize>, depth: usize) {
        let Some(inst) = self.instances.get(&id) else {
            return;
        };
        let refs = |v: Option<&Value>| -> Vec<usize> {
            match v {
                Some(Value::Ref(r)) => vec![*r],
                Some(Value::List(l)) => l
                    .iter()
                    .filter_map(|x| match x {
                        Value::Ref(r) => Some(*r),
                        _ => None,
                    })
                    .collect(),
                _ => Vec::new(),
            }
        };
        for (name, p) in &inst.parts {
            let below = match name.as_str() {
                "ADVANCED_FACE" => {
                    out.push(id);
                    return;
                }
                "MANIFOLD_SOLID_BREP"
                | "SHELL_BASED_SURFACE_MODEL"
                | "CLOSED_SHELL"
                | "OPEN_SHELL" => refs(p.get(1)),
                "BREP_WITH_VOIDS" => [refs(p.get(1)), refs(p.get(2))].concat(),
                _ => continue,
            };
            if depth < 8 {
                for b in below {
                    self.collect_faces(b, out, depth + 1);
                }
            }
        }
    }

    /// An `AXIS2_PLACEMENT_3D` as `(R, origin)`: columns `x_dir, axis x x_dir... ` (see the
    /// module docs); defaults `axis = z`, `ref_direction = x`.
    fn axis_placement(&self, id: usize, from: usize) -> Result<Pose> {
        let p = self.part(id, "AXIS2_PLACEMENT_3D").ok_or_else(|| {
            self.fail(
                from,
                format!("its placement #{id} is not an AXIS2_PLACEMENT_3D"),
            )
        })?;
        let location = self.point(self.reference(id, p.get(1), "location")?, id)?;
        let direction = |v: Option<&Value>, default: Vec3| -> Result<Vec3> {
            match v {
                Some(Value::Ref(d)) => {
                    let q = self.part(*d, "DIRECTION").ok_or_else(|| {
                        self.fail(id, format!("its direction #{d} is not a DIRECTION"))
                    })?;
                    let c = self.list(*d, q.get(1), "direction ratios")?;
                    let c: Vec<f64> = c
                        .iter()
                        .map(|x| self.number(*d, Some(x), "direction ratio"))
                        .collect::<Result<_>>()?;
                    if c.len() != 3 {
                        return Err(self.fail(*d, "a direction of placement needs 3 ratios".into()));
                    }
                    Vec3::new(c[0], c[1], c[2])
                        .try_normalize(1e-300)
                        .ok_or_else(|| self.fail(*d, "a zero direction".into()))
                }
                _ => Ok(default),
            }
        };
        let z = direction(p.get(2), Vec3::z())?;
        let x_ref = direction(p.get(3), Vec3::x())?;
        let x = (x_ref - z * z.dot(&x_ref))
            .try_normalize(1e-12)
            .ok_or_else(|| self.fail(id, "its ref_direction is along its axis".into()))?;
        let y = z.cross(&x);
        if location.len() != 3 {
            return Err(self.fail(id, "its location is not a 3D point".into()));
        }
        Ok((
            Mat3::from_columns(&[x, y, z]),
            Vec3::new(location[0], location[1], location[2]),
        ))
    }
}
