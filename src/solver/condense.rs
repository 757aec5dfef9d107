//! Node-by-node elimination of the contact multipliers from the mixed Newton system.
//!
//! For a contact node `a` with a single (tool, node) pair, multiplier block `l`, augmentation
//! `r`, the two block rows of the mixed system are
//!
//! ```text
//! R1 (equilibrium of a):  K_a du + E_x du_a + E_l dl = -R_u,a
//! R2 (multiplier):        S_x du_a + S_l dl          = -R_l,      S_x = E_x / r,  S_l = (E_l - I) / r
//! ```
//!
//! `R1 - r R2` reads `K_a du + dl = -R_u,a + r R_l`: the multiplier increment follows from
//! the displacements, `dl = (-R_u,a + r R_l) - K_a du`, whatever the contact status (the
//! identity never degenerates). Put into `r R2`, with `M = I - E_l`:
//!
//! ```text
//! (E_x e_a + M K_a) du = -r R_l + M (-R_u,a + r R_l)
//! ```
//!
//! which replaces node a's equilibrium rows; its pattern is K's row pattern. (In gap M = I
//! and the row is plain equilibrium; in stick M = 0 and it is the kinematic constraint.)
//! The reduced system has the displacement unknowns plus the multipliers that stay: pairs
//! at nodes with a prescribed component or with several pairs (a node that two tools may
//! touch).
//!
//! A force-controlled tool adds an offset unknown `s` (see `force_control`): its column
//! enters R1 as `E_s ds` and R2 as `(E_s / r) ds`, which cancel in `R1 - r R2`, so `dl`
//! keeps the form above and node a's condensed row gains `E_s ds`. The tool's force row
//! `sum_k c_k . dl_k = -R_s` is kept, with `dl_k` substituted: it gains `-c_k K_k` on the
//! displacement columns around each eliminated node k.
//!
//! Cost: O(nnz) per iteration to build, by a slot plan recorded once per pattern (the value
//! index of every contribution, in a fixed order), so that no entry is searched for; the
//! factorization shrinks by the number of eliminated multipliers.

use super::assembly::DofMap;
use super::linear::LinearSolver;
use super::model::Model;
use super::sparse::{SparseMatrix, SparsePattern};
use crate::Result;
use std::sync::Arc;

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

/// A pair whose multiplier is eliminated.
#[derive(Clone, Debug)]
struct Eliminated {
    node: usize,
    lambda: usize,
    r: f64,
}

/// The static reduction of a model's mixed system (which multipliers go, where the rest
/// land), built once per model.
#[derive(Debug)]
pub struct Condenser {
    eliminated: Vec<Eliminated>,
    /// Full dof -> reduced dof (None: eliminated multiplier).
    reduced_index: Vec<Option<usize>>,
    /// Pattern of the reduced matrix.
    pattern: Arc<SparsePattern>,
    /// Row-wise view of the full pattern: for each row, (column, value position).
    rows: Vec<Vec<(usize, usize)>>,
    /// Rows of eliminated nodes' equilibrium equations (full index), to skip when copying.
    condensed_row: Vec<bool>,
    /// Eliminated multiplier dof -> (index in `eliminated`, component).
    owner: Vec<Option<(usize, usize)>>,
    /// Number of displacement unknowns (they come first).
    n_u: usize,
    /// Per eliminated pair, position in J of E_l = (u_a + alpha, lambda + beta).
    e_l_position: Vec<[[Option<usize>; 3]; 3]>,
    /// Per eliminated pair, position in J of the contact block (lambda + beta, u_a + g).
    e_x_position: Vec<[[Option<usize>; 3]; 3]>,
    /// The slot plan: the reduced matrix's value index of every contribution, in the order
    /// of [`Self::walk`] (u32: the reduced pattern has fewer than 2^32 entries).
    slots: Vec<u32>,
}

impl Condenser {
    /// `None` when nothing can be eliminated (penalty, or no eligible pair).
    pub fn new(
        model: &Model,
        dofs: &DofMap,
        full: &SparsePattern,
        is_fixed: &[bool],
    ) -> Option<Self> {
        let n_u = 3 * dofs.n_nodes;
        let mut pairs_at_node = vec![0usize; dofs.n_nodes];
        for c in &model.contacts {
            for &node in &c.candidates {
                pairs_at_node[node] += 1;
            }
        }
        let mut eliminated = Vec::new();
        for (c, contact) in model.contacts.iter().enumerate() {
            let Some(off) = dofs.lambda_offset[c] else {
                continue;
            };
            for (k, &node) in contact.candidates.iter().enumerate() {
                let free = (0..3).all(|i| !is_fixed[3 * node + i]);
                if pairs_at_node[node] == 1 && free {
                    eliminated.push(Eliminated {
                        node,
                        lambda: off + 3 * k,
                        r: contact.r[k],
                    });
                }
            }
        }
        if eliminated.is_empty() {
            return None;
        }
        let mut gone = vec![false; full.n];
        let mut condensed_row = vec![false; full.n];
        let mut owner = vec![None; full.n];
        for (index, e) in eliminated.iter().enumerate() {
            for i in 0..3 {
                gone[e.lambda + i] = true;
                owner[e.lambda + i] = Some((index, i));
                condensed_row[3 * e.node + i] = true;
            }
        }
        let mut reduced_index = vec![None; full.n];
        let mut next = 0;
        for (d, g) in gone.iter().enumerate() {
            if !g {
                reduced_index[d] = Some(next);
                next += 1;
            }
        }
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
        // A kept row with an eliminated column (the force row of a force-controlled tool)
        // receives the substitution dl = rhs1 - K_a du: the pattern of K_a's row.
        for (r, row) in rows.iter().enumerate() {
            let (Some(ri), false) = (reduced_index[r], condensed_row[r]) else {
                continue;
            };
            for &(c, _) in row {
                if let Some((index, beta)) = owner[c] {
                    for &(col, _) in &rows[3 * eliminated[index].node + beta] {
                        if let Some(ci) = reduced_index[col] {
                            entries.push((ri, ci));
                        }
                    }
                }
            }
        }
        let positions = |row: &dyn Fn(&Eliminated, usize) -> usize,
                         col: &dyn Fn(&Eliminated, usize) -> usize| {
            eliminated
                .iter()
                .map(|e| {
                    std::array::from_fn(|a| {
                        std::array::from_fn(|b| full.position(row(e, a), col(e, b)))
                    })
                })
                .collect::<Vec<[[Option<usize>; 3]; 3]>>()
        };
        let e_l_position = positions(&|e, a| 3 * e.node + a, &|e, b| e.lambda + b);
        let e_x_position = positions(&|e, a| e.lambda + a, &|e, b| 3 * e.node + b);
        let full_groups = elimination_groups(model, dofs);
        let mut groups = vec![0; next];
        for (d, ri) in reduced_index.iter().enumerate() {
            if let Some(ri) = ri {
                groups[*ri] = full_groups[d];
            }
        }
        let pattern = Arc::new(SparsePattern::from_entries(next, entries).with_groups(groups));
        if pattern.nnz() > u32::MAX as usize {
            return None;
        }
        let mut condenser = Condenser {
            owner,
            n_u,
            eliminated,
            reduced_index,
            pattern,
            rows,
            condensed_row,
            e_l_position,
            e_x_position,
            slots: Vec::new(),
        };
        // Record the plan: the walk only depends on the pattern, so zero values will do.
        let zeros = vec![0.0; full.nnz()];
        let mut rhs = vec![0.0; next];
        let mut slots = Vec::new();
        let reduced = condenser.pattern.clone();
        condenser.walk(&zeros, &vec![0.0; full.n], &mut rhs, |r, c, _| {
            let k = reduced
                .position(r, c)
                .expect("the reduced pattern holds every contribution");
            slots.push(k as u32);
        });
        condenser.slots = slots;
        Some(condenser)
    }

    pub fn eliminated_count(&self) -> usize {
        3 * self.eliminated.len()
    }

    /// Adds `factor * K_a[beta]` to reduced row `ri`: K_a is the equilibrium row of the
    /// eliminated node minus r times its multiplier row (which removes the contact block
    /// E_x and a tool offset's column E_s, leaving the element stiffness).
    fn add_k_row(
        &self,
        emit: &mut impl FnMut(usize, usize, f64),
        j: &[f64],
        ri: usize,
        e: &Eliminated,
        beta: usize,
        factor: f64,
    ) {
        for &(col, k) in &self.rows[3 * e.node + beta] {
            if let Some(ci) = self.reduced_index[col] {
                emit(ri, ci, factor * j[k]);
            }
        }
        for &(col, k) in &self.rows[e.lambda + beta] {
            if let Some(ci) = self.reduced_index[col] {
                emit(ri, ci, -factor * e.r * j[k]);
            }
        }
    }

    /// Walks every contribution to the reduced matrix, in a fixed order that depends only
    /// on the pattern, calling `emit(row, col, value)`, and fills the reduced right-hand
    /// side. The slot plan is this walk recorded once; the numeric pass replays it.
    fn walk(
        &self,
        j: &[f64],
        residual: &[f64],
        rhs: &mut [f64],
        mut emit: impl FnMut(usize, usize, f64),
    ) {
        let n = self.rows.len();
        // Rows that stay as they are.
        for row in 0..n {
            let Some(ri) = self.reduced_index[row] else {
                continue;
            };
            if self.condensed_row[row] {
                continue;
            }
            rhs[ri] = -residual[row];
            for &(col, k) in &self.rows[row] {
                if let Some(ci) = self.reduced_index[col] {
                    emit(ri, ci, j[k]);
                } else if let Some((index, beta)) = self.owner[col] {
                    // c dl_beta with dl_beta = rhs1_beta - K_a[beta] du.
                    let e = &self.eliminated[index];
                    let (ua, l, c) = (3 * e.node, e.lambda, j[k]);
                    rhs[ri] -= c * (-residual[ua + beta] + e.r * residual[l + beta]);
                    self.add_k_row(&mut emit, j, ri, e, beta, -c);
                }
            }
        }
        // Condensed rows: (E_x e_a + M K_a) du + E_s ds = -r R_l + M (-R_u,a + r R_l).
        for (index, e) in self.eliminated.iter().enumerate() {
            let (ua, l, r) = (3 * e.node, e.lambda, e.r);
            let mut m = [[0.0; 3]; 3];
            for (alpha, m_row) in m.iter_mut().enumerate() {
                for (beta, m_ab) in m_row.iter_mut().enumerate() {
                    let e_l = self.e_l_position[index][alpha][beta].map_or(0.0, |k| j[k]);
                    *m_ab = f64::from(u8::from(alpha == beta)) - e_l;
                }
            }
            let rhs1: [f64; 3] = std::array::from_fn(|b| -residual[ua + b] + r * residual[l + b]);
            for alpha in 0..3 {
                let ri = self.reduced_index[ua + alpha].expect("displacements stay");
                rhs[ri] =
                    -r * residual[l + alpha] + (0..3).map(|b| m[alpha][b] * rhs1[b]).sum::<f64>();
                for (beta, &m_ab) in m[alpha].iter().enumerate() {
                    self.add_k_row(&mut emit, j, ri, e, beta, m_ab);
                }
                // r S: E_x on the node's own displacements (and E_s on a tool offset).
                for &(col, k) in &self.rows[l + alpha] {
                    if let Some(ci) = self.reduced_index[col] {
                        emit(ri, ci, r * j[k]);
                    }
                }
            }
        }
    }

    /// The reduced matrix and right-hand side, built by replaying the slot plan: one linear
    /// pass over the contributions, no search. O(contributions) = O(nnz(J)) per call.
    pub fn reduced_system(&self, j: &SparseMatrix, residual: &[f64]) -> (SparseMatrix, Vec<f64>) {
        let mut a = SparseMatrix::zeros(self.pattern.clone());
        let mut rhs = vec![0.0; self.pattern.n];
        let mut slots = self.slots.iter();
        self.walk(&j.values, residual, &mut rhs, |_, _, v| {
            let k = *slots.next().expect("the plan covers every contribution");
            a.values[k as usize] += v;
        });
        (a, rhs)
    }

    /// The same reduced system with every contribution placed by a binary search in the
    /// pattern (the construction before the slot plan): the reference the plan is tested
    /// against.
    #[doc(hidden)]
    pub fn reduced_system_by_search(
        &self,
        j: &SparseMatrix,
        residual: &[f64],
    ) -> (SparseMatrix, Vec<f64>) {
        let mut a = SparseMatrix::zeros(self.pattern.clone());
        let mut rhs = vec![0.0; self.pattern.n];
        self.walk(&j.values, residual, &mut rhs, |r, c, v| a.add(r, c, v));
        (a, rhs)
    }

    /// Solves `J dx = -residual` through the reduced system; returns the full dx. The
    /// unknowns `border` (full indices, never eliminated multipliers) are solved by the
    /// linear solver's Schur complement.
    pub fn solve(
        &self,
        j: &SparseMatrix,
        residual: &[f64],
        border: &[usize],
        linear: &mut dyn LinearSolver,
    ) -> Result<Vec<f64>> {
        let n = j.pattern.n;
        let (a, mut rhs) = self.reduced_system(j, residual);
        let reduced_border: Vec<usize> = border
            .iter()
            .filter_map(|&d| self.reduced_index[d])
            .collect();
        linear.solve_bordered(&a, &mut rhs, &reduced_border)?;
        let mut dx = vec![0.0; n];
        for (d, ri) in self.reduced_index.iter().enumerate() {
            if let Some(ri) = ri {
                dx[d] = rhs[*ri];
            }
        }
        // Back-substitution: dl = (-R_u,a + r R_l) - K_a du.
        for (index, e) in self.eliminated.iter().enumerate() {
            let (ua, l, r) = (3 * e.node, e.lambda, e.r);
            for beta in 0..3 {
                let mut k_du = 0.0;
                for &(col, k) in &self.rows[ua + beta] {
                    if col < self.n_u {
                        k_du += j.values[k] * dx[col];
                    }
                }
                // Remove the contact block's own contribution E_x du_a.
                for g in 0..3 {
                    let e_x = self.e_x_position[index][beta][g].map_or(0.0, |k| j.values[k]);
                    k_du -= r * e_x * dx[ua + g];
                }
                dx[l + beta] = -residual[ua + beta] + r * residual[l + beta] - k_du;
            }
        }
        Ok(dx)
    }
}
