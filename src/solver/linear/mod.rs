//! The one interface through which the Newton solver solves its linear systems.
//!
//! The mixed (u, lambda) Jacobian is unsymmetric and indefinite (a stick node has a zero
//! lambda-lambda block). Two factorizations sit behind [`LinearSolver`]:
//!
//! - [`SymmetricLu`], the default: LU without pivoting on the symmetric structure of
//!   `A + A^T` (AMD order on the pattern's elimination groups, so that a node's multipliers
//!   come after its displacements; see `symmetric_lu`). Pivots and backward errors are
//!   checked; a failure solves that call with [`FaerLu`]. On the square cup's condensed,
//!   displacement-only system it is 3-3.7x faster than [`FaerLu`] and 2-2.5x the
//!   Cholesky floor of the same pattern (BENCHMARKS.md).
//! - [`FaerLu`]: faer's sparse LU with partial pivoting, columns ordered by COLAMD on
//!   `A^T A`; robust for any regular matrix, but its row pivoting fills far more.
//!
//! Both compute their symbolic analysis once per pattern; each Newton iteration pays only
//! the numeric factorization. A few dense border unknowns (a force-controlled tool's
//! offset) are eliminated by a Schur complement around either ([`BorderedSystem`]).

pub mod condense;
pub mod subtree_split;
pub mod symmetric_lu;
pub mod system_dump;

pub use symmetric_lu::{SymmetricLu, BACKWARD_ERROR_TOLERANCE};

use crate::solver::settings::LinearSolverKind;
use crate::solver::sparse::{SparseMatrix, SparsePattern};
use crate::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Par};
use std::sync::Arc;

/// Solves A x = b for a sparse square A.
pub trait LinearSolver {
    /// Factorizes `a` (reusing any analysis of an identical pattern) and solves for `b` in place.
    fn solve(&mut self, a: &SparseMatrix, b: &mut [f64]) -> Result<()> {
        self.solve_bordered(a, b, &[])
    }

    /// Like [`Self::solve`], with the unknowns `border` (a few dense rows and columns, such
    /// as a force-controlled tool's offset) eliminated by a Schur complement instead of
    /// entering the sparse factorization.
    fn solve_bordered(&mut self, a: &SparseMatrix, b: &mut [f64], border: &[usize]) -> Result<()>;

    /// Number of symbolic analyses done (one per sparsity pattern, not per call).
    fn symbolic_analyses(&self) -> usize;

    /// Whether a factorization without pivoting that refuses a system may hand it to a
    /// pivoting one (on by default). Off, such a call fails instead: for a system that is
    /// only tried, such as a status prediction's re-solve.
    fn set_pivoting_fallback(&mut self, _allowed: bool) {}

    /// Threads the factorization may use (1 by default). The solution does not depend on
    /// it where the solver honours it ([`SymmetricLu`]: bit for bit the same factors).
    fn set_threads(&mut self, _threads: usize) {}

    /// Factorizations that ran on several threads ([`Self::set_threads`]).
    fn split_factorizations(&self) -> usize {
        0
    }
}

/// A factorization that solves several right-hand sides at once: what the bordered solve
/// needs from the sparse solver inside it.
trait Factorization: Default {
    /// Factorizes `a` and solves for the `nrhs` right-hand sides stored column after column
    /// in `rhs`.
    fn factor_and_solve(&mut self, a: &SparseMatrix, rhs: &mut [f64], nrhs: usize) -> Result<()>;

    fn symbolic_count(&self) -> usize;
}

/// Checks the sizes and values of a system before it is factorized.
fn check_system(a: &SparseMatrix, rhs: &[f64], nrhs: usize) -> Result<()> {
    let n = a.pattern.n;
    if rhs.len() != n * nrhs {
        return Err(Error::LinearSolver(format!(
            "right-hand side has {} entries, matrix has {n} rows",
            rhs.len()
        )));
    }
    if let Some(bad) = a.values.iter().position(|v| !v.is_finite()) {
        return Err(Error::LinearSolver(format!(
            "matrix entry {bad} is not finite ({})",
            a.values[bad]
        )));
    }
    Ok(())
}

/// The bordered solve with the system kept in `slot` (rebuilt when the pattern or the
/// border changes); returns the number of new symbolic analyses.
fn solve_bordered_in<F: Factorization>(
    slot: &mut Option<Box<BorderedSystem<F>>>,
    a: &SparseMatrix,
    b: &mut [f64],
    border: &[usize],
    configure: impl FnOnce(&mut F),
) -> Result<usize> {
    if b.len() != a.pattern.n {
        return Err(Error::LinearSolver(format!(
            "right-hand side has {} entries, matrix has {} rows",
            b.len(),
            a.pattern.n
        )));
    }
    let fresh = match slot {
        Some(s) => !s.fits(&a.pattern, border),
        None => true,
    };
    if fresh {
        *slot = Some(Box::new(BorderedSystem::new(&a.pattern, border)?));
    }
    let system = slot.as_mut().expect("set above");
    configure(&mut system.inner);
    let before = system.inner.symbolic_count();
    let result = system.solve(a, b);
    result.map(|()| system.inner.symbolic_count() - before)
}

/// Which sparse LU kernel faer uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LuKernel {
    /// faer's own choice from the estimated flop count.
    #[default]
    Auto,
    Simplicial,
    Supernodal,
}

/// faer sparse LU with partial pivoting. The symbolic analysis is cached per pattern, and
/// the numeric factors and the workspace are kept between calls, so that a Newton
/// iteration allocates nothing. Runs sequentially: on the small, banded systems of
/// contact problems thread start-up costs more than it saves (measured in BENCHMARKS.md).
pub struct FaerLu {
    kernel: LuKernel,
    symbolic: Option<(Arc<SparsePattern>, SymbolicLu<usize>)>,
    numeric: NumericLu<usize, f64>,
    workspace: Option<(usize, MemBuffer)>,
    border: Option<Box<BorderedSystem<FaerLu>>>,
    /// Number of symbolic analyses done (a pattern change triggers a new one).
    pub symbolic_count: usize,
}

impl Default for FaerLu {
    fn default() -> Self {
        FaerLu::with_kernel(LuKernel::Auto)
    }
}

impl FaerLu {
    pub fn with_kernel(kernel: LuKernel) -> Self {
        FaerLu {
            kernel,
            symbolic: None,
            numeric: NumericLu::new(),
            workspace: None,
            border: None,
            symbolic_count: 0,
        }
    }
}

impl Factorization for FaerLu {
    fn symbolic_count(&self) -> usize {
        self.symbolic_count
    }

    fn factor_and_solve(&mut self, a: &SparseMatrix, rhs: &mut [f64], nrhs: usize) -> Result<()> {
        check_system(a, rhs, nrhs)?;
        let p = &a.pattern;
        let par = Par::Seq;
        let sym = SymbolicSparseColMatRef::new_checked(p.n, p.n, &p.col_ptr, None, &p.row_idx);
        let reuse = matches!(&self.symbolic, Some((q, _)) if Arc::ptr_eq(q, p) || **q == **p);
        if !reuse {
            let threshold = match self.kernel {
                LuKernel::Auto => SupernodalThreshold::AUTO,
                LuKernel::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
                LuKernel::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
            };
            let params = LuSymbolicParams {
                supernodal_flop_ratio_threshold: threshold,
                ..Default::default()
            };
            let s = factorize_symbolic_lu(sym, params)
                .map_err(|e| Error::LinearSolver(format!("symbolic LU failed: {e:?}")))?;
            self.symbolic = Some((p.clone(), s));
            self.workspace = None;
            self.symbolic_count += 1;
        }
        let (_, symbolic) = self.symbolic.as_ref().expect("set above");
        if !matches!(&self.workspace, Some((k, _)) if *k >= nrhs) {
            let req = symbolic
                .factorize_numeric_lu_scratch::<f64>(par, Default::default())
                .or(symbolic.solve_in_place_scratch::<f64>(nrhs, par));
            let buffer = MemBuffer::try_new(req)
                .map_err(|e| Error::LinearSolver(format!("LU workspace: {e:?}")))?;
            self.workspace = Some((nrhs, buffer));
        }
        let buffer = &mut self.workspace.as_mut().expect("set above").1;
        let mat = SparseColMatRef::new(sym, &a.values);
        let lu = symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                par,
                MemStack::new(buffer),
                Default::default(),
            )
            .map_err(|e| Error::LinearSolver(format!("singular Jacobian ({e:?})")))?;
        let rhs_mat = faer::MatMut::from_column_major_slice_mut(rhs, p.n, nrhs);
        lu.solve_in_place_with_conj(Conj::No, rhs_mat, par, MemStack::new(buffer));
        if let Some(bad) = rhs.iter().position(|v| !v.is_finite()) {
            return Err(Error::LinearSolver(format!(
                "solution entry {} is not finite: the Jacobian is singular",
                bad % p.n
            )));
        }
        Ok(())
    }
}

impl LinearSolver for FaerLu {
    fn solve_bordered(&mut self, a: &SparseMatrix, b: &mut [f64], border: &[usize]) -> Result<()> {
        if border.is_empty() {
            return self.factor_and_solve(a, b, 1);
        }
        self.symbolic_count += solve_bordered_in(&mut self.border, a, b, border, |_| ())?;
        Ok(())
    }

    fn symbolic_analyses(&self) -> usize {
        self.symbolic_count
    }
}

/// The solver chosen by a [`LinearSolverKind`].
pub enum Solver {
    SymmetricLu(Box<SymmetricLu>),
    Lu(Box<FaerLu>),
}

/// Where every solve's system is written (see [`crate::solver::linear::system_dump`]), read once.
fn dump_path() -> Option<&'static std::path::Path> {
    static PATH: std::sync::OnceLock<Option<std::path::PathBuf>> = std::sync::OnceLock::new();
    PATH.get_or_init(|| {
        std::env::var_os(crate::solver::linear::system_dump::DUMP_VARIABLE).map(Into::into)
    })
    .as_deref()
}

impl Default for Solver {
    fn default() -> Self {
        Solver::new(LinearSolverKind::default())
    }
}

impl Solver {
    pub fn new(kind: LinearSolverKind) -> Self {
        match kind {
            LinearSolverKind::SymmetricLu => Solver::SymmetricLu(Box::default()),
            LinearSolverKind::Lu => Solver::Lu(Box::default()),
        }
    }
}

impl LinearSolver for Solver {
    fn solve_bordered(&mut self, a: &SparseMatrix, b: &mut [f64], border: &[usize]) -> Result<()> {
        if let Some(path) = dump_path() {
            crate::solver::linear::system_dump::write(path, a, b, border)?;
        }
        match self {
            Solver::SymmetricLu(s) => s.solve_bordered(a, b, border),
            Solver::Lu(s) => s.solve_bordered(a, b, border),
        }
    }

    fn symbolic_analyses(&self) -> usize {
        match self {
            Solver::SymmetricLu(s) => s.symbolic_analyses(),
            Solver::Lu(s) => s.symbolic_analyses(),
        }
    }

    fn set_pivoting_fallback(&mut self, allowed: bool) {
        if let Solver::SymmetricLu(s) = self {
            s.set_pivoting_fallback(allowed);
        }
    }

    fn set_threads(&mut self, threads: usize) {
        if let Solver::SymmetricLu(s) = self {
            s.set_threads(threads);
        }
    }

    fn split_factorizations(&self) -> usize {
        match self {
            Solver::SymmetricLu(s) => s.split_factorizations(),
            Solver::Lu(_) => 0,
        }
    }
}

/// Where an entry of the full matrix outside A goes in the bordered split
/// `[[A, B], [C, D]]` (A sparse, gathered by `BorderedSystem::inner_source`; the border's
/// B, C, D dense).
#[derive(Clone, Copy, Debug)]
enum Slot {
    B { row: usize, col: usize },
    C { row: usize, col: usize },
    D { row: usize, col: usize },
}

/// A system `[[A, B], [C, D]] [x; y] = [f; g]` with a handful of border unknowns `y`
/// (m of them) that couple to many others. Solved by block elimination:
///
/// ```text
/// A [z_0, Z] = [f, B],   (D - C Z) y = g - C z_0,   x = z_0 - Z y
/// ```
///
/// One sparse factorization of A and m + 1 triangular solves; the Schur complement is a
/// dense m x m matrix. A dense row and column inside the sparse LU would instead tie every
/// unknown they touch into one front (a force-controlled tool's offset touches every node
/// of the tool: measured 7x slower factorizations on the square cup). Needs A regular: the
/// system with the border unknowns held fixed (for a tool offset: the tool under
/// displacement control), which is the case wherever the full system is.
struct BorderedSystem<F> {
    full: Arc<SparsePattern>,
    border: Vec<usize>,
    /// Full unknown -> index in A (None: a border unknown).
    inner_index: Vec<Option<usize>>,
    /// For each entry of A, the position of its value in the full matrix (every entry of
    /// A has exactly one), so that A is a gather of the full values.
    inner_source: Vec<usize>,
    /// The full matrix's entries in B, C or D, with their positions there.
    border_slots: Vec<(usize, Slot)>,
    inner: F,
    /// A, the right-hand sides `[f, B]` and the dense C and D, kept from call to call: A's
    /// values are all overwritten by the gather, C and D only ever hold the pattern's
    /// positions, and the right-hand sides are rewritten whole.
    matrix: SparseMatrix,
    rhs: Vec<f64>,
    c_mat: nalgebra::DMatrix<f64>,
    d_mat: nalgebra::DMatrix<f64>,
}

impl<F: Factorization> BorderedSystem<F> {
    fn new(full: &Arc<SparsePattern>, border: &[usize]) -> Result<Self> {
        let n = full.n;
        let mut border_index = vec![None; n];
        for (k, &d) in border.iter().enumerate() {
            if d >= n || border_index[d].is_some() {
                return Err(Error::LinearSolver(format!(
                    "border unknown {d} is out of range or repeated (n = {n})"
                )));
            }
            border_index[d] = Some(k);
        }
        let mut inner_index = vec![None; n];
        let mut next = 0;
        for (d, slot) in inner_index.iter_mut().enumerate() {
            if border_index[d].is_none() {
                *slot = Some(next);
                next += 1;
            }
        }
        // Entries of the full pattern in storage order (column by column), as (row, col).
        let entries = || {
            (0..n).flat_map(move |col| {
                full.row_idx[full.col_ptr[col]..full.col_ptr[col + 1]]
                    .iter()
                    .map(move |&row| (row, col))
            })
        };
        let mut inner_pattern = SparsePattern::from_entries(
            next,
            entries().filter_map(|(row, col)| Some((inner_index[row]?, inner_index[col]?))),
        );
        if let Some(groups) = &full.groups {
            let inner_groups = (0..n)
                .filter(|&d| inner_index[d].is_some())
                .map(|d| groups[d]);
            inner_pattern = inner_pattern.with_groups(inner_groups.collect());
        }
        let inner_pattern = Arc::new(inner_pattern);
        let mut inner_source = vec![usize::MAX; inner_pattern.nnz()];
        let mut border_slots = Vec::new();
        for (i, (row, col)) in entries().enumerate() {
            let slot = match (inner_index[row], inner_index[col]) {
                (Some(r), Some(c)) => {
                    let k = inner_pattern
                        .position(r, c)
                        .expect("entry of the inner pattern");
                    inner_source[k] = i;
                    continue;
                }
                (Some(r), None) => Slot::B {
                    row: r,
                    col: border_index[col].expect("a border unknown"),
                },
                (None, Some(c)) => Slot::C {
                    row: border_index[row].expect("a border unknown"),
                    col: c,
                },
                (None, None) => Slot::D {
                    row: border_index[row].expect("a border unknown"),
                    col: border_index[col].expect("a border unknown"),
                },
            };
            border_slots.push((i, slot));
        }
        debug_assert!(inner_source.iter().all(|&i| i != usize::MAX));
        let (n_a, m) = (next, border.len());
        Ok(BorderedSystem {
            full: full.clone(),
            border: border.to_vec(),
            inner_index,
            inner_source,
            border_slots,
            inner: F::default(),
            matrix: SparseMatrix::zeros(inner_pattern),
            rhs: vec![0.0; n_a * (m + 1)],
            c_mat: nalgebra::DMatrix::zeros(m, n_a),
            d_mat: nalgebra::DMatrix::zeros(m, m),
        })
    }

    fn fits(&self, full: &Arc<SparsePattern>, border: &[usize]) -> bool {
        self.border == border && (Arc::ptr_eq(&self.full, full) || *self.full == **full)
    }

    fn solve(&mut self, a: &SparseMatrix, b: &mut [f64]) -> Result<()> {
        let (n_a, m) = (self.matrix.pattern.n, self.border.len());
        let (inner, rhs) = (&mut self.matrix, &mut self.rhs);
        let (c_mat, d_mat) = (&mut self.c_mat, &mut self.d_mat);
        for (v, &i) in inner.values.iter_mut().zip(&self.inner_source) {
            *v = a.values[i];
        }
        // Columns: f, then B (n_a x m, column-major); the last solve left its solution here.
        rhs[n_a..].fill(0.0);
        for &(i, slot) in &self.border_slots {
            let v = a.values[i];
            match slot {
                Slot::B { row, col } => rhs[(col + 1) * n_a + row] = v,
                Slot::C { row, col } => c_mat[(row, col)] = v,
                Slot::D { row, col } => d_mat[(row, col)] = v,
            }
        }
        for (d, i) in self.inner_index.iter().enumerate() {
            if let Some(i) = i {
                rhs[*i] = b[d];
            }
        }
        self.inner.factor_and_solve(inner, rhs, m + 1)?;
        let z0 = nalgebra::DVectorView::from_slice(&rhs[..n_a], n_a);
        let z = nalgebra::DMatrixView::from_slice(&rhs[n_a..], n_a, m);
        let g = nalgebra::DVector::from_iterator(m, self.border.iter().map(|&d| b[d]));
        let schur = &*d_mat - &*c_mat * z;
        let y = schur
            .clone()
            .lu()
            .solve(&(g - &*c_mat * z0))
            .filter(|y| y.iter().all(|v| v.is_finite()))
            .ok_or_else(|| {
                Error::LinearSolver(format!(
                    "singular Schur complement of the border unknowns {:?} ({schur})",
                    self.border
                ))
            })?;
        let x = z0 - z * &y;
        for (d, i) in self.inner_index.iter().enumerate() {
            if let Some(i) = i {
                b[d] = x[*i];
            }
        }
        for (k, &d) in self.border.iter().enumerate() {
            b[d] = y[k];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_an_indefinite_saddle_system_and_reuses_the_analysis() {
        // [[2, 0, 1], [0, 3, 1], [1, 1, 0]]: zero diagonal entry, needs pivoting.
        let entries = [(0, 0), (1, 1), (0, 2), (2, 0), (1, 2), (2, 1)];
        let p = Arc::new(SparsePattern::from_entries(3, entries));
        let mut a = SparseMatrix::zeros(p);
        for (r, c, v) in [
            (0, 0, 2.0),
            (1, 1, 3.0),
            (0, 2, 1.0),
            (2, 0, 1.0),
            (1, 2, 1.0),
            (2, 1, 1.0),
        ] {
            a.add(r, c, v);
        }
        let x = [1.0, -2.0, 0.5];
        let mut b = a.mul_vec(&x);
        let mut solver = FaerLu::default();
        solver.solve(&a, &mut b).unwrap();
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut b2 = a.mul_vec(&x);
        solver.solve(&a, &mut b2).unwrap();
        assert_eq!(solver.symbolic_count, 1);
    }

    /// A tridiagonal system with one unknown coupled to every other (a tool offset's row
    /// and column): the bordered solve must equal the plain one to round-off.
    #[test]
    fn bordered_solve_equals_the_plain_one() {
        let n = 40;
        let dense = 17;
        let mut entries = Vec::new();
        let mut values = Vec::new();
        for i in 0..n {
            entries.push((i, i));
            values.push(4.0 + (i % 3) as f64);
            if i + 1 < n {
                entries.push((i, i + 1));
                values.push(-1.0 + 0.01 * i as f64);
                entries.push((i + 1, i));
                values.push(-1.2);
            }
            if i != dense {
                entries.push((dense, i));
                values.push(0.3 * ((i * 7 % 5) as f64 - 2.0));
                entries.push((i, dense));
                values.push(0.1 * ((i * 3 % 4) as f64 - 1.5));
            }
        }
        let p = Arc::new(SparsePattern::from_entries(n, entries.iter().copied()));
        let mut a = SparseMatrix::zeros(p);
        for (&(r, c), &v) in entries.iter().zip(&values) {
            a.add(r, c, v);
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let b = a.mul_vec(&x);
        let mut solver = FaerLu::default();
        for border in [vec![dense], vec![dense, 3], vec![n - 1, 0, dense]] {
            let mut y = b.clone();
            solver.solve_bordered(&a, &mut y, &border).unwrap();
            for i in 0..n {
                // A condition number of order 10 on O(1) data: round-off is ~1e-15.
                assert!(
                    (y[i] - x[i]).abs() < 1e-12,
                    "border {border:?}, unknown {i}"
                );
            }
        }
        // Same pattern and border: the analysis of A is reused.
        let count = solver.symbolic_count;
        let mut y = b.clone();
        solver
            .solve_bordered(&a, &mut y, &[n - 1, 0, dense])
            .unwrap();
        assert_eq!(solver.symbolic_count, count);
        // Other values and another right-hand side on the kept system (its matrix, dense
        // blocks and right-hand sides reused), both solvers: nothing of the last call
        // leaks into the next.
        let mut other = a.clone();
        for (k, v) in other.values.iter_mut().enumerate() {
            *v *= 1.0 + 0.05 * ((k * 13 % 7) as f64 - 3.0) / 3.0;
        }
        let x2: Vec<f64> = (0..n).map(|i| (i as f64 * 0.91).cos()).collect();
        let b2 = other.mul_vec(&x2);
        let mut symmetric = SymmetricLu::default();
        for (matrix, rhs, expected) in [(&a, &b, &x), (&other, &b2, &x2), (&a, &b, &x)] {
            for solver in [&mut solver as &mut dyn LinearSolver, &mut symmetric] {
                let mut y = rhs.clone();
                solver
                    .solve_bordered(matrix, &mut y, &[n - 1, 0, dense])
                    .unwrap();
                for i in 0..n {
                    assert!((y[i] - expected[i]).abs() < 1e-12, "unknown {i}");
                }
            }
        }
    }

    #[test]
    fn singular_border_is_an_error_not_a_panic() {
        // x0 + x1 = 1, x0 + x1 = 2 with x1 on the border: the Schur complement is 0.
        let p = Arc::new(SparsePattern::from_entries(
            2,
            [(0, 0), (1, 1), (0, 1), (1, 0)],
        ));
        let mut a = SparseMatrix::zeros(p);
        for (r, c) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            a.add(r, c, 1.0);
        }
        let mut b = vec![1.0, 2.0];
        let err = FaerLu::default()
            .solve_bordered(&a, &mut b, &[1])
            .unwrap_err();
        assert!(err.to_string().contains("Schur"), "{err}");
    }

    #[test]
    fn singular_matrix_is_an_error_not_a_panic() {
        let p = Arc::new(SparsePattern::from_entries(
            2,
            [(0, 0), (1, 1), (0, 1), (1, 0)],
        ));
        let mut a = SparseMatrix::zeros(p);
        a.add(0, 0, 1.0);
        a.add(0, 1, 1.0);
        a.add(1, 0, 1.0);
        a.add(1, 1, 1.0);
        let mut b = vec![1.0, 2.0];
        assert!(FaerLu::default().solve(&a, &mut b).is_err());
    }
}
