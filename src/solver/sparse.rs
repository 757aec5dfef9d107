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
    /// The value positions of each row's entries (a row-major index of the pattern:
    /// `row_ptr`, positions), built on first use by [`Self::row_positions`].
    pub row_index: std::sync::OnceLock<(Vec<usize>, Vec<usize>)>,
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
            row_index: std::sync::OnceLock::new(),
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

    /// The value positions of the entries of row `row`, by column. The index is built
    /// once per pattern (O(nnz)) and shared by every matrix on it.
    pub fn row_positions(&self, row: usize) -> &[usize] {
        let (ptr, positions) = self.row_index.get_or_init(|| {
            let mut ptr = vec![0; self.n + 1];
            for &r in &self.row_idx {
                ptr[r + 1] += 1;
            }
            for r in 0..self.n {
                ptr[r + 1] += ptr[r];
            }
            let mut next = ptr.clone();
            let mut positions = vec![0; self.nnz()];
            for c in 0..self.n {
                for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                    let r = self.row_idx[k];
                    positions[next[r]] = k;
                    next[r] += 1;
                }
            }
            (ptr, positions)
        });
        &positions[ptr[row]..ptr[row + 1]]
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

    /// Replaces every row `r` with `is_fixed[r]` by the unit row (Dirichlet condition):
    /// zeroes the row, sets 1 on the diagonal (where the pattern has it).
    pub fn set_unit_rows(&mut self, is_fixed: &[bool]) {
        // Only the fixed rows' entries, through the pattern's row index: O(n + entries
        // of fixed rows) per call instead of a scan of the whole pattern.
        let p = &self.pattern;
        for (r, _) in is_fixed.iter().enumerate().filter(|(_, f)| **f) {
            for &k in p.row_positions(r) {
                self.values[k] = 0.0;
            }
            if let Some(k) = p.position(r, r) {
                self.values[k] = 1.0;
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
        let mut y = Vec::new();
        self.mul_vec_into(x, &mut y);
        y
    }

    /// y = A x into `y`'s storage.
    pub fn mul_vec_into(&self, x: &[f64], y: &mut Vec<f64>) {
        let p = &self.pattern;
        y.clear();
        y.resize(p.n, 0.0);
        for c in 0..p.n {
            let (range, xc) = (p.col_ptr[c]..p.col_ptr[c + 1], x[c]);
            for (&r, &v) in p.row_idx[range.clone()].iter().zip(&self.values[range]) {
                y[r] += v * xc;
            }
        }
    }

    /// [`Self::mul_vec`] of each of the `columns` vectors stored one after the other in `x`
    /// (into `y`, likewise), and [`Self::row_abs_sums`] into `sums`, in one pass over the
    /// entries: each the same sums, added in the same order.
    pub fn mul_columns_and_row_abs_sums(
        &self,
        x: &[f64],
        columns: usize,
        y: &mut Vec<f64>,
        sums: &mut Vec<f64>,
    ) {
        let p = &self.pattern;
        let n = p.n;
        y.clear();
        y.resize(n * columns, 0.0);
        sums.clear();
        sums.resize(n, 0.0);
        for c in 0..n {
            let range = p.col_ptr[c]..p.col_ptr[c + 1];
            let column = p.row_idx[range.clone()].iter().zip(&self.values[range]);
            match columns {
                1 => {
                    let xc = x[c];
                    for (&r, &v) in column {
                        y[r] += v * xc;
                        sums[r] += v.abs();
                    }
                }
                _ => {
                    for (&r, &v) in column {
                        for j in 0..columns {
                            y[j * n + r] += v * x[j * n + c];
                        }
                        sums[r] += v.abs();
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The row-index form equals a scan of the whole pattern (the form before it) on a
    /// random unsymmetric pattern, with a row lacking its diagonal, and fixing rows twice
    /// on the same pattern (the index reused) gives the same again.
    #[test]
    fn unit_rows_through_the_row_index_equal_a_scan_of_the_pattern() {
        let n = 40;
        let mut seed = 3u64;
        let mut rnd = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as usize
        };
        let entries: Vec<(usize, usize)> = (0..400)
            .map(|_| (rnd() % n, rnd() % n))
            .chain((0..n).filter(|&i| i != 7).map(|i| (i, i)))
            .filter(|&e| e != (7, 7))
            .collect();
        let pattern = std::sync::Arc::new(SparsePattern::from_entries(n, entries));
        assert!(pattern.position(7, 7).is_none());
        for round in 0..2 {
            let fixed: Vec<bool> = (0..n).map(|i| i % 3 == round || i == 7).collect();
            let mut a = SparseMatrix::zeros(pattern.clone());
            a.values = (0..a.values.len()).map(|k| 1.0 + k as f64).collect();
            let mut scanned = a.clone();
            for c in 0..n {
                for k in pattern.col_ptr[c]..pattern.col_ptr[c + 1] {
                    let r = pattern.row_idx[k];
                    if fixed[r] {
                        scanned.values[k] = if r == c { 1.0 } else { 0.0 };
                    }
                }
            }
            a.set_unit_rows(&fixed);
            assert_eq!(a.values, scanned.values);
        }
    }

    /// The products of one or several columns in one pass, and `mul_vec`, equal the plain
    /// product entry by entry, and the row sums `row_abs_sums`, bit for bit (the
    /// backward-error check relies on it).
    #[test]
    fn columns_multiplied_together_equal_each_alone() {
        let n = 30;
        let entries = (0..n).flat_map(|i| [(i, i), (i, (7 * i + 3) % n), ((5 * i + 1) % n, i)]);
        let mut a =
            SparseMatrix::zeros(std::sync::Arc::new(SparsePattern::from_entries(n, entries)));
        a.values = (0..a.values.len())
            .map(|k| (k as f64 * 0.77).sin() / 3.0)
            .collect();
        let x: Vec<f64> = (0..3 * n).map(|i| (i as f64 * 1.3).cos() * 1e3).collect();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for columns in [1, 3] {
            let (mut y, mut sums) = (Vec::new(), Vec::new());
            a.mul_columns_and_row_abs_sums(&x[..columns * n], columns, &mut y, &mut sums);
            for j in 0..columns {
                // The plain product, entry by entry in the pattern's order.
                let mut alone = vec![0.0; n];
                for c in 0..n {
                    for k in a.pattern.col_ptr[c]..a.pattern.col_ptr[c + 1] {
                        alone[a.pattern.row_idx[k]] += a.values[k] * x[j * n + c];
                    }
                }
                assert_eq!(
                    bits(&y[j * n..(j + 1) * n]),
                    bits(&alone),
                    "column {j} of {columns}"
                );
                assert_eq!(bits(&a.mul_vec(&x[j * n..(j + 1) * n])), bits(&alone));
            }
            assert_eq!(bits(&sums), bits(&a.row_abs_sums()));
        }
    }

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
