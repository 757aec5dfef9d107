//! Node-by-node elimination of the contact multipliers from the mixed Newton system.
//!
//! A contact node `a` with pairs `p = 1..m` (one per tool that may touch it), multiplier
//! blocks `l_p`, augmentations `r_p`, has `3 + 3m` local rows: its equilibrium and its
//! pairs' multiplier rows,
//!
//! ```text
//! R1   (equilibrium of a):  K_a du + sum_p (E_x,p du_a + E_l,p dl_p) = -R_u,a
//! R2_p (multiplier of p):   S_x,p du_a + S_l,p dl_p                  = -R_l,p
//!                           S_x,p = E_x,p / r_p,  S_l,p = (E_l,p - I) / r_p
//! ```
//!
//! With `M_p = I - E_l,p` (I in gap, singular once the pair is active: 0 in stick, the
//! normal direction removed in slip), two combinations of the local rows never degenerate:
//!
//! ```text
//! Sigma = R1 - sum_p r_p R2_p:   K_a du + sum_p dl_p = ...     (the multipliers' sum)
//! W_p   = r_p R2_p:              E_x,p du_a - M_p dl_p = ...   (pair p's own row)
//! ```
//!
//! Let `q` be the pair with the most singular `M_q` (the active one) and every other `M_p`
//! invertible (those pairs are in gap). Then `dl_p = -M_p^-1 W_p` for `p != q`,
//! `dl_q = Sigma - sum_{p != q} dl_p`, and `W_q + M_q dl_q` is free of multipliers: it
//! replaces node a's equilibrium rows,
//!
//! ```text
//! P = W_q + M_q (Sigma + sum_{p != q} M_p^-1 W_p)      (3 rows, pattern of K's row)
//! ```
//!
//! For one pair, `P = M R1 + r E_l R2`: plain equilibrium in gap (M = I), the kinematic
//! constraint `E_x du_a` in stick (M = 0); for a top-face node of the cup (punch and holder
//! pairs) at most one of which touches, it is the active pair's row, or plain equilibrium
//! when neither does. The coefficients, `C = [P; H]` with `dl = H (rhs - N du)` (`N` the
//! local rows' other columns), form one `(3 + 3m)^2` matrix per node and iteration; the
//! reduced system is displacement-only with the symmetric structure of the stiffness, so a
//! factorization on that structure fills like a Cholesky. Two pairs of one node active at
//! once (no `q` exists) is not reduced: that call solves the mixed system instead
//! ([`Condenser::fallback_count`]).
//!
//! Nodes with a prescribed component keep their multipliers (their equilibrium row is a
//! unit row, so `Sigma` does not exist), as do their pairs: the reduced system then has the
//! displacements plus those few multipliers.
//!
//! A force-controlled tool adds an offset unknown `s` (see `force_control`): its column
//! enters the local rows and so the condensed rows; the tool's force row
//! `sum_k c_k . dl_k = -R_s` is kept, with `dl_k = H_k (rhs - N du)` substituted (the
//! columns of node k's equilibrium row).
//!
//! Cost: O(nnz) per iteration to build, by a slot plan recorded once per pattern (the value
//! index of every contribution, in a fixed order), so that no entry is searched for; the
//! factorization shrinks by the number of eliminated multipliers.

use crate::solver::assembly::DofMap;
use crate::solver::linear::LinearSolver;
use crate::solver::model::Model;
use crate::solver::sparse::{SparseMatrix, SparsePattern};
use crate::Result;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// The last reduced system with the Jacobian values and coefficients it was built from,
/// kept between calls: the next call replays only what changed into it
/// ([`Condenser::reduce`]) and the linear solver works on it in place. Its buffers are
/// reused from call to call.
#[derive(Debug)]
struct Reduction {
    /// The Jacobian values it was built from (empty before the first call).
    jacobian: Vec<f64>,
    coefficients: Vec<f64>,
    /// The coefficients of the call under way, until they are compared with
    /// `coefficients` and swapped with them.
    fresh_coefficients: Vec<f64>,
    matrix: SparseMatrix,
    rhs: Vec<f64>,
    /// [`Condenser::mark_dirty`]'s flags: per full row, per eliminated node, per segment.
    row_changed: Vec<bool>,
    node_changed: Vec<bool>,
    dirty: Vec<bool>,
}

/// Elimination groups of the mixed unknowns (see `SparsePattern::groups`): a node's
/// displacements and the multipliers of its contact pairs form one group (the node's
/// index), so that a factorization without pivoting eliminates a multiplier, whose own
/// pivot is zero in stick, after its node's displacements; any other unknown (a tool
/// offset) is alone.
pub fn elimination_groups(model: &Model, dofs: &DofMap) -> Vec<usize> {
    let mut groups: Vec<usize> = (0..dofs.n_dofs).map(|d| dofs.n_nodes + d).collect();
    for (d, g) in groups.iter_mut().enumerate().take(3 * dofs.n_nodes) {
        *g = d / 3;
    }
    for (c, contact) in model.contacts.iter().enumerate() {
        let Some(off) = dofs.lambda_offset[c] else {
            continue;
        };
        for (k, &node) in contact.candidates.iter().enumerate() {
            groups[off + 3 * k..off + 3 * k + 3].fill(node);
        }
    }
    groups
}

/// A pair of an eliminated node.
#[derive(Clone, Debug)]
struct Pair {
    /// First multiplier unknown.
    lambda: usize,
    /// Augmentation parameter.
    r: f64,
    /// Position in J of E_l = (u_a + alpha, lambda + beta).
    e_l_position: [[Option<usize>; 3]; 3],
}

/// A node whose multipliers are all eliminated.
#[derive(Clone, Debug)]
struct EliminatedNode {
    node: usize,
    pairs: Vec<Pair>,
    /// Offset of its coefficient matrix `C = [P; H]` (`width^2` values, row-major) in the
    /// per-iteration coefficient buffer.
    offset: usize,
}

impl EliminatedNode {
    /// Number of local rows (and columns of C): equilibrium, then each pair's multipliers.
    fn width(&self) -> usize {
        3 + 3 * self.pairs.len()
    }

    /// Full row index of local row `i`.
    fn local_row(&self, i: usize) -> usize {
        if i < 3 {
            3 * self.node + i
        } else {
            self.pairs[(i - 3) / 3].lambda + (i - 3) % 3
        }
    }
}

/// The local elimination of a node with two active pairs does not exist.
#[derive(Debug)]
struct NoLocalElimination;

/// The static reduction of a model's mixed system (which multipliers go, where the rest
/// land), built once per model.
#[derive(Debug)]
pub struct Condenser {
    nodes: Vec<EliminatedNode>,
    /// Length of the coefficient buffer (sum of the nodes' `width^2`).
    coefficient_count: usize,
    /// Full dof -> reduced dof (None: eliminated multiplier).
    reduced_index: Vec<Option<usize>>,
    /// Pattern of the reduced matrix.
    pattern: Arc<SparsePattern>,
    /// Row-wise view of the full pattern: for each row, (column, value position).
    rows: Vec<Vec<(usize, usize)>>,
    /// Rows of eliminated nodes' local blocks (full index), to skip when copying.
    condensed_row: Vec<bool>,
    /// Per full row, whether it has a column of an eliminated multiplier (a kept row
    /// that substitutes one, see [`Self::walk`]): few rows do, and the others' reduced
    /// right-hand side and dirtiness need no pass over their entries.
    substitutes: Vec<bool>,
    /// Per full row, its entries that land in the reduced matrix (columns that are not
    /// eliminated multipliers), as (reduced column, value position) in `rows`' order: the
    /// contributions [`Self::add_local_row`] makes and the back-substitution's `N du`
    /// terms, listed once instead of filtered per call; row `r` owns `reduced_entries[reduced_ptr[r]..reduced_ptr[r + 1]]` (u32: the
    /// full pattern has fewer than 2^32 entries).
    reduced_entries: Vec<(u32, u32)>,
    reduced_ptr: Vec<usize>,
    /// Eliminated multiplier dof -> (index in `nodes`, row of C that recovers it).
    owner: Vec<Option<(usize, usize)>>,
    /// The slot plan: the reduced matrix's value index of every contribution, in the order
    /// of [`Self::walk`] (u32: the reduced pattern has fewer than 2^32 entries).
    slots: Vec<u32>,
    /// Where each segment of the walk starts in `slots` (and `slots.len()` at the end):
    /// the kept rows in `kept_rows`' order, then the eliminated nodes.
    segment_start: Vec<usize>,
    kept_rows: Vec<usize>,
    /// The last reduced system and what it was built from, for [`Self::reduce`].
    last: Mutex<Reduction>,
    /// Calls solved through the mixed system because no local elimination existed.
    fallbacks: AtomicUsize,
}

/// With this variable set, nodes with several pairs keep their multipliers (the reduction
/// before two-pair nodes were eliminated): for before/after benchmarks of the factorization
/// only (BENCHMARKS.md); the answers are the same either way.
pub const SINGLE_PAIR_VARIABLE: &str = "TRIBO_CONDENSE_SINGLE_PAIR";

/// |det M| under which a gap pair's `M_p` counts as singular (M is I in gap, exactly
/// singular once active: the entries are O(1) and dimensionless).
const SINGULAR_DET: f64 = 1e-6;

fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn inverse3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let d = det3(m);
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            // Cofactor (j, i) over the determinant.
            let (r0, r1) = ((j + 1) % 3, (j + 2) % 3);
            let (c0, c1) = ((i + 1) % 3, (i + 2) % 3);
            (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / d
        })
    })
}

impl Condenser {
    /// `None` when nothing can be eliminated (penalty, or no eligible pair).
    pub fn new(
        model: &Model,
        dofs: &DofMap,
        full: &SparsePattern,
        is_fixed: &[bool],
    ) -> Option<Self> {
        let (nodes, coefficient_count) = Self::eliminated_nodes(model, dofs, full, is_fixed);
        if nodes.is_empty() {
            return None;
        }
        let (gone, condensed_row, owner) = Self::local_rows_of(&nodes, full.n);
        let (reduced_index, next) = Self::reduced_numbering(&gone);
        let (rows, mut entries) = Self::full_rows(full, &reduced_index);
        Self::add_condensed_entries(&nodes, &rows, &reduced_index, &mut entries);
        Self::add_substitution_entries(
            &nodes,
            &rows,
            &reduced_index,
            &condensed_row,
            &owner,
            &mut entries,
        );
        let groups = Self::reduced_groups(model, dofs, &reduced_index, next);
        let pattern = Arc::new(SparsePattern::from_entries(next, entries).with_groups(groups));
        if pattern.nnz() > u32::MAX as usize || full.nnz() > u32::MAX as usize {
            return None;
        }
        let last = Self::empty_reduction(&pattern);
        let substitutes = rows
            .iter()
            .map(|row| row.iter().any(|&(c, _)| owner[c].is_some()))
            .collect();
        let mut condenser = Condenser {
            nodes,
            coefficient_count,
            reduced_index,
            pattern,
            rows,
            condensed_row,
            substitutes,
            owner,
            slots: Vec::new(),
            reduced_entries: Vec::new(),
            reduced_ptr: vec![0],
            segment_start: Vec::new(),
            kept_rows: Vec::new(),
            last: Mutex::new(last),
            fallbacks: AtomicUsize::new(0),
        };
        condenser.list_reduced_entries();
        condenser.record_slot_plan(full, next);
        // The walk's kept-row segments, in its order (then one segment per node).
        condenser.kept_rows = (0..full.n)
            .filter(|&r| condenser.reduced_index[r].is_some() && !condenser.condensed_row[r])
            .collect();
        debug_assert_eq!(
            condenser.segment_start.len(),
            condenser.kept_rows.len() + condenser.nodes.len() + 1
        );
        Some(condenser)
    }

    /// The nodes whose multipliers are eliminated, with the offset of each one's
    /// coefficient matrix, and the coefficient buffer's length (the sum of their
    /// `width^2`): every node with at least one contact pair (a candidate of a contact
    /// with multipliers) and no prescribed component, in node order. Under
    /// [`SINGLE_PAIR_VARIABLE`], nodes with several pairs keep their multipliers.
    fn eliminated_nodes(
        model: &Model,
        dofs: &DofMap,
        full: &SparsePattern,
        is_fixed: &[bool],
    ) -> (Vec<EliminatedNode>, usize) {
        let mut pairs_at: Vec<Vec<(usize, f64)>> = vec![Vec::new(); dofs.n_nodes];
        for (c, contact) in model.contacts.iter().enumerate() {
            let Some(off) = dofs.lambda_offset[c] else {
                continue;
            };
            for (k, &node) in contact.candidates.iter().enumerate() {
                pairs_at[node].push((off + 3 * k, contact.r[k]));
            }
        }
        let single_pair_only = std::env::var_os(SINGLE_PAIR_VARIABLE).is_some();
        let mut nodes = Vec::new();
        let mut coefficient_count = 0;
        for (node, pairs) in pairs_at.into_iter().enumerate() {
            let free = (0..3).all(|i| !is_fixed[3 * node + i]);
            if pairs.is_empty() || !free || (single_pair_only && pairs.len() > 1) {
                continue;
            }
            let pairs: Vec<Pair> = pairs
                .into_iter()
                .map(|(lambda, r)| Pair {
                    lambda,
                    r,
                    e_l_position: std::array::from_fn(|a| {
                        std::array::from_fn(|b| full.position(3 * node + a, lambda + b))
                    }),
                })
                .collect();
            let e = EliminatedNode {
                node,
                pairs,
                offset: coefficient_count,
            };
            coefficient_count += e.width() * e.width();
            nodes.push(e);
        }
        (nodes, coefficient_count)
    }

    /// Per full row, `(gone, condensed_row, owner)`: whether it is an eliminated multiplier,
    /// whether it is one of an eliminated node's local rows (its equilibrium rows, which the
    /// condensed rows replace, and its multipliers), and for an eliminated multiplier the
    /// node (index in `nodes`) and row of its `C` that recovers it.
    #[allow(clippy::type_complexity)]
    fn local_rows_of(
        nodes: &[EliminatedNode],
        n: usize,
    ) -> (Vec<bool>, Vec<bool>, Vec<Option<(usize, usize)>>) {
        let mut gone = vec![false; n];
        let mut condensed_row = vec![false; n];
        let mut owner = vec![None; n];
        for (index, e) in nodes.iter().enumerate() {
            for i in 0..e.width() {
                condensed_row[e.local_row(i)] = true;
                if i >= 3 {
                    gone[e.local_row(i)] = true;
                    owner[e.local_row(i)] = Some((index, i));
                }
            }
        }
        (gone, condensed_row, owner)
    }

    /// The reduced unknowns: every full unknown that is not eliminated, numbered in full
    /// order; `(full -> reduced, number of reduced unknowns)`.
    fn reduced_numbering(gone: &[bool]) -> (Vec<Option<usize>>, usize) {
        let mut reduced_index = vec![None; gone.len()];
        let mut next = 0;
        for (d, g) in gone.iter().enumerate() {
            if !g {
                reduced_index[d] = Some(next);
                next += 1;
            }
        }
        (reduced_index, next)
    }

    /// The row-wise view of the full pattern (for each row, its (column, value position)
    /// in column order) and the reduced entries the full pattern carries over as they are
    /// (both row and column kept).
    #[allow(clippy::type_complexity)]
    fn full_rows(
        full: &SparsePattern,
        reduced_index: &[Option<usize>],
    ) -> (Vec<Vec<(usize, usize)>>, Vec<(usize, usize)>) {
        let mut rows = vec![Vec::new(); full.n];
        let mut entries = Vec::new();
        for c in 0..full.n {
            for k in full.col_ptr[c]..full.col_ptr[c + 1] {
                let r = full.row_idx[k];
                rows[r].push((c, k));
                if let (Some(ri), Some(ci)) = (reduced_index[r], reduced_index[c]) {
                    entries.push((ri, ci));
                }
            }
        }
        (rows, entries)
    }

    /// The reduced columns of node `e`'s local rows (repeats included): the columns that a
    /// combination of its local rows, or the substitution of one of its multipliers, fills.
    fn local_columns(
        e: &EliminatedNode,
        rows: &[Vec<(usize, usize)>],
        reduced_index: &[Option<usize>],
    ) -> Vec<usize> {
        (0..e.width())
            .flat_map(|i| rows[e.local_row(i)].iter())
            .filter_map(|&(col, _)| reduced_index[col])
            .collect()
    }

    /// The entries of the condensed rows: `P` combines a node's local rows, so each of its
    /// three displacement rows takes all their reduced columns.
    fn add_condensed_entries(
        nodes: &[EliminatedNode],
        rows: &[Vec<(usize, usize)>],
        reduced_index: &[Option<usize>],
        entries: &mut Vec<(usize, usize)>,
    ) {
        for e in nodes {
            let columns = Self::local_columns(e, rows, reduced_index);
            for alpha in 0..3 {
                let ri = reduced_index[3 * e.node + alpha].expect("displacements stay");
                entries.extend(columns.iter().map(|&ci| (ri, ci)));
            }
        }
    }

    /// The entries of the kept rows that have an eliminated column (the force row of a
    /// force-controlled tool): the multiplier `dl = H (rhs - N du)` substituted, they take
    /// its node's local rows' reduced columns.
    fn add_substitution_entries(
        nodes: &[EliminatedNode],
        rows: &[Vec<(usize, usize)>],
        reduced_index: &[Option<usize>],
        condensed_row: &[bool],
        owner: &[Option<(usize, usize)>],
        entries: &mut Vec<(usize, usize)>,
    ) {
        for (r, row) in rows.iter().enumerate() {
            let (Some(ri), false) = (reduced_index[r], condensed_row[r]) else {
                continue;
            };
            for &(c, _) in row {
                if let Some((index, _)) = owner[c] {
                    entries.extend(
                        Self::local_columns(&nodes[index], rows, reduced_index)
                            .into_iter()
                            .map(|ci| (ri, ci)),
                    );
                }
            }
        }
    }

    /// The reduced unknowns' elimination groups: each keeps its full unknown's group
    /// ([`elimination_groups`]), so a kept multiplier is still eliminated after its node's
    /// displacements.
    fn reduced_groups(
        model: &Model,
        dofs: &DofMap,
        reduced_index: &[Option<usize>],
        next: usize,
    ) -> Vec<usize> {
        let full_groups = elimination_groups(model, dofs);
        let mut groups = vec![0; next];
        for (d, ri) in reduced_index.iter().enumerate() {
            if let Some(ri) = ri {
                groups[*ri] = full_groups[d];
            }
        }
        groups
    }

    /// The kept reduction before the first call: a zero matrix of the reduced pattern and
    /// empty buffers (an empty `jacobian` makes the first [`Self::reduce`] whole).
    fn empty_reduction(pattern: &Arc<SparsePattern>) -> Reduction {
        Reduction {
            jacobian: Vec::new(),
            coefficients: Vec::new(),
            fresh_coefficients: Vec::new(),
            matrix: SparseMatrix::zeros(pattern.clone()),
            rhs: Vec::new(),
            row_changed: Vec::new(),
            node_changed: Vec::new(),
            dirty: Vec::new(),
        }
    }

    /// Fills `reduced_entries` and `reduced_ptr`: per full row, its entries whose column
    /// is kept, as (reduced column, value position), in `rows`' order.
    fn list_reduced_entries(&mut self) {
        for row in &self.rows {
            let kept = row
                .iter()
                .filter_map(|&(col, k)| self.reduced_index[col].map(|ci| (ci as u32, k as u32)));
            self.reduced_entries.extend(kept);
            self.reduced_ptr.push(self.reduced_entries.len());
        }
    }

    /// Records the slot plan (`slots`, `segment_start`) by one walk with a [`Recorder`]: the
    /// walk only depends on the pattern, so zero values will do (with a zero Jacobian every
    /// pair is in gap, `M_p = I`, and every coefficient matrix exists). `next` is the number
    /// of reduced unknowns.
    fn record_slot_plan(&mut self, full: &SparsePattern, next: usize) {
        let zeros = vec![0.0; full.nnz()];
        let mut coefficients = Vec::new();
        self.coefficients(&zeros, &mut coefficients)
            .expect("with a zero Jacobian every pair is in gap");
        let mut rhs = vec![0.0; next];
        let mut plan = Recorder {
            pattern: self.pattern.clone(),
            slots: Vec::new(),
            segment_start: Vec::new(),
        };
        self.walk(
            &coefficients,
            &zeros,
            &vec![0.0; full.n],
            &mut rhs,
            &mut plan,
        );
        plan.segment_start.push(plan.slots.len());
        self.slots = plan.slots;
        self.segment_start = plan.segment_start;
    }

    /// Number of eliminated multiplier unknowns.
    pub fn eliminated_count(&self) -> usize {
        self.nodes.iter().map(|e| 3 * e.pairs.len()).sum()
    }

    /// Number of solves that went through the mixed system because a node had two active
    /// pairs (no local elimination).
    pub fn fallback_count(&self) -> usize {
        self.fallbacks.load(Ordering::Relaxed)
    }

    /// The reduced system's pattern (displacements, tool offsets and kept multipliers).
    pub fn pattern(&self) -> &Arc<SparsePattern> {
        &self.pattern
    }

    /// Every node's coefficient matrix `C = [P; H]` (module doc) from the Jacobian values,
    /// into `out`: rows 0..3 combine the local rows into the condensed rows, row
    /// `3 + 3p + beta` recovers pair p's multiplier component beta. O(m^2) per node.
    fn coefficients(
        &self,
        j: &[f64],
        out: &mut Vec<f64>,
    ) -> std::result::Result<(), NoLocalElimination> {
        out.clear();
        out.resize(self.coefficient_count, 0.0);
        let (mut m, mut dets) = (Vec::new(), Vec::new());
        for e in &self.nodes {
            let w = e.width();
            let c = &mut out[e.offset..e.offset + w * w];
            m.clear();
            m.extend(e.pairs.iter().map(|p| -> [[f64; 3]; 3] {
                std::array::from_fn(|a| {
                    std::array::from_fn(|b| {
                        let e_l = p.e_l_position[a][b].map_or(0.0, |k| j[k]);
                        f64::from(u8::from(a == b)) - e_l
                    })
                })
            }));
            dets.clear();
            dets.extend(m.iter().map(|mp| det3(mp).abs()));
            let q = (0..m.len())
                .min_by(|&a, &b| dets[a].total_cmp(&dets[b]))
                .expect("an eliminated node has a pair");
            // H_q starts as Sigma (rows 3 + 3q ..).
            let hq = 3 + 3 * q;
            for alpha in 0..3 {
                c[(hq + alpha) * w + alpha] = 1.0;
                for (p, pair) in e.pairs.iter().enumerate() {
                    c[(hq + alpha) * w + 3 + 3 * p + alpha] = -pair.r;
                }
            }
            for (p, pair) in e.pairs.iter().enumerate() {
                if p == q {
                    continue;
                }
                if dets[p] <= SINGULAR_DET {
                    return Err(NoLocalElimination);
                }
                // H_p = -M_p^-1 W_p, and H_q -= H_p.
                let inv = inverse3(&m[p]);
                for alpha in 0..3 {
                    for beta in 0..3 {
                        let v = -inv[alpha][beta] * pair.r;
                        c[(3 + 3 * p + alpha) * w + 3 + 3 * p + beta] = v;
                        c[(hq + alpha) * w + 3 + 3 * p + beta] -= v;
                    }
                }
            }
            // P = W_q + M_q H_q.
            let r_q = e.pairs[q].r;
            for alpha in 0..3 {
                for i in 0..w {
                    let mut v: f64 = (0..3).map(|b| m[q][alpha][b] * c[(hq + b) * w + i]).sum();
                    if i == hq + alpha {
                        v += r_q;
                    }
                    c[alpha * w + i] = v;
                }
            }
        }
        Ok(())
    }

    /// Adds `factor` times the reduced columns of node `e`'s local row `i` to reduced row
    /// `ri`. A zero factor adds nothing but zeros: the sink is told to skip them.
    fn add_local_row(
        &self,
        sink: &mut impl Contributions,
        j: &[f64],
        ri: usize,
        e: &EliminatedNode,
        i: usize,
        factor: f64,
    ) {
        let row = e.local_row(i);
        let entries = &self.reduced_entries[self.reduced_ptr[row]..self.reduced_ptr[row + 1]];
        if sink.skips(factor) {
            sink.skip(entries.len());
            return;
        }
        sink.add_row(ri, entries, j, factor);
    }

    /// Walks every contribution to the reduced matrix, in a fixed order that depends only
    /// on the pattern, handing each to `sink`, and fills the reduced right-hand side. The
    /// slot plan is this walk recorded once; the numeric pass replays it.
    ///
    /// A local row whose coefficient is zero is skipped whole when the sink allows it: in
    /// a condensed row most coefficients are exact zeros (a node in gap keeps its
    /// equilibrium rows, `P = [I 0]`; in stick only the pair's own rows count). A sink may
    /// also skip whole segments whose inputs did not change ([`Replay`]).
    fn walk(
        &self,
        coefficients: &[f64],
        j: &[f64],
        residual: &[f64],
        rhs: &mut [f64],
        sink: &mut impl Contributions,
    ) {
        let n = self.rows.len();
        let mut segment = 0;
        // Rows that stay as they are.
        for row in 0..n {
            let Some(ri) = self.reduced_index[row] else {
                continue;
            };
            if self.condensed_row[row] {
                continue;
            }
            rhs[ri] = -residual[row];
            // A row the sink keeps, without substitution: its right-hand side is all.
            if !self.substitutes[row] && !sink.writes(segment) {
                segment += 1;
                continue;
            }
            sink.begin_segment(segment);
            segment += 1;
            for &(col, k) in &self.rows[row] {
                if let Some(ci) = self.reduced_index[col] {
                    sink.add(ri, ci, j[k]);
                } else if let Some((index, h_row)) = self.owner[col] {
                    // c dl with dl = H (rhs_local - N du).
                    let e = &self.nodes[index];
                    let w = e.width();
                    let h = &coefficients[e.offset + h_row * w..e.offset + (h_row + 1) * w];
                    for (i, &h_i) in h.iter().enumerate() {
                        rhs[ri] += j[k] * h_i * residual[e.local_row(i)];
                        self.add_local_row(sink, j, ri, e, i, -j[k] * h_i);
                    }
                }
            }
        }
        // Condensed rows: P N du = P rhs_local.
        for e in &self.nodes {
            sink.begin_segment(segment);
            segment += 1;
            let w = e.width();
            for alpha in 0..3 {
                let ri = self.reduced_index[3 * e.node + alpha].expect("displacements stay");
                let p = &coefficients[e.offset + alpha * w..e.offset + (alpha + 1) * w];
                rhs[ri] = -(0..w).map(|i| p[i] * residual[e.local_row(i)]).sum::<f64>();
                for (i, &p_i) in p.iter().enumerate() {
                    self.add_local_row(sink, j, ri, e, i, p_i);
                }
            }
        }
    }

    /// The reduced matrix and right-hand side, built by replaying the slot plan: one linear
    /// pass over the contributions, no search. After a first call, only the segments whose
    /// Jacobian rows or node coefficients changed are replayed (a status prediction
    /// re-solve changes a few nodes); the result is bit for bit a full replay's (but for the
    /// sign of an exact zero). O(nnz(J)) per call to find what changed, then
    /// O(contributions) of the changed segments. `None` when a node has two active pairs
    /// (no local elimination).
    pub fn reduced_system(
        &self,
        j: &SparseMatrix,
        residual: &[f64],
    ) -> Option<(SparseMatrix, Vec<f64>)> {
        let mut kept = self.last.lock().unwrap_or_else(|e| e.into_inner());
        self.coefficients(&j.values, &mut kept.fresh_coefficients)
            .ok()?;
        self.reduce(&mut kept, j, residual);
        Some((kept.matrix.clone(), kept.rhs.clone()))
    }

    /// Brings `kept` to the reduced system of `j` and `residual`, with the coefficients of
    /// `j` in `kept.fresh_coefficients` ([`Self::reduced_system`]): from the last reduction's
    /// values, replaying the dirty segments only, or, on the first call, every segment into
    /// zeros.
    fn reduce(&self, kept: &mut Reduction, j: &SparseMatrix, residual: &[f64]) {
        std::mem::swap(&mut kept.coefficients, &mut kept.fresh_coefficients);
        let partial = kept.jacobian.len() == j.values.len();
        if partial {
            self.mark_dirty(kept, j);
        } else {
            kept.jacobian.clone_from(&j.values);
        }
        // The first call, or most segments dirty (a Newton step's new Jacobian: all but
        // the rows a Dirichlet condition keeps as they are): one clear of the whole matrix
        // and every segment replayed instead of each dirty segment's slots cleared one by
        // one, the same sums (a reduced entry receives the contributions of one segment
        // only, from zero either way, and a clean segment's inputs are unchanged).
        let replay_all =
            !partial || 2 * kept.dirty.iter().filter(|&&d| d).count() > kept.dirty.len();
        if replay_all {
            kept.matrix.values.fill(0.0);
        }
        kept.rhs.clear();
        kept.rhs.resize(self.pattern.n, 0.0);
        let mut replay = Replay {
            slots: &self.slots,
            segment_start: &self.segment_start,
            dirty: (!replay_all).then_some(&kept.dirty[..]),
            active: true,
            next: 0,
            values: &mut kept.matrix.values,
        };
        self.walk(
            &kept.coefficients,
            &j.values,
            residual,
            &mut kept.rhs,
            &mut replay,
        );
    }

    /// Sets `kept.dirty` to the segments of the walk whose contributions differ from those
    /// of the kept reduction: an eliminated node whose coefficients (`kept.coefficients`
    /// against the previous ones, now in `kept.fresh_coefficients`) or local rows changed,
    /// a kept row that changed or has a column of such a node. Values are compared bit for
    /// bit, and the changed Jacobian values copied into `kept.jacobian` in the same pass.
    fn mark_dirty(&self, kept: &mut Reduction, j: &SparseMatrix) {
        let n = self.rows.len();
        let row_changed = &mut kept.row_changed;
        row_changed.clear();
        row_changed.resize(n, false);
        for (k, (&new, old)) in j.values.iter().zip(&mut kept.jacobian).enumerate() {
            if new.to_bits() != old.to_bits() {
                row_changed[j.pattern.row_idx[k]] = true;
                *old = new;
            }
        }
        let (coefficients, previous) = (&kept.coefficients, &kept.fresh_coefficients);
        kept.node_changed.clear();
        kept.node_changed.extend(self.nodes.iter().map(|e| {
            let w = e.width();
            let range = e.offset..e.offset + w * w;
            (0..w).any(|i| row_changed[e.local_row(i)])
                || coefficients[range.clone()]
                    .iter()
                    .zip(&previous[range])
                    .any(|(a, b)| a.to_bits() != b.to_bits())
        }));
        let node_changed = &kept.node_changed;
        kept.dirty.clear();
        kept.dirty.extend(
            self.kept_rows
                .iter()
                .map(|&row| {
                    row_changed[row]
                        || (self.substitutes[row]
                            && self.rows[row].iter().any(|&(col, _)| {
                                self.owner[col].is_some_and(|(e, _)| node_changed[e])
                            }))
                })
                .chain(node_changed.iter().copied()),
        );
    }

    /// The same reduced system with every contribution placed by a binary search in the
    /// pattern, zero coefficients included (the construction before the slot plan): the
    /// reference the plan is tested against.
    #[doc(hidden)]
    pub fn reduced_system_by_search(
        &self,
        j: &SparseMatrix,
        residual: &[f64],
    ) -> Option<(SparseMatrix, Vec<f64>)> {
        let mut coefficients = Vec::new();
        self.coefficients(&j.values, &mut coefficients).ok()?;
        let mut a = SparseMatrix::zeros(self.pattern.clone());
        let mut rhs = vec![0.0; self.pattern.n];
        self.walk(
            &coefficients,
            &j.values,
            residual,
            &mut rhs,
            &mut Search(&mut a),
        );
        Some((a, rhs))
    }

    /// Solves `J dx = -residual` through the reduced system; returns the full dx. The
    /// unknowns `border` (full indices, never eliminated multipliers) are solved by the
    /// linear solver's Schur complement. A node with two active pairs makes this call solve
    /// the mixed system with the same solver.
    pub fn solve(
        &self,
        j: &SparseMatrix,
        residual: &[f64],
        border: &[usize],
        linear: &mut dyn LinearSolver,
    ) -> Result<Vec<f64>> {
        let n = j.pattern.n;
        let mut kept = self.last.lock().unwrap_or_else(|e| e.into_inner());
        let kept = &mut *kept;
        if self
            .coefficients(&j.values, &mut kept.fresh_coefficients)
            .is_err()
        {
            self.fallbacks.fetch_add(1, Ordering::Relaxed);
            let mut dx: Vec<f64> = residual.iter().map(|v| -v).collect();
            linear.solve_bordered(j, &mut dx, border)?;
            return Ok(dx);
        }
        self.reduce(kept, j, residual);
        let reduced_border: Vec<usize> = border
            .iter()
            .filter_map(|&d| self.reduced_index[d])
            .collect();
        linear.solve_bordered(&kept.matrix, &mut kept.rhs, &reduced_border)?;
        let (rhs, coefficients) = (&kept.rhs, &kept.coefficients);
        let mut dx = vec![0.0; n];
        for (d, ri) in self.reduced_index.iter().enumerate() {
            if let Some(ri) = ri {
                dx[d] = rhs[*ri];
            }
        }
        // Back-substitution: dl = H (rhs_local - N du), N over the reduced columns (the
        // local rows' reduced entries, du read from the reduced solution).
        let mut t = Vec::new();
        for e in &self.nodes {
            let w = e.width();
            t.clear();
            t.extend((0..w).map(|i| {
                let row = e.local_row(i);
                let terms = &self.reduced_entries[self.reduced_ptr[row]..self.reduced_ptr[row + 1]];
                let n_du: f64 = terms
                    .iter()
                    .map(|&(ci, k)| j.values[k as usize] * rhs[ci as usize])
                    .sum();
                -residual[row] - n_du
            }));
            let c = &coefficients[e.offset..e.offset + w * w];
            for (p, pair) in e.pairs.iter().enumerate() {
                for beta in 0..3 {
                    let h = &c[(3 + 3 * p + beta) * w..(4 + 3 * p + beta) * w];
                    dx[pair.lambda + beta] = h.iter().zip(&t).map(|(a, b)| a * b).sum();
                }
            }
        }
        Ok(dx)
    }
}

/// Where [`Condenser::walk`] puts the reduced matrix's contributions.
trait Contributions {
    /// The contributions that follow, up to the next call, form segment `index`: one
    /// kept row, or one eliminated node's three condensed rows, in the walk's order.
    fn begin_segment(&mut self, _index: usize) {}
    /// Whether segment `index` is to be written; one that is not may be left out of the
    /// walk (no [`Self::begin_segment`], no contributions).
    fn writes(&self, _index: usize) -> bool {
        true
    }
    fn add(&mut self, row: usize, col: usize, value: f64);
    /// `factor` times the Jacobian values of a local row's reduced `entries` ((reduced
    /// column, value position) pairs), added to reduced row `row` in their order.
    fn add_row(&mut self, row: usize, entries: &[(u32, u32)], j: &[f64], factor: f64) {
        for &(col, k) in entries {
            self.add(row, col as usize, factor * j[k as usize]);
        }
    }
    /// Whether the local row about to be added with `factor` may be skipped (then
    /// [`Self::skip`] is called with its number of contributions instead of `add` for
    /// each).
    fn skips(&self, _factor: f64) -> bool {
        false
    }
    fn skip(&mut self, _count: usize) {}
}

/// Records the slot plan: the value index of every contribution, and where each segment
/// starts in it.
struct Recorder {
    pattern: Arc<SparsePattern>,
    slots: Vec<u32>,
    segment_start: Vec<usize>,
}

impl Contributions for Recorder {
    fn begin_segment(&mut self, index: usize) {
        debug_assert_eq!(index, self.segment_start.len());
        self.segment_start.push(self.slots.len());
    }
    fn add(&mut self, row: usize, col: usize, _value: f64) {
        let k = self
            .pattern
            .position(row, col)
            .expect("the reduced pattern holds every contribution");
        self.slots.push(k as u32);
    }
}

/// Replays the slot plan into the reduced matrix's values: every segment into zeros, or,
/// with `dirty`, only the dirty segments, each zeroed first (a reduced row receives the
/// contributions of one segment only), the others' values kept.
struct Replay<'a> {
    slots: &'a [u32],
    segment_start: &'a [usize],
    dirty: Option<&'a [bool]>,
    active: bool,
    next: usize,
    values: &'a mut [f64],
}

impl Contributions for Replay<'_> {
    fn writes(&self, index: usize) -> bool {
        self.dirty.is_none_or(|d| d[index])
    }
    fn begin_segment(&mut self, index: usize) {
        self.next = self.segment_start[index];
        self.active = self.writes(index);
        if self.active && self.dirty.is_some() {
            for &k in &self.slots[self.next..self.segment_start[index + 1]] {
                self.values[k as usize] = 0.0;
            }
        }
    }
    fn add(&mut self, _row: usize, _col: usize, value: f64) {
        if self.active {
            self.values[self.slots[self.next] as usize] += value;
        }
        self.next += 1;
    }
    fn add_row(&mut self, _row: usize, entries: &[(u32, u32)], j: &[f64], factor: f64) {
        let end = self.next + entries.len();
        if self.active {
            for (&(_, k), &slot) in entries.iter().zip(&self.slots[self.next..end]) {
                self.values[slot as usize] += factor * j[k as usize];
            }
        }
        self.next = end;
    }
    fn skips(&self, factor: f64) -> bool {
        factor == 0.0 || !self.active
    }
    fn skip(&mut self, count: usize) {
        self.next += count;
    }
}

/// Places every contribution by a search in the pattern.
struct Search<'a>(&'a mut SparseMatrix);

impl Contributions for Search<'_> {
    fn add(&mut self, row: usize, col: usize, value: f64) {
        self.0.add(row, col, value);
    }
}
