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
