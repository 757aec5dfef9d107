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

use super::force_control;
use super::model::Model;
use super::slots::AssemblySlots;
use super::sparse::{SparseMatrix, SparsePattern};
use crate::contact::{
    alart_curnier, BernsteinLaw, ContactNodeState, Enforcement, FrictionUpdate, NodalContact,
    OperatorParams,
};
use crate::element::{hexahedron, in_element};
use crate::geometry::{Mat3, Projection, Vec3};
use crate::material::PointState;
use crate::tool::pose::Pose;
use crate::{Error, Result};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

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
        let tool_offset = force_control::allocate(model, &lambda_offset, &mut next);
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
    fn slots(&self, model: &Model, pattern: &Arc<SparsePattern>) -> Arc<AssemblySlots> {
        let build = || {
            Arc::new(AssemblySlots::new(
                model,
                &self.lambda_offset,
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
        force_control::pattern_entries(model, self, &mut entries);
        for d in 0..self.n_dofs {
            entries.push((d, d));
        }
        SparsePattern::from_entries(self.n_dofs, entries)
    }
}

/// Number of element threads for the setting `threads` (0: every core).
fn element_threads(setting: usize) -> usize {
    match setting {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    }
}

/// Element forces and stiffnesses of one evaluation, element after element: `force[24 e..]`
/// and `stiffness[576 e..]` (column-major), the latter empty for a residual-only
/// evaluation.
struct ElementBuffers {
    force: Vec<f64>,
    stiffness: Vec<f64>,
}

/// Evaluates every element at the unknowns `x`, on `threads` threads over contiguous
/// blocks of elements, writing the trial states of their integration points and each
/// element's force (and, with `tangent`, stiffness) straight into its place in the
/// returned buffers, so that the assembly (and hence every result) is the same whatever
/// the thread count. The first failing element in element order is the one reported.
fn evaluate_elements(
    model: &Model,
    x: &[f64],
    committed: &[PointState],
    trial: &mut [PointState],
    threads: usize,
    tangent: bool,
) -> Result<ElementBuffers> {
    const D: usize = crate::element::hex8::DOFS;
    let element = hexahedron(model.settings.kinematics, model.settings.fbar);
    let per_elem = element.point_count();
    let (hexes, nodes, material) = (
        &model.mesh.hexes,
        &model.mesh.nodes,
        model.material.as_ref(),
    );
    let n_elem = hexes.len();
    let mut buffers = ElementBuffers {
        force: vec![0.0; n_elem * D],
        stiffness: vec![0.0; if tangent { n_elem * D * D } else { 0 }],
    };
    let evaluate_block =
        |first: usize, trial: &mut [PointState], force: &mut [f64], stiffness: &mut [f64]| {
            let mut xs = [Vec3::zeros(); 8];
            let mut us = [Vec3::zeros(); 8];
            let mut stiffness = tangent.then(|| stiffness.chunks_mut(D * D));
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
                element
                    .evaluate_into(
                        &xs,
                        &us,
                        committed_e,
                        trial_e,
                        material,
                        force_e,
                        stiffness_e,
                    )
                    .map_err(|err| Error::NoConvergence(in_element(err, e).to_string()))?;
            }
            Ok::<_, Error>(())
        };
    // Below a few dozen elements, starting threads costs more than it saves.
    const MIN_PARALLEL_ELEMENTS: usize = 64;
    if threads <= 1 || n_elem < MIN_PARALLEL_ELEMENTS {
        evaluate_block(0, trial, &mut buffers.force, &mut buffers.stiffness)?;
        return Ok(buffers);
    }
    let block = n_elem.div_ceil(threads);
    let stiffness_block = if tangent { block * D * D } else { 1 };
    let mut stiffness_chunks: Vec<&mut [f64]> =
        buffers.stiffness.chunks_mut(stiffness_block).collect();
    stiffness_chunks.resize_with(n_elem.div_ceil(block), Default::default);
    let results: Vec<Result<()>> = std::thread::scope(|scope| {
        let handles: Vec<_> = trial
            .chunks_mut(block * per_elem)
            .zip(buffers.force.chunks_mut(block * D))
            .zip(stiffness_chunks)
            .enumerate()
            .map(|(i, ((trial, force), stiffness))| {
                let evaluate_block = &evaluate_block;
                scope.spawn(move || evaluate_block(i * block, trial, force, stiffness))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    for r in results {
        r?;
    }
    Ok(buffers)
}

/// Wall time spent in each phase of assembly (seconds), accumulated.
#[derive(Clone, Copy, Debug, Default)]
pub struct PhaseTimes {
    pub elements: f64,
    pub contact: f64,
    pub factorization_and_solve: f64,
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
    pub frozen: Option<Vec<Vec<Option<FrozenFrame>>>>,
    pub is_fixed: &'a [bool],
    /// Contact status imposed per (tool, candidate) by the anti-cycling treatment.
    pub forced: Option<Vec<Vec<Option<crate::contact::ContactStatus>>>>,
}

impl IncrementContext<'_> {
    /// Evaluates residual and Jacobian at displacements `u` and multipliers `lambda`
    /// (the multiplier part of the unknown vector `x = [u, lambda]`).
    pub fn evaluate(&self, x: &[f64], times: &mut PhaseTimes) -> Result<Evaluation> {
        let model = self.model;
        let n = self.dofs.n_dofs;
        let mut residual = vec![0.0; n];
        let mut f_int = vec![0.0; 3 * self.dofs.n_nodes];
        let mut jac = SparseMatrix::zeros(self.pattern.clone());
        let mut trial_points = self.committed_points.to_vec();

        let t0 = Instant::now();
        let threads = element_threads(model.settings.threads);
        let slots = self.dofs.slots(model, &self.pattern);
        let elements = evaluate_elements(
            model,
            x,
            self.committed_points,
            &mut trial_points,
            threads,
            true,
        )?;
        for (hex, force) in model.mesh.hexes.iter().zip(elements.force.chunks(24)) {
            for (a, &na) in hex.iter().enumerate() {
                for i in 0..3 {
                    f_int[3 * na + i] += force[3 * a + i];
                }
            }
        }
        slots.gather_elements(&elements.stiffness, &mut jac.values, threads);
        times.elements += t0.elapsed().as_secs_f64();

        let f_ext = model.external_forces(self.time);
        for d in 0..3 * self.dofs.n_nodes {
            residual[d] = f_int[d] - f_ext[d];
        }

        let t1 = Instant::now();
        // Multiplier components whose equation is replaced by lambda_k = 0 (see below).
        let mut unit_rows: Vec<(usize, f64)> = Vec::new();
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
                let proj = match &self.frozen {
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
                    None => contact.tool.project(pose, &xn, committed.hint.as_ref()),
                };
                let lam_dof = self.dofs.lambda_offset[c].map(|off| off + 3 * k);
                let lambda = match lam_dof {
                    Some(l) => Vec3::new(x[l], x[l + 1], x[l + 2]),
                    None => Vec3::zeros(),
                };
                let mut params = OperatorParams::fixed_mu(
                    contact.r[k],
                    committed.mu,
                    model.settings.contact.curvature,
                );
                params.forced = self.forced.as_ref().and_then(|f| f[c][k]);
                if let (FrictionUpdate::Implicit, Some(law), Some(p), Some(_)) = (
                    model.settings.contact.friction_update,
                    contact.tool.friction.bernstein(),
                    proj.as_ref(),
                    lam_dof,
                ) {
                    implicit_mu(
                        &mut params,
                        law,
                        committed,
                        contact.areas[k],
                        &xn,
                        &x_ref,
                        &lambda,
                        p,
                    );
                }
                let result = match (proj.as_ref(), lam_dof) {
                    (Some(p), Some(_)) => alart_curnier(&xn, &x_ref, &lambda, p, &params),
                    (Some(p), None) => penalty(&xn, &x_ref, committed, p, &params),
                    (None, _) => far_from_tool(&lambda, params.r),
                };
                for i in 0..3 {
                    residual[3 * node + i] += result.f_equi[i];
                    for j in 0..3 {
                        jac.values[pair_slots[0][3 * i + j]] += result.equi_x[(i, j)];
                    }
                }
                if let Some(l) = lam_dof {
                    // A sticking node with a prescribed displacement component k: its
                    // tangential force along k and the support reaction are one and the same
                    // unknown (the Jacobian is singular), so the support carries it:
                    // lambda_k = 0. This is exact on symmetry planes and in plane strain,
                    // where the tool normal lies in the constrained plane.
                    if result.status == crate::contact::ContactStatus::Stick {
                        for k in 0..3 {
                            if self.is_fixed[3 * node + k] {
                                unit_rows.push((l + k, lambda[k]));
                            }
                        }
                    }
                    for i in 0..3 {
                        residual[l + i] = result.f_suppl[i];
                        for j in 0..3 {
                            let ij = 3 * i + j;
                            jac.values[pair_slots[1][ij]] += result.equi_lambda[(i, j)];
                            jac.values[pair_slots[2][ij]] += result.suppl_x[(i, j)];
                            jac.values[pair_slots[3][ij]] += result.suppl_lambda[(i, j)];
                        }
                    }
                    force_control::add_node_column(&mut jac, model, self.dofs, c, node, l, &result);
                }
                list.push((result, proj));
            }
            nodal.push(list);
        }
        force_control::add_force_rows(
            model,
            self.dofs,
            self.time,
            x,
            &nodal,
            &mut residual,
            &mut jac,
        )?;
        times.contact += t1.elapsed().as_secs_f64();

        let support_forces: Vec<f64> = (0..3 * self.dofs.n_nodes)
            .map(|d| if self.is_fixed[d] { residual[d] } else { 0.0 })
            .collect();
        let mut unit = self.is_fixed.to_vec();
        for (d, fixed) in self.is_fixed.iter().enumerate() {
            if *fixed {
                residual[d] = 0.0;
            }
        }
        for &(d, value) in &unit_rows {
            unit[d] = true;
            residual[d] = value;
        }
        jac.set_unit_rows(&unit);
        Ok(Evaluation {
            residual,
            jacobian: jac,
            trial_points,
            nodal,
            f_int,
            f_ext,
            support_forces,
        })
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
