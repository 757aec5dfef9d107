//! 1 000 randomly mutated versions of the demo script: each either runs or stops with an
//! error, and none panics (errors are expected and fine).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use tribo::script::{self, HostOptions};

struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

const TOKENS: &[&str] = &[
    "0",
    "-1",
    "1e300",
    "-0.0",
    "\"\"",
    "[]",
    "#{}",
    "(",
    ")",
    ",",
    ";",
    "true",
    "1/0",
    "[0, 0]",
    "[1, 2, 3, 4]",
    "999999999",
    "-5",
    "0.5",
    "sim",
    "\"x-\"",
    "\"w\"",
    "[[1, 0, 0, 0], [0, 0, 0, 0]]",
];

#[test]
fn mutated_scripts_never_panic() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(root.join("scripts/cylinder_drag.rhai"))
        .unwrap()
        .replace("let cells = 32;", "let cells = 8;")
        .replace("let increments = 30;", "let increments = 3;");
    let dir = std::env::temp_dir().join(format!("tribo-mutated-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("mutant.rhai");
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    let (mut ran, mut refused, mut panicked) = (0, 0, Vec::new());
    for case in 0..1000 {
        let mut text: Vec<char> = source.chars().collect();
        for _ in 0..1 + rng.below(3) {
            let at = rng.below(text.len());
            match rng.below(3) {
                0 => {
                    let end = (at + 1 + rng.below(4)).min(text.len());
                    text.splice(at..end, TOKENS[rng.below(TOKENS.len())].chars());
                }
                1 => {
                    let end = (at + 1 + rng.below(3)).min(text.len());
                    text.drain(at..end);
                }
                _ => {
                    text.splice(at..at, TOKENS[rng.below(TOKENS.len())].chars());
                }
            }
        }
        std::fs::write(&path, text.iter().collect::<String>()).unwrap();
        let host = HostOptions {
            out_dir: dir.join("out"),
            max_operations: 2_000_000,
            ..HostOptions::default()
        };
        match catch_unwind(AssertUnwindSafe(|| script::run_file(&path, &[], &host))) {
            Ok(Ok(())) => ran += 1,
            Ok(Err(_)) => refused += 1,
            Err(_) => panicked.push(case),
        }
    }
    println!(
        "1000 mutants: {ran} ran, {refused} stopped with an error, {} panicked",
        panicked.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
    assert!(panicked.is_empty(), "mutants that panicked: {panicked:?}");
    assert!(
        ran > 0 && refused > 0,
        "the mutations exercise both outcomes"
    );
}
