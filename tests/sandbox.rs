//! The file-access sandbox, tried as a hostile script would: links inside the output folder,
//! `..`, absolute paths, imports and JSON reads outside the allowed folders, a FIFO and
//! /dev/zero as inputs. Each is refused with a clear message, and the file system shows that
//! nothing was written or read outside (the files there are unchanged, no file appeared).

use std::os::unix::fs::symlink;
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A fresh tree: `script/` (the script's folder), `outside/` (holding a marker file) and
/// `script/out` (the output folder).
struct Tree {
    base: PathBuf,
}

impl Tree {
    fn new(tag: &str) -> Tree {
        let base = std::env::temp_dir().join(format!("tribo-sandbox-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir_all(base.join("script/out")).unwrap();
        std::fs::create_dir_all(base.join("outside")).unwrap();
        std::fs::write(base.join("outside/marker.txt"), "untouched").unwrap();
        Tree { base }
    }
    fn script_dir(&self) -> PathBuf {
        self.base.join("script")
    }
    fn out(&self) -> PathBuf {
        self.base.join("script/out")
    }
    fn outside(&self) -> PathBuf {
        self.base.join("outside")
    }

    /// Runs `source` as script/s.rhai with a 60 s limit; (exit code, stdout, stderr).
    fn run(&self, source: &str, extra: &[&str]) -> (i32, String, String) {
        let path = self.script_dir().join("s.rhai");
        std::fs::write(&path, source).unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_tribo"))
            .arg("run")
            .arg(&path)
            .args(["--quiet", "--out"])
            .arg(self.out())
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let start = Instant::now();
        while child.try_wait().unwrap().is_none() {
            if start.elapsed() > Duration::from_secs(60) {
                child.kill().unwrap();
                panic!("script did not stop within 60 s:\n{source}");
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(!stderr.contains("panicked"), "panic: {stderr}");
        (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout).to_string(),
            stderr,
        )
    }

    /// The outside folder holds exactly the marker, unchanged.
    fn assert_outside_untouched(&self) {
        let names: Vec<_> = std::fs::read_dir(self.outside())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        assert_eq!(
            names,
            vec!["marker.txt".to_string()],
            "files appeared outside"
        );
        assert_eq!(
            std::fs::read_to_string(self.outside().join("marker.txt")).unwrap(),
            "untouched"
        );
    }
}

impl Drop for Tree {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.base);
    }
}

/// A small run that writes history.csv and frames.
const RUN: &str = r#"
let mesh = block([0, 0, 0], [1, 1, 1], [2, 2, 2]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
let roller = tool("roller", cylinder([0, 0, 2], [0, 1, 0], 1.0)).path([[0, 0, 0, 0], [1, 0, 0, -1.1]]);
sim.add_tool(roller, "z+");
sim.fix("z-", "xyz");
sim.settings(#{ increments: 2, kinematics: "small" });
sim.run();
"#;

#[test]
fn write_text_refuses_links_dots_and_absolute_paths() {
    let t = Tree::new("write");
    symlink(t.outside(), t.out().join("link")).unwrap();
    symlink(
        t.outside().join("marker.txt"),
        t.out().join("file_link.txt"),
    )
    .unwrap();
    let absolute = t.outside().join("abs.txt");
    let cases = [
        ("link/x.txt".to_string(), "symbolic link 'link'"),
        ("link/deeper/x.txt".to_string(), "symbolic link 'link'"),
        ("file_link.txt".to_string(), "symbolic link 'file_link.txt'"),
        ("../../outside/x.txt".to_string(), "'..'"),
        ("sub/../../outside/x.txt".to_string(), "'..'"),
        (absolute.display().to_string(), "absolute paths are refused"),
    ];
    for (path, why) in &cases {
        let (code, _, err) = t.run(&format!("write_text({path:?}, \"ESCAPED\");"), &[]);
        assert_ne!(code, 0, "{path}: accepted");
        assert!(err.contains(&format!("\"{path}\"")), "{path}: {err}");
        assert!(err.contains(why), "{path}: {err}");
        assert!(err.contains("s.rhai:1:"), "{path}: position named: {err}");
        t.assert_outside_untouched();
    }
    // Positive control: a plain relative path is written below the output folder.
    let (code, _, err) = t.run("write_text(\"notes/a.txt\", \"ok\");", &[]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read_to_string(t.out().join("notes/a.txt")).unwrap(),
        "ok"
    );
}

#[test]
fn run_outputs_refuse_linked_history_and_frames() {
    // history.csv linked to a file outside.
    let t = Tree::new("history");
    symlink(t.outside().join("marker.txt"), t.out().join("history.csv")).unwrap();
    let (code, _, err) = t.run(RUN, &[]);
    assert_ne!(code, 0);
    assert!(
        err.contains("\"history.csv\"") && err.contains("symbolic link"),
        "{err}"
    );
    t.assert_outside_untouched();

    // frames/ linked to a folder outside.
    let t = Tree::new("frames");
    symlink(t.outside(), t.out().join("frames")).unwrap();
    let (code, _, err) = t.run(RUN, &[]);
    assert_ne!(code, 0);
    assert!(err.contains("symbolic link 'frames'"), "{err}");
    t.assert_outside_untouched();

    // checkpoints/ linked to a folder outside.
    let t = Tree::new("checkpoints");
    symlink(t.outside(), t.out().join("checkpoints")).unwrap();
    let (code, _, err) = t.run(
        &format!("{RUN}\nsim.checkpoint(\"checkpoints/c.json\");"),
        &[],
    );
    assert_ne!(code, 0);
    assert!(err.contains("symbolic link 'checkpoints'"), "{err}");
    t.assert_outside_untouched();

    // Positive control: the same run into a clean folder writes its files.
    let t = Tree::new("clean");
    let (code, _, err) = t.run(RUN, &[]);
    assert_eq!(code, 0, "{err}");
    assert!(t.out().join("history.csv").is_file());
    assert!(t.out().join("frames/frame_0001.vtu").is_file());
}

#[test]
fn imports_outside_the_allowed_folders_are_refused() {
    let t = Tree::new("import");
    // A module that would leave a trace if it ran.
    std::fs::write(
        t.outside().join("evil.rhai"),
        "print(\"EVIL MODULE RAN\");\nfn f() { 1 }\n",
    )
    .unwrap();
    let abs = t.outside().join("evil");
    symlink(
        t.outside().join("evil.rhai"),
        t.script_dir().join("linked.rhai"),
    )
    .unwrap();
    for import in [
        "../outside/evil".to_string(),
        abs.display().to_string(),
        "linked".to_string(),
    ] {
        let (code, out, err) = t.run(&format!("import {import:?} as m;\nprint(m::f());"), &[]);
        assert_ne!(code, 0, "{import}: accepted");
        assert!(!out.contains("EVIL MODULE RAN"), "{import}: module ran");
        assert!(
            err.contains("outside the folders scripts may read") && err.contains("--allow-read"),
            "{import}: {err}"
        );
        assert!(err.contains("s.rhai:1:"), "{import}: position named: {err}");
    }
    // The same import is allowed once its folder is named on the command line.
    let outside = t.outside().display().to_string();
    let (code, out, err) = t.run(
        &format!(
            "import {:?} as m;\nprint(m::f());",
            abs.display().to_string()
        ),
        &["--allow-read", &outside],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("EVIL MODULE RAN"));
    // A module next to the script imports fine; an import cycle is refused, not a crash.
    std::fs::write(t.script_dir().join("good.rhai"), "fn g() { 7 }\n").unwrap();
    let (code, out, err) = t.run("import \"good\" as m;\nprint(m::g());", &[]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains('7'));
    std::fs::write(
        t.script_dir().join("cycle.rhai"),
        "import \"cycle\" as c;\n",
    )
    .unwrap();
    let (code, _, err) = t.run("import \"cycle\" as m;", &[]);
    assert_ne!(code, 0);
    assert!(err.contains("import cycle"), "{err}");
}

#[test]
fn json_reads_outside_do_not_reveal_what_exists() {
    let t = Tree::new("json");
    std::fs::write(
        t.outside().join("secret.json"),
        "{\"patches\": \"TOP-SECRET\"}",
    )
    .unwrap();
    let existing = t.outside().join("secret.json").display().to_string();
    let missing = t.outside().join("nothing-here.json").display().to_string();
    let message = |path: &str| {
        let (code, _, err) = t.run(&format!("bezier_surface_json({path:?});"), &[]);
        assert_ne!(code, 0, "{path}: accepted");
        assert!(!err.contains("TOP-SECRET"), "contents echoed: {err}");
        assert!(
            err.contains("outside the folders scripts may read"),
            "{path}: {err}"
        );
        err.replace(path, "PATH")
    };
    // The same message whether or not the outside file exists.
    assert_eq!(message(&existing), message(&missing));
    assert_eq!(message("/etc/passwd"), message("/etc/no-such-file"));
    message("../outside/secret.json");
    // A link in the script's folder pointing outside is refused too, with the same message
    // whether its target exists or not (issue 52: a dangling link said "no such file").
    symlink(
        t.outside().join("secret.json"),
        t.script_dir().join("link.json"),
    )
    .unwrap();
    symlink(
        t.outside().join("nothing-here.json"),
        t.script_dir().join("dangling.json"),
    )
    .unwrap();
    assert_eq!(message("link.json"), message("dangling.json"));
    // A dangling link inside the folder is just a missing file.
    symlink("nothing.json", t.script_dir().join("inner.json")).unwrap();
    let (code, _, err) = t.run("bezier_surface_json(\"inner.json\");", &[]);
    assert_ne!(code, 0);
    assert!(err.contains("\"inner.json\": no such file"), "{err}");
}

#[test]
fn fifo_and_device_inputs_are_refused_without_reading() {
    // `Tree::run` kills the run and fails after 60 s: a blocking read would show as that.
    let t = Tree::new("fifo");
    for name in ["pipe.json", "m.rhai"] {
        let status = Command::new("mkfifo")
            .arg(t.script_dir().join(name))
            .status()
            .unwrap();
        assert!(status.success());
    }
    let (code, _, err) = t.run("bezier_surface_json(\"pipe.json\");", &[]);
    assert_ne!(code, 0);
    assert!(err.contains("\"pipe.json\" is not a regular file"), "{err}");
    let (code, _, err) = t.run("import \"m\" as m;", &[]);
    assert_ne!(code, 0);
    assert!(err.contains("\"m.rhai\" is not a regular file"), "{err}");

    // /dev/zero: outside by default; with /dev allowed, still not a regular file.
    let (code, _, err) = t.run("bezier_surface_json(\"/dev/zero\");", &[]);
    assert_ne!(code, 0);
    assert!(
        err.contains("outside the folders scripts may read"),
        "{err}"
    );
    let (code, _, err) = t.run(
        "bezier_surface_json(\"/dev/zero\");",
        &["--allow-read", "/dev"],
    );
    assert_ne!(code, 0);
    assert!(err.contains("\"/dev/zero\" is not a regular file"), "{err}");
}

#[test]
fn files_over_the_read_cap_are_refused() {
    let t = Tree::new("cap");
    let big = format!("{{\"patches\": [], \"pad\": \"{}\"}}", "x".repeat(2 << 20));
    std::fs::write(t.script_dir().join("big.json"), big).unwrap();
    let (code, _, err) = t.run(
        "bezier_surface_json(\"big.json\");",
        &["--max-read-mb", "1"],
    );
    assert_ne!(code, 0);
    assert!(
        err.contains("over the read limit of 1048576 bytes"),
        "{err}"
    );
    assert!(!err.contains("xxxx"), "contents echoed: {err}");
}
