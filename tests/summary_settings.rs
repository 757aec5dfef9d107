//! What a run was (issue 52): summary.json's `settings` holds every solver setting in force,
//! defaults included, so two runs can be told apart from their summaries alone.
//!
//! Three runs of one scene: the defaults; `max_iterations` set to its default value (the
//! same run, so the same summary); and `threads` set to 1 where the default is 0 (all
//! cores), which changes no result (the engine's results do not depend on the thread
//! count, tests/parallel_assembly.rs), so the summaries differ in that one entry alone,
//! apart from the measured times.

mod common;

use serde_json::Value;

const SCENE: &str = r#"
let mesh = block([0, 0, 0], [4, 1, 1], [4, 1, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
let roller = tool("roller", cylinder([2, 0, 2], [0, 1, 0], 1.0)).path([[0, 0, 0, 0], [1, 0, 0, -0.05]]);
sim.add_tool(roller, "z+");
sim.fix("z-", "xyz");
sim.settings(#{ increments: 2 });
sim.run();
"#;

/// The run's summary.json, without the entries that are measured times.
fn summary(dir: &std::path::Path, tag: &str, settings: rhai::Map) -> Value {
    let script = dir.join("scene.rhai");
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(&script, SCENE).unwrap();
    let host = tribo::script::HostOptions {
        out_dir: dir.join(tag),
        base_settings: settings,
        ..Default::default()
    };
    tribo::script::run_file(&script, &[], &host).unwrap();
    let text = std::fs::read_to_string(dir.join(tag).join("summary.json")).unwrap();
    let mut v: Value = serde_json::from_str(&text).unwrap();
    let map = v.as_object_mut().unwrap();
    assert!(map.contains_key("wall_time_s") && map.contains_key("phase_times_s"));
    // No tool has tool-side fields here: their phase is never entered (issue 53's clock
    // times only what a run with fields does).
    assert_eq!(map["phase_times_s"]["tool_fields"], 0.0);
    map.remove("wall_time_s");
    map.remove("phase_times_s");
    v
}

/// Paths (a.b.c) of the leaves where `a` and `b` differ.
fn differences(a: &Value, b: &Value, at: &str, out: &mut Vec<String>) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            for k in keys {
                let (u, v) = (x.get(k), y.get(k));
                let path = format!("{at}{}{k}", if at.is_empty() { "" } else { "." });
                match (u, v) {
                    (Some(u), Some(v)) => differences(u, v, &path, out),
                    _ => out.push(path),
                }
            }
        }
        _ if a != b => out.push(at.to_string()),
        _ => {}
    }
}

#[test]
fn summaries_differ_in_exactly_the_setting_that_differs() {
    let dir = common::TestDir::new(&format!("tribo-summary-settings-{}", std::process::id()));
    let defaults = summary(&dir, "defaults", rhai::Map::new());
    let mut same = rhai::Map::new();
    same.insert("max_iterations".into(), rhai::Dynamic::from(25_i64));
    let explicit_default = summary(&dir, "explicit_default", same);
    let mut one = rhai::Map::new();
    one.insert("threads".into(), rhai::Dynamic::from(1_i64));
    let one_thread = summary(&dir, "one_thread", one);

    let settings = defaults["settings"].as_object().expect("a settings object");
    assert_eq!(settings["max_iterations"], 25, "the default is written");
    assert_eq!(settings["threads"], 0);
    for key in [
        "element",
        "thickness_points",
        "kinematics",
        "line_search",
        "dt_min",
    ] {
        assert!(settings.contains_key(key), "settings.{key} missing");
    }

    // Every key of sim.settings that configures the solver (the others are the output's and
    // the checkpoints', in summary.json's other entries).
    let output_keys = [
        "output_every",
        "output_interval",
        "frame_points",
        "units",
        "model_fraction",
        "flc",
        "flc_safety_margin",
        "thinning_limit",
        "stretch_limit",
        "wrinkle_limit",
        "checkpoint_every",
        "trim_tolerance",
    ];
    for key in tribo::script::SETTING_KEYS {
        assert!(
            settings.contains_key(*key) || output_keys.contains(key),
            "setting {key} missing from summary.json's settings"
        );
    }

    let mut diff = Vec::new();
    differences(&defaults, &explicit_default, "", &mut diff);
    assert!(
        diff.is_empty(),
        "a setting given its default value: {diff:?}"
    );
    differences(&defaults, &one_thread, "", &mut diff);
    assert_eq!(diff, ["settings.threads"]);
    assert_eq!(one_thread["settings"]["threads"], 1);
}
