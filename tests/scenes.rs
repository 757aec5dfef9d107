//! Scenes nobody tuned (issue 14): every tests/scenes/*.rhai script is written as a new
//! user would, from README.md and docs/script-api.md, with the engine's default solver
//! settings (only end time, increments and kinematics set). Each script asserts its own
//! outcome (finished, no increment above 25 Newton iterations, and a physical check such as
//! Coulomb's ratio or a force balance); a failure names the script, line and column.

mod common;

use std::path::PathBuf;
use tribo::script::{self, HostOptions};

#[test]
fn every_scene_finishes_with_engine_defaults() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
    let scripts = common::rhai_scripts("scenes");
    assert!(scripts.len() >= 3, "scenes in {}", dir.display());
    let mut failures = Vec::new();
    for path in &scripts {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let host = HostOptions {
            out_dir: std::env::temp_dir()
                .join(format!("tribo-scene-{}-{name}", std::process::id())),
            ..HostOptions::default()
        };
        if let Err(e) = script::run_file(path, &[], &host) {
            failures.push(format!("{name}: {e}"));
        }
    }
    assert!(
        failures.is_empty(),
        "failed scenes:\n{}",
        failures.join("\n")
    );
}
