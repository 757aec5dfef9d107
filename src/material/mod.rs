//! Constitutive models: the [`Material`] trait, the per-integration-point state
//! [`PointState`], the kinematic input [`Kinematics`] and Voigt-notation helpers.
//!
//! # Voigt convention
//!
//! Symmetric second-order tensors are stored as 6-vectors in the order
//! `[xx, yy, zz, xy, yz, zx]`:
//!
//! * stress-like tensors with their tensor components,
//!   `σ = [σxx, σyy, σzz, σxy, σyz, σzx]`;
//! * strain-like tensors with *engineering* shear components,
//!   `ε = [εxx, εyy, εzz, γxy, γyz, γzx]` with `γxy = 2 εxy`.
//!
//! Why: with this pairing the plain dot product of the two vectors is the double
//! contraction, `σ·ε = σ : ε` (the work density), so `f_int = ∫ Bᵀσ dV` and the energy
//! `½ σ·ε` need no factors of 2, and a tangent `D = ∂σ/∂ε` is a symmetric 6x6 matrix
//! whenever the 4th-order tangent has major symmetry.
//!
//! # How a material is called
//!
//! Each integration point carries a *committed* state (converged at the end of the last
//! load step) and a *trial* state (the current Newton iterate). For each iterate the
//! element computes the [`Kinematics`] at the point and calls
//! [`Material::update`]`(kin, committed, trial)`, which computes the full trial state from
//! the committed one (never from the previous iterate, so Newton iterations do not
//! accumulate path dependence) and returns the algorithmic tangent. The solver copies
//! trial into committed when a step converges and discards trial when it is cut back.

use nalgebra::{Matrix6, Vector6};

use crate::geometry::Mat3;
use crate::Result;

mod elastoplastic;
mod hardening;
mod hill48;
mod kinematic;
mod linear_elastic;
pub mod log_strain;
mod spectral_return;
mod sym_eigen3;
mod uniaxial;

pub use elastoplastic::ElastoPlastic;
pub use hardening::Hardening;
pub use hill48::Hill48;
pub use kinematic::Chaboche;
pub use linear_elastic::LinearElastic;
pub use uniaxial::{uniaxial_direction, uniaxial_stress_path};

/// A symmetric tensor in Voigt notation `[xx, yy, zz, xy, yz, zx]`; see the module
/// documentation for the stress / strain (engineering shear) convention.
pub type Voigt = Vector6<f64>;

/// A 6x6 material tangent in Voigt notation, mapping engineering strain to stress.
pub type Tangent = Matrix6<f64>;

/// The state of a material at one integration point.
///
/// All fields are fixed-size so the state is `Copy` and arrays of states need no heap
/// allocation per point. A material keeps in it whatever history it needs; fields it does
/// not use are carried over unchanged. Construct with [`PointState::default`] (or
/// [`Material::initial_state`]) and struct-update syntax, so that fields added for later
/// materials do not break existing code.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PointState {
    /// Cauchy stress (Voigt, tensor components). Equal to the small-strain stress for
    /// small-strain materials.
    pub stress: Voigt,
    /// Total strain (Voigt, engineering shear): the small strain `sym ∇u` for small-strain
    /// materials, a logarithmic (Hencky) strain for finite-strain ones.
    pub strain: Voigt,
    /// Plastic strain (Voigt, engineering shear); zero for elastic materials.
    pub plastic_strain: Voigt,
    /// Equivalent (accumulated) plastic strain, the hardening variable; zero for elastic
    /// materials.
    pub eq_plastic_strain: f64,
    /// Deformation gradient `F = I + ∂u/∂X` at which this state was computed. Stored so
    /// that a finite-strain material can form the incremental gradient
    /// `f = F_{n+1} F_n⁻¹` between the committed and the trial state (objective
    /// stress updates, rotation of anisotropy axes).
    pub deformation_gradient: Mat3,
    /// Under finite kinematics ([`Material::update_finite`]): the stress `T` work-conjugate
    /// to the logarithmic strain `strain`, the material's own stress measure (the elastic
    /// energy and the return mapping live in it); `stress` then holds the Cauchy stress.
    /// Zero under small strain.
    pub log_stress: Voigt,
    /// Plastic work dissipated so far per unit reference volume, `∫ σ·dεp` (small strain)
    /// or `∫ T·dEp` (finite strain), accumulated by the trapezoidal rule per increment
    /// (exact energy balance with the trapezoidal external work at small strain).
    pub plastic_dissipation: f64,
    /// Element-level internal variables of the point's element, written by the element
    /// (the enhanced-strain parameters of the solid-shell, `element::solid_shell`), carried
    /// unchanged by the materials. Zero for elements without any. Absent from checkpoints
    /// written before it existed (read as zero).
    #[serde(default)]
    pub enhanced: [f64; ENHANCED_PARAMETERS],
    /// Back stresses `X_i` of a kinematic hardening law (`material::kinematic`: one per
    /// Armstrong-Frederick term, unused ones zero), in the stress the material works in
    /// (Cauchy under small strain, the log-space stress `T` under finite kinematics).
    /// All zero for materials without kinematic hardening; then not written into
    /// checkpoints (so their files are unchanged) and read back as zero.
    #[serde(
        default = "no_back_stress",
        skip_serializing_if = "is_zero_back_stress"
    )]
    pub back_stress: [Voigt; BACK_STRESSES],
}

/// Largest number of back stresses a [`PointState`] carries (Armstrong-Frederick terms
/// of a Chaboche law).
pub const BACK_STRESSES: usize = 3;

fn no_back_stress() -> [Voigt; BACK_STRESSES] {
    [Voigt::zeros(); BACK_STRESSES]
}

fn is_zero_back_stress(x: &[Voigt; BACK_STRESSES]) -> bool {
    x.iter().all(|v| v.iter().all(|&c| c == 0.0))
}

/// Number of element-level internal variables a [`PointState`] carries
/// ([`PointState::enhanced`]).
pub const ENHANCED_PARAMETERS: usize = 6;

impl PointState {
    /// The stress the material model works in: `log_stress` under finite kinematics,
    /// `stress` (Cauchy, equal to the small-strain stress) under small strain.
    pub fn material_stress(&self, finite: bool) -> &Voigt {
        if finite {
            &self.log_stress
        } else {
            &self.stress
        }
    }
}

impl PointState {
    /// The total back stress `X = Σ X_i` (zero without kinematic hardening).
    pub fn total_back_stress(&self) -> Voigt {
        self.back_stress.iter().sum()
    }
}

impl Default for PointState {
    /// The virgin state: stress- and strain-free, `F = I`.
    fn default() -> Self {
        PointState {
            stress: Voigt::zeros(),
            strain: Voigt::zeros(),
            plastic_strain: Voigt::zeros(),
            eq_plastic_strain: 0.0,
            deformation_gradient: Mat3::identity(),
            log_stress: Voigt::zeros(),
            plastic_dissipation: 0.0,
            enhanced: [0.0; ENHANCED_PARAMETERS],
            back_stress: no_back_stress(),
        }
    }
}

/// Output of a finite-strain material update ([`Material::update_finite`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FiniteResponse {
    /// Second Piola-Kirchhoff stress `S` (Voigt, tensor shear).
    pub pk2: Voigt,
    /// Material tangent `∂S/∂E_GL` (Voigt; Green-Lagrange strain with engineering shear).
    pub tangent: Tangent,
}

/// Kinematic input of a material update at one integration point, at the end of the
/// current increment (the trial configuration).
///
/// Both a small-strain measure and the full deformation gradient are supplied so that the
/// element interface does not change when a finite-strain material is added: small-strain
/// materials read `strain`, finite-strain materials read `deformation_gradient` (together
/// with the committed state's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kinematics {
    /// Small strain `ε = sym ∇u` (Voigt, engineering shear), with the element's
    /// volumetric treatment applied (B-bar: the volumetric part is the element average).
    pub strain: Voigt,
    /// Deformation gradient `F = I + ∂u/∂X` (reference gradient, no volumetric
    /// modification; an F-bar element would pass the modified gradient here).
    pub deformation_gradient: Mat3,
}

impl Kinematics {
    /// Kinematics of a pure small-strain state `ε` (with `F = I + ε` as tensor, i.e.
    /// without rotation); handy for testing small-strain materials.
    pub fn from_strain(strain: Voigt) -> Self {
        Kinematics {
            strain,
            deformation_gradient: Mat3::identity() + strain_to_tensor(&strain),
        }
    }
}

/// A constitutive model.
///
/// The interface is the same for small-strain elastic and for finite-strain elastoplastic
/// models (e.g. Hill48 yield with Swift hardening and a return mapping): the history lives
/// in [`PointState`], the kinematics in [`Kinematics`], and `update` returns the tangent
/// the element needs.
pub trait Material: std::fmt::Debug + Send + Sync {
    /// Computes the trial state at the end of the increment from the `committed` state
    /// and the kinematics `kin`, writing every field of `trial` (fields the model does not
    /// use are copied from `committed`), and returns the algorithmic (consistent) tangent
    /// `D = ∂σ/∂ε` (Voigt, engineering shear strain), which makes Newton's method converge
    /// quadratically. Under finite kinematics this same update runs on the logarithmic
    /// strain (see [`update_finite`](Self::update_finite)).
    ///
    /// Errors: the update is impossible (e.g. non-finite strain from a diverging Newton
    /// iterate, or a return mapping that fails); the solver then cuts the step back.
    fn update(
        &self,
        kin: &Kinematics,
        committed: &PointState,
        trial: &mut PointState,
    ) -> Result<Tangent>;

    /// The trial state of [`update`](Self::update) without its tangent, for a
    /// residual-only evaluation (a line-search trial): the same `trial`, bit for bit.
    /// The default drops the tangent of `update`; a model whose tangent costs work of its
    /// own (a return mapping) skips it.
    fn update_stress(
        &self,
        kin: &Kinematics,
        committed: &PointState,
        trial: &mut PointState,
    ) -> Result<()> {
        self.update(kin, committed, trial).map(|_| ())
    }

    /// Finite-strain update at the deformation gradient `f` (an F-bar element passes its
    /// modified gradient): returns the second Piola-Kirchhoff stress and `∂S/∂E_GL`, and
    /// writes the Cauchy stress into `trial.stress`, the log-space stress into
    /// `trial.log_stress`, the logarithmic strain into `trial.strain`.
    ///
    /// The default is the Lagrangian logarithmic-strain extension of the small-strain
    /// model ([`log_strain::lagrangian_update`]): [`update`](Self::update) is applied to
    /// `E = ½ ln C` unchanged, so [`LinearElastic`] becomes Hencky hyperelasticity and
    /// [`ElastoPlastic`] log-strain hyperelasto-plasticity with material (reference-frame)
    /// orthotropy axes.
    fn update_finite(
        &self,
        f: &Mat3,
        committed: &PointState,
        trial: &mut PointState,
    ) -> Result<FiniteResponse> {
        self.update_finite_displacement_gradient(&(f - Mat3::identity()), committed, trial)
    }

    /// [`update_finite`](Self::update_finite) at `F = I + h`, given by the displacement
    /// gradient `h`: what elements call, because `F` itself stores a strain of `10⁻⁶` to
    /// only ~10 digits (round-off of `I`), too few for the force residual of a stiff,
    /// thin body (see [`log_strain`]). A material that overrides one of the two
    /// overrides both.
    fn update_finite_displacement_gradient(
        &self,
        h: &Mat3,
        committed: &PointState,
        trial: &mut PointState,
    ) -> Result<FiniteResponse> {
        log_strain::lagrangian_update(self, h, committed, trial)
    }

    /// The second Piola-Kirchhoff stress and `trial` of
    /// [`update_finite_displacement_gradient`](Self::update_finite_displacement_gradient)
    /// without the tangent (bit for bit the same), for a residual-only evaluation. The
    /// default is the log-strain extension's stress part
    /// ([`log_strain::lagrangian_stress`]); a material that overrides the update overrides
    /// this too.
    fn update_finite_stress(
        &self,
        h: &Mat3,
        committed: &PointState,
        trial: &mut PointState,
    ) -> Result<Voigt> {
        log_strain::lagrangian_stress(self, h, committed, trial)
    }

    /// The elastic tangent (initial stiffness), e.g. for a first predictor or a
    /// stiffness-proportional damping or penalty scale.
    fn elastic_tangent(&self) -> Tangent;

    /// Stored elastic energy per unit (reference) volume in `state`.
    fn elastic_energy_density(&self, state: &PointState) -> f64;

    /// The equivalent stress of the model's yield function at `state` (the value its
    /// plastic points keep equal to the current yield stress), of the stress the model
    /// works in: the log-space stress `log_stress` under finite kinematics (`finite`), the
    /// Cauchy stress `stress` under small strain. The default, for models without a yield
    /// function, is the von Mises stress of that stress.
    fn equivalent_stress(&self, state: &PointState, finite: bool) -> f64 {
        von_mises(state.material_stress(finite))
    }

    /// The state of a virgin point. Defaults to [`PointState::default`].
    fn initial_state(&self) -> PointState {
        PointState::default()
    }

    /// A short human-readable description ("linear elastic E=210000 nu=0.3") for logs.
    fn describe(&self) -> String;

    /// The strain-hardening exponent `n` of a Swift law `C (ε0 + ε̄p)^n`, when the model
    /// hardens by one: the default forming limit curve (Keeler-Brazier) is built from it.
    fn hardening_exponent(&self) -> Option<f64> {
        None
    }
}

/// Strain tensor from a Voigt strain vector with engineering shear (halves the shears).
pub fn strain_to_tensor(e: &Voigt) -> Mat3 {
    Mat3::new(
        e[0],
        0.5 * e[3],
        0.5 * e[5],
        0.5 * e[3],
        e[1],
        0.5 * e[4],
        0.5 * e[5],
        0.5 * e[4],
        e[2],
    )
}

/// Voigt strain vector (engineering shear, doubles the shears) of the symmetric part of `m`.
pub fn strain_from_tensor(m: &Mat3) -> Voigt {
    Voigt::new(
        m[(0, 0)],
        m[(1, 1)],
        m[(2, 2)],
        m[(0, 1)] + m[(1, 0)],
        m[(1, 2)] + m[(2, 1)],
        m[(2, 0)] + m[(0, 2)],
    )
}

/// Stress tensor from a Voigt stress vector (tensor components).
pub fn stress_to_tensor(s: &Voigt) -> Mat3 {
    Mat3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2])
}

/// Voigt stress vector (tensor components) of the symmetric part of `m`.
pub fn stress_from_tensor(m: &Mat3) -> Voigt {
    Voigt::new(
        m[(0, 0)],
        m[(1, 1)],
        m[(2, 2)],
        0.5 * (m[(0, 1)] + m[(1, 0)]),
        0.5 * (m[(1, 2)] + m[(2, 1)]),
        0.5 * (m[(2, 0)] + m[(0, 2)]),
    )
}

/// Von Mises equivalent stress `sqrt(3/2 s:s)` of a Voigt stress, `s` its deviator.
pub fn von_mises(s: &Voigt) -> f64 {
    let (a, b, c) = (s[0] - s[1], s[1] - s[2], s[2] - s[0]);
    (0.5 * (a * a + b * b + c * c) + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])).sqrt()
}

/// Pressure `-tr(σ)/3` of a Voigt stress (positive in compression).
pub fn pressure(s: &Voigt) -> f64 {
    -(s[0] + s[1] + s[2]) / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voigt_round_trips_and_double_contraction() {
        let e = Voigt::new(1.0, 2.0, 3.0, 0.4, 0.6, 0.8);
        let s = Voigt::new(5.0, -1.0, 2.0, 0.3, -0.7, 1.1);
        assert_eq!(strain_from_tensor(&strain_to_tensor(&e)), e);
        assert_eq!(stress_from_tensor(&stress_to_tensor(&s)), s);
        // σ·ε (Voigt) = σ : ε (tensors) thanks to engineering shears.
        let contraction = stress_to_tensor(&s)
            .component_mul(&strain_to_tensor(&e))
            .sum();
        assert!((s.dot(&e) - contraction).abs() < 1e-14);
    }

    #[test]
    fn von_mises_and_pressure() {
        let uniaxial = Voigt::new(7.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        assert!((von_mises(&uniaxial) - 7.0).abs() < 1e-14);
        let shear = Voigt::new(0.0, 0.0, 0.0, 2.0, 0.0, 0.0);
        assert!((von_mises(&shear) - 2.0 * 3f64.sqrt()).abs() < 1e-14);
        let hydro = Voigt::new(-3.0, -3.0, -3.0, 0.0, 0.0, 0.0);
        assert_eq!(von_mises(&hydro), 0.0);
        assert_eq!(pressure(&hydro), 3.0);
    }

    #[test]
    fn default_state_is_virgin() {
        let s = PointState::default();
        assert_eq!(s.stress, Voigt::zeros());
        assert_eq!(s.deformation_gradient, Mat3::identity());
        assert_eq!(s.eq_plastic_strain, 0.0);
    }
}
