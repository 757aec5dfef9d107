//! Scenes nobody tuned (issue 14): every tests/scenes/*.rhai script is written as a new
//! user would, from README.md and docs/script-api.md, with the engine's default solver
//! settings (only end time, increments and kinematics set). Each script asserts its own
//! outcome (finished, no increment above 25 Newton iterations, and a physical check such as
//! Coulomb's ratio or a force balance); a failure names the script, line and column.

mod common;

use std::path::PathBuf;
use tribo::script::{self, HostOptions};

/// Scenes run by a test of their own (about 17 s of CPU), so that no test takes much more
/// than 20 s.
const OWN_TEST: &[&str] = &["u_channel"];

/// Runs one scene script; its error (script, line, column and message) on failure. The
/// output (frames of every increment, several MB per scene) is removed when the scene
/// passes and kept, with its folder named, when it fails.
fn run_scene(path: &std::path::Path) -> Result<(), String> {
    let name = path.file_stem().unwrap().to_string_lossy().to_string();
    let out = std::env::temp_dir().join(format!("tribo-scene-{}-{name}", std::process::id()));
    let host = HostOptions {
        out_dir: out.clone(),
        ..HostOptions::default()
    };
    match script::run_file(path, &[], &host) {
        Ok(_) => {
            let _ = std::fs::remove_dir_all(&out);
            Ok(())
        }
        Err(e) => Err(format!("{name}: {e} (output in {})", out.display())),
    }
}

#[test]
fn every_scene_finishes_with_engine_defaults() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes");
    let scripts = common::rhai_scripts("scenes");
    assert!(scripts.len() >= 3, "scenes in {}", dir.display());
    let failures: Vec<String> = scripts
        .iter()
        .filter(|p| !OWN_TEST.contains(&p.file_stem().unwrap().to_string_lossy().as_ref()))
        .filter_map(|p| run_scene(p).err())
        .collect();
    assert!(
        failures.is_empty(),
        "failed scenes:\n{}",
        failures.join("\n")
    );
}

/// The whole 20 mm U-channel draw, punch at zero gap and 0.1 mm above, with engine
/// defaults (tests/scenes/u_channel.rhai asserts finishing, iteration bounds, the holder's
/// force and Coulomb ratio, vertical balance, draw-in and no penetration).
#[test]
fn u_channel_draws_its_20mm_in_both_variants() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/u_channel.rhai");
    if let Err(e) = run_scene(&path) {
        panic!("{e}");
    }
}
