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
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use std::sync::Arc;

/// Solves A x = b for a sparse square A.
pub trait LinearSolver {
    /// Factorizes `a` (reusing any analysis of an identical pattern) and solves for `b` in place.
    fn solve(&mut self, a: &SparseMatrix, b: &mut [f64]) -> Result<()>;
}

/// faer sparse LU with the symbolic analysis cached per pattern.
#[derive(Default)]
pub struct FaerLu {
    symbolic: Option<(Arc<SparsePattern>, SymbolicLu<usize>)>,
    /// Number of symbolic analyses done (a pattern change triggers a new one).
    pub symbolic_count: usize,
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
        let sym = SymbolicSparseColMatRef::new_checked(p.n, p.n, &p.col_ptr, None, &p.row_idx);
        let reuse = matches!(&self.symbolic, Some((q, _)) if Arc::ptr_eq(q, p) || **q == **p);
        if !reuse {
            let s = SymbolicLu::try_new(sym)
                .map_err(|e| Error::LinearSolver(format!("symbolic LU failed: {e:?}")))?;
            self.symbolic = Some((p.clone(), s));
            self.symbolic_count += 1;
        }
        let symbolic = self.symbolic.as_ref().expect("set above").1.clone();
        let mat = SparseColMatRef::new(sym, &a.values);
        let lu = Lu::try_new_with_symbolic(symbolic, mat)
            .map_err(|e| Error::LinearSolver(format!("singular Jacobian ({e:?})")))?;
        let rhs = faer::MatMut::from_column_major_slice_mut(b, p.n, 1);
        lu.solve_in_place(rhs);
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
