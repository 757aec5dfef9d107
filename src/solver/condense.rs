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
//! Cost: O(nnz) per iteration to build; the factorization shrinks by the number of
//! eliminated multipliers.

use super::assembly::DofMap;
use super::linear::LinearSolver;
use super::model::Model;
use super::sparse::{SparseMatrix, SparsePattern};
use crate::Result;
use std::sync::Arc;

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
        Some(Condenser {
            owner,
            n_u,
            eliminated,
            reduced_index,
            pattern: Arc::new(SparsePattern::from_entries(next, entries)),
            rows,
            condensed_row,
        })
    }

    pub fn eliminated_count(&self) -> usize {
        3 * self.eliminated.len()
    }

    /// Adds `factor * K_a[beta]` to reduced row `ri`: K_a is the equilibrium row of the
    /// eliminated node minus r times its multiplier row (which removes the contact block
    /// E_x and a tool offset's column E_s, leaving the element stiffness).
    fn add_k_row(
        &self,
        a: &mut SparseMatrix,
        j: &SparseMatrix,
        ri: usize,
        e: &Eliminated,
        beta: usize,
        factor: f64,
    ) {
        for &(col, k) in &self.rows[3 * e.node + beta] {
            if let Some(ci) = self.reduced_index[col] {
                a.add(ri, ci, factor * j.values[k]);
            }
        }
        for &(col, k) in &self.rows[e.lambda + beta] {
            if let Some(ci) = self.reduced_index[col] {
                a.add(ri, ci, -factor * e.r * j.values[k]);
            }
        }
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
        let mut a = SparseMatrix::zeros(self.pattern.clone());
        let mut rhs = vec![0.0; self.pattern.n];
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
                    a.add(ri, ci, j.values[k]);
                } else if let Some((index, beta)) = self.owner[col] {
                    // c dl_beta with dl_beta = rhs1_beta - K_a[beta] du.
                    let e = &self.eliminated[index];
                    let (ua, l, c) = (3 * e.node, e.lambda, j.values[k]);
                    rhs[ri] -= c * (-residual[ua + beta] + e.r * residual[l + beta]);
                    self.add_k_row(&mut a, j, ri, e, beta, -c);
                }
            }
        }
        // Condensed rows: (E_x e_a + M K_a) du + E_s ds = -r R_l + M (-R_u,a + r R_l).
        let at = |r: usize, c: usize| j.pattern.position(r, c).map_or(0.0, |k| j.values[k]);
        for e in &self.eliminated {
            let (ua, l, r) = (3 * e.node, e.lambda, e.r);
            let mut m = [[0.0; 3]; 3];
            for (alpha, m_row) in m.iter_mut().enumerate() {
                for (beta, m_ab) in m_row.iter_mut().enumerate() {
                    *m_ab = f64::from(u8::from(alpha == beta)) - at(ua + alpha, l + beta);
                }
            }
            let rhs1: Vec<f64> = (0..3)
                .map(|b| -residual[ua + b] + r * residual[l + b])
                .collect();
            for alpha in 0..3 {
                let ri = self.reduced_index[ua + alpha].expect("displacements stay");
                rhs[ri] =
                    -r * residual[l + alpha] + (0..3).map(|b| m[alpha][b] * rhs1[b]).sum::<f64>();
                for (beta, &m_ab) in m[alpha].iter().enumerate() {
                    self.add_k_row(&mut a, j, ri, e, beta, m_ab);
                }
                // r S: E_x on the node's own displacements (and E_s on a tool offset).
                for &(col, k) in &self.rows[l + alpha] {
                    if let Some(ci) = self.reduced_index[col] {
                        a.add(ri, ci, r * j.values[k]);
                    }
                }
            }
        }
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
        for e in &self.eliminated {
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
                    k_du -= r * at(l + beta, ua + g) * dx[ua + g];
                }
                dx[l + beta] = -residual[ua + beta] + r * residual[l + beta] - k_du;
            }
        }
        Ok(dx)
    }
}
