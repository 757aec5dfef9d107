//! The script functions tool_from_iges / tool_from_step / tool_from_nurbs_json through the
//! command line: options, the read policy, and refusals naming the file and line.

mod common;
use common::run_script;

fn data_dir() -> String {
    format!("{}/tests/data/cad", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn scripts_read_cad_tools_with_options() {
    let dir = data_dir();
    let plate = r#"{ "faces": [ { "degree": [1, 1], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
        "points": [[[0,0,0],[0,1,0]], [[1,0,0],[1,1,0]]] } ] }"#;
    let source = format!(
        r#"
        let punch = tool_from_iges("{dir}/punch_nurbs.igs", #{{ faces: [0, 1], flip: true, translate: [0.0, 0.0, 0.81] }});
        let r = punch.seam_report();
        if r.patches < 2 {{ throw `patches ${{r.patches}}`; }}
        let die = tool_from_step("{dir}/die_nurbs.step").seam_report();
        // Faces meet without gaps; the sharpest kink is the block's square outer edge.
        if die.worst_gap > 1e-9 || (die.worst_kink_deg - 90.0).abs() > 1e-6 {{ throw `die seams ${{die}}`; }}
        // The die's faces facing up within 10 degrees: its top, one plane patch.
        let top = tool_from_step("{dir}/die_analytic.step", #{{ facing: [0, 0, 1], facing_angle: 10 }}).seam_report();
        if top.patches != 1 {{ throw `top ${{top}}`; }}
        let one = tool_from_nurbs_json("plate.json", #{{ flip: false }}).seam_report();
        if one.patches != 1 {{ throw "plate"; }}
        "#
    );
    // The JSON table beside the script (its folder is readable).
    let dir_of = common::TestDir::new(&format!("tribo-cad-{}-ok", std::process::id()));
    std::fs::create_dir_all(&*dir_of).unwrap();
    std::fs::write(dir_of.join("plate.json"), plate).unwrap();
    let path = dir_of.join("ok.rhai");
    std::fs::write(&path, source).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tribo"))
        .args(["run"])
        .arg(&path)
        .args(["--quiet", "--allow-read", &dir, "--out"])
        .arg(dir_of.join("out"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
}

#[test]
fn scripts_get_the_file_line_and_entity_of_a_refusal() {
    let dir = data_dir();
    let allow = ["--allow-read", dir.as_str()];
    let cases = [
        (
            format!("tool_from_iges(\"{dir}/punch_nurbs.igs\", #{{ flop: true }});"),
            "tool_from_iges option 'flop' is unknown".to_string(),
        ),
        (
            format!("tool_from_step(\"{dir}/die_nurbs.step\", #{{ faces: [999] }});"),
            "face index = 999 must be < the file's face count".to_string(),
        ),
        (
            format!("tool_from_step(\"{dir}/punch_nurbs.igs\");"),
            "punch_nurbs.igs:1: no DATA section".to_string(),
        ),
        (
            "tool_from_iges(\"/etc/passwd\");".to_string(),
            "IGES file \"/etc/passwd\"".to_string(),
        ),
    ];
    for (k, (source, expected)) in cases.iter().enumerate() {
        let (code, stderr) = run_script("cad", &format!("bad{k}"), source, &allow);
        assert_ne!(code, 0, "{source}");
        assert!(stderr.contains(expected.as_str()), "{source}: {stderr}");
    }
}
