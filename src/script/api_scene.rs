//! Scene objects for scripts: meshes, materials, tool surfaces, schedules, friction laws and
//! tools. Registered in one place; scripts see only these functions.

use super::convert::*;
use crate::contact::{BernsteinLaw, FrictionLaw, WorkMeasure};
use crate::geometry::{Cylinder, Plane, RigidSurface, Sphere};
use crate::material::{Chaboche, ElastoPlastic, Hardening, Hill48, LinearElastic, Material};
use crate::mesh::{End, Grading, Mesh};
use crate::tool::schedule::{ScalarSchedule, Schedule};
use crate::tool::Tool;
use rhai::{Array, Dynamic, Engine, FnPtr, Map, NativeCallContext};
use std::sync::Arc;

/// A material as scripts hold it.
#[derive(Clone, Debug)]
pub struct ScriptMaterial(pub Arc<dyn Material>);

/// A tool surface as scripts hold it.
#[derive(Clone, Debug)]
pub struct ScriptSurface(pub Arc<dyn RigidSurface>);

pub fn register(engine: &mut Engine, host: std::rc::Rc<super::HostOptions>) {
    register_mesh(engine, &host);
    register_material(engine);
    register_tools(engine);
    register_friction(engine, host);
}

fn work_measure(name: &str) -> ScriptResult<WorkMeasure> {
    match name {
        "per_node" => Ok(WorkMeasure::PerNode),
        "per_area" => Ok(WorkMeasure::PerArea),
        other => runtime_error(format!(
            "work measure '{other}' must be \"per_node\" or \"per_area\""
        )),
    }
}

fn register_friction(engine: &mut Engine, host: std::rc::Rc<super::HostOptions>) {
    // bernstein([P0, ..., Pm], work_cut [, "per_node" | "per_area"])
    engine.register_fn(
        "bernstein",
        |points: Array, work_cut: Dynamic| -> ScriptResult<FrictionLaw> {
            let p = points
                .iter()
                .map(|v| number(v, "Bernstein control point"))
                .collect::<ScriptResult<Vec<f64>>>()?;
            Ok(FrictionLaw::Bernstein(lift(BernsteinLaw::new(
                p,
                number(&work_cut, "work_cut")?,
                WorkMeasure::PerNode,
            ))?))
        },
    );
    engine.register_fn(
        "bernstein",
        |points: Array, work_cut: Dynamic, measure: &str| -> ScriptResult<FrictionLaw> {
            let p = points
                .iter()
                .map(|v| number(v, "Bernstein control point"))
                .collect::<ScriptResult<Vec<f64>>>()?;
            let law = BernsteinLaw::new(p, number(&work_cut, "work_cut")?, work_measure(measure)?);
            Ok(FrictionLaw::Bernstein(lift(law)?))
        },
    );
    // mu(theta) of a law, for plotting or checking: law.mu_at(theta)
    engine.register_fn(
        "mu_at",
        |law: &mut FrictionLaw, theta: f64| -> ScriptResult<f64> {
            if !theta.is_finite() {
                return fail(crate::Error::input("mu_at theta", theta, "must be finite"));
            }
            match law {
                FrictionLaw::Bernstein(l) if !(0.0..=1.0).contains(&theta) => {
                    fail(crate::Error::input(
                        "mu_at theta",
                        theta,
                        "must be in [0, 1] (theta is the work over work_cut, saturated at 1)",
                    ))
                }
                FrictionLaw::Bernstein(l) => Ok(l.mu_of_theta(theta)),
                FrictionLaw::Coulomb { mu } => Ok(*mu),
                _ => runtime_error("mu_at needs a Coulomb or Bernstein law"),
            }
        },
    );
    // tool.friction(|work, slip, pressure| mu): a script function of the node's state,
    // called once per contact node after each converged increment.
    engine.register_fn(
        "friction",
        move |ctx: NativeCallContext, t: &mut Tool, law: FnPtr| -> ScriptResult<Tool> {
            let initial = law.call_within_context::<f64>(&ctx, (0.0, 0.0, 0.0))?;
            lift(crate::contact::friction::check_mu(
                &format!("friction function of tool '{}' at zero work", t.name),
                initial,
            ))?;
            let source = {
                let sources = host.sources.borrow();
                let text = ctx.call_source().and_then(|name| sources.get(name));
                let p = ctx.call_position();
                super::law_source::describe(
                    &law,
                    text.map(|t| &**t),
                    p.line().unwrap_or(0),
                    p.position().unwrap_or(0),
                )
            };
            host.script_laws.borrow_mut().insert(t.name.clone(), law);
            t.friction = FrictionLaw::External { initial, source };
            Ok(t.clone())
        },
    );
}

fn parse_grading(spec: &Map) -> ScriptResult<[Grading; 3]> {
    let mut g = [Grading::Uniform, Grading::Uniform, Grading::Uniform];
    for (key, value) in spec {
        let axis = match key.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            other => return runtime_error(format!("grading axis '{other}' must be x, y or z")),
        };
        let pair = value
            .clone()
            .try_cast::<Array>()
            .filter(|a| a.len() == 2)
            .ok_or_else(|| format!("grading.{key} must be [\"min\" or \"max\", ratio]"))
            .or_else(runtime_error)?;
        let end = match pair[0].clone().into_string().unwrap_or_default().as_str() {
            "min" => End::Min,
            "max" => End::Max,
            other => {
                return runtime_error(format!(
                    "grading.{key}[0] = '{other}' must be \"min\" or \"max\""
                ))
            }
        };
        let ratio = number(&pair[1], &format!("grading.{key}[1]"))?;
        g[axis] = Grading::Toward { end, ratio };
    }
    Ok(g)
}

/// The cell counts of a block, refused before the mesh is built when its estimated memory is
/// over the run's limit.
fn block_cells(cells: &Array, limits: &super::limits::Limits) -> ScriptResult<[usize; 3]> {
    let n = counts3(cells, "block cells")?;
    let nodes = n.iter().fold(1u64, |acc, &k| {
        acc.saturating_mul((k as u64).saturating_add(1))
    });
    limits.check_mesh(nodes).or_else(runtime_error)?;
    Ok(n)
}

fn register_mesh(engine: &mut Engine, host: &std::rc::Rc<super::HostOptions>) {
    let limits = host.limits.clone();
    engine.register_type_with_name::<Mesh>("Mesh");
    let l = limits.clone();
    engine.register_fn(
        "block",
        move |origin: Array, size: Array, cells: Array| -> ScriptResult<Mesh> {
            lift(Mesh::block(
                vec3(&origin, "block origin")?,
                vec3(&size, "block size")?,
                block_cells(&cells, &l)?,
            ))
        },
    );
    engine.register_fn(
        "block",
        move |origin: Array, size: Array, cells: Array, grading: Map| -> ScriptResult<Mesh> {
            lift(Mesh::block_graded(
                vec3(&origin, "block origin")?,
                vec3(&size, "block size")?,
                block_cells(&cells, &limits)?,
                parse_grading(&grading)?,
            ))
        },
    );
    engine.register_get("n_nodes", |m: &mut Mesh| m.nodes.len() as i64);
    engine.register_get("n_elements", |m: &mut Mesh| m.hexes.len() as i64);
    engine.register_fn(
        "node_set",
        |m: &mut Mesh, name: &str| -> ScriptResult<Array> {
            Ok(lift(m.node_set(name))?
                .iter()
                .map(|&n| Dynamic::from(n as i64))
                .collect())
        },
    );
    engine.register_fn(
        "position",
        |m: &mut Mesh, node: i64| -> ScriptResult<Array> {
            match m.nodes.get(node as usize) {
                Some(p) if node >= 0 => Ok(array3(p)),
                _ => runtime_error(format!(
                    "node {node} is out of range (mesh has {} nodes)",
                    m.nodes.len()
                )),
            }
        },
    );
    // Named node set from a predicate |x, y, z| -> bool over reference coordinates.
    let h = host.clone();
    engine.register_fn(
        "select",
        move |ctx: NativeCallContext, m: &mut Mesh, name: &str, pred: FnPtr| -> ScriptResult<i64> {
            if !h.simulations.is_empty() {
                if m.node_set(name).is_ok() {
                    // The simulation holds its own copy of the mesh: a changed set would
                    // reach this mesh only, and the run would use the old one unnoticed.
                    return runtime_error(format!(
                        "mesh.select(\"{name}\", ...): the set \"{name}\" already exists and a \
                         simulation was built from this mesh before this call, so it would keep \
                         the old set\n  select under a new name, or make the selection before \
                         simulation(mesh, ...)"
                    ));
                }
                h.late_sets.borrow_mut().insert(name.to_string());
            }
            let mut chosen = Vec::new();
            for (i, p) in m.nodes.iter().enumerate() {
                if pred.call_within_context::<bool>(&ctx, (p.x, p.y, p.z))? {
                    chosen.push(i);
                }
            }
            let count = chosen.len() as i64;
            lift(m.add_node_set(name, chosen))?;
            Ok(count)
        },
    );
    engine.register_fn(
        "nearest_node",
        |m: &mut Mesh, p: Array| -> ScriptResult<i64> {
            let q = vec3(&p, "point")?;
            m.nodes
                .iter()
                .enumerate()
                .min_by(|a, b| (a.1 - q).norm().total_cmp(&(b.1 - q).norm()))
                .map(|(i, _)| i as i64)
                .ok_or_else(|| "the mesh has no nodes".to_string())
                .or_else(runtime_error)
        },
    );
}

fn register_material(engine: &mut Engine) {
    engine.register_type_with_name::<ScriptMaterial>("Material");
    engine.register_fn(
        "linear_elastic",
        |e: Dynamic, nu: Dynamic| -> ScriptResult<ScriptMaterial> {
            let m = lift(LinearElastic::new(
                number(&e, "Young's modulus")?,
                number(&nu, "Poisson's ratio")?,
            ))?;
            Ok(ScriptMaterial(Arc::new(m)))
        },
    );
    engine.register_fn("to_string", |m: &mut ScriptMaterial| format!("{:?}", m.0));

    // Small-strain elastoplasticity: elastoplastic(E, nu, yield, hardening).
    engine.register_type_with_name::<Hardening>("Hardening");
    engine.register_type_with_name::<Hill48>("YieldFunction");
    engine.register_fn(
        "swift",
        |c: Dynamic, eps0: Dynamic, n: Dynamic| -> ScriptResult<Hardening> {
            lift(Hardening::swift(
                number(&c, "Swift C")?,
                number(&eps0, "Swift eps0")?,
                number(&n, "Swift n")?,
            ))
        },
    );
    engine.register_fn(
        "voce",
        |s0: Dynamic, q: Dynamic, b: Dynamic| -> ScriptResult<Hardening> {
            lift(Hardening::voce(
                number(&s0, "Voce s0")?,
                number(&q, "Voce Q")?,
                number(&b, "Voce b")?,
            ))
        },
    );
    engine.register_fn(
        "linear_hardening",
        |s0: Dynamic, h: Dynamic| -> ScriptResult<Hardening> {
            lift(Hardening::linear(
                number(&s0, "initial yield stress")?,
                number(&h, "hardening modulus")?,
            ))
        },
    );
    engine.register_fn(
        "hardening_table",
        |strain: Array, stress: Array| -> ScriptResult<Hardening> {
            let e = strain
                .iter()
                .map(|v| number(v, "table strain"))
                .collect::<ScriptResult<Vec<f64>>>()?;
            let s = stress
                .iter()
                .map(|v| number(v, "table stress"))
                .collect::<ScriptResult<Vec<f64>>>()?;
            lift(Hardening::tabulated(e, s))
        },
    );
    engine.register_fn("von_mises", Hill48::von_mises);
    engine.register_fn(
        "hill48",
        |r0: Dynamic, r45: Dynamic, r90: Dynamic| -> ScriptResult<Hill48> {
            lift(Hill48::from_lankford(
                number(&r0, "r0")?,
                number(&r45, "r45")?,
                number(&r90, "r90")?,
            ))
        },
    );
    // hill48(r0, r45, r90, rd): rolling direction at rd degrees from x about z.
    engine.register_fn(
        "hill48",
        |r0: Dynamic, r45: Dynamic, r90: Dynamic, rd: Dynamic| -> ScriptResult<Hill48> {
            let hill = lift(Hill48::from_lankford(
                number(&r0, "r0")?,
                number(&r45, "r45")?,
                number(&r90, "r90")?,
            ))?;
            lift(hill.with_rolling_angle(rolling_angle(&rd)?))
        },
    );
    engine.register_fn(
        "hill48_coefficients",
        |f: Dynamic,
         g: Dynamic,
         h: Dynamic,
         l: Dynamic,
         m: Dynamic,
         n: Dynamic|
         -> ScriptResult<Hill48> {
            lift(Hill48::new(
                number(&f, "Hill48 F")?,
                number(&g, "Hill48 G")?,
                number(&h, "Hill48 H")?,
                number(&l, "Hill48 L")?,
                number(&m, "Hill48 M")?,
                number(&n, "Hill48 N")?,
            ))
        },
    );
    engine.register_fn(
        "rolling_direction",
        |hill: &mut Hill48, rd: Dynamic| -> ScriptResult<Hill48> {
            lift(hill.with_rolling_angle(rolling_angle(&rd)?))
        },
    );
    engine.register_fn(
        "elastoplastic",
        |e: Dynamic,
         nu: Dynamic,
         yield_function: Hill48,
         hardening: Hardening|
         -> ScriptResult<ScriptMaterial> {
            let elastic = lift(LinearElastic::new(
                number(&e, "Young's modulus")?,
                number(&nu, "Poisson's ratio")?,
            ))?;
            Ok(ScriptMaterial(Arc::new(ElastoPlastic::new(
                elastic,
                yield_function,
                hardening,
            ))))
        },
    );
    register_kinematic(engine);
}

/// Mixed hardening: `chaboche([[C1, g1], ...])` (one to three Armstrong-Frederick terms)
/// and `elastoplastic(E, nu, yield, hardening, kinematic)`, the isotropic law and the back
/// stresses together (`material::kinematic`).
fn register_kinematic(engine: &mut Engine) {
    engine.register_type_with_name::<Chaboche>("KinematicHardening");
    engine.register_fn("chaboche", |terms: Array| -> ScriptResult<Chaboche> {
        let mut pairs = Vec::new();
        for (i, term) in terms.iter().enumerate() {
            let what = format!("chaboche term {} ([C, gamma])", i + 1);
            let Some(pair) = term.clone().try_cast::<Array>().filter(|p| p.len() == 2) else {
                return runtime_error(format!("{what} must be a pair [C, gamma], got {term}"));
            };
            pairs.push((number(&pair[0], &what)?, number(&pair[1], &what)?));
        }
        lift(Chaboche::new(&pairs))
    });
    engine.register_fn(
        "elastoplastic",
        |e: Dynamic,
         nu: Dynamic,
         yield_function: Hill48,
         hardening: Hardening,
         kinematic: Chaboche|
         -> ScriptResult<ScriptMaterial> {
            let elastic = lift(LinearElastic::new(
                number(&e, "Young's modulus")?,
                number(&nu, "Poisson's ratio")?,
            ))?;
            Ok(ScriptMaterial(Arc::new(
                ElastoPlastic::new(elastic, yield_function, hardening).with_kinematic(kinematic),
            )))
        },
    );
}

/// The rolling direction as an angle from x in radians, from degrees or from a vector
/// `[x, y, z]` in the sheet plane (z = 0; the sheet normal is z).
fn rolling_angle(rd: &Dynamic) -> ScriptResult<f64> {
    let Some(v) = rd.clone().try_cast::<Array>() else {
        return Ok(number(rd, "rolling-direction angle (degrees)")?.to_radians());
    };
    let d = vec3(&v, "rolling direction")?;
    if d.z != 0.0 || d.x.hypot(d.y) == 0.0 || !d.iter().all(|c| c.is_finite()) {
        return runtime_error(format!(
            "rolling direction [{}, {}, {}] must be a non-zero vector in the sheet plane (z = 0)",
            d.x, d.y, d.z
        ));
    }
    Ok(d.y.atan2(d.x))
}

fn schedule_points(table: &Array, columns: usize) -> ScriptResult<Vec<Vec<f64>>> {
    let mut rows = Vec::new();
    for (i, row) in table.iter().enumerate() {
        let row = row
            .clone()
            .try_cast::<Array>()
            .filter(|r| r.len() == columns)
            .ok_or_else(|| format!("schedule row {i} must be an array of {columns} numbers"))
            .or_else(runtime_error)?;
        rows.push(
            row.iter()
                .map(|v| number(v, &format!("schedule row {i}")))
                .collect::<ScriptResult<Vec<f64>>>()?,
        );
    }
    Ok(rows)
}

/// `[[t, dx, dy, dz], ...]` -> translation schedule.
pub fn translation_schedule(table: &Array) -> ScriptResult<Schedule> {
    let rows = schedule_points(table, 4)?;
    lift(Schedule::new(
        rows.iter()
            .map(|r| (r[0], crate::geometry::Vec3::new(r[1], r[2], r[3])))
            .collect(),
    ))
}

/// A number (constant) or `[[t, v], ...]` -> scalar schedule.
pub fn scalar_schedule(value: &Dynamic) -> ScriptResult<ScalarSchedule> {
    if let Some(table) = value.clone().try_cast::<Array>() {
        let rows = schedule_points(&table, 2)?;
        lift(ScalarSchedule::new(
            rows.iter().map(|r| (r[0], r[1])).collect(),
        ))
    } else {
        let v = number(value, "value")?;
        if !v.is_finite() {
            return fail(crate::Error::input("value", v, "must be finite"));
        }
        Ok(ScalarSchedule::constant(v))
    }
}

fn register_tools(engine: &mut Engine) {
    engine.register_type_with_name::<ScriptSurface>("Surface");
    engine.register_fn(
        "plane",
        |p: Array, n: Array| -> ScriptResult<ScriptSurface> {
            Ok(ScriptSurface(Arc::new(lift(Plane::new(
                vec3(&p, "plane point")?,
                vec3(&n, "plane normal")?,
            ))?)))
        },
    );
    engine.register_fn(
        "cylinder",
        |p: Array, axis: Array, r: Dynamic| -> ScriptResult<ScriptSurface> {
            let c = Cylinder::new(
                vec3(&p, "cylinder axis point")?,
                vec3(&axis, "cylinder axis")?,
                number(&r, "cylinder radius")?,
            );
            Ok(ScriptSurface(Arc::new(lift(c)?)))
        },
    );
    engine.register_fn(
        "sphere",
        |c: Array, r: Dynamic| -> ScriptResult<ScriptSurface> {
            Ok(ScriptSurface(Arc::new(lift(Sphere::new(
                vec3(&c, "sphere centre")?,
                number(&r, "sphere radius")?,
            ))?)))
        },
    );
    engine.register_fn("to_string", |s: &mut ScriptSurface| s.0.describe());

    engine.register_type_with_name::<FrictionLaw>("FrictionLaw");
    engine.register_fn("coulomb", |mu: Dynamic| -> ScriptResult<FrictionLaw> {
        lift(FrictionLaw::coulomb(number(
            &mu,
            "friction coefficient mu",
        )?))
    });
    engine.register_fn("frictionless", FrictionLaw::frictionless);
    engine.register_fn("to_string", |f: &mut FrictionLaw| f.describe());

    engine.register_type_with_name::<Tool>("Tool");
    engine.register_fn("tool", |name: &str, s: ScriptSurface| Tool::new(name, s.0));
    // tool.path([[t, dx, dy, dz], ...]): piecewise-linear translation against time.
    engine.register_fn("path", |t: &mut Tool, table: Array| -> ScriptResult<Tool> {
        let rotation = t.schedule.rotation().cloned();
        t.schedule = translation_schedule(&table)?.keeping_rotation(rotation);
        Ok(t.clone())
    });
    // tool.rotate(axis_point, axis, [[t, angle_deg], ...]): rotation about a fixed axis by a
    // piecewise-linear angle, applied before the path's translation.
    engine.register_fn(
        "rotate",
        |t: &mut Tool, point: Array, axis: Array, table: Array| -> ScriptResult<Tool> {
            let rows = schedule_points(&table, 2)?;
            t.schedule = lift(t.schedule.clone().with_rotation(
                vec3(&point, "rotation axis point")?,
                vec3(&axis, "rotation axis")?,
                rows.iter().map(|r| (r[0], r[1])).collect(),
            ))?;
            Ok(t.clone())
        },
    );
    // tool.force_control([ax, ay, az], force): the tool's offset along the axis becomes an
    // unknown fixed by the force it applies to the body along the axis (a number or
    // [[t, F], ...]).
    engine.register_fn(
        "force_control",
        |t: &mut Tool, axis: Array, force: Dynamic| -> ScriptResult<Tool> {
            let axis = vec3(&axis, &format!("force-control axis of tool '{}'", t.name))?;
            t.force_control = Some(lift(crate::tool::ForceControl::new(
                axis,
                scalar_schedule(&force)?,
            ))?);
            Ok(t.clone())
        },
    );
    engine.register_fn("friction", |t: &mut Tool, law: FrictionLaw| -> Tool {
        t.friction = law;
        t.clone()
    });
    register_wear(engine);
    engine.register_get("name", |t: &mut Tool| t.name.clone());
    engine.register_fn("to_string", |t: &mut Tool| {
        format!(
            "tool '{}': {}, {}",
            t.name,
            t.surface.describe(),
            t.friction.describe()
        )
    });
}

/// Archard wear laws and `tool.wear(law[, cell])`, which switches a tool's tool-side fields
/// on (src/tool/surface_fields.rs).
fn register_wear(engine: &mut Engine) {
    use crate::tool::{FieldSpec, WearLaw};
    engine.register_type_with_name::<WearLaw>("WearLaw");
    engine.register_fn(
        "archard",
        |k: Dynamic, h: Dynamic| -> ScriptResult<WearLaw> {
            lift(WearLaw::archard(
                number(&k, "Archard wear coefficient k")?,
                number(&h, "Archard hardness H")?,
            ))
        },
    );
    engine.register_fn(
        "archard_coefficient",
        |c: Dynamic| -> ScriptResult<WearLaw> {
            lift(WearLaw::dimensional(number(
                &c,
                "dimensional wear coefficient",
            )?))
        },
    );
    engine.register_fn("to_string", |w: &mut WearLaw| {
        format!("Archard wear, dh = {} p |ds|", w.coefficient)
    });
    engine.register_fn("wear", |t: &mut Tool, law: WearLaw| -> Tool {
        t.fields = Some(FieldSpec {
            wear: law,
            cell: None,
        });
        t.clone()
    });
    engine.register_fn(
        "wear",
        |t: &mut Tool, law: WearLaw, cell: Dynamic| -> ScriptResult<Tool> {
            let what = format!("cell size of the tool-side fields of tool '{}'", t.name);
            let cell = number(&cell, &what)?;
            if !(cell > 0.0 && cell.is_finite()) {
                return lift(Err(crate::Error::input(&what, cell, "must be > 0")));
            }
            t.fields = Some(FieldSpec {
                wear: law,
                cell: Some(cell),
            });
            Ok(t.clone())
        },
    );
    // tool.friction_of_tool_work(bernstein([...], w_cut)): mu of the tool's frictional work
    // per area at each node's foot, frozen at the stroke's start (solver::simulation::strokes).
    engine.register_fn(
        "friction_of_tool_work",
        |t: &mut Tool, law: FrictionLaw| -> ScriptResult<Tool> {
            let FrictionLaw::Bernstein(l) = law else {
                return runtime_error(format!(
                    "tool '{}': friction_of_tool_work needs a Bernstein law (bernstein([P0, ..., Pm], w_cut), w_cut the tool's work per area at which mu reaches Pm), not {}",
                    t.name,
                    law.describe()
                ));
            };
            t.friction = FrictionLaw::ToolWork(l);
            Ok(t.clone())
        },
    );
}

#[cfg(test)]
mod kinematic_tests {
    use super::ScriptMaterial;
    use crate::script::{engine, HostOptions};

    fn eval(src: &str) -> Result<ScriptMaterial, String> {
        engine(&HostOptions::default(), None)
            .eval::<ScriptMaterial>(src)
            .map_err(|e| e.to_string())
    }

    /// `chaboche` composes with every isotropic law and yield function through the
    /// five-argument `elastoplastic`; bad terms are errors naming the term and value.
    #[test]
    fn chaboche_from_a_script() {
        let m = eval(
            "elastoplastic(210000, 0.3, hill48(0.7, 1.3, 2.1), swift(500, 0.01, 0.22), \
             chaboche([[30000, 200], [5000, 20.0]]))",
        )
        .unwrap();
        let d = format!("{:?}", m.0);
        assert!(d.contains("Chaboche") && d.contains("30000"), "{d}");
        let m = eval(
            "elastoplastic(210000, 0.3, von_mises(), voce(200, 100, 8), chaboche([[1000, 0]]))",
        );
        assert!(m.is_ok());
        let err = eval("chaboche([[30000, 200], [-5, 1]])")
            .map(|_| ())
            .unwrap_err();
        assert!(err.contains("Chaboche term 2 C = -5"), "{err}");
        let err = eval("chaboche([[1, 1], [1, 1], [1, 1], [1, 1]])")
            .map(|_| ())
            .unwrap_err();
        assert!(err.contains("number of terms = 4"), "{err}");
        let err = eval("chaboche([[1000]])").map(|_| ()).unwrap_err();
        assert!(
            err.contains("chaboche term 1") && err.contains("[C, gamma]"),
            "{err}"
        );
    }
}
