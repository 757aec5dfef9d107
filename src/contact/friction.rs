//! Friction laws: how a contact node's friction coefficient follows from its history.
//!
//! The generalised Coulomb law of the paper (eqs. 12-16): each node carries its frictional
//! work Psi, theta = min(Psi / Psi_cut, 1) and
//!
//! ```text
//! mu(theta) = sum_{i=0..m} B_{i,m}(theta) P_i,   B_{i,m}(theta) = C(m,i) theta^i (1 - theta)^(m-i)
//! ```
//!
//! so that mu(0) = P_0 (the virgin coefficient) and mu(1) = P_m (the cut-off value).
//! Evaluated by de Casteljau's algorithm, O(m^2), stable for any degree.
//!
//! By default the coefficient is updated explicitly after each converged increment (as in
//! the paper) and held fixed during the next increment's Newton iterations; see
//! [`FrictionUpdate`] for the implicit (trapezoidal) alternative.

use crate::{Error, Result};
use std::sync::Arc;

/// What the work in theta is measured in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WorkMeasure {
    /// The paper's: the node's frictional work (force x length). Depends on the mesh,
    /// because nodal forces scale with the tributary area.
    #[default]
    PerNode,
    /// Frictional work per unit area (Psi / A_node): mesh-objective.
    PerArea,
}

impl WorkMeasure {
    pub fn name(self) -> &'static str {
        match self {
            WorkMeasure::PerNode => "per_node",
            WorkMeasure::PerArea => "per_area",
        }
    }
}

/// When the friction coefficient follows the frictional work.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FrictionUpdate {
    /// After each converged increment, from the committed work (the paper): forward
    /// Euler in the slide distance, first-order accurate.
    #[default]
    Explicit,
    /// Inside the Newton loop: the increment's coefficient is the mean of mu at the start
    /// and at the end-of-increment work Psi_n + lambda_t . delta_t, with its derivative in
    /// the Jacobian. The trapezoidal rule in the slide distance: second-order accurate, so
    /// large increments stay accurate.
    Implicit,
}

/// The state a friction law may depend on, at one node after a converged increment.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrictionInput {
    /// Accumulated frictional work Psi (force x length).
    pub work: f64,
    /// Accumulated slip length.
    pub slip: f64,
    /// Contact pressure -lambda_n / A.
    pub pressure: f64,
    /// The node's tributary area A.
    pub area: f64,
}

/// mu as a Bernstein polynomial of theta = min(work / work_cut, 1).
#[derive(Clone, Debug, PartialEq)]
pub struct BernsteinLaw {
    control_points: Vec<f64>,
    work_cut: f64,
    measure: WorkMeasure,
}

impl BernsteinLaw {
    /// `control_points` P_0..P_m (m >= 1, every P_i >= 0), `work_cut` > 0 (force x length
    /// per node, or force/length per unit area with [`WorkMeasure::PerArea`]).
    pub fn new(control_points: Vec<f64>, work_cut: f64, measure: WorkMeasure) -> Result<Self> {
        if control_points.len() < 2 {
            return Err(Error::input(
                "Bernstein friction law degree",
                control_points.len() as i64 - 1,
                "must be >= 1 (give at least 2 control points)",
            ));
        }
        for (i, p) in control_points.iter().enumerate() {
            if !(p.is_finite() && *p >= 0.0) {
                return Err(Error::input(
                    &format!("Bernstein control point P_{i}"),
                    p,
                    "must be >= 0 and finite",
                ));
            }
        }
        if !(work_cut.is_finite() && work_cut > 0.0) {
            return Err(Error::input(
                "Bernstein friction law work_cut",
                work_cut,
                "must be > 0 and finite",
            ));
        }
        Ok(BernsteinLaw {
            control_points,
            work_cut,
            measure,
        })
    }

    pub fn degree(&self) -> usize {
        self.control_points.len() - 1
    }

    pub fn control_points(&self) -> &[f64] {
        &self.control_points
    }

    pub fn work_cut(&self) -> f64 {
        self.work_cut
    }

    pub fn measure(&self) -> WorkMeasure {
        self.measure
    }

    /// d theta / d work at this work (0 past the cut-off), for a node of area `area`.
    pub fn dtheta_dwork(&self, work: f64, area: f64) -> f64 {
        let scale = self.work_scale(area);
        if work / scale >= 1.0 || work < 0.0 {
            0.0
        } else {
            1.0 / scale
        }
    }

    fn work_scale(&self, area: f64) -> f64 {
        match self.measure {
            WorkMeasure::PerNode => self.work_cut,
            WorkMeasure::PerArea => self.work_cut * area.max(f64::MIN_POSITIVE),
        }
    }

    /// theta = min(work / work_cut, 1) (work per unit area with [`WorkMeasure::PerArea`]).
    pub fn theta(&self, work: f64, area: f64) -> f64 {
        (work / self.work_scale(area)).clamp(0.0, 1.0)
    }

    /// mu(theta) by de Casteljau's algorithm.
    pub fn mu_of_theta(&self, theta: f64) -> f64 {
        de_casteljau(&self.control_points, theta)
    }

    /// d mu / d theta = m sum_i (P_{i+1} - P_i) B_{i,m-1}(theta).
    pub fn dmu_dtheta(&self, theta: f64) -> f64 {
        let m = self.degree() as f64;
        let diffs: Vec<f64> = self
            .control_points
            .windows(2)
            .map(|w| m * (w[1] - w[0]))
            .collect();
        de_casteljau(&diffs, theta)
    }

    pub fn mu(&self, work: f64, area: f64) -> f64 {
        self.mu_of_theta(self.theta(work, area))
    }
}

fn de_casteljau(points: &[f64], t: f64) -> f64 {
    let mut b = points.to_vec();
    for level in 1..b.len() {
        for i in 0..b.len() - level {
            b[i] = (1.0 - t) * b[i] + t * b[i + 1];
        }
    }
    b[0]
}

/// The i-th Bernstein basis polynomial of degree m at t.
pub fn bernstein_basis(i: usize, m: usize, t: f64) -> f64 {
    let mut binom = 1.0;
    for k in 0..i {
        binom *= (m - k) as f64 / (k + 1) as f64;
    }
    binom * t.powi(i as i32) * (1.0 - t).powi((m - i) as i32)
}

/// A friction law; each tool carries its own.
#[derive(Clone)]
pub enum FrictionLaw {
    /// Classical Coulomb friction with a constant coefficient.
    Coulomb { mu: f64 },
    /// The paper's work-dependent law.
    Bernstein(BernsteinLaw),
    /// A Rust function of the node's state, called once per node per converged increment.
    Function(Arc<dyn Fn(&FrictionInput) -> f64 + Send + Sync>),
    /// Set from outside after each converged increment (a script function: the script layer
    /// calls it, so that nothing below it knows Rhai). `initial` is mu of a virgin node;
    /// `source` says what the function is (the script layer's description of its source
    /// text), so that the checkpoint's fingerprint of the law changes with its body.
    External { initial: f64, source: String },
    /// mu as a Bernstein polynomial of the TOOL's accumulated frictional work per area at
    /// the node's foot: theta = min(w_tool / work_cut, 1) (issue 53: a coating wearing over
    /// the strokes raises mu). The law's work is the tool's work per area (force/length),
    /// whatever its `measure`. The tool's state is held by the simulation, not by a node,
    /// so the simulation sets mu (`mu` returns `None`), from the tool state frozen at the
    /// start of the stroke; mu is therefore constant within an increment and has no
    /// derivative in the Jacobian (module `solver::simulation::strokes`).
    ToolWork(BernsteinLaw),
}

impl std::fmt::Debug for FrictionLaw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.describe())
    }
}

impl FrictionLaw {
    /// Constant Coulomb friction, `mu >= 0` and finite.
    pub fn coulomb(mu: f64) -> Result<Self> {
        check_mu("friction coefficient mu", mu)?;
        Ok(FrictionLaw::Coulomb { mu })
    }

    /// Frictionless contact.
    pub fn frictionless() -> Self {
        FrictionLaw::Coulomb { mu: 0.0 }
    }

    /// Friction coefficient of a node with the given history. `None` for an external law
    /// (its owner sets mu).
    pub fn mu(&self, input: &FrictionInput) -> Option<f64> {
        match self {
            FrictionLaw::Coulomb { mu } => Some(*mu),
            FrictionLaw::Bernstein(law) => Some(law.mu(input.work, input.area)),
            FrictionLaw::Function(f) => Some(f(input)),
            FrictionLaw::External { .. } | FrictionLaw::ToolWork(_) => None,
        }
    }

    /// mu of a node that has done no frictional work.
    pub fn initial_mu(&self, area: f64) -> f64 {
        match self {
            FrictionLaw::External { initial, .. } => *initial,
            FrictionLaw::ToolWork(law) => law.mu_of_theta(0.0),
            other => other
                .mu(&FrictionInput {
                    area,
                    ..Default::default()
                })
                .unwrap_or(0.0),
        }
    }

    /// The work-dependent law, if the coefficient depends on the frictional work in a way
    /// the implicit update can differentiate.
    pub fn bernstein(&self) -> Option<&BernsteinLaw> {
        match self {
            FrictionLaw::Bernstein(law) => Some(law),
            _ => None,
        }
    }

    pub fn describe(&self) -> String {
        match self {
            FrictionLaw::Coulomb { mu } => format!("Coulomb mu = {mu}"),
            FrictionLaw::Bernstein(l) => format!(
                "Bernstein degree {} control points {:?}, work_cut = {} ({})",
                l.degree(),
                l.control_points,
                l.work_cut,
                l.measure.name()
            ),
            FrictionLaw::Function(_) => "function of the node's state".into(),
            FrictionLaw::External { initial, source } => {
                format!("{source} (mu at zero work = {initial})")
            }
            FrictionLaw::ToolWork(l) => format!(
                "Bernstein of the tool's work per area, degree {} control points {:?}, work_cut = {}",
                l.degree(),
                l.control_points,
                l.work_cut
            ),
        }
    }
}

/// Checks a friction coefficient computed by a user function.
pub fn check_mu(what: &str, mu: f64) -> Result<()> {
    if mu.is_finite() && mu >= 0.0 {
        Ok(())
    } else {
        Err(Error::input(what, mu, "must be >= 0 and finite"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bernstein_basis_is_a_partition_of_unity() {
        for m in 1..=8 {
            for k in 0..=20 {
                let t = k as f64 / 20.0;
                let s: f64 = (0..=m).map(|i| bernstein_basis(i, m, t)).sum();
                assert!((s - 1.0).abs() < 1e-14, "degree {m}, t {t}: sum {s}");
            }
        }
    }

    #[test]
    fn end_values_are_the_first_and_last_control_points() {
        let law =
            BernsteinLaw::new(vec![0.3, 0.7, 0.1, 0.25, 0.05], 2.0, WorkMeasure::PerNode).unwrap();
        assert_eq!(law.mu(0.0, 1.0), 0.3);
        assert_eq!(law.mu(2.0, 1.0), 0.05);
        assert_eq!(law.mu(50.0, 1.0), 0.05, "cut off beyond work_cut");
        // de Casteljau agrees with the explicit basis sum.
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            let direct: f64 = (0..=4)
                .map(|i| bernstein_basis(i, 4, t) * law.control_points()[i])
                .sum();
            assert!((law.mu_of_theta(t) - direct).abs() < 1e-15);
        }
    }

    #[test]
    fn papers_curve_is_antisymmetric_about_its_midpoint() {
        let (init, cut) = (0.16, 0.01);
        let law =
            BernsteinLaw::new(vec![init, init, cut, cut], 2000.0, WorkMeasure::PerNode).unwrap();
        let mid = 0.5 * (init + cut);
        assert!((law.mu_of_theta(0.5) - mid).abs() < 1e-15);
        for k in 0..=50 {
            let d = k as f64 / 100.0;
            let up = law.mu_of_theta(0.5 - d) - mid;
            let down = law.mu_of_theta(0.5 + d) - mid;
            assert!((up + down).abs() < 1e-15, "antisymmetry at offset {d}");
        }
        // Flat at both ends (P_0 = P_1, P_2 = P_3).
        assert!(law.dmu_dtheta(0.0).abs() < 1e-15 && law.dmu_dtheta(1.0).abs() < 1e-15);
    }

    #[test]
    fn derivative_matches_finite_differences() {
        let law = BernsteinLaw::new(
            vec![0.2, 0.5, 0.05, 0.3, 0.1, 0.12],
            1.0,
            WorkMeasure::PerNode,
        )
        .unwrap();
        for k in 1..20 {
            let t = k as f64 / 20.0;
            let h = 1e-6;
            let fd = (law.mu_of_theta(t + h) - law.mu_of_theta(t - h)) / (2.0 * h);
            assert!((fd - law.dmu_dtheta(t)).abs() < 1e-8);
        }
    }

    #[test]
    fn per_area_measure_scales_the_cut_off_by_the_area() {
        let law = BernsteinLaw::new(vec![0.2, 0.1], 4.0, WorkMeasure::PerArea).unwrap();
        assert_eq!(law.theta(2.0, 0.25), 1.0);
        assert_eq!(law.theta(0.5, 0.25), 0.5);
        assert_eq!(law.dtheta_dwork(0.5, 0.25), 1.0);
    }

    #[test]
    fn invalid_parameters_name_the_value() {
        let e = BernsteinLaw::new(vec![0.2], 1.0, WorkMeasure::PerNode)
            .unwrap_err()
            .to_string();
        assert!(e.contains("degree") && e.contains("0"), "{e}");
        let e = BernsteinLaw::new(vec![0.2, -0.1], 1.0, WorkMeasure::PerNode)
            .unwrap_err()
            .to_string();
        assert!(e.contains("P_1") && e.contains("-0.1"), "{e}");
        let e = BernsteinLaw::new(vec![0.2, 0.1], 0.0, WorkMeasure::PerNode)
            .unwrap_err()
            .to_string();
        assert!(e.contains("work_cut = 0"), "{e}");
        assert!(FrictionLaw::coulomb(-0.1)
            .unwrap_err()
            .to_string()
            .contains("-0.1"));
    }
}
