//! Everything a run writes to its output folder: a VTK frame per output increment with a
//! .pvd series, history.csv (one row per converged increment) and summary.json.
//! Files are flushed as they are written, so a run that stops keeps everything so far.

use super::{write_summary, write_vtu, Field, Frame, HistoryCsv, OutputFolder, PvdSeries};
use crate::contact::ContactStatus;
use crate::geometry::Vec3;
use crate::solver::{IncrementReport, Simulation};
use crate::Result;
use std::path::Path;

pub struct RunOutput {
    folder: OutputFolder,
    pvd: PvdSeries,
    history: HistoryCsv,
    /// Time of each frame written (frame i is frames/frame_{i:04}.vtu).
    frame_times: Vec<f64>,
}

impl RunOutput {
    pub fn create(dir: &Path, sim: &Simulation) -> Result<Self> {
        let folder = OutputFolder::create(dir)?;
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

    /// Writes the committed state as a checkpoint at `relative` (below the output folder).
    pub fn write_checkpoint(&self, sim: &Simulation, relative: &str) -> Result<std::path::PathBuf> {
        let path = self.folder.resolve_for_write(relative)?;
        let json =
            crate::solver::checkpoint::Checkpoint::of(sim, self.frame_times.clone()).to_json()?;
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
            self.record_one(r)?;
        }
        Ok(())
    }

    fn record_one(&mut self, r: &IncrementReport) -> Result<()> {
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

    /// Writes summary.json; `error` records why a run stopped early.
    pub fn write_summary(
        &self,
        sim: &Simulation,
        wall_time_s: f64,
        error: Option<&str>,
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
                    }),
                )
            })
            .collect();
        let iterations: usize = sim.history.iter().map(|r| r.iterations).sum();
        let settings = &sim.model.settings;
        let summary = serde_json::json!({
            "status": if error.is_some() { "stopped" } else if sim.is_finished() { "finished" } else { "running" },
            "error": error,
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
        write_summary(&self.folder.resolve_for_write("summary.json")?, &summary)
    }
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
