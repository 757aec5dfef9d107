//! Issue 53: production runs of several strokes (src/solver/model/strokes.rs,
//! src/solver/simulation/strokes.rs) on the roller drag of tests/tool_fields.rs (a roller of
//! two cylinder patches pressed into an elastic block and dragged along it, tool-side fields
//! on the roller), 12 increments a stroke.
//!
//! - Two simulated strokes with a law independent of the tool's state: the roller's fields
//!   are twice one stroke's (1e-12 relative: the second stroke adds the same deposits to
//!   what the first left, so the sums differ from 2 F_1 by round-off), the peak pressure is
//!   one stroke's, and stroke 2's sheet results (every increment's tool force, the final
//!   displacements) are stroke 1's.
//! - Two strokes simulated and extrapolated to 1000: 1000 times one stroke's fields (1e-12
//!   relative: a product of round-off-exact sums by 500).
//! - A friction law of the tool's work: stroke 1 is the run with mu = P_0; in stroke 2 every
//!   slipping node's tangential force over its normal force is the law at stroke 1's tool
//!   work per area under its foot (the reference run's field, not the simulation's frozen
//!   copy); its tangential forces grow. A restart inside stroke 2 ends bit for bit as the
//!   uninterrupted run.
//! - Refusals: extrapolating with a tool-state law, a tool-state law without fields.
//! - Geometry updated by the wear (`update_geometry_every`): stroke 2 on the roller worn by
//!   stroke 1 (contact nodes at the worn surface to 1e-10), its restart, its refusals.

mod common;

use std::sync::Arc;
use tribo::contact::{BernsteinLaw, ContactStatus, FrictionLaw, WorkMeasure};
use tribo::geometry::{BezierPatch, PatchSurface, Vec3};
use tribo::solver::model::strokes::Strokes;
use tribo::solver::simulation::checkpoint::Checkpoint;
use tribo::solver::{Model, Simulation};
use tribo::tool::surface_fields::FieldValues;
use tribo::tool::{FieldSpec, WearLaw};

/// The roller drag of tests/tool_fields.rs with friction `law` and `strokes`.
fn roller(law: FrictionLaw, strokes: Strokes) -> Model {
    let mut model = common::cylinder_drag_model(8.0, 2.0, 16, 3.0);
    let axis = Vec3::new(2.0, -0.5, 2.0 + 5.0 + 0.02);
    let patches = (0..2)
        .map(|k| {
            BezierPatch::cylinder_patch(
                axis,
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, 0.0, -1.0),
                (-60.0 + 60.0 * k as f64).to_radians(),
                60f64.to_radians(),
                5.0,
                2.0,
            )
            .unwrap()
        })
        .collect();
    let contact = &mut model.contacts[0];
    contact.tool.surface = Arc::new(PatchSurface::new(patches).unwrap());
    contact.tool.friction = law;
    contact.tool.fields = Some(FieldSpec {
        wear: WearLaw::archard(2e-4, 6000.0).unwrap(),
        cell: None,
    });
    model.settings.increments = 12;
    model.strokes = strokes;
    model
}

fn coulomb() -> FrictionLaw {
    FrictionLaw::coulomb(0.2).unwrap()
}

/// Steps until the current stroke ends; returns the reports' tool forces.
fn run_stroke(sim: &mut Simulation) -> Vec<[f64; 3]> {
    // The stroke this call runs: the next one when the current one has ended.
    let stroke = sim.stroke() + usize::from(sim.stroke_done());
    let mut forces = Vec::new();
    loop {
        let r = sim.step().unwrap();
        assert_eq!(r.stroke, stroke);
        forces.push(r.tool_forces[0]);
        if sim.stroke_done() {
            return forces;
        }
    }
}

/// Largest |a - f b| over the cells, relative to the largest |f b|.
fn rel_diff(a: &[f64], b: &[f64], f: f64) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max((f * x).abs()));
    assert!(scale > 0.0, "the field is not zero");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - f * y).abs())
        .fold(0.0, f64::max)
        / scale
}

/// `a` against `f` times `b` on the additive fields, and the same peak pressure.
fn check_scaled(a: &FieldValues, b: &FieldValues, f: f64, what: &str) {
    for (name, x, y) in [
        ("work", &a.work, &b.work),
        ("slip", &a.slip, &b.slip),
        ("pressure_time", &a.pressure_time, &b.pressure_time),
        ("wear", &a.wear, &b.wear),
    ] {
        let d = rel_diff(x, y, f);
        println!("{what}: {name} differs from {f} x one stroke's by {d:e} (relative)");
        assert!(d <= 1e-12, "{what}: {name}: {d:e}");
    }
    assert_eq!(a.peak_pressure, b.peak_pressure, "{what}: peak pressure");
}

#[test]
fn two_strokes_give_twice_the_fields_and_the_same_sheet() {
    let mut one = Simulation::new(roller(coulomb(), Strokes::default())).unwrap();
    let forces_one = run_stroke(&mut one);
    assert!(one.is_finished());
    let mut model = roller(coulomb(), Strokes::new(2, 2).unwrap());
    // Enough kept states to roll a whole stroke back (below).
    model.settings.stepping.rollback_depth = 16;
    let mut sim = Simulation::new(model).unwrap();
    let forces_1 = run_stroke(&mut sim);
    assert!(!sim.is_finished() && sim.stroke() == 1);
    // Stroke 1 of the production run is the run of one stroke, bit for bit.
    assert_eq!(forces_1, forces_one);
    let after_1 = sim.tool_fields(0).unwrap().values.clone();
    assert_eq!(after_1, one.tool_fields(0).unwrap().values);
    let forces_2 = run_stroke(&mut sim);
    assert!(sim.is_finished() && sim.stroke() == 2);
    assert!(sim.step().is_err(), "no stroke after the last");
    // The sheet of stroke 2 is the sheet of stroke 1: a new blank, the tools from the start.
    let force_scale = forces_one
        .iter()
        .flatten()
        .fold(0.0f64, |m, f| m.max(f.abs()));
    let force_diff = (forces_2.iter().flatten())
        .zip(forces_one.iter().flatten())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!(
        "stroke 2's tool forces differ from stroke 1's by {force_diff:e} (largest {force_scale:e})"
    );
    assert!(force_diff <= 1e-12 * force_scale);
    let u_diff = (sim.displacements().iter())
        .zip(one.displacements())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let u_scale = one
        .displacements()
        .iter()
        .fold(0.0f64, |m, u| m.max(u.abs()));
    assert!(u_diff <= 1e-12 * u_scale, "{u_diff:e}");
    assert_eq!(
        sim.energy().frictional_dissipation,
        one.energy().frictional_dissipation
    );
    check_scaled(
        &sim.tool_fields(0).unwrap().values,
        &one.tool_fields(0).unwrap().values,
        2.0,
        "two strokes",
    );
    // The history holds both strokes, increments numbered on.
    assert_eq!(sim.history.len(), 24);
    assert_eq!(sim.history[12].stroke, 2);
    assert_eq!(sim.history[12].index, 13);
    // A rollback stays inside the stroke: to its start, not past it.
    let err = sim.rollback(13).unwrap_err().to_string();
    assert!(err.contains("past the start of stroke 2"), "{err}");
    assert_eq!(sim.rollback(12).unwrap(), 0.0);
    assert_eq!(sim.stroke(), 2);
    assert!(sim.displacements().iter().all(|&u| u == 0.0));
    assert_eq!(
        sim.tool_fields(0).unwrap().values,
        after_1,
        "back at stroke 2's start: the fields stroke 1 left"
    );
}

#[test]
fn two_strokes_extrapolated_to_1000_give_1000_times_one_stroke() {
    let mut one = Simulation::new(roller(coulomb(), Strokes::default())).unwrap();
    one.run(|_, _| Ok(())).unwrap();
    let mut sim = Simulation::new(roller(coulomb(), Strokes::new(1000, 2).unwrap())).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    assert_eq!((sim.stroke(), sim.history.len()), (2, 24));
    check_scaled(
        &sim.tool_fields(0).unwrap().values,
        &one.tool_fields(0).unwrap().values,
        1000.0,
        "1000 strokes",
    );
}

/// mu = P_0 + (P_1 - P_0) theta of the tool's work per area, theta = min(w / w_cut, 1).
fn tool_work_law(w_cut: f64) -> BernsteinLaw {
    BernsteinLaw::new(vec![0.1, 0.4], w_cut, WorkMeasure::PerArea).unwrap()
}

#[test]
fn tool_state_friction_changes_stroke_two_as_the_law_says() {
    // The reference: one stroke at mu = P_0 = 0.1, its tool work per area w_1.
    let mut reference = Simulation::new(roller(
        FrictionLaw::coulomb(0.1).unwrap(),
        Strokes::default(),
    ))
    .unwrap();
    let forces_ref = run_stroke(&mut reference);
    let w1 = reference.tool_fields(0).unwrap().values.work.clone();
    let w_max = w1.iter().cloned().fold(0.0, f64::max);
    assert!(w_max > 0.0);
    // w_cut = 2 max w_1: mu under the worked track goes up to 0.25, below the law's top.
    let law = tool_work_law(2.0 * w_max);
    let model = roller(
        FrictionLaw::ToolWork(law.clone()),
        Strokes::new(2, 2).unwrap(),
    );
    let mut sim = Simulation::new(model).unwrap();
    // Stroke 1 reads the virgin tool: the reference run, bit for bit.
    assert_eq!(run_stroke(&mut sim), forces_ref);
    assert_eq!(sim.tool_fields(0).unwrap().values.work, w1);
    // Stroke 2: each increment's mu is the law at w_1 in the cell of the node's committed
    // foot before the increment.
    let fields = sim.tool_fields(0).unwrap().clone();
    // Where each node's foot is when a stroke starts (the blank as built).
    let initial: Vec<_> = Simulation::new(roller(coulomb(), Strokes::default()))
        .unwrap()
        .contact_states(0)
        .iter()
        .map(|s| s.hint)
        .collect();
    let (mut checked, mut raised) = (0, 0);
    let mut tangential = [0.0; 2];
    for (stroke, t) in tangential.iter_mut().enumerate() {
        if stroke == 0 {
            *t = forces_ref.iter().map(|f| f[0].abs()).sum();
            continue;
        }
        while !sim.stroke_done() || sim.stroke() == 1 {
            let feet: Vec<_> = if sim.stroke_done() {
                initial.clone()
            } else {
                sim.contact_states(0).iter().map(|s| s.hint).collect()
            };
            let r = sim.step().unwrap();
            *t += r.tool_forces[0][0].abs();
            for (s, foot) in sim.contact_states(0).iter().zip(&feet) {
                let (ContactStatus::Slip, Some(h)) = (s.status, foot) else {
                    continue;
                };
                let cell = fields.offsets[h.patch] + fields.grids[h.patch].cell_of([h.u, h.v]);
                let expected = law.mu_of_theta((w1[cell] / law.work_cut()).min(1.0));
                let lambda_n = s.lambda.dot(&s.normal);
                let lambda_t = (s.lambda - s.normal * lambda_n).norm();
                let mu = lambda_t / lambda_n.abs();
                assert!(
                    (mu - expected).abs() <= 1e-8 * expected,
                    "t = {}: |lambda_t| / |lambda_n| = {mu}, the law at w_1 gives {expected}",
                    sim.time()
                );
                checked += 1;
                raised += usize::from(expected > 0.1 + 1e-3);
            }
        }
    }
    println!("stroke 2: {checked} slipping node-increments checked, {raised} with mu > 0.101; |F_x| summed: stroke 1 {}, stroke 2 {}", tangential[0], tangential[1]);
    assert!(checked >= 20 && raised >= 10, "{checked} {raised}");
    // The worked tool holds the sheet back harder.
    assert!(tangential[1] > 1.05 * tangential[0]);
}

/// A checkpoint inside stroke 2 of the tool-state law (its stroke, fields and frozen work
/// in it) continues to the uninterrupted run's fields and forces, bit for bit.
#[test]
fn a_restart_inside_stroke_two_continues_bit_for_bit() {
    let model = || {
        roller(
            FrictionLaw::ToolWork(tool_work_law(0.05)),
            Strokes::new(2, 2).unwrap(),
        )
    };
    let mut whole = Simulation::new(model()).unwrap();
    whole.run(|_, _| Ok(())).unwrap();
    let mut first = Simulation::new(model()).unwrap();
    for _ in 0..17 {
        first.step().unwrap();
    }
    assert_eq!(first.stroke(), 2);
    let json = Checkpoint::of(&first, Vec::new()).to_json().unwrap();
    let mut second = Simulation::new(model()).unwrap();
    Checkpoint::from_json(&json, "test")
        .unwrap()
        .restore(&mut second)
        .unwrap();
    assert_eq!(second.stroke(), 2);
    assert_eq!(second.frozen_tool_work(0), first.frozen_tool_work(0));
    second.run(|_, _| Ok(())).unwrap();
    assert_eq!(
        whole.tool_fields(0).unwrap().values,
        second.tool_fields(0).unwrap().values
    );
    let forces = |s: &Simulation| {
        s.history
            .iter()
            .map(|r| r.tool_forces[0])
            .collect::<Vec<_>>()
    };
    assert_eq!(forces(&whole), forces(&second));
    // A script of one stroke refuses the checkpoint of stroke 2.
    let mut short = Simulation::new({
        let mut m = model();
        m.strokes = Strokes::default();
        m
    })
    .unwrap();
    let err = Checkpoint::from_json(&json, "test")
        .unwrap()
        .restore(&mut short)
        .unwrap_err()
        .to_string();
    assert!(err.contains("stroke 2"), "{err}");
}

#[test]
fn tool_state_laws_refuse_extrapolation_and_need_fields() {
    let law = FrictionLaw::ToolWork(tool_work_law(1.0));
    let err = Simulation::new(roller(law.clone(), Strokes::new(1000, 2).unwrap()))
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("'roller'") && err.contains("extrapolated") && err.contains("tool's state"),
        "{err}"
    );
    let mut model = roller(law, Strokes::new(2, 2).unwrap());
    model.contacts[0].tool.fields = None;
    let err = Simulation::new(model).err().unwrap().to_string();
    assert!(
        err.contains("'roller'") && err.contains("tool.wear"),
        "{err}"
    );
}

/// The script layer (tests/scripts/strokes_block.rhai: a block pressed and dragged over a
/// flat patch with fields, `sim.strokes(2)`): history.csv's `stroke` column, summary.json's
/// `strokes`, the floor's tool-side work the two strokes' dissipation (twice the last
/// stroke's, 1e-12 relative), frames of the last stroke only.
#[test]
fn a_script_of_two_strokes_reports_them() {
    use tribo::script::{self, HostOptions};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = common::TestDir::new(&format!("tribo_strokes_script_{}", std::process::id()));
    let host = HostOptions {
        out_dir: out.to_path_buf(),
        ..HostOptions::default()
    };
    script::run_file(&root.join("tests/scripts/strokes_block.rhai"), &[], &host).unwrap();
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let lines: Vec<&str> = history.lines().collect();
    assert!(
        lines[0].starts_with("increment,stroke,time,"),
        "{}",
        lines[0]
    );
    let strokes: Vec<f64> = (lines[1..].iter())
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(strokes, [1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let s = &summary["strokes"];
    assert_eq!(
        (s["total"].as_u64(), s["simulated"].as_u64()),
        (Some(2), Some(2))
    );
    assert_eq!(
        (s["extrapolated"].as_bool(), s["current"].as_u64()),
        (Some(false), Some(2))
    );
    let floor = &summary["tools"]["floor"];
    let dissipation = floor["frictional_dissipation"].as_f64().unwrap();
    let work = floor["tool_fields"]["total_work"].as_f64().unwrap();
    assert!(dissipation > 0.0);
    assert!(
        (work - 2.0 * dissipation).abs() <= 1e-12 * work,
        "{work} vs 2 x {dissipation}"
    );
    // Frames: t = 0 and the last stroke's (4 increments, an interval of end_time / 20).
    let pvd = std::fs::read_to_string(out.join("frames.pvd")).unwrap();
    let times: Vec<&str> = pvd
        .lines()
        .filter(|l| l.contains("name=\"blank\""))
        .map(|l| {
            l.split("timestep=\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap()
        })
        .collect();
    assert_eq!(times, ["0", "0.5", "1", "1.5", "2"], "{pvd}");
}

/// The roller of [`roller`] wearing fast (k / H = 1e-5 /MPa, so that one stroke wears
/// micrometres to hundredths of a millimetre, far above the 1e-10 the test reads), with
/// its geometry updated by its wear after every `every` strokes.
fn wearing_roller(strokes: Strokes) -> Model {
    let mut model = roller(coulomb(), strokes);
    model.contacts[0].tool.fields = Some(FieldSpec {
        wear: WearLaw::archard(1.0, 1e5).unwrap(),
        cell: None,
    });
    model
}

/// Per candidate node in contact: (its signed distance to the EXACT roller, the wear depth
/// of the cell under its foot as applied to the geometry; 0 when not worn).
fn contact_gaps(sim: &Simulation) -> Vec<(f64, f64)> {
    let contact = &sim.model.contacts[0];
    let pose = sim.tool_pose(0);
    let fields = sim.tool_fields(0).unwrap();
    let applied = sim.applied_tool_wear(0);
    (contact.candidates.iter().zip(sim.contact_states(0)))
        .filter(|(_, s)| s.status.is_active())
        .map(|(&n, s)| {
            let x = sim.model.mesh.nodes[n] + sim.displacement(n);
            let exact = tribo::tool::project_posed(
                contact.tool.surface.as_ref(),
                &pose,
                &x,
                s.hint.as_ref(),
            )
            .unwrap();
            let h = applied.map_or(0.0, |a| {
                let hint = exact.hint;
                a[fields.offsets[hint.patch] + fields.grids[hint.patch].cell_of([hint.u, hint.v])]
            });
            (exact.gap, h)
        })
        .collect()
}

/// Issue 53, geometry updated by the wear (`update_geometry_every: 1`): stroke 1 runs on
/// the exact roller (bit for bit the run without the option), stroke 2 on the roller worn by
/// stroke 1's wear: every node in contact at every increment of stroke 2 lies at the worn
/// surface, its distance to the exact roller minus the wear depth of the cell under it, to
/// 1e-10 (contact and force tolerances of the roller drag bound the gap of a converged
/// contact node by far less). Newton keeps its iteration counts (the per-cell constant
/// offset leaves the consistent Jacobian exact: no dh/du term exists).
#[test]
fn stroke_two_runs_on_the_roller_worn_by_stroke_one() {
    let plain = Strokes::new(2, 2).unwrap();
    let mut exact = Simulation::new(wearing_roller(plain)).unwrap();
    let mut worn =
        Simulation::new(wearing_roller(plain.updating_geometry_every(1).unwrap())).unwrap();
    assert_eq!(run_stroke(&mut worn), run_stroke(&mut exact));
    assert!(worn.applied_tool_wear(0).is_none());
    let wear_1 = worn.tool_fields(0).unwrap().values.wear.clone();
    println!(
        "stroke 1 wears the roller by up to {:e}",
        wear_1.iter().fold(0.0f64, |m, x| m.max(*x))
    );
    let (mut checked, mut largest, mut iterations) = (0, 0.0f64, [0, 0]);
    for (k, sim) in [&mut exact, &mut worn].into_iter().enumerate() {
        loop {
            let r = sim.step().unwrap();
            iterations[k] += r.iterations;
            for (d, h) in contact_gaps(sim) {
                assert!(
                    (d + h).abs() <= 1e-10,
                    "stroke 2, t = {}: exact gap {d:e}, wear {h:e}",
                    r.time
                );
                checked += 1;
                largest = largest.max(h);
            }
            if sim.stroke_done() {
                break;
            }
        }
    }
    assert_eq!(worn.applied_tool_wear(0), Some(&wear_1[..]));
    println!("{checked} contact nodes checked, largest wear depth {largest:e}; Newton iterations of stroke 2 exact/worn {iterations:?}");
    assert!(
        largest > 1e-5,
        "the wear is far above the tolerance: {largest:e}"
    );
    assert!(iterations[1] <= iterations[0] + 2, "{iterations:?}");
}

/// A restart inside stroke 2 of a run updating the geometry after stroke 1: the checkpoint
/// carries the applied wear (`state.tool_wear_applied`), the restart ends bit for bit as
/// the uninterrupted run, and a script without the update refuses the checkpoint.
#[test]
fn a_restart_on_the_worn_roller_continues_bit_for_bit() {
    let strokes = Strokes::new(2, 2)
        .unwrap()
        .updating_geometry_every(1)
        .unwrap();
    let mut whole = Simulation::new(wearing_roller(strokes)).unwrap();
    whole.run(|_, _| Ok(())).unwrap();
    let mut first = Simulation::new(wearing_roller(strokes)).unwrap();
    for _ in 0..17 {
        first.step().unwrap();
    }
    assert_eq!(first.stroke(), 2);
    let json = Checkpoint::of(&first, Vec::new()).to_json().unwrap();
    let mut second = Simulation::new(wearing_roller(strokes)).unwrap();
    Checkpoint::from_json(&json, "test")
        .unwrap()
        .restore(&mut second)
        .unwrap();
    assert_eq!(second.applied_tool_wear(0), first.applied_tool_wear(0));
    second.run(|_, _| Ok(())).unwrap();
    assert_eq!(
        whole.tool_fields(0).unwrap().values,
        second.tool_fields(0).unwrap().values
    );
    let forces = |s: &Simulation| {
        s.history
            .iter()
            .map(|r| r.tool_forces[0])
            .collect::<Vec<_>>()
    };
    assert_eq!(forces(&whole), forces(&second));
    let mut unworn = Simulation::new(wearing_roller(Strokes::new(2, 2).unwrap())).unwrap();
    let err = Checkpoint::from_json(&json, "test")
        .unwrap()
        .restore(&mut unworn)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("worn") && err.contains("update_geometry_every"),
        "{err}"
    );
}

#[test]
fn geometry_updates_refuse_extrapolation_and_need_a_wear_law() {
    let strokes = Strokes::new(10, 2)
        .unwrap()
        .updating_geometry_every(1)
        .unwrap();
    let err = Simulation::new(wearing_roller(strokes))
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("extrapolated") && err.contains("update_geometry_every"),
        "{err}"
    );
    let mut model = wearing_roller(
        Strokes::new(2, 2)
            .unwrap()
            .updating_geometry_every(1)
            .unwrap(),
    );
    model.contacts[0].tool.fields = None;
    let err = Simulation::new(model).err().unwrap().to_string();
    assert!(
        err.contains("update_geometry_every") && err.contains("wear law"),
        "{err}"
    );
}

/// The script key: `update_geometry_every` runs stroke 2 of the block over the flat floor
/// (tests/scripts/strokes_block.rhai) on the worn floor; a value below 1 is refused,
/// naming the key and the value.
#[test]
fn the_script_key_update_geometry_every_is_read_and_checked() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = std::fs::read_to_string(root.join("tests/scripts/strokes_block.rhai")).unwrap();
    let with = |every: &str| {
        base.replace(
            "sim.strokes(2);",
            &format!("sim.strokes(2, #{{ update_geometry_every: {every} }});"),
        )
    };
    let (code, err) = common::run_script("strokes_geom_ok", "worn", &with("1"), &[]);
    assert_eq!(code, 0, "{err}");
    let (code, err) = common::run_script("strokes_geom_bad", "worn", &with("0"), &[]);
    assert_ne!(code, 0);
    assert!(
        err.contains("update_geometry_every") && err.contains('0'),
        "{err}"
    );
}
