//! Writes and reads a linear system (matrix, right-hand side, border unknowns) in a small
//! binary format, so that a solver can be benchmarked on the systems of a real run: with
//! `TRIBO_DUMP_SYSTEM=PATH` in the environment, every solve of the default solver
//! overwrites PATH with its system (diagnostics only; costs a file write per solve; the
//! file is replaced whole, so a run may be stopped at any time).
//!
//! Format, little-endian u64 / f64: `n, nnz, n_border, has_groups`, then `col_ptr (n + 1)`,
//! `row_idx (nnz)`, `values (nnz)`, `rhs (n)`, `border (n_border)`, `groups (n, if any)`.

use crate::solver::sparse::{SparseMatrix, SparsePattern};
use crate::{Error, Result};
use std::io::{Read, Write};
use std::path::Path;
use std::sync::Arc;

/// The environment variable naming the dump file.
pub const DUMP_VARIABLE: &str = "TRIBO_DUMP_SYSTEM";

pub fn write(path: &Path, a: &SparseMatrix, rhs: &[f64], border: &[usize]) -> Result<()> {
    let p = &a.pattern;
    let mut out = Vec::with_capacity(8 * (2 * p.nnz() + 3 * p.n + 8));
    let int = |v: usize, out: &mut Vec<u8>| out.extend_from_slice(&(v as u64).to_le_bytes());
    int(p.n, &mut out);
    int(p.nnz(), &mut out);
    int(border.len(), &mut out);
    int(usize::from(p.groups.is_some()), &mut out);
    for &v in p.col_ptr.iter().chain(&p.row_idx) {
        int(v, &mut out);
    }
    for &v in a.values.iter().chain(rhs) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for &v in border.iter().chain(p.groups.iter().flat_map(|g| g.iter())) {
        int(v, &mut out);
    }
    let fail = |e: std::io::Error| Error::LinearSolver(format!("{}: {e}", path.display()));
    // Written aside and renamed, so that a run stopped at any moment leaves a whole system.
    let aside = path.with_extension("partial");
    std::fs::File::create(&aside)
        .and_then(|mut f| f.write_all(&out))
        .and_then(|()| std::fs::rename(&aside, path))
        .map_err(fail)
}

/// A system read back: matrix, right-hand side, border unknowns.
pub fn read(path: &Path) -> Result<(SparseMatrix, Vec<f64>, Vec<usize>)> {
    let fail = |what: String| Error::LinearSolver(format!("{}: {what}", path.display()));
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .map_err(|e| fail(e.to_string()))?;
    let mut words = bytes
        .chunks_exact(8)
        .map(|c| <[u8; 8]>::try_from(c).expect("8 bytes"));
    let mut int = || -> Result<usize> {
        words
            .next()
            .map(|w| u64::from_le_bytes(w) as usize)
            .ok_or_else(|| fail("truncated".into()))
    };
    let (n, nnz, n_border, has_groups) = (int()?, int()?, int()?, int()?);
    if bytes.len() != 8 * (4 + n + 1 + 2 * nnz + n + n_border + has_groups * n) {
        return Err(fail("size does not match its header".into()));
    }
    let mut words = bytes[32..]
        .chunks_exact(8)
        .map(|c| <[u8; 8]>::try_from(c).expect("8 bytes"));
    let mut ints = |k: usize| -> Vec<usize> {
        (0..k)
            .map(|_| u64::from_le_bytes(words.next().expect("size checked")) as usize)
            .collect()
    };
    let col_ptr = ints(n + 1);
    let row_idx = ints(nnz);
    let floats: Vec<f64> = ints(nnz + n)
        .into_iter()
        .map(|b| f64::from_bits(b as u64))
        .collect();
    let border = ints(n_border);
    let groups = ints(has_groups * n);
    let mut pattern = SparsePattern {
        n,
        col_ptr,
        row_idx,
        groups: None,
        row_index: Default::default(),
    };
    if has_groups == 1 {
        pattern = pattern.with_groups(groups);
    }
    let a = SparseMatrix {
        pattern: Arc::new(pattern),
        values: floats[..nnz].to_vec(),
    };
    Ok((a, floats[nnz..].to_vec(), border))
}
