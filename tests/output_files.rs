//! A scripted run leaves a complete output folder: a VTK frame per increment listed in a
//! .pvd series, history.csv with one row per increment, summary.json; the frames carry the
//! fields a user looks at, with the values the simulation reports.

use std::path::PathBuf;
use tribo::output::read_vtu_point_field;
use tribo::script::{self, HostOptions};

#[test]
fn a_run_writes_frames_history_and_summary() {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/scripts/sliding_block.rhai");
    let out = std::env::temp_dir().join(format!("tribo-output-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let host = HostOptions {
        out_dir: out.clone(),
        ..HostOptions::default()
    };
    script::run_file(&script, &[], &host).unwrap();

    let pvd = std::fs::read_to_string(out.join("frames.pvd")).unwrap();
    // The blank and the floor plane tool at each time.
    for part in ["name=\"blank\"", "name=\"floor\""] {
        assert_eq!(
            pvd.matches(part).count(),
            5,
            "{part}: initial frame + 4 increments:\n{pvd}"
        );
    }
    assert_eq!(pvd.matches("<DataSet").count(), 10, "{pvd}");

    let history = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let lines: Vec<&str> = history.lines().collect();
    assert_eq!(lines.len(), 5, "header + 4 rows");
    assert!(lines[0].starts_with("increment,time,dt,newton_iterations"));
    assert!(lines[0].contains("floor_force_x"));
    let last: Vec<f64> = lines[4].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(last[1], 2.0, "last row at the end time");

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "finished");
    assert_eq!(summary["increments"], 4);
    assert_eq!(summary["symbolic_analyses"], 1);
    let fz = summary["tools"]["floor"]["final_force"][2]
        .as_f64()
        .unwrap();
    assert!((fz + 100.0).abs() < 1e-8);

    let frame = out.join("frames/frame_0004.vtu");
    let status = read_vtu_point_field(&frame, "contact_status").unwrap();
    assert_eq!(
        status.iter().filter(|&&s| s == 2.0).count(),
        16,
        "16 slipping nodes in the last frame"
    );
    let lambda_n = read_vtu_point_field(&frame, "lambda_n").unwrap();
    assert!(
        (lambda_n.iter().sum::<f64>() + 100.0).abs() < 1e-8,
        "nodal lambda_n sums to -N"
    );
    let u = read_vtu_point_field(&frame, "displacement").unwrap();
    assert_eq!(u.len(), 3 * status.len());
    for name in [
        "gap",
        "lambda_t_norm",
        "contact_pressure",
        "frictional_work",
        "mu",
    ] {
        assert_eq!(
            read_vtu_point_field(&frame, name).unwrap().len(),
            status.len(),
            "{name}"
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}
