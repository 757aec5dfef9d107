//! Issue 53: tool-side fields (src/tool/surface_fields.rs, src/solver/simulation/tool_fields.rs).
//!
//! - The transfer alone, on a block's contact face laid on a flat patch and wrapped on a
//!   cylinder patch, with a uniform tool-side pressure and slip: Archard wear `c p s`,
//!   pressure `p` and sliding distance `s` in every fully covered cell to 1e-10 relative;
//!   the tool-side work integral equal to the nodes' dissipation to 1e-10. The same on a
//!   general doubly curved rational Bézier patch (degree 3 x 2, unequal weights).
//! - A real run (a roller of cylinder patches pressed and dragged over an elastic block):
//!   after every increment the tool-side work integral equals the energy balance's frictional
//!   dissipation to 1e-10 relative; a restart from a checkpoint continues the fields bit for
//!   bit.

mod common;

use std::sync::Arc;
use tribo::contact::{ContactNodeState, FrictionLaw};
use tribo::geometry::{BezierPatch, PatchSurface, Vec3};
use tribo::mesh::Mesh;
use tribo::solver::simulation::checkpoint::Checkpoint;
use tribo::solver::simulation::tool_fields::ContactFields;
use tribo::solver::{Model, Simulation};
use tribo::tool::surface_fields::NodeLoad;
use tribo::tool::{FieldSpec, Pose, Tool, WearLaw};

/// Archard's k and H of the tests (a tool steel's order of magnitude).
const K: f64 = 2e-4;
const H: f64 = 6000.0;

/// A model holding `mesh` and a fixed tool on `patch` with fields of cell size `cell`,
/// touching the nodes of "z-".
fn model_on(mesh: Mesh, patch: BezierPatch, cell: f64) -> Model {
    let mut model = Model::new(mesh, common::elastic(1000.0, 0.3)).unwrap();
    let mut tool = Tool::new("die", Arc::new(PatchSurface::new(vec![patch]).unwrap()));
    tool.fields = Some(FieldSpec {
        wear: WearLaw::archard(K, H).unwrap(),
        cell: Some(cell),
    });
    model.add_tool(tool, "z-", None).unwrap();
    model
}

/// Contact states with each candidate's foot on the tool (identity pose).
fn states(model: &Model) -> Vec<ContactNodeState> {
    let c = &model.contacts[0];
    c.candidates
        .iter()
        .map(|&n| {
            let p = c
                .tool
                .project(&Pose::identity(), &model.mesh.nodes[n], None)
                .unwrap();
            assert!(p.gap.abs() < 1e-12, "the contact face lies on the tool");
            ContactNodeState {
                hint: Some(p.hint),
                ..Default::default()
            }
        })
        .collect()
}

/// Deposits a uniform tool-side pressure `p` and slip `s` (mu = 0.3) for every node
/// (normal force p times the node's footprint area on the tool), and returns the fields and
/// the sum of the nodes' frictional work.
fn uniform_load(model: &Model, p: f64, s: f64) -> (ContactFields, f64) {
    let contact = &model.contacts[0];
    let mut fields = ContactFields::new(contact, &model.mesh).unwrap().unwrap();
    let states = states(model);
    let position = |n: usize| model.mesh.nodes[n];
    let pose = Pose::identity();
    let pieces = fields.footprints(contact, &pose, position, &states, |_| true);
    let loads: Vec<NodeLoad> = pieces
        .iter()
        .map(|pk| {
            let force = p * fields.fields.footprint_area(pk);
            NodeLoad {
                work: 0.3 * force * s,
                normal_force: force,
                slip: s,
            }
        })
        .collect();
    let work = loads.iter().map(|l| l.work).sum();
    fields.accumulate(contact, &pose, position, &states, &loads, 0.5);
    (fields, work)
}

/// Checks the uniform fields in the cells whose four corners satisfy `inside` (given their
/// `(u, v)` and their point on the patch); returns
/// how many cells that is. Partly covered cells get less, never more.
fn check_uniform(
    fields: &ContactFields,
    patch: &BezierPatch,
    inside: impl Fn([f64; 2], Vec3) -> bool,
    p: f64,
    s: f64,
) -> usize {
    let f = &fields.fields;
    let grid = &f.grids[0];
    let wear = K / H * p * s;
    let mut covered = 0;
    for c in 0..grid.len() {
        let (i, j) = (c / grid.nv, c % grid.nv);
        let corners = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
            .map(|(a, b)| [a as f64 / grid.nu as f64, b as f64 / grid.nv as f64]);
        let v = &f.values;
        if corners
            .iter()
            .all(|uv| inside(*uv, patch.point(uv[0], uv[1])))
        {
            covered += 1;
            let rel = |a: f64, b: f64| (a - b).abs() / b;
            assert!(
                rel(v.wear[c], wear) < 1e-10,
                "cell {c}: wear {} != {wear}",
                v.wear[c]
            );
            assert!(
                rel(v.peak_pressure[c], p) < 1e-10,
                "cell {c}: pressure {}",
                v.peak_pressure[c]
            );
            assert!(rel(v.pressure_time[c], 0.5 * p) < 1e-10, "cell {c}");
            assert!(rel(v.slip[c], s) < 1e-10, "cell {c}: slip {}", v.slip[c]);
        } else {
            // 1e-12: the round-off of a sum of a few pieces.
            assert!(
                v.wear[c] <= wear * (1.0 + 1e-12),
                "cell {c}: {} > {wear}",
                v.wear[c]
            );
        }
    }
    covered
}

/// A 3 x 2 block (6 x 4 elements) on a flat 6 x 5 patch with cells of 0.2 that do not line
/// up with the elements: Archard's k p s / H in the 10 x 5... fully covered cells.
#[test]
fn uniform_pressure_and_slip_on_a_flat_tool_give_archard_in_every_covered_cell() {
    let (x0, y0) = (0.13, 0.27);
    let mesh = Mesh::block(Vec3::new(x0, y0, 0.0), Vec3::new(3.0, 2.0, 0.5), [6, 4, 1]).unwrap();
    let patch = BezierPatch::parallelogram(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(6.0, 0.0, 0.0),
        Vec3::new(0.0, 5.0, 0.0),
    )
    .unwrap();
    let model = model_on(mesh, patch.clone(), 0.2);
    let (p, s) = (80.0, 0.35);
    let (fields, work) = uniform_load(&model, p, s);
    let f = &fields.fields;
    assert_eq!((f.grids[0].nu, f.grids[0].nv), (30, 25));
    // The grid's area is the patch's: 30, exact on a flat patch.
    let area: f64 = f.cell_areas().sum();
    assert!((area - 30.0).abs() < 1e-12, "{area}");
    let inside =
        |_: [f64; 2], x: Vec3| x.x >= x0 && x.x <= x0 + 3.0 && x.y >= y0 && x.y <= y0 + 2.0;
    let covered = check_uniform(&fields, &patch, inside, p, s);
    // Cells of 0.2 inside [0.13, 3.13] x [0.27, 2.27]: x from 0.2 to 3.0 (14), y from 0.4
    // to 2.2 (9).
    assert_eq!(covered, 14 * 9);
    let rel = (f.total_work() - work).abs() / work;
    assert!(
        rel < 1e-10,
        "tool-side work {} vs the nodes' {work}",
        f.total_work()
    );
    // On a flat tool the footprints are the nodes' tributary areas, so the total normal
    // force is p times the block's face.
    let force: f64 = f
        .cell_areas()
        .zip(&f.values.peak_pressure)
        .map(|(a, p)| a * p)
        .sum();
    assert!((force - p * 6.0).abs() < 1e-10 * p * 6.0, "{force}");
}

/// The same block wrapped on a cylinder patch (radius 10, 60 degrees, axis along y): the
/// fields follow the curved surface.
#[test]
fn uniform_pressure_and_slip_on_a_cylinder_give_archard_in_every_covered_cell() {
    let radius = 10.0;
    let block = Mesh::block(
        Vec3::new(-2.9, 0.23, 0.0),
        Vec3::new(6.0, 2.0, 0.5),
        [12, 4, 1],
    )
    .unwrap();
    // (x, y, z) -> arc length x around the axis at radius R + z.
    let mut mesh = block.clone();
    for node in &mut mesh.nodes {
        let (theta, r) = (node.x / radius, radius + node.z);
        *node = Vec3::new(r * theta.sin(), node.y, r * theta.cos());
    }
    let sweep = 60f64.to_radians();
    // u from -30 degrees (about +z towards +x) over 60 degrees; v along y over 4.
    let patch = BezierPatch::cylinder_patch(
        Vec3::zeros(),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        -0.5 * sweep,
        sweep,
        radius,
        4.0,
    )
    .unwrap();
    // The patch's outward normal at its middle is +z (the sheet lies outside).
    let mid = patch.evaluate(0.5, 0.5);
    let n = patch.normal(&mid).unwrap();
    assert!(n.z > 0.999, "{n:?}");
    let model = model_on(mesh, patch.clone(), 0.15);
    let (p, s) = (80.0, 0.35);
    let (fields, work) = uniform_load(&model, p, s);
    let f = &fields.fields;
    // The grid's area is the cylinder's R * sweep * 4, not a projection's (which would be
    // 4.5 % smaller); the bilinear metric errs by O(cell^2 / R^2) = 2.3e-4 here, measured
    // -8.7e-6.
    let area: f64 = f.cell_areas().sum();
    let exact = radius * sweep * 4.0;
    println!(
        "cylinder: grid area error {:e} relative",
        (area - exact) / exact
    );
    assert!(
        (area - exact).abs() < (0.15f64 / radius).powi(2) * exact,
        "{area} vs {exact}"
    );
    let inside = |_: [f64; 2], x: Vec3| {
        let arc = radius * x.x.atan2(x.z);
        arc >= -2.9 && arc <= 3.1 && x.y >= 0.23 && x.y <= 2.23
    };
    let covered = check_uniform(&fields, &patch, inside, p, s);
    println!("cylinder: {covered} fully covered cells of {}", f.len());
    assert!(covered > 200, "{covered} covered cells");
    let rel = (f.total_work() - work).abs() / work;
    assert!(
        rel < 1e-10,
        "tool-side work {} vs the nodes' {work}",
        f.total_work()
    );
}

/// A general rational Bézier patch (degree 3 x 2, doubly curved, unequal weights) over
/// about 6 x 5, and a block whose contact face is laid on it: the block's nodes `(x, y, z)`
/// are put at `S(x, y) + 4 z n(x, y)`, so the contact face is the image of
/// `[0.13, 0.83] x [0.17, 0.77]` in the patch's parameters.
fn curved_patch() -> BezierPatch {
    // Heights of the 4 x 3 control net: a saddle with a bump, nowhere flat.
    let z = [
        [0.0, 0.6, -0.2],
        [0.8, -0.5, 0.4],
        [-0.4, 0.9, 0.1],
        [0.3, -0.3, 0.7],
    ];
    let w = [
        [1.0, 1.4, 1.0],
        [0.8, 1.2, 1.1],
        [1.3, 0.7, 0.9],
        [1.0, 1.1, 1.0],
    ];
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..4 {
        for j in 0..3 {
            points.push(Vec3::new(
                -1.0 + 2.0 * i as f64,
                -1.0 + 2.5 * j as f64,
                2.5 * z[i][j],
            ));
            weights.push(w[i][j]);
        }
    }
    BezierPatch::new(3, 2, points, weights).unwrap()
}

/// The same transfer on `curved_patch`: Archard's k p s / H, p, s in every cell whose
/// parameter corners lie inside the contact face's parameter rectangle by a margin, and the
/// tool-side work integral equal to the nodes' dissipation. Both are exact to round-off
/// whatever the surface (the footprints tile the covered cells in (u, v), and pieces and
/// cells are integrated with the same bilinear metric, field_grid.rs), hence 1e-10.
#[test]
fn uniform_pressure_and_slip_on_a_curved_bezier_patch_give_archard_in_every_covered_cell() {
    let patch = curved_patch();
    assert!(patch.fold().is_none());
    let (lo, hi) = ([0.13, 0.17], [0.83, 0.77]);
    let block = Mesh::block(
        Vec3::new(lo[0], lo[1], 0.0),
        Vec3::new(hi[0] - lo[0], hi[1] - lo[1], 0.05),
        [14, 12, 1],
    )
    .unwrap();
    let mut mesh = block.clone();
    for node in &mut mesh.nodes {
        let e = patch.evaluate(node.x, node.y);
        let n = patch.normal(&e).unwrap();
        // The sheet lies on the normal's side, which is +z (S_u along x, S_v along y).
        assert!(n.z > 0.5, "{n:?}");
        *node = e.point + 4.0 * node.z * n;
    }
    // Not flat and not a cylinder: the normal turns in both parameter directions (measured
    // by 12 and 11 degrees over 0.6 of u and of v).
    let normal = |u, v| patch.normal(&patch.evaluate(u, v)).unwrap();
    let (n0, nu, nv) = (normal(0.2, 0.2), normal(0.8, 0.2), normal(0.2, 0.8));
    println!(
        "normal turns: {} along u, {} along v",
        n0.cross(&nu).norm(),
        n0.cross(&nv).norm()
    );
    assert!(n0.cross(&nu).norm() > 0.15 && n0.cross(&nv).norm() > 0.15);
    let model = model_on(mesh, patch.clone(), 0.2);
    let (p, s) = (80.0, 0.35);
    let (fields, work) = uniform_load(&model, p, s);
    let f = &fields.fields;
    // The grid's area against a 400 x 400 midpoint sum of |S_u x S_v|: the bilinear metric
    // errs by O(cell^2 kappa^2), measured 5.3e-4.
    let m = 400;
    let exact: f64 = (0..m * m)
        .map(|c| {
            let (u, v) = (
                ((c / m) as f64 + 0.5) / m as f64,
                ((c % m) as f64 + 0.5) / m as f64,
            );
            let e = patch.evaluate(u, v);
            e.su.cross(&e.sv).norm() / (m * m) as f64
        })
        .sum();
    let area: f64 = f.cell_areas().sum();
    println!(
        "curved patch: {} x {} cells, grid area {area} vs {exact} ({:e} relative)",
        f.grids[0].nu,
        f.grids[0].nv,
        (area - exact) / exact
    );
    assert!((area - exact).abs() < 1e-3 * exact, "{area} vs {exact}");
    // The face's outer edges run through the projections of its edges' chord midpoints,
    // which leave the parameter rectangle's sides by O(h^2 kappa); a margin of a quarter
    // cell keeps the checked cells inside the footprint.
    let margin = 0.25 / f.grids[0].nu.min(f.grids[0].nv) as f64;
    let inside =
        |uv: [f64; 2], _: Vec3| (0..2).all(|k| uv[k] >= lo[k] + margin && uv[k] <= hi[k] - margin);
    let covered = check_uniform(&fields, &patch, inside, p, s);
    println!("curved patch: {covered} fully covered cells of {}", f.len());
    assert!(covered > 150, "{covered} covered cells");
    let rel = (f.total_work() - work).abs() / work;
    println!("curved patch: work integral error {rel:e} relative");
    assert!(
        rel < 1e-10,
        "tool-side work {} vs the nodes' {work}",
        f.total_work()
    );
}

/// A roller made of two 60-degree cylinder patches (radius 5, axis along y), pressed 0.1
/// into an elastic block and dragged 3 along it with Coulomb 0.2 (the set-up of
/// common::cylinder_drag_model with the analytic cylinder replaced by patches).
fn roller_drag(increments: usize) -> Model {
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
    contact.tool.friction = FrictionLaw::coulomb(0.2).unwrap();
    contact.tool.fields = Some(FieldSpec {
        wear: WearLaw::archard(K, H).unwrap(),
        cell: None,
    });
    model.settings.increments = increments;
    model
}

#[test]
fn tool_side_work_equals_the_frictional_dissipation_in_a_drag() {
    let mut sim = Simulation::new(roller_drag(12)).unwrap();
    let mut checked = 0;
    while !sim.is_finished() {
        sim.step().unwrap();
        let sheet = sim.energy().frictional_dissipation[0];
        let tool = sim.tool_fields(0).unwrap().total_work();
        if sheet > 0.0 {
            checked += 1;
            assert!(
                (tool - sheet).abs() <= 1e-10 * sheet,
                "t = {}: tool {tool} vs sheet {sheet}",
                sim.time()
            );
        }
    }
    assert!(checked >= 6, "{checked} increments with friction");
    let f = sim.tool_fields(0).unwrap();
    let max_wear = f.values.wear.iter().cloned().fold(0.0, f64::max);
    let peak = f.values.peak_pressure.iter().cloned().fold(0.0, f64::max);
    println!(
        "drag: tool-side work {}, max wear {max_wear:e}, peak pressure {peak}",
        f.total_work()
    );
    // The roller's rim slides over the block, so wear and pressure are where it touched.
    assert!(max_wear > 0.0 && peak > 0.0);
}

/// A run stopped after 6 of 12 increments, written to a checkpoint and continued in a new
/// simulation ends with the uninterrupted run's fields, bit for bit.
#[test]
fn tool_side_fields_restart_bit_for_bit() {
    let mut whole = Simulation::new(roller_drag(12)).unwrap();
    whole.run(|_, _| Ok(())).unwrap();
    let mut first = Simulation::new(roller_drag(12)).unwrap();
    for _ in 0..6 {
        first.step().unwrap();
    }
    let json = Checkpoint::of(&first, Vec::new()).to_json().unwrap();
    let mut second = Simulation::new(roller_drag(12)).unwrap();
    Checkpoint::from_json(&json, "test")
        .unwrap()
        .restore(&mut second)
        .unwrap();
    assert_eq!(
        second.tool_fields(0).unwrap().values,
        first.tool_fields(0).unwrap().values
    );
    second.run(|_, _| Ok(())).unwrap();
    let (a, b) = (
        &whole.tool_fields(0).unwrap().values,
        &second.tool_fields(0).unwrap().values,
    );
    assert!(a.wear.iter().any(|&w| w > 0.0));
    assert_eq!(a, b);
    // A model without fields refuses the checkpoint with them, naming the tool.
    let mut model = roller_drag(12);
    model.contacts[0].tool.fields = None;
    let mut plain = Simulation::new(model).unwrap();
    let err = Checkpoint::from_json(&json, "test")
        .unwrap()
        .restore(&mut plain)
        .unwrap_err();
    assert!(err.to_string().contains("'roller'"), "{err}");
}

/// Fields on an analytic surface are refused with the tool's name.
#[test]
fn fields_on_an_analytic_tool_are_refused() {
    let mut model = common::cylinder_drag_model(8.0, 2.0, 16, 3.0);
    model.contacts[0].tool.fields = Some(FieldSpec {
        wear: WearLaw::archard(K, H).unwrap(),
        cell: None,
    });
    let err = Simulation::new(model).err().unwrap().to_string();
    assert!(
        err.contains("'roller'") && err.contains("Bézier patches"),
        "{err}"
    );
}

/// The cylindrical cup script (scripts/cylindrical_cup.rhai, quarter, coarse default mesh)
/// with `wear = true`, 6 mm of punch travel through the command line: for every tool the
/// tool-side work in summary.json equals the tool's frictional dissipation to 1e-8
/// relative (by construction to round-off; summary.json's numbers round-trip exactly), and
/// the die's frames carry the wear field; the wear and work maps are written.
#[test]
fn cup_stroke_tool_side_work_equals_the_dissipation_on_every_tool() {
    let out = common::TestDir::new(&format!("tribo_tool_fields_cup_{}", std::process::id()));
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_tribo"))
        .current_dir(root)
        .args(["run", "scripts/cylindrical_cup.rhai", "--quiet", "--out"])
        .arg(&*out)
        .args([
            "--set",
            "charts=true",
            "--set",
            "wear=true",
            "--set",
            "travel=6.0",
        ])
        .status()
        .expect("tribo runs");
    assert!(status.success());
    let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    let (mut sheet, mut tools) = (0.0, 0.0);
    for name in ["punch", "die", "blankholder"] {
        let tool = &summary["tools"][name];
        let dissipation = tool["frictional_dissipation"].as_f64().unwrap();
        let fields = &tool["tool_fields"];
        let work = fields["total_work"].as_f64().unwrap();
        println!("{name}: dissipation {dissipation}, tool-side work {work}, max wear {} at {}, peak pressure {}",
            fields["max_wear_depth"], fields["max_wear_at"], fields["peak_pressure"]);
        assert!(
            (work - dissipation).abs() <= 1e-8 * dissipation.abs().max(1e-300),
            "{name}: {work} vs {dissipation}"
        );
        sheet += dissipation;
        tools += work;
    }
    assert!(sheet > 0.0 && (tools - sheet).abs() <= 1e-8 * sheet);
    // The run's own clock accounts for the fields (issue 53's cost, BENCHMARKS.md [w]):
    // their accumulation and the tool frames that carry them are timed phases.
    let phases = &summary["phase_times_s"];
    for phase in ["tool_fields", "tool_frames", "frames"] {
        let seconds = phases[phase].as_f64().unwrap();
        assert!(
            seconds > 0.0 && seconds < summary["wall_time_s"].as_f64().unwrap(),
            "{phase}: {seconds}"
        );
    }
    // The die (drawn over its entry radius) wears; its wear lies on the die's surface.
    let die = &summary["tools"]["die"]["tool_fields"];
    assert!(die["max_wear_depth"].as_f64().unwrap() > 0.0);
    let frames: Vec<_> = std::fs::read_dir(out.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with("_die.vtu"))
        .collect();
    assert!(!frames.is_empty());
    let last = frames.iter().max().unwrap();
    let vtu = std::fs::read_to_string(last).unwrap();
    assert!(vtu.contains("tool_wear_depth") && vtu.contains("tool_work_per_area"));
    // The wear and work maps seen from above (sim.chart_tool_field): under 200 kB, and the
    // wear map's CSV holds the largest wear depth (a block shows its cells' largest value)
    // exactly as summary.json gives it (both print f64 round-trip).
    for (file, tool) in [
        ("wear_die", "die"),
        ("work_die", "die"),
        ("wear_punch", "punch"),
    ] {
        let svg = out.join(format!("{file}.svg"));
        let bytes = std::fs::metadata(&svg).unwrap().len();
        println!("{file}.svg: {bytes} bytes");
        assert!(bytes < 200_000, "{file}.svg: {bytes} bytes");
        if file.starts_with("wear") {
            let csv = std::fs::read_to_string(out.join(format!("{file}.csv"))).unwrap();
            let max = csv
                .lines()
                .skip(1)
                .filter_map(|l| l.rsplit(',').next().unwrap().parse::<f64>().ok())
                .fold(f64::NEG_INFINITY, f64::max);
            let expected = summary["tools"][tool]["tool_fields"]["max_wear_depth"]
                .as_f64()
                .unwrap();
            assert_eq!(max, expected, "{file}.csv");
        }
    }
}

/// `sim.rollback(2)` after two more increments gives back the fields of the state it returns
/// to, bit for bit (they are part of the kept states).
#[test]
fn rollback_restores_the_tool_side_fields() {
    let mut sim = Simulation::new(roller_drag(12)).unwrap();
    for _ in 0..6 {
        sim.step().unwrap();
    }
    let kept = sim.tool_fields(0).unwrap().values.clone();
    sim.step().unwrap();
    sim.step().unwrap();
    assert_ne!(
        sim.tool_fields(0).unwrap().values,
        kept,
        "the drag goes on wearing"
    );
    sim.rollback(2).unwrap();
    assert_eq!(sim.tool_fields(0).unwrap().values, kept);
}

/// Scripts: wear on an analytic plane and a hardness of 0 are refused, naming the tool or
/// the value, with the script's line.
#[test]
fn script_wear_errors_name_the_fault() {
    let dir = common::TestDir::new(&format!("tribo_tool_fields_script_{}", std::process::id()));
    std::fs::create_dir_all(&*dir).unwrap();
    let cases = [
        (
            "let mesh = block([0.0, 0.0, 0.0], [2.0, 1.0, 0.5], [4, 2, 1]);\n\
             let sim = simulation(mesh, linear_elastic(1000.0, 0.3));\n\
             sim.add_tool(tool(\"floor\", plane([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])).wear(archard(1e-4, 6000.0)), \"z-\");\n\
             sim.run();\n",
            "'floor'",
        ),
        ("let law = archard(1e-4, 0.0);\n", "hardness"),
    ];
    for (k, (script, expected)) in cases.iter().enumerate() {
        let path = dir.join(format!("case{k}.rhai"));
        std::fs::write(&path, script).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_tribo"))
            .args(["run", "--quiet", "--out"])
            .arg(dir.join(format!("out{k}")))
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "case {k} ran");
        assert!(stderr.contains(expected), "case {k}: {stderr}");
    }
}

/// The square cup script (scripts/square_cup.rhai, 10 x 10 cells, 15 mm of travel) with
/// `wear = true`: the punch and die report their tool-side fields in summary.json (work equal
/// to their frictional dissipation to 1e-8 relative, a positive wear depth), and the die's
/// wear map at the 15 mm report travel is under 200 kB with summary.json's maximum in its CSV.
#[test]
fn square_cup_reports_the_die_and_punch_wear() {
    let out = common::TestDir::new(&format!("tribo_tool_fields_square_{}", std::process::id()));
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_tribo"))
        .current_dir(root)
        .args(["run", "scripts/square_cup.rhai", "--quiet", "--out"])
        .arg(&*out)
        .args([
            "--set",
            "cells=10",
            "--set",
            "travel=15.0",
            "--set",
            "wear=true",
        ])
        .status()
        .expect("tribo runs");
    assert!(status.success());
    let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    for name in ["punch", "die"] {
        let tool = &summary["tools"][name];
        let dissipation = tool["frictional_dissipation"].as_f64().unwrap();
        let fields = &tool["tool_fields"];
        let work = fields["total_work"].as_f64().unwrap();
        println!(
            "{name}: dissipation {dissipation}, tool-side work {work}, max wear {} at {}",
            fields["max_wear_depth"], fields["max_wear_at"]
        );
        assert!(
            (work - dissipation).abs() <= 1e-8 * dissipation,
            "{name}: {work} vs {dissipation}"
        );
        assert!(fields["max_wear_depth"].as_f64().unwrap() > 0.0, "{name}");
    }
    // Without wear the holder has no entry (runs without fields keep their summary).
    assert!(summary["tools"]["blankholder"].get("tool_fields").is_none());
    let svg = out.join("wear_die_15mm.svg");
    let bytes = std::fs::metadata(&svg).unwrap().len();
    println!("wear_die_15mm.svg: {bytes} bytes");
    assert!(bytes < 200_000, "{bytes} bytes");
    let csv = std::fs::read_to_string(out.join("wear_die_15mm.csv")).unwrap();
    let max = csv
        .lines()
        .skip(1)
        .filter_map(|l| l.rsplit(',').next().unwrap().parse::<f64>().ok())
        .fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(
        max,
        summary["tools"]["die"]["tool_fields"]["max_wear_depth"]
            .as_f64()
            .unwrap()
    );
}
