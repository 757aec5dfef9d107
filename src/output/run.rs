//! Everything a run writes to its output folder: a VTK frame per output increment with a
//! .pvd series, history.csv (one row per converged increment) and summary.json.
//! Files are flushed as they are written, so a run that stops keeps everything so far.

use super::{write_summary, write_vtu, Field, Frame, HistoryCsv, OutputFolder, PvdSeries};
use crate::contact::ContactStatus;
use crate::geometry::Vec3;
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
}

pub struct RunOutput {
    folder: OutputFolder,
    pvd: PvdSeries,
    history: HistoryCsv,
    /// Entries a script added to summary.json (top level, beside the built-in ones).
    extra: serde_json::Map<String, serde_json::Value>,
    /// Time of each frame written (frame i is frames/frame_{i:04}.vtu).
    frame_times: Vec<f64>,
}

impl RunOutput {
    pub fn create(dir: &Path, sim: &Simulation) -> Result<Self> {
        let folder = OutputFolder::create(dir)?;
        for (path, pid) in remove_stale_temporaries(folder.root()) {
            eprintln!(
                "note: removed {}, left by process {pid} (no longer running) in the middle of a write",
                path.display()
            );
        }
        let pvd = PvdSeries::new(folder.root(), "frames")?;
        let mut columns: Vec<String> = [
            "increment",
            "time",
            "dt",
            "newton_iterations",
            "cutbacks",
            "force_residual_rel",
            "contact_residual",
            "active_nodes",
            "slipping_nodes",
            "rejected_steps",
            "line_search_cuts",
            "cycling_nodes",
            "frozen_nodes",
            "step_limit",
            "next_dt",
            "max_plastic_strain_increment",
            "max_rotation_increment",
            "max_slip_increment",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        for c in &sim.model.contacts {
            for axis in ["x", "y", "z"] {
                columns.push(format!("{}_force_{axis}", c.tool.name));
            }
        }
        for c in &sim.model.contacts {
            columns.push(format!("{}_frictional_dissipation", c.tool.name));
        }
        for c in sim
            .model
            .contacts
            .iter()
            .filter(|c| c.tool.force_control.is_some())
        {
            columns.push(format!("{}_offset", c.tool.name));
        }
        for name in [
            "tool_work",
            "load_work",
            "support_work",
            "elastic_energy",
            "plastic_dissipation",
            "energy_balance_error",
        ] {
            columns.push(name.to_string());
        }
        let history = HistoryCsv::create(folder.resolve_for_write("history.csv")?, &columns)?;
        Ok(RunOutput {
            folder,
            pvd,
            history,
            extra: serde_json::Map::new(),
            frame_times: Vec::new(),
        })
    }

    /// Continues the output of a restarted run in `dir`: history.csv is written again from
    /// the restored increment reports, and the frames the run had written before the
    /// checkpoint (`frame_times`) are listed in the .pvd when their files are there.
    pub fn resume(dir: &Path, sim: &Simulation, frame_times: &[f64]) -> Result<Self> {
        let mut out = RunOutput::create(dir, sim)?;
        for (i, &t) in frame_times.iter().enumerate() {
            let name = format!("frames/frame_{i:04}.vtu");
            if out.folder.resolve(&name)?.is_file() {
                out.pvd.add(t, &name)?;
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
            crate::solver::checkpoint::Checkpoint::of(sim, self.frame_times.clone());
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
            r.cycling.len() as f64,
            r.cycling.iter().filter(|c| c.frozen.is_some()).count() as f64,
            r.limit.code(),
            r.next_dt,
            r.measures.plastic_strain,
            r.measures.rotation,
            r.measures.slip,
        ];
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
        ]);
        self.history.append(&row)
    }

    /// Writes the committed state as frames/frame_NNNN.vtu and adds it to frames.pvd.
    pub fn write_frame(&mut self, sim: &Simulation) -> Result<()> {
        let name = format!("frames/frame_{:04}.vtu", self.frame_times.len());
        let path = self.folder.resolve_for_write(&name)?;
        write_vtu(&path, &frame(sim))?;
        self.pvd.add(sim.time(), &name)?;
        self.frame_times.push(sim.time());
        Ok(())
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
                (
                    contact.tool.name.clone(),
                    serde_json::json!({
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
                    }),
                )
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
            "final_checkpoint": stop.and_then(|s| s.final_checkpoint.as_ref()),
            "write_failures": stop.map(|s| &s.write_failures),
            "time": sim.time(),
            "end_time": settings.end_time,
            "increments": sim.history.len(),
            "newton_iterations": iterations,
            "cutbacks": sim.history.iter().map(|r| r.cutbacks).sum::<usize>(),
            "symbolic_analyses": sim.symbolic_analyses(),
            "wall_time_s": wall_time_s,
            "phase_times_s": {
                "elements": sim.phase_times.elements,
                "contact": sim.phase_times.contact,
                "factorization_and_solve": sim.phase_times.factorization_and_solve,
            },
            "evaluations": {
                "full": sim.phase_times.full_evaluations,
                "residual_only": sim.phase_times.residual_evaluations,
            },
            "kinematics": settings.kinematics.name(),
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
            "rejected_steps": sim.history.iter().map(|r| r.rejected).sum::<usize>(),
            "line_search_cuts": sim.history.iter().map(|r| r.line_search_cuts).sum::<usize>(),
            "increments_with_cycling": sim.history.iter().filter(|r| !r.cycling.is_empty()).count(),
            "step_control": format!("{:?}", settings.stepping.mode).to_lowercase(),
        });
        if let Some(map) = summary.as_object_mut() {
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

/// The committed state as a VTK frame: displacement and contact fields on the nodes (and,
/// for sheet meshes with through-thickness columns, the current thickness and the
/// thickness strain ln(t/t0) of each column on its nodes), element-averaged Cauchy stress,
/// von Mises stress and equivalent plastic strain on the cells. A node touching several tools shows the tool
/// pressing it hardest.
pub fn frame(sim: &Simulation) -> Frame {
    let mesh = &sim.model.mesh;
    let n = mesh.nodes.len();
    let u = sim.displacements();
    let mut status = vec![0.0; n];
    let mut gap = vec![f64::NAN; n];
    let mut lambda_n = vec![0.0; n];
    let mut lambda_t = vec![0.0; n];
    let mut pressure = vec![0.0; n];
    let mut work = vec![0.0; n];
    let mut slip = vec![0.0; n];
    let mut mu = vec![0.0; n];
    let mut theta = vec![0.0; n];
    let mut flips = vec![0.0; n];
    for (c, contact) in sim.model.contacts.iter().enumerate() {
        for (k, s) in sim.contact_states(c).iter().enumerate() {
            let node = contact.candidates[k];
            let ln = s.lambda_n();
            let first = gap[node].is_nan();
            if first || ln < lambda_n[node] || (ln == lambda_n[node] && s.gap < gap[node]) {
                status[node] = s.status.code();
                gap[node] = s.gap;
                lambda_n[node] = ln;
                lambda_t[node] = s.lambda_t_norm();
                pressure[node] = if s.status == ContactStatus::Gap {
                    0.0
                } else {
                    -ln / contact.areas[k].max(f64::MIN_POSITIVE)
                };
                mu[node] = s.mu;
                theta[node] = s.theta;
            }
            flips[node] += s.flips as f64;
            work[node] += s.work;
            slip[node] = f64::max(slip[node], s.slip);
        }
    }
    for g in gap.iter_mut().filter(|g| g.is_nan()) {
        *g = 0.0;
    }
    let per = sim.points().len() / mesh.hexes.len().max(1);
    let mut stress = vec![0.0; 6 * mesh.hexes.len()];
    let mut von_mises = vec![0.0; mesh.hexes.len()];
    let mut eq_plastic = vec![0.0; mesh.hexes.len()];
    for e in 0..mesh.hexes.len() {
        let pts = &sim.points()[e * per..(e + 1) * per];
        for p in pts {
            for i in 0..6 {
                stress[6 * e + i] += p.stress[i] / per as f64;
            }
            eq_plastic[e] += p.eq_plastic_strain / per as f64;
        }
        let s = &stress[6 * e..6 * e + 6];
        von_mises[e] = (0.5
            * ((s[0] - s[1]).powi(2) + (s[1] - s[2]).powi(2) + (s[2] - s[0]).powi(2))
            + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))
            .sqrt();
    }
    // Sheet thickness per through-thickness column (block meshes), on the column's nodes.
    let mut sheet_fields = Vec::new();
    if !mesh.columns().is_empty() {
        let disp = |n: usize| Vec3::new(u[3 * n], u[3 * n + 1], u[3 * n + 2]);
        let current = mesh.column_thicknesses(disp);
        let initial = mesh.column_thicknesses(|_| Vec3::zeros());
        let mut thickness = vec![0.0; n];
        let mut thickness_strain = vec![0.0; n];
        for (k, col) in mesh.columns().iter().enumerate() {
            for &node in col {
                thickness[node] = current[k];
                thickness_strain[node] = (current[k] / initial[k]).ln();
            }
        }
        sheet_fields.push(Field::scalar("thickness", thickness));
        sheet_fields.push(Field::scalar("thickness_strain", thickness_strain));
    }
    // VTK orders symmetric tensors xx, yy, zz, xy, yz, xz, as our Voigt vector.
    Frame {
        points: mesh.nodes.iter().map(|p| [p.x, p.y, p.z]).collect(),
        hexes: mesh.hexes.clone(),
        point_data: vec![
            Field::new("displacement", 3, u.to_vec()),
            Field::scalar("contact_status", status),
            Field::scalar("gap", gap),
            Field::scalar("lambda_n", lambda_n),
            Field::scalar("lambda_t_norm", lambda_t),
            Field::scalar("contact_pressure", pressure),
            Field::scalar("frictional_work", work),
            Field::scalar("accumulated_slip", slip),
            Field::scalar("mu", mu),
            Field::scalar("theta", theta),
            Field::scalar("stick_slip_flips", flips),
        ]
        .into_iter()
        .chain(sheet_fields)
        .collect(),
        cell_data: vec![
            Field::new("stress", 6, stress),
            Field::scalar("von_mises", von_mises),
            Field::scalar("equivalent_plastic_strain", eq_plastic),
        ],
    }
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
