//! Runs every tests/scripts/*.rhai through the script engine; a script error or a failed
//! script assertion fails the test and names the file, line and column.

mod common;

use common::TestDir;
use std::path::PathBuf;
use tribo::script::{self, HostOptions};

/// The output folder of case `name`, removed when the test passes.
fn out_dir(name: &str) -> TestDir {
    TestDir::new(&format!("tribo-scripted-{}-{name}", std::process::id()))
}

#[test]
fn every_scripted_case_passes() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scripts");
    let scripts = common::rhai_scripts("scripts");
    assert!(
        !scripts.is_empty(),
        "no scripted cases in {}",
        dir.display()
    );
    let mut failures = Vec::new();
    // Kept until the end: a failure leaves every case's output for inspection.
    let mut outputs = Vec::new();
    for path in &scripts {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let out = out_dir(&name);
        let host = HostOptions {
            out_dir: out.to_path_buf(),
            ..HostOptions::default()
        };
        outputs.push(out);
        match script::run_file(path, &[], &host) {
            Ok(()) => println!("ok    {name}"),
            Err(e) => {
                println!("FAIL  {name}: {e}");
                failures.push(format!("{name}: {e}"));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "failed scripted cases:\n{}",
        failures.join("\n")
    );
}

#[test]
fn a_failed_script_assertion_is_an_error_with_its_position() {
    let dir = out_dir("assert");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("fails.rhai");
    std::fs::write(&path, "let x = 1;\n\nassert(x == 2, \"x is two\");\n").unwrap();
    let err = script::run_file(&path, &[], &HostOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("x is two"), "{err}");
    assert!(err.contains("fails.rhai:3:"), "{err}");
}
