//! The mutation campaign over all shipped scripts: every script's number literals set to 0,
//! -1, 1e308, NaN, inf and 2.5, its strings emptied and its arrays emptied, one site per
//! mutant, each run as `tribo run` (release binary) with a time limit. Counts runs, refusals,
//! panics, hangs, signals, errors that name neither place nor value, and escapes (files that
//! appeared in the scripts' own folders).
//!
//! `cargo build --release && cargo run --release --example mutation_campaign -- --mutants 3000`

#[path = "mutate.rs"]
mod mutate;

use mutate::*;
use std::path::PathBuf;
use std::time::Duration;

fn listing(dirs: &[PathBuf]) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = dirs
        .iter()
        .flat_map(|d| std::fs::read_dir(d).unwrap().flatten().map(|e| e.path()))
        .collect();
    v.sort();
    v
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str, default: u64| -> u64 {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .and_then(|v| v.parse().ok())
            .unwrap_or(default)
    };
    let wanted = arg("--mutants", 3000) as usize;
    let seed = arg("--seed", 0x9E37_79B9_7F4A_7C15);
    let jobs = arg("--jobs", 2) as usize;
    let limit = Duration::from_secs(arg("--timeout", 60));
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let bin = root.join("target/release/tribo");
    assert!(
        bin.is_file(),
        "build the release binary first: cargo build --release"
    );

    let scripts = shipped_scripts(&root);
    let mut pool: Vec<(PathBuf, String, String)> = Vec::new();
    for s in &scripts {
        let src = std::fs::read_to_string(s).unwrap();
        for (what, text) in mutants(&src) {
            pool.push((s.clone(), what, text));
        }
    }
    // A seeded choice of `wanted` mutants (all of them when there are fewer).
    let mut rng = XorShift(seed);
    for i in (1..pool.len()).rev() {
        pool.swap(i, rng.below(i + 1));
    }
    pool.truncate(wanted);
    println!(
        "{} scripts, {} mutants chosen, {jobs} jobs, {} s limit each",
        scripts.len(),
        pool.len(),
        limit.as_secs()
    );
    let dirs: Vec<PathBuf> = ["scripts", "tests/scripts", "tests/robust"]
        .iter()
        .map(|d| root.join(d))
        .collect();
    let before = listing(&dirs);

    let work_base = std::env::temp_dir().join(format!("tribo-campaign-{}", std::process::id()));
    let started = std::time::Instant::now();
    let t = run_all(&bin, pool, jobs, limit, &work_base, Some(250));
    let escapes: Vec<PathBuf> = listing(&dirs)
        .into_iter()
        .filter(|p| !before.contains(p))
        .collect();
    for (what, list) in [
        ("panic", &t.panics),
        ("hang", &t.hangs),
        ("signal", &t.signals),
        ("error naming neither place nor value", &t.unlocated),
    ] {
        for item in list.iter().take(20) {
            println!("{what}: {item}");
        }
    }
    println!(
        "tries {}, ran {}, refused {} ({} without place or value), panics {}, hangs {}, signals {}, escapes {} ({:.0} s)",
        t.tries,
        t.ran,
        t.refused,
        t.unlocated.len(),
        t.panics.len(),
        t.hangs.len(),
        t.signals.len(),
        escapes.len(),
        started.elapsed().as_secs_f64()
    );
    if !(t.panics.is_empty() && t.hangs.is_empty() && t.signals.is_empty() && escapes.is_empty()) {
        std::process::exit(1);
    }
}
