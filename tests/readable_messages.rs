//! Messages a person can read (issue 52, item 4): a run that stops says why on its first
//! line and gives the details on the following lines, each of a readable length. (The
//! contact-cycling warning's single line: tests/status_prediction.rs; `:help settings` as a
//! table: the unit tests of script::repl::help.)

mod common;

/// A roller pressed into a block with one Newton iteration per attempt, one cutback and no
/// last resort: the first increment cannot converge.
const STOPS: &str = r#"
let mesh = block([0, 0, 0], [4, 1, 1], [4, 1, 2]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
let roller = tool("roller", cylinder([2, 0, 2], [0, 1, 0], 1.0)).path([[0, 0, 0, 0], [1, 0, 0, -0.5]]);
sim.add_tool(roller, "z+");
sim.fix("z-", "xyz");
sim.settings(#{ increments: 2, max_iterations: 1, max_cutbacks: 1, last_resort: false,
                kinematics: "small" });
sim.run();
"#;

#[test]
fn a_stop_gives_its_reason_first_and_details_below() {
    let (code, err) = common::run_script("stop-lines", "stops", STOPS, &[]);
    assert_eq!(code, 1, "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with("error:"))
        .expect("an error line");
    let first = lines[at];
    assert!(
        first.contains("no convergence: increment 1") && first.contains("without convergence"),
        "the reason on the first line: {first}"
    );
    let details = &lines[at + 1..];
    assert!(details.len() >= 2, "details on lines of their own: {err}");
    assert!(details.iter().all(|l| l.starts_with("  ")), "{err}");
    assert!(
        details.iter().any(|l| l.contains("checkpoints/final.json")),
        "where the state was saved: {err}"
    );
    assert!(
        !err.contains("Young's modulus"),
        "no units note at E = 1000: {err}"
    );
    // The first line carries the script's path and position before the reason (a temporary
    // folder here, some 45 characters); the one line was 455 characters before.
    for line in &lines[at..] {
        assert!(
            line.chars().count() <= 280,
            "{} characters: {line}",
            line.len()
        );
    }
}

/// A stop before any increment converged, with a sheet metal's modulus written in GPa in a
/// model of mm and N (the default units), says what the number means; named other units,
/// or no stop, say nothing of it.
#[test]
fn a_first_increment_stop_with_a_modulus_in_gpa_suggests_the_units() {
    let soft = STOPS.replace("linear_elastic(1000.0, 0.3)", "linear_elastic(210.0, 0.3)");
    let (code, err) = common::run_script("units-note", "gpa", &soft, &[]);
    assert_eq!(code, 1, "{err}");
    let note = err
        .lines()
        .find(|l| l.contains("note: Young's modulus"))
        .unwrap_or_else(|| panic!("no units note: {err}"));
    assert!(
        note.starts_with("  note: Young's modulus 210.0 in a model of mm and N is 210.0 MPa")
            && note.contains("times 1,000"),
        "{note}"
    );
    let metres = soft.replace(
        "kinematics: \"small\"",
        "kinematics: \"small\", units: #{ length: \"m\" }",
    );
    assert!(metres.contains("units"), "the replacement took");
    let (code, err) = common::run_script("units-note", "metres", &metres, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(!err.contains("Young's modulus"), "{err}");
}
