//! The multiplier components whose equation is replaced by `lambda_k = 0` (a unit row of
//! the Jacobian, residual `lambda_k`): those the linearised system leaves undetermined.
//!
//! The column of a multiplier component `lambda_j` of pair `p` (node `a`, augmentation
//! `r`, tool `c`) holds, once the prescribed displacement rows are unit rows, only
//!
//! ```text
//! dF_equi,i  / dlambda_j   in node a's equilibrium rows i that are not prescribed
//!                          (natural scale 1: a sticking pair puts I there)
//! dF_suppl,i / dlambda_j   in the pair's three multiplier rows (scale 1/r: gap puts -I/r)
//! -a_j / r_s               in tool c's force row, while its force equation holds
//!                          (force_control.rs; scale 1/r_s)
//! ```
//!
//! and nothing else: a multiplier enters only its own pair's operator and its tool's force
//! row. Two rules pick the components that get the unit row.
//!
//! **Stick with a prescribed component** (`stick_rows`). A sticking pair has
//! `F_equi = sigma`, `F_suppl = -(lambda - sigma) / r = -g` (free of `lambda`), so the column
//! of `lambda_j` is `e_j` in node a's equilibrium row j only; with that row prescribed the
//! tangential force along `j` and the support reaction are one unknown. The support carries
//! it: `lambda_j = 0`. Exact on symmetry planes and in plane strain, where the tool normal
//! lies in the constrained plane.
//!
//! **Empty column** (`empty_columns`). Every entry of the column above is at most
//! [`EMPTY_COLUMN_TOLERANCE`] times its row's natural scale. The case met (issue 47, the
//! U-channel's release with Chaboche hardening): a pair slipping exactly on the Coulomb cone
//! (`|sigma_t| = mu |sigma_n|`: it slipped in the last increment and has not moved since),
//! with `n_j = 0`, `t_j = 0` and node a's component `j` prescribed (plane strain). Slip
//! gives `dF_equi/dlambda = n n^T - mu sigma_n (I - t t^T)(I - n n^T) / |sigma_t|`, whose
//! column j is `c e_j`, `c = mu |sigma_n| / |sigma_t|`, in the prescribed row only, and
//! `dF_suppl,j/dlambda_j = (c - 1) / r`, zero on the cone. The stick side's column is zero
//! too, so every element of the generalised (Clarke) Jacobian there has this column empty:
//! no choice of element gives a regular matrix, and the rule is not a choice of element but
//! a choice of equation for an unknown the linearisation leaves free.
//!
//! Why `lambda_j = 0` is a valid equation and the resulting step a valid Newton step. With
//! `n_j = 0`, `sigma_j = lambda_j + r Delta_j` (`Delta_j` the slip increment along `j`, zero
//! for a prescribed component the tool does not move along), and the slip law's own row
//! reads `F_suppl,j = ((c - 1) lambda_j + c r Delta_j) / r`: off the cone its only root is
//! `lambda_j = 0`, on it every `lambda_j` is a root, `0` the one continuous with the
//! neighbouring slip states. At such a state the Jacobian with an empty column `j` has rank
//! `n - 1` at most: no step satisfies all its rows. The rule keeps every other row and
//! column as they are and swaps the pair's own row `j`, whose entries besides its vanishing
//! diagonal are the derivatives of `F_suppl,j = (c sigma_j - lambda_j) / r` through `t_j`
//! (proportional to `sigma_j`, zero at `lambda_j = 0`), `c` in the prescribed column `j`
//! (whose step is zero) and, on a tool whose normal turns across `j`, curvature terms
//! `c (d - n . delta) dn_j/dx` (none on a surface extruded along `j`, as in plane strain).
//! The step then satisfies every other row, as a Newton step of the system without the free
//! unknown does, and sets the free component to `-lambda_j` (to zero). Wherever no column is
//! empty no row changes, so every other Jacobian and residual is the one before this rule
//! bit for bit (the finite-difference tests, whose states are off the cone, cannot move).
//!
//! The threshold. On the cone the diagonal `(c - 1)/r` is the round-off of a quotient of
//! norms, `|c - 1| <= ~10 eps = 2e-15` for a multiplier stored on the cone (the U-channel's
//! holder node: exactly 0; its neighbour -8.5e-20); the equilibrium entries off the
//! prescribed row are `-c t_i t_j`, exactly 0 for `lambda_j = 0`. [`EMPTY_COLUMN_TOLERANCE`]
//! = 1e-12 leaves 500 times that round-off for a state a few operations off the cone, and
//! is 100 times below the symmetric LU's relative pivot tolerance (`PIVOT_TOLERANCE` =
//! 1e-10): a column the rule keeps has an entry the factorization can tell from round-off.
//! A column that is small but above it (a node 1e-12 or more off the cone) keeps its own
//! equation, whose root is `lambda_j = 0` as well.
//!
//! The decision is made from the operator outputs (`Evaluation::nodal`), not from the
//! assembled matrix, so that a residual-only evaluation (line search) and the Jacobian
//! completed afterwards choose the same equations as a full evaluation, bit for bit.
//! O(pairs) per evaluation.

use crate::contact::{ContactStatus, NodalContact};
use crate::geometry::Projection;
use crate::solver::assembly::dofs::DofMap;
use crate::solver::assembly::force_control;
use crate::solver::model::Model;

/// Largest entry, relative to its row's natural scale, of a multiplier column counted as
/// empty (see the module doc for why 1e-12).
pub const EMPTY_COLUMN_TOLERANCE: f64 = 1e-12;

/// The components `k` of a pair (operator output `result`, candidate `node`) that stick with
/// node component `k` prescribed (`is_fixed`, indexed by unknown).
pub(super) fn stick_rows<'a>(
    result: &'a NodalContact,
    node: usize,
    is_fixed: &'a [bool],
) -> impl Iterator<Item = usize> + 'a {
    let stick = result.status == ContactStatus::Stick;
    (0..3).filter(move |&k| stick && is_fixed[3 * node + k])
}

/// The multiplier unknowns whose column is empty (see the module doc) at the operator
/// outputs `nodal` of an evaluation at time `time`, those of [`stick_rows`] left out (they
/// already have their unit row), in the order of tools, candidates and components.
pub(super) fn empty_columns(
    model: &Model,
    dofs: &DofMap,
    time: f64,
    is_fixed: &[bool],
    nodal: &[Vec<(NodalContact, Option<Projection>)>],
) -> Vec<usize> {
    let mut empty = Vec::new();
    for (c, contact) in model.contacts.iter().enumerate() {
        let Some(off) = dofs.lambda_offset[c] else {
            continue;
        };
        // The force row's entries in the multiplier columns, -axis / r_s, while the force
        // equation holds (force_control::add_force_rows); relative to its scale 1/r_s.
        let force_axis = contact
            .tool
            .force_control
            .as_ref()
            .filter(|_| {
                dofs.tool_offset[c].is_some()
                    && force_control::active(model, c, time)
                    && !force_control::approaching(model, c, time, nodal)
            })
            .map(|fc| fc.axis);
        for (k, &node) in contact.candidates.iter().enumerate() {
            let result = &nodal[c][k].0;
            let r = contact.r[k];
            for j in 0..3 {
                if result.status == ContactStatus::Stick && is_fixed[3 * node + j] {
                    continue; // a stick row already
                }
                let equilibrium = (0..3)
                    .filter(|&i| !is_fixed[3 * node + i])
                    .map(|i| result.equi_lambda[(i, j)].abs())
                    .fold(0.0, f64::max);
                let multiplier = (0..3)
                    .map(|i| r * result.suppl_lambda[(i, j)].abs())
                    .fold(0.0, f64::max);
                let force = force_axis.map_or(0.0, |a| a[j].abs());
                if equilibrium.max(multiplier).max(force) <= EMPTY_COLUMN_TOLERANCE {
                    empty.push(off + 3 * k + j);
                }
            }
        }
    }
    empty
}
