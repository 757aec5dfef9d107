//! Springback measures of release steps (issue 47): the shape change of the sheet from the
//! end of loading to the released state, with its rigid-body part removed.
//!
//! Loading ends at the start of the first step that ramps a tool off or releases the sheet
//! (`Step::ramp_off`, `Step::release`): the node positions `a_i` there are kept. At the end
//! of each release step the positions are `b_i`. The rigid motion that best maps the loaded
//! shape onto the released one in least squares, `min_{R, t} sum_i |R a_i + t - b_i|^2`
//! over rotations `R`, is Kabsch's: with the centroids `a_c`, `b_c` and the covariance
//! `H = sum_i (a_i - a_c)(b_i - b_c)^T = U S V^T` (nalgebra's SVD),
//!
//! ```text
//! R = V diag(1, 1, d) U^T,   d = sign det(V U^T),   t = b_c - R a_c
//! ```
//!
//! (`d` keeps `R` a rotation, not a reflection). The springback displacement of node `i` is
//! `e_i = b_i - (R a_i + t)`; the measures are `max_i |e_i|` and `sqrt(mean_i |e_i|^2)`,
//! lengths in the mesh's units. The loaded shape and the measures so far are part of the
//! committed state (checkpoints and rollback), so a run restarted after loading ended
//! reports the measures of the uninterrupted run; one restarted from an older checkpoint
//! without them reports none.

use crate::geometry::{Mat3, Vec3};
use crate::solver::model::steps;
use crate::solver::simulation::Simulation;

/// The springback of one release step.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Springback {
    /// The release step (index into `Model::steps`).
    pub step: usize,
    /// Largest nodal springback displacement, rigid part removed.
    pub max: f64,
    /// Root mean square of the nodal springback displacements, rigid part removed.
    pub rms: f64,
}

/// The rotation and translation that best map `a` onto `b` (Kabsch; module doc).
pub fn best_rigid_fit(a: &[Vec3], b: &[Vec3]) -> (Mat3, Vec3) {
    let n = a.len().max(1) as f64;
    let ca = a.iter().fold(Vec3::zeros(), |s, p| s + p) / n;
    let cb = b.iter().fold(Vec3::zeros(), |s, p| s + p) / n;
    let h = a.iter().zip(b).fold(Mat3::zeros(), |h, (p, q)| {
        h + (p - ca) * (q - cb).transpose()
    });
    let svd = h.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return (Mat3::identity(), cb - ca);
    };
    let v = v_t.transpose();
    let d = (v * u.transpose()).determinant().signum();
    let r = v * Mat3::from_diagonal(&Vec3::new(1.0, 1.0, d)) * u.transpose();
    (r, cb - r * ca)
}

/// Max and RMS of the springback displacements from `a` to `b`, rigid part removed.
pub fn measures(a: &[Vec3], b: &[Vec3]) -> (f64, f64) {
    let (r, t) = best_rigid_fit(a, b);
    let e: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(p, q)| (q - (r * p + t)).norm())
        .collect();
    let max = e.iter().copied().fold(0.0, f64::max);
    let rms = (e.iter().map(|x| x * x).sum::<f64>() / e.len().max(1) as f64).sqrt();
    (max, rms)
}

impl Simulation {
    /// The committed node positions.
    pub(super) fn node_positions(&self) -> Vec<Vec3> {
        let nodes = &self.model.mesh.nodes;
        (0..nodes.len())
            .map(|n| nodes[n] + Vec3::new(self.x[3 * n], self.x[3 * n + 1], self.x[3 * n + 2]))
            .collect()
    }

    /// Keeps the loaded shape before the first attempt at the first unloading step (called
    /// with the step the next increment falls in).
    pub(super) fn keep_loaded_shape(&mut self, step: Option<usize>) {
        let list = &self.model.steps;
        let Some(k) = step else { return };
        let first = list
            .iter()
            .position(|s| s.release || !s.ramp_off.is_empty());
        if first == Some(k) && self.loaded_shape.is_none() && self.time <= steps::start(list, k) {
            self.loaded_shape = Some(self.node_positions());
        }
    }

    /// After an increment committed at the end of a release step, its springback.
    pub(super) fn measure_springback(&mut self, step: Option<usize>) {
        let Some(k) = step else { return };
        let s = &self.model.steps[k];
        if !s.release || self.time < s.end * (1.0 - 1e-12) {
            return;
        }
        let Some(loaded) = &self.loaded_shape else {
            return;
        };
        let (max, rms) = measures(loaded, &self.node_positions());
        self.springback.retain(|m| m.step != k);
        self.springback.push(Springback { step: k, max, rms });
    }

    /// The springback of each release step completed since loading ended (module doc).
    pub fn springback(&self) -> &[Springback] {
        &self.springback
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rigid_motion_has_no_springback_and_a_bend_has_its_own() {
        let a: Vec<Vec3> = (0..12)
            .map(|i| Vec3::new(i as f64, (i % 3) as f64, (i % 2) as f64 * 0.5))
            .collect();
        // A rotation of 0.3 rad about an oblique axis and a translation: nothing is left
        // but round-off (1e-12 against coordinates of order 10).
        let r = nalgebra::Rotation3::from_axis_angle(
            &nalgebra::Unit::new_normalize(Vec3::new(1.0, 2.0, 0.5)),
            0.3,
        );
        let t = Vec3::new(3.0, -1.0, 2.0);
        let b: Vec<Vec3> = a.iter().map(|p| r * p + t).collect();
        let (max, rms) = measures(&a, &b);
        assert!(max < 1e-12 && rms < 1e-12, "{max} {rms}");
        // One node moved by 0.1 after the same motion: the fit spreads part of it, so the
        // largest displacement is below 0.1 and above a half of it, and the RMS below.
        let mut c = b.clone();
        c[11].z += 0.1;
        let (max, rms) = measures(&a, &c);
        assert!(max < 0.1 && max > 0.05, "{max}");
        assert!(rms < max && rms > 0.0, "{rms}");
    }
}
