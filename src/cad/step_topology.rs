//! What a STEP face's topology says about it: the names it answers to and whether its shell
//! uses it reversed.
//!
//! * **Names**: the `ADVANCED_FACE`'s own name string; the name of every `ORIENTED_FACE`
//!   that refers to it; the name of each `OPEN_SHELL` / `CLOSED_SHELL` listing it (directly
//!   or through an `ORIENTED_FACE`); the name of the `MANIFOLD_SOLID_BREP` or
//!   `BREP_WITH_VOIDS` whose outer shell that is, and of the `SHELL_BASED_SURFACE_MODEL`
//!   that lists it. Empty names (`''`, what CAD writes by default) are left out.
//! * **Orientation**: a shell that lists `ORIENTED_FACE('', *, #face, .F.)` uses the face
//!   with its normal reversed. With `same_sense` (the face's normal is `S_u x S_v` when
//!   true, `-S_u x S_v` when false) the face's outward normal is
//!   `n = s * o * (S_u x S_v)`, `s = +1/-1` for `same_sense` `.T./.F.`, `o = +1/-1` for
//!   the orientation `.T./.F.` (1 where no `ORIENTED_FACE` refers to the face). A face of a
//!   closed shell or solid then points out of the material.

use super::step::{Step, Value};
use crate::Result;
use std::collections::BTreeMap;

/// A face's names and whether a shell uses it reversed.
#[derive(Debug, Default, Clone)]
pub(super) struct FaceContext {
    pub names: Vec<String>,
    pub reversed: bool,
}

fn text(v: Option<&Value>) -> Option<String> {
    match v {
        Some(Value::Text(s)) if !s.trim().is_empty() => Some(s.trim().to_string()),
        _ => None,
    }
}

impl Step<'_> {
    /// The context of every face referred to by an `ORIENTED_FACE`, a shell or a solid,
    /// by the `ADVANCED_FACE`'s instance id (faces listed nowhere have none).
    pub(super) fn face_contexts(&self) -> Result<BTreeMap<usize, FaceContext>> {
        let mut ctx: BTreeMap<usize, FaceContext> = BTreeMap::new();
        // Face -> the shells listing it; shell -> its faces.
        let mut shell_faces: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for (&id, inst) in &self.instances {
            for (kind, p) in &inst.parts {
                match kind.as_str() {
                    "ORIENTED_FACE" => {
                        let face = self.reference(id, p.get(2), "face_element")?;
                        let entry = ctx.entry(face).or_default();
                        entry.reversed = !self.boolean(id, p.get(3), "orientation")?;
                        entry.names.extend(text(p.first()));
                    }
                    "OPEN_SHELL" | "CLOSED_SHELL" => {
                        let mut faces = Vec::new();
                        for f in self.list(id, p.get(1), "faces")? {
                            let f = self.reference(id, Some(f), "face")?;
                            // Through an ORIENTED_FACE to the ADVANCED_FACE.
                            let target = match self.part(f, "ORIENTED_FACE") {
                                Some(op) => self.reference(f, op.get(2), "face_element")?,
                                None => f,
                            };
                            faces.push(target);
                        }
                        if let Some(name) = text(p.first()) {
                            for &f in &faces {
                                ctx.entry(f).or_default().names.push(name.clone());
                            }
                        }
                        shell_faces.insert(id, faces);
                    }
                    _ => {}
                }
            }
        }
        // Solids and surface models name the faces of their shells.
        for (&id, inst) in &self.instances {
            for (kind, p) in &inst.parts {
                let shells: Vec<usize> = match kind.as_str() {
                    "MANIFOLD_SOLID_BREP" | "BREP_WITH_VOIDS" => {
                        vec![self.reference(id, p.get(1), "outer shell")?]
                    }
                    "SHELL_BASED_SURFACE_MODEL" => self
                        .list(id, p.get(1), "shells")?
                        .iter()
                        .map(|s| self.reference(id, Some(s), "shell"))
                        .collect::<Result<_>>()?,
                    _ => continue,
                };
                let Some(name) = text(p.first()) else {
                    continue;
                };
                for s in shells {
                    for &f in shell_faces.get(&s).map_or(&[][..], |v| &v[..]) {
                        ctx.entry(f).or_default().names.push(name.clone());
                    }
                }
            }
        }
        for (&id, inst) in &self.instances {
            if let Some((_, p)) = inst.parts.iter().find(|(n, _)| n == "ADVANCED_FACE") {
                if let Some(name) = text(p.first()) {
                    ctx.entry(id).or_default().names.insert(0, name);
                }
            }
        }
        Ok(ctx)
    }
}
