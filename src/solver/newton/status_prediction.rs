//! Newton steps linearised on the contact statuses they lead to (status prediction).
//!
//! The semismooth Newton step at `x` linearises every contact node on the status (gap,
//! stick, slip) its augmented multiplier `sigma` has at `x`. Where a step carries `sigma`
//! of many barely touching nodes across a status boundary, that linearisation is wrong for
//! them: after the step they bring `r` times their gap error into their equilibrium rows,
//! the merit rises, the line search cuts the step, and the next iterate flips a few nodes
//! only. On the 25 x 25 x 1 square cup that node-by-node march is most of an increment's
//! iterations (docs/convergence.md).
//!
//! Here the step is solved again with each such node linearised on the status it would
//! have at the step's end, predicted from the first-order model of `sigma`
//! ([`crate::contact::SigmaModel`]: `sigma + dsigma/dx du + dlambda`, the tool moved by its
//! offset's change), until the statuses used and the statuses predicted agree (a step of
//! the piecewise-linear Newton model, Josephy-Newton) or `rounds` re-solves are spent.
//! A node linearised on a predicted status carries that status's branch in its residual
//! at `x` too (`IncrementContext::forced`), so each re-solve is the Newton step of the
//! branch the node is heading into. Only the step changes: the line search and the
//! convergence test use the exact law, so the converged answer is the same.
//!
//! Cost per re-solve: the contact part of one evaluation (the element part and the tool
//! projections at `x` are kept from the step's own evaluation,
//! [`IncrementContext::relinearised`]) and one linear solve, whose factorization
//! recomputes only the supernodes that the changed nodes' rows reach (their paths to the
//! root of the elimination tree: 58-67 % of a whole factorization's flops on the 25 x 25 x 1
//! cup, [`crate::solver::linear::symmetric_lu::NumericSymmetricLu::factorize`]); the prediction itself is
//! O(1) per contact pair.

use crate::contact::ContactStatus;
use crate::geometry::Vec3;
use crate::solver::assembly::{DofMap, Evaluation, IncrementContext, PhaseTimes};
use crate::solver::linear::LinearSolver;
use crate::solver::model::Model;
use crate::solver::newton::norm;
use crate::solver::newton::Newton;
use crate::Result;

/// How much longer than the plain step (displacement parts) a re-solved step may be. On
/// the cylindrical cup's first increment (every node of the flat blank at zero gap under
/// punch, die and holder) re-solves ran away to 1e3-1e15 times the plain step, each round
/// predicting from the last, and the increment was halved four times over inverted
/// elements; with this limit, once. A limit of 100 also cut useful re-solves: the coarse
/// benchmark cup's first 3 mm took 57 iterations instead of 46.
const STEP_GROWTH_LIMIT: f64 = 1000.0;

/// Status per (tool, candidate).
type Statuses = Vec<Vec<ContactStatus>>;

/// The statuses of an evaluation.
pub fn statuses(eval: &Evaluation) -> Statuses {
    eval.nodal
        .iter()
        .map(|list| list.iter().map(|(n, _)| n.status).collect())
        .collect()
}

/// The status a pair touching or not at `current` is linearised on in a re-solve, of the
/// status `predicted` by its model: only whether it touches is predicted (gap to stick or
/// slip, either to gap); a touching pair predicted to touch keeps its stick or slip.
///
/// Why: the march that prediction is for is one of touch and lift-off (slip and gap flips
/// of barely touching nodes, docs/convergence.md); predicting the stick-slip switches as
/// well made the re-solves longer and the steps worse: the 25 x 25 x 1 cup's first 3 mm
/// took 45 iterations (paper) and 68 (benchmark) instead of 43 and 59, at 1.12 and 1.28
/// times the CPU. And the incremental frictional problem of a first contact can have
/// several converged states: on the cylindrical cup's first increment (flat blank at zero
/// gap, force-controlled holder, mu = 0.1, one step of 0.125 mm, quarter model) the
/// prediction of every switch, with the pivoting solves below, led to 1,674.69 N instead
/// of the plain Newton's 1,782.50 N (2 and 8 steps: 1,782.50 and 1,782.68 N). Either
/// change alone keeps that increment on the plain Newton's state (test
/// `prediction_keeps_the_first_contact_of_the_cylindrical_cup`).
fn touching_status(current: ContactStatus, predicted: ContactStatus) -> ContactStatus {
    match (current, predicted) {
        (ContactStatus::Gap, p) | (_, p @ ContactStatus::Gap) => p,
        (touching, _) => touching,
    }
}

/// The status every contact pair of `eval` is linearised on after the step `dx`: from the
/// first-order model of its augmented multiplier, whether it touches
/// ([`touching_status`]). A pair without a multiplier unknown (penalty) or without a
/// projection keeps its status.
pub fn predicted_statuses(model: &Model, dofs: &DofMap, eval: &Evaluation, dx: &[f64]) -> Statuses {
    eval.nodal
        .iter()
        .enumerate()
        .map(|(c, list)| {
            let contact = &model.contacts[c];
            let tool_shift = match (&contact.tool.force_control, dofs.tool_offset[c]) {
                (Some(fc), Some(s)) => fc.axis * dx[s],
                _ => Vec3::zeros(),
            };
            list.iter()
                .enumerate()
                .map(|(k, (result, _))| {
                    let (Some(m), Some(off)) = (result.sigma_model, dofs.lambda_offset[c]) else {
                        return result.status;
                    };
                    let node = contact.candidates[k];
                    let du = Vec3::new(dx[3 * node], dx[3 * node + 1], dx[3 * node + 2]);
                    let l = off + 3 * k;
                    let dlambda = Vec3::new(dx[l], dx[l + 1], dx[l + 2]);
                    let predicted = m.predicted_status(&(du - tool_shift), &dlambda, result.status);
                    touching_status(result.status, predicted)
                })
                .collect()
        })
        .collect()
}

/// The rounds of status prediction: from the statuses `at_x` and their step `plain`, each
/// round predicts statuses from the last step (`predict`) and, until the statuses used and
/// predicted agree or `rounds` are spent, solves again on the predicted ones (`solve`:
/// `None` ends the rounds with the last step, as a failed or runaway re-solve does).
///
/// A predicted set already used earlier in these rounds starts a cycle: from there the
/// rounds would repeat the sets (and, the solves being deterministic functions of the set,
/// the steps) already met, none agreeing with its own prediction, until spent. Their last
/// step is then returned without solving again: the same step, bit for bit, at none of
/// the cost (on the 25 x 25 x 1 solid-shell benchmark cup 23 of 584 steps end in such a
/// cycle, 115 of 3,112 re-solves; BENCHMARKS.md). O(rounds) set comparisons per round, each
/// O(contact pairs).
pub fn prediction_rounds<S: PartialEq + Clone>(
    at_x: S,
    plain: Vec<f64>,
    rounds: usize,
    mut predict: impl FnMut(&[f64]) -> S,
    mut solve: impl FnMut(&S) -> Option<Vec<f64>>,
) -> Vec<f64> {
    // The sets used so far with their steps; the last is the one in use.
    let mut tried = vec![(at_x, plain)];
    for round in 0..rounds {
        let predicted = predict(&tried[tried.len() - 1].1);
        if let Some(start) = tried.iter().position(|(used, _)| *used == predicted) {
            if start + 1 == tried.len() {
                break; // agreement
            }
            let period = tried.len() - start;
            let last_round = (rounds - round - 1) % period;
            return tried.swap_remove(start + last_round).1;
        }
        match solve(&predicted) {
            Some(step) => tried.push((predicted, step)),
            None => break,
        }
    }
    tried.pop().expect("the plain step is always there").1
}

impl Newton<'_> {
    /// The Newton step `dx` solved at the evaluation `eval` of `x`, re-solved up to `rounds`
    /// times with the contact pairs whose predicted status differs from their status at `x`
    /// linearised on the predicted one (see the module doc and [`prediction_rounds`]); the
    /// line search then judges the step returned. A re-solve that fails (a predicted set
    /// leaving a body held by nothing) ends the rounds with the last good step (the plain
    /// step if it was the first).
    ///
    /// The re-solved step is not checked against the merit before the line search: that
    /// check (one residual-only evaluation at its full step, falling back to the plain step
    /// when the merit did not fall) rejected most re-solved steps (198 of 264 on the
    /// solid-shell 12 x 12 x 1 paper cup, 36 of 56 on the 25 x 25 x 1 benchmark cup's first
    /// 3 mm), and the plain step's line search then cut back where the re-solved one's
    /// did not: without it, the solid-shell cup took 6.0 s instead of 22.9 s
    /// (BENCHMARKS.md). Where a re-solved step leads far off, the increment fails and is
    /// tried again without prediction (`Simulation::try_increment`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn status_consistent_step(
        &self,
        ctx: &mut IncrementContext<'_>,
        x: &[f64],
        eval: &Evaluation,
        dx: Vec<f64>,
        linear: &mut dyn LinearSolver,
        times: &mut PhaseTimes,
        rounds: usize,
    ) -> Result<Vec<f64>> {
        let n_u = 3 * self.dofs.n_nodes;
        let at_x = statuses(eval);
        let plain_length = norm(&dx[..n_u]);
        let predict = |step: &[f64]| predicted_statuses(&self.model, &self.dofs, eval, step);
        let solve = |predicted: &Statuses| {
            let forced = predicted
                .iter()
                .zip(&at_x)
                .map(|(p, a)| {
                    p.iter()
                        .zip(a)
                        .map(|(p, a)| (p != a).then_some(*p))
                        .collect()
                })
                .collect();
            ctx.forced = Some(forced);
            let held = ctx.relinearised(x, eval, times);
            ctx.forced = None;
            // A predicted set can leave a body held by nothing (every node of a
            // force-controlled holder predicted to lift off): a singular or nearly singular
            // system. Its factorization without pivoting fails, and the pivoting one is not
            // tried (it cost five times as much, and three such failures in a row sent the
            // next 50 solves to it: the 25 x 25 x 1 paper cup's first 3 mm took 7.5 s of CPU
            // instead of 4.0 s). The last good step is kept then.
            linear.set_pivoting_fallback(false);
            let solved = held.and_then(|held| self.newton_step(&held, linear));
            linear.set_pivoting_fallback(true);
            // A re-solve far longer than the plain step comes from a predicted set that
            // holds the body by almost nothing, and each further round predicts from it:
            // the last step before it is kept.
            solved
                .ok()
                .filter(|s| norm(&s[..n_u]) <= STEP_GROWTH_LIMIT * plain_length)
        };
        Ok(prediction_rounds(at_x.clone(), dx, rounds, predict, solve))
    }
}

#[cfg(test)]
mod tests {
    use super::prediction_rounds;

    /// A prediction map on numbered sets, named.
    type NamedMap = (&'static str, Box<dyn Fn(u32) -> u32>);

    /// The rounds as they ran before cycles were recognised: every round solved.
    fn spent_rounds(
        rounds: usize,
        next: &dyn Fn(u32) -> u32,
        fails: &dyn Fn(u32) -> bool,
    ) -> (Vec<f64>, usize) {
        let (mut used, mut step, mut solves) = (0, vec![0.0], 0);
        for _ in 0..rounds {
            let predicted = next(used);
            if predicted == used {
                break;
            }
            solves += 1;
            if fails(predicted) {
                break;
            }
            step = vec![f64::from(predicted)];
            used = predicted;
        }
        (step, solves)
    }

    /// Sets are numbers, a step is its set's number, and the prediction from a step is
    /// `next` of it: chains into cycles of every period up to 5 and fixed points.
    #[test]
    fn a_cycle_ends_the_rounds_with_the_step_they_would_have_spent_to() {
        let maps: Vec<NamedMap> = vec![
            ("agree after 3", Box::new(|s| (s + 1).min(3))),
            ("2-cycle from the plain set", Box::new(|s| 1 - s)),
            (
                "2-cycle after 2",
                Box::new(|s| if s < 2 { s + 1 } else { 5 - s }),
            ),
            (
                "3-cycle after 1",
                Box::new(|s| if s == 0 { 1 } else { s % 3 + 1 }),
            ),
            ("5-cycle", Box::new(|s| (s + 1) % 5)),
        ];
        let fails_at: [Option<u32>; 2] = [None, Some(3)];
        for (name, next) in &maps {
            for fail in fails_at {
                let fails = |s: u32| Some(s) == fail;
                for rounds in 0..=12 {
                    let (expected, spent) = spent_rounds(rounds, next.as_ref(), &fails);
                    let mut solves = 0;
                    let step = prediction_rounds(
                        0u32,
                        vec![0.0],
                        rounds,
                        |step| next(step[0] as u32),
                        |&set| {
                            solves += 1;
                            (!fails(set)).then(|| vec![f64::from(set)])
                        },
                    );
                    assert_eq!(
                        step, expected,
                        "{name}, failing at {fail:?}, {rounds} rounds"
                    );
                    assert!(solves <= spent, "{name}: {solves} solves against {spent}");
                    if *name == "5-cycle" && rounds == 12 && fail.is_none() {
                        assert_eq!((solves, spent), (4, 12), "a cycle is solved once round");
                    }
                }
            }
        }
    }
}
