//! Charts and summary entries from a script: a force-controlled strip-drawing run writes a
//! line chart of the holder's offset and colour maps of nodal fields on the strip's top
//! face, each with its CSV, and adds entries to summary.json; paths that would leave the
//! output folder are refused.

mod common;

use std::path::{Path, PathBuf};
use tribo::script::{self, HostOptions};

const SCENE: &str = r#"
let mu = 0.25;
let mesh = block([0, 0, 0], [10, 10, 2], [6, 6, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.add_tool(tool("floor", plane([0, 0, 0], [0, 0, 1])).friction(coulomb(mu)), "z-");
sim.add_tool(tool("holder", plane([0, 0, 2], [0, 0, -1])).friction(coulomb(mu))
    .force_control([0, 0, -1], [[0.0, 0.0], [1.0, 100.0]]), "z+");
sim.prescribe("x-", "x", [[0.0, 0.0], [1.0, 0.0], [2.0, 0.5]]);
sim.fix("y-", "y");
sim.settings(#{ end_time: 2.0, increments: 4 });
"#;

/// Runs the scene with `body` after it; the run's folder (removed when the test passes), its
/// `out` and the outcome.
fn run(name: &str, body: &str) -> (common::TestDir, PathBuf, tribo::Result<()>) {
    let dir = common::TestDir::new(&format!("tribo-charts-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&*dir).unwrap();
    let script = dir.join("case.rhai");
    std::fs::write(&script, format!("{SCENE}\n{body}")).unwrap();
    let out = dir.join("out");
    let host = HostOptions {
        out_dir: out.clone(),
        ..HostOptions::default()
    };
    let result = script::run_file(&script, &[], &host);
    (dir, out, result)
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn script_writes_charts_with_csv_and_summary_entries() {
    let (_dir, out, result) = run(
        "ok",
        r#"
let t = []; let s = [];
while !sim.finished() {
    let r = sim.step();
    t.push(r.time);
    s.push(r.tool_offsets.holder);
}
line_chart("charts/holder.svg", #{ title: "Holder offset", x_label: "time", y_label: "offset [mm]",
    series: [#{ name: "holder", x: t, y: s }] });
sim.chart_field("charts/work_top.svg", "z+", "frictional_work", #{ title: "Frictional work, top" });
sim.chart_field("charts/mu_top.svg", "z+", "mu", #{ range: [0.0, 0.3], configuration: "reference" });
sim.chart_field("charts/uz.svg", "z+", "displacement_z");
sim.chart_field("charts/vm.svg", "z-", "von_mises");
sim.chart_field("charts/epsp.svg", "z+", "equivalent_plastic_strain", #{ range: [0, 0.1] });
sim.summary("draw_in", [#{ punch_travel: 15, dx: 1.5, dd: () }]);
sim.summary("holder_offset_max", s[s.len() - 1]);
"#,
    );
    result.unwrap();
    let chart = read(&out.join("charts/holder.svg"));
    assert!(chart.contains(">Holder offset</text>"));
    let csv = read(&out.join("charts/holder.csv"));
    assert_eq!(
        csv.lines().count(),
        1 + 4,
        "header and one row per increment"
    );
    for name in ["work_top", "mu_top", "uz", "vm", "epsp"] {
        let svg = read(&out.join(format!("charts/{name}.svg")));
        assert!(svg.starts_with("<?xml") && svg.trim_end().ends_with("</svg>"));
        let csv = read(&out.join(format!("charts/{name}.csv")));
        assert_eq!(
            csv.lines().count(),
            1 + 49,
            "{name}: header and the 7 x 7 face nodes"
        );
    }
    // The fixed range shows on the colour bar.
    let mu = read(&out.join("charts/mu_top.svg"));
    assert!(mu.contains("class=\"tick\">0.30</text>"), "range top tick");
    // The frictional work is positive somewhere on top (the strip slid under the holder).
    let work = read(&out.join("charts/work_top.csv"));
    assert!(work
        .lines()
        .skip(1)
        .any(|l| l.rsplit(',').next().unwrap().parse::<f64>().unwrap() > 0.0));
    let summary: serde_json::Value =
        serde_json::from_str(&read(&out.join("summary.json"))).unwrap();
    assert_eq!(summary["status"], "finished");
    assert_eq!(summary["draw_in"][0]["dx"], 1.5);
    assert!(summary["draw_in"][0]["dd"].is_null());
    let s_max = summary["holder_offset_max"].as_f64().unwrap();
    assert!(s_max > 0.0);
    assert_eq!(
        summary["tools"]["holder"]["offset"].as_f64().unwrap(),
        s_max
    );
    let history = read(&out.join("history.csv"));
    assert!(history.lines().next().unwrap().contains("holder_offset"));
}

#[test]
fn chart_paths_outside_the_output_folder_are_refused() {
    for (file, why) in [
        ("../escape.svg", "'..'"),
        ("/tmp/escape.svg", "absolute"),
        ("charts/x.png", "must end in .svg"),
    ] {
        let (_dir, out, result) = run(
            "refuse",
            &format!(
                "line_chart(\"{file}\", #{{ series: [#{{ name: \"a\", x: [0], y: [1] }}] }});"
            ),
        );
        let err = result.unwrap_err().to_string();
        assert!(err.contains(why), "{file}: {err}");
        assert!(!out.parent().unwrap().join("escape.svg").exists());
        let (_, _, result) = run(
            "refuse-field",
            &format!("sim.chart_field(\"{file}\", \"z+\", \"mu\");"),
        );
        assert!(result.unwrap_err().to_string().contains(why), "{file}");
    }
}

#[test]
fn bad_chart_and_summary_input_is_reported() {
    for (body, message) in [
        (
            "sim.chart_field(\"a.svg\", \"z+\", \"nope\");",
            "no nodal field 'nope'",
        ),
        (
            "sim.chart_field(\"a.svg\", \"z+\", \"mu\", #{ range: [1, 1] });",
            "low < high",
        ),
        (
            "sim.chart_field(\"a.svg\", \"z+\", \"mu\", #{ colour: 1 });",
            "unknown chart_field option 'colour'",
        ),
        (
            "sim.chart_field(\"a.svg\", \"z+\", \"mu\", #{ configuration: \"deformed\" });",
            "\"reference\" or \"current\"",
        ),
        (
            "line_chart(\"a.svg\", #{ series: [#{ name: \"a\", x: [0, 1], y: [1] }] });",
            "2 x values and 1 y values",
        ),
        (
            "line_chart(\"a.svg\", #{ series: [#{ name: \"a\", x: [\"s\"], y: [1] }] });",
            "series[0].x[0] must be a number",
        ),
        (
            "sim.summary(\"increments\", 3);",
            "summary entry 'increments' is written by the engine",
        ),
        ("sim.summary(\"f\", |x| x);", "summary value f is a Fn"),
    ] {
        let (_, _, result) = run("bad", body);
        let err = result.unwrap_err().to_string();
        assert!(err.contains(message), "{body}: {err}");
    }
}
