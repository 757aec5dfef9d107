//! Finite elements: the [`Element`] interface, the 8-node hexahedron [`Hex8`] with
//! selective reduced integration (B-bar, small strain) and its finite-strain counterpart
//! [`Hex8FBar`] (total Lagrangian, F-bar). [`StrainTheory`] picks one for a model.
//!
//! An element maps nodal displacements to the internal force vector and its tangent
//!
//! ```text
//! f_int = ∫ Bᵀ σ dV,        K = ∂f_int/∂u = ∫ Bᵀ D B dV   (small strain),
//! ```
//!
//! calling the [`Material`] at each integration point. Degrees of freedom are numbered
//! node by node, `[u0x, u0y, u0z, u1x, ...]`, nodes in the element's connectivity order.

use nalgebra::{SMatrix, SVector};

use crate::geometry::Vec3;
use crate::material::{Material, PointState, Voigt};
use crate::mesh::Mesh;
use crate::{Error, Result};

pub mod hex8;
pub mod hex8_fbar;
#[doc(hidden)]
pub mod hex8_fbar_reference;
pub mod solid_shell;
pub mod solid_shell_counts;
#[doc(hidden)]
pub mod solid_shell_reference;

pub use hex8::Hex8;
pub use hex8_fbar::Hex8FBar;
pub use solid_shell::{ElementKind, SolidShell};

/// Kinematics of a model: which hexahedron the solver uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum StrainTheory {
    /// Small strain and rotation: [`Hex8`] (B-bar), the material's small-strain
    /// [`Material::update`]. The default, so that models written for linear theory keep it.
    #[default]
    Small,
    /// Large strain and rotation: [`Hex8FBar`] (total Lagrangian, F-bar), the material's
    /// [`Material::update_finite`] (Lagrangian logarithmic strain).
    Finite,
}

impl StrainTheory {
    /// The script name: "small" or "finite".
    pub fn name(self) -> &'static str {
        match self {
            StrainTheory::Small => "small",
            StrainTheory::Finite => "finite",
        }
    }

    /// From the script name; errors name the value and the choices.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "small" => Ok(StrainTheory::Small),
            "finite" => Ok(StrainTheory::Finite),
            other => Err(Error::input(
                "kinematics",
                format!("\"{other}\""),
                "must be \"small\" or \"finite\"",
            )),
        }
    }
}

/// The hexahedron of a strain theory (both have the 2x2x2 points in the same order).
/// `fbar = false` drops the F-bar modification of the finite-strain element (a fully
/// integrated total-Lagrangian hexahedron, which locks in nearly incompressible flow: for
/// verification only); the small-strain element is always B-bar.
pub fn hexahedron(theory: StrainTheory, fbar: bool) -> &'static dyn Element<{ hex8::DOFS }> {
    static SMALL: Hex8 = Hex8;
    static FINITE: Hex8FBar = Hex8FBar { fbar: true };
    static FINITE_FULL: Hex8FBar = Hex8FBar { fbar: false };
    match (theory, fbar) {
        (StrainTheory::Small, _) => &SMALL,
        (StrainTheory::Finite, true) => &FINITE,
        (StrainTheory::Finite, false) => &FINITE_FULL,
    }
}

/// Internal force and tangent stiffness of one element with `D` degrees of freedom
/// (`D = 3 x nodes`).
#[derive(Clone, Debug, PartialEq)]
pub struct ElementResponse<const D: usize> {
    /// Internal force vector `f_int = ∫ Bᵀ σ dV`.
    pub force: SVector<f64, D>,
    /// Tangent stiffness `K = ∂f_int/∂u` (symmetric when the material tangent is).
    pub stiffness: SMatrix<f64, D, D>,
}

/// How an element call solved the element's own unknowns (the solid-shell's enhanced
/// parameters); elements without any are always exact.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LocalSolve {
    /// To the element's tight tolerance: forces and states a function of the displacements
    /// and the committed state to round-off.
    Exact,
    /// Stopped earlier from a linearised prediction: forces off the exact local solution by
    /// a bounded amount (the solid-shell: `O(δ²)`, `δ <= 1e-4` of its strain scale), fine for
    /// a Newton iterate, not for a converged state (Newton does not accept one).
    Approximate,
}

/// A finite element with `D` degrees of freedom (3 per node).
///
/// Every method takes the *reference* nodal coordinates, and `evaluate` the *total*
/// displacement from the reference configuration as well, so that a finite-strain
/// (total or updated Lagrangian) element can implement the same interface: the current
/// coordinates are `ref_coords + u`.
///
/// Errors never carry the element index (the element does not know it): the caller adds
/// it with [`in_element`].
pub trait Element<const D: usize>: std::fmt::Debug + Send + Sync {
    /// Number of nodes (`D / 3`).
    fn node_count(&self) -> usize;

    /// Number of integration points, i.e. of [`PointState`]s per element.
    fn point_count(&self) -> usize;

    /// Internal force and tangent for the displacements `u` (one per node).
    ///
    /// `committed` are the converged states of the integration points, `trial` receives
    /// the states for `u` (see [`Material::update`]); both have
    /// [`point_count`](Self::point_count) entries. Errors: wrong slice lengths, a
    /// non-positive Jacobian determinant at an integration point (inverted element), a
    /// failed material update.
    fn evaluate(
        &self,
        ref_coords: &[Vec3],
        u: &[Vec3],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
    ) -> Result<ElementResponse<D>>;

    /// [`evaluate`](Self::evaluate) writing straight into the caller's buffers: `force`
    /// (length `D`) and, unless `None` (residual only), `stiffness` (length `D²`,
    /// column-major). Both are overwritten, not accumulated. The assembly calls this one, so
    /// that an element may skip the tangent for a residual-only evaluation and avoid moving
    /// a `D x D` matrix by value; the default forwards to `evaluate` and copies.
    #[allow(clippy::too_many_arguments)]
    fn evaluate_into(
        &self,
        ref_coords: &[Vec3],
        u: &[Vec3],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
        force: &mut [f64],
        stiffness: Option<&mut [f64]>,
    ) -> Result<()> {
        let response = self.evaluate(ref_coords, u, committed, trial, material)?;
        force.copy_from_slice(response.force.as_slice());
        if let Some(k) = stiffness {
            k.copy_from_slice(response.stiffness.as_slice());
        }
        Ok(())
    }

    /// Length of what one element remembers between the evaluations of a Newton attempt
    /// ([`Self::evaluate_remembering`]); none by default.
    fn memory_len(&self) -> usize {
        0
    }

    /// [`Self::evaluate_into`] with the element's `memory` (length [`Self::memory_len`]; all
    /// NaN at the start of an attempt), which it may read to start from and writes with a
    /// `stiffness` only: line-search trials leave it as the last linearisation left it. The
    /// result depends on it at round-off at most where the call returns
    /// [`LocalSolve::Exact`]; an element with internal unknowns may stop their solve
    /// earlier from a good start and say so ([`LocalSolve::Approximate`]). The default
    /// ignores the memory.
    #[allow(clippy::too_many_arguments)]
    fn evaluate_remembering(
        &self,
        ref_coords: &[Vec3],
        u: &[Vec3],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
        memory: &mut [f64],
        force: &mut [f64],
        stiffness: Option<&mut [f64]>,
    ) -> Result<LocalSolve> {
        let _ = memory;
        self.evaluate_into(ref_coords, u, committed, trial, material, force, stiffness)?;
        Ok(LocalSolve::Exact)
    }

    /// Reference volume weight `w_g det J_g` of each integration point.
    fn point_volumes(&self, ref_coords: &[Vec3]) -> Result<Vec<f64>>;

    /// `∫ f(state) dV` over the reference volume with the element's quadrature.
    fn integrate(
        &self,
        ref_coords: &[Vec3],
        states: &[PointState],
        f: &dyn Fn(&PointState) -> f64,
    ) -> Result<f64> {
        let w = self.point_volumes(ref_coords)?;
        if w.len() != states.len() {
            return Err(Error::input(
                "length of states",
                states.len(),
                &format!("must be {}", w.len()),
            ));
        }
        Ok(w.iter().zip(states).map(|(w, s)| w * f(s)).sum())
    }

    /// Volume of the element (reference configuration).
    fn volume(&self, ref_coords: &[Vec3]) -> Result<f64> {
        Ok(self.point_volumes(ref_coords)?.iter().sum())
    }

    /// Volume average of the integration-point stresses, `(1/V) ∫ σ dV` evaluated with the
    /// element's quadrature: one stress per element for output.
    fn average_stress(&self, ref_coords: &[Vec3], states: &[PointState]) -> Result<Voigt> {
        let volume = self.volume(ref_coords)?;
        let mut avg = Voigt::zeros();
        for i in 0..6 {
            avg[i] = self.integrate(ref_coords, states, &|s| s.stress[i])? / volume;
        }
        Ok(avg)
    }

    /// Elastic strain energy stored in the element, `∫ ψ dV` with
    /// `ψ = material.elastic_energy_density(state)`. For a linear elastic material and
    /// zero initial state this is `½ uᵀ K u`.
    fn strain_energy(
        &self,
        ref_coords: &[Vec3],
        states: &[PointState],
        material: &dyn Material,
    ) -> Result<f64> {
        self.integrate(ref_coords, states, &|s| material.elastic_energy_density(s))
    }

    /// Plastic work dissipated in the element so far, `∫ d_p dV₀` with the points'
    /// [`PointState::plastic_dissipation`].
    fn plastic_dissipation(&self, ref_coords: &[Vec3], states: &[PointState]) -> Result<f64> {
        self.integrate(ref_coords, states, &|s| s.plastic_dissipation)
    }
}

/// Prefixes the message of `err` with "element {index}: " so that a caller looping over
/// elements reports which one failed (I/O errors are returned unchanged).
pub fn in_element(err: Error, index: usize) -> Error {
    prefix(err, &format!("element {index}"))
}

/// Prefixes `err`'s message with `what: `.
pub(crate) fn prefix(err: Error, what: &str) -> Error {
    match err {
        Error::Input(m) => Error::Input(format!("{what}: {m}")),
        Error::Script(m) => Error::Script(format!("{what}: {m}")),
        Error::LinearSolver(m) => Error::LinearSolver(format!("{what}: {m}")),
        Error::NoConvergence {
            kind,
            cycling,
            message,
        } => Error::NoConvergence {
            kind,
            cycling,
            message: format!("{what}: {message}"),
        },
        other => other,
    }
}

/// The volume-averaged stress of every element of `mesh`, for output. `states` holds the
/// integration-point states element by element (`point_count` per element, in the
/// element's point order). Errors name the element.
pub fn element_average_stresses<const D: usize, E: Element<D> + ?Sized>(
    mesh: &Mesh,
    element: &E,
    states: &[PointState],
) -> Result<Vec<Voigt>> {
    let np = check_state_count(mesh, element.point_count(), states)?;
    (0..mesh.element_count())
        .map(|e| {
            element
                .average_stress(&mesh.hex_coordinates(e), &states[e * np..(e + 1) * np])
                .map_err(|err| in_element(err, e))
        })
        .collect()
}

/// Total elastic strain energy of the mesh (sum of [`Element::strain_energy`]), with the
/// states laid out as in [`element_average_stresses`].
pub fn total_strain_energy<const D: usize, E: Element<D> + ?Sized>(
    mesh: &Mesh,
    element: &E,
    states: &[PointState],
    material: &dyn Material,
) -> Result<f64> {
    let np = check_state_count(mesh, element.point_count(), states)?;
    (0..mesh.element_count()).try_fold(0.0, |sum, e| {
        element
            .strain_energy(
                &mesh.hex_coordinates(e),
                &states[e * np..(e + 1) * np],
                material,
            )
            .map(|w| sum + w)
            .map_err(|err| in_element(err, e))
    })
}

/// Total plastic dissipation of the mesh (sum of [`Element::plastic_dissipation`]), with
/// the states laid out as in [`element_average_stresses`].
pub fn total_plastic_dissipation<const D: usize, E: Element<D> + ?Sized>(
    mesh: &Mesh,
    element: &E,
    states: &[PointState],
) -> Result<f64> {
    let np = check_state_count(mesh, element.point_count(), states)?;
    (0..mesh.element_count()).try_fold(0.0, |sum, e| {
        element
            .plastic_dissipation(&mesh.hex_coordinates(e), &states[e * np..(e + 1) * np])
            .map(|w| sum + w)
            .map_err(|err| in_element(err, e))
    })
}

/// Checks `states.len() == elements x points` (and the indices of the mesh) and returns
/// the number of points per element.
fn check_state_count(mesh: &Mesh, points: usize, states: &[PointState]) -> Result<usize> {
    mesh.validate()?;
    let expected = mesh.element_count() * points;
    if states.len() != expected {
        return Err(Error::input(
            "number of integration-point states",
            states.len(),
            &format!(
                "must be {expected} ({} elements x {points} points)",
                mesh.element_count()
            ),
        ));
    }
    Ok(points)
}
