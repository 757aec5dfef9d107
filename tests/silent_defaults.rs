//! Defaults that used to fail silently (issue 52, item 2): each is now an error that names
//! the fault and the fix.
//!
//! * A run on the default small-strain kinematics that rotates past their range (0.1 rad,
//!   `kinematics_check`) stops; a script that chose "small" itself is only warned, and
//!   "finite" runs on.
//! * `--set travel=-5` on the square cup is refused (it used to run the variant's 30 mm).
//! * A node set selected after `simulation(mesh, ...)` made its copy of the mesh: the
//!   unknown-set error says why.

mod common;

/// A strip clamped at x = 0 and pushed down 3 mm at its tip by a roller: the tip cells turn
/// by 0.15 rad at t = 0.3, well past 0.1 rad, with elastic strains of a few 1e-3.
const BEND: &str = r#"
let kin = "";
let mesh = block([0, 0, 0], [10, 1, 0.5], [10, 1, 2]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
let roller = tool("roller", cylinder([9, 0, 1.5], [0, 1, 0], 1.0)).path([[0, 0, 0, 0], [1, 0, 0, -3.0]]);
sim.add_tool(roller, "z+");
sim.fix("x-", "xyz");
sim.fix("y-", "y");
if kin != "" { sim.settings(#{ kinematics: kin }); }
sim.settings(#{ increments: 10 });
sim.run();
"#;

#[test]
fn default_small_strain_past_its_range_stops_with_the_fix() {
    let (code, err, dir) = common::run_script_in("kin", "bend", BEND, &[]);
    assert_eq!(code, 1, "{err}");
    let first = err.lines().find(|l| l.starts_with("error:")).unwrap_or("");
    assert!(
        first.contains("is past the range of the default small-strain kinematics (0.1 rad)"),
        "reason first: {err}"
    );
    assert!(
        err.contains("fix: sim.settings(#{ kinematics: \"finite\" })"),
        "{err}"
    );
    assert!(
        !err.contains("warning: increment"),
        "the error replaces the warning: {err}"
    );
    let summary = std::fs::read_to_string(dir.join("out/summary.json")).unwrap();
    assert!(summary.contains("\"status\": \"stopped\""), "{summary}");

    // Chosen knowingly: the solver's warning, and the run finishes.
    let (code, err) = common::run_script("kin-small", "bend", BEND, &["--set", "kin=small"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("warning: increment 3"), "{err}");
    // Finite strain: no complaint at all.
    let (code, err) = common::run_script("kin-finite", "bend", BEND, &["--set", "kin=finite"]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("kinematics"), "{err}");
}

#[test]
fn square_cup_refuses_a_negative_travel() {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/square_cup.rhai");
    let out = common::TestDir::new(&format!("tribo-cup-travel-{}", std::process::id()));
    for (set, shown) in [
        ("travel=-5", "travel = -5"),
        ("mu=-0.1", "mu = -0.1"),
        ("die_radius=-8", "die_radius = -8"),
    ] {
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_tribo"))
            .arg("run")
            .arg(&script)
            .args([
                "--quiet",
                "--overwrite",
                "--set",
                "cells=4",
                "--set",
                set,
                "--out",
            ])
            .arg(&*out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{set}: {err}");
        assert!(
            err.contains(shown) && err.contains("must be >= 0"),
            "{set}: {err}"
        );
        assert!(!out.join("history.csv").exists(), "{set}: nothing ran");
    }
}

#[test]
fn a_set_selected_after_the_simulation_says_why_it_is_unknown() {
    let src = "let mesh = block([0, 0, 0], [1, 1, 1], [2, 2, 2]);\n\
               let sim = simulation(mesh, linear_elastic(1000.0, 0.3));\n\
               mesh.select(\"top\", |x, y, z| z > 0.9);\n\
               sim.fix(\"top\", \"z\");\n";
    let (code, err) = common::run_script("late-set", "late", src, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("node set = \"top\" is unknown")
            && err.contains("mesh.select(\"top\", ...) ran after simulation(mesh, ...)")
            && err.contains("select every set before simulation(...)"),
        "{err}"
    );
    // Selected before: no such note (and the set is known).
    let src = src
        .replace(
            "let sim = simulation(mesh, linear_elastic(1000.0, 0.3));\n",
            "",
        )
        .replace(
            "sim.fix",
            "let sim = simulation(mesh, linear_elastic(1000.0, 0.3));\nsim.fix",
        );
    let (code, err) = common::run_script("early-set", "early", &src, &[]);
    assert_eq!(code, 0, "{err}");
}

/// Re-selecting a set the simulation already holds used to change the script's mesh only,
/// and the run went on with the old set unnoticed.
#[test]
fn reselecting_a_set_after_the_simulation_is_refused() {
    let src = "let mesh = block([0, 0, 0], [1, 1, 1], [2, 2, 2]);\n\
               mesh.select(\"top\", |x, y, z| z > 0.9);\n\
               let sim = simulation(mesh, linear_elastic(1000.0, 0.3));\n\
               mesh.select(\"top\", |x, y, z| z < 0.1);\n\
               sim.fix(\"top\", \"z\");\n";
    let (code, err) = common::run_script("reselect", "reselect", src, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("mesh.select(\"top\", ...): the set \"top\" already exists")
            && err.contains("select under a new name")
            && err.contains(":4:"),
        "{err}"
    );
}

/// `sim.step()` after the end time was reported as a failure to converge, and overwrote
/// the finished run's summary with a stop.
#[test]
fn stepping_after_the_end_says_so_and_how_to_go_on() {
    let src = "let mesh = block([0, 0, 0], [10, 10, 2], [2, 2, 1]);\n\
               let sim = simulation(mesh, linear_elastic(1000.0, 0.3));\n\
               sim.fix(\"z-\", \"xyz\");\n\
               sim.load(\"z+\", [0.0, 0.0, -10.0], [[0.0, 0.0], [1.0, 1.0]]);\n\
               sim.settings(#{ end_time: 1.0, increments: 2 });\n\
               sim.run();\n\
               let after = \"stepped\";\n\
               try { sim.step(); } catch (e) { after = \"\" + e; }\n\
               assert(after.contains(\"already reached its end time 1 (increment 2)\"), after);\n\
               assert(after.contains(\"sim.settings(#{ end_time: 2 })\"), after);\n\
               assert(!after.contains(\"no convergence\"), after);\n\
               sim.settings(#{ end_time: 2.0 });\n\
               let r = sim.step();\n\
               assert(r.time == 2.0, \"raising the end time steps on: \" + r.time);\n";
    let (code, err) = common::run_script("after-end", "after_end", src, &[]);
    assert_eq!(code, 0, "{err}");
}
