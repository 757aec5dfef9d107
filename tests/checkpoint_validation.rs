//! Issue 16, item 10: a checkpoint is JSON a person can edit; restoring one checks every
//! value (finite, physical) and the mesh/tool fingerprint and refuses a tampered file with
//! a message naming the field. Temporary files of a writer killed mid-write are removed
//! at the next start.

mod common;

use serde_json::Value;
use tribo::solver::simulation::checkpoint::Checkpoint;
use tribo::solver::Simulation;

fn model() -> tribo::solver::Model {
    let mut model = common::cylinder_drag_model(8.0, 2.0, 8, 3.0);
    model.settings.increments = 6;
    model
}

/// A checkpoint after 3 increments (pressed and sliding), as JSON.
fn checkpoint_json() -> Value {
    let mut sim = Simulation::new(model()).unwrap();
    for _ in 0..3 {
        sim.step().unwrap();
    }
    serde_json::from_str(&Checkpoint::of(&sim, vec![0.0]).to_json().unwrap()).unwrap()
}

/// Restores `json` into a fresh simulation of the same model: Ok, or the error message.
fn restore(json: &Value) -> Result<(), String> {
    let mut sim = Simulation::new(model()).unwrap();
    Checkpoint::from_json(&json.to_string(), "tampered.json")
        .map_err(|e| e.to_string())?
        .restore(&mut sim)
        .map_err(|e| e.to_string())
}

/// The index of a contact node in contact, whose mu and work matter.
fn active_node(json: &Value) -> usize {
    json["state"]["contact"][0]
        .as_array()
        .unwrap()
        .iter()
        .position(|n| n["status"] != "Gap")
        .expect("a node in contact")
}

#[test]
fn an_untouched_checkpoint_is_accepted() {
    restore(&checkpoint_json()).unwrap();
}

#[test]
fn tampered_values_are_refused_naming_the_field() {
    let base = checkpoint_json();
    let k = active_node(&base);
    type Tamper = Box<dyn Fn(&mut Value)>;
    let cases: Vec<(&str, Tamper, String)> = vec![
        (
            "negative mu",
            Box::new(move |j: &mut Value| j["state"]["contact"][0][k]["mu"] = (-3.0).into()),
            format!("state.contact[0][{k}].mu = -3"),
        ),
        (
            "huge displacement",
            Box::new(|j: &mut Value| j["state"]["x"][7] = 1e308.into()),
            "state.x[7] (displacement y of node 2) = 100000000".to_string(),
        ),
        (
            "negative frictional work",
            Box::new(move |j: &mut Value| j["state"]["contact"][0][k]["work"] = (-1.0).into()),
            format!("state.contact[0][{k}].work = -1"),
        ),
        (
            "negative plastic strain",
            Box::new(|j: &mut Value| j["state"]["points"][5]["eq_plastic_strain"] = (-0.1).into()),
            "state.points[5].eq_plastic_strain = -0.1".to_string(),
        ),
        (
            "non-positive next increment",
            Box::new(|j: &mut Value| j["state"]["controller"]["dt"] = 0.0.into()),
            "state.controller.dt = 0".to_string(),
        ),
        (
            "huge multiplier",
            Box::new(move |j: &mut Value| j["state"]["contact"][0][k]["lambda"][2] = 1e300.into()),
            format!("state.contact[0][{k}].lambda[2] = 1000000000000000000000000000000"),
        ),
        (
            "wrong mesh fingerprint",
            Box::new(|j: &mut Value| j["model"]["mesh_hash"] = "0123456789abcdef".into()),
            "model.mesh_hash".to_string(),
        ),
        (
            "wrong tool fingerprint",
            Box::new(|j: &mut Value| j["model"]["tool_hashes"][0] = "0123456789abcdef".into()),
            "model.tool_hashes[0]".to_string(),
        ),
        (
            "wrong node count",
            Box::new(|j: &mut Value| {
                let n = j["model"]["nodes"].as_u64().unwrap();
                j["model"]["nodes"] = (n + 1).into();
            }),
            "mesh:".to_string(),
        ),
    ];
    for (what, tamper, expected) in cases {
        let mut json = base.clone();
        tamper(&mut json);
        let err = restore(&json).expect_err(what);
        assert!(err.contains(&expected), "{what}: {err}");
    }
    // A value JSON cannot hold as a finite f64 does not even parse.
    let text = base
        .to_string()
        .replacen("\"mu\":", "\"mu\":1e999,\"x\":", 1);
    assert!(Checkpoint::from_json(&text, "tampered.json").is_err());
}

/// The fingerprint also catches a mesh of the same size moved elsewhere.
#[test]
fn a_checkpoint_of_a_moved_mesh_is_refused() {
    let json = checkpoint_json();
    let mut moved = model();
    for p in moved.mesh.nodes.iter_mut() {
        p.x += 1e-9;
    }
    let mut sim = Simulation::new(moved).unwrap();
    let err = Checkpoint::from_json(&json.to_string(), "ck.json")
        .unwrap()
        .restore(&mut sim)
        .unwrap_err()
        .to_string();
    assert!(err.contains("model.mesh_hash"), "{err}");
}

/// A writer killed between creating its temporary file and renaming it leaves
/// `.NAME.PID.tmp`; the next run into the folder removes it when that process is gone,
/// and leaves other files alone.
#[test]
fn leftover_temporaries_of_a_dead_writer_are_removed_at_the_next_start() {
    let dir = std::env::temp_dir().join(format!("tribo-leftover-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("out/checkpoints")).unwrap();
    // PIDs above the kernel's limit (pid_max <= 4194304) are never running.
    let dead = dir.join("out/checkpoints/.checkpoint_0004.json.99999999.tmp");
    let live = dir.join(format!(
        "out/checkpoints/.checkpoint_0005.json.{}.tmp",
        std::process::id()
    ));
    let other = dir.join("out/checkpoints/notes.99999999.tmp");
    for f in [&dead, &live, &other] {
        std::fs::write(f, "partial").unwrap();
    }
    let script = dir.join("press.rhai");
    std::fs::write(
        &script,
        r#"let mesh = block([0, 0, 0], [1, 1, 1], [1, 1, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.fix("z-", "xyz");
sim.prescribe("z+", "z", [[0.0, 0.0], [1.0, -0.01]]);
sim.settings(#{ increments: 2, checkpoint_every: 1 });
sim.run();
"#,
    )
    .unwrap();
    let host = tribo::script::HostOptions {
        out_dir: dir.join("out"),
        ..Default::default()
    };
    tribo::script::run_file(&script, &[], &host).unwrap();
    assert!(!dead.exists(), "the dead writer's temporary is removed");
    assert!(live.exists() && other.exists(), "other files stay");
    assert!(dir.join("out/checkpoints/checkpoint_0002.json").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 52: a checkpoint restored into a model with another material or another friction
/// law was accepted (only the mesh and the tools' surfaces were fingerprinted).
#[test]
fn a_checkpoint_of_another_material_or_friction_law_is_refused() {
    let json = checkpoint_json();
    let restore_into = |model: tribo::solver::Model| {
        let mut sim = Simulation::new(model).unwrap();
        Checkpoint::from_json(&json.to_string(), "other.json")
            .unwrap()
            .restore(&mut sim)
            .map_err(|e| e.to_string())
    };
    let mut stiffer = model();
    stiffer.material = common::elastic(2000.0, 0.3);
    let err = restore_into(stiffer).unwrap_err();
    assert!(
        err.contains("model.material_hash") && err.contains("2000"),
        "{err}"
    );
    let mut rougher = model();
    rougher.contacts[0].tool.friction = tribo::contact::FrictionLaw::coulomb(0.3).unwrap();
    let err = restore_into(rougher).unwrap_err();
    assert!(
        err.contains("model.friction_hashes[0]") && err.contains("mu = 0.3"),
        "{err}"
    );
    // An old checkpoint without these fingerprints is still read (sizes and names checked).
    let mut old = json.clone();
    let fingerprint = old["model"].as_object_mut().unwrap();
    fingerprint.remove("material_hash");
    fingerprint.remove("friction_hashes");
    let mut sim = Simulation::new(model()).unwrap();
    Checkpoint::from_json(&old.to_string(), "old.json")
        .unwrap()
        .restore(&mut sim)
        .unwrap();
}

/// A block pressed on a plane and dragged, with a script friction law of body `law` (the
/// function's text, after `|work, slip, pressure|`), `before` above it (declarations, a
/// comment); checkpoints every 2 increments of 4.
fn law_scene(before: &str, law: &str) -> String {
    format!(
        r#"{before}
let mesh = block([0, 0, 0], [10, 10, 2], [3, 3, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.add_tool(tool("floor", plane([0, 0, 0], [0, 0, 1])).friction(|work, slip, pressure| {law}), "z-");
sim.load("z+", [0.0, 0.0, -100.0], [[0.0, 0.0], [1.0, 1.0]]);
sim.prescribe("z+", "x", [[0.0, 0.0], [1.0, 0.0], [2.0, 0.5]]);
sim.fix("z+", "y");
sim.settings(#{{ end_time: 2.0, increments: 4, checkpoint_every: 2 }});
sim.run();
"#
    )
}

/// Issue 52: a script friction law's body was not in the fingerprint (only its mu at zero
/// work), so a restart with another function of the same mu at zero work was accepted. Each
/// changed law below has mu = 0.2 at zero work; the same law after an unrelated edit of the
/// script (a comment line moving it down) is still accepted.
#[test]
fn a_restart_with_another_script_friction_law_body_is_refused() {
    let dir = common::TestDir::new(&format!("tribo-law-source-{}", std::process::id()));
    std::fs::create_dir_all(&*dir).unwrap();
    let run = |name: &str, text: &str, restart: Option<std::path::PathBuf>| {
        let script = dir.join(format!("{name}.rhai"));
        std::fs::write(&script, text).unwrap();
        let host = tribo::script::HostOptions {
            out_dir: dir.join(name),
            warnings: false,
            script_print: false,
            restart,
            ..Default::default()
        };
        tribo::script::run_file(&script, &[], &host).map_err(|e| e.to_string())
    };
    let law = "0.2 + 0.01 * work";
    run("first", &law_scene("let k = 0.01;", law), None).unwrap();
    let ck = dir.join("first/checkpoints/checkpoint_0002.json");
    assert!(ck.is_file());
    let again =
        |name: &str, before: &str, law: &str| run(name, &law_scene(before, law), Some(ck.clone()));
    again("same", "let k = 0.01;", law).unwrap();
    again("moved", "let k = 0.01;\n// an edit above the law\n", law).unwrap();
    for (name, before, other) in [
        ("body", "let k = 0.01;", "0.2 + 0.02 * work"),
        ("slip", "let k = 0.01;", "0.2 + 0.01 * work + 0.001 * slip"),
        ("captured", "let k = 0.02;", "0.2 + k * work"),
    ] {
        // The captured case: the first run's law must read k too.
        let reference = if name == "captured" {
            let first = run("first-k", &law_scene("let k = 0.01;", other), None);
            first.unwrap();
            dir.join("first-k/checkpoints/checkpoint_0002.json")
        } else {
            ck.clone()
        };
        let err = run(name, &law_scene(before, other), Some(reference)).unwrap_err();
        assert!(
            err.contains("model.friction_hashes[0]")
                && err.contains("friction law of tool 'floor'")
                && err.contains("script function |work, slip, pressure|")
                && err.contains("source fnv1a"),
            "{name}: {err}"
        );
    }
}
