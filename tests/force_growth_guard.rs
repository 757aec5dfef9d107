//! The divergence guard of models with force-controlled tools (`solver::newton`,
//! `FORCE_GROWTH_LIMIT`): once every force-controlled tool pressed at the committed state, an
//! attempt whose force residual grows to 3 times its first value after two Newton steps
//! ends (and is retried or cut back) instead of running out its budget; where a tool's force
//! is still coming on, the residual rises by design and the guard stays off. That it ends
//! attempts on the U-channel is asserted by the scene itself (tests/scenes/u_channel.rhai).

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
