//! Issue 16, item 11: each bad input is refused with the value the user gave (or accepted and
//! correct); never a silent wrong answer.

mod common;

fn run(name: &str, source: &str, extra: &[&str]) -> (i32, String) {
    common::run_script("item11", name, source, extra)
}

const SCENE: &str = r#"
let mesh = block([0, 0, 0], [1, 1, 1], [2, 2, 2]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
let roller = tool("roller", cylinder([0, 0, 2], [0, 1, 0], 1.0)).path([[0, 0, 0, 0], [1, 0, 0, -0.05]]);
"#;

#[test]
fn force_control_refuses_nan_and_infinity() {
    for (given, shown) in [("1.0/0.0", "inf"), ("-1.0/0.0", "-inf"), ("0.0/0.0", "NaN")] {
        let src = format!("{SCENE}let t = roller.force_control([0, 0, -1], {given});\n");
        let (code, err) = run("fc", &src, &[]);
        assert_eq!(code, 1, "{given}: {err}");
        assert!(
            err.contains(&format!("value = {shown} must be finite")),
            "{given}: {err}"
        );
        assert!(err.contains("fc.rhai:5:"), "{err}");
    }
}

#[test]
fn a_tool_with_no_candidate_nodes_warns() {
    let src = format!(
        "{SCENE}mesh.select(\"none\", |x, y, z| false);\nlet sim = simulation(mesh, linear_elastic(1000.0, 0.3));\nsim.add_tool(roller, \"none\");\n"
    );
    let (code, err) = run("empty", &src, &[]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning: ")
            && err.contains("empty.rhai:7:")
            && err.contains("tool 'roller' has no candidate nodes (node set 'none' is empty)"),
        "{err}"
    );
}

#[test]
fn a_second_value_for_a_held_component_is_refused() {
    let src = format!("{SCENE}sim.fix(\"z-\", \"xyz\");\nsim.prescribe(\"z-\", \"z\", 0.1);\n");
    let (code, err) = run("conflict", &src, &[]);
    assert_eq!(code, 1);
    assert!(
        err.contains("prescribing 'z-' z conflicts with the earlier constraint 'z-.z'")
            && err.contains("conflict.rhai:6:"),
        "{err}"
    );
    // The same value twice (or other components) is fine.
    let src = format!("{SCENE}sim.fix(\"z-\", \"xyz\");\nsim.fix(\"z-\", \"z\");\nsim.prescribe(\"z+\", \"z\", -0.01);\n");
    assert_eq!(run("same", &src, &[]).0, 0);
}

#[test]
fn a_folded_bezier_patch_is_refused() {
    // Bilinear patch whose far edge is reversed: a bow-tie crossing itself at v = 1/2.
    let bow = "bezier_patch([[[0, 0, 0], [0, 1, 0]], [[1, 1, 0], [1, 0, 0]]])";
    let (code, err) = run("bow", &format!("let s = patch_surface([{bow}]);\n"), &[]);
    assert_eq!(code, 1);
    assert!(
        err.contains("patch 0 folds over itself") && err.contains("bow.rhai:1:"),
        "{err}"
    );
    // The same patch with its corners in order is accepted.
    let ok = "bezier_patch([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0]]])";
    assert_eq!(
        run("flat", &format!("let s = patch_surface([{ok}]);\n"), &[]).0,
        0
    );
}

#[test]
fn counts_are_refused_with_the_given_value() {
    for (setting, msg) in [
        (
            "increments: -3",
            "increments = -3 must be a whole number from 1 to",
        ),
        (
            "increments: 2.5",
            "increments = 2.5 must be a whole number from 1 to",
        ),
        (
            "increments: 0",
            "increments = 0 must be a whole number from 1 to",
        ),
        (
            "max_cutbacks: -1",
            "max_cutbacks = -1 must be a whole number >= 0",
        ),
        (
            "max_iterations: 2.5",
            "max_iterations = 2.5 must be a whole number >= 0",
        ),
        ("r_fraction: -0.1", "r_fraction = -0.1 must be > 0"),
        ("r_fraction: 0.0", "r_fraction = 0 must be > 0"),
    ] {
        let src = format!("{SCENE}sim.settings(#{{ {setting} }});\n");
        let (code, err) = run("counts", &src, &[]);
        assert_eq!(code, 1, "{setting}");
        assert!(
            err.contains(msg) && err.contains("counts.rhai:5:"),
            "{setting}: {err}"
        );
    }
}

#[test]
fn set_values_are_clear_and_integers_fill_float_declarations() {
    let src = "let mu = 0.2;\nprint(mu);\n";
    for bad in ["nan", "inf", "-inf", "NaN"] {
        let (code, err) = run("setnan", src, &["--set", &format!("mu={bad}")]);
        assert_eq!(code, 1);
        assert!(
            err.contains(&format!(
                "--set mu={bad}: the value must be a finite number"
            )),
            "{err}"
        );
    }
    // An integer for a float declaration is a float: ceil() of it works.
    let src = "let travel = 40.0;\nlet step = 2.5;\nlet n = (travel / step).ceiling();\nassert(n == 10.0, `${n}`);\n";
    let (code, err) = run("setint", src, &["--set", "travel=10", "--set", "step=1"]);
    assert_eq!(code, 0, "{err}");
    // An integer declaration keeps integers.
    let src = "let cells = 4;\nlet m = block([0, 0, 0], [1, 1, 1], [cells, 1, 1]);\n";
    assert_eq!(run("setcells", src, &["--set", "cells=3"]).0, 0);
}

#[test]
fn restart_without_a_simulation_is_an_error() {
    let (code, err) = run(
        "norestart",
        "let a = 1;\n",
        &["--restart", "/nonexistent/ck.json"],
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("started no simulation, so the checkpoint was not used"),
        "{err}"
    );
}

#[test]
fn mu_at_and_charts_refuse_non_finite_values() {
    let (code, err) = run(
        "muat",
        "let law = coulomb(0.2);\nlaw.mu_at(0.0/0.0);\n",
        &[],
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("mu_at theta = NaN must be finite") && err.contains("muat.rhai:2:"),
        "{err}"
    );
    let chart =
        "line_chart(\"c.svg\", #{ series: [#{ name: \"a\", x: [0.0, 1.0], y: [0.0, 1e308] }] });\n";
    let (code, err, dir) = common::run_script_in("item11", "chart", chart, &[]);
    assert_eq!(code, 1);
    assert!(
        err.contains("series[0].y[1] = 100000000000000000000")
            || err.contains("series[0].y[1] = 1e308"),
        "{err}"
    );
    let out = dir.join("out");
    assert!(out.is_dir(), "the run's output folder exists");
    assert!(!out.join("c.svg").exists() && !out.join("c.csv").exists());
}

#[test]
fn a_tool_path_far_beyond_the_body_is_refused() {
    let src = SCENE.replace("[1, 0, 0, -0.05]", "[1, 1e308, 0, -0.05]")
        + "sim.add_tool(roller, \"z+\");\n";
    let (code, err) = run("reach", &src, &[]);
    assert_eq!(code, 1);
    assert!(
        err.contains(
            "path of tool 'roller': its travel = 1e308 is more than 1e6 times the body's size"
        ) && err.contains("reach.rhai:5:"),
        "{err}"
    );
}
