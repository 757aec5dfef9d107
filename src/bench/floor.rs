//! The factorization floor and the cost growth of the linear solve: times the default
//! solver (`SymmetricLu`, numeric factorization + solve after its symbolic analysis) on a
//! system written by a real run (`TRIBO_DUMP_SYSTEM`, see `solver::linear::system_dump`) against
//! the floor, faer's supernodal Cholesky (AMD) of an SPD matrix with the pattern of
//! `A + A^T`; and fits the growth `t = c n^p` over several sizes.
//!
//! The ratio quoted is the numeric factorization alone against the floor's (also alone);
//! the factorization + solve with the solver's pivot and backward-error checks, as a Newton
//! step pays it, is reported next to it.
//!
//! The floor's matrix has -1 off the diagonal and its row's degree + 1 on it (diagonally
//! dominant, so SPD): its factorization costs what any Cholesky of that structure costs,
//! whatever the values. One thread (`Par::Seq`) throughout.

use crate::solver::linear::symmetric_lu::{NumericSymmetricLu, SymbolicSymmetricLu};
use crate::solver::linear::{LinearSolver, SymmetricLu};
use crate::solver::sparse::{SparseMatrix, SparsePattern};
use crate::{Error, Result};
use std::sync::Arc;
use std::time::Instant;

/// CPU seconds of this process (user + system, Linux `/proc/self/stat`, 1/100 s ticks);
/// 0 elsewhere.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let tick = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (tick(11) + tick(12)) / 100.0
}

/// Peak resident memory of this process in MiB (Linux `VmHWM`), if known.
pub fn peak_memory_mib() -> Option<f64> {
    peak_memory_mib_of("self")
}

/// Peak resident memory of process `pid` ("self" or a number) in MiB, if known.
pub fn peak_memory_mib_of(pid: &str) -> Option<f64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// Mean wall and CPU milliseconds of `f` over at least `repeats` calls and at least one
/// second of calls (CPU time is counted in 10 ms ticks), after one untimed call.
pub fn time_ms(repeats: usize, mut f: impl FnMut() -> Result<()>) -> Result<(f64, f64)> {
    f()?;
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let mut calls = 0;
    while calls < repeats.max(1) || (cpu_seconds() - c0 < 1.0 && calls < 1000) {
        f()?;
        calls += 1;
    }
    let per = |v: f64| v * 1e3 / calls as f64;
    Ok((per(t0.elapsed().as_secs_f64()), per(cpu_seconds() - c0)))
}

/// One system's timings, milliseconds per numeric factorization + solve.
#[derive(Clone, Debug)]
pub struct FloorRow {
    pub n: usize,
    pub nnz: usize,
    /// Entries of the default solver's L + U.
    pub factor_entries: usize,
    /// Numeric factorization + solve (with the solver's checks), as a Newton step pays it.
    pub new_wall_ms: f64,
    pub new_cpu_ms: f64,
    /// Numeric factorization alone: what the floor measures.
    pub factor_cpu_ms: f64,
    /// Entries of the floor's L.
    pub floor_entries: usize,
    pub floor_wall_ms: f64,
    pub floor_cpu_ms: f64,
    /// Calls the default solver handed to its pivoting fallback.
    pub fallbacks: usize,
    /// |b - A x| / (|A| |x| + |b|), infinity norms (without border unknowns).
    pub backward_error: f64,
}

impl FloorRow {
    /// Factorization / floor, CPU.
    pub fn ratio(&self) -> f64 {
        self.factor_cpu_ms / self.floor_cpu_ms
    }
}

/// A matrix `a` and its negation in turn, one per call: every value changes from one call
/// to the next, so a solver that refactorizes only what changed (the default one, for status
/// prediction's re-solves) factorizes the whole matrix on every timed call, as a Newton
/// step's new Jacobian makes it. (Timed on the same values twice, the second call would
/// recompute nothing.) The negation keeps every pivot's magnitude and the pattern.
pub struct Alternating<'a> {
    a: &'a SparseMatrix,
    negated: SparseMatrix,
    flip: bool,
}

impl<'a> Alternating<'a> {
    pub fn new(a: &'a SparseMatrix) -> Self {
        let negated = SparseMatrix {
            pattern: a.pattern.clone(),
            values: a.values.iter().map(|v| -v).collect(),
        };
        Alternating {
            a,
            negated,
            flip: false,
        }
    }

    /// The matrix of the next call: the negation, then `a`, and so on.
    pub fn next_matrix(&mut self) -> &SparseMatrix {
        self.flip = !self.flip;
        if self.flip {
            &self.negated
        } else {
            self.a
        }
    }
}

/// Times the default solver and the floor on one system, `repeats` times each, every
/// call a whole factorization ([`Alternating`]).
pub fn measure(
    a: &SparseMatrix,
    rhs: &[f64],
    border: &[usize],
    repeats: usize,
) -> Result<FloorRow> {
    let mut solver = SymmetricLu::default();
    let mut x = rhs.to_vec();
    let mut matrices = Alternating::new(a);
    let (new_wall_ms, new_cpu_ms) = time_ms(repeats, || {
        x.copy_from_slice(rhs);
        solver.solve_bordered(matrices.next_matrix(), &mut x, border)
    })?;
    // The last timed call may have solved the negated system.
    x.copy_from_slice(rhs);
    solver.solve_bordered(a, &mut x, border)?;
    let backward_error = if border.is_empty() {
        let norm_a = a.row_abs_sums().into_iter().fold(0.0, f64::max);
        let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let r: Vec<f64> = rhs.iter().zip(a.mul_vec(&x)).map(|(b, y)| b - y).collect();
        inf(&r) / (norm_a * inf(&x) + inf(rhs))
    } else {
        f64::NAN
    };
    let symbolic = SymbolicSymmetricLu::new(&a.pattern)?;
    let mut numeric = NumericSymmetricLu::default();
    let mut matrices = Alternating::new(a);
    let (_, factor_cpu_ms) = time_ms(repeats, || {
        numeric
            .factorize(&symbolic, &matrices.next_matrix().values)
            .map_err(|e| Error::LinearSolver(format!("{e:?}")))
    })?;
    let (floor_wall_ms, floor_cpu_ms, floor_entries) = cholesky_floor(&a.pattern, repeats, false)?;
    Ok(FloorRow {
        n: a.pattern.n,
        nnz: a.pattern.nnz(),
        factor_entries: solver.factor_len().unwrap_or(0),
        new_wall_ms,
        new_cpu_ms,
        factor_cpu_ms,
        floor_entries,
        floor_wall_ms,
        floor_cpu_ms,
        fallbacks: solver.fallback_count,
        backward_error,
    })
}

/// Mean wall and CPU milliseconds of faer's numeric LL^T (after its symbolic analysis) of
/// the SPD matrix on the pattern of `A + A^T`, and the entries of L; in faer's AMD order,
/// or (`grouped`) in the default solver's order over elimination groups.
pub fn cholesky_floor(
    p: &SparsePattern,
    repeats: usize,
    grouped: bool,
) -> Result<(f64, f64, usize)> {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::cholesky::llt::factor::LltRegularization;
    use faer::sparse::linalg::cholesky::{
        factorize_symbolic_cholesky, CholeskySymbolicParams, SymmetricOrdering,
    };
    use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
    use faer::{Par, Side};
    let fail = |what: String| Error::LinearSolver(format!("factorization floor: {what}"));
    let n = p.n;
    let lower = SparsePattern::from_entries(
        n,
        (0..n)
            .flat_map(|c| {
                p.row_idx[p.col_ptr[c]..p.col_ptr[c + 1]]
                    .iter()
                    .map(move |&r| (r.max(c), r.min(c)))
            })
            .chain((0..n).map(|i| (i, i))),
    );
    let mut m = SparseMatrix::zeros(Arc::new(lower.clone()));
    let mut degree = vec![0.0; n];
    for c in 0..n {
        for k in lower.col_ptr[c]..lower.col_ptr[c + 1] {
            let r = lower.row_idx[k];
            if r != c {
                m.values[k] = -1.0;
                degree[r] += 1.0;
                degree[c] += 1.0;
            }
        }
    }
    for (c, d) in degree.iter().enumerate() {
        let k = lower
            .position(c, c)
            .expect("the diagonal is in the pattern");
        m.values[k] = d + 1.0;
    }
    let sym = SymbolicSparseColMatRef::new_checked(n, n, &lower.col_ptr, None, &lower.row_idx);
    let order = match (&p.groups, grouped) {
        (Some(groups), true) => Some(crate::solver::linear::symmetric_lu::grouped_order(
            &lower, groups,
        )?),
        _ => None,
    };
    let ordering = match &order {
        Some((fwd, inv)) => {
            SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(fwd, inv, n))
        }
        None => SymmetricOrdering::Amd,
    };
    let symbolic = factorize_symbolic_cholesky(
        sym,
        Side::Lower,
        ordering,
        CholeskySymbolicParams::default(),
    )
    .map_err(|e| fail(format!("{e:?}")))?;
    let mut l_values = vec![0.0; symbolic.len_val()];
    let mut buffer =
        MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
    let (wall, cpu) = time_ms(repeats, || {
        symbolic
            .factorize_numeric_llt(
                &mut l_values,
                SparseColMatRef::new(sym, &m.values),
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut buffer),
                Default::default(),
            )
            .map(|_| ())
            .map_err(|e| fail(format!("{e:?}")))
    })?;
    Ok((wall, cpu, symbolic.len_val()))
}

/// Least-squares fit of `log t = log c + p log n` over the points `(n, t)`; returns `p`
/// (NaN with fewer than two distinct n).
pub fn growth_exponent(points: &[(f64, f64)]) -> f64 {
    let logs: Vec<(f64, f64)> = points.iter().map(|&(n, t)| (n.ln(), t.ln())).collect();
    let k = logs.len() as f64;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x / k, b + y / k));
    let (sxy, sxx) = logs.iter().fold((0.0, 0.0), |(a, b), &(x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    if sxx > 0.0 {
        sxy / sxx
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_exponent_recovers_a_power_law() {
        let points: Vec<(f64, f64)> = [1e3, 4e3, 2e4, 1e5]
            .iter()
            .map(|&n: &f64| (n, 3e-4 * n.powf(1.27)))
            .collect();
        assert!((growth_exponent(&points) - 1.27).abs() < 1e-12);
        assert!(growth_exponent(&points[..1]).is_nan());
    }

    /// Timed calls on [`Alternating`] matrices factorize the whole matrix every time (the
    /// recomputed flops equal a whole factorization's), where the same values twice would
    /// recompute nothing on the second call: what made the timings of the factorization
    /// measure a refactorization that found nothing changed.
    #[test]
    fn alternating_matrices_make_every_factorization_whole() {
        let side = 30;
        let n = side * side;
        let mut entries = Vec::new();
        for i in 0..n {
            entries.push((i, i));
            for d in [1, side] {
                if i + d < n {
                    entries.extend([(i, i + d), (i + d, i)]);
                }
            }
        }
        let p = Arc::new(SparsePattern::from_entries(n, entries));
        let mut a = SparseMatrix::zeros(p.clone());
        for c in 0..n {
            for k in p.col_ptr[c]..p.col_ptr[c + 1] {
                let r = p.row_idx[k];
                a.values[k] = if r == c {
                    6.0
                } else {
                    -1.0 - 0.1 * ((r + 2 * c) % 3) as f64
                };
            }
        }
        let symbolic = SymbolicSymmetricLu::new(&p).unwrap();
        let mut same = NumericSymmetricLu::default();
        same.factorize(&symbolic, &a.values).unwrap();
        same.factorize(&symbolic, &a.values).unwrap();
        assert!(
            same.flops_done < 0.6 * same.flops_total,
            "{}",
            same.flops_done
        );
        let mut numeric = NumericSymmetricLu::default();
        let mut matrices = Alternating::new(&a);
        for _ in 0..4 {
            numeric
                .factorize(&symbolic, &matrices.next_matrix().values)
                .unwrap();
        }
        assert_eq!(numeric.flops_done, numeric.flops_total);
        assert_eq!(
            matrices.next_matrix().values,
            a.values.iter().map(|v| -v).collect::<Vec<_>>()
        );
    }

    /// The floor's matrix is SPD on a 2D Laplacian-like pattern (the factorization
    /// succeeds) and L holds at least the lower triangle.
    #[test]
    fn the_floor_factorizes_a_grid_pattern() {
        let side = 20;
        let n = side * side;
        let mut entries = Vec::new();
        for i in 0..side {
            for j in 0..side {
                let a = i * side + j;
                entries.push((a, a));
                if i + 1 < side {
                    entries.push((a, a + side));
                }
                if j + 1 < side {
                    entries.push((a + 1, a));
                }
            }
        }
        let p = SparsePattern::from_entries(n, entries);
        let (_, _, l) = cholesky_floor(&p, 1, false).unwrap();
        assert!(l >= n + 2 * side * (side - 1), "{l}");
    }
}
