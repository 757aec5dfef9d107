//! Shared set-up for the integration tests.
#![allow(dead_code)]

pub mod exact_surfaces;
pub mod pty;

/// A test's output folder in the system's temporary folder: emptied when made, removed when
/// the test passes (the guard dropped without a panic), kept for inspection when it fails.
pub struct TestDir(std::path::PathBuf);

impl TestDir {
    /// `name` under the system's temporary folder.
    pub fn new(name: &str) -> TestDir {
        let path = std::env::temp_dir().join(name);
        let _ = std::fs::remove_dir_all(&path);
        TestDir(path)
    }
}

impl std::ops::Deref for TestDir {
    type Target = std::path::Path;
    fn deref(&self) -> &std::path::Path {
        &self.0
    }
}

impl AsRef<std::path::Path> for TestDir {
    fn as_ref(&self) -> &std::path::Path {
        &self.0
    }
}

impl Drop for TestDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

use std::sync::Arc;
use tribo::contact::FrictionLaw;
use tribo::geometry::{RigidSurface, Vec3};
use tribo::material::{LinearElastic, Material};
use tribo::tool::schedule::Schedule;
use tribo::tool::Tool;

pub fn elastic(young: f64, poisson: f64) -> Arc<dyn Material> {
    Arc::new(LinearElastic::new(young, poisson).unwrap())
}

pub fn tool(
    name: &str,
    surface: impl RigidSurface + 'static,
    path: &[(f64, [f64; 3])],
    mu: f64,
) -> Tool {
    let mut t = Tool::new(name, Arc::new(surface));
    t.schedule = Schedule::new(
        path.iter()
            .map(|(t, d)| (*t, Vec3::new(d[0], d[1], d[2])))
            .collect(),
    )
    .unwrap();
    t.friction = FrictionLaw::coulomb(mu).unwrap();
    t
}

/// Observed orders p_k = log(r_{k+1}/r_k) / log(r_k/r_{k-1}) over consecutive residuals,
/// keeping only triples above `floor` (below it round-off dominates).
pub fn convergence_orders(residuals: &[f64], floor: f64) -> Vec<f64> {
    let r: Vec<f64> = residuals.iter().copied().filter(|&x| x > floor).collect();
    r.windows(3)
        .filter(|w| w[0] != w[1])
        .map(|w| (w[2] / w[1]).ln() / (w[1] / w[0]).ln())
        .collect()
}

/// A rigid cylinder (radius 5, axis along y) over an elastic block `length` x 1 x `depth`
/// (E = 1000, nu = 0.3, plane strain, glued to the ground) with `cells` cells along x and
/// `cells * depth / length` through the depth; the cylinder starts 0.02 above the block at
/// x = length / 4, presses 0.1 into it over t in [0, 1] and is dragged by `drag` in x over
/// t in [1, 3], with Coulomb friction 0.2.
pub fn cylinder_drag_model(
    length: f64,
    depth: f64,
    cells: usize,
    drag: f64,
) -> tribo::solver::Model {
    use tribo::geometry::Cylinder;
    use tribo::tool::ScalarSchedule;
    let radius = 5.0;
    let size = Vec3::new(length, 1.0, depth);
    let mesh = tribo::mesh::Mesh::block(
        Vec3::zeros(),
        size,
        [cells, 1, (cells as f64 * depth / length) as usize],
    )
    .unwrap();
    let mut model = tribo::solver::Model::new(mesh, elastic(1000.0, 0.3)).unwrap();
    let axis = Vec3::new(length / 4.0, 0.0, depth + radius + 0.02);
    let cyl = Cylinder::new(axis, Vec3::y(), radius).unwrap();
    let path = [
        (0.0, [0.0; 3]),
        (1.0, [0.0, 0.0, -0.12]),
        (3.0, [drag, 0.0, -0.12]),
    ];
    model
        .add_tool(tool("roller", cyl, &path, 0.2), "z+", None)
        .unwrap();
    model
        .prescribe("z-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    model
        .prescribe("y-", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model
        .prescribe("y+", "y", ScalarSchedule::constant(0.0))
        .unwrap();
    model.settings.end_time = 3.0;
    model
}

/// Per column j of the Jacobian at (`t`, `x`): the largest difference, over the rows without
/// a prescribed displacement, between the assembled column and the central difference of
/// the assembled residual with step `h`.
pub fn jacobian_column_errors(
    sim: &tribo::solver::Simulation,
    t: f64,
    x: &[f64],
    h: f64,
) -> Vec<f64> {
    let n = x.len();
    let mut fixed = vec![false; n];
    for bc in &sim.model.dirichlet {
        for &node in &bc.nodes {
            fixed[3 * node + bc.component] = true;
        }
    }
    let e = sim.evaluate_at(t, x).unwrap();
    (0..n)
        .map(|j| {
            let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
            xp[j] += h;
            xm[j] -= h;
            let rp = sim.evaluate_at(t, &xp).unwrap().residual;
            let rm = sim.evaluate_at(t, &xm).unwrap().residual;
            let mut ej = vec![0.0; n];
            ej[j] = 1.0;
            let col = e.jacobian.mul_vec(&ej);
            (0..n)
                .filter(|&i| !fixed[i])
                .map(|i| ((rp[i] - rm[i]) / (2.0 * h) - col[i]).abs())
                .fold(0.0, f64::max)
        })
        .collect()
}

/// The Newton step J dx = -R solved on the full mixed system (faer's pivoting LU) and
/// through the simulation's condensation (the default solver, LU without pivoting on the
/// symmetric structure, which must not have needed its pivoting fallback), and the largest
/// entry and largest difference.
pub fn full_and_condensed_steps(
    sim: &tribo::solver::Simulation,
    e: &tribo::solver::assembly::Evaluation,
) -> (Vec<f64>, Vec<f64>, f64, f64) {
    use tribo::solver::linear::{FaerLu, LinearSolver, SymmetricLu};
    let mut full: Vec<f64> = e.residual.iter().map(|v| -v).collect();
    FaerLu::default().solve(&e.jacobian, &mut full).unwrap();
    let mut solver = SymmetricLu::default();
    let condensed = sim.newton_step(e, &mut solver).unwrap();
    assert_eq!(solver.fallback_count, 0, "no pivot refused");
    let scale = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = full
        .iter()
        .zip(&condensed)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    (full, condensed, scale, diff)
}

/// The first Newton iterate at time `t` from the committed state (one full mixed solve).
pub fn first_newton_iterate(sim: &tribo::solver::Simulation, t: f64) -> Vec<f64> {
    use tribo::solver::linear::{FaerLu, LinearSolver};
    let mut x = sim.unknowns().to_vec();
    let e0 = sim.evaluate_at(t, &x).unwrap();
    let mut dx: Vec<f64> = e0.residual.iter().map(|v| -v).collect();
    FaerLu::default().solve(&e0.jacobian, &mut dx).unwrap();
    for (a, b) in x.iter_mut().zip(&dx) {
        *a += b;
    }
    x
}

/// Scales tool `c`'s default augmentation parameters (the membrane stiffness E h, before the
/// simulation takes its default fraction of it) to the first default, the column stiffness
/// M A / h, on a mesh whose contact faces all have area `area` and element height `height`
/// (Poisson ratio `nu`), and keeps them as given. Tests that read Newton's convergence order
/// were written with it: with the smaller defaults Newton reaches round-off in too few
/// iterations to measure an order (at a tenth of E h, the default, the cylinder drag's last
/// residual is 3e-15 after three iterations and a three-point estimate reads 1.5-1.8); the
/// Jacobian under test is the same.
pub fn former_default_r(
    model: &mut tribo::solver::Model,
    c: usize,
    nu: f64,
    area: f64,
    height: f64,
) {
    let p_wave_over_young = (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    for r in &mut model.contacts[c].r {
        *r *= p_wave_over_young * area / (height * height);
    }
    model.contacts[c].r_default = false;
}

/// Runs `source` as the script `name.rhai` through the `tribo run` command line (output in a
/// fresh folder under the system temp, `tag` keeping test files apart, removed when the test
/// passes), with `extra` arguments; returns the exit code and stderr, and fails on a panic.
pub fn run_script(tag: &str, name: &str, source: &str, extra: &[&str]) -> (i32, String) {
    let (code, stderr, _dir) = run_script_in(tag, name, source, extra);
    (code, stderr)
}

/// [`run_script`], also returning its folder (the script and the run's `out`), for a test
/// that looks into it.
pub fn run_script_in(
    tag: &str,
    name: &str,
    source: &str,
    extra: &[&str],
) -> (i32, String, TestDir) {
    let dir = TestDir::new(&format!("tribo-{tag}-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&*dir).unwrap();
    let path = dir.join(format!("{name}.rhai"));
    std::fs::write(&path, source).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_tribo"))
        .arg("run")
        .arg(&path)
        .args(["--quiet", "--out"])
        .arg(dir.join("out"))
        .args(extra)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!stderr.contains("panicked"), "{name}: panic: {stderr}");
    (out.status.code().unwrap_or(-1), stderr, dir)
}

/// The `*.rhai` files of `tests/<folder>`, sorted by name.
pub fn rhai_scripts(folder: &str) -> Vec<std::path::PathBuf> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(folder);
    let mut scripts: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rhai"))
        .collect();
    scripts.sort();
    scripts
}

/// Tip deflection over length of the inextensible elastica under a dead end load, for the
/// load parameter `alpha = P L² / EI`: with the slope `θ(s)` over the arc length `s / L`,
/// `θ'' = -alpha cos θ`, `θ(0) = 0` (clamp), `θ'(1) = 0` (free end), deflection
/// `∫ sin θ ds`. Shooting on `θ'(0)` (bisection; `θ'(1)` grows with it) with RK4 on 4000
/// steps: error ~1e-14, far below what is compared here.
pub fn elastica(alpha: f64) -> f64 {
    let rhs = |y: [f64; 3]| [y[1], -alpha * y[0].cos(), y[0].sin()];
    let shoot = |curvature: f64| {
        let n = 4000;
        let h = 1.0 / n as f64;
        let add = |a: [f64; 3], b: [f64; 3], s: f64| std::array::from_fn(|i| a[i] + s * b[i]);
        let mut y = [0.0, curvature, 0.0];
        for _ in 0..n {
            let k1 = rhs(y);
            let k2 = rhs(add(y, k1, h / 2.0));
            let k3 = rhs(add(y, k2, h / 2.0));
            let k4 = rhs(add(y, k3, h));
            y = std::array::from_fn(|i| {
                y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            });
        }
        y
    };
    // θ'(0) = M(0)/EI lies in [0, alpha] (the lever arm is at most L).
    let (mut lo, mut hi) = (0.0, alpha);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if shoot(mid)[1] > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    shoot(0.5 * (lo + hi))[2]
}

/// Runs `scripts/<script>` with `extra` inserted right after `marker` (an entry of the
/// script's settings map), under `--quiet --set charts=false` and the `sets` overrides,
/// into `out` (emptied first), and returns its summary.json. The edited copy is written
/// next to `out` and removed after the run.
pub fn run_edited_script(
    script: &str,
    marker: &str,
    extra: &str,
    sets: &[String],
    out: &std::path::Path,
) -> serde_json::Value {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(root.join("scripts").join(script)).unwrap();
    assert!(source.contains(marker), "{script} has {marker}");
    let _ = std::fs::remove_dir_all(out);
    let folder = out.with_extension("script");
    std::fs::create_dir_all(&folder).unwrap();
    let copy = folder.join(script);
    std::fs::write(&copy, source.replace(marker, &format!("{marker}{extra}"))).unwrap();
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_tribo"));
    command
        .arg("run")
        .arg(&copy)
        .args(["--quiet", "--set", "charts=false", "--out"])
        .arg(out);
    // The cup script's default element is the solid-shell for one layer (docs/solid-shell.md,
    // "Default"); the tests written against F-bar hexahedra keep testing those.
    if script == "square_cup.rhai" && !sets.iter().any(|s| s.starts_with("element=")) {
        command.args(["--set", "element=\"hexahedron\""]);
    }
    for s in sets {
        command.args(["--set", s]);
    }
    let status = command.status().expect("tribo runs");
    assert!(status.success(), "{script} ({extra}, {sets:?}) failed");
    let _ = std::fs::remove_dir_all(&folder);
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}
