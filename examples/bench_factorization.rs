//! Times the linear solve of a Newton step on a system written by a real run, old (faer's
//! pivoting LU) against new (LU without pivoting on the symmetric structure), and the
//! factorization floor: faer's supernodal Cholesky (AMD) of an SPD matrix with the pattern
//! of A + A^T.
//!
//! ```text
//! TRIBO_DUMP_SYSTEM=/tmp/cup.sys tribo run scripts/square_cup.rhai --quiet \
//!     --set cells=25 --set travel=2 --set charts=false --out /tmp/cup
//! cargo run --release --example bench_factorization -- /tmp/cup.sys [REPEATS]
//! ```
//! One thread; each figure is the mean of REPEATS (default 5) numeric factorizations and
//! solves after the symbolic analysis, wall and process CPU seconds.
use std::sync::Arc;
use std::time::Instant;
use tribo::bench::floor;
use tribo::solver::linear::system_dump;
use tribo::solver::linear::{FaerLu, LinearSolver, SymmetricLu};
use tribo::solver::sparse::SparsePattern;

/// Mean wall and CPU milliseconds of `f` over `repeats` calls, after one untimed call.
fn time(repeats: usize, mut f: impl FnMut()) -> (f64, f64) {
    floor::time_ms(repeats, || {
        f();
        Ok(())
    })
    .expect("infallible")
}

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .expect("usage: bench_factorization SYSTEM_FILE [REPEATS]");
    let repeats: usize = args.next().map_or(5, |s| s.parse().expect("REPEATS"));
    let (mut a, rhs, border) = system_dump::read(path.as_ref()).unwrap();
    if std::env::var_os("BENCH_NO_GROUPS").is_some() {
        let mut p = (*a.pattern).clone();
        p.groups = None;
        a.pattern = Arc::new(p);
    }
    let only_new = std::env::var_os("BENCH_ONLY_NEW").is_some();
    let n = a.pattern.n;
    println!(
        "system: n = {n}, nnz(A) = {}, border unknowns {:?}, elimination groups: {}",
        a.pattern.nnz(),
        border,
        a.pattern.groups.is_some()
    );
    let solve = |solver: &mut dyn LinearSolver| {
        let mut x = rhs.clone();
        solver.solve_bordered(&a, &mut x, &border).unwrap();
        x
    };
    let mut lu = FaerLu::default();
    let t0 = Instant::now();
    let x_lu = solve(&mut lu);
    let first_lu = t0.elapsed().as_secs_f64() * 1e3;
    let (lu_wall, lu_cpu) = time(if only_new { 0 } else { repeats }, || {
        solve(&mut lu);
    });
    let mut sym = SymmetricLu::default();
    let t0 = Instant::now();
    let x_sym = solve(&mut sym);
    let first_sym = t0.elapsed().as_secs_f64() * 1e3;
    // The negation and the matrix in turn: each call factorizes the whole matrix (on the
    // same values twice the solver would recompute nothing, floor::Alternating).
    let mut matrices = floor::Alternating::new(&a);
    let (sym_wall, sym_cpu) = time(repeats, || {
        let mut x = rhs.clone();
        sym.solve_bordered(matrices.next_matrix(), &mut x, &border)
            .unwrap();
    });
    let scale = x_lu.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = x_lu
        .iter()
        .zip(&x_sym)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    println!(
        "faer LU (partial pivoting, COLAMD): first call {first_lu:.1} ms, then {lu_wall:.1} ms wall / {lu_cpu:.1} ms CPU per factorization + solve"
    );
    println!(
        "symmetric LU (no pivoting, AMD on A + A^T): first call {first_sym:.1} ms, then {sym_wall:.1} ms wall / {sym_cpu:.1} ms CPU; L+U {} entries; fallbacks {}",
        sym.factor_len().map_or("?".into(), |l| l.to_string()),
        sym.fallback_count
    );
    // Backward errors |b - A x| / (|A| |x| + |b|) (infinity norms); without a border.
    let norm_a = a.row_abs_sums().into_iter().fold(0.0, f64::max);
    let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let backward = |x: &[f64]| {
        let r: Vec<f64> = rhs.iter().zip(a.mul_vec(x)).map(|(b, y)| b - y).collect();
        inf(&r) / (norm_a * inf(x) + inf(&rhs))
    };
    println!(
        "solutions differ by {:.1e} of the largest entry; backward errors: LU {:.1e}, symmetric LU {:.1e}; speed-up {:.2}x wall, {:.2}x CPU",
        diff / scale,
        backward(&x_lu),
        backward(&x_sym),
        lu_wall / sym_wall,
        lu_cpu / sym_cpu
    );
    if only_new {
        return;
    }
    let (floor_wall, floor_cpu, l_len) = cholesky_floor(&a.pattern, repeats, false);
    println!(
        "floor, faer Cholesky (AMD, supernodal) of an SPD matrix on A + A^T: {floor_wall:.1} ms wall / {floor_cpu:.1} ms CPU, L {l_len} entries; new / floor {:.2} wall, {:.2} CPU; old / floor {:.2} wall, {:.2} CPU",
        sym_wall / floor_wall,
        sym_cpu / floor_cpu,
        lu_wall / floor_wall,
        lu_cpu / floor_cpu
    );
    if a.pattern.groups.is_some() {
        let (w, c, l) = cholesky_floor(&a.pattern, repeats, true);
        println!(
            "the same Cholesky in the symmetric LU's grouped order: {w:.1} ms wall / {c:.1} ms CPU, L {l} entries; new / this {:.2} CPU",
            sym_cpu / c
        );
    }
}

fn cholesky_floor(p: &SparsePattern, repeats: usize, grouped: bool) -> (f64, f64, usize) {
    floor::cholesky_floor(p, repeats, grouped).unwrap()
}
