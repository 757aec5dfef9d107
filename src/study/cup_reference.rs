//! The square-cup study's reference values: a Richardson extrapolation (see `richardson`) of
//! each measured quantity over a stored sequence of refined meshes.
//!
//! The finest meshes cost tens of CPU minutes, so their results are committed data
//! (`docs/studies/square_cup/reference/meshes.json`: per run its mesh, the command that made
//! it, the commit, CPU and wall seconds, Newton iterations and the measured values), and the
//! study reads them instead of running them again.
//!
//! Representative cell size of a cells x cells x layers block of the quarter blank (side
//! a = 75 mm, thickness t = 0.81 mm), after Celik et al. (2008):
//!
//! ```text
//! h = (a^2 t / (cells^2 layers))^(1/3)
//! ```
//!
//! A sequence that refines in-plane and through the thickness by the same ratio keeps the
//! cells similar, and h's ratio is that ratio. The extrapolation is made from the stored
//! sequence's three named meshes; any other stored mesh (e.g. 25 x 25 x 1 and 50 x 50 x 2) is
//! listed with its distance to the extrapolated value, a check of it.
//!
//! A second stored sequence, made with the solid-shell element
//! (`docs/studies/square_cup/reference/solid_shell_meshes.json`), is an independent check of
//! the first: trilinear hexahedra are too stiff in bending on coarse meshes (their draw-in
//! grows and their force falls with refinement), the solid-shell is not, so the two
//! families approach the converged values from different sides and their extrapolations
//! should agree within the sum of their bands ([`cross_check`]). One solid-shell layer
//! resolves the thickness by its integration rule, which stays the same along the sequence,
//! so its cell size is the in-plane one:
//!
//! ```text
//! h = a / cells        (solid-shell)
//! ```

use super::richardson::{extrapolate, Extrapolation, Level, OrderRule};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The quantities extrapolated, as the study's values name them.
pub const QUANTITIES: [&str; 4] = [
    "draw_in_dx_mm",
    "draw_in_dy_mm",
    "draw_in_dd_mm",
    "punch_force_n",
];

/// Where the stored runs live, relative to the study's output folder.
pub const STORED_FILE: &str = "square_cup/reference/meshes.json";

/// The solid-shell sequence, the independent check of the first (see the module doc).
pub const SOLID_SHELL_FILE: &str = "square_cup/reference/solid_shell_meshes.json";

/// The element of a stored sequence, as the script's `element` names it.
pub const HEXAHEDRON: &str = "hexahedron";
pub const SOLID_SHELL: &str = "solid_shell";

fn hexahedron() -> String {
    HEXAHEDRON.to_string()
}

/// One stored run of the mesh sequence.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StoredRun {
    pub cells: u32,
    pub layers: u32,
    pub command: String,
    /// User + system CPU seconds of the whole run (GNU time).
    pub cpu_s: f64,
    pub wall_s: f64,
    pub iterations: usize,
    pub increments: usize,
    pub cutbacks: usize,
    pub values: BTreeMap<String, f64>,
}

impl StoredRun {
    pub fn label(&self) -> String {
        mesh_label(self.cells, self.layers)
    }
}

/// The committed file: the runs and which three of them make the extrapolation.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StoredSequence {
    /// What the runs are and how they were made, in words.
    pub about: String,
    /// The commit of the engine that ran them.
    pub commit: String,
    /// The element every run used (`hexahedron`: F-bar trilinear, `solid_shell`).
    #[serde(default = "hexahedron")]
    pub element: String,
    pub travel_mm: f64,
    pub step_mm: f64,
    /// Blank half side and thickness [mm], for the representative cell size.
    pub half_side_mm: f64,
    pub thickness_mm: f64,
    /// (cells, layers) of the three meshes extrapolated from, finest first.
    pub sequence: [[u32; 2]; 3],
    pub rule: OrderRule,
    pub runs: Vec<StoredRun>,
}

/// The extrapolated reference, per quantity, with the sequence it came from.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExtrapolatedReference {
    /// The element of the stored runs.
    #[serde(default = "hexahedron")]
    pub element: String,
    /// The meshes extrapolated from, finest first, e.g. "48x48x4".
    pub sequence: Vec<String>,
    /// Refinement ratios of h between consecutive meshes (fine/medium, medium/coarse).
    pub ratios: [f64; 2],
    /// Whether every refinement keeps the cells similar (same ratio in-plane and through
    /// the thickness).
    pub similar: bool,
    pub rule: OrderRule,
    pub quantities: BTreeMap<String, Extrapolation>,
    /// Every stored run (the three above and the checks), as committed.
    pub runs: Vec<StoredRun>,
    pub commit: String,
    pub step_mm: f64,
}

impl ExtrapolatedReference {
    /// The extrapolated values, keyed like the study's measured values.
    pub fn values(&self) -> BTreeMap<String, f64> {
        self.quantities
            .iter()
            .map(|(k, e)| (k.clone(), e.value))
            .collect()
    }

    /// The largest relative uncertainty over the quantities.
    pub fn worst_relative_uncertainty(&self) -> f64 {
        self.quantities
            .values()
            .map(|e| e.relative_uncertainty)
            .fold(0.0, f64::max)
    }
}

pub fn mesh_label(cells: u32, layers: u32) -> String {
    format!("{cells}x{cells}x{layers}")
}

impl StoredSequence {
    /// Representative cell size of a cells x cells x layers block [mm]: the volume's for
    /// hexahedra, the in-plane one for solid-shells (see the module doc).
    pub fn cell_size(&self, cells: u32, layers: u32) -> f64 {
        if self.element == SOLID_SHELL {
            return self.half_side_mm / f64::from(cells);
        }
        let volume = self.half_side_mm * self.half_side_mm * self.thickness_mm;
        (volume / f64::from(cells * cells * layers)).cbrt()
    }

    /// Whether refining `coarse` into `fine` keeps the cells similar: the same ratio
    /// in-plane and through the thickness for hexahedra; the same layers (and thickness
    /// rule) for solid-shells.
    fn similar_refinement(&self, fine: &StoredRun, coarse: &StoredRun) -> bool {
        let thick = f64::from(fine.layers) / f64::from(coarse.layers);
        if self.element == SOLID_SHELL {
            return thick == 1.0;
        }
        let plane = f64::from(fine.cells) / f64::from(coarse.cells);
        (plane - thick).abs() <= 1e-12 * plane
    }

    fn run(&self, cells: u32, layers: u32) -> Result<&StoredRun> {
        self.runs
            .iter()
            .find(|r| r.cells == cells && r.layers == layers)
            .ok_or_else(|| {
                Error::Input(format!(
                    "the square-cup reference sequence names {} but no stored run has that mesh",
                    mesh_label(cells, layers)
                ))
            })
    }

    /// Extrapolates every quantity over the sequence's three meshes.
    pub fn extrapolate(&self) -> Result<ExtrapolatedReference> {
        let runs = self
            .sequence
            .iter()
            .map(|[c, l]| self.run(*c, *l))
            .collect::<Result<Vec<_>>>()?;
        let h: Vec<f64> = runs
            .iter()
            .map(|r| self.cell_size(r.cells, r.layers))
            .collect();
        let similar = runs.windows(2).all(|w| self.similar_refinement(w[0], w[1]));
        let mut quantities = BTreeMap::new();
        for q in QUANTITIES {
            let value = |r: &StoredRun| {
                r.values.get(q).copied().ok_or_else(|| {
                    Error::Input(format!(
                        "stored square-cup run {} has no value '{q}'",
                        r.label()
                    ))
                })
            };
            let levels = [0, 1, 2].map(|i| (h[i], runs[i]));
            let mut l = [Level { h: 0.0, value: 0.0 }; 3];
            for (slot, (h, r)) in l.iter_mut().zip(levels) {
                *slot = Level {
                    h,
                    value: value(r)?,
                };
            }
            let e = extrapolate(l, self.rule)
                .map_err(|e| Error::Input(format!("square-cup reference, {q}: {e}")))?;
            quantities.insert(q.to_string(), e);
        }
        Ok(ExtrapolatedReference {
            element: self.element.clone(),
            sequence: runs.iter().map(|r| r.label()).collect(),
            ratios: [h[1] / h[0], h[2] / h[1]],
            similar,
            rule: self.rule,
            quantities,
            runs: self.runs.clone(),
            commit: self.commit.clone(),
            step_mm: self.step_mm,
        })
    }
}

/// Reads the stored sequence, naming the file on failure.
pub fn load(path: &Path) -> Result<StoredSequence> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text)
        .map_err(|e| Error::io(path, format!("not a stored square-cup mesh sequence: {e}")))
}

/// The stored file `file` (e.g. [`STORED_FILE`]) under the output folder, else the one in
/// the source tree this binary was built from.
pub fn locate(out: &Path, file: &str) -> Result<PathBuf> {
    let local = out.join(file);
    if local.is_file() {
        return Ok(local);
    }
    let built = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("docs/studies")
        .join(file);
    if built.is_file() {
        return Ok(built);
    }
    Err(Error::Input(format!(
        "the square-cup study needs its stored mesh sequence {file} (looked under {} and {})",
        out.display(),
        env!("CARGO_MANIFEST_DIR")
    )))
}

/// How two extrapolated references of one quantity compare.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Agreement {
    pub quantity: String,
    pub first: f64,
    pub second: f64,
    /// |first - second| / |first|.
    pub relative_difference: f64,
    /// The sum of both bands, relative to |first|: the difference two sound references may
    /// have.
    pub relative_band: f64,
    pub agrees: bool,
}

/// Compares two references quantity by quantity: they agree where their values differ by
/// no more than the sum of their uncertainty bands.
pub fn cross_check(
    first: &ExtrapolatedReference,
    second: &ExtrapolatedReference,
) -> Vec<Agreement> {
    first
        .quantities
        .iter()
        .filter_map(|(q, a)| {
            let b = second.quantities.get(q)?;
            let scale = a.value.abs();
            let difference = (a.value - b.value).abs();
            let band = a.uncertainty + b.uncertainty;
            Some(Agreement {
                quantity: q.clone(),
                first: a.value,
                second: b.value,
                relative_difference: difference / scale,
                relative_band: band / scale,
                agrees: difference <= band,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stored(sequence: [[u32; 2]; 3], value: impl Fn(f64) -> f64) -> StoredSequence {
        let mut s = StoredSequence {
            about: String::new(),
            commit: String::new(),
            element: HEXAHEDRON.into(),
            travel_mm: 15.0,
            step_mm: 0.5,
            half_side_mm: 75.0,
            thickness_mm: 0.81,
            sequence,
            rule: OrderRule {
                min: 0.5,
                max: 3.0,
                assumed: 1.0,
            },
            runs: Vec::new(),
        };
        for [c, l] in sequence {
            let h = s.cell_size(c, l);
            s.runs.push(StoredRun {
                cells: c,
                layers: l,
                command: String::new(),
                cpu_s: 0.0,
                wall_s: 0.0,
                iterations: 0,
                increments: 0,
                cutbacks: 0,
                values: QUANTITIES
                    .iter()
                    .map(|q| (q.to_string(), value(h)))
                    .collect(),
            });
        }
        s
    }

    #[test]
    fn similar_sequence_has_the_cells_ratio_and_recovers_a_manufactured_limit() {
        let s = stored([[48, 4], [24, 2], [12, 1]], |h| 5.0 + 0.2 * h * h);
        let r = s.extrapolate().unwrap();
        assert!(r.similar);
        assert!(
            r.ratios.iter().all(|q| (q - 2.0).abs() < 1e-12),
            "{:?}",
            r.ratios
        );
        for e in r.quantities.values() {
            assert!(e.asymptotic && (e.order - 2.0).abs() < 1e-9 && (e.value - 5.0).abs() < 1e-11);
        }
    }

    #[test]
    fn layers_fixed_sequence_is_not_similar_and_a_missing_run_is_named() {
        let s = stored([[48, 1], [24, 1], [12, 1]], |h| 5.0 + 0.2 * h);
        let r = s.extrapolate().unwrap();
        assert!(!r.similar);
        // In-plane only: h falls by 2^(2/3) per halving of the in-plane size.
        assert!((r.ratios[0] - 2f64.powf(2.0 / 3.0)).abs() < 1e-12);
        let mut broken = s.clone();
        broken.runs.pop();
        let err = broken.extrapolate().unwrap_err().to_string();
        assert!(err.contains("12x12x1"), "{err}");
    }

    #[test]
    fn solid_shell_sequence_refines_in_plane_and_stays_similar() {
        let mut s = stored([[48, 1], [24, 1], [12, 1]], |_| 1.0);
        s.element = SOLID_SHELL.into();
        for run in s.runs.iter_mut() {
            let h = 75.0 / f64::from(run.cells);
            for v in run.values.values_mut() {
                *v = 5.0 + 0.2 * h * h;
            }
        }
        let r = s.extrapolate().unwrap();
        assert!(r.similar && r.element == SOLID_SHELL);
        assert!(
            r.ratios.iter().all(|q| (q - 2.0).abs() < 1e-12),
            "{:?}",
            r.ratios
        );
        for e in r.quantities.values() {
            assert!((e.order - 2.0).abs() < 1e-9 && (e.value - 5.0).abs() < 1e-11);
        }
        // Two solid-shell layers against one: not the same element discretisation.
        s.runs[0].layers = 2;
        s.sequence[0] = [48, 2];
        assert!(!s.extrapolate().unwrap().similar);
    }

    #[test]
    fn cross_check_accepts_differences_within_both_bands_only() {
        let mut a = stored([[48, 4], [24, 2], [12, 1]], |h| 5.0 + 0.2 * h * h)
            .extrapolate()
            .unwrap();
        let mut b = a.clone();
        for e in a.quantities.values_mut() {
            e.uncertainty = 0.004;
        }
        for e in b.quantities.values_mut() {
            e.uncertainty = 0.006;
            e.value += 0.009;
        }
        // 0.009 <= 0.004 + 0.006: agrees.
        assert!(cross_check(&a, &b).iter().all(|g| g.agrees));
        for e in b.quantities.values_mut() {
            e.value += 0.002;
        }
        let checks = cross_check(&a, &b);
        assert_eq!(checks.len(), QUANTITIES.len());
        assert!(checks
            .iter()
            .all(|g| !g.agrees && g.relative_difference > g.relative_band));
    }

    fn committed(file: &str) -> StoredSequence {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("docs/studies")
            .join(file);
        load(&path).unwrap()
    }

    #[test]
    fn committed_sequences_are_consistent_and_extrapolate_every_quantity() {
        for (file, element) in [(STORED_FILE, HEXAHEDRON), (SOLID_SHELL_FILE, SOLID_SHELL)] {
            let stored = committed(file);
            assert_eq!(stored.element, element, "{file}");
            // Every stored run's command made the mesh it is filed under, with the file's
            // element, to the study's travel and step.
            for run in &stored.runs {
                let mut parts = vec![
                    format!("--set cells={} ", run.cells),
                    format!("--set layers={} ", run.layers),
                    format!("--set travel={:.1} ", stored.travel_mm),
                    format!("--set step={} ", stored.step_mm),
                ];
                if element == SOLID_SHELL {
                    parts.push(format!("--set 'element=\"{SOLID_SHELL}\"' "));
                }
                for part in parts {
                    assert!(
                        run.command.contains(&part),
                        "{file}, {}: {} lacks {part}",
                        run.label(),
                        run.command
                    );
                }
            }
            let r = stored.extrapolate().unwrap();
            assert_eq!(r.quantities.len(), QUANTITIES.len());
            // The quarter model is symmetric about the diagonal: DX and DY agree to
            // round-off.
            let (dx, dy) = (
                &r.quantities["draw_in_dx_mm"],
                &r.quantities["draw_in_dy_mm"],
            );
            assert!((dx.value - dy.value).abs() < 1e-9 * dx.value, "{file}");
        }
    }

    /// The two element families' references agree within their bands: the F-bar one,
    /// approached from the stiff side, is not an artefact of its element's locking.
    #[test]
    fn hexahedron_and_solid_shell_references_agree() {
        let hex = committed(STORED_FILE).extrapolate().unwrap();
        let shell = committed(SOLID_SHELL_FILE).extrapolate().unwrap();
        let checks = cross_check(&hex, &shell);
        assert_eq!(checks.len(), QUANTITIES.len());
        for c in &checks {
            assert!(c.agrees, "{c:?}");
        }
    }
}
