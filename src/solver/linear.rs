//! The one interface through which the Newton solver solves its linear systems.
//!
//! The mixed (u, lambda) Jacobian is unsymmetric and indefinite (a stick node has a zero
//! lambda-lambda block), so the default is faer's sparse LU with partial pivoting. Its
//! symbolic analysis (column ordering, elimination structure) depends only on the pattern
//! and is computed once per pattern; each Newton iteration pays only the numeric
//! factorization. Kept behind [`LinearSolver`] so that another factorization can be swapped
//! in without touching the Newton code.

use super::sparse::{SparseMatrix, SparsePattern};
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
    border: Option<Box<BorderedSystem>>,
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

    /// Factorizes `a` and solves for the `nrhs` right-hand sides stored column after column
    /// in `rhs`.
    fn factor_and_solve(&mut self, a: &SparseMatrix, rhs: &mut [f64], nrhs: usize) -> Result<()> {
        let p = &a.pattern;
        if rhs.len() != p.n * nrhs {
            return Err(Error::LinearSolver(format!(
                "right-hand side has {} entries, matrix has {} rows",
                rhs.len(),
                p.n
            )));
        }
        if let Some(bad) = a.values.iter().position(|v| !v.is_finite()) {
            return Err(Error::LinearSolver(format!(
                "matrix entry {bad} is not finite ({})",
                a.values[bad]
            )));
        }
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
        if b.len() != a.pattern.n {
            return Err(Error::LinearSolver(format!(
                "right-hand side has {} entries, matrix has {} rows",
                b.len(),
                a.pattern.n
            )));
        }
        let fresh = match &self.border {
            Some(s) => !s.fits(&a.pattern, border),
            None => true,
        };
        if fresh {
            self.border = Some(Box::new(BorderedSystem::new(&a.pattern, border)?));
        }
        let system = self.border.as_mut().expect("set above");
        let before = system.inner.symbolic_count;
        let result = system.solve(a, b);
        self.symbolic_count += system.inner.symbolic_count - before;
        result
    }
}

/// Where an entry of the full matrix goes in the bordered split
/// `[[A, B], [C, D]]` (A sparse, the border's B, C, D dense).
#[derive(Clone, Copy, Debug)]
enum Slot {
    A(usize),
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
struct BorderedSystem {
    full: Arc<SparsePattern>,
    border: Vec<usize>,
    /// Full unknown -> index in A (None: a border unknown).
    inner_index: Vec<Option<usize>>,
    slots: Vec<Slot>,
    inner_pattern: Arc<SparsePattern>,
    inner: FaerLu,
}

impl BorderedSystem {
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
        let inner_pattern = Arc::new(SparsePattern::from_entries(
            next,
            entries().filter_map(|(row, col)| Some((inner_index[row]?, inner_index[col]?))),
        ));
        let slots = entries()
            .map(|(row, col)| match (inner_index[row], inner_index[col]) {
                (Some(r), Some(c)) => Slot::A(
                    inner_pattern
                        .position(r, c)
                        .expect("entry of the inner pattern"),
                ),
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
            })
            .collect();
        Ok(BorderedSystem {
            full: full.clone(),
            border: border.to_vec(),
            inner_index,
            slots,
            inner_pattern,
            inner: FaerLu::default(),
        })
    }

    fn fits(&self, full: &Arc<SparsePattern>, border: &[usize]) -> bool {
        self.border == border && (Arc::ptr_eq(&self.full, full) || *self.full == **full)
    }

    fn solve(&mut self, a: &SparseMatrix, b: &mut [f64]) -> Result<()> {
        let (n_a, m) = (self.inner_pattern.n, self.border.len());
        let mut inner = SparseMatrix::zeros(self.inner_pattern.clone());
        // Columns: f, then B (n_a x m, column-major).
        let mut rhs = vec![0.0; n_a * (m + 1)];
        let mut c_mat = nalgebra::DMatrix::<f64>::zeros(m, n_a);
        let mut d_mat = nalgebra::DMatrix::<f64>::zeros(m, m);
        for (&v, slot) in a.values.iter().zip(&self.slots) {
            match *slot {
                Slot::A(k) => inner.values[k] = v,
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
        self.inner.factor_and_solve(&inner, &mut rhs, m + 1)?;
        let z0 = nalgebra::DVectorView::from_slice(&rhs[..n_a], n_a);
        let z = nalgebra::DMatrixView::from_slice(&rhs[n_a..], n_a, m);
        let g = nalgebra::DVector::from_iterator(m, self.border.iter().map(|&d| b[d]));
        let schur = d_mat - &c_mat * z;
        let y = schur
            .clone()
            .lu()
            .solve(&(g - &c_mat * z0))
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
