//! Issue 49, large meshes in scripts: `sim.contact_nodes` of a tool with more than 10 000
//! candidate nodes reaches the script (it stopped at about 6 000 on Rhai's map-size limit,
//! which counts the entries of every nested map); and a post-processing call that fails after `sim.run()`
//! leaves summary.json with the error, the simulation's figures and the script's entries,
//! and the final checkpoint.

mod common;

use common::TestDir;
use tribo::script::{self, HostOptions};

fn host(out: &std::path::Path) -> HostOptions {
    HostOptions {
        out_dir: out.to_path_buf(),
        warnings: false,
        script_print: false,
        ..HostOptions::default()
    }
}

/// A 100 x 100 x 1 block (20 402 nodes) on a flat floor: 101 x 101 = 10 201 candidates.
/// Only the query runs (no increment), with the output off, so the test takes seconds.
#[test]
fn contact_nodes_of_ten_thousand_candidates_reach_the_script() {
    let dir = TestDir::new(&format!("tribo-large-query-{}", std::process::id()));
    std::fs::create_dir_all(&*dir).unwrap();
    let path = dir.join("big.rhai");
    std::fs::write(
        &path,
        r#"
let mesh = block([0, 0, 0], [100, 100, 2], [100, 100, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.add_tool(tool("floor", plane([0, 0, 0], [0, 0, 1])).friction(coulomb(0.1)), "z-");
sim.fix("z+", "z");
sim.settings(#{ end_time: 1.0, increments: 1, output_every: 0 });
let all = sim.contact_nodes("floor");
assert(all.len() == 101 * 101, `${all.len()} candidates`);
// Every record reads like the map it replaces: the bottom face, untouched, at gap 0.
let seen = [];
seen.pad(mesh.n_nodes, false);
for n in all {
    assert(n.x[2].abs() < 1e-12 && n.x[0] >= 0.0 && n.x[0] <= 100.0, `node ${n.node} at ${n.x}`);
    assert(n.status == "gap" && n.gap.abs() < 1e-12 && n.work == 0.0, `node ${n.node}: ${n}`);
    assert(!seen[n.node], `node ${n.node} listed twice`);
    seen[n.node] = true;
}
// One record as a map, and one node looked up among the ten thousand.
let last = all[all.len() - 1];
let m = last.to_map();
assert(m.keys().len() == 11 && m.node == last.node, `to_map: ${m}`);
assert(sim.contact_node("floor", last.node).x == last.x, "contact_node finds the last one");
"#,
    )
    .unwrap();
    let out = dir.join("out");
    if let Err(e) = script::run_file(&path, &[], &host(&out)) {
        panic!("{e}");
    }
}

/// The sliding block run to its end, then a post-processing call that fails (a node that is
/// no candidate): summary.json records the failed call with its line, and keeps the run's
/// figures and the entry the script added before; the final checkpoint holds the end state.
#[test]
fn a_call_failing_after_the_run_leaves_the_summary_and_final_checkpoint() {
    let dir = TestDir::new(&format!("tribo-after-run-{}", std::process::id()));
    std::fs::create_dir_all(&*dir).unwrap();
    let path = dir.join("after_run.rhai");
    std::fs::write(
        &path,
        r#"
let mesh = block([0, 0, 0], [10, 10, 2], [3, 3, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.add_tool(tool("floor", plane([0, 0, 0], [0, 0, 1])).friction(coulomb(0.25)), "z-");
sim.load("z+", [0.0, 0.0, -100.0], [[0.0, 0.0], [1.0, 1.0]]);
sim.prescribe("z+", "x", [[0.0, 0.0], [1.0, 0.0], [2.0, 0.5]]);
sim.fix("z+", "y");
sim.settings(#{ end_time: 2.0, increments: 4 });
sim.run();
sim.summary("slipping", sim.contact_nodes("floor").filter(|n| n.status == "slip").len());
let top = sim.contact_node("floor", 31);
"#,
    )
    .unwrap();
    let out = dir.join("out");
    let err = script::run_file(&path, &[], &host(&out))
        .expect_err("the last call fails")
        .to_string();
    assert!(err.contains("not a contact candidate"), "{err}");
    let text = std::fs::read_to_string(out.join("summary.json")).expect("summary.json written");
    let summary: serde_json::Value = serde_json::from_str(&text).unwrap();
    let error = summary["error"].as_str().expect("the error is recorded");
    assert!(
        error.contains("node 31 is not a contact candidate")
            && error.contains("after_run.rhai:11:"),
        "the failed call and its line: {error}"
    );
    assert_eq!(summary["increments"], 4);
    assert_eq!(summary["time"], 2.0);
    assert_eq!(summary["slipping"], 16, "the script's entry kept");
    let ck = out.join("checkpoints/final.json");
    let text = std::fs::read_to_string(&ck).expect("checkpoints/final.json");
    let ck =
        tribo::solver::simulation::checkpoint::Checkpoint::from_json(&text, "final.json").unwrap();
    assert_eq!(ck.history.len(), 4);
}

/// `sim.history()` and `sim.node_history` at 20 402 nodes (a 100 x 100 x 1 block pressed on
/// a floor by 1e-3, one increment; one is enough: neither grows with the mesh): records
/// that read like the maps they replace, for the last of the 10 201 candidates.
#[test]
fn history_and_node_history_at_ten_thousand_candidates() {
    run_script(
        "big_history.rhai",
        r#"
let mesh = block([0, 0, 0], [100, 100, 2], [100, 100, 1]);
assert(mesh.n_nodes == 20402, `${mesh.n_nodes} nodes`);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.add_tool(tool("floor", plane([0, 0, 0], [0, 0, 1])).friction(coulomb(0.1)), "z-");
sim.prescribe("z+", "z", [[0.0, 0.0], [1.0, -1e-3]]);
sim.settings(#{ end_time: 1.0, increments: 1, output_every: 0 });
sim.run();
let rows = sim.history();
assert(rows.len() == 1 && rows[0].index == 1 && rows[0]["time"] == 1.0, `history: ${rows}`);
assert("iterations" in rows[0] && rows[0].keys().len() == rows[0].to_map().len(), "keys");
assert(rows[0].active_nodes == 101 * 101, `every candidate presses: ${rows[0].active_nodes}`);
let last = sim.contact_nodes("floor")[101 * 101 - 1].node;
let h = sim.node_history("floor", last);
assert(h.len() == 1 && h[0].increment == 1 && h[0].status != "gap", `node ${last}: ${h}`);
"#,
    );
}

/// A run of 4 000 increments (one hexahedron pressed on a floor): `sim.history()`, 19
/// entries an increment and a map of one entry per tool for forces and offsets (21 here),
/// is past Rhai's 65 536 map entries, where its array of maps stopped (at 3 120 increments
/// here); its last record goes into summary.json as its map.
#[test]
fn history_of_more_increments_than_the_map_limit() {
    run_script(
        "long_history.rhai",
        r#"
let mesh = block([0, 0, 0], [1, 1, 1], [1, 1, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.add_tool(tool("floor", plane([0, 0, 0], [0, 0, 1])).friction(coulomb(0.1)), "z-");
sim.prescribe("z+", "z", [[0.0, 0.0], [1.0, -1e-3]]);
sim.fix("z+", "x");
sim.fix("z+", "y");
sim.settings(#{ end_time: 1.0, increments: 4000, output_interval: 0.5 });
sim.run();
let rows = sim.history();
assert(rows.len() == 4000, `${rows.len()} reports`);
let entries = 0;
for r in rows { entries += r.keys().len(); }
assert(entries > 65536, `${entries} entries in all`);
assert(rows[3999].index == 4000 && (rows[3999].time - 1.0).abs() < 1e-9, `${rows[3999]}`);
let node = sim.contact_nodes("floor")[0].node;
let h = sim.node_history("floor", node);
assert(h.len() == 4000 && h[3999].increment == 4000, `${h.len()} entries`);
sim.summary("last_row", rows[3999]);
"#,
    );
}

/// Runs `source` as the script `name` in a fresh folder; panics with the script's error.
fn run_script(name: &str, source: &str) {
    let dir = TestDir::new(&format!("tribo-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&*dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, source).unwrap();
    if let Err(e) = script::run_file(&path, &[], &host(&dir.join("out"))) {
        panic!("{e}");
    }
}
