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
    fn solve(&mut self, a: &SparseMatrix, b: &mut [f64]) -> Result<()>;
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
    workspace: Option<MemBuffer>,
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
            symbolic_count: 0,
        }
    }
}

impl LinearSolver for FaerLu {
    fn solve(&mut self, a: &SparseMatrix, b: &mut [f64]) -> Result<()> {
        let p = &a.pattern;
        if b.len() != p.n {
            return Err(Error::LinearSolver(format!(
                "right-hand side has {} entries, matrix has {} rows",
                b.len(),
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
            let req = s
                .factorize_numeric_lu_scratch::<f64>(par, Default::default())
                .or(s.solve_in_place_scratch::<f64>(1, par));
            self.workspace = Some(
                MemBuffer::try_new(req)
                    .map_err(|e| Error::LinearSolver(format!("LU workspace: {e:?}")))?,
            );
            self.symbolic = Some((p.clone(), s));
            self.symbolic_count += 1;
        }
        let (_, symbolic) = self.symbolic.as_ref().expect("set above");
        let stack = MemStack::new(self.workspace.as_mut().expect("set with the symbolic"));
        let mat = SparseColMatRef::new(sym, &a.values);
        let lu = symbolic
            .factorize_numeric_lu(&mut self.numeric, mat, par, stack, Default::default())
            .map_err(|e| Error::LinearSolver(format!("singular Jacobian ({e:?})")))?;
        let rhs = faer::MatMut::from_column_major_slice_mut(b, p.n, 1);
        let stack = MemStack::new(self.workspace.as_mut().expect("set with the symbolic"));
        lu.solve_in_place_with_conj(Conj::No, rhs, par, stack);
        if let Some(bad) = b.iter().position(|v| !v.is_finite()) {
            return Err(Error::LinearSolver(format!(
                "solution entry {bad} is not finite: the Jacobian is singular"
            )));
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
