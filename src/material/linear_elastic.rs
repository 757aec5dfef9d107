//! Isotropic linear elasticity, small strain.

use super::{Kinematics, Material, PointState, Tangent, Voigt};
use crate::{Error, Result};

/// Isotropic linear elastic material (Hooke's law), small strain:
/// `σ = λ tr(ε) I + 2 μ ε`, in Voigt form `σ = D ε` with
///
/// ```text
///     | λ+2μ  λ     λ     0  0  0 |
///     | λ     λ+2μ  λ     0  0  0 |
/// D = | λ     λ     λ+2μ  0  0  0 |      (engineering shear strains, so the shear
///     | 0     0     0     μ  0  0 |       entries are μ, not 2μ)
///     | 0     0     0     0  μ  0 |
///     | 0     0     0     0  0  μ |
/// ```
///
/// with `λ = E ν / ((1 + ν)(1 - 2ν))` and `μ = E / (2(1 + ν))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearElastic {
    young: f64,
    poisson: f64,
}

impl LinearElastic {
    /// Young's modulus `young` (finite, > 0) and Poisson's ratio `poisson` (finite,
    /// -1 < ν < 0.5: the bounds at which the bulk or the shear modulus would vanish).
    pub fn new(young: f64, poisson: f64) -> Result<Self> {
        if !young.is_finite() {
            return Err(Error::input("Young's modulus", young, "must be finite"));
        }
        if young <= 0.0 {
            return Err(Error::input("Young's modulus", young, "must be > 0"));
        }
        if !poisson.is_finite() {
            return Err(Error::input("Poisson's ratio", poisson, "must be finite"));
        }
        if !(poisson > -1.0 && poisson < 0.5) {
            return Err(Error::input(
                "Poisson's ratio",
                poisson,
                "must be > -1 and < 0.5",
            ));
        }
        Ok(LinearElastic { young, poisson })
    }

    /// Young's modulus E.
    pub fn young(&self) -> f64 {
        self.young
    }

    /// Poisson's ratio ν.
    pub fn poisson(&self) -> f64 {
        self.poisson
    }

    /// Lamé parameters `(λ, μ)`.
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.young, self.poisson);
        (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            self.shear_modulus(),
        )
    }

    /// Shear modulus `μ = G = E / (2(1 + ν))`.
    pub fn shear_modulus(&self) -> f64 {
        self.young / (2.0 * (1.0 + self.poisson))
    }

    /// Bulk modulus `K = E / (3(1 - 2ν)) = λ + 2μ/3`.
    pub fn bulk_modulus(&self) -> f64 {
        self.young / (3.0 * (1.0 - 2.0 * self.poisson))
    }

    /// The elasticity matrix `D` (see the type documentation).
    pub fn tangent(&self) -> Tangent {
        let (lambda, mu) = self.lame();
        let mut d = Tangent::zeros();
        for i in 0..3 {
            for j in 0..3 {
                d[(i, j)] = lambda;
            }
            d[(i, i)] = lambda + 2.0 * mu;
            d[(i + 3, i + 3)] = mu;
        }
        d
    }

    /// The compliance matrix `S = D⁻¹`: `1/E` and `-ν/E` on the normal block, `1/μ` on
    /// the shears. Written out rather than inverted, exact for all admissible ν.
    pub fn compliance(&self) -> Tangent {
        let (e, nu) = (self.young, self.poisson);
        let mut s = Tangent::zeros();
        for i in 0..3 {
            for j in 0..3 {
                s[(i, j)] = -nu / e;
            }
            s[(i, i)] = 1.0 / e;
            s[(i + 3, i + 3)] = 1.0 / self.shear_modulus();
        }
        s
    }

    /// Stress `σ = D ε` for the strain `ε` (Voigt, engineering shear).
    pub fn stress(&self, strain: &Voigt) -> Voigt {
        let (lambda, mu) = self.lame();
        let tr = strain[0] + strain[1] + strain[2];
        Voigt::new(
            lambda * tr + 2.0 * mu * strain[0],
            lambda * tr + 2.0 * mu * strain[1],
            lambda * tr + 2.0 * mu * strain[2],
            mu * strain[3],
            mu * strain[4],
            mu * strain[5],
        )
    }

    /// Strain energy density `W = ½ ε·Dε = ½ λ tr(ε)² + μ ε:ε` of the strain `ε`.
    pub fn energy_density(&self, strain: &Voigt) -> f64 {
        0.5 * strain.dot(&self.stress(strain))
    }

    /// Elastic energy density `½ σ·Sσ` of the stress `σ`. Equal to
    /// [`energy_density`](Self::energy_density) of the elastic strain; written in terms of
    /// the stress so that it stays right when part of the strain is plastic.
    pub fn energy_density_of_stress(&self, stress: &Voigt) -> f64 {
        0.5 * stress.dot(&(self.compliance() * stress))
    }
}

impl Material for LinearElastic {
    fn update(
        &self,
        kin: &Kinematics,
        committed: &PointState,
        trial: &mut PointState,
    ) -> Result<Tangent> {
        if !kin.strain.iter().all(|v| v.is_finite()) {
            // A diverging Newton iterate, not bad user input: the solver cuts back.
            return Err(Error::no_convergence(
                crate::error::Failure::Local,
                format!(
                    "non-finite strain {:?} at an integration point",
                    kin.strain.as_slice()
                ),
            ));
        }
        // Elastic: no history, the stress depends on the current strain only.
        *trial = PointState {
            stress: self.stress(&kin.strain),
            strain: kin.strain,
            deformation_gradient: kin.deformation_gradient,
            ..*committed
        };
        Ok(self.tangent())
    }

    fn elastic_tangent(&self) -> Tangent {
        self.tangent()
    }

    fn elastic_energy_density(&self, state: &PointState) -> f64 {
        self.energy_density_of_stress(&state.stress)
    }

    fn describe(&self) -> String {
        format!("linear elastic E={} nu={}", self.young, self.poisson)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs().max(1e-300)
    }

    #[test]
    fn moduli_of_steel() {
        let m = LinearElastic::new(210e3, 0.3).unwrap();
        let (lambda, mu) = m.lame();
        assert!(rel(mu, 80769.23076923077) < 1e-14);
        assert!(rel(lambda, 121153.84615384616) < 1e-14);
        assert!(rel(m.bulk_modulus(), 175e3) < 1e-14);
        assert!(rel(m.bulk_modulus(), lambda + 2.0 * mu / 3.0) < 1e-14);
        assert_eq!((m.young(), m.poisson()), (210e3, 0.3));
    }

    #[test]
    fn uniaxial_stress_gives_young_and_poisson() {
        let m = LinearElastic::new(70e3, 0.33).unwrap();
        // Strain of a uniaxial stress σxx = 70: εxx = 1e-3, εyy = εzz = -ν 1e-3.
        let e = Voigt::new(1e-3, -0.33e-3, -0.33e-3, 0.0, 0.0, 0.0);
        let s = m.stress(&e);
        assert!(rel(s[0], 70.0) < 1e-12);
        assert!(s[1].abs() < 1e-12 && s[2].abs() < 1e-12);
        // Pure shear: τ = μ γ.
        let g = Voigt::new(0.0, 0.0, 0.0, 2e-3, 0.0, 0.0);
        assert!(rel(m.stress(&g)[3], m.shear_modulus() * 2e-3) < 1e-14);
        assert!((m.tangent() * e - s).abs().max() < 1e-12);
    }

    #[test]
    fn tangent_is_symmetric_positive_definite_and_compliance_is_its_inverse() {
        for nu in [-0.9, 0.0, 0.3, 0.49] {
            let m = LinearElastic::new(1.0, nu).unwrap();
            let d = m.tangent();
            assert_eq!(d, d.transpose());
            assert!(d.symmetric_eigenvalues().min() > 0.0);
            let err = (d * m.compliance() - Tangent::identity()).abs().max();
            assert!(err < 1e-12, "nu = {nu}: {err}");
        }
    }

    #[test]
    fn energy_density_forms_agree() {
        let m = LinearElastic::new(210e3, 0.3).unwrap();
        let e = Voigt::new(1e-3, -2e-4, 5e-4, 3e-4, -1e-4, 2e-4);
        let s = m.stress(&e);
        let w = m.energy_density(&e);
        assert!(rel(w, 0.5 * s.dot(&e)) < 1e-14);
        assert!(rel(m.energy_density_of_stress(&s), w) < 1e-12);
        let (lambda, mu) = m.lame();
        let tr = e[0] + e[1] + e[2];
        let eps_eps = e[0] * e[0]
            + e[1] * e[1]
            + e[2] * e[2]
            + 0.5 * (e[3] * e[3] + e[4] * e[4] + e[5] * e[5]);
        assert!(rel(w, 0.5 * lambda * tr * tr + mu * eps_eps) < 1e-12);
    }

    #[test]
    fn update_writes_trial_and_keeps_history() {
        let m = LinearElastic::new(100.0, 0.25).unwrap();
        let committed = PointState {
            eq_plastic_strain: 0.125,
            ..PointState::default()
        };
        let mut trial = PointState::default();
        let kin = Kinematics::from_strain(Voigt::new(0.01, 0.0, 0.0, 0.02, 0.0, 0.0));
        let d = m.update(&kin, &committed, &mut trial).unwrap();
        assert_eq!(d, m.tangent());
        assert_eq!(trial.stress, m.stress(&kin.strain));
        assert_eq!(trial.strain, kin.strain);
        assert_eq!(trial.deformation_gradient, kin.deformation_gradient);
        assert_eq!(trial.eq_plastic_strain, 0.125);
        assert!((m.elastic_energy_density(&trial) - m.energy_density(&kin.strain)).abs() < 1e-15);

        let bad = Kinematics::from_strain(Voigt::new(f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0));
        assert!(m.update(&bad, &committed, &mut trial).is_err());
    }

    #[test]
    fn invalid_constants_are_errors_naming_the_value() {
        let msg = |e: f64, nu: f64| LinearElastic::new(e, nu).unwrap_err().to_string();
        assert!(msg(-5.0, 0.3).contains("Young's modulus = -5 must be > 0"));
        assert!(msg(0.0, 0.3).contains("Young's modulus = 0 must be > 0"));
        assert!(msg(f64::NAN, 0.3).contains("Young's modulus = NaN must be finite"));
        assert!(msg(f64::INFINITY, 0.3).contains("Young's modulus = inf must be finite"));
        assert!(msg(1.0, 0.5).contains("Poisson's ratio = 0.5 must be > -1 and < 0.5"));
        assert!(msg(1.0, 0.7).contains("Poisson's ratio = 0.7 must be > -1 and < 0.5"));
        assert!(msg(1.0, -1.0).contains("Poisson's ratio = -1 must be > -1 and < 0.5"));
        assert!(msg(1.0, f64::NAN).contains("Poisson's ratio = NaN must be finite"));
        assert!(LinearElastic::new(1.0, 0.4999).is_ok());
        assert_eq!(
            LinearElastic::new(2.0, 0.3).unwrap().describe(),
            "linear elastic E=2 nu=0.3"
        );
    }
}
