//! The unknowns' layout: 3 displacements per node, then 3 multipliers per (tool, candidate
//! node) pair under the augmented Lagrangian, then one offset per force-controlled tool;
//! the sparsity pattern of the system on them (element blocks, node-multiplier couplings,
//! the force-controlled tools' rows and columns, the whole diagonal) and, built once, the
//! position of every assembled entry in it (`slots`).

use crate::contact::Enforcement;
use crate::solver::assembly::slots::AssemblySlots;
use crate::solver::model::Model;
use crate::solver::sparse::SparsePattern;
use std::sync::{Arc, OnceLock};

/// Where each unknown lives.
#[derive(Clone, Debug)]
pub struct DofMap {
    pub n_nodes: usize,
    /// First multiplier dof of each contact (tool) block, or None under penalty.
    pub lambda_offset: Vec<Option<usize>>,
    /// Offset unknown of each force-controlled tool (after all multipliers), see
    /// `force_control`.
    pub tool_offset: Vec<Option<usize>>,
    pub n_dofs: usize,
    /// Value positions of the element and contact entries in [`Self::pattern`], built on
    /// first use.
    slots: OnceLock<Arc<AssemblySlots>>,
}

impl DofMap {
    pub fn new(model: &Model) -> Self {
        let n_nodes = model.mesh.nodes.len();
        let mut next = 3 * n_nodes;
        let lambda_offset = model
            .contacts
            .iter()
            .map(|c| match model.settings.contact.enforcement {
                Enforcement::AugmentedLagrangian => {
                    let off = next;
                    next += 3 * c.candidates.len();
                    Some(off)
                }
                Enforcement::Penalty => None,
            })
            .collect::<Vec<_>>();
        let tool_offset = allocate_tool_offsets(model, &lambda_offset, &mut next);
        DofMap {
            n_nodes,
            lambda_offset,
            tool_offset,
            n_dofs: next,
            slots: OnceLock::new(),
        }
    }

    /// The assembly slots of `pattern` (built from this map by [`Self::pattern`]): computed
    /// once and kept; a different pattern gets its own, uncached.
    pub(super) fn slots(&self, model: &Model, pattern: &Arc<SparsePattern>) -> Arc<AssemblySlots> {
        let build = || {
            Arc::new(AssemblySlots::new(
                model,
                &self.lambda_offset,
                &self.tool_offset,
                pattern.clone(),
            ))
        };
        let cached = self.slots.get_or_init(build);
        if cached.indexes(pattern) {
            cached.clone()
        } else {
            build()
        }
    }

    pub fn pattern(&self, model: &Model) -> SparsePattern {
        let mut entries = Vec::new();
        for hex in &model.mesh.hexes {
            for &a in hex {
                for &b in hex {
                    for i in 0..3 {
                        for j in 0..3 {
                            entries.push((3 * a + i, 3 * b + j));
                        }
                    }
                }
            }
        }
        for (c, contact) in model.contacts.iter().enumerate() {
            let Some(off) = self.lambda_offset[c] else {
                continue;
            };
            for (k, &node) in contact.candidates.iter().enumerate() {
                let l = off + 3 * k;
                for i in 0..3 {
                    for j in 0..3 {
                        entries.push((3 * node + i, l + j));
                        entries.push((l + i, 3 * node + j));
                        entries.push((l + i, l + j));
                    }
                }
            }
        }
        tool_offset_entries(model, self, &mut entries);
        for d in 0..self.n_dofs {
            entries.push((d, d));
        }
        SparsePattern::from_entries(self.n_dofs, entries)
    }
}

/// Allocates the offset unknowns of force-controlled tools after `next`: one per such tool
/// that has multipliers (`force_control`).
fn allocate_tool_offsets(
    model: &Model,
    lambda_offset: &[Option<usize>],
    next: &mut usize,
) -> Vec<Option<usize>> {
    model
        .contacts
        .iter()
        .zip(lambda_offset)
        .map(|(c, l)| match (&c.tool.force_control, l) {
            (Some(_), Some(_)) => {
                *next += 1;
                Some(*next - 1)
            }
            _ => None,
        })
        .collect()
}

/// Sparsity entries of the force-controlled tools' offset unknowns: the column (equilibrium and multiplier rows of
/// every candidate) and the row (every multiplier); the diagonal is added by the caller.
fn tool_offset_entries(model: &Model, dofs: &DofMap, entries: &mut Vec<(usize, usize)>) {
    for (c, contact) in model.contacts.iter().enumerate() {
        let (Some(s), Some(off)) = (dofs.tool_offset[c], dofs.lambda_offset[c]) else {
            continue;
        };
        for (k, &node) in contact.candidates.iter().enumerate() {
            let l = off + 3 * k;
            for i in 0..3 {
                entries.push((3 * node + i, s));
                entries.push((l + i, s));
                entries.push((s, l + i));
            }
        }
    }
}
