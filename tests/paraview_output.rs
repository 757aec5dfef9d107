//! What ParaView opens: frames.pvd lists, at every time, the blank (points in the current
//! configuration, displacement alongside, named stress components) and the tools (patch and
//! analytic) at their scheduled pose; frames follow the output cadence, and a rollback rewrites the
//! series to the kept frames. Files are read back with an XML parser (quick-xml) and
//! tribo's VTU reader, independently of how they were written.

use std::path::{Path, PathBuf};
use tribo::output::{read_vtu, Frame, SYMMETRIC_TENSOR_COMPONENTS};
use tribo::script::{self, HostOptions};

/// A 4 x 4 x 1 elastic block on a floor plane, under a biquadratic patch punch that moves
/// by (0.3, 0, -0.1) t (linear path over t in [0, 1]) with Coulomb friction 0.1.
/// `settings` and `steps` are Rhai inserted into the script.
fn scene(settings: &str, steps: &str) -> String {
    format!(
        r#"
let mesh = block([0.0, 0.0, 0.0], [4.0, 4.0, 1.0], [4, 4, 1]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
sim.fix("z-", "xyz");
let rows = [];
for i in 0..3 {{
    let row = [];
    for j in 0..3 {{ row.push([-1.0 + 3.0 * i, -1.0 + 3.0 * j, 1.02]); }}
    rows.push(row);
}}
let punch = tool("punch", patch_surface([bezier_patch(rows).flip()], [2.0, 2.0, 0.0]))
    .path([[0.0, 0.0, 0.0, 0.0], [1.0, 0.3, 0.0, -0.1]])
    .friction(coulomb(0.1));
sim.add_tool(punch, "z+");
sim.add_tool(tool("floor", plane([0.0, 0.0, 0.0], [0.0, 0.0, 1.0])), "z-");
sim.settings(#{{ end_time: 1.0, {settings} }});
{steps}
"#
    )
}

/// The punch's translation at time t.
fn punch_translation(t: f64) -> [f64; 3] {
    [0.3 * t, 0.0, -0.1 * t]
}

fn run(name: &str, source: &str) -> PathBuf {
    let base = std::env::temp_dir().join(format!("tribo-paraview-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    std::fs::create_dir_all(&base).unwrap();
    let file = base.join("scene.rhai");
    std::fs::write(&file, source).unwrap();
    let out = base.join("out");
    let host = HostOptions {
        out_dir: out.clone(),
        progress: false,
        ..HostOptions::default()
    };
    script::run_file(&file, &[], &host).unwrap();
    out
}

/// One `<DataSet>` of a .pvd: (timestep, part, name, file).
type Entry = (f64, usize, String, String);

/// The datasets of a .pvd, parsed as XML.
fn pvd_entries(path: &Path) -> Vec<Entry> {
    use quick_xml::events::Event;
    let text = std::fs::read_to_string(path).unwrap();
    let mut reader = quick_xml::Reader::from_str(&text);
    let mut out = Vec::new();
    let mut root_seen = false;
    loop {
        match reader.read_event().expect("well-formed XML") {
            Event::Start(e) | Event::Empty(e) => {
                let tag = String::from_utf8_lossy(e.name().as_ref()).to_string();
                let attr = |key: &str| {
                    e.attributes()
                        .map(|a| a.unwrap())
                        .find(|a| a.key.as_ref() == key.as_bytes())
                        .map(|a| a.unescape_value().unwrap().to_string())
                };
                if tag == "VTKFile" {
                    assert_eq!(attr("type").as_deref(), Some("Collection"));
                    root_seen = true;
                }
                if tag == "DataSet" {
                    out.push((
                        attr("timestep").unwrap().parse().unwrap(),
                        attr("part").unwrap().parse().unwrap(),
                        attr("name").unwrap_or_default(),
                        attr("file").unwrap(),
                    ));
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    assert!(root_seen);
    out
}

/// The distinct times of the series, in order.
fn times(entries: &[Entry]) -> Vec<f64> {
    entries.iter().filter(|e| e.1 == 0).map(|e| e.0).collect()
}

fn field<'a>(frame: &'a Frame, name: &str) -> &'a tribo::output::Field {
    frame
        .point_data
        .iter()
        .chain(&frame.cell_data)
        .find(|f| f.name == name)
        .unwrap_or_else(|| panic!("no field {name}"))
}

#[test]
fn frames_show_the_deformed_blank_and_the_tools_at_their_pose() {
    let out = run("pose", &scene("increments: 4", "sim.run();"));
    let entries = pvd_entries(&out.join("frames.pvd"));
    let t = times(&entries);
    assert_eq!(t, vec![0.0, 0.25, 0.5, 0.75, 1.0], "{entries:?}");
    // Each time: the blank (part 0), the punch (part 1) and the floor plane (part 2).
    for (k, &time) in t.iter().enumerate() {
        let parts: Vec<&Entry> = entries.iter().filter(|e| e.0 == time).collect();
        assert_eq!(parts.len(), 3, "{parts:?}");
        assert_eq!((parts[2].1, parts[2].2.as_str()), (2, "floor"));
        assert_eq!(parts[2].3, format!("frames/frame_{k:04}_floor.vtu"));
        assert_eq!(
            (parts[0].1, parts[0].3.as_str()),
            (0, format!("frames/frame_{k:04}.vtu").as_str())
        );
        assert_eq!((parts[1].1, parts[1].2.as_str()), (1, "punch"));
        assert_eq!(parts[1].3, format!("frames/frame_{k:04}_punch.vtu"));
    }
    let blank0 = read_vtu(&out.join(&entries[0].3)).unwrap();
    let punch0 = read_vtu(&out.join(&entries[1].3)).unwrap();
    // 8 x 8 quadrilaterals sample the biquadratic patch.
    assert_eq!(punch0.quads.len(), 64);
    assert!(punch0.hexes.is_empty());
    let mut moved = 0.0f64;
    for (k, &time) in t.iter().enumerate() {
        let blank = read_vtu(&out.join(format!("frames/frame_{k:04}.vtu"))).unwrap();
        let u = &field(&blank, "displacement").values;
        // Current configuration: points = reference + displacement (round-off of one sum).
        for (i, (p, x)) in blank.points.iter().zip(&blank0.points).enumerate() {
            for c in 0..3 {
                assert!(
                    (p[c] - u[3 * i + c] - x[c]).abs() < 1e-14,
                    "frame {k} node {i}: {p:?} - u != {x:?}"
                );
                moved = moved.max(u[3 * i + c].abs());
            }
        }
        let stress = field(&blank, "stress");
        assert_eq!(stress.components, 6);
        assert_eq!(stress.component_names, SYMMETRIC_TENSOR_COMPONENTS);
        // The punch: every vertex is the first frame's moved by the schedule's translation.
        let punch = read_vtu(&out.join(format!("frames/frame_{k:04}_punch.vtu"))).unwrap();
        let d = punch_translation(time);
        assert_eq!(punch.quads, punch0.quads);
        for (p, p0) in punch.points.iter().zip(&punch0.points) {
            for c in 0..3 {
                assert!((p[c] - p0[c] - d[c]).abs() < 1e-14, "frame {k}: {p:?}");
            }
        }
    }
    assert!(moved > 1e-3, "the blank deforms: largest |u| {moved}");
    // The floor plane (z = 0, not moving): the square of half side the blank box's half
    // diagonal sqrt(4^2 + 4^2 + 1) / 2 about (2, 2, 0), the same in every frame.
    let half = 33f64.sqrt() / 2.0;
    let floor0 = read_vtu(&out.join("frames/frame_0000_floor.vtu")).unwrap();
    assert_eq!(floor0.quads.len(), 1);
    for p in &floor0.points {
        assert_eq!(p[2], 0.0);
        for c in 0..2 {
            assert!(((p[c] - 2.0).abs() - half).abs() < 1e-12, "{p:?}");
        }
    }
    for k in 1..t.len() {
        let floor = read_vtu(&out.join(format!("frames/frame_{k:04}_floor.vtu"))).unwrap();
        assert_eq!(floor.points, floor0.points);
    }
    // At t = 0 the punch is the patch itself: its corner (-1, -1, 1.02).
    assert!(punch0.points.iter().any(|p| p == &[-1.0, -1.0, 1.02]));

    // Contact vectors of the last increment: |tangential_force| = lambda_t_norm, and the
    // slip the sideways punch drags the top face through.
    let last = read_vtu(&out.join("frames/frame_0004.vtu")).unwrap();
    let ft = &field(&last, "tangential_force").values;
    let lt = &field(&last, "lambda_t_norm").values;
    let slip = &field(&last, "slip_increment").values;
    let status = &field(&last, "contact_status").values;
    let mut slipping = 0;
    for i in 0..last.points.len() {
        let norm = (ft[3 * i].powi(2) + ft[3 * i + 1].powi(2) + ft[3 * i + 2].powi(2)).sqrt();
        assert!((norm - lt[i]).abs() <= 1e-9 * (1.0 + lt[i]), "node {i}");
        if status[i] == 2.0 {
            slipping += 1;
            assert!(slip[3 * i].abs() > 0.0, "a slipping node slips: node {i}");
        }
        if status[i] == 0.0 {
            assert_eq!(&slip[3 * i..3 * i + 3], &[0.0; 3], "no slip out of contact");
        }
    }
    assert!(slipping > 0, "the punch drags the top face: {status:?}");

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["frames"], 5);
    assert_eq!(summary["frame_points"], "current");
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
}

#[test]
fn reference_points_on_request() {
    let out = run(
        "reference",
        &scene("increments: 2, frame_points: \"reference\"", "sim.run();"),
    );
    let first = read_vtu(&out.join("frames/frame_0000.vtu")).unwrap();
    let last = read_vtu(&out.join("frames/frame_0002.vtu")).unwrap();
    assert_eq!(first.points, last.points);
    assert!(field(&last, "displacement")
        .values
        .iter()
        .any(|u| u.abs() > 1e-3));
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
}

#[test]
fn frames_follow_the_interval_not_the_increments() {
    // Default: end_time / 20. 30 increments of 1/30 cross each multiple of 0.05 once.
    let out = run("default", &scene("increments: 30", "sim.run();"));
    let t = times(&pvd_entries(&out.join("frames.pvd")));
    assert_eq!(t.len(), 21, "{t:?}");
    assert!(
        (t[20] - 1.0).abs() < 1e-12,
        "the end time is the last frame: {t:?}"
    );
    // One frame per interval [0.05 k, 0.05 (k + 1)): the first increment past each multiple.
    let slot = |t: f64| (t / 0.05 + 1e-9).floor() as i64;
    for (k, &time) in t.iter().enumerate() {
        assert_eq!(slot(time), k as i64, "{t:?}");
    }
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert_eq!(
        history.lines().count(),
        1 + 30,
        "history keeps every increment"
    );
    let _ = std::fs::remove_dir_all(out.parent().unwrap());

    let out = run(
        "interval",
        &scene("increments: 8, output_interval: 0.5", "sim.run();"),
    );
    assert_eq!(
        times(&pvd_entries(&out.join("frames.pvd"))),
        vec![0.0, 0.5, 1.0]
    );
    assert!(!out.join("frames/frame_0003.vtu").exists());
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
}

#[test]
fn rollback_rewrites_the_series_to_the_kept_frames() {
    let steps = "sim.step(); sim.step(); sim.step(); sim.rollback(2); sim.step();";
    let out = run("rollback", &scene("increments: 4, output_every: 1", steps));
    let entries = pvd_entries(&out.join("frames.pvd"));
    // Frames at 0, 0.25, 0.5, 0.75; back to 0.25; one step to 0.5 again.
    assert_eq!(times(&entries), vec![0.0, 0.25, 0.5]);
    assert_eq!(entries.len(), 9, "blank, punch and floor at each kept time");
    for e in &entries {
        assert!(out.join(&e.3).is_file(), "{e:?}");
    }
    assert!(!out.join("frames/frame_0003.vtu").exists());
    assert!(!out.join("frames/frame_0003_punch.vtu").exists());
    // The frame rewritten at 0.5 shows the punch there.
    let punch0 = read_vtu(&out.join("frames/frame_0000_punch.vtu")).unwrap();
    let punch2 = read_vtu(&out.join("frames/frame_0002_punch.vtu")).unwrap();
    let d = punch_translation(0.5);
    assert!((punch2.points[0][0] - punch0.points[0][0] - d[0]).abs() < 1e-14);
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
}

/// history.csv names each dimensional column's unit and carries the model fraction;
/// summary.json has both. Numbers stay exact (shortest round-trip text).
#[test]
fn history_names_units_and_the_model_fraction() {
    let settings = r#"increments: 2, model_fraction: 0.25,
        units: #{ length: "mm", force: "N", time: "mm" }"#;
    let out = run("units", &scene(settings, "sim.run();"));
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let mut lines = history.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for name in [
        "increment",
        "time [mm]",
        "dt [mm]",
        "newton_iterations",
        "max_slip_increment [mm]",
        "max_rotation_increment [rad]",
        "punch_force_z [N]",
        "floor_frictional_dissipation [N mm]",
        "tool_work [N mm]",
        "energy_balance_error",
        "model_fraction",
    ] {
        assert!(header.contains(&name), "{name} in {header:?}");
    }
    let fraction = header.iter().position(|h| *h == "model_fraction").unwrap();
    let time = header.iter().position(|h| *h == "time [mm]").unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    assert!(rows.iter().all(|r| r[fraction] == 0.25));
    assert_eq!(rows[1][time], 1.0);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["model_fraction"], 0.25);
    assert_eq!(summary["units"]["force"], "N");
    let _ = std::fs::remove_dir_all(out.parent().unwrap());

    // Without units the names are bare; a bad fraction or unit is refused by name.
    let out = run("no-units", &scene("increments: 1", "sim.run();"));
    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(history.lines().next().unwrap().contains(",punch_force_z,"));
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
    for (bad, what) in [
        ("model_fraction: 4.0", "model_fraction"),
        ("units: #{ force: \"N,m\" }", "units.force"),
        ("units: #{ mass: \"kg\" }", "unknown unit 'mass'"),
    ] {
        let dir = std::env::temp_dir().join(format!("tribo-paraview-bad-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("bad.rhai");
        std::fs::write(&file, scene(&format!("increments: 1, {bad}"), "")).unwrap();
        let host = HostOptions {
            out_dir: dir.join("out"),
            ..HostOptions::default()
        };
        let err = script::run_file(&file, &[], &host).unwrap_err().to_string();
        assert!(err.contains(what) && err.contains("bad.rhai:"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// A field map restricted to a tool shows values only where that tool touched the face
/// set (the rest grey, NaN in its CSV), and `range: "law"` spans the law's coefficients.
#[test]
fn field_maps_split_by_tool_on_the_law_range() {
    let charts = r#"sim.run();
        sim.settings(#{ units: #{ length: "mm" } });
        sim.chart_field("mu_punch.svg", "z+", "mu", #{ tool: "punch", range: "law" });
        sim.chart_field("mu_floor.svg", "z+", "mu", #{ tool: "floor" });"#;
    let out = run("maps", &scene("increments: 2", charts));
    let values = |name: &str| -> Vec<f64> {
        let csv = std::fs::read_to_string(out.join(name)).unwrap();
        csv.lines()
            .skip(1)
            .map(|l| l.rsplit(',').next().unwrap().parse().unwrap())
            .collect()
    };
    let punch = values("mu_punch.csv");
    assert_eq!(punch.len(), 25, "the 5 x 5 nodes of the top face");
    let touched = punch.iter().filter(|v| v.is_finite()).count();
    assert!(touched > 0, "{punch:?}");
    assert!(punch.iter().filter(|v| v.is_finite()).all(|&v| v == 0.1));
    // The floor never touches the top face: every value is missing.
    assert!(values("mu_floor.csv").iter().all(|v| v.is_nan()));
    // Coulomb 0.1: the law's range is 0.1 +- 10 %, ticked at both ends; axes in mm.
    let svg = std::fs::read_to_string(out.join("mu_punch.svg")).unwrap();
    let ticks: Vec<f64> = svg
        .split("class=\"tick\">")
        .skip(1)
        .map(|t| t[..t.find('<').unwrap()].parse().unwrap())
        .collect();
    assert!((ticks[0] - 0.09).abs() < 1e-12, "{ticks:?}");
    assert!((ticks[ticks.len() - 1] - 0.11).abs() < 1e-12, "{ticks:?}");
    assert!(svg.contains(">x [mm]</text>") && svg.contains(">y [mm]</text>"));
    let _ = std::fs::remove_dir_all(out.parent().unwrap());
}

/// The square cup's frames.pvd (scripts/square_cup.rhai, 4 x 4 cells, 2 mm of travel), read
/// back as XML: at every time the blank and the punch, blankholder and die, each tool placed
/// at the schedule's pose: the punch moved down by the travel (the pseudo-time), the holder
/// up by its opening 0.5 mm / 30 mm of travel, the die still.
#[test]
fn the_cups_frames_hold_every_tool_at_its_scheduled_pose() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::env::temp_dir().join(format!("tribo-paraview-cup-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_tribo"))
        .current_dir(root)
        .args(["run", "scripts/square_cup.rhai", "--quiet", "--out"])
        .arg(&out)
        .args([
            "--set",
            "cells=4",
            "--set",
            "travel=2.0",
            "--set",
            "charts=false",
            "--set",
            "element=\"hexahedron\"",
        ])
        .status()
        .expect("tribo runs");
    assert!(status.success());
    let entries = pvd_entries(&out.join("frames.pvd"));
    let t = times(&entries);
    assert!(
        t.len() >= 3 && t[0] == 0.0 && (t[t.len() - 1] - 2.0).abs() < 1e-12,
        "{t:?}"
    );
    let names = ["blank", "punch", "blankholder", "die"];
    let shift = |name: &str, time: f64| match name {
        "punch" => -time,
        "blankholder" => 0.5 / 30.0 * time,
        _ => 0.0,
    };
    for (k, &time) in t.iter().enumerate() {
        let parts: Vec<&Entry> = entries.iter().filter(|e| e.0 == time).collect();
        let got: Vec<&str> = parts.iter().map(|e| e.2.as_str()).collect();
        assert_eq!(got, names, "time {time}");
        for (part, e) in parts.iter().enumerate().skip(1) {
            assert_eq!(e.1, part);
            let first = entries.iter().find(|f| f.0 == 0.0 && f.1 == part).unwrap();
            let (now, then) = (
                read_vtu(&out.join(&e.3)).unwrap(),
                read_vtu(&out.join(&first.3)).unwrap(),
            );
            assert!(!now.quads.is_empty() && now.quads == then.quads, "{e:?}");
            let dz = shift(&e.2, time);
            for (p, p0) in now.points.iter().zip(&then.points) {
                assert_eq!([p[0], p[1]], [p0[0], p0[1]], "frame {k} {}", e.2);
                assert!(
                    (p[2] - p0[2] - dz).abs() < 1e-12,
                    "frame {k} {}: {p:?}",
                    e.2
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}
