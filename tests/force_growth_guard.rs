//! The divergence guard of models with force-controlled tools (`solver::newton`,
//! `FORCE_GROWTH_LIMIT`): once every force-controlled tool pressed at the committed state, an
//! attempt whose force residual grows to 3 times its first value after two Newton steps
//! ends (and is retried or cut back) instead of running out its budget; where a tool's force
//! is still coming on, the residual rises by design and the guard stays off.

mod common;

use common::TestDir;
use serde_json::Value;

fn reasons(summary: &Value) -> Vec<String> {
    summary["cutback_reasons"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["reason"].as_str().unwrap().to_string())
        .collect()
}

/// The 25 x 25 x 1 benchmark cup's first increment: the holder's force comes on (it touched
/// nothing at the committed state), and the residual rises by design over the first
/// iterations. With the guard on there, that increment's prediction attempt ended early and
/// its plain retry failed (one cutback, 22 iterations discarded, measured); without, it
/// converges in one attempt of 30 iterations.
#[test]
fn the_guard_waits_for_the_holder_force_to_come_on() {
    let out = TestDir::new(&format!(
        "tribo_force_growth_cup_first_{}",
        std::process::id()
    ));
    let sets = [
        "travel=0.5".to_string(),
        "variant=\"benchmark\"".to_string(),
    ];
    let s = common::run_edited_script(
        "square_cup.rhai",
        "linear_solver: linear_solver,",
        "",
        &sets,
        &out,
    );
    assert_eq!(s["cutbacks"].as_u64(), Some(0), "{:?}", reasons(&s));
    assert_eq!(s["discarded_iterations"].as_u64(), Some(0));
}

/// The U-channel of tests/scenes (its own definition, punch at zero gap, first 3 mm in 6
/// increments) with r at the membrane stiffness under each node (`r_fraction: 1.0`, the
/// default before it became a tenth): attempts go astray there and the guard ends them
/// (measured: two of the recorded cutback reasons, at 2 and 2.5 mm, each after the force
/// residual grew over a thousandfold). At the default r no attempt of the whole scene grows
/// so (the scene's 8 and 7 cutbacks end otherwise), so this is the guard's test.
#[test]
fn the_guard_ends_attempts_gone_astray_on_the_u_channel() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = std::fs::read_to_string(root.join("tests/scenes/u_channel.rhai")).unwrap();
    let marker = "kinematics: \"finite\" });";
    let driver = "for lift in [0.0, 0.1] {";
    assert!(
        scene.contains(marker) && scene.contains(driver),
        "the scene's layout"
    );
    let source = format!(
        "{}let r = u_channel(0.0, 3.0, 6, false);\nprint(`cutbacks ${{r.cutbacks}}`);\n",
        scene[..scene.find(driver).unwrap()]
            .replace(marker, "kinematics: \"finite\", r_fraction: 1.0 });")
    );
    let (code, stderr, dir) =
        common::run_script_in("force_growth_uc", "u_channel_former_r", &source, &[]);
    assert_eq!(code, 0, "{stderr}");
    let summary: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("out").join("summary.json")).unwrap(),
    )
    .unwrap();
    // Counted by the failures' typed kind, not their text.
    let grown = summary["cutback_reasons"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["kind"] == "force_growth")
        .count();
    assert!(
        grown > 0,
        "no attempt ended by the guard: {:?}",
        reasons(&summary)
    );
}
