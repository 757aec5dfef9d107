//! Issue 18: README.md works as written. Its command lines run (the heavy ones made small
//! with `--set`, see `runnable`), its usage lines name only options the CLI has, the tour
//! script runs and its `--set mu` is used, the REPL transcript is what the REPL prints, the
//! sweep table it shows is the committed one, and the files it cites exist.
//!
//! Each README command runs from the repository's root with `--out` redirected to a
//! temporary folder (so that the test writes nothing into the working tree).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_tribo");

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

/// The fenced blocks of README.md with the info string `lang`, each with the heading of
/// the section it is in.
fn blocks(lang: &str) -> Vec<(String, String)> {
    let text = readme();
    let (mut out, mut heading, mut current): (Vec<(String, String)>, String, Option<String>) =
        (Vec::new(), String::new(), None);
    for line in text.lines() {
        match current.as_mut() {
            Some(body) if line.starts_with("```") => {
                out.push((heading.clone(), std::mem::take(body)));
                current = None;
            }
            Some(body) => {
                body.push_str(line);
                body.push('\n');
            }
            None if line == format!("```{lang}") => current = Some(String::new()),
            None if line.starts_with("## ") => heading = line[3..].to_string(),
            None => {}
        }
    }
    out
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tribo-readme-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn tribo(args: &[String], stdin: Option<&str>) -> std::process::Output {
    let mut child = Command::new(BIN)
        .args(args)
        .current_dir(root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    {
        use std::io::Write;
        let mut input = child.stdin.take().unwrap();
        input.write_all(stdin.unwrap_or("").as_bytes()).unwrap();
    }
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "tribo {}: {}\n{}",
        args.join(" "),
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Splits a command line into words (double quotes group, as the README's lines need).
fn words(line: &str) -> Vec<String> {
    let (mut out, mut word, mut quoted) = (Vec::new(), String::new(), false);
    for c in line.chars() {
        match c {
            '"' => {
                quoted = !quoted;
                word.push(c);
            }
            ' ' if !quoted => {
                if !word.is_empty() {
                    out.push(std::mem::take(&mut word));
                }
            }
            c => word.push(c),
        }
    }
    if !word.is_empty() {
        out.push(word);
    }
    out
}

/// A README command line as the test runs it: `--out` to `out` (added for `run`), and the
/// square cup made small: 4 x 4 cells and 1 mm of travel instead of 25 x 25 (or 50 x 50)
/// and 30 mm. The variant, the layers and every other `--set` stay, so each line's names
/// and values are still checked by the script. An error says why a line is not run here.
fn runnable(line: &str, out: &Path) -> Result<Vec<String>, &'static str> {
    let line = line.trim();
    if line == "cargo test --release" {
        return Err("the test command: this suite");
    }
    if line.contains("--example mutation_campaign") {
        return Err("3 000 mutants, some 260 s: tests/mutated_scripts.rs runs a 200-mutant sample of the same campaign");
    }
    let args = line
        .strip_prefix("cargo run --release -- ")
        .or_else(|| line.strip_prefix("tribo "))
        .unwrap_or_else(|| panic!("README command line not covered by tests/readme.rs: {line}"));
    let mut args = words(args);
    if args[0] == "study" {
        return Err("1009 s of studies: the names are checked against the CLI's list instead");
    }
    let out_at = args.iter().position(|a| a == "--out");
    match (out_at, args[0].as_str()) {
        (Some(i), _) => args[i + 1] = out.display().to_string(),
        (None, "run") => args.extend(["--out".into(), out.display().to_string()]),
        _ => {}
    }
    if args[0] == "sweep" && args[1] == "collect" {
        args[2] = out.display().to_string();
    }
    if args[0] == "run" {
        args.push("--quiet".into());
    }
    if args.get(1).is_some_and(|s| s.ends_with("square_cup.rhai")) {
        args.retain(|a| !a.starts_with("cells=") && !a.starts_with("travel="));
        while let Some(i) = args
            .windows(2)
            .position(|w| w[0] == "--set" && w[1] == "--set")
        {
            args.remove(i);
        }
        if args.last().is_some_and(|a| a == "--set") {
            args.pop();
        }
        args.extend(["--set", "cells=4", "--set", "travel=1"].map(String::from));
    }
    Ok(args)
}

#[test]
fn command_lines_run_as_written() {
    let dir = temp_dir("commands");
    let mut ran = 0;
    let mut sweep_out: Option<PathBuf> = None;
    for (b, (section, body)) in blocks("sh").into_iter().enumerate() {
        if section == "Commands" {
            continue; // usage lines, checked by `usage_lines_name_options_the_cli_has`
        }
        for (k, line) in body.lines().enumerate() {
            // A folder per line (block b, line k): a used folder is refused (issue 52), as the
            // README says; two blocks of one section used to share their folders.
            let out = if line.contains("sweep collect") {
                sweep_out.clone().expect("a sweep before its collect")
            } else {
                dir.join(format!("{}_{b}_{k}", section.replace(' ', "_")))
            };
            let Ok(args) = runnable(line, &out) else {
                continue;
            };
            tribo(&args, None);
            ran += 1;
            match args[0].as_str() {
                "run" => {
                    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
                    assert!(summary.contains("\"status\": \"finished\""), "{line}");
                }
                "sweep" if args[1] == "collect" => {
                    let table = std::fs::read_to_string(out.join("collected.csv")).unwrap();
                    assert_eq!(table.lines().count(), 13, "{line}");
                    let ys: Vec<&String> = args
                        .windows(2)
                        .filter(|w| w[0] == "--y")
                        .map(|w| &w[1])
                        .collect();
                    for y in ys {
                        let name = format!("chart_{}_vs_mu.svg", y.replace('.', "_"));
                        assert!(out.join(&name).is_file(), "{line}: no {name}");
                    }
                }
                "sweep" => sweep_out = Some(out.clone()),
                _ => {}
            }
        }
    }
    assert!(ran >= 6, "only {ran} README command lines ran");
    // The one test command, exactly as CI's .ci/run calls it.
    assert!(readme().contains("```sh\ncargo test --release\n```"));
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    assert_eq!(ci.lines().last(), Some("cargo test --release"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn usage_lines_name_options_the_cli_has() {
    let (_, usage) = blocks("sh")
        .into_iter()
        .find(|(section, _)| section == "Commands")
        .expect("a Commands section");
    let mut checked = 0;
    for line in usage.lines() {
        let (command, options) = match line.strip_prefix("# LIMITS:") {
            Some(limits) => ("run".to_string(), limits.to_string()),
            None => {
                let code = line.split(" #").next().unwrap();
                let w = words(code);
                assert_eq!(w[0], "tribo", "{line}");
                let sub = if w[1] == "sweep" && w[2] == "collect" {
                    "sweep collect".to_string()
                } else {
                    w[1].clone()
                };
                (sub, code.to_string())
            }
        };
        let mut args: Vec<String> = command.split(' ').map(String::from).collect();
        args.push("--help".into());
        let help = String::from_utf8(tribo(&args, None).stdout).unwrap();
        for option in options
            .split(|c: char| c.is_whitespace() || "[],|".contains(c))
            .filter(|w| w.starts_with("--"))
        {
            assert!(
                help.contains(&format!("{option} ")) || help.contains(&format!("{option}\n")),
                "README's `{line}`: `tribo {command} --help` has no {option}"
            );
            checked += 1;
        }
        // The study names of the usage comment are the CLI's.
        if let Some(names) = line.split("# NAME: ").nth(1) {
            let out = Command::new(BIN)
                .args(["study", "no-such-study", "--out"])
                .arg(std::env::temp_dir())
                .output()
                .unwrap();
            let known = String::from_utf8_lossy(&out.stderr).to_string();
            for name in names.split(", ") {
                assert!(known.contains(name.trim()), "study {name} unknown: {known}");
            }
        }
    }
    assert!(checked >= 20, "only {checked} options checked");
}

/// The tour's lines `|Fx/Fz| = X`.
fn ratio(stdout: &[u8]) -> f64 {
    let text = String::from_utf8_lossy(stdout);
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("|Fx/Fz| = "))
        .unwrap_or_else(|| panic!("the tour printed no ratio:\n{text}"));
    line.trim().parse().unwrap()
}

#[test]
fn tour_script_runs_and_its_mu_is_the_friction_coefficient() {
    let (_, tour) = blocks("rhai")
        .into_iter()
        .find(|(section, _)| section == "A short tour of a script")
        .expect("the tour");
    let dir = temp_dir("tour");
    let script = dir.join("tour.rhai");
    std::fs::write(&script, &tour).unwrap();
    // Sliding under the whole contact zone, the tool's force ratio is mu up to the tilt of
    // the contact normals under the cylinder: within 2 % (measured 0.8 %).
    for (set, mu) in [(None, 0.2), (Some("mu=0.3"), 0.3)] {
        let mut args = vec![
            "run".to_string(),
            script.display().to_string(),
            "--quiet".into(),
        ];
        args.extend([
            "--out".into(),
            dir.join(format!("out{mu}")).display().to_string(),
        ]);
        if let Some(s) = set {
            args.extend(["--set".into(), s.into()]);
        }
        let r = ratio(&tribo(&args, None).stdout);
        assert!((r / mu - 1.0).abs() < 0.02, "mu = {mu}: |Fx/Fz| = {r}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Numbers in REPL output compare to 1e-4 relative: the REPL shows 6 significant digits,
/// and a round-off change can move the last one. Numbers below 1e-9 are residuals at the
/// round-off level (Newton's tolerance is 1e-9 relative), which any change of summation
/// order changes: any two such numbers match. Integers (increments, iterations, counts)
/// and all text must be equal.
fn same_output_line(expected: &str, actual: &str) -> bool {
    fn tokens(s: &str) -> Vec<String> {
        let mut out: Vec<String> = Vec::new();
        let mut current = String::new();
        let mut numeric = false;
        for c in s.chars() {
            let is_num = c.is_ascii_digit()
                || (c == '.' && numeric)
                || (c == 'e' && numeric)
                || (c == '-' && (!numeric || current.ends_with('e')));
            if is_num != numeric && !current.is_empty() {
                out.push(std::mem::take(&mut current));
            }
            numeric = is_num;
            current.push(c);
        }
        out.push(current);
        out
    }
    let (a, b) = (tokens(expected), tokens(actual));
    a.len() == b.len()
        && a.iter()
            .zip(&b)
            .all(|(x, y)| match (x.parse::<f64>(), y.parse::<f64>()) {
                (Ok(u), Ok(v)) if x.contains(['.', 'e']) || y.contains(['.', 'e']) => {
                    (u.abs() < 1e-9 && v.abs() < 1e-9)
                        || (u - v).abs() <= 1e-4 * u.abs().max(v.abs())
                }
                _ => x == y,
            })
}

#[test]
fn repl_transcript_is_what_the_repl_prints() {
    let (_, transcript) = blocks("text")
        .into_iter()
        .find(|(_, body)| body.starts_with("$ tribo repl "))
        .expect("a REPL transcript");
    let mut lines = transcript.lines();
    let command = lines.next().unwrap().strip_prefix("$ tribo ").unwrap();
    let (mut input, mut expected) = (String::new(), Vec::new());
    for line in lines {
        match line
            .strip_prefix("tribo> ")
            .or_else(|| line.strip_prefix("  ...> "))
        {
            Some(typed) => {
                input.push_str(typed);
                input.push('\n');
            }
            None => expected.push(line),
        }
    }
    let dir = temp_dir("repl");
    let mut args = words(command);
    args.extend(["--out".into(), dir.display().to_string()]);
    // Standard input is not a terminal: the REPL reads the lines without echo or prompts,
    // so its standard output is exactly the transcript's non-input lines.
    let out = tribo(&args, Some(&input));
    let stdout = String::from_utf8(out.stdout).unwrap();
    let actual: Vec<&str> = stdout.lines().collect();
    let same = actual.len() == expected.len()
        && expected
            .iter()
            .zip(&actual)
            .all(|(e, a)| same_output_line(e, a));
    assert!(
        same,
        "README's REPL transcript differs from what the REPL prints; it prints:\n{}",
        stdout
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn number_comparison_of_transcripts() {
    assert!(same_output_line(
        "t = 0.1 (dt 0.1), [-0.0225488, 1.74793]",
        "t = 0.1 (dt 0.1), [-0.0225489, 1.74793]"
    ));
    assert!(same_output_line(
        "residuals 1.5268e-15 (force)",
        "residuals 3.1e-16 (force)"
    ));
    assert!(!same_output_line(
        "residuals 1.5e-5 (force)",
        "residuals 3.1e-16 (force)"
    ));
    assert!(!same_output_line("2 iterations", "3 iterations"));
    assert!(!same_output_line(
        "[-0.0225488, 1.74793]",
        "[-0.0225488, 1.75793]"
    ));
    assert!(!same_output_line("increment 1: x", "increment 1: y"));
}

#[test]
fn shown_sweep_table_is_the_committed_one_and_cited_files_exist() {
    let text = readme();
    let (_, shown) = blocks("text")
        .into_iter()
        .find(|(_, body)| body.starts_with("mu,r,"))
        .expect("the sweep table");
    let committed = std::fs::read_to_string(root().join("scripts/cylinder_drag_mu_r.csv")).unwrap();
    for (shown, file) in shown.lines().filter(|l| *l != "...").zip(committed.lines()) {
        assert_eq!(shown, file);
    }
    // Files and folders the README names exist.
    let mut cited = 0;
    for word in text.split(|c: char| c.is_whitespace() || "`()[],:;".contains(c)) {
        let word = word.trim_end_matches('.');
        let looks_like_file = ["tests/", "docs/", "scripts/", "std-lib/", "src/"]
            .iter()
            .any(|p| word.starts_with(p))
            && !word.contains('*')
            && !word.contains("NAME");
        if looks_like_file {
            assert!(
                root().join(word).exists(),
                "README cites {word}, which does not exist"
            );
            cited += 1;
        }
    }
    assert!(cited >= 30, "only {cited} files cited");
    assert!(
        !text.contains("DESIGN.md"),
        "README points to a page outside the repository"
    );
    for dir in ["docs", "std-lib"] {
        for entry in std::fs::read_dir(root().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if let Ok(body) = std::fs::read_to_string(&path) {
                assert!(
                    !body.contains("shared/reference"),
                    "{} cites shared/reference",
                    path.display()
                );
            }
        }
    }
}
