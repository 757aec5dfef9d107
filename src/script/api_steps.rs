//! A process in named steps, for scripts: `sim.steps([...])` compiles a list of steps onto
//! the model's pseudo-time axis, `sim.run_step()` runs to the end of the current step and
//! `sim.step_name()` names the step the next increment falls in.
//!
//! Step `k` lasts `duration_k` of pseudo-time, `(t_{k-1}, t_k]`. Its tools map says, per
//! tool, what the tool does in the step:
//!
//! ```text
//! move: [dx, dy, dz]            translation change over the step, linear in time
//! force: F | [[f, F], ...]      force control along `axis`: the force the tool applies,
//!                               constant or piecewise linear in the fraction f in [0, 1]
//!                               of the step
//! axis: [ax, ay, az]            the force-control axis (the same in every step)
//! ramp_off: true                force control along `axis` from the tool's last force
//!                               to zero at the step's end (solver `simulation::release`)
//! (tool not named)              held where it is
//! ```
//!
//! A step's `supports: [[set_or_node, "xyz"], ...]` holds those node components where
//! they are during the step; `supports: "3-2-1"` asks for the default chosen from the mesh
//! (solver `rigid_modes::three_two_one`), and `[..., "3-2-1"]` for both.
//!
//! A step's `end_when: #{ tool: name, force: F }` or `end_when: #{ tool: name, contact: "lost" }`
//! ends it at the first increment where the tool's contact force magnitude reaches `F`
//! or no node touches the tool; the rest of its pseudo-time is skipped and the tools hold
//! where they were (solver `simulation::step_end`).
//!
//! Compiled: a tool's translation becomes the piecewise-linear schedule through its
//! translation at every step end (`u_k = u_{k-1} + move_k`), and a tool force-controlled in
//! some step gets one `ForceControl` whose `windows` are those steps and whose force
//! schedule is the steps' forces mapped onto pseudo-time. Between its windows the tool is
//! kinematic and keeps the offset it reached (solver `force_control`), so its position is
//! continuous when control switches. A step's force that starts at the previous step's last
//! force goes on from it; one that jumps there is placed a millionth of the step after the
//! start (the step's window opens after its start).

use super::api_scene::scalar_schedule;
use super::api_sim::ScriptSim;
use super::convert::*;
use crate::geometry::Vec3;
use crate::solver::model::steps::{Condition, Step, Support, Until};
use crate::solver::model::Model;
use crate::tool::{ForceControl, ScalarSchedule, Schedule};
use rhai::{Array, Dynamic, Engine, Map};

/// What one tool does in one step.
#[derive(Default)]
struct ToolStep {
    movement: Vec3,
    /// (fraction of the step, force) points.
    force: Option<Vec<(f64, f64)>>,
    axis: Option<Vec3>,
    /// The tool's force ramped from its last value to zero over the step.
    ramp_off: bool,
}

pub fn register(engine: &mut Engine) {
    engine.register_fn(
        "steps",
        |s: &mut ScriptSim, list: Array| -> ScriptResult<()> {
            let mut st = s.borrow_mut();
            let model = st.model_mut()?;
            compile(model, &list)
        },
    );
    engine.register_fn(
        "section_angles",
        |s: &mut ScriptSim, nodes: Array| -> ScriptResult<Map> { section_angles(s, &nodes) },
    );
    engine.register_fn("step_name", |s: &mut ScriptSim| -> ScriptResult<Dynamic> {
        let mut st = s.borrow_mut();
        let sim = st.simulation()?;
        Ok(match sim.current_step() {
            Some(k) => Dynamic::from(sim.model.steps[k].name.clone()),
            None => Dynamic::UNIT,
        })
    });
}

/// `sim.section_angles(nodes)`: the section measures of the nodes (in order along the
/// section) between the loaded shape and the committed one (solver
/// `simulation::section_angles`), also written to summary.json as `section_angles` when the
/// simulation writes output.
fn section_angles(s: &mut ScriptSim, nodes: &Array) -> ScriptResult<Map> {
    let mut list = Vec::with_capacity(nodes.len());
    for (i, v) in nodes.iter().enumerate() {
        match v.clone().try_cast::<i64>() {
            Some(k) if k >= 0 => list.push(k as usize),
            _ => {
                return runtime_error(format!(
                    "sim.section_angles: entry {i} of the node list is {v}, not a node index"
                ))
            }
        }
    }
    let mut st = s.borrow_mut();
    let measured = lift(st.simulation()?.section_angles(&list))?;
    let json = serde_json::to_value(measured).map_err(|e| {
        Box::new(rhai::EvalAltResult::ErrorRuntime(
            e.to_string().into(),
            rhai::Position::NONE,
        ))
    })?;
    if st.has_output() {
        st.add_summary_entry("section_angles", json.clone())?;
    }
    Ok(super::convert::from_json(&json)
        .try_cast::<Map>()
        .unwrap_or_default())
}

/// Reads the list and rewrites the tools' schedules and force control of `model`.
fn compile(model: &mut Model, list: &Array) -> ScriptResult<()> {
    if list.is_empty() {
        return runtime_error("sim.steps([...]): the list of steps is empty");
    }
    if !model.steps.is_empty() {
        return runtime_error("sim.steps: the steps are already given (call it once)");
    }
    let names: Vec<String> = model.contacts.iter().map(|c| c.tool.name.clone()).collect();
    let mut steps = Vec::new();
    let mut plans: Vec<Vec<ToolStep>> = Vec::new();
    let mut end = 0.0;
    for (i, item) in list.iter().enumerate() {
        let Some(map) = item.clone().try_cast::<Map>() else {
            return runtime_error(format!(
                "step {i}: expected a map #{{ name, duration, ... }}"
            ));
        };
        let (step, plan) = read_step(i, &map, &names, end, model)?;
        end = step.end;
        steps.push(step);
        plans.push(plan);
    }
    lift(crate::solver::model::steps::validate(&steps))?;
    for (c, name) in names.iter().enumerate() {
        let tool = &mut model.contacts[c].tool;
        if tool.schedule.points().len() > 1 || tool.force_control.is_some() {
            return runtime_error(format!(
                "tool '{name}' has a path or force control of its own: in a process of steps, give its motion in the steps (move, force)"
            ));
        }
        let per_step: Vec<&ToolStep> = plans.iter().map(|p| &p[c]).collect();
        let rotation = tool.schedule.rotation().cloned();
        tool.schedule = lift(translation_schedule(
            tool.schedule.translation(0.0),
            &steps,
            &per_step,
        ))?
        .keeping_rotation(rotation);
        tool.force_control = force_control(name, &steps, &per_step)?;
    }
    model.settings.end_time = end;
    model.settings.increments = steps.iter().map(|s| s.increments).sum();
    model.steps = steps;
    Ok(())
}

/// One step's map: `name`, `duration` (> 0), `increments` (>= 1, default 10) and `tools`.
fn read_step(
    i: usize,
    map: &Map,
    names: &[String],
    start: f64,
    model: &Model,
) -> ScriptResult<(Step, Vec<ToolStep>)> {
    for key in map.keys() {
        if ![
            "name",
            "duration",
            "increments",
            "tools",
            "end_when",
            "release",
            "supports",
        ]
        .contains(&key.as_str())
        {
            return runtime_error(format!(
                "step {i}: unknown key '{key}' (expected name, duration, increments, tools, end_when, release, supports)"
            ));
        }
    }
    let name = match map.get("name").and_then(|v| v.clone().into_string().ok()) {
        Some(n) => n,
        None => return runtime_error(format!("step {i}: `name` (a string) is missing")),
    };
    let at = format!("step {i} ('{name}')");
    let duration = match map.get("duration") {
        Some(v) => number(v, &format!("{at} duration"))?,
        None => return runtime_error(format!("{at}: `duration` is missing")),
    };
    if !(duration > 0.0 && duration.is_finite()) {
        return runtime_error(format!("{at}: duration = {duration} must be > 0"));
    }
    let increments = match map.get("increments") {
        None => 10,
        Some(v) => match v.as_int() {
            Ok(n) if n >= 1 => n as usize,
            _ => return runtime_error(format!("{at}: increments = {v} must be an integer >= 1")),
        },
    };
    let mut plan: Vec<ToolStep> = names.iter().map(|_| ToolStep::default()).collect();
    if let Some(tools) = map.get("tools") {
        let Some(tools) = tools.clone().try_cast::<Map>() else {
            return runtime_error(format!(
                "{at}: `tools` must be a map #{{ tool_name: #{{ ... }} }}"
            ));
        };
        for (tool, spec) in &tools {
            let Some(c) = names.iter().position(|n| n == tool.as_str()) else {
                return runtime_error(format!(
                    "{at}: no tool named '{tool}' (the tools added so far: {})",
                    names.join(", ")
                ));
            };
            plan[c] = read_tool_step(&format!("{at}, tool '{tool}'"), spec)?;
        }
    }
    let until = match map.get("end_when") {
        None => None,
        Some(v) => Some(read_until(&at, v, names)?),
    };
    let release = match map.get("release") {
        None => false,
        Some(v) => match v.as_bool() {
            Ok(b) => b,
            Err(_) => return runtime_error(format!("{at}: release = {v} must be true or false")),
        },
    };
    let (supports, three_two_one) = match map.get("supports") {
        None => (Vec::new(), false),
        Some(v) => read_supports(&at, v, model)?,
    };
    let step = Step {
        name,
        end: start + duration,
        increments,
        until,
        release,
        supports,
        three_two_one,
        ramp_off: (0..names.len()).filter(|&c| plan[c].ramp_off).collect(),
    };
    Ok((step, plan))
}

/// A step's supports: `"3-2-1"`, or a list of `[set_or_node, "xyz"]` pairs and
/// `"3-2-1"`. Returns the supports and whether the 3-2-1 default is asked for.
fn read_supports(at: &str, v: &Dynamic, model: &Model) -> ScriptResult<(Vec<Support>, bool)> {
    let expected = "expected \"3-2-1\" or [[set_or_node, \"xyz\"], ...]";
    if let Ok(text) = v.clone().into_string() {
        if text == "3-2-1" {
            return Ok((Vec::new(), true));
        }
        return runtime_error(format!("{at} supports: \"{text}\" is unknown ({expected})"));
    }
    let Some(list) = v.clone().try_cast::<Array>() else {
        return runtime_error(format!("{at} supports: {expected}"));
    };
    let (mut supports, mut default) = (Vec::new(), false);
    for (j, item) in list.iter().enumerate() {
        let here = format!("{at} supports[{j}]");
        if item.clone().into_string().ok().as_deref() == Some("3-2-1") {
            default = true;
            continue;
        }
        let pair = item.clone().try_cast::<Array>().unwrap_or_default();
        let [place, components] = pair.as_slice() else {
            return runtime_error(format!("{here}: {expected}"));
        };
        let (label, nodes) = if let Ok(n) = place.as_int() {
            let count = model.mesh.nodes.len();
            if n < 0 || n as usize >= count {
                return runtime_error(format!(
                    "{here}: node {n} is not in the mesh ({count} nodes, 0 to {})",
                    count.saturating_sub(1)
                ));
            }
            (format!("node {n}"), vec![n as usize])
        } else if let Ok(set) = place.clone().into_string() {
            let nodes = model.nodes(&set).map_err(|e| format!("{here}: {e}"))?;
            (set, nodes)
        } else {
            return runtime_error(format!(
                "{here}: {place} is neither a node set's name nor a node number"
            ));
        };
        let Ok(text) = components.clone().into_string() else {
            return runtime_error(format!(
                "{here}: the directions {components} must be a string such as \"xz\""
            ));
        };
        let components =
            crate::solver::model::parse_components(&text).map_err(|e| format!("{here}: {e}"))?;
        for component in components {
            supports.push(Support {
                label: label.clone(),
                nodes: nodes.clone(),
                component,
            });
        }
    }
    Ok((supports, default))
}

/// A step's condition: `#{ tool: name, force: F }` (F > 0) or `#{ tool: name, contact:
/// "lost" }`.
fn read_until(at: &str, v: &Dynamic, names: &[String]) -> ScriptResult<Until> {
    let expected = "expected #{ tool: name, force: F } or #{ tool: name, contact: \"lost\" }";
    let Some(map) = v.clone().try_cast::<Map>() else {
        return runtime_error(format!("{at} end_when: {expected}"));
    };
    if let Some(key) = map
        .keys()
        .find(|k| !["tool", "force", "contact"].contains(&k.as_str()))
    {
        return runtime_error(format!("{at} end_when: unknown key '{key}' ({expected})"));
    }
    let tool = match map.get("tool").and_then(|t| t.clone().into_string().ok()) {
        Some(t) => t,
        None => return runtime_error(format!("{at} end_when: `tool` (a string) is missing")),
    };
    let Some(c) = names.iter().position(|n| *n == tool) else {
        return runtime_error(format!(
            "{at} end_when: no tool named '{tool}' (the tools added so far: {})",
            names.join(", ")
        ));
    };
    let condition = match (map.get("force"), map.get("contact")) {
        (Some(f), None) => {
            let f = number(f, &format!("{at} end_when force"))?;
            if !(f.is_finite() && f > 0.0) {
                return runtime_error(format!("{at} end_when: force = {f} must be > 0"));
            }
            Condition::Force(f)
        }
        (None, Some(c)) if c.clone().into_string().ok().as_deref() == Some("lost") => {
            Condition::ContactLost
        }
        (None, Some(c)) => {
            return runtime_error(format!(
                "{at} end_when: contact = {c} (only \"lost\" is known)"
            ))
        }
        _ => {
            return runtime_error(format!(
                "{at} end_when: give one of force or contact ({expected})"
            ))
        }
    };
    Ok(Until { tool: c, condition })
}

/// A tool's map in a step: `move`, `force`, `axis`.
fn read_tool_step(at: &str, spec: &Dynamic) -> ScriptResult<ToolStep> {
    let Some(spec) = spec.clone().try_cast::<Map>() else {
        return runtime_error(format!("{at}: expected a map #{{ move, force, axis }}"));
    };
    let mut out = ToolStep::default();
    for (key, v) in &spec {
        match key.as_str() {
            "move" => out.movement = vec3(&array(at, key, v)?, &format!("{at} move"))?,
            "axis" => out.axis = Some(vec3(&array(at, key, v)?, &format!("{at} axis"))?),
            "ramp_off" => match v.as_bool() {
                Ok(b) => out.ramp_off = b,
                Err(_) => {
                    return runtime_error(format!("{at}: ramp_off = {v} must be true or false"))
                }
            },
            "force" => {
                let points = scalar_schedule(v)
                    .map_err(|e| format!("{at} force: {e}"))?
                    .points()
                    .to_vec();
                if points.iter().any(|p| !(0.0..=1.0).contains(&p.0)) {
                    return runtime_error(format!(
                        "{at}: force times are fractions of the step, in [0, 1]"
                    ));
                }
                out.force = Some(points);
            }
            other => {
                return runtime_error(format!(
                    "{at}: unknown key '{other}' (expected move, force, axis, ramp_off)"
                ))
            }
        }
    }
    if out.force.is_some() && out.movement != Vec3::zeros() {
        return runtime_error(format!("{at}: give either move or force, not both"));
    }
    if out.ramp_off && (out.force.is_some() || out.movement != Vec3::zeros()) {
        return runtime_error(format!(
            "{at}: ramp_off sets the tool's force (from its last value to zero): give no move or force with it"
        ));
    }
    Ok(out)
}

fn array(at: &str, key: &str, v: &Dynamic) -> ScriptResult<Array> {
    match v.clone().try_cast::<Array>() {
        Some(a) => Ok(a),
        None => runtime_error(format!("{at}: {key} must be an array [x, y, z]")),
    }
}

/// The translation through `u0` at 0 and `u_{k-1} + move_k` at each step's end.
fn translation_schedule(u0: Vec3, steps: &[Step], plan: &[&ToolStep]) -> crate::Result<Schedule> {
    let mut points = vec![(0.0, u0)];
    let mut u = u0;
    for (s, p) in steps.iter().zip(plan) {
        u += p.movement;
        points.push((s.end, u));
    }
    Schedule::new(points)
}

/// The force control of a tool force-controlled in some steps (`None` in none).
fn force_control(
    name: &str,
    steps: &[Step],
    plan: &[&ToolStep],
) -> ScriptResult<Option<ForceControl>> {
    let mut axis: Option<Vec3> = None;
    let mut points: Vec<(f64, f64)> = Vec::new();
    let mut windows = Vec::new();
    for (k, (s, p)) in steps.iter().zip(plan).enumerate() {
        let at = format!("step {k} ('{}'), tool '{name}'", s.name);
        if p.axis.is_some() && p.force.is_none() && !p.ramp_off {
            return runtime_error(format!("{at}: an axis without a force"));
        }
        // A ramp's force is set as the run goes (solver `simulation::release`): its
        // schedule here holds a zero at the step's end.
        let ramp = [(1.0, 0.0)].to_vec();
        let Some(force) = p.force.as_ref().or(p.ramp_off.then_some(&ramp)) else {
            continue;
        };
        match (axis, p.axis) {
            (None, None) if p.ramp_off => {
                return runtime_error(format!(
                    "{at}: ramp_off needs the axis along which the tool pushes (axis: [ax, ay, az], here or in an earlier step)"
                ))
            }
            (None, None) => return runtime_error(format!("{at}: force control needs an axis")),
            (Some(a), Some(b)) if (a.normalize() - b.normalize()).norm() > 1e-12 => {
                return runtime_error(format!(
                    "{at}: axis [{}, {}, {}] differs from the earlier steps' (one axis per tool)",
                    b.x, b.y, b.z
                ))
            }
            (_, Some(b)) => axis = Some(b),
            _ => {}
        }
        let start = crate::solver::model::steps::start(steps, k);
        let length = s.end - start;
        // A constant force is held over the whole step.
        let force = if force.len() == 1 {
            vec![(0.0, force[0].1), (1.0, force[0].1)]
        } else {
            force.clone()
        };
        for (f, value) in force {
            let mut t = start + f * length;
            if let Some(&(last, previous)) = points.last() {
                if t <= last && value == previous {
                    // The force goes on from the previous step's last value.
                    continue;
                }
                if t <= last {
                    // The step's window opens after its start: a jump sits just inside.
                    t = last + 1e-6 * length;
                }
            }
            points.push((t, value));
        }
        windows.push((start, s.end));
    }
    let Some(axis) = axis else { return Ok(None) };
    let mut fc = lift(ForceControl::new(axis, lift(ScalarSchedule::new(points))?))?;
    fc.windows = windows;
    Ok(Some(fc))
}
