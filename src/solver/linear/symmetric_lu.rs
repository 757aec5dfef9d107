//! Sparse LU without pivoting on the symmetric structure of `A + A^T`.
//!
//! The condensed contact system has a structurally symmetric pattern (a contact node's
//! condensed rows have K's row pattern) and safe diagonal pivots (gap rows: K's diagonal;
//! stick rows: r times about the identity; slip rows a mix), but it is numerically far from
//! symmetric. A partial-pivoting LU (faer's, ordered by COLAMD on `A^T A`) pays for the
//! freedom to pivot with a much larger fill. Here instead:
//!
//! - symbolic (once per pattern): AMD on `A + A^T`, and faer's supernodal symbolic Cholesky
//!   of the permuted `A + A^T`; `L` and `U^T` both take the structure of that Cholesky
//!   factor. A supernode `s` (columns `f..f+k`, rows `R` below its diagonal block) stores a
//!   dense panel `(k + |R|) x k` holding the diagonal block `L_ss \ U_ss` and `L_Rs`, and a
//!   dense panel `|R| x k` holding `U_sR^T`;
//! - numeric (every call), left-looking by supernodes: gather `A`'s entries into the panels
//!   through a precomputed slot per entry; subtract the updates of every descendant `d`
//!   whose rows meet `s`'s columns (`L_{R_d,d} U_{d,s}` and `U^T` likewise, two dense
//!   products); factorize the diagonal block without pivoting (recursive, dense kernels of
//!   faer); `L_Rs = A_Rs U_ss^{-1}` and `U_sR = L_ss^{-1} A_sR` by triangular solves.
//!
//! Cost: the flops of a Cholesky factorization of the same pattern times two (both triangles),
//! memory `nnz(L) + nnz(U) = 2 nnz(L_chol) - n`.
//!
//! Refactorization: the numeric factors keep the values they were computed from. A call
//! whose matrix differs in a few entries recomputes only the supernodes owning a changed
//! entry and their ancestors in the supernodal elimination tree (a supernode's panels are
//! a function of its own entries and of its descendants' panels), bit for bit what a fresh
//! factorization gives. The root separators carry most of the flops, so a change of a few
//! scattered rows still costs about 60 % of a whole factorization on the square cup; what it
//! is for is status prediction's re-solves, which change the rows of a few contact nodes.
//!
//! Threads: a supernode's panels depend on its own entries and its descendants' panels
//! only, so disjoint subtrees of the elimination tree are factorized at once (each a
//! contiguous range of supernodes, hence of the value array, cut apart without sharing),
//! one thread per bin of subtrees of about equal recomputed flops
//! ([`crate::solver::linear::subtree_split`]), and the supernodes above them (the root separators) after
//! them on one thread. Each supernode is computed by the same operations whatever thread
//! runs it: the factors are bit for bit the sequential ones. Where two bins meet refused
//! pivots, the one of least column is reported (the sequential order may stop at another
//! one first; either way the call fails and the next factorization is whole).
//!
//! Without pivoting, a tiny pivot would spoil the factors: every diagonal pivot is checked
//! against the largest entry of its column of `L` and row of `U` before elimination
//! (`|u_jj| > 1e-10 max`), and the caller checks the backward error of the solution (see
//! [`SymmetricLu`]), falling back to a pivoting LU when either fails.

use super::subtree_split::Forest;
use super::{check_system, solve_bordered_in, BorderedSystem, Factorization, FaerLu, LinearSolver};
use crate::solver::sparse::{SparseMatrix, SparsePattern};
use crate::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_unit_lower_triangular_in_place,
    solve_upper_triangular_in_place,
};
use faer::perm::PermRef;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::{amd, SupernodalThreshold};
use faer::sparse::SymbolicSparseColMatRef;
use faer::{Accum, MatMut, MatRef, Par, Side};
use std::sync::Arc;

/// A pivot is refused when `|pivot| <= PIVOT_TOLERANCE * (largest entry of its column of L
/// and row of U)` (or is not finite).
pub const PIVOT_TOLERANCE: f64 = 1e-10;

/// One descendant update of a supernode: supernode `d`'s rows `p1..p2` (positions in its row
/// list) fall into the updated supernode's columns; `relative[rel..rel + rd - p1]` are the
/// local rows, in the updated supernode's L panel, of `d`'s rows `p1..` (the positions its
/// products are subtracted at, the same in every numeric call).
#[derive(Clone, Copy, Debug)]
struct Update {
    d: usize,
    p1: usize,
    p2: usize,
    rel: usize,
}

/// The symbolic analysis of a pattern: ordering, supernodes, panel layout and the slot of
/// every entry of `A`.
#[derive(Debug)]
pub struct SymbolicSymmetricLu {
    pattern: Arc<SparsePattern>,
    n: usize,
    /// New index -> original index.
    perm: Vec<usize>,
    /// First column of each supernode (and `n` at the end).
    begin: Vec<usize>,
    /// Below-diagonal rows of supernode s: `rows[row_ptr[s]..row_ptr[s + 1]]`, sorted.
    row_ptr: Vec<usize>,
    rows: Vec<usize>,
    /// Offset of supernode s's panels in the value array (L panel, then U^T panel).
    offset: Vec<usize>,
    /// Descendant updates of supernode s: `updates[update_ptr[s]..update_ptr[s + 1]]`.
    update_ptr: Vec<usize>,
    updates: Vec<Update>,
    /// The updates' local rows ([`Update`]).
    relative: Vec<u32>,
    /// The entries of `A` that supernode s's panels hold, as (index in `A`'s values,
    /// value index): `gather[gather_ptr[s]..gather_ptr[s + 1]]`. Indices as `u32`: half
    /// the memory traffic of `usize` pairs (the pass is bound by it); checked to fit.
    gather_ptr: Vec<usize>,
    gather: Vec<(u32, u32)>,
    /// Floating-point operations of each supernode's numeric step (its descendant updates,
    /// its diagonal block and its triangular solves): what a partial refactorization saves.
    flops: Vec<f64>,
    /// Their sum: a whole factorization's.
    total_flops: f64,
    len: usize,
    /// Identifies this analysis, so that numeric factors kept for a partial
    /// refactorization are never reused on another one.
    id: u64,
    /// The supernodal elimination tree (a supernode's parent owns its first row below the
    /// diagonal block; `None` if a parent came before its child, which faer's order never
    /// does): disjoint subtrees can be factorized by different threads
    /// ([`NumericSymmetricLu::set_threads`]).
    forest: Option<Forest>,
}

/// The error of an index beyond 32 bits (`what` of a factor of `len` entries).
fn too_large(what: &str, len: usize) -> Error {
    Error::LinearSolver(format!(
        "{what} beyond 32-bit indices (factor of {len} entries): matrix too large"
    ))
}

static NEXT_ANALYSIS_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl SymbolicSymmetricLu {
    /// AMD ordering and supernodal structure of `A + A^T`. O(nnz(L)) time and memory.
    pub fn new(pattern: &Arc<SparsePattern>) -> Result<Self> {
        let n = pattern.n;
        let lower = Self::lower_triangle_of_sum(pattern);
        let (perm, mut begin, row_ptr, rows) = Self::ordered_supernodes(pattern, &lower)?;
        begin.push(n);
        let (col_super, offset, len) = Self::panel_layout(n, &begin, &row_ptr);
        let lists = Self::descendant_updates(&begin, &row_ptr, &rows, &col_super);
        let (update_ptr, updates, relative) =
            Self::update_local_rows(lists, &begin, &row_ptr, &rows, len)?;
        let mut inverse = vec![0; n];
        for (new, &old) in perm.iter().enumerate() {
            inverse[old] = new;
        }
        let mut analysis = SymbolicSymmetricLu {
            pattern: pattern.clone(),
            n,
            perm,
            begin,
            row_ptr,
            rows,
            offset,
            update_ptr,
            updates,
            relative,
            gather_ptr: Vec::new(),
            gather: Vec::new(),
            flops: Vec::new(),
            total_flops: 0.0,
            len,
            id: NEXT_ANALYSIS_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            forest: None,
        };
        analysis.forest = Forest::new(analysis.supernode_parents(&col_super));
        analysis.flops = analysis.supernode_flops();
        analysis.total_flops = analysis.flops.iter().sum();
        let (gather_ptr, gather) = analysis.gather_entries(&inverse, &col_super)?;
        analysis.gather_ptr = gather_ptr;
        analysis.gather = gather;
        Ok(analysis)
    }

    /// The lower triangle of the pattern of `A + A^T`, diagonal included (every diagonal
    /// entry present, even where `A` stores none): the graph the ordering and the symbolic
    /// Cholesky factorization are computed on, whose factor `L` and `U^T` both share.
    fn lower_triangle_of_sum(pattern: &SparsePattern) -> SparsePattern {
        let n = pattern.n;
        SparsePattern::from_entries(
            n,
            (0..n)
                .flat_map(|c| {
                    pattern.row_idx[pattern.col_ptr[c]..pattern.col_ptr[c + 1]]
                        .iter()
                        .map(move |&r| (r.max(c), r.min(c)))
                })
                .chain((0..n).map(|i| (i, i))),
        )
    }

    /// The fill-reducing ordering (AMD on `lower`, or AMD on the graph of the pattern's
    /// elimination groups, [`grouped_order`]) and faer's supernodal symbolic Cholesky
    /// factorization of the permuted `A + A^T`: `(perm, begin, row_ptr, rows)`, `perm` new
    /// index -> original index, then the supernodes' first columns (without the closing
    /// `n`) and their below-diagonal rows ([`Self::supernode_rows`]).
    #[allow(clippy::type_complexity)]
    fn ordered_supernodes(
        pattern: &SparsePattern,
        lower: &SparsePattern,
    ) -> Result<(Vec<usize>, Vec<usize>, Vec<usize>, Vec<usize>)> {
        let n = pattern.n;
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &lower.col_ptr, None, &lower.row_idx);
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let grouped = match &pattern.groups {
            Some(groups) => Some(grouped_order(lower, groups)?),
            None => None,
        };
        let ordering = match &grouped {
            Some((fwd, inv)) => SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, n)),
            None => SymmetricOrdering::Amd,
        };
        let symbolic = factorize_symbolic_cholesky(sym, Side::Lower, ordering, params)
            .map_err(|e| Error::LinearSolver(format!("symbolic analysis failed: {e:?}")))?;
        let perm: Vec<usize> = match symbolic.perm() {
            Some(p) => p.arrays().0.to_vec(),
            None => (0..n).collect(),
        };
        let (begin, row_ptr, rows) = Self::supernode_rows(symbolic.raw(), n);
        Ok((perm, begin, row_ptr, rows))
    }

    /// Supernodes (first column) and their below-diagonal rows, sorted:
    /// `(begin, row_ptr, rows)`, supernode s's rows being `rows[row_ptr[s]..row_ptr[s + 1]]`
    /// (`begin` without the closing `n`). faer may still choose a simplicial structure for
    /// a tiny or very sparse matrix: then every column is a supernode of its own, its rows
    /// those of its column of `L` below the diagonal.
    fn supernode_rows(
        raw: &SymbolicCholeskyRaw<usize>,
        n: usize,
    ) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
        let mut begin = Vec::new();
        let mut row_ptr = vec![0];
        let mut rows = Vec::new();
        match raw {
            SymbolicCholeskyRaw::Supernodal(sn) => {
                for s in 0..sn.n_supernodes() {
                    begin.push(sn.supernode_begin()[s]);
                    let mut r: Vec<usize> = sn.supernode(s).pattern().to_vec();
                    r.sort_unstable();
                    rows.extend_from_slice(&r);
                    row_ptr.push(rows.len());
                }
            }
            SymbolicCholeskyRaw::Simplicial(sc) => {
                for j in 0..n {
                    begin.push(j);
                    let mut r: Vec<usize> = sc.row_idx()[sc.col_ptr()[j]..sc.col_ptr()[j + 1]]
                        .iter()
                        .copied()
                        .filter(|&i| i > j)
                        .collect();
                    r.sort_unstable();
                    rows.extend_from_slice(&r);
                    row_ptr.push(rows.len());
                }
            }
        }
        (begin, row_ptr, rows)
    }

    /// The value array's layout: `(col_super, offset, len)`, the supernode owning each
    /// column, the offset of each supernode's panels (and the total at the end) and the
    /// total. Supernode s of `k` columns and `r` rows below its diagonal block takes
    /// `(k + r) k` values for its L panel (diagonal block and `L_Rs`) then `r k` for its
    /// `U^T` panel.
    fn panel_layout(
        n: usize,
        begin: &[usize],
        row_ptr: &[usize],
    ) -> (Vec<usize>, Vec<usize>, usize) {
        let ns = begin.len() - 1;
        let mut col_super = vec![0; n];
        let mut offset = Vec::with_capacity(ns + 1);
        let mut len = 0;
        for s in 0..ns {
            col_super[begin[s]..begin[s + 1]].fill(s);
            offset.push(len);
            let (k, r) = (begin[s + 1] - begin[s], row_ptr[s + 1] - row_ptr[s]);
            len += (k + r) * k + r * k;
        }
        offset.push(len);
        (col_super, offset, len)
    }

    /// The descendant updates of each supernode, by updated supernode, in increasing order
    /// of descendant: supernode d's sorted rows `R_d` cut into runs that fall into one
    /// supernode's columns; the run `p1..p2` falling into s's columns makes `d` update `s`:
    /// s's L panel loses `L_{R_d[p1..], d} U_{d, R_d[p1..p2]}` and its U^T panel
    /// `U^T_{R_d[p2..], d} L_{R_d[p1..p2], d}^T` (left-looking: these are the only
    /// descendants whose factors reach s's columns). Their local rows (`rel`) are left at 0
    /// ([`Self::update_local_rows`]).
    fn descendant_updates(
        begin: &[usize],
        row_ptr: &[usize],
        rows: &[usize],
        col_super: &[usize],
    ) -> Vec<Vec<Update>> {
        let ns = begin.len() - 1;
        let mut lists: Vec<Vec<Update>> = vec![Vec::new(); ns];
        for d in 0..ns {
            let rd = &rows[row_ptr[d]..row_ptr[d + 1]];
            let mut p1 = 0;
            while p1 < rd.len() {
                let s = col_super[rd[p1]];
                let mut p2 = p1;
                while p2 < rd.len() && rd[p2] < begin[s + 1] {
                    p2 += 1;
                }
                lists[s].push(Update { d, p1, p2, rel: 0 });
                p1 = p2;
            }
        }
        lists
    }

    /// Flattens the updates into `(update_ptr, updates, relative)`, computing once the local
    /// rows the numeric step subtracts each update's products at: for supernode s, a global
    /// row `g` is local row `g - f` in its diagonal block (columns `f..l`) or `l - f + p` if
    /// it is s's `p`-th row below it; `relative` holds them for every descendant row from
    /// `p1` on. Fails when a local row does not fit 32 bits.
    fn update_local_rows(
        lists: Vec<Vec<Update>>,
        begin: &[usize],
        row_ptr: &[usize],
        rows: &[usize],
        len: usize,
    ) -> Result<(Vec<usize>, Vec<Update>, Vec<u32>)> {
        let n = begin[begin.len() - 1];
        let mut update_ptr = vec![0];
        let mut updates = Vec::new();
        let mut relative = Vec::new();
        let mut local = vec![0u32; n];
        for (s, list) in lists.into_iter().enumerate() {
            let (f, l) = (begin[s], begin[s + 1]);
            for g in f..l {
                local[g] = (g - f) as u32;
            }
            for (p, &g) in rows[row_ptr[s]..row_ptr[s + 1]].iter().enumerate() {
                local[g] = u32::try_from(l - f + p).map_err(|_| too_large("a supernode", len))?;
            }
            for mut up in list {
                up.rel = relative.len();
                let rd = &rows[row_ptr[up.d]..row_ptr[up.d + 1]];
                relative.extend(rd[up.p1..].iter().map(|&g| local[g]));
                updates.push(up);
            }
            update_ptr.push(updates.len());
        }
        Ok((update_ptr, updates, relative))
    }

    /// The supernodal elimination tree: a supernode's parent is the supernode owning its
    /// first row below the diagonal block (none for a root).
    fn supernode_parents(&self, col_super: &[usize]) -> Vec<Option<usize>> {
        let ns = self.begin.len() - 1;
        (0..ns)
            .map(|s| {
                let (_, _, _, rows) = self.panels(s);
                rows.first().map(|&g| col_super[g])
            })
            .collect()
    }

    /// Floating-point operations of each supernode's numeric step, `k` columns and `r` rows
    /// below: `2/3 k^3` for the LU of its diagonal block and `2 r k^2` for the two
    /// triangular solves, plus `2 ((rd - p1) + (rd - p2)) nc kd` per descendant update (its
    /// two products, L's over d's rows from `p1` and U^T's from `p2`, each `nc = p2 - p1`
    /// columns of s deep `kd`, d's column count). The cost model of
    /// [`super::subtree_split`]'s bins and of a partial refactorization's saving.
    fn supernode_flops(&self) -> Vec<f64> {
        let ns = self.begin.len() - 1;
        (0..ns)
            .map(|s| {
                let (_, k, r, _) = self.panels(s);
                let (k, r) = (k as f64, r as f64);
                let own = 2.0 / 3.0 * k * k * k + 2.0 * r * k * k;
                let updates = &self.updates[self.update_ptr[s]..self.update_ptr[s + 1]];
                own + updates
                    .iter()
                    .map(|up| {
                        let (_, kd, rd, _) = self.panels(up.d);
                        let nc = (up.p2 - up.p1) as f64;
                        let rows = ((rd - up.p1) + (rd - up.p2)) as f64;
                        2.0 * rows * nc * kd as f64
                    })
                    .sum::<f64>()
            })
            .collect()
    }

    /// The slot in the value array of every entry of `A` (`inverse`: original index -> new
    /// index), grouped by owning supernode (counting sort, stable): `(gather_ptr, gather)`,
    /// so that each supernode's numeric step gathers its own entries only. Fails when an
    /// entry lies outside the factor (an internal error) or an index does not fit 32 bits.
    #[allow(clippy::type_complexity)]
    fn gather_entries(
        &self,
        inverse: &[usize],
        col_super: &[usize],
    ) -> Result<(Vec<usize>, Vec<(u32, u32)>)> {
        let (pattern, n, ns, len) = (&self.pattern, self.n, self.begin.len() - 1, self.len);
        let mut slot = Vec::with_capacity(pattern.nnz());
        let mut entry_super = Vec::with_capacity(pattern.nnz());
        for c in 0..n {
            for &r in &pattern.row_idx[pattern.col_ptr[c]..pattern.col_ptr[c + 1]] {
                let (pi, pj) = (inverse[r], inverse[c]);
                let s = col_super[pi.min(pj)];
                entry_super.push(s);
                slot.push(self.slot_of(s, pi, pj).ok_or_else(|| {
                    Error::LinearSolver(format!(
                        "entry ({r}, {c}) outside the symbolic factor (internal error)"
                    ))
                })?);
            }
        }
        // Counting sort of the entries by supernode.
        let mut gather_ptr = vec![0; ns + 1];
        for &s in &entry_super {
            gather_ptr[s + 1] += 1;
        }
        for s in 0..ns {
            gather_ptr[s + 1] += gather_ptr[s];
        }
        if u32::try_from(len).is_err() || u32::try_from(slot.len()).is_err() {
            return Err(too_large("the factor's entries", len));
        }
        let mut next = gather_ptr.clone();
        let mut gather = vec![(0, 0); slot.len()];
        for (i, (&k, &s)) in slot.iter().zip(&entry_super).enumerate() {
            gather[next[s]] = (i as u32, k as u32);
            next[s] += 1;
        }
        Ok((gather_ptr, gather))
    }

    /// Value index of permuted entry (i, j) in supernode s, which owns column min(i, j).
    fn slot_of(&self, s: usize, i: usize, j: usize) -> Option<usize> {
        let (f, l) = (self.begin[s], self.begin[s + 1]);
        let k = l - f;
        let r = &self.rows[self.row_ptr[s]..self.row_ptr[s + 1]];
        let m = k + r.len();
        let local = |g: usize| {
            if (f..l).contains(&g) {
                Some(g - f)
            } else {
                r.binary_search(&g).ok().map(|p| k + p)
            }
        };
        if i >= j || i >= f && j < l {
            // Lower part, or anywhere in the diagonal block: the L panel.
            Some(self.offset[s] + local(i)? + (j - f) * m)
        } else {
            // Upper part outside the diagonal block: U^T panel, row of j, column i.
            let p = local(j)? - k;
            Some(self.offset[s] + m * k + p + (i - f) * r.len())
        }
    }

    pub fn pattern(&self) -> &Arc<SparsePattern> {
        &self.pattern
    }

    /// Stored entries of L and U together (dense panels, explicit zeros included).
    pub fn factor_len(&self) -> usize {
        self.len
    }

    fn panels(&self, s: usize) -> (usize, usize, usize, &[usize]) {
        let (f, l) = (self.begin[s], self.begin[s + 1]);
        let r = &self.rows[self.row_ptr[s]..self.row_ptr[s + 1]];
        (f, l - f, r.len(), r)
    }
}

/// AMD on the graph of the groups (a vertex per group, an edge where any two members are
/// coupled), each group expanded in index order: `(new -> old, old -> new)`. `lower` is
/// the lower triangle of `A + A^T` (or any pattern with its structure). Same cost as
/// AMD on the unknowns, on a graph smaller by the group size.
pub fn grouped_order(lower: &SparsePattern, groups: &[usize]) -> Result<(Vec<usize>, Vec<usize>)> {
    let n = lower.n;
    if groups.len() != n {
        return Err(Error::LinearSolver(format!(
            "{} elimination groups for {n} unknowns",
            groups.len()
        )));
    }
    // Group ids to 0..ng.
    let mut id = std::collections::HashMap::new();
    let compact: Vec<usize> = groups
        .iter()
        .map(|g| {
            let next = id.len();
            *id.entry(*g).or_insert(next)
        })
        .collect();
    let ng = id.len();
    let graph = SparsePattern::from_entries(
        ng,
        (0..n).flat_map(|c| {
            let compact = &compact;
            lower.row_idx[lower.col_ptr[c]..lower.col_ptr[c + 1]]
                .iter()
                .flat_map(move |&r| [(compact[r], compact[c]), (compact[c], compact[r])])
        }),
    );
    let (mut fwd, mut inv) = (vec![0usize; ng], vec![0usize; ng]);
    let mut buffer = MemBuffer::try_new(amd::order_scratch::<usize>(ng, graph.nnz()))
        .map_err(|e| Error::LinearSolver(format!("ordering workspace: {e:?}")))?;
    let g = SymbolicSparseColMatRef::new_checked(ng, ng, &graph.col_ptr, None, &graph.row_idx);
    amd::order(
        &mut fwd,
        &mut inv,
        g,
        Default::default(),
        MemStack::new(&mut buffer),
    )
    .map_err(|e| Error::LinearSolver(format!("ordering failed: {e:?}")))?;
    // Members of each group, ascending (counting sort by group).
    let mut start = vec![0usize; ng + 1];
    for &g in &compact {
        start[g + 1] += 1;
    }
    for g in 0..ng {
        start[g + 1] += start[g];
    }
    let mut members = vec![0usize; n];
    let mut fill = start.clone();
    for (d, &g) in compact.iter().enumerate() {
        members[fill[g]] = d;
        fill[g] += 1;
    }
    let perm: Vec<usize> = fwd
        .iter()
        .flat_map(|&g| members[start[g]..start[g + 1]].iter().copied())
        .collect();
    let mut inverse = vec![0usize; n];
    for (new, &old) in perm.iter().enumerate() {
        inverse[old] = new;
    }
    Ok((perm, inverse))
}

/// Why a numeric factorization without pivoting stopped.
#[derive(Debug)]
pub struct PivotFailure {
    /// Permuted column whose pivot was refused.
    pub column: usize,
    pub pivot: f64,
    pub column_max: f64,
}

/// The numeric factors on a [`SymbolicSymmetricLu`] structure, with their workspace (kept
/// between calls: a Newton iteration allocates nothing).
#[derive(Default)]
pub struct NumericSymmetricLu {
    values: Vec<f64>,
    /// One per thread of the factorization.
    scratch: Vec<Scratch>,
    /// The solves' permuted right-hand sides.
    work: Vec<f64>,
    /// The values of `A` that `values` are the complete factors of, and the analysis they
    /// were computed on: a later call recomputes only what differs ([`Self::factorize`]).
    factored: Vec<f64>,
    factored_on: Option<u64>,
    dirty: Vec<bool>,
    /// Threads of the numeric factorization (0 or 1: this one).
    threads: usize,
    /// Work of all calls and of the supernodes they recomputed (flops).
    pub flops_total: f64,
    pub flops_done: f64,
    /// Calls that ran on several threads.
    pub split_calls: usize,
}

/// What one thread of the factorization writes besides the factors.
#[derive(Default)]
struct Scratch {
    /// A descendant's update.
    product: Vec<f64>,
    /// The pivot test's scale per column of the supernode.
    column_max: Vec<f64>,
}

/// A factorization recomputing fewer flops than this runs on one thread, whatever
/// [`NumericSymmetricLu::set_threads`] says: starting a thread costs about as much as
/// 10^5-10^6 flops of the dense kernels (tens of microseconds).
pub const PARALLEL_MIN_FLOPS: f64 = 5e6;

impl NumericSymmetricLu {
    /// Threads of the numeric factorization (module docs, "Threads"); the factors are the
    /// same bit for bit whatever their number.
    pub fn set_threads(&mut self, threads: usize) {
        self.threads = threads;
    }

    /// Factorizes the matrix with values `a` on the analysed pattern.
    ///
    /// When the factors of the previous call are complete and on the same analysis, only
    /// the supernodes that differ are recomputed: those owning an entry of `a` that
    /// changed (bit for bit), and every supernode updated by a recomputed one (its
    /// ancestors in the elimination tree). The others' panels depend on unchanged entries
    /// only, so the factors are the ones a full factorization gives, bit for bit. A
    /// re-solve that changes the rows of a few contact nodes (status prediction,
    /// [`crate::solver::newton::status_prediction`]) then pays for their paths to the root only.
    pub fn factorize(
        &mut self,
        symbolic: &SymbolicSymmetricLu,
        a: &[f64],
    ) -> std::result::Result<(), PivotFailure> {
        let sy = symbolic;
        let ns = sy.begin.len() - 1;
        let partial = self.factored_on == Some(sy.id) && self.factored.len() == a.len();
        self.factored_on = None;
        self.dirty.clear();
        self.dirty.resize(ns, !partial);
        if partial {
            // A supernode is dirty at its first changed entry: after a Newton step's new
            // Jacobian that is each one's first, and only a re-solve's unchanged supernodes
            // are read through. A failure below leaves `factored_on` unset, so the next
            // call is whole anyway.
            for s in 0..ns {
                let entries = &sy.gather[sy.gather_ptr[s]..sy.gather_ptr[s + 1]];
                let factored = &self.factored;
                self.dirty[s] = entries
                    .iter()
                    .any(|&(i, _)| a[i as usize].to_bits() != factored[i as usize].to_bits());
            }
            self.factored.copy_from_slice(a);
            for s in 0..ns {
                if !self.dirty[s] {
                    let updates = &sy.updates[sy.update_ptr[s]..sy.update_ptr[s + 1]];
                    self.dirty[s] = updates.iter().any(|up| self.dirty[up.d]);
                }
            }
        } else {
            self.factored.clear();
            self.factored.extend_from_slice(a);
        }
        // Each recomputed supernode zeroes and gathers its own panels when it is computed
        // (`factor_supernode`), while they are about to be used: the others keep theirs.
        self.values.resize(sy.len, 0.0);
        self.flops_total += sy.total_flops;
        let mut recomputed = 0.0;
        for s in (0..ns).filter(|&s| self.dirty[s]) {
            recomputed += sy.flops[s];
        }
        self.flops_done += recomputed;
        let threads = self.threads.max(1);
        self.scratch.resize_with(threads, Scratch::default);
        let split = match &sy.forest {
            Some(forest) if threads > 1 && recomputed >= PARALLEL_MIN_FLOPS => {
                let work: Vec<f64> = (0..ns)
                    .map(|s| if self.dirty[s] { sy.flops[s] } else { 0.0 })
                    .collect();
                forest.split(&work, threads)
            }
            _ => None,
        };
        let dirty = &self.dirty;
        let mut in_subtree = vec![false; ns];
        if let Some(bins) = &split {
            self.split_calls += 1;
            // Each subtree's panels are one contiguous range of the value array:
            // cut it into one slice per subtree, and compute the bins at once.
            let mut ranges: Vec<(usize, usize, usize)> = bins
                .iter()
                .enumerate()
                .flat_map(|(b, r)| r.iter().map(move |&(first, root)| (first, root, b)))
                .collect();
            ranges.sort_unstable();
            let mut per_bin: Vec<Vec<(usize, usize, &mut [f64])>> =
                (0..threads).map(|_| Vec::new()).collect();
            let mut rest: &mut [f64] = &mut self.values;
            let mut cut = 0;
            for &(first, root, b) in &ranges {
                in_subtree[first..=root].fill(true);
                let (start, end) = (sy.offset[first], sy.offset[root + 1]);
                let (_, tail) = std::mem::take(&mut rest).split_at_mut(start - cut);
                let (piece, tail) = tail.split_at_mut(end - start);
                rest = tail;
                cut = end;
                per_bin[b].push((first, root, piece));
            }
            let run = |pieces: Vec<(usize, usize, &mut [f64])>, scratch: &mut Scratch| {
                for (first, root, piece) in pieces {
                    let base = sy.offset[first];
                    for s in (first..=root).filter(|&s| dirty[s]) {
                        factor_supernode(sy, s, a, piece, base, scratch)?;
                    }
                }
                Ok(())
            };
            let mut pieces = per_bin.into_iter();
            let own = pieces.next().expect("threads >= 2");
            let (first_scratch, others) = self.scratch.split_at_mut(1);
            let results: Vec<std::result::Result<(), PivotFailure>> = std::thread::scope(|scope| {
                let handles: Vec<_> = pieces
                    .zip(others.iter_mut())
                    .map(|(bin, scratch)| scope.spawn(move || run(bin, scratch)))
                    .collect();
                let mut results = vec![run(own, &mut first_scratch[0])];
                results.extend(
                    handles
                        .into_iter()
                        .map(|h| h.join().expect("a factorization thread panicked")),
                );
                results
            });
            // The refused pivot of least column, whichever thread met it.
            if let Some(failure) = results
                .into_iter()
                .filter_map(|r| r.err())
                .min_by_key(|f| f.column)
            {
                return Err(failure);
            }
        }
        for s in 0..ns {
            if dirty[s] && !in_subtree[s] {
                factor_supernode(sy, s, a, &mut self.values, 0, &mut self.scratch[0])?;
            }
        }
        self.factored_on = Some(sy.id);
        Ok(())
    }

    /// Solves `A X = B` in place for `nrhs` right-hand sides stored column after column.
    /// O(nnz(L + U) nrhs).
    pub fn solve_in_place(&mut self, symbolic: &SymbolicSymmetricLu, b: &mut [f64], nrhs: usize) {
        let sy = symbolic;
        let n = sy.n;
        self.work.clear();
        self.work.resize(n * nrhs, 0.0);
        let x = &mut self.work;
        for c in 0..nrhs {
            for (new, &old) in sy.perm.iter().enumerate() {
                x[c * n + new] = b[c * n + old];
            }
        }
        let ns = sy.begin.len() - 1;
        // Each column's operations are those of a solve of it alone, in the same order;
        // two columns at a time share each pass over the factor's panels (the bordered
        // solve's second column, `crate::solver::linear::BorderedSystem`).
        // L y = P b.
        for s in 0..ns {
            let (f, k, r, rows) = sy.panels(s);
            let m = k + r;
            let panel =
                MatRef::from_column_major_slice(&self.values[sy.offset[s]..][..m * k], m, k);
            let diagonal = panel.subrows(0, k);
            for c in 0..nrhs {
                let block = MatMut::from_column_major_slice_mut(&mut x[c * n + f..][..k], k, 1);
                solve_unit_lower_triangular_in_place(diagonal, block, Par::Seq);
            }
            for j in 0..k {
                let col = &self.values[sy.offset[s] + j * m + k..][..r];
                let mut columns = x.chunks_exact_mut(n);
                while let Some(x0) = columns.next() {
                    let v0 = x0[f + j];
                    match columns.next() {
                        Some(x1) if v0 != 0.0 && x1[f + j] != 0.0 => {
                            let v1 = x1[f + j];
                            for (l, &g) in col.iter().zip(rows) {
                                x0[g] -= l * v0;
                                x1[g] -= l * v1;
                            }
                        }
                        x1 => {
                            for xc in std::iter::once(x0).chain(x1) {
                                let v = xc[f + j];
                                if v != 0.0 {
                                    for (l, &g) in col.iter().zip(rows) {
                                        xc[g] -= l * v;
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        // U x = y.
        for s in (0..ns).rev() {
            let (f, k, r, rows) = sy.panels(s);
            let m = k + r;
            let panel =
                MatRef::from_column_major_slice(&self.values[sy.offset[s]..][..m * k], m, k);
            let diagonal = panel.subrows(0, k);
            for j in 0..k {
                let col = &self.values[sy.offset[s] + m * k + j * r..][..r];
                let mut columns = x.chunks_exact_mut(n);
                while let Some(x0) = columns.next() {
                    match columns.next() {
                        Some(x1) => {
                            // `Sum` of f64 starts from -0.0: so do these.
                            let (mut dot0, mut dot1) = (-0.0, -0.0);
                            for (u, &g) in col.iter().zip(rows) {
                                dot0 += u * x0[g];
                                dot1 += u * x1[g];
                            }
                            x0[f + j] -= dot0;
                            x1[f + j] -= dot1;
                        }
                        None => {
                            let dot: f64 = col.iter().zip(rows).map(|(u, &g)| u * x0[g]).sum();
                            x0[f + j] -= dot;
                        }
                    }
                }
            }
            for c in 0..nrhs {
                let block = MatMut::from_column_major_slice_mut(&mut x[c * n + f..][..k], k, 1);
                solve_upper_triangular_in_place(diagonal, block, Par::Seq);
            }
        }
        for c in 0..nrhs {
            for (new, &old) in sy.perm.iter().enumerate() {
                b[c * n + old] = x[c * n + new];
            }
        }
    }
}

/// Computes supernode `s`'s panels (module docs, "numeric") in `values`, the value array
/// from index `base` on, which holds `s`'s panels and those of its descendants: gathers
/// its entries of `a` (the values of `A`) into zeroed panels and its descendants'
/// updates, factorizes the diagonal block without pivoting (refusing a pivot below
/// [`PIVOT_TOLERANCE`] of its column of L and row of U) and solves for the off-diagonal
/// panels. The same operations in the same order wherever it runs, so the factors do not
/// depend on the threads.
fn factor_supernode(
    sy: &SymbolicSymmetricLu,
    s: usize,
    a: &[f64],
    values: &mut [f64],
    base: usize,
    scratch: &mut Scratch,
) -> std::result::Result<(), PivotFailure> {
    let (f, k, r, _) = sy.panels(s);
    let m = k + r;
    values[sy.offset[s] - base..sy.offset[s + 1] - base].fill(0.0);
    for &(i, slot) in &sy.gather[sy.gather_ptr[s]..sy.gather_ptr[s + 1]] {
        values[slot as usize - base] = a[i as usize];
    }
    let (done, rest) = values.split_at_mut(sy.offset[s] - base);
    let (l_panel, rest) = rest.split_at_mut(m * k);
    let u_panel = &mut rest[..r * k];
    for up in &sy.updates[sy.update_ptr[s]..sy.update_ptr[s + 1]] {
        let (_, kd, rd, _) = sy.panels(up.d);
        let md = kd + rd;
        let at = sy.offset[up.d] - base;
        let ld = MatRef::from_column_major_slice(&done[at..at + md * kd], md, kd);
        let ud = MatRef::from_column_major_slice(&done[at + md * kd..][..rd * kd], rd, kd);
        let (nr, nc) = (rd - up.p1, up.p2 - up.p1);
        // Local rows of d's rows p1..: the first nc are s's columns.
        let local = &sy.relative[up.rel..up.rel + nr];
        // L: rows p1.. of d times U's columns p1..p2.
        let l_rows = ld.subrows(kd + up.p1, nr);
        let u_cols = ud.subrows(up.p1, nc);
        dense_product(&mut scratch.product, l_rows, u_cols, nr, nc);
        for (c, &col) in local[..nc].iter().enumerate() {
            let col = col as usize;
            let target = &mut l_panel[col * m..(col + 1) * m];
            let product = &scratch.product[c * nr..(c + 1) * nr];
            for (&row, &p) in local.iter().zip(product) {
                target[row as usize] -= p;
            }
        }
        // U^T: rows p2.. of d's U^T panel times L's rows p1..p2.
        let nu = rd - up.p2;
        if nu > 0 {
            let u_rows = ud.subrows(up.p2, nu);
            let l_cols = ld.subrows(kd + up.p1, nc);
            dense_product(&mut scratch.product, u_rows, l_cols, nu, nc);
            for (c, &col) in local[..nc].iter().enumerate() {
                let col = col as usize;
                let target = &mut u_panel[col * r..(col + 1) * r];
                let product = &scratch.product[c * nu..(c + 1) * nu];
                for (&row, &p) in local[nc..].iter().zip(product) {
                    target[row as usize - k] -= p;
                }
            }
        }
    }
    // The pivot test's scale: the largest entry of the column of L and row of U.
    scratch.column_max.clear();
    for j in 0..k {
        // Column j of L from the diagonal down, row j of U right of the diagonal.
        let row = (j + 1..k).map(|c| l_panel[c * m + j]);
        let max = largest_magnitude(&l_panel[j * m + j..(j + 1) * m])
            .max(largest_magnitude(&u_panel[j * r..(j + 1) * r]));
        scratch
            .column_max
            .push(row.fold(max, |a, v| a.max(v.abs())));
    }
    let mut panel = MatMut::from_column_major_slice_mut(l_panel, m, k);
    let (mut diagonal, _, mut below, _) = panel.rb_mut().split_at_mut(k, k);
    lu_no_pivoting(diagonal.rb_mut());
    for j in 0..k {
        let pivot = diagonal[(j, j)];
        if !(pivot.is_finite() && pivot.abs() > PIVOT_TOLERANCE * scratch.column_max[j]) {
            return Err(PivotFailure {
                column: f + j,
                pivot,
                column_max: scratch.column_max[j],
            });
        }
    }
    if r > 0 {
        // L_Rs U_ss = A_Rs  <=>  U_ss^T L_Rs^T = A_Rs^T.
        solve_lower_triangular_in_place(
            diagonal.rb().transpose(),
            below.rb_mut().transpose_mut(),
            Par::Seq,
        );
        // L_ss U_sR = A_sR, with U_sR^T stored.
        let mut ut = MatMut::from_column_major_slice_mut(u_panel, r, k);
        solve_unit_lower_triangular_in_place(diagonal.rb(), ut.rb_mut().transpose_mut(), Par::Seq);
    }
    Ok(())
}

/// The largest `|v|` of `values` (0 for none), NaN entries passed over as `f64::max` does.
/// Four running maxima, so that the loop is not one chain of dependent comparisons: the
/// maximum does not depend on the order.
fn largest_magnitude(values: &[f64]) -> f64 {
    let mut lanes = [0.0f64; 4];
    let mut chunks = values.chunks_exact(4);
    for chunk in &mut chunks {
        for (lane, v) in lanes.iter_mut().zip(chunk) {
            *lane = lane.max(v.abs());
        }
    }
    let tail = chunks
        .remainder()
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()));
    lanes.iter().fold(tail, |a, &v| a.max(v))
}

/// `out (rows x cols, column-major) = a b^T` for `a` (rows x k) and `b` (cols x k). Small
/// products by plain loops (faer's dispatch costs more than a few hundred flops).
fn dense_product(
    out: &mut Vec<f64>,
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
    rows: usize,
    cols: usize,
) {
    if out.len() < rows * cols {
        out.resize(rows * cols, 0.0);
    }
    let out = &mut out[..rows * cols];
    let k = a.ncols();
    if rows * cols * k <= 512 {
        out.fill(0.0);
        for c in 0..cols {
            for p in 0..k {
                let w = b[(c, p)];
                if w != 0.0 {
                    let column = a.col(p);
                    for i in 0..rows {
                        out[i + c * rows] += column[i] * w;
                    }
                }
            }
        }
    } else {
        // Replace does not read what `out` held.
        let dst = MatMut::from_column_major_slice_mut(out, rows, cols);
        matmul(dst, Accum::Replace, a, b.transpose(), 1.0, Par::Seq);
    }
}

/// In-place LU without pivoting of a dense square block: unit lower L below the diagonal,
/// U on and above. Recursive halving, so that the bulk of the flops is in faer's matmul and
/// triangular solves. O(k^3) flops.
fn lu_no_pivoting(mut a: MatMut<'_, f64>) {
    let n = a.nrows();
    if n <= 16 {
        for j in 0..n {
            let pivot = a[(j, j)];
            for i in j + 1..n {
                a[(i, j)] /= pivot;
            }
            for c in j + 1..n {
                let u = a[(j, c)];
                if u != 0.0 {
                    for i in j + 1..n {
                        let l = a[(i, j)];
                        a[(i, c)] -= l * u;
                    }
                }
            }
        }
        return;
    }
    let h = n / 2;
    let (mut a11, mut a12, mut a21, mut a22) = a.split_at_mut(h, h);
    lu_no_pivoting(a11.rb_mut());
    solve_unit_lower_triangular_in_place(a11.rb(), a12.rb_mut(), Par::Seq);
    solve_lower_triangular_in_place(a11.rb().transpose(), a21.rb_mut().transpose_mut(), Par::Seq);
    matmul(a22.rb_mut(), Accum::Add, a21.rb(), a12.rb(), -1.0, Par::Seq);
    lu_no_pivoting(a22);
}

// The solver behind `LinearSolver`: the factors above with their checks and fallback.

/// Backward error above which a solution without pivoting is refined once, and after the
/// refinement handed to the pivoting LU: `|b - A x|_inf / (|A|_inf |x|_inf + |b|_inf)`.
/// A stable factorization gives about n eps = 1e-16..1e-11 in the worst case bound, far
/// less in practice; a bad pivot order gives orders of magnitude more.
pub const BACKWARD_ERROR_TOLERANCE: f64 = 1e-12;

/// Sparse LU without pivoting on the symmetric structure of `A + A^T` (AMD order,
/// supernodal; see [`crate::solver::linear::symmetric_lu`]), for structurally symmetric systems with safe
/// diagonal pivots like the condensed contact system. Every pivot is checked, and every
/// solution's backward error (one step of iterative refinement allowed); when either fails,
/// that call is solved by faer's pivoting LU instead, so robustness is the pivoting LU's.
#[derive(Default)]
pub struct SymmetricLu {
    symbolic: Option<SymbolicSymmetricLu>,
    numeric: NumericSymmetricLu,
    fallback: FaerLu,
    border: Option<Box<BorderedSystem<SymmetricLu>>>,
    /// Number of symbolic analyses done (a pattern change triggers a new one).
    pub symbolic_count: usize,
    /// Calls solved by the pivoting LU because a pivot or the backward error failed.
    pub fallback_count: usize,
    /// Consecutive failures; after [`GIVE_UP_AFTER`] of them the next [`SKIP_CALLS`] calls
    /// go straight to the pivoting LU (a system without safe pivots, such as the mixed
    /// system with every multiplier kept, then costs one factorization per call, not two).
    failures_in_a_row: usize,
    skip: usize,
    /// Refused systems fail instead of going to the pivoting LU
    /// ([`LinearSolver::set_pivoting_fallback`]).
    no_fallback: bool,
    /// Threads of the numeric factorization ([`LinearSolver::set_threads`]).
    threads: usize,
    /// The backward-error check's `A X` (every column), `A x` and `b - A x` (the column
    /// checked) and row sums of `|A|`, kept between calls.
    products: Vec<f64>,
    product: Vec<f64>,
    residual: Vec<f64>,
    row_sums: Vec<f64>,
}

/// See [`SymmetricLu::failures_in_a_row`].
const GIVE_UP_AFTER: usize = 3;
const SKIP_CALLS: usize = 50;

impl SymmetricLu {
    /// Stored entries of L and U (dense supernodal panels) of the last analysis.
    pub fn factor_len(&self) -> Option<usize> {
        self.symbolic.as_ref().map(|s| s.factor_len())
    }

    /// Factorizes and solves without pivoting; `Ok(false)` when a pivot or the backward
    /// error is refused (then `rhs` is garbage).
    fn try_without_pivoting(
        &mut self,
        a: &SparseMatrix,
        rhs: &mut [f64],
        nrhs: usize,
        original: &[f64],
    ) -> Result<bool> {
        let p = &a.pattern;
        let reuse = matches!(&self.symbolic, Some(s) if Arc::ptr_eq(s.pattern(), p) || **s.pattern() == **p);
        if !reuse {
            self.symbolic = Some(SymbolicSymmetricLu::new(p)?);
            self.symbolic_count += 1;
        }
        let symbolic = self.symbolic.as_ref().expect("set above");
        self.numeric.set_threads(self.threads);
        if self.numeric.factorize(symbolic, &a.values).is_err() {
            return Ok(false);
        }
        self.numeric.solve_in_place(symbolic, rhs, nrhs);
        let n = p.n;
        // A X for every column and |A|_inf (from the row sums) in one pass over A.
        a.mul_columns_and_row_abs_sums(rhs, nrhs, &mut self.products, &mut self.row_sums);
        let norm_a = self.row_sums.iter().copied().fold(0.0, f64::max);
        for c in 0..nrhs {
            let (x, b) = (&mut rhs[c * n..(c + 1) * n], &original[c * n..(c + 1) * n]);
            self.product.clear();
            self.product
                .extend_from_slice(&self.products[c * n..(c + 1) * n]);
            let mut refined = false;
            loop {
                let r = &mut self.residual;
                r.clear();
                r.extend(b.iter().zip(&self.product).map(|(b, y)| b - y));
                let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let scale = norm_a * inf(x) + inf(b);
                let error = inf(r);
                if !(error.is_finite() && scale.is_finite()) {
                    return Ok(false);
                }
                if error <= BACKWARD_ERROR_TOLERANCE * scale {
                    break;
                }
                if refined {
                    return Ok(false);
                }
                self.numeric.solve_in_place(symbolic, r, 1);
                x.iter_mut().zip(r.iter()).for_each(|(x, d)| *x += d);
                refined = true;
                a.mul_vec_into(x, &mut self.product);
            }
        }
        Ok(true)
    }
}

impl Factorization for SymmetricLu {
    fn symbolic_count(&self) -> usize {
        self.symbolic_count + self.fallback.symbolic_count
    }

    fn factor_and_solve(&mut self, a: &SparseMatrix, rhs: &mut [f64], nrhs: usize) -> Result<()> {
        check_system(a, rhs, nrhs)?;
        let original = rhs.to_vec();
        if self.no_fallback {
            return match self.try_without_pivoting(a, rhs, nrhs, &original)? {
                true => Ok(()),
                false => Err(Error::LinearSolver(
                    "a pivot or the backward error was refused (no pivoting fallback)".into(),
                )),
            };
        }
        if self.skip > 0 {
            self.skip -= 1;
        } else if self.try_without_pivoting(a, rhs, nrhs, &original)? {
            self.failures_in_a_row = 0;
            return Ok(());
        } else {
            self.failures_in_a_row += 1;
            if self.failures_in_a_row >= GIVE_UP_AFTER {
                self.failures_in_a_row = 0;
                self.skip = SKIP_CALLS;
            }
        }
        self.fallback_count += 1;
        rhs.copy_from_slice(&original);
        self.fallback.factor_and_solve(a, rhs, nrhs)
    }
}

impl LinearSolver for SymmetricLu {
    fn solve_bordered(&mut self, a: &SparseMatrix, b: &mut [f64], border: &[usize]) -> Result<()> {
        if border.is_empty() {
            return self.factor_and_solve(a, b, 1);
        }
        let (no_fallback, threads) = (self.no_fallback, self.threads);
        self.symbolic_count += solve_bordered_in(&mut self.border, a, b, border, |inner| {
            inner.no_fallback = no_fallback;
            inner.threads = threads;
        })?;
        Ok(())
    }

    fn symbolic_analyses(&self) -> usize {
        Factorization::symbolic_count(self)
    }

    fn set_pivoting_fallback(&mut self, allowed: bool) {
        self.no_fallback = !allowed;
    }

    fn set_threads(&mut self, threads: usize) {
        self.threads = threads;
    }

    fn split_factorizations(&self) -> usize {
        self.numeric.split_calls
            + self
                .border
                .as_ref()
                .map_or(0, |b| b.inner.split_factorizations())
    }
}

#[cfg(test)]
mod tests {
    use super::{NumericSymmetricLu, SymbolicSymmetricLu};
    use crate::solver::linear::{FaerLu, LinearSolver, SymmetricLu};
    use crate::solver::sparse::{SparseMatrix, SparsePattern};
    use std::sync::Arc;

    /// A small deterministic generator (no test depends on a crate's random stream).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64) / ((1u64 << 53) as f64)
        }
    }

    /// A random structurally symmetric pattern (a 3D-grid-like graph plus random couplings)
    /// with unsymmetric values and a dominant diagonal.
    fn random_matrix(n: usize, seed: u64) -> SparseMatrix {
        let mut rng = Lcg(seed);
        let mut entries = Vec::new();
        for i in 0..n {
            entries.push((i, i));
            for d in [1, 7, 29] {
                if i + d < n && rng.next() < 0.8 {
                    entries.push((i, i + d));
                    entries.push((i + d, i));
                }
            }
            let j = (rng.next() * n as f64) as usize % n;
            entries.push((i, j));
            entries.push((j, i));
        }
        let p = Arc::new(SparsePattern::from_entries(n, entries));
        let mut a = SparseMatrix::zeros(p.clone());
        for v in a.values.iter_mut() {
            *v = rng.next() * 2.0 - 1.0;
        }
        let sums = a.row_abs_sums();
        for i in 0..n {
            let k = p.position(i, i).unwrap();
            a.values[k] = sums[i] + 1.0;
        }
        a
    }

    fn dense_solve(a: &SparseMatrix, b: &[f64]) -> Vec<f64> {
        let n = a.pattern.n;
        let mut m = nalgebra::DMatrix::<f64>::zeros(n, n);
        for c in 0..n {
            for k in a.pattern.col_ptr[c]..a.pattern.col_ptr[c + 1] {
                m[(a.pattern.row_idx[k], c)] = a.values[k];
            }
        }
        m.lu()
            .solve(&nalgebra::DVector::from_column_slice(b))
            .unwrap()
            .as_slice()
            .to_vec()
    }

    #[test]
    fn equals_a_dense_solve_on_random_diagonally_dominant_matrices() {
        for (n, seed) in [(1, 1), (5, 2), (60, 3), (300, 4), (900, 5)] {
            let a = random_matrix(n, seed);
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.5).collect();
            let b = a.mul_vec(&x);
            let mut solver = SymmetricLu::default();
            let mut y = b.clone();
            solver.solve(&a, &mut y).unwrap();
            let reference = dense_solve(&a, &b);
            // Diagonally dominant, condition number O(10): errors are round-off, ~1e-15.
            for i in 0..n {
                assert!((y[i] - reference[i]).abs() < 1e-12, "n {n}, unknown {i}");
                assert!((y[i] - x[i]).abs() < 1e-12, "n {n}, unknown {i}");
            }
            assert_eq!(solver.fallback_count, 0, "no pivot is small here");
            assert!(solver.factor_len().unwrap() >= a.pattern.nnz());
            // The same pattern with other values reuses the analysis.
            let mut a2 = a.clone();
            a2.values.iter_mut().for_each(|v| *v *= 1.5);
            let mut y2 = a2.mul_vec(&x);
            solver.solve(&a2, &mut y2).unwrap();
            assert_eq!(solver.symbolic_count, 1);
            for i in 0..n {
                assert!((y2[i] - x[i]).abs() < 1e-12);
            }
        }
    }

    /// A refactorization after a change of a few entries recomputes only their supernodes'
    /// paths to the root, and its factors are those of a fresh factorization, bit for bit.
    #[test]
    fn a_partial_refactorization_equals_a_fresh_one_bit_for_bit() {
        let n = 900;
        let a = random_matrix(n, 11);
        let symbolic = SymbolicSymmetricLu::new(&a.pattern).unwrap();
        let mut kept = NumericSymmetricLu::default();
        kept.factorize(&symbolic, &a.values).unwrap();
        let whole = kept.flops_done;
        assert_eq!(kept.flops_total, whole);
        let mut rng = Lcg(12);
        let mut changed = a.clone();
        for (round, rows) in [1usize, 5, 40].into_iter().enumerate() {
            // New values in a few rows (a re-solve changes the rows of a few nodes), and
            // once, between two calls, nothing at all.
            for _ in 0..rows {
                let r = (rng.next() * n as f64) as usize % n;
                for c in 0..n {
                    if let Some(k) = changed.pattern.position(r, c) {
                        changed.values[k] *= 1.0 + 0.1 * rng.next();
                    }
                }
            }
            let before = kept.flops_done;
            kept.factorize(&symbolic, &changed.values).unwrap();
            let done = kept.flops_done - before;
            let mut fresh = NumericSymmetricLu::default();
            fresh.factorize(&symbolic, &changed.values).unwrap();
            assert_eq!(kept.values.len(), fresh.values.len());
            for (k, (u, v)) in kept.values.iter().zip(&fresh.values).enumerate() {
                assert_eq!(u.to_bits(), v.to_bits(), "round {round}, factor entry {k}");
            }
            assert!(
                done > 0.0 && done < whole,
                "round {round}: {done} of {whole} flops"
            );
            let mut x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin()).collect();
            let mut y = x.clone();
            kept.solve_in_place(&symbolic, &mut x, 1);
            fresh.solve_in_place(&symbolic, &mut y, 1);
            assert!(x.iter().zip(&y).all(|(u, v)| u.to_bits() == v.to_bits()));
        }
        let before = kept.flops_done;
        kept.factorize(&symbolic, &changed.values).unwrap();
        assert_eq!(kept.flops_done, before, "same values: nothing to recompute");
    }

    /// Several right-hand sides solved at once (two share each pass over the factor) give
    /// each column's lone solve bit for bit, also where a column's entry is zero at a
    /// supernode's column (that column skips the update alone) and for an odd count.
    #[test]
    fn columns_solved_together_equal_each_solved_alone_bit_for_bit() {
        let n = 3000;
        let a = random_matrix(n, 17);
        let sy = SymbolicSymmetricLu::new(&a.pattern).unwrap();
        let mut lu = NumericSymmetricLu::default();
        lu.factorize(&sy, &a.values).unwrap();
        let columns: Vec<Vec<f64>> = (0..3)
            .map(|c| {
                (0..n)
                    .map(|i| match c {
                        // Sparse: zero at most unknowns, so most updates skip it.
                        1 if i % 7 != 0 => 0.0,
                        _ => ((i * (c + 2)) as f64 * 0.37).sin(),
                    })
                    .collect()
            })
            .collect();
        let alone: Vec<Vec<f64>> = columns
            .iter()
            .map(|b| {
                let mut x = b.clone();
                lu.solve_in_place(&sy, &mut x, 1);
                x
            })
            .collect();
        for count in [2, 3] {
            let mut together: Vec<f64> = columns[..count].concat();
            lu.solve_in_place(&sy, &mut together, count);
            for (c, x) in together.chunks(n).enumerate() {
                let same = x
                    .iter()
                    .zip(&alone[c])
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "column {c} of {count} differs from its lone solve");
            }
        }
    }

    /// The factorization on 2, 3 and 4 threads (disjoint subtrees at once, the top after
    /// them) gives the sequential factors bit for bit, whole and partial, and so the same
    /// solutions; a matrix large enough that the split runs (its recomputed flops above
    /// `PARALLEL_MIN_FLOPS`), and one change of a few rows for the partial call.
    #[test]
    fn threads_give_the_sequential_factors_bit_for_bit() {
        let a = random_matrix(6000, 41);
        let sy = SymbolicSymmetricLu::new(&a.pattern).unwrap();
        assert!(
            sy.forest.is_some(),
            "faer's supernodes come after their children"
        );
        let mut changed = a.clone();
        for (k, v) in changed.values.iter_mut().enumerate() {
            let r = changed.pattern.row_idx[k];
            if r % 997 == 3 {
                *v *= 1.25;
            }
        }
        let mut sequential = NumericSymmetricLu::default();
        sequential.factorize(&sy, &a.values).unwrap();
        assert!(
            sequential.flops_done >= super::PARALLEL_MIN_FLOPS,
            "{}",
            sequential.flops_done
        );
        let whole = sequential.values.clone();
        sequential.factorize(&sy, &changed.values).unwrap();
        let partial = sequential.values.clone();
        let b: Vec<f64> = (0..6000).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x_seq = b.clone();
        sequential.solve_in_place(&sy, &mut x_seq, 1);
        for threads in [2, 3, 4] {
            let mut parallel = NumericSymmetricLu::default();
            parallel.set_threads(threads);
            let split = sy
                .forest
                .as_ref()
                .unwrap()
                .split(&sy.flops, threads)
                .expect("the tree splits");
            assert!(split.iter().all(|bin| !bin.is_empty()));
            parallel.factorize(&sy, &a.values).unwrap();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&parallel.values),
                bits(&whole),
                "{threads} threads, whole"
            );
            let done = parallel.flops_done;
            parallel.factorize(&sy, &changed.values).unwrap();
            assert!(parallel.flops_done - done < sy.total_flops, "partial");
            assert_eq!(
                bits(&parallel.values),
                bits(&partial),
                "{threads} threads, partial"
            );
            let mut x = b.clone();
            parallel.solve_in_place(&sy, &mut x, 1);
            assert_eq!(bits(&x), bits(&x_seq));
        }
    }

    /// A refused pivot inside a subtree computed by a second thread is reported as on one
    /// thread, and leaves the next factorization whole.
    #[test]
    fn a_refused_pivot_in_a_thread_fails_the_call() {
        let a = random_matrix(6000, 43);
        let sy = SymbolicSymmetricLu::new(&a.pattern).unwrap();
        let mut bad = a.clone();
        // Zero the first unknown's row and column in the factor order: its supernode is a
        // leaf, in some bin.
        let first = sy.perm[0];
        for c in 0..6000 {
            for k in bad.pattern.col_ptr[c]..bad.pattern.col_ptr[c + 1] {
                if c == first || bad.pattern.row_idx[k] == first {
                    bad.values[k] = 0.0;
                }
            }
        }
        let mut sequential = NumericSymmetricLu::default();
        let expected = sequential.factorize(&sy, &bad.values).unwrap_err();
        let mut parallel = NumericSymmetricLu::default();
        parallel.set_threads(2);
        let failure = parallel.factorize(&sy, &bad.values).unwrap_err();
        assert_eq!(failure.column, expected.column);
        assert_eq!(failure.column, 0);
        parallel.factorize(&sy, &a.values).unwrap();
        sequential.factorize(&sy, &a.values).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&parallel.values), bits(&sequential.values));
    }

    /// After a refused pivot the kept factors are incomplete: the next call factorizes
    /// everything.
    #[test]
    fn a_refused_pivot_makes_the_next_factorization_whole() {
        let a = random_matrix(300, 13);
        let symbolic = SymbolicSymmetricLu::new(&a.pattern).unwrap();
        let mut kept = NumericSymmetricLu::default();
        kept.factorize(&symbolic, &a.values).unwrap();
        let mut broken = a.clone();
        for (c, v) in broken.values.iter_mut().enumerate() {
            if c % 2 == 0 {
                *v = 0.0;
            }
        }
        for i in 0..300 {
            let k = broken.pattern.position(i, i).unwrap();
            broken.values[k] = 0.0;
        }
        assert!(kept.factorize(&symbolic, &broken.values).is_err());
        let before = kept.flops_done;
        kept.factorize(&symbolic, &a.values).unwrap();
        let mut fresh = NumericSymmetricLu::default();
        fresh.factorize(&symbolic, &a.values).unwrap();
        let whole = kept.flops_done - before;
        assert!(
            (whole - fresh.flops_done).abs() <= 1e-12 * fresh.flops_done,
            "{whole} flops"
        );
        assert!(kept
            .values
            .iter()
            .zip(&fresh.values)
            .all(|(u, v)| u.to_bits() == v.to_bits()));
    }

    #[test]
    fn several_right_hand_sides_and_a_border_equal_the_pivoting_lu() {
        let a = random_matrix(200, 9);
        let b: Vec<f64> = (0..200).map(|i| (i as f64).cos()).collect();
        for border in [vec![], vec![17], vec![3, 150, 99]] {
            let (mut y, mut z) = (b.clone(), b.clone());
            SymmetricLu::default()
                .solve_bordered(&a, &mut y, &border)
                .unwrap();
            FaerLu::default()
                .solve_bordered(&a, &mut z, &border)
                .unwrap();
            for i in 0..200 {
                assert!(
                    (y[i] - z[i]).abs() < 1e-12,
                    "border {border:?}, unknown {i}"
                );
            }
        }
    }

    #[test]
    fn a_zero_pivot_falls_back_to_the_pivoting_lu() {
        // [[0, 1], [1, 1]]: regular, but its first pivot is 0 in any symmetric order that
        // puts unknown 0 first; and [[1, 1], [1, 0]] in the other order. Both are solved.
        let p = Arc::new(SparsePattern::from_entries(
            2,
            [(0, 0), (1, 1), (0, 1), (1, 0)],
        ));
        for diagonal in [[0.0, 1.0], [1.0, 0.0]] {
            let mut a = SparseMatrix::zeros(p.clone());
            a.add(0, 0, diagonal[0]);
            a.add(1, 1, diagonal[1]);
            a.add(0, 1, 1.0);
            a.add(1, 0, 1.0);
            let x = [2.0, -3.0];
            let mut b = a.mul_vec(&x);
            let mut solver = SymmetricLu::default();
            solver.solve(&a, &mut b).unwrap();
            assert!(
                (b[0] - x[0]).abs() < 1e-14 && (b[1] - x[1]).abs() < 1e-14,
                "{b:?}"
            );
            // Either the zero pivot came first and was refused, or the order avoided it.
            assert!(solver.fallback_count <= 1);
        }
        // Zero pivot in a saddle-point system: [[2, 0, 1], [0, 3, 1], [1, 1, 0]].
        let entries = [(0, 0), (1, 1), (2, 2), (0, 2), (2, 0), (1, 2), (2, 1)];
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
        SymmetricLu::default().solve(&a, &mut b).unwrap();
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
    }

    #[test]
    fn a_tiny_pivot_is_refused_and_the_fallback_is_used() {
        // Unknown 0's pivot is 1e-14 against off-diagonal entries of 1: no pivoting would
        // amplify round-off by 1e14. The answer must still be right.
        let p = Arc::new(SparsePattern::from_entries(
            2,
            [(0, 0), (1, 1), (0, 1), (1, 0)],
        ));
        let mut a = SparseMatrix::zeros(p);
        for (r, c, v) in [(0, 0, 1e-14), (1, 1, 1e-14), (0, 1, 1.0), (1, 0, 1.0)] {
            a.add(r, c, v);
        }
        let x = [0.3, 0.7];
        let mut b = a.mul_vec(&x);
        let mut solver = SymmetricLu::default();
        solver.solve(&a, &mut b).unwrap();
        assert_eq!(solver.fallback_count, 1);
        assert!(
            (b[0] - x[0]).abs() < 1e-14 && (b[1] - x[1]).abs() < 1e-14,
            "{b:?}"
        );
    }

    #[test]
    fn a_singular_matrix_is_an_error_not_a_panic() {
        let p = Arc::new(SparsePattern::from_entries(
            2,
            [(0, 0), (1, 1), (0, 1), (1, 0)],
        ));
        let mut a = SparseMatrix::zeros(p);
        for (r, c) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            a.add(r, c, 1.0);
        }
        let mut b = vec![1.0, 2.0];
        let mut solver = SymmetricLu::default();
        assert!(solver.solve(&a, &mut b).is_err());
        assert_eq!(solver.fallback_count, 1);
        let mut nan = a.clone();
        nan.values[0] = f64::NAN;
        assert!(solver.solve(&nan, &mut [1.0, 2.0]).is_err());
    }
}
