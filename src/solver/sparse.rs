//! Compressed-sparse-column matrix with a pattern fixed before assembly.
//!
//! The pattern (every entry any element or contact node may touch) is built once per
//! mesh/contact layout; Newton iterations only overwrite values, so the linear solver's
//! symbolic analysis is reused. Adding an entry costs a binary search in its column,
//! O(log nnz_col).

/// Column-major sparsity pattern with sorted row indices in each column.
#[derive(Clone, Debug, PartialEq)]
pub struct SparsePattern {
    pub n: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
    /// Optional elimination groups, one id per unknown: unknowns sharing an id are
    /// eliminated together, in index order, by a factorization without pivoting (a contact
    /// node's displacements, then its multipliers, whose own pivot may be zero). Pivoting
    /// factorizations ignore it.
    pub groups: Option<std::sync::Arc<Vec<usize>>>,
}

impl SparsePattern {
    /// Builds an `n x n` pattern from (row, col) pairs; duplicates are merged.
    pub fn from_entries(n: usize, entries: impl IntoIterator<Item = (usize, usize)>) -> Self {
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (r, c) in entries {
            cols[c].push(r);
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for col in &mut cols {
            col.sort_unstable();
            col.dedup();
            row_idx.extend_from_slice(col);
            col_ptr.push(row_idx.len());
        }
        SparsePattern {
            n,
            col_ptr,
            row_idx,
            groups: None,
        }
    }

    /// The same pattern with elimination groups (see [`Self::groups`]).
    pub fn with_groups(mut self, groups: Vec<usize>) -> Self {
        debug_assert_eq!(groups.len(), self.n);
        self.groups = Some(std::sync::Arc::new(groups));
        self
    }

    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Position of (row, col) in the value array, if it is in the pattern.
    pub fn position(&self, row: usize, col: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        self.row_idx[a..b].binary_search(&row).ok().map(|k| a + k)
    }
}

/// Values on a fixed [`SparsePattern`].
#[derive(Clone, Debug)]
pub struct SparseMatrix {
    pub pattern: std::sync::Arc<SparsePattern>,
    pub values: Vec<f64>,
}

impl SparseMatrix {
    pub fn zeros(pattern: std::sync::Arc<SparsePattern>) -> Self {
        let values = vec![0.0; pattern.nnz()];
        SparseMatrix { pattern, values }
    }

    pub fn clear(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
    }

    /// Adds `v` at (row, col). Entries outside the pattern are a programming error of the
    /// pattern builder, not of the user, hence the debug assertion.
    #[inline]
    pub fn add(&mut self, row: usize, col: usize, v: f64) {
        match self.pattern.position(row, col) {
            Some(k) => self.values[k] += v,
            None => debug_assert!(false, "entry ({row}, {col}) outside the sparsity pattern"),
        }
    }

    /// Replaces row `row` by the unit row (Dirichlet condition): zeroes the row, sets 1 on the
    /// diagonal. O(nnz) once per call; callers batch rows with [`Self::set_unit_rows`].
    pub fn set_unit_rows(&mut self, is_fixed: &[bool]) {
        let p = self.pattern.clone();
        for c in 0..p.n {
            for k in p.col_ptr[c]..p.col_ptr[c + 1] {
                let r = p.row_idx[k];
                if is_fixed[r] {
                    self.values[k] = if r == c { 1.0 } else { 0.0 };
                }
            }
        }
    }

    /// Sum of the absolute values of each row (the infinity norm is their largest).
    pub fn row_abs_sums(&self) -> Vec<f64> {
        let p = &self.pattern;
        let mut sums = vec![0.0; p.n];
        for c in 0..p.n {
            for k in p.col_ptr[c]..p.col_ptr[c + 1] {
                sums[p.row_idx[k]] += self.values[k].abs();
            }
        }
        sums
    }

    /// y = A x.
    pub fn mul_vec(&self, x: &[f64]) -> Vec<f64> {
        let p = &self.pattern;
        let mut y = vec![0.0; p.n];
        for c in 0..p.n {
            for k in p.col_ptr[c]..p.col_ptr[c + 1] {
                y[p.row_idx[k]] += self.values[k] * x[c];
            }
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pattern_merges_duplicates_and_finds_entries() {
        let p = SparsePattern::from_entries(3, [(0, 0), (2, 0), (0, 0), (1, 1), (2, 2), (0, 2)]);
        assert_eq!(p.nnz(), 5);
        assert_eq!(p.position(2, 0), Some(1));
        assert_eq!(p.position(1, 0), None);
        let mut m = SparseMatrix::zeros(std::sync::Arc::new(p));
        m.add(0, 2, 2.0);
        m.add(0, 2, 1.0);
        assert_eq!(m.mul_vec(&[0.0, 0.0, 1.0]), vec![3.0, 0.0, 0.0]);
    }
}
