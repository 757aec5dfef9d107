//! A `tribo repl` in a pseudo-terminal, driven by util-linux `script`, so that the REPL
//! sees a terminal: typed bytes are keystrokes (TAB completes, 0x03 is the terminal's
//! Ctrl-C), and the output is what a person would see.

use std::io::{Read, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// A cylinder dragged over a 16 x 1 x 2 block of `cells` x 1 x `cells / 8` hexahedra in
/// `increments` fixed increments up to the end time 3, writing a frame every `output_every`
/// (0: no files), then `tail` (how the scene is stepped). Line 11 is the first of `tail`.
pub fn drag_scene(cells: usize, increments: usize, output_every: usize, tail: &str) -> String {
    format!(
        r#"
let mesh = block([0, 0, 0], [16, 1, 2], [{cells}, 1, {depth}]);
let sim = simulation(mesh, linear_elastic(1000.0, 0.3));
let roller = tool("roller", cylinder([4.0, 0, 7.02], [0, 1, 0], 5.0))
    .path([[0, 0, 0, 0], [1, 0, 0, -0.12], [3, 8.0, 0, -0.12]]).friction(coulomb(0.2));
sim.add_tool(roller, "z+");
sim.fix("z-", "xyz");
sim.fix("y-", "y");
sim.fix("y+", "y");
sim.settings(#{{ end_time: 3.0, increments: {increments}, output_every: {output_every} }});
{tail}
"#,
        depth = cells / 8
    )
}

pub struct Session {
    pub child: Child,
    input: ChildStdin,
    pub output: Arc<Mutex<String>>,
}

impl Session {
    /// Starts `tribo repl SCRIPT --out OUT` with the terminal type `term` ("dumb": plain
    /// line reading; "xterm": rustyline's editor with completion).
    pub fn start(bin: &str, script: &Path, out: &Path, term: &str) -> Session {
        let command = format!("{bin} repl {} --out {}", script.display(), out.display());
        let mut child = Command::new("script")
            .args(["-q", "-e", "-c", &command, "/dev/null"])
            .env("TERM", term)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("util-linux `script` runs the REPL in a pseudo-terminal");
        let input = child.stdin.take().unwrap();
        let mut stdout = child.stdout.take().unwrap();
        let output = Arc::new(Mutex::new(String::new()));
        let sink = output.clone();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = stdout.read(&mut buf) {
                if n == 0 {
                    break;
                }
                sink.lock()
                    .unwrap()
                    .push_str(&String::from_utf8_lossy(&buf[..n]));
            }
        });
        Session {
            child,
            input,
            output,
        }
    }

    pub fn send(&mut self, bytes: &[u8]) {
        self.input.write_all(bytes).unwrap();
        self.input.flush().unwrap();
    }

    /// Waits until the output after byte `from` contains `text`; returns the end of the match.
    pub fn expect(&self, from: usize, text: &str) -> usize {
        let start = Instant::now();
        loop {
            {
                let out = self.output.lock().unwrap();
                if let Some(i) = out[from.min(out.len())..].find(text) {
                    return from + i + text.len();
                }
                assert!(
                    start.elapsed() < Duration::from_secs(300),
                    "no {text:?} in the REPL's output:\n{}",
                    &out[from.min(out.len())..]
                );
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// The output from byte `from` to `to`.
    pub fn text(&self, from: usize, to: usize) -> String {
        self.output.lock().unwrap()[from..to].to_string()
    }

    /// Sends `:quit` and waits for the REPL to end.
    pub fn quit(&mut self) {
        self.send(b":quit\r");
        let start = Instant::now();
        while self.child.try_wait().unwrap().is_none() {
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "the REPL did not quit"
            );
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
