//! The simulation object of scripts: set up the model, then step or run it and query it.

use super::api_scene::{scalar_schedule, ScriptMaterial};
use super::convert::*;
use super::settings::{apply_settings, FrameKnobs, Knobs};
use super::HostOptions;
use crate::contact::{FrictionInput, FrictionLaw};
use crate::mesh::Mesh;
use crate::output::RunOutput;
use crate::solver::simulation::checkpoint::Checkpoint;
use crate::solver::{IncrementReport, Model, Simulation};
use crate::tool::Tool;
use crate::Error;
use rhai::{Array, Dynamic, Engine, FnPtr, Map, NativeCallContext};
use std::cell::RefCell;
use std::rc::Rc;
use std::time::Instant;

/// The model until the first step, then the running simulation, and its output folder.
pub struct SimState {
    model: Option<Model>,
    sim: Option<Simulation>,
    output: Option<RunOutput>,
    frames: FrameKnobs,
    /// Write checkpoints/checkpoint_NNNN.json every this many increments (0: never).
    checkpoint_every: usize,
    /// The script set `kinematics` (see [`SimState::refuse_default_small_strain`]).
    kinematics_chosen: bool,
    host: Rc<HostOptions>,
    started: Option<Instant>,
    /// Wall time of the run, fixed when it finished (post-processing does not count).
    wall_time: Option<f64>,
    /// Per converged increment: (index, time, per tool, per candidate [work, mu, status]).
    node_log: Vec<NodeSnapshot>,
    /// The script's own values (`sim.keep`), saved in every checkpoint and restored with it.
    kept: serde_json::Map<String, serde_json::Value>,
    /// A periodic checkpoint due for the committed state. It is written when the script
    /// steps again, stops or ends, so that it holds what the script kept after seeing the
    /// increment (a restarted run then repeats the script's bookkeeping exactly).
    checkpoint_due: Option<String>,
    /// Increment count of the state last saved as checkpoints/final.json.
    final_saved: Option<usize>,
    /// Why the simulation's last increment failed (its kind, and whether a contact status
    /// cycled), for summary.json at the stop; cleared by an increment that converges, so a
    /// failure a script caught is not reported at a later stop.
    failure: Option<(crate::error::Failure, bool)>,
    /// The progress bar of a running `sim.run()`: warnings are printed with the bar cleared
    /// and drawn again under them, so the bar's line is not repeated above every warning.
    progress: Option<indicatif::ProgressBar>,
}

pub(super) type NodeSnapshot = (usize, f64, Vec<Vec<[f64; 3]>>);

/// One increment with script friction laws applied: the simulation is not borrowed while
/// a script function runs (it may itself query the simulation).
fn advance(ctx: &NativeCallContext, s: &ScriptSim) -> ScriptResult<IncrementReport> {
    let (done, cap, clock) = {
        let st = s.borrow();
        let done = st.sim.as_ref().map_or(0, |x| x.history.len());
        (done, st.host.limits.max_increments, st.host.clock.clone())
    };
    if done >= cap {
        return runtime_error(format!(
            "the simulation has taken {done} increments, the limit (raise it with --max-increments)"
        ));
    }
    let report = clock.exclude(|| s.borrow_mut().step_once())?;
    let pending: Vec<(usize, FnPtr, Vec<FrictionInput>)> = {
        let st = s.borrow();
        let sim = st.sim.as_ref().expect("started");
        let laws = st.host.script_laws.borrow();
        sim.model
            .contacts
            .iter()
            .enumerate()
            .filter(|(_, c)| matches!(c.tool.friction, FrictionLaw::External { .. }))
            .filter_map(|(i, c)| {
                laws.get(&c.tool.name)
                    .map(|f| (i, f.clone(), sim.friction_inputs(i)))
            })
            .collect()
    };
    for (c, law, inputs) in pending {
        let mu = inputs
            .iter()
            .map(|q| law.call_within_context::<f64>(ctx, (q.work, q.slip, q.pressure)))
            .collect::<ScriptResult<Vec<f64>>>();
        let applied = mu.and_then(|mu| {
            lift(
                s.borrow_mut()
                    .sim
                    .as_mut()
                    .expect("started")
                    .set_friction_coefficients(c, &mu),
            )
        });
        if let Err(e) = applied {
            // The increment converged: its history row is kept whatever the law did.
            let mut st = s.borrow_mut();
            let SimState { sim, output, .. } = &mut *st;
            if let (Some(out), Some(sim)) = (output.as_mut(), sim.as_ref()) {
                if let Err(w) = out.record(sim) {
                    eprintln!("warning: {w}");
                }
            }
            return Err(e);
        }
    }
    s.borrow_mut().record_step(&report)?;
    s.borrow().refuse_default_small_strain()?;
    if let Some(missed) = &report.until_missed {
        // Recorded (history row, frame), then the run stops: the next step would start
        // from a state its process did not reach.
        return runtime_error(missed.clone());
    }
    Ok(report)
}

/// How the solver's warning about small-strain kinematics past their range begins.
use crate::solver::simulation::kinematics_check::SMALL_STRAIN_WARNING_START as SMALL_STRAIN_WARNING;

impl SimState {
    /// A run on the default kinematics ("small": the script never chose) whose largest
    /// rotation has passed the small-strain range (`SMALL_STRAIN_ROTATION_LIMIT`, 0.1 rad:
    /// a spurious strain θ²/2 several times a metal's yield strain) stops here with the
    /// fix, rather than finishing with results that look plausible and are wrong. A script
    /// that sets `kinematics: "small"` itself keeps the solver's warning instead.
    fn refuse_default_small_strain(&self) -> ScriptResult<()> {
        use crate::solver::simulation::kinematics_check as check;
        let Some(sim) = self.sim.as_ref() else {
            return Ok(());
        };
        if self.kinematics_chosen
            || sim.model.settings.kinematics != crate::element::StrainTheory::Small
        {
            return Ok(());
        }
        let (angle, _) = check::largest_rotation(sim.points());
        if angle < check::SMALL_STRAIN_ROTATION_LIMIT {
            return Ok(());
        }
        runtime_error(format!(
            "rotation of {angle:.3} rad at t = {} is past the range of the default small-strain \
             kinematics ({} rad)\n  small strain reads a rotation θ as a stretch of about \
             θ²/2 = {:.1e}: stresses and plastic flow would be wrong from here on\n  fix: \
             sim.settings(#{{ kinematics: \"finite\" }}) for forming (large rotations and \
             strains), or kinematics: \"small\" to keep the small-strain theory knowingly",
            crate::output::significant(sim.time(), 6),
            check::SMALL_STRAIN_ROTATION_LIMIT,
            0.5 * angle * angle
        ))
    }
}

/// A tool given an empty node set can never touch the body: it would run with zero force.
fn warn_if_no_candidates(ctx: &NativeCallContext, s: &ScriptSim, t: &Tool, set: &str) {
    let st = s.borrow();
    let empty = st
        .model
        .as_ref()
        .and_then(|m| m.nodes(set).ok())
        .is_some_and(|n| n.is_empty());
    if empty && st.host.warnings {
        let p = ctx.call_position();
        eprintln!(
            "warning: {}:{}:{}: tool '{}' has no candidate nodes (node set '{set}' is empty): it \
             will exert no force",
            ctx.call_source().unwrap_or("script"),
            p.line().unwrap_or(0),
            p.position().unwrap_or(0),
            t.name
        );
    }
}

/// A tool path that moves the tool (largest component) by more than [`REACH`] times the
/// body's size is a unit or typing mistake (1e308 instead of 0.1): refused, since adaptive stepping would creep
/// along it at the minimum step.
fn check_reach(s: &ScriptSim, t: &Tool) -> ScriptResult<()> {
    let st = s.borrow();
    let Some(model) = st.model.as_ref() else {
        return Ok(());
    };
    let nodes = &model.mesh.nodes;
    let (lo, hi) = nodes.iter().fold(
        (
            crate::geometry::Vec3::repeat(f64::INFINITY),
            crate::geometry::Vec3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let size = (hi - lo).norm();
    let points = t.schedule.points();
    let Some(first) = points.first() else {
        return Ok(());
    };
    let travel = points
        .iter()
        .map(|(_, u)| (u - first.1).amax())
        .fold(0.0, f64::max);
    if size.is_finite() && !(travel <= REACH * size) {
        return fail(Error::input(
            &format!("path of tool '{}': its travel", t.name),
            format!("{travel:e}"),
            &format!(
                "is more than {REACH:e} times the body's size {size} (a unit or typing mistake?)"
            ),
        ));
    }
    Ok(())
}

/// Largest tool travel, in body sizes.
const REACH: f64 = 1e6;

/// Shared handle: Rhai values are clones of it.
pub type ScriptSim = Rc<RefCell<SimState>>;

/// What ends the REPL's loading of a script at its first `sim.step()`.
pub const DEFERRED: &str = "(repl) stepping deferred";

/// Every simulation a script created, so that the host can record a stop (or write the
/// due checkpoints at the end) whatever variables the script kept.
#[derive(Clone, Default)]
pub struct Simulations(Rc<RefCell<Vec<ScriptSim>>>);

impl std::fmt::Debug for Simulations {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Simulations({})", self.0.borrow().len())
    }
}

impl Simulations {
    fn add(&self, sim: ScriptSim) {
        self.0.borrow_mut().push(sim);
    }

    /// Whether the script has created no simulation yet.
    pub fn is_empty(&self) -> bool {
        self.0.borrow().is_empty()
    }

    /// Forgets the simulations of an earlier script.
    pub fn clear(&self) {
        self.0.borrow_mut().clear();
    }

    /// Whether any simulation has started (taken its first step or query).
    pub fn any_started(&self) -> bool {
        self.0.borrow().iter().any(|s| s.borrow().sim.is_some())
    }

    /// Records a stop in every started simulation's output folder (see
    /// [`SimState::record_stop`]).
    pub fn record_stop(&self, status: &str, reason: &str) {
        for s in self.0.borrow().iter() {
            if let Ok(mut st) = s.try_borrow_mut() {
                st.record_stop(status, reason);
            }
        }
    }

    /// Writes the checkpoints still due (the script ended normally).
    pub fn close(&self) -> crate::Result<()> {
        for s in self.0.borrow().iter() {
            if let Ok(mut st) = s.try_borrow_mut() {
                st.write_due_checkpoint()
                    .map_err(|e| Error::Script(e.to_string()))?;
            }
        }
        Ok(())
    }

    /// Names of the tools of every simulation, in the order they were added (the REPL
    /// completes them).
    pub fn tool_names(&self) -> Vec<String> {
        let mut names: Vec<String> = Vec::new();
        for s in self.0.borrow().iter() {
            if let Ok(st) = s.try_borrow() {
                for name in tool_names(&st) {
                    if !names.contains(&name) {
                        names.push(name);
                    }
                }
            }
        }
        names
    }

    /// Per tool of the one started simulation: its name and translation now (the REPL's
    /// line after `sim.step()`); empty when no simulation or several have started.
    pub fn tool_positions(&self) -> Vec<(String, [f64; 3])> {
        let sims = self.0.borrow();
        let started: Vec<_> = sims
            .iter()
            .filter_map(|s| s.try_borrow().ok())
            .filter(|st| st.sim.is_some())
            .collect();
        let [st] = started.as_slice() else {
            return Vec::new();
        };
        let sim = st.sim.as_ref().expect("started");
        tool_names(st)
            .into_iter()
            .enumerate()
            .map(|(c, name)| {
                let p = sim.tool_position(c);
                (name, [p[0], p[1], p[2]])
            })
            .collect()
    }

    /// Times of the started simulations (for the REPL's messages).
    pub fn times(&self) -> Vec<f64> {
        self.0
            .borrow()
            .iter()
            .filter_map(|s| s.borrow().sim.as_ref().map(|x| x.time()))
            .collect()
    }
}

impl SimState {
    /// Per converged increment: its index, time and per tool and candidate node the
    /// [work, mu, status code].
    pub(super) fn node_log(&self) -> &[NodeSnapshot] {
        &self.node_log
    }

    pub(super) fn model_mut(&mut self) -> ScriptResult<&mut Model> {
        match self.model.as_mut() {
            Some(m) => Ok(m),
            None => runtime_error("the model cannot be changed after the simulation has started"),
        }
    }

    /// Starts the simulation on first use (the model is frozen from then on).
    pub fn simulation(&mut self) -> ScriptResult<&mut Simulation> {
        if self.sim.is_none() {
            let Some(model) = self.model.clone() else {
                return runtime_error("the simulation has no model");
            };
            refuse_free_body(&model)?;
            let mut sim = lift(Simulation::new(model))?;
            // The run's memory bound rides on its stop request (polled at every Newton
            // iteration), so a run that passes it stops like an interrupted one.
            self.host
                .interrupt
                .set_memory_limit(self.host.limits.max_memory);
            sim.set_interrupt(self.host.interrupt.clone());
            self.model = None;
            let frame_times = match self.host.restart.as_ref() {
                Some(path) if !self.host.restart_used.get() => {
                    self.host.restart_used.set(true);
                    let max_bytes = self.host.limits.max_memory;
                    let (times, kept) = lift(load_checkpoint(path, max_bytes, &mut sim))?;
                    self.kept = kept;
                    Some(times)
                }
                _ => None,
            };
            if !self.frames.off || self.checkpoint_every > 0 {
                let dir = self.host.out_dir.clone();
                let options = self.frames.options(sim.model.settings.end_time);
                let out = match &frame_times {
                    Some(times) => lift(RunOutput::resume(&dir, &sim, options, times))?,
                    None => {
                        let mut out = lift(RunOutput::create(&dir, &sim, options))?;
                        if !self.frames.off {
                            lift(out.write_frame(&sim))?;
                        }
                        out
                    }
                };
                self.output = Some(out);
            }
            self.sim = Some(sim);
            self.started = Some(Instant::now());
        }
        Ok(self.sim.as_mut().expect("just set"))
    }

    /// Solves one increment. On failure the summary records why and the last converged
    /// state is saved; every frame already written stays. An interrupt ends the script
    /// (not catchable by `try`): the host records the stop.
    fn step_once(&mut self) -> ScriptResult<IncrementReport> {
        self.simulation()?;
        self.write_due_checkpoint()?;
        let sim = self.sim.as_mut().expect("started");
        if sim.is_finished() {
            // Not a failure: the run ended well and its summary stays as written.
            return runtime_error(after_the_end(sim));
        }
        match sim.step() {
            Ok(report) => {
                self.failure = None;
                Ok(report)
            }
            Err(Error::Interrupted(why)) if self.host.interrupt.is_raised() => {
                Err(interrupted(&why))
            }
            // The memory bound (the flag is down): a stop, recorded as such by the host.
            Err(Error::Interrupted(why)) => Err(Box::new(rhai::EvalAltResult::ErrorTerminated(
                Dynamic::from(why),
                rhai::Position::NONE,
            ))),
            Err(err) => {
                let mut err = err;
                let (kind, cycling) = err.failure();
                self.failure = Some((kind, cycling));
                if let Some(saved) = self.record_stop("stopped", &err.to_string()) {
                    err = Error::NoConvergence {
                        kind,
                        cycling,
                        message: format!(
                            "{}; {saved}",
                            err.to_string().trim_start_matches("no convergence: "),
                        ),
                    };
                }
                let sim = self.sim.as_ref().expect("started");
                match units_hint(sim, &self.frames.units) {
                    Some(hint) => Err(Box::new(rhai::EvalAltResult::ErrorRuntime(
                        // A clause of its own, which the host puts on a line of its own.
                        format!("{err}; {hint}").into(),
                        rhai::Position::NONE,
                    ))),
                    None => fail(err),
                }
            }
        }
    }

    /// Writes the periodic checkpoint due for the committed state, if any.
    fn write_due_checkpoint(&mut self) -> ScriptResult<()> {
        let (Some(out), Some(sim), Some(name)) = (
            self.output.as_ref(),
            self.sim.as_ref(),
            self.checkpoint_due.take(),
        ) else {
            return Ok(());
        };
        lift(out.write_checkpoint(sim, &name, &self.kept)).map(|_| ())
    }

    /// Records a stop of the run (no convergence, a script error, a signal, a failed
    /// write): the due checkpoint, checkpoints/final.json with the last converged state
    /// (when every unknown is finite), the history rows not written yet, and summary.json
    /// with `status` ("stopped" or "interrupted") and `reason`. A write that fails is
    /// reported on stderr naming its file and listed in the summary; the others are still
    /// made. Returns where the last converged state was saved, if it was. Nothing is
    /// written when the simulation has not started or its output is off.
    pub(super) fn record_stop(&mut self, status: &str, reason: &str) -> Option<String> {
        let wall = self.elapsed();
        let (Some(out), Some(sim)) = (self.output.as_mut(), self.sim.as_ref()) else {
            return None;
        };
        let mut failures = Vec::new();
        let note = |e: Error, failures: &mut Vec<String>| {
            eprintln!("warning: {e}");
            failures.push(e.to_string());
        };
        if let Some(name) = self.checkpoint_due.take() {
            if let Err(e) = out.write_checkpoint(sim, &name, &self.kept) {
                note(e, &mut failures);
            }
        }
        let mut saved = None;
        if sim.unknowns().iter().all(|v| v.is_finite()) {
            if self.final_saved == Some(sim.history.len()) {
                saved = out
                    .folder()
                    .resolve("checkpoints/final.json")
                    .ok()
                    .map(|p| p.display().to_string());
            } else {
                match out.write_checkpoint(sim, "checkpoints/final.json", &self.kept) {
                    Ok(path) => {
                        saved = Some(path.display().to_string());
                        self.final_saved = Some(sim.history.len());
                    }
                    Err(e) => note(e, &mut failures),
                }
            }
        } else {
            failures.push("checkpoints/final.json not written: the state is not finite".into());
        }
        if let Err(e) = out.record(sim) {
            note(e, &mut failures);
        }
        if !self.frames.off {
            if let Err(e) = out.write_last_frame(sim) {
                note(e, &mut failures);
            }
        }
        let stop = crate::output::run::Stop {
            status: status.to_string(),
            reason: reason.to_string(),
            final_checkpoint: saved.clone(),
            write_failures: failures,
            failure: self.failure,
        };
        if let Err(e) = out.write_stop_summary(sim, wall, &stop) {
            eprintln!("warning: {e}");
        }
        saved.map(|path| {
            format!(
                "last converged state (t = {}) saved in {path}",
                crate::output::significant(sim.time(), 6)
            )
        })
    }

    /// The forming limit curve and zone thresholds of the settings.
    pub(super) fn formability(&self) -> crate::output::formability::FormabilityOptions {
        self.frames.formability.clone()
    }

    /// The length unit named in the output settings ("" when none was set).
    pub(super) fn length_unit(&self) -> String {
        self.frames.units.length.clone()
    }

    /// The pseudo-time unit named in the output settings ("" when none was set).
    pub(super) fn time_unit(&self) -> String {
        self.frames.units.time.clone()
    }

    /// What the script keeps (`sim.keep`), as checkpoints store it.
    pub(super) fn keep(&mut self, name: &str, value: serde_json::Value) {
        self.kept.insert(name.to_string(), value);
    }

    pub(super) fn kept(&mut self, name: &str) -> Option<&serde_json::Value> {
        self.kept.get(name)
    }

    fn elapsed(&self) -> f64 {
        self.wall_time.unwrap_or_else(|| {
            self.started
                .map(|s| s.elapsed().as_secs_f64())
                .unwrap_or(0.0)
        })
    }

    /// Adds a top-level entry to summary.json and rewrites it at once (so that an entry
    /// added after `sim.run()` lands in the file, and a name clash is reported here).
    /// Whether this simulation writes output (summary.json among it).
    pub(super) fn has_output(&self) -> bool {
        self.output.is_some()
    }

    pub(super) fn add_summary_entry(
        &mut self,
        key: &str,
        value: serde_json::Value,
    ) -> ScriptResult<()> {
        self.simulation()?;
        let wall = self.elapsed();
        let (Some(out), Some(sim)) = (self.output.as_mut(), self.sim.as_ref()) else {
            return runtime_error("output is off for this simulation (settings output_every = 0)");
        };
        out.set_summary_entry(key, value);
        let result = out.write_summary(sim, wall, None);
        if result.is_err() {
            out.remove_summary_entry(key);
        }
        lift(result)
    }

    /// Writes the increment's outputs and keeps each contact node's history.
    fn record_step(&mut self, report: &IncrementReport) -> ScriptResult<()> {
        let frames_on = !self.frames.off;
        let fmt = |x: f64| crate::output::significant(x, 6);
        let sim = self.sim.as_ref().expect("started");
        if self.host.warnings {
            // The default kinematics past their range is an error (below), not a warning.
            let refused =
                |w: &&String| !self.kinematics_chosen && w.starts_with(SMALL_STRAIN_WARNING);
            for w in report.warnings.iter().filter(|w| !refused(w)) {
                let line = format!(
                    "warning: increment {} (t = {}): {w}",
                    report.index,
                    fmt(report.time)
                );
                match &self.progress {
                    Some(bar) => bar.suspend(|| eprintln!("{line}")),
                    None => eprintln!("{line}"),
                }
            }
        }
        if let Some(out) = self.output.as_mut() {
            lift(out.record(sim))?;
            // A production run of strokes writes the frames of its last simulated stroke
            // (beside the t = 0 frame of the blank, the same in every stroke).
            if frames_on && sim.is_last_stroke() {
                lift(out.write_frame_if_due(sim, report.index))?;
                // A process in steps: a frame at every step's end (the formed, the
                // clamped and the released shapes).
                let at_step_end =
                    report.until_met || (sim.model.steps.iter()).any(|s| s.end == report.time);
                if at_step_end && out.frame_times().last() != Some(&report.time) {
                    lift(out.write_frame(sim))?;
                }
            }
            let ck = self.checkpoint_every;
            if ck > 0 && (report.index % ck == 0 || sim.is_finished()) {
                self.checkpoint_due =
                    Some(format!("checkpoints/checkpoint_{:04}.json", report.index));
            }
        }
        let snapshot = (0..sim.model.contacts.len())
            .map(|c| {
                sim.contact_states(c)
                    .iter()
                    .map(|s| [s.work, s.mu, s.status.code()])
                    .collect()
            })
            .collect();
        self.node_log.push((report.index, report.time, snapshot));
        Ok(())
    }

    fn finish(&mut self) -> ScriptResult<()> {
        let wall = self.elapsed();
        self.wall_time = Some(wall);
        if let (Some(out), Some(sim)) = (self.output.as_mut(), self.sim.as_ref()) {
            lift(out.write_summary(sim, wall, None))?;
        }
        // The forming engineer's first answer: the largest thinning and the worst zone.
        if let Some(sim) = self.sim.as_ref() {
            if let Some(f) = crate::output::formability::evaluate(sim, &self.frames.formability) {
                for line in crate::output::formability::terminal_lines(&f) {
                    match &self.progress {
                        Some(bar) => bar.suspend(|| eprintln!("{line}")),
                        None => eprintln!("{line}"),
                    }
                }
            }
        }
        Ok(())
    }
}

fn report_map(r: &IncrementReport, tools: &[String]) -> Map {
    let mut m = Map::new();
    m.insert("index".into(), Dynamic::from(r.index as i64));
    m.insert(
        "step".into(),
        r.step.map_or(Dynamic::UNIT, |k| Dynamic::from(k as i64)),
    );
    m.insert("stroke".into(), Dynamic::from(r.stroke as i64));
    m.insert("time".into(), Dynamic::from(r.time));
    m.insert("iterations".into(), Dynamic::from(r.iterations as i64));
    m.insert("cutbacks".into(), Dynamic::from(r.cutbacks as i64));
    m.insert(
        "cutback_reasons".into(),
        Dynamic::from(strings(r.cutback_reasons.iter().map(String::as_str))),
    );
    m.insert(
        "cutback_kinds".into(),
        Dynamic::from(strings(r.cutback_kinds.iter().map(|k| k.name()))),
    );
    m.insert(
        "last_resort".into(),
        r.last_resort.clone().map_or(Dynamic::UNIT, Dynamic::from),
    );
    m.insert("dt".into(), Dynamic::from(r.dt));
    m.insert("rejected_steps".into(), Dynamic::from(r.rejected as i64));
    m.insert(
        "line_search_cuts".into(),
        Dynamic::from(r.line_search_cuts as i64),
    );
    m.insert(
        "discarded_iterations".into(),
        Dynamic::from(r.discarded_iterations as i64),
    );
    m.insert(
        "cycling_nodes".into(),
        Dynamic::from(
            r.cycling
                .iter()
                .map(|c| Dynamic::from(c.node as i64))
                .collect::<Array>(),
        ),
    );
    m.insert(
        "warnings".into(),
        Dynamic::from(strings(r.warnings.iter().map(String::as_str))),
    );
    m.insert("active_nodes".into(), Dynamic::from(r.active_nodes as i64));
    m.insert(
        "slipping_nodes".into(),
        Dynamic::from(r.slipping_nodes as i64),
    );
    let res: Array = r
        .residuals
        .iter()
        .map(|x| {
            Dynamic::from(vec![
                Dynamic::from(x.force_rel),
                Dynamic::from(x.contact),
                Dynamic::from(x.status_changes as i64),
                Dynamic::from(x.yield_changes as i64),
                Dynamic::from(x.full_step),
                Dynamic::from(x.correction),
            ])
        })
        .collect();
    m.insert("residuals".into(), Dynamic::from(res));
    let mut forces = Map::new();
    for (name, f) in tools.iter().zip(&r.tool_forces) {
        forces.insert(
            name.into(),
            Dynamic::from(f.iter().map(|v| Dynamic::from(*v)).collect::<Array>()),
        );
    }
    m.insert("tool_forces".into(), Dynamic::from(forces));
    let offsets: Map = tools
        .iter()
        .zip(&r.tool_offsets)
        .map(|(name, s)| (name.into(), Dynamic::from(*s)))
        .collect();
    m.insert("tool_offsets".into(), Dynamic::from(offsets));
    m
}

fn tool_names(s: &SimState) -> Vec<String> {
    let model = s
        .sim
        .as_ref()
        .map(|x| &x.model)
        .or(s.model.as_ref())
        .expect("model or simulation");
    model.contacts.iter().map(|c| c.tool.name.clone()).collect()
}

/// Reads a checkpoint file into `sim`; returns the times of the frames written before it
/// and the values the script kept.
/// The checkpoint file is read as the command line named it, but only if it is a regular
/// file no larger than the run's memory limit (a FIFO or a device would block or never end).
fn load_checkpoint(
    path: &std::path::Path,
    max_bytes: u64,
    sim: &mut Simulation,
) -> crate::Result<(Vec<f64>, serde_json::Map<String, serde_json::Value>)> {
    let text = crate::paths::read_named_text(path, max_bytes, "--restart")?;
    let ck = Checkpoint::from_json(&text, &path.display().to_string())?;
    let times = ck.frame_times.clone();
    let kept = ck.script.clone();
    ck.restore(sim)?;
    Ok((times, kept))
}

/// Refuses a model whose body is surely free to move as a rigid body: its supports
/// (Dirichlet conditions) leave rigid-body modes free ([`rigid_modes`]) and nothing else
/// can hold it, no tool (so no contact, no force-controlled tool) and no process step (whose
/// supports are chosen later). Such a run used to "finish" with 0 Newton iterations and an
/// energy error of 1. A body that only tools hold is left alone: contact may well hold it.
///
/// [`rigid_modes`]: crate::solver::model::rigid_modes
fn refuse_free_body(model: &Model) -> ScriptResult<()> {
    if !model.contacts.is_empty() || !model.steps.is_empty() || model.mesh.nodes.is_empty() {
        return Ok(());
    }
    let free = crate::solver::model::rigid_modes::free_rigid_body_modes(model);
    if free.is_empty() {
        return Ok(());
    }
    runtime_error(format!(
        "the body is free to move as a rigid body: its supports leave free {} and no tool can \
         touch it\n  hold it: sim.fix(set, components) on enough nodes (e.g. sim.fix(\"z-\", \
         \"xyz\")), prescribed displacements (sim.prescribe), or a tool in contact \
         (sim.add_tool)",
        free.join(", ")
    ))
}

/// The error that ends a script on an interrupt: not catchable by the script's `try`.
pub(super) fn interrupted(why: &str) -> Box<rhai::EvalAltResult> {
    Box::new(rhai::EvalAltResult::ErrorTerminated(
        Dynamic::from(format!("interrupted: {why}")),
        rhai::Position::NONE,
    ))
}

/// Registers the `Simulation` type and everything scripts do with it, one domain at a
/// time (each function below says what scripts get; docs/script-api.md, "Simulation",
/// describes every call).
pub fn register(engine: &mut Engine, host: Rc<HostOptions>) {
    engine.register_type_with_name::<ScriptSim>("Simulation");
    register_setup(engine, &host);
    register_boundary_conditions(engine);
    register_contact(engine);
    register_stepping(engine, &host);
    register_queries(engine);
    super::api_contact::register(engine);
    register_checkpoints(engine);
    register_output(engine, &host);
}

/// `simulation(mesh, material)`, a new simulation with the host's base settings, and
/// `sim.settings(#{ ... })` (the keys of [`super::settings::SETTINGS`]), before or between
/// increments.
fn register_setup(engine: &mut Engine, host: &Rc<HostOptions>) {
    let h = host.clone();
    engine.register_fn(
        "simulation",
        move |mesh: Mesh, mat: ScriptMaterial| -> ScriptResult<ScriptSim> {
            new_simulation(&h, mesh, mat)
        },
    );
    engine.register_fn("settings", |s: &mut ScriptSim, spec: Map| {
        change_settings(s, &spec)
    });
}

/// A simulation of `mesh` and `mat`, the host's base settings applied, added to the
/// host's list of simulations.
fn new_simulation(
    host: &Rc<HostOptions>,
    mesh: Mesh,
    mat: ScriptMaterial,
) -> ScriptResult<ScriptSim> {
    let mut model = lift(Model::new(mesh, mat.0))?;
    let mut knobs = Knobs {
        frames: FrameKnobs::default(),
        checkpoint_every: 0,
        max_increments: host.limits.max_increments,
        kinematics_chosen: false,
    };
    apply_settings(&mut model.settings, &mut knobs, &host.base_settings)?;
    let sim = Rc::new(RefCell::new(SimState {
        model: Some(model),
        sim: None,
        output: None,
        frames: knobs.frames,
        checkpoint_every: knobs.checkpoint_every,
        kinematics_chosen: knobs.kinematics_chosen,
        host: host.clone(),
        started: None,
        wall_time: None,
        node_log: Vec::new(),
        kept: serde_json::Map::new(),
        checkpoint_due: None,
        final_saved: None,
        failure: None,
        progress: None,
    }));
    host.simulations.add(sim.clone());
    Ok(sim)
}

/// `sim.settings(spec)`: into the model, or into a running simulation for its next
/// increments.
fn change_settings(s: &mut ScriptSim, spec: &Map) -> ScriptResult<()> {
    let mut st = s.borrow_mut();
    let mut knobs = Knobs {
        frames: st.frames.clone(),
        checkpoint_every: st.checkpoint_every,
        max_increments: st.host.limits.max_increments,
        kinematics_chosen: st.kinematics_chosen,
    };
    if let Some(model) = st.model.as_mut() {
        apply_settings(&mut model.settings, &mut knobs, spec)?;
    } else if let Some(sim) = st.sim.as_mut() {
        // A running simulation (the REPL after a rollback, say) takes new settings
        // for its next increments.
        let mut settings = sim.model.settings.clone();
        apply_settings(&mut settings, &mut knobs, spec)?;
        lift(sim.change_settings(settings))?;
    }
    st.frames = knobs.frames;
    st.checkpoint_every = knobs.checkpoint_every;
    st.kinematics_chosen = knobs.kinematics_chosen;
    Ok(())
}

/// `sim.fix(set, comps)`, `sim.prescribe(set, comps, value)` and `sim.load(set, force)`,
/// `sim.load(set, force, scale)`: held components and nodal loads of the model.
fn register_boundary_conditions(engine: &mut Engine) {
    engine.register_fn(
        "fix",
        |s: &mut ScriptSim, set: &str, comps: &str| -> ScriptResult<()> {
            let mut st = s.borrow_mut();
            lift(st.model_mut()?.prescribe(
                set,
                comps,
                crate::tool::schedule::ScalarSchedule::constant(0.0),
            ))
        },
    );
    engine.register_fn(
        "prescribe",
        |s: &mut ScriptSim, set: &str, comps: &str, value: Dynamic| -> ScriptResult<()> {
            let sched = scalar_schedule(&value)?;
            lift(s.borrow_mut().model_mut()?.prescribe(set, comps, sched))
        },
    );
    engine.register_fn(
        "load",
        |s: &mut ScriptSim, set: &str, force: Array| -> ScriptResult<()> {
            let f = vec3(&force, "load force")?;
            lift(s.borrow_mut().model_mut()?.add_load(
                set,
                f,
                crate::tool::schedule::ScalarSchedule::constant(1.0),
            ))
        },
    );
    engine.register_fn(
        "load",
        |s: &mut ScriptSim, set: &str, force: Array, scale: Dynamic| -> ScriptResult<()> {
            let f = vec3(&force, "load force")?;
            let sched = scalar_schedule(&scale)?;
            lift(s.borrow_mut().model_mut()?.add_load(set, f, sched))
        },
    );
}

/// `sim.add_tool(tool, set)` and `sim.add_tool(tool, set, r)`: contact between a tool and
/// a node set (a warning for an empty set; a path far beyond the body refused).
fn register_contact(engine: &mut Engine) {
    engine.register_fn(
        "add_tool",
        |ctx: NativeCallContext, s: &mut ScriptSim, t: Tool, set: &str| -> ScriptResult<()> {
            warn_if_no_candidates(&ctx, s, &t, set);
            check_reach(s, &t)?;
            lift(s.borrow_mut().model_mut()?.add_tool(t, set, None))
        },
    );
    engine.register_fn(
        "add_tool",
        |ctx: NativeCallContext,
         s: &mut ScriptSim,
         t: Tool,
         set: &str,
         r: Dynamic|
         -> ScriptResult<()> {
            let r = number(&r, "augmentation parameter r")?;
            warn_if_no_candidates(&ctx, s, &t, set);
            check_reach(s, &t)?;
            lift(s.borrow_mut().model_mut()?.add_tool(t, set, Some(r)))
        },
    );
}

/// `sim.step()` (one increment, its report), `sim.run()` (to the end time, with the
/// progress bar), `sim.rollback()` and `sim.rollback(n)` (undo converged increments, so
/// that the REPL can change a setting and step on).
fn register_stepping(engine: &mut Engine, host: &Rc<HostOptions>) {
    let h = host.clone();
    engine.register_fn(
        "step",
        move |ctx: NativeCallContext, s: &mut ScriptSim| -> ScriptResult<Map> { step(&ctx, s, &h) },
    );
    let h = host.clone();
    engine.register_fn(
        "run",
        move |ctx: NativeCallContext, s: &mut ScriptSim| -> ScriptResult<Map> { run(&ctx, s, &h) },
    );
    let h = host.clone();
    engine.register_fn(
        "run_step",
        move |ctx: NativeCallContext, s: &mut ScriptSim| -> ScriptResult<Dynamic> {
            run_step(&ctx, s, &h)
        },
    );
    engine.register_fn("rollback", |s: &mut ScriptSim| -> ScriptResult<f64> {
        rollback(s, 1)
    });
    engine.register_fn(
        "rollback",
        |s: &mut ScriptSim, n: i64| -> ScriptResult<f64> {
            if n < 1 {
                return runtime_error(format!("rollback({n}): the count must be >= 1"));
            }
            rollback(s, n as usize)
        },
    );
}

/// Young's modulus below which a model in mm and N (the default units) is suspect: 1,000
/// MPa is softer than any sheet metal by a factor of 40 and stiffer than rubbers and foams,
/// whose models are written knowingly.
const SUSPECT_MODULUS_MPA: f64 = 1000.0;

/// For a stop before any increment converged: when the sheet's Young's modulus reads as a
/// sheet metal's in GPa (or Pa) in a model of mm and N, the line that says so. The modulus
/// is read from the elastic tangent as 1 / (C^-1)_11, exact for isotropic elasticity.
fn units_hint(sim: &Simulation, units: &crate::output::Units) -> Option<String> {
    let in_mm_n =
        matches!(units.length.as_str(), "" | "mm") && matches!(units.force.as_str(), "" | "N");
    if !sim.history.is_empty() || !in_mm_n {
        return None;
    }
    let young = 1.0 / sim.model.material.elastic_tangent().try_inverse()?[(0, 0)];
    (young.is_finite() && young > 0.0 && young < SUSPECT_MODULUS_MPA).then(|| {
        // Four significant digits: 210.0, 0.2100.
        let decimals = (4 - young.log10().ceil() as i32).max(0) as usize;
        let young = format!("{young:.decimals$}");
        format!(
            "note: Young's modulus {young} in a model of mm and N is {young} MPa (steel \
             210,000 MPa, aluminium 70,000): if it was meant in GPa, write it times 1,000, \
             or name other units with sim.settings(#{{ units: ... }})"
        )
    })
}

/// The message for `sim.step()` after the run's end: what happened, then the fix.
fn after_the_end(sim: &Simulation) -> String {
    let end = sim.model.settings.end_time;
    let done = sim.history.len();
    if sim.model.steps.is_empty() {
        format!(
            "sim.step(): the run already reached its end time {end} (increment {done}); \
             nothing is left to step\n  to go on, raise the end time first: \
             sim.settings(#{{ end_time: {} }})",
            2.0 * end
        )
    } else {
        format!(
            "sim.step(): the process already finished its last step at time {end} \
             (increment {done}); nothing is left to step\n  to go on, add a step to sim.steps([...]) \
             before the run"
        )
    }
}

/// `sim.step()`: one increment and its report; the summary is written when it ends the
/// run.
fn step(ctx: &NativeCallContext, s: &mut ScriptSim, host: &HostOptions) -> ScriptResult<Map> {
    if host.defer_run.get() {
        // The REPL loading a script that steps itself: loading ends here, with the
        // scene built and nothing stepped.
        return Err(Box::new(rhai::EvalAltResult::ErrorTerminated(
            Dynamic::from(DEFERRED),
            rhai::Position::NONE,
        )));
    }
    let r = advance(ctx, s)?;
    let mut st = s.borrow_mut();
    if st.sim.as_ref().is_some_and(|x| x.is_finished()) {
        st.finish()?;
    }
    Ok(report_map(&r, &tool_names(&st)))
}

/// `sim.run()`: increments to the end time (a progress bar under `tribo run`), then the
/// summary; returns the last increment's report.
fn run(ctx: &NativeCallContext, s: &mut ScriptSim, host: &HostOptions) -> ScriptResult<Map> {
    if host.defer_run.get() {
        println!("(repl) sim.run() deferred: step with sim.step(), or call sim.run() to finish");
        return Ok(Map::new());
    }
    let mut st = s.borrow_mut();
    st.simulation()?;
    let end_time = st.sim.as_ref().expect("started").model.settings.end_time;
    let simulated = st.sim.as_ref().expect("started").model.strokes.simulated;
    let bar = host.progress.then(progress_bar);
    st.progress = bar.clone();
    let mut last = None;
    drop(st);
    while !s.borrow().sim.as_ref().expect("started").is_finished() {
        let r = match advance(ctx, s) {
            Ok(r) => r,
            Err(e) => {
                if let Some(b) = &bar {
                    b.abandon_with_message("stopped");
                }
                s.borrow_mut().progress = None;
                return Err(e);
            }
        };
        if let Some(b) = &bar {
            // Over all simulated strokes (time restarts in each).
            let done = ((r.stroke - 1) as f64 + r.time / end_time) / simulated as f64;
            b.set_position((1000.0 * done).round() as u64);
            b.set_message(format!(
                "increment {}, t = {:.4}, dt = {:.3e}, {} Newton iterations",
                r.index, r.time, r.dt, r.iterations
            ));
        }
        last = Some(r);
    }
    if let Some(b) = &bar {
        b.finish();
    }
    let mut st = s.borrow_mut();
    st.progress = None;
    st.finish()?;
    let names = tool_names(&st);
    Ok(last.map(|r| report_map(&r, &names)).unwrap_or_default())
}

/// `sim.run_step()`: increments to the end of the current step of a process in steps
/// (`sim.steps`), the summary written when that ends the run; returns the last increment's
/// report (an empty map when the run had already ended).
fn run_step(
    ctx: &NativeCallContext,
    s: &mut ScriptSim,
    host: &HostOptions,
) -> ScriptResult<Dynamic> {
    if host.defer_run.get() {
        // The REPL loading a script that steps itself: loading ends here, as at `sim.step()`.
        return Err(Box::new(rhai::EvalAltResult::ErrorTerminated(
            Dynamic::from(DEFERRED),
            rhai::Position::NONE,
        )));
    }
    let (step, finished) = {
        let mut st = s.borrow_mut();
        let sim = st.simulation()?;
        (sim.current_step(), sim.is_finished())
    };
    let Some(k) = step else {
        return runtime_error(
            "sim.run_step(): the simulation has no steps (give them with sim.steps([...]))",
        );
    };
    let mut last = None;
    if !finished {
        loop {
            let r = advance(ctx, s)?;
            let done = r.step != Some(k) || {
                let st = s.borrow();
                let sim = st.sim.as_ref().expect("started");
                sim.is_finished() || sim.current_step() != Some(k)
            };
            last = Some(r);
            if done {
                break;
            }
        }
    }
    let mut st = s.borrow_mut();
    if st.sim.as_ref().is_some_and(|x| x.is_finished()) {
        st.finish()?;
    }
    let names = tool_names(&st);
    Ok(Dynamic::from(
        last.map(|r| report_map(&r, &names)).unwrap_or_default(),
    ))
}

/// The bar of `sim.run()`: progress in pseudo-time (per mille), since the number of
/// adaptive increments is not known beforehand.
fn progress_bar() -> indicatif::ProgressBar {
    let b = indicatif::ProgressBar::new(1000);
    b.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {percent:>3}% of the time  {msg}  [{elapsed_precise}, ETA {eta}]",
        )
        .expect("valid template"),
    );
    b
}

/// `sim.time`, `sim.finished()`, `sim.tool_force(name)`, `sim.tool_offset(name)`,
/// `sim.tool_position(name)`, `sim.displacement(node)`, `sim.reaction(set)` and
/// `sim.history()`: the state of the simulation (a query starts it).
fn register_queries(engine: &mut Engine) {
    engine.register_get("time", |s: &mut ScriptSim| {
        s.borrow().sim.as_ref().map(|x| x.time()).unwrap_or(0.0)
    });
    engine.register_fn("finished", |s: &mut ScriptSim| {
        s.borrow().sim.as_ref().is_some_and(|x| x.is_finished())
    });
    engine.register_fn(
        "tool_force",
        |s: &mut ScriptSim, name: &str| -> ScriptResult<Array> {
            let mut st = s.borrow_mut();
            let sim = st.simulation()?;
            let c = lift(sim.model.tool_index(name))?;
            Ok(array3(&sim.tool_force(c)))
        },
    );
    // Offset of a force-controlled tool along its axis (0 for a kinematic tool).
    engine.register_fn(
        "tool_offset",
        |s: &mut ScriptSim, name: &str| -> ScriptResult<f64> {
            let mut st = s.borrow_mut();
            let sim = st.simulation()?;
            let c = lift(sim.model.tool_index(name))?;
            Ok(sim.tool_offset(c))
        },
    );
    // Translation of a tool now: its schedule plus any force-control offset.
    engine.register_fn(
        "tool_position",
        |s: &mut ScriptSim, name: &str| -> ScriptResult<Array> {
            let mut st = s.borrow_mut();
            let sim = st.simulation()?;
            let c = lift(sim.model.tool_index(name))?;
            Ok(array3(&sim.tool_position(c)))
        },
    );
    engine.register_fn(
        "displacement",
        |s: &mut ScriptSim, node: i64| -> ScriptResult<Array> {
            let mut st = s.borrow_mut();
            let sim = st.simulation()?;
            if node < 0 || node as usize >= sim.model.mesh.nodes.len() {
                return runtime_error(format!("node {node} is out of range"));
            }
            Ok(array3(&sim.displacement(node as usize)))
        },
    );
    engine.register_fn(
        "reaction",
        |s: &mut ScriptSim, set: &str| -> ScriptResult<Array> {
            let mut st = s.borrow_mut();
            let sim = st.simulation()?;
            let nodes = lift(sim.model.nodes(set))?;
            Ok(array3(&lift(sim.reaction(&nodes))?))
        },
    );
    engine.register_fn("history", |s: &mut ScriptSim| -> Array {
        let st = s.borrow();
        let names = tool_names(&st);
        st.sim
            .as_ref()
            .map(|sim| {
                // Records, not maps: an array of maps stops at Rhai's map-size limit
                // (src/script/record.rs).
                sim.history
                    .iter()
                    .map(|r| Dynamic::from(super::record::Record::new(report_map(r, &names))))
                    .collect()
            })
            .unwrap_or_default()
    });
}

/// `sim.checkpoint(path)` (the committed state, now) and the script's own values across a
/// restart: `sim.keep(name, value)`, kept in every checkpoint, and `sim.kept(name)`,
/// restored with it.
fn register_checkpoints(engine: &mut Engine) {
    engine.register_fn(
        "checkpoint",
        |s: &mut ScriptSim, path: &str| -> ScriptResult<String> {
            let mut st = s.borrow_mut();
            st.simulation()?;
            let SimState {
                sim, output, kept, ..
            } = &mut *st;
            match (output.as_ref(), sim.as_ref()) {
                (Some(out), Some(sim)) => Ok(lift(out.write_checkpoint(sim, path, kept))?
                    .display()
                    .to_string()),
                _ => runtime_error("output is off for this simulation (settings output_every = 0)"),
            }
        },
    );
    engine.register_fn(
        "keep",
        |s: &mut ScriptSim, name: &str, value: Dynamic| -> ScriptResult<()> {
            if name.is_empty() {
                return runtime_error("sim.keep needs a non-empty name");
            }
            let json = super::convert::to_json(&value, name, super::convert::JsonUse::Checkpoint)?;
            s.borrow_mut().keep(name, json);
            Ok(())
        },
    );
    engine.register_fn(
        "kept",
        |s: &mut ScriptSim, name: &str| -> ScriptResult<Dynamic> {
            let mut st = s.borrow_mut();
            // Starting the simulation loads the restart checkpoint, if any.
            st.simulation()?;
            Ok(st
                .kept(name)
                .map(super::convert::from_json)
                .unwrap_or(Dynamic::UNIT))
        },
    );
}

/// `sim.write_frame()` (a VTK frame now) and `write_text(path, text)` (a text file below
/// the run's output folder; absolute paths and '..' are refused).
fn register_output(engine: &mut Engine, host: &Rc<HostOptions>) {
    engine.register_fn("write_frame", |s: &mut ScriptSim| -> ScriptResult<()> {
        let mut st = s.borrow_mut();
        st.simulation()?;
        let SimState { sim, output, .. } = &mut *st;
        match (output.as_mut(), sim.as_ref()) {
            (Some(out), Some(sim)) => lift(out.write_frame(sim)),
            _ => runtime_error("output is off for this simulation (settings output_every = 0)"),
        }
    });
    let h = host.clone();
    engine.register_fn(
        "write_text",
        move |path: &str, text: &str| -> ScriptResult<String> {
            let folder = lift(crate::output::OutputFolder::create(&h.out_dir))?;
            let file = lift(folder.resolve_for_write(path))?;
            lift(
                crate::paths::create_file(&file)
                    .and_then(|mut f| std::io::Write::write_all(&mut f, text.as_bytes()))
                    .map_err(|e| Error::io(&file, e)),
            )?;
            Ok(file.display().to_string())
        },
    );
}

/// Undoes the last `n` converged increments (the node histories and the output files
/// with them); returns the time reached.
fn rollback(s: &mut ScriptSim, n: usize) -> ScriptResult<f64> {
    let mut st = s.borrow_mut();
    let SimState {
        sim,
        output,
        node_log,
        ..
    } = &mut *st;
    let Some(sim) = sim.as_mut() else {
        return runtime_error("nothing to roll back: the simulation has not started");
    };
    let t = lift(sim.rollback(n))?;
    let kept = sim.history.len();
    node_log.retain(|(index, _, _)| *index <= kept);
    if let Some(out) = output.as_mut() {
        lift(out.rollback(sim))?;
    }
    Ok(t)
}
