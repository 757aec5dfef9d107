//! Residual and Jacobian of the mixed (u, lambda) system for one trial state.
//!
//! Unknowns: 3 displacements per node, then 3 multipliers per (tool, candidate node) pair
//! when the augmented Lagrangian is used. Equations:
//!
//! ```text
//! R_u      = f_int(u) - f_ext(t) + sum_pairs F_equi     (per node)
//! R_lambda = F_suppl                                     (per pair)
//! ```
//!
//! Dirichlet rows are replaced by unit rows (the prescribed values are set before Newton
//! starts, so their update is zero). Cost per iteration: O(elements * 24^2 + pairs * 9)
//! for the values, plus one projection per pair.

pub mod dofs;
pub use dofs::DofMap;
pub mod force_control;
pub mod slots;
pub mod unit_rows;

use crate::contact::{
    alart_curnier, BernsteinLaw, ContactNodeState, FrictionUpdate, NodalContact, OperatorParams,
};
use crate::element::{in_element, LocalSolve};
use crate::geometry::{Mat3, Projection, Vec3};
use crate::material::PointState;
use crate::solver::assembly::slots::AssemblySlots;
use crate::solver::model::Model;
use crate::solver::sparse::{SparseMatrix, SparsePattern};
use crate::tool::pose::Pose;
use crate::{Error, Result};
use std::sync::Arc;
use std::time::Instant;

/// Threads for the elements and the factorization of the setting `threads` (0: every core).
pub(super) fn worker_threads(setting: usize) -> usize {
    match setting {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    }
}

/// Element forces and stiffnesses of one evaluation, element after element: `force[24 e..]`
/// and `stiffness[576 e..]` (column-major; a residual-only evaluation leaves it as it
/// was). Kept between the evaluations of an increment
/// ([`IncrementContext::element_buffers`]): every element overwrites its own entries, so
/// the buffers are sized, never cleared.
#[derive(Debug, Default)]
pub struct ElementBuffers {
    force: Vec<f64>,
    stiffness: Vec<f64>,
}

/// What the elements remember between the evaluations of one Newton attempt
/// ([`crate::element::Element::evaluate_remembering`]): `memory_len` numbers per element,
/// NaN until an element writes them. An attempt starts from what the last converged
/// increment left ([`ElementMemory::from`] the committed memory): the linearisation at the
/// committed state predicts the first iterate's local solves, which otherwise start cold
/// (several local iterations to the tight tolerance at every point).
#[derive(Debug, Default)]
pub struct ElementMemory(std::sync::Mutex<Vec<f64>>);

impl From<Vec<f64>> for ElementMemory {
    fn from(memory: Vec<f64>) -> Self {
        Self(std::sync::Mutex::new(memory))
    }
}

impl ElementMemory {
    /// The numbers the elements left.
    pub fn into_inner(self) -> Vec<f64> {
        self.0.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}

/// Evaluates every element at the unknowns `x`, on `threads` threads over contiguous
/// blocks of elements, writing the trial states of their integration points and each
/// element's force (and, with `tangent`, stiffness) straight into its place in
/// `buffers`, so that the assembly (and hence every result) is the same whatever the
/// thread count. Returns the number of elements whose call stopped their local solve
/// early ([`LocalSolve::Approximate`]). The first failing element in element order is the
/// one reported.
#[allow(clippy::too_many_arguments)]
fn evaluate_elements(
    model: &Model,
    x: &[f64],
    committed: &[PointState],
    trial: &mut [PointState],
    threads: usize,
    tangent: bool,
    memory: &ElementMemory,
    buffers: &mut ElementBuffers,
) -> Result<usize> {
    const D: usize = crate::element::hex8::DOFS;
    let element = model.element()?;
    let per_elem = element.point_count();
    let remembers = element.memory_len();
    let mut memory = memory.0.lock().unwrap_or_else(|e| e.into_inner());
    let memory_len = model.mesh.hexes.len() * remembers;
    if memory.len() != memory_len {
        memory.clear();
        memory.resize(memory_len, f64::NAN);
    }
    let (hexes, nodes, material) = (
        &model.mesh.hexes,
        &model.mesh.nodes,
        model.material.as_ref(),
    );
    let n_elem = hexes.len();
    buffers.force.resize(n_elem * D, 0.0);
    let force = &mut buffers.force[..];
    let stiffness: &mut [f64] = if tangent {
        buffers.stiffness.resize(n_elem * D * D, 0.0);
        &mut buffers.stiffness
    } else {
        &mut []
    };
    let evaluate_block = |first: usize,
                          trial: &mut [PointState],
                          force: &mut [f64],
                          stiffness: &mut [f64],
                          memory: &mut [f64]| {
        let mut xs = [Vec3::zeros(); 8];
        let mut us = [Vec3::zeros(); 8];
        let mut stiffness = tangent.then(|| stiffness.chunks_mut(D * D));
        let mut approximate = 0;
        for (k, (trial_e, force_e)) in trial
            .chunks_mut(per_elem)
            .zip(force.chunks_mut(D))
            .enumerate()
        {
            let e = first + k;
            for (a, &node) in hexes[e].iter().enumerate() {
                xs[a] = nodes[node];
                us[a] = Vec3::new(x[3 * node], x[3 * node + 1], x[3 * node + 2]);
            }
            let committed_e = &committed[e * per_elem..(e + 1) * per_elem];
            let stiffness_e = stiffness.as_mut().and_then(|s| s.next());
            let memory_e = &mut memory[k * remembers..(k + 1) * remembers];
            let solve = element
                .evaluate_remembering(
                    &xs,
                    &us,
                    committed_e,
                    trial_e,
                    material,
                    memory_e,
                    force_e,
                    stiffness_e,
                )
                // Any element failure inside an iterate is retryable (a smaller step
                // may pass), kept as "no convergence" without a second kind prefix.
                .map_err(|err| match in_element(err, e) {
                    err @ Error::NoConvergence { .. } => err,
                    other => Error::no_convergence(crate::error::Failure::Local, other.to_string()),
                })?;
            approximate += usize::from(solve == LocalSolve::Approximate);
        }
        Ok::<_, Error>(approximate)
    };
    // A failed evaluation leaves the memory as it was: else which elements had written
    // theirs before the failure would depend on the thread count.
    let before = (tangent && remembers > 0).then(|| memory.clone());
    // Below a few dozen elements, starting threads costs more than it saves.
    const MIN_PARALLEL_ELEMENTS: usize = 64;
    let outcome = if threads <= 1 || n_elem < MIN_PARALLEL_ELEMENTS {
        evaluate_block(0, trial, force, stiffness, &mut memory)
    } else {
        evaluate_on_threads(
            n_elem,
            threads,
            per_elem,
            remembers,
            tangent,
            trial,
            force,
            stiffness,
            &mut memory,
            &evaluate_block,
        )
    };
    if let (Err(_), Some(before)) = (&outcome, before) {
        *memory = before;
    }
    outcome
}

/// The element loop of [`evaluate_elements`] on `threads` threads, over contiguous blocks
/// of elements; the first error in element order.
#[allow(clippy::too_many_arguments)]
fn evaluate_on_threads<F>(
    n_elem: usize,
    threads: usize,
    per_elem: usize,
    remembers: usize,
    tangent: bool,
    trial: &mut [PointState],
    force: &mut [f64],
    stiffness: &mut [f64],
    memory: &mut [f64],
    evaluate_block: &F,
) -> Result<usize>
where
    F: Fn(usize, &mut [PointState], &mut [f64], &mut [f64], &mut [f64]) -> Result<usize> + Sync,
{
    const D: usize = crate::element::hex8::DOFS;
    let block = n_elem.div_ceil(threads);
    let stiffness_block = if tangent { block * D * D } else { 1 };
    let mut stiffness_chunks: Vec<&mut [f64]> = stiffness.chunks_mut(stiffness_block).collect();
    stiffness_chunks.resize_with(n_elem.div_ceil(block), Default::default);
    let mut memory_chunks: Vec<&mut [f64]> = if remembers == 0 {
        Vec::new()
    } else {
        memory.chunks_mut(block * remembers).collect()
    };
    memory_chunks.resize_with(n_elem.div_ceil(block), Default::default);
    let results: Vec<Result<usize>> = std::thread::scope(|scope| {
        let handles: Vec<_> = trial
            .chunks_mut(block * per_elem)
            .zip(force.chunks_mut(block * D))
            .zip(stiffness_chunks)
            .zip(memory_chunks)
            .enumerate()
            .map(|(i, (((trial, force), stiffness), memory))| {
                scope.spawn(move || evaluate_block(i * block, trial, force, stiffness, memory))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    results.into_iter().sum()
}

/// Wall time spent in each phase of assembly (seconds), and the evaluations made,
/// accumulated.
#[derive(Clone, Copy, Debug, Default)]
pub struct PhaseTimes {
    pub elements: f64,
    pub contact: f64,
    pub factorization_and_solve: f64,
    /// Accumulating the tool-side fields of committed increments (`ToolFields::accumulate`,
    /// issue 53): timed inside the run so that its share of the run's time is measured
    /// without a second run, whatever the host's speed does meanwhile.
    pub tool_fields: f64,
    /// Evaluations with element tangents and assembly ([`IncrementContext::evaluate`]).
    pub full_evaluations: usize,
    /// Residual-only evaluations ([`IncrementContext::evaluate_residual`]).
    pub residual_evaluations: usize,
    /// Residual-only evaluations given their Jacobian afterwards
    /// ([`IncrementContext::complete`]: element tangents and assembly, no contact pass).
    pub jacobian_completions: usize,
    /// Evaluations (full or residual-only) in which some element stopped its local solve
    /// early ([`LocalSolve::Approximate`]).
    pub approximate_evaluations: usize,
    /// Newton steps solved (a correction computed and searched along), in every attempt:
    /// those of an accepted attempt are its iterations; a failed attempt's include the step
    /// it failed in.
    pub newton_steps: usize,
}

impl PhaseTimes {
    /// Adds `other`'s times and counts.
    pub fn add(&mut self, other: &PhaseTimes) {
        self.elements += other.elements;
        self.contact += other.contact;
        self.factorization_and_solve += other.factorization_and_solve;
        self.tool_fields += other.tool_fields;
        self.full_evaluations += other.full_evaluations;
        self.residual_evaluations += other.residual_evaluations;
        self.jacobian_completions += other.jacobian_completions;
        self.approximate_evaluations += other.approximate_evaluations;
        self.newton_steps += other.newton_steps;
    }

    /// Adds `other`'s times, not its counts.
    pub fn add_times(&mut self, other: &PhaseTimes) {
        self.elements += other.elements;
        self.contact += other.contact;
        self.factorization_and_solve += other.factorization_and_solve;
        self.tool_fields += other.tool_fields;
    }

    /// The counts alone (no times), as a checkpoint keeps them.
    pub fn counts(&self) -> EvaluationCounts {
        EvaluationCounts {
            full: self.full_evaluations,
            residual_only: self.residual_evaluations,
            jacobian_completions: self.jacobian_completions,
            with_approximate_local_solves: self.approximate_evaluations,
            newton_steps: self.newton_steps,
        }
    }

    /// Sets the counts (the times stay: they are this process's own).
    pub fn set_counts(&mut self, c: &EvaluationCounts) {
        self.full_evaluations = c.full;
        self.residual_evaluations = c.residual_only;
        self.jacobian_completions = c.jacobian_completions;
        self.approximate_evaluations = c.with_approximate_local_solves;
        self.newton_steps = c.newton_steps;
    }
}

/// The evaluations and Newton steps of [`PhaseTimes`] without its times: what a run did up
/// to a committed state, carried by checkpoints so that a restarted run's summary counts
/// what the uninterrupted run counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct EvaluationCounts {
    pub full: usize,
    pub residual_only: usize,
    pub jacobian_completions: usize,
    pub with_approximate_local_solves: usize,
    pub newton_steps: usize,
}

/// Frozen contact frame of a pair (foot point and normal in the tool's frame at the start of
/// the increment), used with [`FrameUpdate::Frozen`].
#[derive(Clone, Copy, Debug)]
pub struct FrozenFrame {
    pub foot_local: Vec3,
    pub normal_local: Vec3,
}

/// Everything Newton needs from one evaluation.
pub struct Evaluation {
    pub residual: Vec<f64>,
    pub jacobian: SparseMatrix,
    pub trial_points: Vec<PointState>,
    /// Per contact, per candidate: operator output and projection (None: no projection).
    pub nodal: Vec<Vec<(NodalContact, Option<Projection>)>>,
    /// Internal forces (all dofs), for reactions and residual scaling.
    pub f_int: Vec<f64>,
    pub f_ext: Vec<f64>,
    /// Force of the supports on the body at prescribed displacement components (zero
    /// elsewhere): f_int - f_ext + contact at those rows.
    pub support_forces: Vec<f64>,
    /// The assembled element stiffness alone (before loads, contact and unit rows), kept
    /// when the context asks for it ([`IncrementContext::keep_element_jacobian`]) so that
    /// the contact part can be linearised again at the same unknowns without running the
    /// elements again ([`IncrementContext::relinearised`]).
    pub element_jacobian: Option<Vec<f64>>,
    /// Elements whose local solve stopped early ([`LocalSolve::Approximate`]): a Newton
    /// iterate may have them, a converged state may not.
    pub approximate_elements: usize,
    /// The pseudo-time evaluated at (which tools are force-controlled then).
    pub time: f64,
}

impl Evaluation {
    /// False for a residual-only evaluation ([`IncrementContext::evaluate_residual`]),
    /// whose `jacobian` holds no values.
    pub fn has_jacobian(&self) -> bool {
        self.jacobian.values.len() == self.jacobian.pattern.nnz()
    }
}

/// Inputs that stay fixed during the Newton iterations of one increment.
pub struct IncrementContext<'a> {
    pub model: &'a Model,
    pub dofs: &'a DofMap,
    pub pattern: Arc<SparsePattern>,
    pub time: f64,
    pub poses: Vec<Pose>,
    pub committed_points: &'a [PointState],
    pub committed_contact: &'a [Vec<ContactNodeState>],
    /// The committed unknowns: the offset a force-controlled tool holds outside its
    /// windows (`force_control::add_force_rows`); may be empty where no tool is held.
    pub committed_x: &'a [f64],
    pub frozen: Option<Vec<Vec<Option<FrozenFrame>>>>,
    pub is_fixed: &'a [bool],
    /// Contact status imposed per (tool, candidate) by the anti-cycling treatment.
    pub forced: Option<Vec<Vec<Option<crate::contact::ContactStatus>>>>,
    /// What the elements remember between evaluations (the solid-shell: its last
    /// linearisation, the start of its next local solve).
    pub element_memory: ElementMemory,
    /// Whether full evaluations keep their element stiffness (status prediction re-solves
    /// with other contact statuses at the same unknowns).
    pub keep_element_jacobian: bool,
    /// The element loop's output, reused by every evaluation.
    pub element_buffers: std::sync::Mutex<ElementBuffers>,
}

/// What the elements give at some unknowns: the part of an evaluation that does not depend
/// on the contact statuses.
struct ElementPart {
    /// Assembled element stiffness (no values for a residual-only evaluation).
    jacobian: SparseMatrix,
    f_int: Vec<f64>,
    trial_points: Vec<PointState>,
    approximate_elements: usize,
}

impl IncrementContext<'_> {
    /// Evaluates residual and Jacobian at displacements `u` and multipliers `lambda`
    /// (the multiplier part of the unknown vector `x = [u, lambda]`).
    pub fn evaluate(&self, x: &[f64], times: &mut PhaseTimes) -> Result<Evaluation> {
        self.evaluate_with(x, times, true)
    }

    /// Everything of [`Self::evaluate`] but the Jacobian, for line-search trials: the
    /// material update, the internal forces and the contact residual, bit for bit those of
    /// a full evaluation, with neither element tangents nor assembly. The returned
    /// `jacobian` has no values ([`Evaluation::has_jacobian`] is false): an accepted trial
    /// is evaluated again in full before Newton solves with it.
    pub fn evaluate_residual(&self, x: &[f64], times: &mut PhaseTimes) -> Result<Evaluation> {
        self.evaluate_with(x, times, false)
    }

    /// A residual-only evaluation at `x` whose elements are not run: `f_int` are their
    /// internal forces at `x` (the committed state's, kept from its converged evaluation),
    /// and loads, contact and force control are evaluated as in
    /// [`Self::evaluate_residual`]. It carries no point states and is not counted as an
    /// element evaluation.
    pub fn residual_with_forces(
        &self,
        x: &[f64],
        f_int: Vec<f64>,
        times: &mut PhaseTimes,
    ) -> Result<Evaluation> {
        let part = ElementPart {
            jacobian: SparseMatrix {
                pattern: self.pattern.clone(),
                values: Vec::new(),
            },
            f_int,
            trial_points: Vec::new(),
            approximate_elements: 0,
        };
        self.with_contact(x, part, times, false, None)
    }

    /// The Jacobian of a residual-only evaluation `eval` at the same `x`, so that an
    /// accepted line-search cut needs no second evaluation: the element tangents (the
    /// kernel run again with its tangent: the same point states) and their assembly, and
    /// the contact blocks from the operator outputs `eval` already holds (no projection,
    /// no operator), and the force-controlled tools' rows from them too. The result equals
    /// [`Self::evaluate`] at `x`, bit for bit: the same additions in the same order. An
    /// `eval` that already has its Jacobian is returned as it is.
    pub fn complete(
        &self,
        x: &[f64],
        eval: Evaluation,
        times: &mut PhaseTimes,
    ) -> Result<Evaluation> {
        if eval.has_jacobian() {
            return Ok(eval);
        }
        times.jacobian_completions += 1;
        let model = self.model;
        let t0 = Instant::now();
        let threads = worker_threads(model.settings.threads);
        let slots = self.dofs.slots(model, &self.pattern);
        let mut trial_points = self.committed_points.to_vec();
        let mut elements = self.element_buffers();
        evaluate_elements(
            model,
            x,
            self.committed_points,
            &mut trial_points,
            threads,
            true,
            &self.element_memory,
            &mut elements,
        )?;
        let mut jac = SparseMatrix::zeros(self.pattern.clone());
        slots.gather_elements(&elements.stiffness, &mut jac.values, threads);
        let element_jacobian = self.keep_element_jacobian.then(|| jac.values.clone());
        times.elements += t0.elapsed().as_secs_f64();
        // The follower loads' stiffness, in `evaluate_with`'s order (their forces are
        // already in `eval`'s residual; the scratch copy is discarded).
        if !model.follower_loads.is_empty() {
            let mut scratch = vec![0.0; 3 * self.dofs.n_nodes];
            for load in &model.follower_loads {
                let mut add = |r: usize, c: usize, v: f64| jac.add(r, c, -v);
                load.add_forces(&model.mesh, x, self.time, &mut scratch, Some(&mut add));
            }
        }
        let t1 = Instant::now();
        let mut unit = self.is_fixed.to_vec();
        for (c, contact) in model.contacts.iter().enumerate() {
            for (k, &node) in contact.candidates.iter().enumerate() {
                let result = &eval.nodal[c][k].0;
                let lam_dof = self.dofs.lambda_offset[c].map(|off| off + 3 * k);
                let fc_column = slots.force_control[c].as_ref().map(|f| &f.column[k]);
                self.add_pair_jacobian(
                    &mut jac,
                    &slots.contact[c][k],
                    fc_column,
                    result,
                    c,
                    lam_dof,
                );
                if let Some(l) = lam_dof {
                    for i in self.multiplier_unit_rows(result, node) {
                        unit[l + i] = true;
                    }
                }
            }
        }
        // The force (or approach) rows of force-controlled tools, in `with_contact`'s
        // order; their residual is already in `eval`.
        force_control::add_force_rows(
            model,
            self.dofs,
            self.time,
            x,
            self.committed_x,
            &eval.nodal,
            &slots.force_control,
            None,
            Some(&mut jac.values),
        )?;
        for d in unit_rows::empty_columns(model, self.dofs, self.time, self.is_fixed, &eval.nodal) {
            unit[d] = true;
        }
        jac.set_unit_rows(&unit);
        times.contact += t1.elapsed().as_secs_f64();
        Ok(Evaluation {
            jacobian: jac,
            trial_points,
            element_jacobian,
            ..eval
        })
    }

    /// The full evaluation at the unknowns `x` of the full evaluation `eval`, with the
    /// contact part linearised again (for other imposed statuses, `forced`), reusing
    /// `eval`'s element part: the element kernel does not run. Its residual, Jacobian,
    /// forces and contact output equal, bit for bit, those of [`Self::evaluate`] at `x`
    /// with the same `forced` (the same additions in the same order). It carries neither
    /// point states nor a kept element stiffness (both are `eval`'s, which every further
    /// re-linearisation starts from): a status-prediction re-solve only solves with it,
    /// and copying them cost the square cup 3.6 MB (F-bar 25 x 25 x 1) to 6 MB
    /// (solid-shell) per re-solve. Without a kept element stiffness in `eval`
    /// (`keep_element_jacobian` off, or no Jacobian), a full evaluation.
    pub fn relinearised(
        &self,
        x: &[f64],
        eval: &Evaluation,
        times: &mut PhaseTimes,
    ) -> Result<Evaluation> {
        let Some(values) = eval.element_jacobian.as_ref() else {
            return self.evaluate(x, times);
        };
        times.full_evaluations += 1;
        let part = ElementPart {
            jacobian: SparseMatrix {
                pattern: self.pattern.clone(),
                values: values.clone(),
            },
            f_int: eval.f_int.clone(),
            trial_points: Vec::new(),
            approximate_elements: eval.approximate_elements,
        };
        // The projections depend on x and the committed hints only: those of `eval`.
        self.with_contact(x, part, times, true, Some(eval))
    }

    fn element_buffers(&self) -> std::sync::MutexGuard<'_, ElementBuffers> {
        self.element_buffers
            .lock()
            .unwrap_or_else(|e| e.into_inner())
    }

    /// The multiplier components `k` of a pair whose equation becomes `lambda_k = 0`: a
    /// sticking candidate `node` with a prescribed displacement component `k`
    /// (`unit_rows::stick_rows`; the empty columns, `unit_rows::empty_columns`, are found
    /// once every pair is evaluated).
    fn multiplier_unit_rows<'b>(
        &'b self,
        result: &'b NodalContact,
        node: usize,
    ) -> impl Iterator<Item = usize> + 'b {
        unit_rows::stick_rows(result, node, self.is_fixed)
    }

    /// Adds one contact pair's blocks (operator output `result` of a candidate of
    /// tool `c`, multipliers at `lam_dof`, offset column `fc_column` when force-controlled)
    /// to the Jacobian at their slots.
    fn add_pair_jacobian(
        &self,
        jac: &mut SparseMatrix,
        pair_slots: &crate::solver::assembly::slots::ContactSlots,
        fc_column: Option<&[usize; 6]>,
        result: &NodalContact,
        c: usize,
        lam_dof: Option<usize>,
    ) {
        for (ij, &slot) in pair_slots[0].iter().enumerate() {
            jac.values[slot] += result.equi_x[(ij / 3, ij % 3)];
        }
        if lam_dof.is_some() {
            for ij in 0..9 {
                let (i, j) = (ij / 3, ij % 3);
                jac.values[pair_slots[1][ij]] += result.equi_lambda[(i, j)];
                jac.values[pair_slots[2][ij]] += result.suppl_x[(i, j)];
                jac.values[pair_slots[3][ij]] += result.suppl_lambda[(i, j)];
            }
            if let Some(column) = fc_column {
                force_control::add_node_column(&mut jac.values, self.model, c, column, result);
            }
        }
    }

    fn evaluate_with(
        &self,
        x: &[f64],
        times: &mut PhaseTimes,
        with_jacobian: bool,
    ) -> Result<Evaluation> {
        if with_jacobian {
            times.full_evaluations += 1;
        } else {
            times.residual_evaluations += 1;
        }
        let part = self.element_part(x, times, with_jacobian)?;
        self.with_contact(x, part, times, with_jacobian, None)
    }

    /// The elements at `x`: their assembled stiffness (when `with_jacobian`, or a
    /// force-controlled tool needs a matrix to write into), internal forces and trial
    /// point states.
    fn element_part(
        &self,
        x: &[f64],
        times: &mut PhaseTimes,
        with_jacobian: bool,
    ) -> Result<ElementPart> {
        let model = self.model;
        let mut f_int = vec![0.0; 3 * self.dofs.n_nodes];
        let mut jac = if with_jacobian {
            SparseMatrix::zeros(self.pattern.clone())
        } else {
            SparseMatrix {
                pattern: self.pattern.clone(),
                values: Vec::new(),
            }
        };
        let mut trial_points = self.committed_points.to_vec();
        let t0 = Instant::now();
        let threads = worker_threads(model.settings.threads);
        let slots = self.dofs.slots(model, &self.pattern);
        let mut elements = self.element_buffers();
        let approximate = evaluate_elements(
            model,
            x,
            self.committed_points,
            &mut trial_points,
            threads,
            with_jacobian,
            &self.element_memory,
            &mut elements,
        )?;
        for (hex, force) in model.mesh.hexes.iter().zip(elements.force.chunks(24)) {
            for (a, &na) in hex.iter().enumerate() {
                for i in 0..3 {
                    f_int[3 * na + i] += force[3 * a + i];
                }
            }
        }
        if with_jacobian {
            slots.gather_elements(&elements.stiffness, &mut jac.values, threads);
        }
        times.elements += t0.elapsed().as_secs_f64();
        times.approximate_evaluations += usize::from(approximate > 0);
        Ok(ElementPart {
            jacobian: jac,
            f_int,
            trial_points,
            approximate_elements: approximate,
        })
    }

    /// An evaluation from its element part: loads, contact, force control, prescribed
    /// components.
    fn with_contact(
        &self,
        x: &[f64],
        part: ElementPart,
        times: &mut PhaseTimes,
        with_jacobian: bool,
        projected_at_x: Option<&Evaluation>,
    ) -> Result<Evaluation> {
        let model = self.model;
        let n = self.dofs.n_dofs;
        let mut residual = vec![0.0; n];
        let ElementPart {
            jacobian: mut jac,
            f_int,
            trial_points,
            approximate_elements,
        } = part;
        // A re-linearisation (`projected_at_x`) keeps none: see `relinearised`.
        let element_jacobian =
            (with_jacobian && self.keep_element_jacobian && projected_at_x.is_none())
                .then(|| jac.values.clone());
        let slots = self.dofs.slots(model, &self.pattern);

        let f_ext = self.loads(x, &mut jac, with_jacobian);
        for d in 0..3 * self.dofs.n_nodes {
            residual[d] = f_int[d] - f_ext[d];
        }

        let t1 = Instant::now();
        // Multiplier components whose equation is replaced by lambda_k = 0 (see
        // `contact_pairs`).
        let mut unit_rows: Vec<(usize, f64)> = Vec::new();
        let nodal = self.contact_pairs(
            x,
            &slots,
            &mut jac,
            &mut residual,
            &mut unit_rows,
            with_jacobian,
            projected_at_x,
        );
        force_control::add_force_rows(
            model,
            self.dofs,
            self.time,
            x,
            self.committed_x,
            &nodal,
            &slots.force_control,
            Some(&mut residual),
            with_jacobian.then_some(&mut jac.values[..]),
        )?;
        // Multiplier components the linearisation leaves free (unit_rows.rs): lambda_k = 0.
        for d in unit_rows::empty_columns(model, self.dofs, self.time, self.is_fixed, &nodal) {
            unit_rows.push((d, x[d]));
        }
        times.contact += t1.elapsed().as_secs_f64();

        let support_forces =
            self.prescribed_rows(&mut residual, &mut jac, &unit_rows, with_jacobian);
        Ok(Evaluation {
            residual,
            jacobian: jac,
            trial_points,
            nodal,
            f_int,
            f_ext,
            support_forces,
            element_jacobian,
            approximate_elements,
            time: self.time,
        })
    }

    /// The external forces at `x`: the scheduled nodal loads, plus the follower loads
    /// (pressures that turn with the surface), whose stiffness `-dF_ext/du` goes into `jac`
    /// when `with_jacobian`.
    fn loads(&self, x: &[f64], jac: &mut SparseMatrix, with_jacobian: bool) -> Vec<f64> {
        let model = self.model;
        let mut f_ext = model.external_forces(self.time);
        for load in &model.follower_loads {
            let mut add = |r: usize, c: usize, v: f64| jac.add(r, c, -v);
            let stiffness = with_jacobian.then_some(&mut add as &mut dyn FnMut(usize, usize, f64));
            load.add_forces(&model.mesh, x, self.time, &mut f_ext, stiffness);
        }
        f_ext
    }

    /// Every contact pair at `x`, tool by tool (each at its pose shifted by its force-control
    /// offset), candidate by candidate: the operator's output added to the node's
    /// equilibrium rows (`F_equi`), written to the pair's multiplier rows (`F_suppl`) and,
    /// when `with_jacobian`, its blocks to `jac`; the multiplier components whose equation
    /// becomes `lambda_k = 0` pushed to `unit_rows` with their current value. Returns the
    /// operator output and projection of every pair (`Evaluation::nodal`).
    #[allow(clippy::too_many_arguments)]
    fn contact_pairs(
        &self,
        x: &[f64],
        slots: &AssemblySlots,
        jac: &mut SparseMatrix,
        residual: &mut [f64],
        unit_rows: &mut Vec<(usize, f64)>,
        with_jacobian: bool,
        projected_at_x: Option<&Evaluation>,
    ) -> Vec<Vec<(NodalContact, Option<Projection>)>> {
        let model = self.model;
        let mut nodal = Vec::with_capacity(model.contacts.len());
        for (c, contact) in model.contacts.iter().enumerate() {
            let pose = &force_control::shifted(&self.poses[c], model, self.dofs, c, x);
            let mut list = Vec::with_capacity(contact.candidates.len());
            for (k, &node) in contact.candidates.iter().enumerate() {
                let pair_slots = &slots.contact[c][k];
                let committed = &self.committed_contact[c][k];
                let xn = model.mesh.nodes[node]
                    + Vec3::new(x[3 * node], x[3 * node + 1], x[3 * node + 2]);
                let x_ref = pose.to_global_point(&committed.x_ref_local);
                let proj = self.pair_projection(c, k, pose, &xn, projected_at_x);
                let lam_dof = self.dofs.lambda_offset[c].map(|off| off + 3 * k);
                let lambda = match lam_dof {
                    Some(l) => Vec3::new(x[l], x[l + 1], x[l + 2]),
                    None => Vec3::zeros(),
                };
                let result = self.pair_operator(c, k, &xn, &x_ref, &lambda, proj.as_ref(), lam_dof);
                for i in 0..3 {
                    residual[3 * node + i] += result.f_equi[i];
                }
                if let Some(l) = lam_dof {
                    // A sticking node with a prescribed displacement component k: its
                    // tangential force along k and the support reaction are one and the same
                    // unknown (the Jacobian is singular), so the support carries it:
                    // lambda_k = 0. This is exact on symmetry planes and in plane strain,
                    // where the tool normal lies in the constrained plane.
                    for k in self.multiplier_unit_rows(&result, node) {
                        unit_rows.push((l + k, lambda[k]));
                    }
                    for i in 0..3 {
                        residual[l + i] = result.f_suppl[i];
                    }
                }
                if with_jacobian {
                    let fc_column = slots.force_control[c].as_ref().map(|f| &f.column[k]);
                    self.add_pair_jacobian(jac, pair_slots, fc_column, &result, c, lam_dof);
                }
                list.push((result, proj));
            }
            nodal.push(list);
        }
        nodal
    }

    /// The projection of candidate `k` of tool `c` (at `xn`, the tool at `pose`): under
    /// frozen frames, the frozen foot and normal carried by the pose, with the gap measured
    /// along that normal and no curvature; in a re-linearisation, the projection
    /// `projected_at_x` already made at the same unknowns; otherwise the tool's own,
    /// started from the committed hint. `None` where no projection exists.
    fn pair_projection(
        &self,
        c: usize,
        k: usize,
        pose: &Pose,
        xn: &Vec3,
        projected_at_x: Option<&Evaluation>,
    ) -> Option<Projection> {
        let contact = &self.model.contacts[c];
        let committed = &self.committed_contact[c][k];
        match &self.frozen {
            Some(frames) => frames[c][k].map(|f| {
                let foot = pose.to_global_point(&f.foot_local);
                let normal = pose.to_global_vector(&f.normal_local);
                Projection {
                    foot,
                    normal,
                    gap: normal.dot(&(xn - foot)),
                    normal_gradient: Mat3::zeros(),
                    hint: committed.hint.unwrap_or_default(),
                }
            }),
            None => match projected_at_x {
                Some(known) => known.nodal[c][k].1,
                None => contact.tool.project(pose, xn, committed.hint.as_ref()),
            },
        }
    }

    /// The contact operator of candidate `k` of tool `c` at node position `xn`, reference
    /// point `x_ref` and multipliers `lambda` (at `lam_dof`; `None` under penalty): its
    /// parameters (augmentation, the committed friction coefficient or, with implicit
    /// friction update and a Bernstein law, the one at the trial state, a status the
    /// anti-cycling treatment imposes), then Alart-Curnier's operator, the penalty one, or
    /// without a projection the one that drives the multipliers to zero.
    #[allow(clippy::too_many_arguments)]
    fn pair_operator(
        &self,
        c: usize,
        k: usize,
        xn: &Vec3,
        x_ref: &Vec3,
        lambda: &Vec3,
        proj: Option<&Projection>,
        lam_dof: Option<usize>,
    ) -> NodalContact {
        let model = self.model;
        let contact = &model.contacts[c];
        let committed = &self.committed_contact[c][k];
        let mut params =
            OperatorParams::fixed_mu(contact.r[k], committed.mu, model.settings.contact.curvature);
        params.forced = self.forced.as_ref().and_then(|f| f[c][k]);
        if let (FrictionUpdate::Implicit, Some(law), Some(p), Some(_)) = (
            model.settings.contact.friction_update,
            contact.tool.friction.bernstein(),
            proj,
            lam_dof,
        ) {
            implicit_mu(
                &mut params,
                law,
                committed,
                contact.areas[k],
                xn,
                x_ref,
                lambda,
                p,
            );
        }
        match (proj, lam_dof) {
            (Some(p), Some(_)) => alart_curnier(xn, x_ref, lambda, p, &params),
            (Some(p), None) => penalty(xn, x_ref, committed, p, &params),
            (None, _) => far_from_tool(lambda, params.r),
        }
    }

    /// The prescribed components: the support forces (the residual's value at each fixed
    /// row, before it is cleared) returned; each fixed row and each multiplier component of
    /// `unit_rows` made a unit row of the Jacobian (when `with_jacobian`; otherwise the
    /// Jacobian is emptied), its residual 0 for a fixed row and the multiplier's value for a
    /// `lambda_k = 0` row.
    fn prescribed_rows(
        &self,
        residual: &mut [f64],
        jac: &mut SparseMatrix,
        unit_rows: &[(usize, f64)],
        with_jacobian: bool,
    ) -> Vec<f64> {
        let support_forces: Vec<f64> = (0..3 * self.dofs.n_nodes)
            .map(|d| if self.is_fixed[d] { residual[d] } else { 0.0 })
            .collect();
        let mut unit = self.is_fixed.to_vec();
        for (d, fixed) in self.is_fixed.iter().enumerate() {
            if *fixed {
                residual[d] = 0.0;
            }
        }
        for &(d, value) in unit_rows {
            unit[d] = true;
            residual[d] = value;
        }
        if with_jacobian {
            jac.set_unit_rows(&unit);
        } else {
            jac.values = Vec::new();
        }
        support_forces
    }
}

/// A node whose projection is undefined: no contact force, the multiplier equation drives
/// lambda to zero.
fn far_from_tool(lambda: &Vec3, r: f64) -> NodalContact {
    NodalContact {
        status: crate::contact::ContactStatus::Gap,
        f_equi: Vec3::zeros(),
        f_suppl: -lambda / r,
        equi_x: Mat3::zeros(),
        equi_lambda: Mat3::zeros(),
        suppl_x: Mat3::zeros(),
        suppl_lambda: -Mat3::identity() / r,
        slip_increment: Vec3::zeros(),
        tangential_force: Vec3::zeros(),
        sigma_model: None,
    }
}

/// Plain penalty: the operator evaluated with lambda = the committed tangential force
/// (projected on the current tangent plane), which is not an unknown. The normal force is
/// r d_n, so the constraint is violated by (normal force)/r.
fn penalty(
    x: &Vec3,
    x_ref: &Vec3,
    committed: &ContactNodeState,
    proj: &Projection,
    params: &OperatorParams,
) -> NodalContact {
    let n = proj.normal;
    let lc = committed.lambda - committed.normal * committed.lambda.dot(&committed.normal);
    let lambda = lc - n * n.dot(&lc);
    let mut res = alart_curnier(x, x_ref, &lambda, proj, params);
    if params.curvature {
        let g = proj.normal_gradient;
        let dlambda_dx = -(g * n.dot(&lc)) - n * (lc.transpose() * g);
        res.equi_x += res.equi_lambda * dlambda_dx;
    }
    res
}

/// Implicit (trapezoidal) friction update: the increment's coefficient is the mean of mu at
/// the committed work Psi_n and at the end-of-increment work Psi_n + lambda_t . delta_t,
/// with lambda_t = P lambda, delta_t = P (x - x_ref), P = I - n n^T. Fills mu and its
/// gradients:
///
/// ```text
/// d(dPsi)/dlambda = delta_t
/// d(dPsi)/dx      = lambda_t - (n.delta) G^T lambda - (n.lambda) G^T delta   (G = dn/dx)
/// ```
#[allow(clippy::too_many_arguments)]
fn implicit_mu(
    params: &mut OperatorParams,
    law: &BernsteinLaw,
    committed: &ContactNodeState,
    area: f64,
    x: &Vec3,
    x_ref: &Vec3,
    lambda: &Vec3,
    proj: &Projection,
) {
    let n = proj.normal;
    let delta = x - x_ref;
    let lambda_t = lambda - n * n.dot(lambda);
    let delta_t = delta - n * n.dot(&delta);
    let work_end = committed.work + lambda_t.dot(&delta_t);
    let theta = law.theta(work_end, area);
    let slope = law.dmu_dtheta(theta) * law.dtheta_dwork(work_end, area);
    params.mu = 0.5 * (committed.mu + law.mu_of_theta(theta));
    let mut dwork_dx = lambda_t;
    if params.curvature {
        let gt = proj.normal_gradient.transpose();
        dwork_dx -= gt * lambda * n.dot(&delta) + gt * delta * n.dot(lambda);
    }
    params.dmu_dx = dwork_dx * (0.5 * slope);
    params.dmu_dlambda = delta_t * (0.5 * slope);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactStatus;
    use crate::solver::test_models::strip_under_roller;
    use crate::tool::schedule::Schedule;
    use crate::tool::{ForceControl, ScalarSchedule};

    /// A Hill48 strip (finite strain) under a rough cylinder pushed into it, optionally
    /// force-controlled, and the unknowns of a state where the cylinder presses the strip:
    /// top bulged into the roller, sheared sideways, multipliers of mixed sign.
    fn pressed_strip(force_controlled: bool) -> (Model, Vec<f64>) {
        let still = Schedule::new(vec![(0.0, Vec3::zeros()), (1.0, Vec3::zeros())]).unwrap();
        let force_control = force_controlled
            .then(|| ForceControl::new(-Vec3::z(), ScalarSchedule::constant(50.0)).unwrap());
        let model = strip_under_roller(500.0, 3.0, still, force_control);
        let dofs = DofMap::new(&model);
        let mut x = vec![0.0; dofs.n_dofs];
        for (node, p) in model.mesh.nodes.iter().enumerate() {
            let squeeze = (-(p.x - 3.0).powi(2)).exp() * p.z;
            x[3 * node] = 0.01 * p.z * p.x.sin();
            x[3 * node + 2] = 0.04 * squeeze;
        }
        for (k, v) in x[3 * dofs.n_nodes..].iter_mut().enumerate() {
            *v = 20.0 * ((k as f64) * 0.7).sin();
        }
        // The force-controlled tool's offset stays where the schedule puts it.
        for s in dofs.tool_offset.iter().flatten() {
            x[*s] = 0.0;
        }
        (model, x)
    }

    /// A fresh increment context at time 1 (no frozen frames, no forced statuses, nothing
    /// remembered, the element stiffness not kept).
    fn context_at_one<'a>(
        model: &'a Model,
        dofs: &'a DofMap,
        pattern: Arc<SparsePattern>,
        points: &'a [PointState],
        contact: &'a [Vec<ContactNodeState>],
        is_fixed: &'a [bool],
    ) -> IncrementContext<'a> {
        IncrementContext {
            model,
            dofs,
            pattern,
            time: 1.0,
            poses: model.contacts.iter().map(|c| c.tool.pose(1.0)).collect(),
            committed_points: points,
            committed_contact: contact,
            committed_x: &[],
            frozen: None,
            is_fixed,
            forced: None,
            element_memory: Default::default(),
            keep_element_jacobian: false,
            element_buffers: Default::default(),
        }
    }

    /// A residual-only evaluation gives, bit for bit, everything a full one gives but the
    /// Jacobian (residual, forces, support forces, point states, contact output): so the
    /// line search, which judges a trial by these alone, takes the same decisions with it.
    /// The full evaluation's Jacobian is complete, the residual-only one's empty, and
    /// completing the latter (`complete`, what an accepted line-search cut gets) gives the
    /// former's, bit for bit.
    #[test]
    fn residual_only_evaluation_equals_the_full_one_but_the_jacobian() {
        for (force_controlled, end_moment) in [(false, false), (true, false), (false, true)] {
            let (mut model, x) = pressed_strip(force_controlled);
            if end_moment {
                // A follower load: its stiffness must be in the completed Jacobian too.
                model
                    .add_end_moment("x+", 40.0, Vec3::z(), ScalarSchedule::constant(1.0))
                    .unwrap();
            }
            let dofs = DofMap::new(&model);
            let pattern = Arc::new(dofs.pattern(&model));
            let mut is_fixed = vec![false; dofs.n_dofs];
            for bc in &model.dirichlet {
                for &node in &bc.nodes {
                    is_fixed[3 * node + bc.component] = true;
                }
            }
            let points = vec![PointState::default(); model.mesh.hexes.len() * 8];
            let contact: Vec<Vec<ContactNodeState>> = model
                .contacts
                .iter()
                .map(|c| {
                    let pose = c.tool.pose(1.0);
                    c.candidates
                        .iter()
                        .map(|&node| ContactNodeState {
                            x_ref_local: pose.to_local(&model.mesh.nodes[node]),
                            mu: 0.2,
                            ..Default::default()
                        })
                        .collect()
                })
                .collect();
            let mut ctx = context_at_one(&model, &dofs, pattern, &points, &contact, &is_fixed);
            ctx.keep_element_jacobian = true;
            let mut times = PhaseTimes::default();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let full = ctx.evaluate(&x, &mut times).unwrap();
            let residual_only = ctx.evaluate_residual(&x, &mut times).unwrap();
            // Completed with its Jacobian: the full evaluation, bit for bit, without a
            // contact pass (the force-controlled model's force rows included).
            let completions = times.jacobian_completions;
            let completed = ctx
                .complete(
                    &x,
                    ctx.evaluate_residual(&x, &mut times).unwrap(),
                    &mut times,
                )
                .unwrap();
            assert_eq!(times.jacobian_completions, completions + 1);
            assert_eq!(
                bits(&completed.jacobian.values),
                bits(&full.jacobian.values)
            );
            assert_eq!(bits(&completed.residual), bits(&full.residual));
            assert_eq!(completed.trial_points, full.trial_points);
            let statuses: Vec<ContactStatus> =
                full.nodal[0].iter().map(|(r, _)| r.status).collect();
            assert!(
                statuses.iter().any(|s| s.is_active()),
                "contact must be active"
            );
            assert!(
                full.trial_points.iter().any(|p| p.eq_plastic_strain > 0.0),
                "the strip must yield"
            );
            assert!(full.has_jacobian() && !residual_only.has_jacobian());
            assert_eq!(bits(&full.residual), bits(&residual_only.residual));
            assert_eq!(bits(&full.f_int), bits(&residual_only.f_int));
            assert_eq!(bits(&full.f_ext), bits(&residual_only.f_ext));
            assert_eq!(
                bits(&full.support_forces),
                bits(&residual_only.support_forces)
            );
            assert_eq!(full.trial_points, residual_only.trial_points);
            assert_eq!(
                statuses,
                residual_only.nodal[0]
                    .iter()
                    .map(|(r, _)| r.status)
                    .collect::<Vec<_>>()
            );
            // The contact part linearised again on other statuses, the element part kept:
            // the full evaluation with those statuses imposed, bit for bit.
            assert!(full.element_jacobian.is_some() && residual_only.element_jacobian.is_none());
            let flipped = |s: &ContactStatus| match s {
                ContactStatus::Gap => Some(ContactStatus::Slip),
                ContactStatus::Stick => Some(ContactStatus::Gap),
                ContactStatus::Slip => Some(ContactStatus::Stick),
            };
            ctx.forced = Some(vec![statuses.iter().map(flipped).collect()]);
            let again = ctx.relinearised(&x, &full, &mut times).unwrap();
            let imposed = ctx.evaluate(&x, &mut times).unwrap();
            assert_ne!(bits(&again.jacobian.values), bits(&full.jacobian.values));
            assert_eq!(bits(&again.jacobian.values), bits(&imposed.jacobian.values));
            assert_eq!(bits(&again.residual), bits(&imposed.residual));
            assert_eq!(bits(&again.support_forces), bits(&imposed.support_forces));
            assert_eq!(bits(&again.f_int), bits(&imposed.f_int));
            assert_eq!(again.nodal.len(), imposed.nodal.len());
            for (a, b) in again
                .nodal
                .iter()
                .flatten()
                .zip(imposed.nodal.iter().flatten())
            {
                assert_eq!(a.0.status, b.0.status);
                assert_eq!(bits(a.0.f_equi.as_slice()), bits(b.0.f_equi.as_slice()));
                assert_eq!(bits(a.0.f_suppl.as_slice()), bits(b.0.f_suppl.as_slice()));
            }
            // Neither point states nor a kept element stiffness: the re-linearisation
            // starts from `full`'s, which has both.
            assert!(again.trial_points.is_empty() && again.element_jacobian.is_none());
            // A second re-linearisation from `full` (the next round) is the same again.
            let next = ctx.relinearised(&x, &full, &mut times).unwrap();
            assert_eq!(bits(&next.jacobian.values), bits(&again.jacobian.values));
            assert_eq!(bits(&next.residual), bits(&again.residual));
        }
    }

    /// The element output buffers are kept between the evaluations of an increment and
    /// sized, never cleared, because every element overwrites its own force and stiffness.
    /// Buffers full of NaN from an earlier use must therefore give, bit for bit, what
    /// fresh ones give, for every element kind (an element that accumulated into its
    /// outputs would fail here).
    #[test]
    fn stale_element_buffers_change_nothing() {
        use crate::element::ElementKind;
        for kind in [ElementKind::Hexahedron, ElementKind::SolidShell] {
            let (mut model, x) = pressed_strip(false);
            model.settings.element = kind;
            let dofs = DofMap::new(&model);
            let pattern = Arc::new(dofs.pattern(&model));
            let is_fixed = vec![false; dofs.n_dofs];
            let per_elem = model.element().unwrap().point_count();
            let points = vec![PointState::default(); model.mesh.hexes.len() * per_elem];
            let contact: Vec<Vec<ContactNodeState>> = model
                .contacts
                .iter()
                .map(|c| vec![ContactNodeState::default(); c.candidates.len()])
                .collect();
            let context =
                || context_at_one(&model, &dofs, pattern.clone(), &points, &contact, &is_fixed);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let mut times = PhaseTimes::default();
            let poisoned = || {
                let ctx = context();
                {
                    let n = model.mesh.hexes.len() * crate::element::hex8::DOFS;
                    let mut buffers = ctx.element_buffers();
                    buffers.force = vec![f64::NAN; n];
                    buffers.stiffness = vec![f64::NAN; n * crate::element::hex8::DOFS];
                }
                ctx
            };
            // Each comparison is a context's first evaluation: a solid-shell's later ones
            // start their local solve from what the first remembered, equal to round-off.
            let fresh = context().evaluate(&x, &mut times).unwrap();
            let again = poisoned().evaluate(&x, &mut times).unwrap();
            assert!(fresh.residual.iter().all(|v| v.is_finite()), "{kind:?}");
            assert_eq!(bits(&again.residual), bits(&fresh.residual), "{kind:?}");
            assert_eq!(bits(&again.f_int), bits(&fresh.f_int), "{kind:?}");
            assert_eq!(
                bits(&again.jacobian.values),
                bits(&fresh.jacobian.values),
                "{kind:?}"
            );
            // A residual-only evaluation leaves the stiffness as it is and reads none of it.
            let fresh = context().evaluate_residual(&x, &mut times).unwrap();
            let again = poisoned().evaluate_residual(&x, &mut times).unwrap();
            assert_eq!(bits(&again.residual), bits(&fresh.residual), "{kind:?}");
        }
    }
}
