//! Precomputed value positions ("slots") of every element and contact entry in the fixed
//! sparsity pattern, so that assembly places an entry by an index instead of a binary
//! search in its column.
//!
//! # Element stiffnesses: a gather, in element order
//!
//! The element loop writes each element's `24 x 24` stiffness into one flat buffer
//! (element `e`, column-major entry `l` at `576 e + l`). For every value position `k` of the
//! pattern the map lists its contributors in that buffer, in increasing element order
//! (CSR: `gather_src[gather_ptr[k]..gather_ptr[k + 1]]`). Assembly is then
//!
//! ```text
//! values[k] = Σ_{s in contributors(k)} buffer[s]      (summed in element order)
//! ```
//!
//! which is the same sum, in the same order, as scattering element by element, so the
//! result is bit-for-bit that of a serial scatter; and since every `k` is independent,
//! contiguous ranges of `values` are gathered on separate threads with results that do not
//! depend on the thread count. Cost: building the map, one search per element entry, once
//! per pattern (`O(E 576 log nnz_col)`); each assembly, `O(E 576)` indexed adds and no
//! search. Memory: one `u32` per element entry plus one offset per value position.
//!
//! # Contact nodal blocks
//!
//! Per (tool, candidate) pair the 36 positions of its four `3 x 3` blocks: node-node,
//! node-multiplier, multiplier-node, multiplier-multiplier (the last three only under the
//! augmented Lagrangian).
//!
//! # Force-controlled tools
//!
//! Per force-controlled tool (offset unknown `s`) the positions of its offset column (per
//! candidate: three equilibrium rows, three multiplier rows), its force row (per candidate:
//! three multiplier columns) and its diagonal `(s, s)` (the approach equation).

use crate::element::hex8::DOFS;
use crate::solver::model::Model;
use crate::solver::sparse::SparsePattern;

/// Entries of one element stiffness.
pub const ELEMENT_ENTRIES: usize = DOFS * DOFS;

/// Positions of a contact pair's blocks, each `3 x 3` row-major:
/// `[node-node, node-lambda, lambda-node, lambda-lambda]`.
pub type ContactSlots = [[usize; 9]; 4];

/// Positions of one force-controlled tool's entries; see the module docs.
#[derive(Debug)]
pub struct ForceControlSlots {
    /// Per candidate: `(3 node + i, s)` for `i < 3`, then `(l + i, s)` (multipliers at `l`).
    pub column: Vec<[usize; 6]>,
    /// Per candidate: `(s, l + j)` for `j < 3`.
    pub row: Vec<[usize; 3]>,
    /// `(s, s)`.
    pub diagonal: usize,
}

/// Value positions of the element and contact entries of one pattern; see the module docs.
#[derive(Debug)]
pub struct AssemblySlots {
    /// The pattern these slots index (compared by address before use).
    pattern: std::sync::Arc<SparsePattern>,
    gather_ptr: Vec<usize>,
    gather_src: Vec<u32>,
    /// Per tool, per candidate.
    pub contact: Vec<Vec<ContactSlots>>,
    /// Per tool: `Some` for a force-controlled tool.
    pub force_control: Vec<Option<ForceControlSlots>>,
}

impl AssemblySlots {
    /// Builds the slots of `model`'s elements and contact pairs in `pattern` (which must
    /// contain them: it is built from the same model by `DofMap::pattern`), with the first
    /// multiplier dof of each tool in `lambda_offset` (None: penalty) and the offset unknown
    /// of each force-controlled tool in `tool_offset`.
    pub fn new(
        model: &Model,
        lambda_offset: &[Option<usize>],
        tool_offset: &[Option<usize>],
        pattern: std::sync::Arc<SparsePattern>,
    ) -> Self {
        let position = |r: usize, c: usize| {
            pattern
                .position(r, c)
                .expect("element and contact entries are in the pattern built from the model")
        };
        let hexes = &model.mesh.hexes;
        assert!(
            hexes.len() * ELEMENT_ENTRIES <= u32::MAX as usize,
            "too many element entries for 32-bit gather indices"
        );
        let nnz = pattern.nnz();
        let mut element_slots = Vec::with_capacity(hexes.len() * ELEMENT_ENTRIES);
        let mut count = vec![0usize; nnz + 1];
        for hex in hexes {
            // Column-major over the element's dofs, as the stiffness buffer is stored.
            for col in 0..DOFS {
                let gc = 3 * hex[col / 3] + col % 3;
                for row in 0..DOFS {
                    let k = position(3 * hex[row / 3] + row % 3, gc);
                    element_slots.push(k);
                    count[k + 1] += 1;
                }
            }
        }
        for k in 0..nnz {
            count[k + 1] += count[k];
        }
        let gather_ptr = count.clone();
        let mut next = count;
        let mut gather_src = vec![0u32; element_slots.len()];
        // Increasing source index = increasing element: each list is in element order.
        for (src, &k) in element_slots.iter().enumerate() {
            gather_src[next[k]] = src as u32;
            next[k] += 1;
        }
        let contact = model
            .contacts
            .iter()
            .enumerate()
            .map(|(c, contact)| {
                contact
                    .candidates
                    .iter()
                    .enumerate()
                    .map(|(k, &node)| {
                        let mut s = [[usize::MAX; 9]; 4];
                        let lam = lambda_offset[c].map(|off| off + 3 * k);
                        for i in 0..3 {
                            for j in 0..3 {
                                s[0][3 * i + j] = position(3 * node + i, 3 * node + j);
                                if let Some(l) = lam {
                                    s[1][3 * i + j] = position(3 * node + i, l + j);
                                    s[2][3 * i + j] = position(l + i, 3 * node + j);
                                    s[3][3 * i + j] = position(l + i, l + j);
                                }
                            }
                        }
                        s
                    })
                    .collect()
            })
            .collect();
        let force_control = model
            .contacts
            .iter()
            .enumerate()
            .map(|(c, contact)| {
                let (s, off) = (tool_offset[c]?, lambda_offset[c]?);
                let column = contact
                    .candidates
                    .iter()
                    .enumerate()
                    .map(|(k, &node)| {
                        let l = off + 3 * k;
                        std::array::from_fn(|i| {
                            if i < 3 {
                                position(3 * node + i, s)
                            } else {
                                position(l + i - 3, s)
                            }
                        })
                    })
                    .collect();
                let row = (0..contact.candidates.len())
                    .map(|k| std::array::from_fn(|j| position(s, off + 3 * k + j)))
                    .collect();
                Some(ForceControlSlots {
                    column,
                    row,
                    diagonal: position(s, s),
                })
            })
            .collect();
        AssemblySlots {
            pattern,
            gather_ptr,
            gather_src,
            contact,
            force_control,
        }
    }

    /// Whether these slots index `pattern` (the same allocation).
    pub fn indexes(&self, pattern: &std::sync::Arc<SparsePattern>) -> bool {
        std::sync::Arc::ptr_eq(&self.pattern, pattern)
    }

    /// `values[k] = Σ buffer[s]` over the element contributions of every position `k`
    /// (overwriting `values`), on `threads` threads over contiguous ranges of positions.
    /// `stiffness` is the element loop's buffer, `576` column-major entries per element.
    /// The result does not depend on `threads`.
    pub fn gather_elements(&self, stiffness: &[f64], values: &mut [f64], threads: usize) {
        // Below this many entries a thread costs more than it saves.
        self.gather_in_blocks(stiffness, values, threads, 1 << 16);
    }

    fn gather_in_blocks(
        &self,
        stiffness: &[f64],
        values: &mut [f64],
        threads: usize,
        min_parallel_entries: usize,
    ) {
        debug_assert_eq!(values.len() + 1, self.gather_ptr.len());
        let gather = |first: usize, out: &mut [f64]| {
            for (i, v) in out.iter_mut().enumerate() {
                let k = first + i;
                let mut sum = 0.0;
                for &s in &self.gather_src[self.gather_ptr[k]..self.gather_ptr[k + 1]] {
                    sum += stiffness[s as usize];
                }
                *v = sum;
            }
        };
        if threads <= 1 || self.gather_src.len() < min_parallel_entries {
            gather(0, values);
            return;
        }
        let block = values.len().div_ceil(threads);
        std::thread::scope(|scope| {
            for (i, chunk) in values.chunks_mut(block).enumerate() {
                let gather = &gather;
                scope.spawn(move || gather(i * block, chunk));
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;
    use crate::material::LinearElastic;
    use crate::mesh::Mesh;
    use crate::solver::assembly::DofMap;
    use crate::solver::sparse::SparseMatrix;
    use std::sync::Arc;

    /// The gather equals the element-by-element scatter by binary search, bit for bit
    /// (same sums in the same order), on 1, 2, 3 and 5 threads.
    #[test]
    fn gather_equals_the_scatter_by_search() {
        let mesh = Mesh::block(Vec3::zeros(), Vec3::new(3.0, 2.0, 1.0), [3, 2, 2]).unwrap();
        let model = Model::new(mesh, Arc::new(LinearElastic::new(1.0, 0.3).unwrap())).unwrap();
        let dofs = DofMap::new(&model);
        let pattern = Arc::new(dofs.pattern(&model));
        let slots = AssemblySlots::new(
            &model,
            &dofs.lambda_offset,
            &dofs.tool_offset,
            pattern.clone(),
        );
        assert!(slots.indexes(&pattern));
        assert!(!slots.indexes(&Arc::new((*pattern).clone())));
        let n_elem = model.mesh.hexes.len();
        let mut seed = 3u64;
        let buffer: Vec<f64> = (0..n_elem * ELEMENT_ENTRIES)
            .map(|_| {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.3
            })
            .collect();
        let mut expected = SparseMatrix::zeros(pattern.clone());
        for (e, hex) in model.mesh.hexes.iter().enumerate() {
            for col in 0..DOFS {
                for row in 0..DOFS {
                    expected.add(
                        3 * hex[row / 3] + row % 3,
                        3 * hex[col / 3] + col % 3,
                        buffer[e * ELEMENT_ENTRIES + col * DOFS + row],
                    );
                }
            }
        }
        for threads in [1, 2, 3, 5] {
            let mut values = vec![f64::NAN; pattern.nnz()];
            slots.gather_in_blocks(&buffer, &mut values, threads, 0);
            assert!(
                values
                    .iter()
                    .zip(&expected.values)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{threads} threads"
            );
        }
    }
}
