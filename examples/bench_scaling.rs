//! Cost growth of the linear solve with the mesh, and the factorization floor at every
//! size: for each square-cup mesh `CELLSxLAYERS` it takes the condensed Newton system of a
//! real run (the cup script run briefly with `TRIBO_DUMP_SYSTEM`, stopped after a few
//! solves once contact is established, or a dump already there), times the default
//! solver's numeric factorization + solve against faer's Cholesky of an SPD matrix with the
//! same pattern (`tribo::bench::floor`), and fits `t = c n^p` over the sizes.
//!
//! ```text
//! cargo build --release
//! cargo run --release --example bench_scaling -- 25x1 50x2 100x2 200x2
//!     [--solves K (default 6)] [--repeats R (default 3)] [--dumps DIR (default /tmp)]
//!     [--tribo PATH (default target/release/tribo)] [--fresh]
//! ```
//!
//! A dump `DIR/tribo_scaling_CELLSxLAYERS.sys` is reused unless `--fresh`. The run that
//! writes it moves the punch by 0.5 mm (one increment) and is stopped after its K-th
//! linear solve; its peak memory is reported. One thread for the timings.
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant, SystemTime};
use tribo::bench::floor;
use tribo::solver::linear::system_dump;

struct Options {
    sizes: Vec<(usize, usize)>,
    solves: usize,
    repeats: usize,
    dumps: PathBuf,
    tribo: PathBuf,
    fresh: bool,
}

fn options() -> Result<Options, String> {
    let mut o = Options {
        sizes: Vec::new(),
        solves: 6,
        repeats: 3,
        dumps: PathBuf::from("/tmp"),
        tribo: PathBuf::from("target/release/tribo"),
        fresh: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--solves" => {
                o.solves = value("--solves")?
                    .parse()
                    .map_err(|e| format!("--solves: {e}"))?
            }
            "--repeats" => {
                o.repeats = value("--repeats")?
                    .parse()
                    .map_err(|e| format!("--repeats: {e}"))?
            }
            "--dumps" => o.dumps = value("--dumps")?.into(),
            "--tribo" => o.tribo = value("--tribo")?.into(),
            "--fresh" => o.fresh = true,
            size => {
                let parsed = size
                    .split_once('x')
                    .and_then(|(c, l)| Some((c.parse().ok()?, l.parse().ok()?)))
                    .filter(|&(c, l): &(usize, usize)| c > 0 && l > 0);
                o.sizes
                    .push(parsed.ok_or(format!("size '{size}' is not CELLSxLAYERS (e.g. 50x2)"))?);
            }
        }
    }
    if o.sizes.is_empty() {
        return Err("give at least one size CELLSxLAYERS, e.g. 25x1 50x2 100x2".into());
    }
    Ok(o)
}

/// Runs the cup briefly, writing its systems to `dump`; stops it after `solves` of them.
/// Returns the run's peak memory (MiB) and wall seconds.
fn make_dump(o: &Options, cells: usize, layers: usize, dump: &Path) -> Result<(f64, f64), String> {
    let _ = std::fs::remove_file(dump);
    let out = o.dumps.join(format!("tribo_scaling_{cells}x{layers}_out"));
    let t0 = Instant::now();
    let mut child = Command::new(&o.tribo)
        .args(["run", "scripts/square_cup.rhai", "--quiet", "--set"])
        .arg(format!("cells={cells}"))
        .arg("--set")
        .arg(format!("layers={layers}"))
        .args(["--set", "travel=0.5", "--set", "charts=false"])
        .args(["--set", "element=\"hexahedron\"", "--out"])
        .arg(&out)
        .env(system_dump::DUMP_VARIABLE, dump)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| format!("{}: {e}", o.tribo.display()))?;
    let pid = child.id().to_string();
    let (mut seen, mut last, mut peak) = (0, None::<SystemTime>, 0.0f64);
    loop {
        if let Some(m) = floor::peak_memory_mib_of(&pid) {
            peak = peak.max(m);
        }
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            if seen == 0 {
                return Err(format!("the run ended ({status}) before writing a system"));
            }
            break;
        }
        let modified = std::fs::metadata(dump).and_then(|m| m.modified()).ok();
        if modified.is_some() && modified != last {
            last = modified;
            seen += 1;
            if seen >= o.solves {
                let _ = child.kill();
                let _ = child.wait();
                break;
            }
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    Ok((peak, t0.elapsed().as_secs_f64()))
}

fn main() {
    let o = options().unwrap_or_else(|e| {
        eprintln!("bench_scaling: {e}");
        std::process::exit(2)
    });
    println!(
        "{:>9} {:>7} {:>8} {:>9} {:>8} {:>9} {:>8} {:>8} {:>9} {:>8} {:>7} {:>7}",
        "mesh",
        "n",
        "nnz(A)",
        "L+U",
        "fact ms",
        "+solve ms",
        "floor L",
        "floor ms",
        "fact/floor",
        "backward",
        "run MiB",
        "bench MiB"
    );
    let mut points = Vec::new();
    let mut ratios = Vec::new();
    for &(cells, layers) in &o.sizes {
        let dump = o.dumps.join(format!("tribo_scaling_{cells}x{layers}.sys"));
        let run_peak = if o.fresh || !dump.exists() {
            match make_dump(&o, cells, layers, &dump) {
                Ok((peak, _)) => format!("{peak:.0}"),
                Err(e) => {
                    eprintln!("{cells}x{layers}: {e}");
                    continue;
                }
            }
        } else {
            "reused".into()
        };
        let row = system_dump::read(&dump)
            .and_then(|(a, rhs, border)| floor::measure(&a, &rhs, &border, o.repeats));
        let row = match row {
            Ok(row) => row,
            Err(e) => {
                eprintln!("{cells}x{layers}: {e}");
                continue;
            }
        };
        println!(
            "{:>9} {:>7} {:>8} {:>9} {:>8.1} {:>9.1} {:>8} {:>8.1} {:>9.2} {:>8.1e} {:>7} {:>7.0}",
            format!("{cells}x{cells}x{layers}"),
            row.n,
            row.nnz,
            row.factor_entries,
            row.factor_cpu_ms,
            row.new_cpu_ms,
            row.floor_entries,
            row.floor_cpu_ms,
            row.ratio(),
            row.backward_error,
            run_peak,
            floor::peak_memory_mib().unwrap_or(f64::NAN),
        );
        if row.fallbacks > 0 {
            println!("  ({} pivoting fallbacks)", row.fallbacks);
        }
        points.push((row.n as f64, row.new_cpu_ms, row.floor_cpu_ms));
        ratios.push(row.ratio());
    }
    let fit = |pick: fn(&(f64, f64, f64)) -> f64| {
        floor::growth_exponent(&points.iter().map(|p| (p.0, pick(p))).collect::<Vec<_>>())
    };
    for pair in points.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let local = |ta: f64, tb: f64| (tb / ta).ln() / (b.0 / a.0).ln();
        println!(
            "n {:.0} -> {:.0}: factorization + solve p = {:.2}, floor p = {:.2}",
            a.0,
            b.0,
            local(a.1, b.1),
            local(a.2, b.2)
        );
    }
    println!(
        "CPU milliseconds (one thread, mean of at least {} calls and 1 s after one untimed call); fact/floor {:?}; fitted growth t ~ n^p over all sizes: factorization + solve p = {:.2}, floor p = {:.2}",
        o.repeats,
        ratios.iter().map(|r| (r * 100.0).round() / 100.0).collect::<Vec<_>>(),
        fit(|p| p.1),
        fit(|p| p.2)
    );
}
