//! Everything a run writes to its output folder: VTK frames of the blank and the tools at the
//! output cadence with a .pvd series, history.csv (one row per converged increment) and
//! summary.json. Files are flushed as they are written, so a run that stops keeps
//! everything so far.

use super::{
    blank_frame, tool_frame, write_summary, write_vtu, Cadence, Configuration, HistoryCsv,
    OutputFolder, PvdSeries,
};
use crate::solver::{IncrementReport, Simulation};
use crate::Result;
use std::path::Path;

/// Why and how a run stopped before its end, for summary.json.
#[derive(Clone, Debug, Default)]
pub struct Stop {
    /// "stopped" (an error) or "interrupted" (a signal).
    pub status: String,
    pub reason: String,
    /// Where the last converged state was saved.
    pub final_checkpoint: Option<String>,
    /// Files that could not be written at the stop, each with its error.
    pub write_failures: Vec<String>,
    /// Why the last increment failed to converge, when it did (its kind, and whether some
    /// contact status cycled).
    pub failure: Option<(crate::error::Failure, bool)>,
}

/// The units of the script's numbers, for the column headers of history.csv (the engine
/// itself is unit-free). An empty name leaves the columns of that dimension without a unit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Units {
    pub length: String,
    pub force: String,
    pub time: String,
}

/// Physical dimension of a history column.
#[derive(Clone, Copy)]
enum Dimension {
    None,
    Length,
    Force,
    Energy,
    Time,
    Angle,
}

impl Units {
    fn of(&self, d: Dimension) -> String {
        match d {
            Dimension::None => String::new(),
            Dimension::Length => self.length.clone(),
            Dimension::Force => self.force.clone(),
            Dimension::Time => self.time.clone(),
            Dimension::Angle => "rad".into(),
            Dimension::Energy if self.force.is_empty() || self.length.is_empty() => String::new(),
            Dimension::Energy => format!("{} {}", self.force, self.length),
        }
    }

    /// `name [unit]`, or `name` when the unit is unknown or the column has no dimension.
    fn column(&self, name: &str, d: Dimension) -> String {
        match self.of(d) {
            u if u.is_empty() => name.to_string(),
            u => format!("{name} [{u}]"),
        }
    }
}

/// What the frames hold, when they are written, and how history.csv and summary.json
/// label their numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputOptions {
    /// Where the blank's points are: current (default) or reference configuration.
    pub points: Configuration,
    /// When frames are written.
    pub cadence: Cadence,
    /// Units named in history.csv's header.
    pub units: Units,
    /// Fraction of the physical part the model is (1/4 for a quarter model with two planes
    /// of symmetry): forces, works and energies are the model's.
    pub model_fraction: f64,
    /// The forming limit curve and zone thresholds of the formability fields.
    pub formability: super::formability::FormabilityOptions,
    /// Chord tolerance (a length) of the trimming curves of trimmed tools in the frames;
    /// `None`: [`super::tool_frame::TRIM_TOLERANCE`] of each trimmed patch's size.
    pub trim_tolerance: Option<f64>,
}

impl OutputOptions {
    /// The defaults for a run to `end_time`: current configuration, an interval cadence, no
    /// units, the whole part.
    pub fn default_for(end_time: f64) -> Self {
        OutputOptions {
            points: Configuration::Current,
            cadence: Cadence::default_for(end_time),
            units: Units::default(),
            model_fraction: 1.0,
            formability: Default::default(),
            trim_tolerance: None,
        }
    }
}

pub struct RunOutput {
    folder: OutputFolder,
    frames: OutputOptions,
    pvd: PvdSeries,
    history: HistoryCsv,
    /// Entries a script added to summary.json (top level, beside the built-in ones).
    extra: serde_json::Map<String, serde_json::Value>,
    /// Time of each frame written (frame i is frames/frame_{i:04}.vtu).
    frame_times: Vec<f64>,
    /// Per tool with tool-side fields, its field grid's nodes sampled once for all its
    /// frames (`tool_fields::GridSamples`: the surface does not change during a run).
    field_samples: Vec<Option<super::tool_fields::GridSamples>>,
    /// Seconds spent writing frames: the blank's, and the tools' (summary.json's
    /// `phase_times_s.frames` and `.tool_frames`), so that a run says what its output cost.
    frame_seconds: f64,
    tool_frame_seconds: f64,
    /// The solid-shell's local-solve counts when this output began: summary.json reports
    /// this process's calls since ([`crate::element::solid_shell_counts`]).
    local_counts: crate::element::solid_shell_counts::Counts,
}

impl RunOutput {
    pub fn create(dir: &Path, sim: &Simulation, frames: OutputOptions) -> Result<Self> {
        let folder = OutputFolder::create(dir)?;
        for (path, pid) in remove_stale_temporaries(folder.root()) {
            eprintln!(
                "note: removed {}, left by process {pid} (no longer running) in the middle of a write",
                path.display()
            );
        }
        let pvd = PvdSeries::new(folder.root(), "frames")?;
        use Dimension::*;
        let mut columns: Vec<(String, Dimension)> = [
            ("increment", None),
            ("time", Time),
            ("dt", Time),
            ("newton_iterations", None),
            ("cutbacks", None),
            ("force_residual_rel", None),
            ("contact_residual", None),
            ("active_nodes", None),
            ("slipping_nodes", None),
            ("rejected_steps", None),
            ("line_search_cuts", None),
            ("discarded_iterations", None),
            ("cycling_nodes", None),
            ("frozen_nodes", None),
            ("step_limit", None),
            ("next_dt", Time),
            ("max_plastic_strain_increment", None),
            ("max_rotation_increment", Angle),
            ("max_slip_increment", Length),
        ]
        .iter()
        .map(|(s, d)| (s.to_string(), *d))
        .collect();
        if !sim.model.steps.is_empty() {
            // A process in steps: which step (0, 1, ... in the order of summary.json's
            // `steps`) each increment belongs to. Single-step runs keep their columns.
            columns.insert(1, ("step".to_string(), None));
        }
        if sim.model.strokes.total > 1 {
            // A production run of strokes: the stroke of each increment, from 1 (time
            // restarts at 0 in every stroke). Runs of one stroke keep their columns.
            columns.insert(1, ("stroke".to_string(), None));
        }
        for c in &sim.model.contacts {
            for axis in ["x", "y", "z"] {
                columns.push((format!("{}_force_{axis}", c.tool.name), Force));
            }
        }
        for c in &sim.model.contacts {
            columns.push((format!("{}_frictional_dissipation", c.tool.name), Energy));
        }
        for c in sim
            .model
            .contacts
            .iter()
            .filter(|c| c.tool.force_control.is_some())
        {
            columns.push((format!("{}_offset", c.tool.name), Length));
        }
        for name in [
            "tool_work",
            "load_work",
            "support_work",
            "elastic_energy",
            "plastic_dissipation",
        ] {
            columns.push((name.to_string(), Energy));
        }
        columns.push(("energy_balance_error".into(), None));
        columns.push(("model_fraction".into(), None));
        let columns: Vec<String> = (columns.iter())
            .map(|(name, d)| frames.units.column(name, *d))
            .collect();
        let history = HistoryCsv::create(folder.resolve_for_write("history.csv")?, &columns)?;
        Ok(RunOutput {
            folder,
            frames,
            pvd,
            history,
            extra: serde_json::Map::new(),
            frame_times: Vec::new(),
            field_samples: Vec::new(),
            frame_seconds: 0.0,
            tool_frame_seconds: 0.0,
            local_counts: crate::element::solid_shell_counts::snapshot(),
        })
    }

    /// Continues the output of a restarted run in `dir`: history.csv is written again from
    /// the restored increment reports, and the frames the run had written before the
    /// checkpoint (`frame_times`) are listed in the .pvd when their files are there.
    pub fn resume(
        dir: &Path,
        sim: &Simulation,
        frames: OutputOptions,
        frame_times: &[f64],
    ) -> Result<Self> {
        let mut out = RunOutput::create(dir, sim, frames)?;
        for (i, &t) in frame_times.iter().enumerate() {
            let names = out.frame_files(sim, i);
            if out.folder.resolve(&names[0].1)?.is_file() {
                let parts: Vec<(&str, &Path)> = (names.iter())
                    .filter(|(_, f)| out.folder.resolve(f).is_ok_and(|p| p.is_file()))
                    .map(|(n, f)| (n.as_str(), Path::new(f.as_str())))
                    .collect();
                out.pvd.add_parts(t, &parts)?;
            }
        }
        out.frame_times = frame_times.to_vec();
        out.record(sim)?;
        Ok(out)
    }

    /// Times of the frames written so far.
    pub fn frame_times(&self) -> &[f64] {
        &self.frame_times
    }

    /// Writes the committed state as a checkpoint at `relative` (below the output folder),
    /// with the values the script keeps (`script`).
    pub fn write_checkpoint(
        &self,
        sim: &Simulation,
        relative: &str,
        script: &serde_json::Map<String, serde_json::Value>,
    ) -> Result<std::path::PathBuf> {
        let path = self.folder.resolve_for_write(relative)?;
        let mut checkpoint =
            crate::solver::simulation::checkpoint::Checkpoint::of(sim, self.frame_times.clone());
        checkpoint.script = script.clone();
        let json = checkpoint.to_json()?;
        super::write_atomic(&path, json.as_bytes())?;
        Ok(path)
    }

    pub fn folder(&self) -> &OutputFolder {
        &self.folder
    }

    /// Appends a row to history.csv for every increment of `sim.history` not written yet
    /// (a fixed step cut back into several increments gives several rows). After a
    /// rollback the file is written again from the remaining increments.
    pub fn record(&mut self, sim: &Simulation) -> Result<()> {
        if self.history.rows() > sim.history.len() {
            let path = self.history.path().to_path_buf();
            let columns = self.history.columns().to_vec();
            self.history = HistoryCsv::create(path, &columns)?;
        }
        for r in &sim.history[self.history.rows()..] {
            self.record_one(sim, r)?;
        }
        Ok(())
    }

    fn record_one(&mut self, sim: &Simulation, r: &IncrementReport) -> Result<()> {
        let last = r.residuals.last();
        let mut row = vec![
            r.index as f64,
            r.time,
            r.dt,
            r.iterations as f64,
            r.cutbacks as f64,
            last.map_or(0.0, |x| x.force_rel),
            last.map_or(0.0, |x| x.contact),
            r.active_nodes as f64,
            r.slipping_nodes as f64,
            r.rejected as f64,
            r.line_search_cuts as f64,
            r.discarded_iterations as f64,
            r.cycling.len() as f64,
            r.cycling.iter().filter(|c| c.frozen.is_some()).count() as f64,
            r.limit.code(),
            r.next_dt,
            r.measures.plastic_strain,
            r.measures.rotation,
            r.measures.slip,
        ];
        if let Some(k) = r.step {
            row.insert(1, k as f64);
        }
        if sim.model.strokes.total > 1 {
            row.insert(1, r.stroke as f64);
        }
        for f in &r.tool_forces {
            row.extend_from_slice(f);
        }
        let e = &r.energy;
        row.extend_from_slice(&e.frictional_dissipation);
        for (c, contact) in sim.model.contacts.iter().enumerate() {
            if contact.tool.force_control.is_some() {
                row.push(r.tool_offsets[c]);
            }
        }
        row.extend_from_slice(&[
            e.tool_work,
            e.load_work,
            e.support_work,
            e.elastic_energy,
            e.plastic_dissipation,
            e.relative_error,
            self.frames.model_fraction,
        ]);
        self.history.append(&row)
    }

    /// (block name, file) of each part of frame `index`: the blank, then every tool with a
    /// display surface (patch and analytic surfaces), as frames/frame_NNNN.vtu and
    /// frames/frame_NNNN_<tool>.vtu.
    fn frame_files(&self, sim: &Simulation, index: usize) -> Vec<(String, String)> {
        let mut files = vec![("blank".to_string(), format!("frames/frame_{index:04}.vtu"))];
        for c in &sim.model.contacts {
            let shown = c.tool.surface.as_patch_surface().is_some()
                || c.tool.surface.analytic_shape().is_some();
            if shown {
                files.push((
                    c.tool.name.clone(),
                    format!("frames/frame_{index:04}_{}.vtu", file_safe(&c.tool.name)),
                ));
            }
        }
        files
    }

    /// The output options of this run.
    pub fn options(&self) -> &OutputOptions {
        &self.frames
    }

    /// Writes the committed state as frames/frame_NNNN.vtu (the blank) and
    /// frames/frame_NNNN_<tool>.vtu (each tool's display surface at its pose), and adds them
    /// to frames.pvd as the parts of one time.
    pub fn write_frame(&mut self, sim: &Simulation) -> Result<()> {
        let index = self.frame_times.len();
        let files = self.frame_files(sim, index);
        let started = std::time::Instant::now();
        write_vtu(
            &self.folder.resolve_for_write(&files[0].1)?,
            &blank_frame::frame_against(sim, self.frames.points, None, &self.frames.formability),
        )?;
        let tools_started = std::time::Instant::now();
        self.frame_seconds += (tools_started - started).as_secs_f64();
        let mut tool_files = files[1..].iter();
        let region = tool_frame::DisplayRegion::around(&sim.model.mesh.nodes);
        for (c, contact) in sim.model.contacts.iter().enumerate() {
            let pose = sim.tool_pose(c);
            // A tool with tool-side fields is drawn on its field grid, carrying the fields,
            // worn when a geometry update of the strokes has worn it.
            let with_fields = (sim.tool_fields(c))
                .zip(contact.tool.surface.as_patch_surface())
                .map(|(fields, surface)| {
                    let samples = self.field_samples(c, surface, fields);
                    super::tool_fields::frame_on(samples, fields, &pose, sim.applied_tool_wear(c))
                });
            if let Some(tool) = with_fields.or_else(|| {
                tool_frame::tool_frame(&contact.tool, &pose, &region, self.frames.trim_tolerance)
            }) {
                let (_, file) = tool_files.next().expect("one file per shown tool");
                write_vtu(&self.folder.resolve_for_write(file)?, &tool)?;
            }
        }
        self.tool_frame_seconds += tools_started.elapsed().as_secs_f64();
        let parts: Vec<(&str, &Path)> = (files.iter())
            .map(|(n, f)| (n.as_str(), Path::new(f.as_str())))
            .collect();
        self.pvd.add_parts(sim.time(), &parts)?;
        self.frame_times.push(sim.time());
        Ok(())
    }

    /// Tool `c`'s field-grid nodes, sampled at its first frame (or again if its grids
    /// differ from those sampled).
    fn field_samples(
        &mut self,
        c: usize,
        surface: &crate::geometry::PatchSurface,
        fields: &crate::tool::ToolFields,
    ) -> &super::tool_fields::GridSamples {
        if self.field_samples.len() <= c {
            self.field_samples.resize(c + 1, None);
        }
        let slot = &mut self.field_samples[c];
        if !slot.as_ref().is_some_and(|s| s.fits(fields)) {
            *slot = Some(super::tool_fields::GridSamples::new(surface, fields));
        }
        slot.as_ref().expect("sampled above")
    }

    /// Writes a frame if the cadence asks for one after increment `index` (or the run has
    /// finished, or no frame exists yet).
    pub fn write_frame_if_due(&mut self, sim: &Simulation, index: usize) -> Result<()> {
        let last = self.frame_times.last().copied();
        if self
            .frames
            .cadence
            .due(index, sim.time(), last, sim.is_finished())
        {
            self.write_frame(sim)?;
        }
        Ok(())
    }

    /// A frame of the committed state unless the last frame is already at its time (a run
    /// that stops keeps its last converged state in ParaView).
    pub fn write_last_frame(&mut self, sim: &Simulation) -> Result<()> {
        if self.frame_times.last() != Some(&sim.time()) {
            self.write_frame(sim)?;
        }
        Ok(())
    }

    /// After a rollback to `sim`'s time: forgets the frames written after it (their files
    /// are removed) and rewrites frames.pvd and history.csv to the kept history.
    pub fn rollback(&mut self, sim: &Simulation) -> Result<()> {
        let kept = self
            .frame_times
            .iter()
            .take_while(|&&t| t <= sim.time())
            .count();
        for index in kept..self.frame_times.len() {
            for (_, file) in self.frame_files(sim, index) {
                if let Ok(path) = self.folder.resolve(&file) {
                    let _ = std::fs::remove_file(path);
                }
            }
        }
        self.frame_times.truncate(kept);
        self.pvd.truncate(kept)?;
        self.record(sim)
    }

    /// Adds (or replaces) a top-level entry of summary.json, written with the next
    /// [`write_summary`](Self::write_summary); a built-in entry's name is refused there.
    pub fn set_summary_entry(&mut self, key: &str, value: serde_json::Value) {
        self.extra.insert(key.to_string(), value);
    }

    /// Removes a script entry of summary.json.
    pub fn remove_summary_entry(&mut self, key: &str) {
        self.extra.remove(key);
    }

    /// Writes summary.json; `error` records why a run stopped early.
    pub fn write_summary(
        &self,
        sim: &Simulation,
        wall_time_s: f64,
        error: Option<&str>,
    ) -> Result<()> {
        let stop = error.map(|e| Stop {
            status: "stopped".into(),
            reason: e.to_string(),
            final_checkpoint: None,
            write_failures: Vec::new(),
            failure: None,
        });
        self.write_summary_of(sim, wall_time_s, stop.as_ref())
    }

    /// Writes summary.json for a run that stopped before its end (see [`Stop`]).
    pub fn write_stop_summary(
        &self,
        sim: &Simulation,
        wall_time_s: f64,
        stop: &Stop,
    ) -> Result<()> {
        self.write_summary_of(sim, wall_time_s, Some(stop))
    }

    fn write_summary_of(
        &self,
        sim: &Simulation,
        wall_time_s: f64,
        stop: Option<&Stop>,
    ) -> Result<()> {
        let tools: serde_json::Map<String, serde_json::Value> = sim
            .model
            .contacts
            .iter()
            .enumerate()
            .map(|(c, contact)| {
                let f = sim.tool_force(c);
                let mut entry = serde_json::json!({
                        "final_force": [f.x, f.y, f.z],
                        "surface": contact.tool.surface.describe(),
                        "friction": contact.tool.friction.describe(),
                        "work_measure": contact.tool.friction.bernstein().map(|l| l.measure().name()),
                        "frictional_dissipation": sim.energy().frictional_dissipation.get(c),
                        "candidate_nodes": contact.candidates.len(),
                        "offset": sim.tool_offset(c),
                        "position": <[f64; 3]>::from(sim.tool_position(c)),
                        "force_control": contact.tool.force_control.as_ref().map(|fc| serde_json::json!({
                            "axis": [fc.axis.x, fc.axis.y, fc.axis.z],
                            "scheduled_force": fc.force.value(sim.time()),
                        })),
                    });
                // Only a tool with fields has the entry, so that other runs' summaries (and
                // the columns `tribo sweep collect` makes of them) are unchanged.
                if let Some((fields, surface)) =
                    (sim.tool_fields(c)).zip(contact.tool.surface.as_patch_surface())
                {
                    entry["tool_fields"] = super::tool_fields::summary(surface, fields);
                }
                (contact.tool.name.clone(), entry)
            })
            .collect();
        let iterations: usize = sim.history.iter().map(|r| r.iterations).sum();
        let settings = &sim.model.settings;
        let mut summary = serde_json::json!({
            "status": match stop {
                Some(s) => s.status.as_str(),
                None if sim.is_finished() => "finished",
                None => "running",
            },
            "error": stop.filter(|s| s.status != "interrupted").map(|s| &s.reason),
            "stop_reason": stop.map(|s| &s.reason),
            "failure": stop.and_then(|s| s.failure).map(|(kind, cycling)| serde_json::json!({
                "kind": kind.name(),
                "status_cycling": cycling,
            })),
            "final_checkpoint": stop.and_then(|s| s.final_checkpoint.as_ref()),
            "write_failures": stop.map(|s| &s.write_failures),
            "time": sim.time(),
            "end_time": settings.end_time,
            "increments": sim.history.len(),
            "newton_iterations": iterations,
            "cutbacks": sim.history.iter().map(|r| r.cutbacks).sum::<usize>(),
            "last_resort_increments": sim.history.iter().filter(|r| r.last_resort.is_some()).count(),
            "cutback_reasons": sim.history.iter().flat_map(|r| {
                r.cutback_reasons.iter().enumerate().map(move |(i, why)| serde_json::json!({
                    "increment": r.index,
                    "reason": why,
                    "kind": r.cutback_kinds.get(i).map(|k| k.name()),
                }))
            }).collect::<Vec<_>>(),
            "symbolic_analyses": sim.symbolic_analyses(),
            "wall_time_s": wall_time_s,
            "phase_times_s": {
                "elements": sim.phase_times.elements,
                "contact": sim.phase_times.contact,
                "factorization_and_solve": sim.phase_times.factorization_and_solve,
                "tool_fields": sim.phase_times.tool_fields,
                "frames": self.frame_seconds,
                "tool_frames": self.tool_frame_seconds,
            },
            "evaluations": {
                "full": sim.phase_times.full_evaluations,
                "residual_only": sim.phase_times.residual_evaluations,
                "jacobian_completions": sim.phase_times.jacobian_completions,
                "with_approximate_local_solves": sim.phase_times.approximate_evaluations,
                "solid_shell_local": local_counts_json(&self.local_counts),
            },
            "kinematics": settings.kinematics.name(),
            "settings": super::run_settings::settings_json(settings),
            "nodes": sim.model.mesh.nodes.len(),
            "elements": sim.model.mesh.hexes.len(),
            "contact": {
                "enforcement": format!("{:?}", settings.contact.enforcement),
                "frame": format!("{:?}", settings.contact.frame),
                "curvature_terms": settings.contact.curvature,
                "friction_update": format!("{:?}", settings.contact.friction_update),
            },
            "energy": sim.energy(),
            "tools": tools,
            "frames": self.frame_times.len(),
            "frame_cadence": self.frames.cadence.describe(),
            "frame_points": self.frames.points.name(),
            "model_fraction": self.frames.model_fraction,
            "units": {
                "length": self.frames.units.length,
                "force": self.frames.units.force,
                "time": self.frames.units.time,
            },
            "rejected_steps": sim.history.iter().map(|r| r.rejected).sum::<usize>(),
            "line_search_cuts": sim.history.iter().map(|r| r.line_search_cuts).sum::<usize>(),
            "discarded_iterations": sim.history.iter().map(|r| r.discarded_iterations).sum::<usize>(),
            "increments_with_cycling": sim.history.iter().filter(|r| !r.cycling.is_empty()).count(),
            "step_control": format!("{:?}", settings.stepping.mode).to_lowercase(),
            "formability": super::formability::evaluate(sim, &self.frames.formability)
                .map(|f| super::formability::summary(sim, &f)),
        });
        if let Some(map) = summary.as_object_mut() {
            if !sim.model.steps.is_empty() {
                map.insert("steps".into(), steps_summary(sim, &self.frame_times));
                if !sim.springback().is_empty() {
                    map.insert("springback".into(), springback_summary(sim));
                }
            }
            let strokes = sim.model.strokes;
            if strokes.total > 1 {
                // The tools' `tool_fields` are totals over all strokes (extrapolated to
                // `total` when fewer were simulated); everything else is the last stroke's.
                map.insert(
                    "strokes".into(),
                    serde_json::json!({
                        "total": strokes.total,
                        "simulated": strokes.simulated,
                        "extrapolated": strokes.extrapolated(),
                        "current": sim.stroke(),
                    }),
                );
            }
            for (key, value) in &self.extra {
                if map.contains_key(key) {
                    return Err(crate::Error::Input(format!(
                        "summary entry '{key}' is written by the engine; choose another name"
                    )));
                }
                map.insert(key.clone(), value.clone());
            }
        }
        write_summary(&self.folder.resolve_for_write("summary.json")?, &summary)
    }
}

/// A tool name as part of a file name: ASCII letters, digits, `-` and `_` kept, anything
/// else `_`.
fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Removes the temporary files of atomic writes (`.NAME.PID.tmp`, see `write_atomic`) that
/// a process killed in the middle of a write left in `root`, `root/frames` and
/// `root/checkpoints`: only names of that pattern whose NAME is one of the run's own files
/// (.json, .vtu, .pvd, .csv, .svg) and whose process is no longer running (Linux: no
/// /proc/PID; elsewhere nothing is removed). Returns the removed files with their PIDs.
pub fn remove_stale_temporaries(root: &Path) -> Vec<(std::path::PathBuf, u32)> {
    let proc_fs = Path::new("/proc/self").exists();
    let mut removed = Vec::new();
    if !proc_fs {
        return removed;
    }
    for dir in [
        root.to_path_buf(),
        root.join("frames"),
        root.join("checkpoints"),
    ] {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            let Some(pid) = name.to_str().and_then(stale_temporary_pid) else {
                continue;
            };
            let running = Path::new("/proc").join(pid.to_string()).exists();
            let is_file = entry.file_type().is_ok_and(|t| t.is_file());
            if !running && is_file && std::fs::remove_file(entry.path()).is_ok() {
                removed.push((entry.path(), pid));
            }
        }
    }
    removed
}

/// The PID in a name `.NAME.PID.tmp` written by `write_atomic` for one of the run's files.
fn stale_temporary_pid(name: &str) -> Option<u32> {
    let inner = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (target, pid) = inner.rsplit_once('.')?;
    if pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let ours = [".json", ".vtu", ".pvd", ".csv", ".svg"]
        .iter()
        .any(|ext| target.len() > ext.len() && target.ends_with(ext));
    if !ours {
        return None;
    }
    pid.parse().ok()
}

/// The solid-shell's local solves since `start` (`evaluations.solid_shell_local` of
/// summary.json; null without a solid-shell call): calls and material updates of all a
/// call's points per kind of call, each as `[residual-only, with stiffness]`, their ratio,
/// and the histograms of [`crate::element::solid_shell_counts`].
fn local_counts_json(start: &crate::element::solid_shell_counts::Counts) -> serde_json::Value {
    use crate::element::solid_shell_counts::{snapshot, KINDS, STEP_DECADES};
    let c = snapshot().since(start);
    let calls = c.total_calls();
    if calls == 0 {
        return serde_json::Value::Null;
    }
    let per_kind = |v: &[[u64; 2]; KINDS.len()]| -> serde_json::Map<String, serde_json::Value> {
        KINDS
            .iter()
            .zip(v)
            .map(|((_, name), n)| (name.to_string(), serde_json::json!(n)))
            .collect()
    };
    let decades: Vec<String> = STEP_DECADES
        .iter()
        .map(|d| format!("<= {d:e}"))
        .chain(["larger".to_string()])
        .collect();
    serde_json::json!({
        "calls": calls,
        "material_updates": c.total_updates(),
        "updates_per_call": c.total_updates() as f64 / calls as f64,
        "calls_by_kind": per_kind(&c.calls),
        "updates_by_kind": per_kind(&c.updates),
        "predicted_calls_by_updates": c.predicted_updates,
        "first_step_decades": decades,
        "predicted_first_step": c.first_step,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_our_temporaries_of_dead_processes_are_removed() {
        assert_eq!(
            stale_temporary_pid(".checkpoint_0004.json.4242.tmp"),
            Some(4242)
        );
        assert_eq!(stale_temporary_pid(".frame_0001.vtu.7.tmp"), Some(7));
        for other in [
            "checkpoint_0004.json.4242.tmp",
            ".checkpoint_0004.json.42a.tmp",
            ".notes.txt.4242.tmp",
            ".json.4242.tmp",
            ".checkpoint_0004.json..tmp",
            ".checkpoint_0004.json.4242.tmp~",
        ] {
            assert_eq!(stale_temporary_pid(other), None, "{other}");
        }
        let root = crate::output::test_util::temp_dir("stale");
        std::fs::create_dir_all(root.join("checkpoints")).unwrap();
        // A PID above the kernel's pid_max (4194304) is never running.
        let dead = root.join("checkpoints/.checkpoint_0002.json.99999999.tmp");
        let alive = root.join(format!(
            "checkpoints/.checkpoint_0003.json.{}.tmp",
            std::process::id()
        ));
        let foreign = root.join("checkpoints/.mine.txt.99999999.tmp");
        for f in [&dead, &alive, &foreign] {
            std::fs::write(f, "x").unwrap();
        }
        let removed = remove_stale_temporaries(&root);
        assert_eq!(removed, vec![(dead.clone(), 99999999)]);
        assert!(!dead.exists() && alive.exists() && foreign.exists());
        let _ = std::fs::remove_dir_all(&root);
    }
}

/// summary.json's `springback`: per release step completed, its name and the largest and
/// RMS nodal springback displacement from the end of loading, rigid part removed
/// (solver `simulation::springback`).
fn springback_summary(sim: &Simulation) -> serde_json::Value {
    let entries = sim.springback().iter().map(|m| {
        serde_json::json!({
            "step": sim.model.steps[m.step].name,
            "max_displacement": m.max,
            "rms_displacement": m.rms,
        })
    });
    serde_json::Value::Array(entries.collect())
}

/// summary.json's `steps`: per step of the process, its name, interval of pseudo-time and
/// planned increments, and what the run did in it (increments, Newton iterations,
/// cutbacks, frames, whether it was completed, its condition and when it was met).
fn steps_summary(sim: &Simulation, frame_times: &[f64]) -> serde_json::Value {
    use crate::solver::model::steps;
    let list = &sim.model.steps;
    let entries = list.iter().enumerate().map(|(k, s)| {
        let done: Vec<&IncrementReport> =
            sim.history.iter().filter(|r| r.step == Some(k)).collect();
        let frames: Vec<usize> = (0..frame_times.len())
            .filter(|&i| frame_times[i] > 0.0 && steps::step_at(list, frame_times[i]) == Some(k))
            .collect();
        serde_json::json!({
            "name": s.name,
            "start_time": steps::start(list, k),
            "end_time": s.end,
            "planned_increments": s.increments,
            "increments": done.len(),
            "first_increment": done.first().map(|r| r.index),
            "last_increment": done.last().map(|r| r.index),
            "newton_iterations": done.iter().map(|r| r.iterations).sum::<usize>(),
            "cutbacks": done.iter().map(|r| r.cutbacks).sum::<usize>(),
            "frames": frames,
            "completed": sim.time() >= s.end * (1.0 - 1e-12),
            "end_when": s.until.as_ref().map(|u| u.describe(&sim.model.contacts[u.tool].tool.name)),
            "end_when_met_at": sim.step_ends().iter().find(|e| e.0 == k).map(|e| e.1),
        })
    });
    serde_json::Value::Array(entries.collect())
}
