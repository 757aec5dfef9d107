//! Bézier tool surfaces for scripts: single patches (flat, cylindrical, toroidal, or the
//! user's own control-point tables), patch surfaces, JSON patch files, the deep-drawing
//! builders (punch, die, blankholder) and the seam report. Registered in one place.

use super::api_scene::ScriptSurface;
use super::convert::*;
use crate::geometry::builders::{
    blankholder_patches, die_patches, punch_patches, BlankholderSpec, DieSpec, Extent, PunchSpec,
};
use crate::geometry::patch_table::{patch_from_rows, patches_from_json};
use crate::geometry::{BezierPatch, PatchSurface, Vec3};
use rhai::{Array, Dynamic, Engine, Map};

use std::sync::Arc;

pub fn register(engine: &mut Engine, policy: std::rc::Rc<crate::paths::ReadPolicy>) {
    register_patches(engine);
    register_surfaces(engine, policy);
    register_builders(engine);
}

fn degrees(v: &Dynamic, what: &str) -> ScriptResult<f64> {
    Ok(number(v, what)?.to_radians())
}

/// `[start, sweep]` in degrees -> radians.
fn angle_pair(a: &Array, what: &str) -> ScriptResult<[f64; 2]> {
    if a.len() != 2 {
        return runtime_error(format!("{what} must be [start, sweep] in degrees"));
    }
    Ok([degrees(&a[0], what)?, degrees(&a[1], what)?])
}

fn rows_of<T>(
    table: &Array,
    what: &str,
    entry: impl Fn(&Dynamic, &str) -> ScriptResult<T>,
) -> ScriptResult<Vec<Vec<T>>> {
    table
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let row = row
                .clone()
                .try_cast::<Array>()
                .ok_or_else(|| format!("{what}[{i}] must be an array (a row)"))
                .or_else(runtime_error)?;
            row.iter()
                .enumerate()
                .map(|(j, v)| entry(v, &format!("{what}[{i}][{j}]")))
                .collect()
        })
        .collect()
}

fn point_entry(v: &Dynamic, what: &str) -> ScriptResult<Vec3> {
    let a = v
        .clone()
        .try_cast::<Array>()
        .ok_or_else(|| format!("{what} must be [x, y, z]"))
        .or_else(runtime_error)?;
    vec3(&a, what)
}

fn patch_from_tables(points: &Array, weights: Option<&Array>) -> ScriptResult<BezierPatch> {
    let p = rows_of(points, "bezier_patch points", point_entry)?;
    let w = match weights {
        Some(w) => Some(rows_of(w, "bezier_patch weights", number)?),
        None => None,
    };
    lift(patch_from_rows("bezier_patch", &p, w.as_deref()))
}

fn register_patches(engine: &mut Engine) {
    engine.register_type_with_name::<BezierPatch>("Patch");
    // bezier_patch(points, weights): rows along u of [x, y, z] (columns along v), and the
    // weights in the same layout; without weights all are 1.
    engine.register_fn(
        "bezier_patch",
        |points: Array, weights: Array| -> ScriptResult<BezierPatch> {
            patch_from_tables(&points, Some(&weights))
        },
    );
    engine.register_fn(
        "bezier_patch",
        |points: Array| -> ScriptResult<BezierPatch> { patch_from_tables(&points, None) },
    );
    engine.register_fn(
        "flat_rectangle",
        |corner: Array, edge_u: Array, edge_v: Array| -> ScriptResult<BezierPatch> {
            lift(BezierPatch::parallelogram(
                vec3(&corner, "flat_rectangle corner")?,
                vec3(&edge_u, "flat_rectangle edge_u")?,
                vec3(&edge_v, "flat_rectangle edge_v")?,
            ))
        },
    );
    // cylinder_patch(axis_point, axis, reference, start_deg, sweep_deg, radius, length)
    engine.register_fn(
        "cylinder_patch",
        |axis_point: Array,
         axis: Array,
         reference: Array,
         start: Dynamic,
         sweep: Dynamic,
         radius: Dynamic,
         length: Dynamic|
         -> ScriptResult<BezierPatch> {
            lift(BezierPatch::cylinder_patch(
                vec3(&axis_point, "cylinder_patch axis point")?,
                vec3(&axis, "cylinder_patch axis")?,
                vec3(&reference, "cylinder_patch reference")?,
                degrees(&start, "cylinder_patch start angle")?,
                degrees(&sweep, "cylinder_patch sweep")?,
                number(&radius, "cylinder_patch radius")?,
                number(&length, "cylinder_patch length")?,
            ))
        },
    );
    // torus_patch(center, axis, reference, [major_start, major_sweep],
    //             [minor_start, minor_sweep], major_radius, minor_radius), angles in degrees
    engine.register_fn(
        "torus_patch",
        |center: Array,
         axis: Array,
         reference: Array,
         major: Array,
         minor: Array,
         major_radius: Dynamic,
         minor_radius: Dynamic|
         -> ScriptResult<BezierPatch> {
            lift(BezierPatch::torus_patch(
                vec3(&center, "torus_patch center")?,
                vec3(&axis, "torus_patch axis")?,
                vec3(&reference, "torus_patch reference")?,
                angle_pair(&major, "torus_patch major angles")?,
                angle_pair(&minor, "torus_patch minor angles")?,
                number(&major_radius, "torus_patch major radius")?,
                number(&minor_radius, "torus_patch minor radius")?,
            ))
        },
    );
    engine.register_fn("flip", |p: &mut BezierPatch| p.clone().flipped());
    engine.register_fn("to_string", |p: &mut BezierPatch| {
        let (du, dv) = p.degrees();
        format!("bezier patch of degree {du} x {dv}")
    });
}

fn patch_list(list: &Array) -> ScriptResult<Vec<BezierPatch>> {
    list.iter()
        .enumerate()
        .map(|(k, p)| {
            p.clone()
                .try_cast::<BezierPatch>()
                .ok_or_else(|| {
                    format!(
                        "patch_surface entry {k} must be a Patch, got {}",
                        p.type_name()
                    )
                })
                .or_else(runtime_error)
        })
        .collect()
}

fn surface(s: PatchSurface) -> ScriptSurface {
    ScriptSurface(Arc::new(s))
}

fn register_surfaces(engine: &mut Engine, policy: std::rc::Rc<crate::paths::ReadPolicy>) {
    engine.register_fn(
        "patch_surface",
        |list: Array| -> ScriptResult<ScriptSurface> {
            Ok(surface(lift(PatchSurface::new(patch_list(&list)?))?))
        },
    );
    // patch_surface(patches, outside_point): refuses inward-facing patches.
    engine.register_fn(
        "patch_surface",
        |list: Array, outside: Array| -> ScriptResult<ScriptSurface> {
            Ok(surface(lift(PatchSurface::with_outside_point(
                patch_list(&list)?,
                vec3(&outside, "patch_surface outside point")?,
            ))?))
        },
    );
    // bezier_surface_json(path): relative to the script's folder, read through the policy.
    engine.register_fn(
        "bezier_surface_json",
        move |path: &str| -> ScriptResult<ScriptSurface> {
            let (_, text) = lift(policy.read_to_string(path, "JSON table"))?;
            let (patches, outside) = lift(patches_from_json(path, &text))?;
            Ok(surface(lift(match outside {
                Some(p) => PatchSurface::with_outside_point(patches, p),
                None => PatchSurface::new(patches),
            })?))
        },
    );
    // surface.seam_report(): worst gap and kink where the patches meet.
    engine.register_fn(
        "seam_report",
        |s: &mut ScriptSurface| -> ScriptResult<Map> {
            let Some(p) = s.0.as_patch_surface() else {
                return runtime_error(format!(
                    "seam_report needs a Bezier patch surface, not {}",
                    s.0.describe()
                ));
            };
            let r = p.seams();
            let mut m = Map::new();
            m.insert("patches".into(), Dynamic::from(p.patches().len() as i64));
            m.insert("worst_gap".into(), Dynamic::from(r.worst_gap));
            m.insert(
                "worst_gap_at".into(),
                Dynamic::from(array3(&r.worst_gap_at)),
            );
            m.insert(
                "worst_kink_deg".into(),
                Dynamic::from(r.worst_kink.to_degrees()),
            );
            m.insert(
                "worst_kink_at".into(),
                Dynamic::from(array3(&r.worst_kink_at)),
            );
            m.insert("seam_points".into(), Dynamic::from(r.seam_points as i64));
            m.insert("free_points".into(), Dynamic::from(r.free_points as i64));
            Ok(m)
        },
    );
}

/// Named numeric parameters of a builder: every key known, every required one present.
struct Params<'a> {
    tool: &'a str,
    map: &'a Map,
}

impl Params<'_> {
    fn check_keys(&self, known: &[&str]) -> ScriptResult<()> {
        for key in self.map.keys() {
            if !known.contains(&key.as_str()) {
                return runtime_error(format!(
                    "{} parameter '{key}' is unknown; expected {}",
                    self.tool,
                    known.join(", ")
                ));
            }
        }
        Ok(())
    }

    fn get(&self, key: &str) -> ScriptResult<f64> {
        match self.map.get(key) {
            Some(v) => number(v, &format!("{} {key}", self.tool)),
            None => runtime_error(format!("{} parameter '{key}' is missing", self.tool)),
        }
    }

    /// An optional parameter, `default` when absent.
    fn get_or(&self, key: &str, default: f64) -> ScriptResult<f64> {
        match self.map.get(key) {
            Some(v) => number(v, &format!("{} {key}", self.tool)),
            None => Ok(default),
        }
    }

    /// Quarter (`quarter_margin` given) or full tool.
    fn extent(&self) -> ScriptResult<Extent> {
        match self.map.get("quarter_margin") {
            None => Ok(Extent::Full),
            Some(v) => Ok(Extent::Quarter {
                margin: number(v, &format!("{} quarter_margin", self.tool))?,
            }),
        }
    }
}

fn register_builders(engine: &mut Engine) {
    engine.register_fn("punch_surface", |map: Map| -> ScriptResult<ScriptSurface> {
        let p = Params {
            tool: "punch",
            map: &map,
        };
        p.check_keys(&[
            "side",
            "corner_radius",
            "nose_radius",
            "wall_height",
            "level",
            "quarter_margin",
        ])?;
        let spec = PunchSpec {
            side: p.get("side")?,
            plan_corner_radius: p.get("corner_radius")?,
            nose_radius: p.get("nose_radius")?,
            wall_height: p.get("wall_height")?,
            level: p.get("level")?,
        };
        let patches = lift(punch_patches(&spec, p.extent()?))?;
        Ok(surface(lift(PatchSurface::new(patches))?))
    });
    engine.register_fn("die_surface", |map: Map| -> ScriptResult<ScriptSurface> {
        let p = Params {
            tool: "die",
            map: &map,
        };
        p.check_keys(&[
            "opening_side",
            "corner_radius",
            "entry_radius",
            "flat_extent",
            "wall_depth",
            "level",
            "quarter_margin",
        ])?;
        let spec = DieSpec {
            opening_side: p.get("opening_side")?,
            plan_corner_radius: p.get("corner_radius")?,
            entry_radius: p.get("entry_radius")?,
            flat_extent: p.get("flat_extent")?,
            wall_depth: p.get("wall_depth")?,
            level: p.get("level")?,
        };
        let patches = lift(die_patches(&spec, p.extent()?))?;
        Ok(surface(lift(PatchSurface::new(patches))?))
    });
    engine.register_fn(
        "blankholder_surface",
        |map: Map| -> ScriptResult<ScriptSurface> {
            let p = Params {
                tool: "blankholder",
                map: &map,
            };
            p.check_keys(&[
                "opening_side",
                "corner_radius",
                "flat_extent",
                "level",
                "edge_radius",
                "wall_height",
                "quarter_margin",
            ])?;
            let spec = BlankholderSpec {
                opening_side: p.get("opening_side")?,
                plan_corner_radius: p.get("corner_radius")?,
                flat_extent: p.get("flat_extent")?,
                level: p.get("level")?,
                edge_radius: p.get_or("edge_radius", 0.0)?,
                wall_height: p.get_or("wall_height", 20.0)?,
            };
            let patches = lift(blankholder_patches(&spec, p.extent()?))?;
            Ok(surface(lift(PatchSurface::new(patches))?))
        },
    );
}
