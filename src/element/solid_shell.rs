//! The solid-shell hexahedron: 8 nodes, displacement degrees of freedom only, for thin
//! sheets modelled with one element through the thickness (Hauptmann & Schweizerhof 1998,
//! Vu-Quoc & Tan 2003, Klinkel, Gruttmann & Wagner 2006). See `docs/solid-shell.md`.
//!
//! # Thickness direction
//!
//! The element's natural axis `ζ` (nodes 0-3 → 4-7) is the sheet's thickness direction:
//! [`check_columns`] verifies that every element edge `a → a + 4` is a step up one of the
//! mesh's through-thickness node columns ([`Mesh::columns`]).
//!
//! # Strains
//!
//! Total Lagrangian. With the covariant base vectors `G_α = ∂X/∂ξ_α`, `g_α = G_α + d_α`,
//! `d_α = ∂u/∂ξ_α`, the covariant Green-Lagrange strains are
//! `E_αβ = ½ (G_α·d_β + d_α·G_β + d_α·d_β)` (formed from `d`, so that a strain of `10⁻⁶`
//! keeps its relative precision; small strain drops `d_α·d_β`). At an integration point
//! `(ξ, η, ζ)`:
//!
//! * in-plane `E_11, E_22, E_12`: compatible, at the point;
//! * transverse shear (Dvorkin & Bathe 1986, assumed natural strain): `E_13` interpolated
//!   linearly in `η` from the mid-edge tying points `(0, ∓1, ζ)`, `E_23` linearly in `ξ`
//!   from `(∓1, 0, ζ)`: cures transverse-shear locking;
//! * thickness `E_33` (Betsch & Stein 1995): interpolated bilinearly in `(ξ, η)` from the
//!   four corner lines `(±1, ±1)`: cures trapezoidal (curvature-thickness) locking of
//!   curved and distorted meshes.
//!
//! These covariant components are mapped to the reference Cartesian frame,
//! `E = J⁻ᵀ E_cov J⁻¹` (`J = [G_1 G_2 G_3]` at the point), and the enhanced assumed strain
//! (EAS, Simo & Rifai 1990, Büchter, Ramm & Roehl 1994) is added, `Ẽ = Σ_m M_m α_m`:
//!
//! * thickness modes: `M_0 = (ζ - ζ̄) n ⊗ n` and `M_1 = (ζ² - ζ²̄) n ⊗ n`, `n = G³₀/|G³₀|` the
//!   normalised contravariant thickness vector at the element centre, `ζ̄`, `ζ²̄` the
//!   volume-weighted means along the point's in-plane position (`ζ̄ = 0` unless the thickness
//!   tapers). Compatible `E_33` is constant in `ζ` for a trilinear hexahedron; `M_0` makes
//!   it linear (cures thickness (Poisson) locking in bending), `M_1` quadratic: in plastic
//!   bending, incompressibility needs the thickness stretch `1/λ_x`, whose Green-Lagrange
//!   strain has a `κ²z²` part; without `M_1` the sheet locks volumetrically (+7 % moment at a
//!   bending radius of 10 thicknesses). Subtracting the means keeps `∫ M : S dV = 0` for a
//!   constant stress on any hexahedron (membrane patch test), and on flat elements `M_0` is
//!   `ζ n ⊗ n` at every point, so that the linear thickness strain of pure bending is exact
//!   on distorted meshes (bending patch test).
//! * with `membrane_modes`, four in-plane modes `(j₀/j) ξ G¹₀⊗G¹₀ |G₁₀|²`,
//!   `(j₀/j) η G²₀⊗G²₀ |G₂₀|²`, `(j₀/j) {ξ, η} sym(G¹₀⊗G²₀) |G₁₀||G₂₀|` (the EAS-4 membrane
//!   modes with the centre transformation of Simo & Rifai), against in-plane shear locking.
//!
//! The material sees `C = I + 2E` (any symmetric positive definite `C` is the right
//! Cauchy-Green tensor of its stretch `U = √C`, and the log-strain materials depend on `C`
//! only), through [`Material::update_finite_displacement_gradient`] at `h = U - I` formed as
//! `Q diag(μ / (1 + √(1 + μ))) Qᵀ` from the eigenpairs of `2E` (no round-off against `I`);
//! under small strain [`Material::update`] at `ε = E`.
//!
//! # Element-level condensation of the EAS parameters
//!
//! With `W = Σ_p w_p ψ(E_p(u, α))`, `r_u = Σ w Bᵀ S`, `r_α = Σ w Mᵀ S`: the parameters `α`
//! solve `r_α(u, α) = 0` by a local Newton iteration (`SolidShell::solve_enhanced_parameters`,
//! "Local solve" below; the converged values are kept in `PointState::enhanced`, so across
//! increments and in checkpoints), and
//!
//! ```text
//! f = r_u(u, α(u)),    K = K_uu - K_uα K_αα⁻¹ K_αu,
//! K_uu = Σ w (Bᵀ ℂ B + G(S)),  K_uα = Σ w Bᵀ ℂ M,  K_αu = Σ w Mᵀ ℂ B,  K_αα = Σ w Mᵀ ℂ M,
//! ```
//!
//! the exact derivative of `f` (implicit function theorem). `G(S)` is the geometric
//! stiffness `Σ_c S^c ∂²E_c/∂u²` of the (ANS-interpolated) covariant strains.
//!
//! # Local solve
//!
//! Solving `α` to convergence in every call keeps the element a function of
//! `(u, committed)` only, like every other element: a Newton iterate, a line-search trial
//! and a cut-back step never depend on the previous iterate. The iteration stops once its
//! next step `δ = K_αα⁻¹ r_α` is at most [`LOCAL_TOLERANCE`] (10⁻⁸) of the element's strain
//! scale, and takes that step to first order, `α - δ` and `S - ℂ M δ`: force, stresses and
//! parameters are then within `O(δ²)` (10⁻¹⁶ relative) of the exact local solution; the
//! tangent and the material's internal variables are those of the last iterate, `δ` away.
//!
//! Where it starts decides its cost (each iteration updates every point's material).
//! Within a Newton attempt the assembly gives each element a memory
//! ([`Element::evaluate_remembering`]): an evaluation with the stiffness writes its `α`,
//! its displacements `u₀` and `P = K_αα⁻¹ K_αu` (already formed for `K`), and the next
//! evaluation starts from the linearised `α - P (u - u₀)`, whose error is of second order
//! in the step `u - u₀`; line-search trials read the memory and leave it. Where the iteration
//! from the prediction fails or wanders ([`PREDICTED_LOCAL_ITERATIONS`]), it starts again
//! from the remembered `α` (without a memory: the values `trial` carries, else the committed
//! ones) with full steps and, where those fail too (a 2-cycle across the elastic-plastic
//! switch of some points, or an overshoot into material inversion), with halved steps.
//! The solver keeps the memory of a converged increment with its committed state, so the
//! next increment's first evaluation is predicted too.
//!
//! From a prediction the iteration stops earlier, at a step of
//! [`PREDICTED_LOCAL_TOLERANCE`] (10⁻⁴) of the strain scale: the force is then within about
//! 10⁻⁸ of the exact local solution's, and the call reports [`LocalSolve::Approximate`]
//! when the step exceeded [`LOCAL_TOLERANCE`]. That is an inexact Newton iterate, not a
//! different problem: Newton accepts convergence only at an evaluation whose every element
//! was exact, and near convergence the predictions are exact anyway (the step `u - u₀` is
//! small). On the 25 x 25 x 1 benchmark cup it takes 0.72 of the material updates to
//! 25 mm and 0.92 of the whole run's CPU, with the punch force and the draw-ins of the
//! tight tolerance to 1e-13 wherever the increments are the same (BENCHMARKS.md).
//!
//! # Integration and cost
//!
//! 2 x 2 Gauss points in plane (full: no hourglass modes) times `n` points through the
//! thickness (default 5; [`thickness_rule`]: Newton-Cotes for odd `n`, Gauss otherwise): point `k * 4 + q` is in-plane point `q` (in the
//! order of the corners 0-3) at thickness level `k` (bottom to top). Per point and local
//! iteration: one material update (plus one 3 x 3 eigen-decomposition under finite
//! strain); per point once: `Bᵀ ℂ B`, ~4.3k multiplications.

use nalgebra::{SMatrix, SVector};

use super::hex8::{jacobian, nodes_array, response_through_into, shape_derivatives, DOFS, NODES};
use super::solid_shell_counts::{self as counts, CallKind};
use super::{prefix, Element, ElementResponse, LocalSolve};
use crate::geometry::{Mat3, Vec3};
use crate::material::{
    strain_from_tensor, strain_to_tensor, stress_from_tensor, stress_to_tensor, Kinematics,
    Material, PointState, Tangent, Voigt, ENHANCED_PARAMETERS,
};
use crate::mesh::Mesh;
use crate::{Error, Result};

/// Most thickness points an element may have.
pub const MAX_THICKNESS_POINTS: usize = 12;
/// Thickness points unless the settings say otherwise: 5 (Simpson per half, Abaqus's
/// default), within 0.33 % of the analytic moment-curvature of an elastic-plastic strip for
/// every bend tighter than `R = 50 t` (the tool radii of forming), at 20 material points
/// per element. In the elastic-plastic transition (`R` of a few hundred `t`) it errs by up
/// to 7.7 %: the stress profile kinks at the edges of the elastic core, which sweep
/// through the thickness, and with a kink inside a panel every fixed rule errs by `O(h²)`
/// times the slope jump whatever its points, so only the count helps.
/// [`ACCURATE_THICKNESS_POINTS`] is within 1.1 % over the whole range, at 2.1 times the
/// cost per iteration: for springback and gentle bends. docs/solid-shell.md,
/// "Elastic-plastic transition".
pub const DEFAULT_THICKNESS_POINTS: usize = 5;
/// The fewest thickness points of the rule within about 1 % of the analytic
/// moment-curvature over bending radii from 5 t to 3000 t, the transition included.
pub const ACCURATE_THICKNESS_POINTS: usize = 11;

/// Covariant strain components in Voigt order: `(α, β)` of `xx, yy, zz, xy, yz, zx`.
pub(super) const COMPONENTS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)];

/// In-plane Gauss abscissa `1/√3`.
const GAUSS: f64 = 0.577_350_269_189_625_8;

/// The enhanced parameters of one element.
type Modes = SVector<f64, ENHANCED_PARAMETERS>;

/// Most local Newton iterations for the EAS parameters.
pub(super) const MAX_LOCAL_ITERATIONS: usize = 30;

/// Most local Newton iterations from a linearised prediction before the remembered start
/// is tried instead: from a good prediction the iteration is quadratic and needs two or
/// three; one that wanders (a prediction across the elastic-plastic switch, or from far
/// away) would otherwise spend all [`MAX_LOCAL_ITERATIONS`].
const PREDICTED_LOCAL_ITERATIONS: usize = 6;

/// The smallest fraction of a local Newton step tried before the step is taken as it is.
const MIN_LOCAL_STEP: f64 = 1.0 / 1024.0;

/// The local iteration stops once its next step `δ` is at most this fraction of the
/// element's strain scale; the force and stresses take that step to first order
/// (`S - ℂ M δ`). Their distance to the exact local solution is then of order
/// `(δ / scale)² ≤ 10⁻¹⁶` relative, round-off (module docs, "Local solve").
const LOCAL_TOLERANCE: f64 = 1e-8;

/// A local iteration started from the linearised prediction of the element's memory
/// ([`Element::evaluate_remembering`]) stops once its next step is at most this fraction of
/// the strain scale, taken to first order: force and stresses within `O((δ / scale)²)`,
/// about 10⁻⁸ relative, of the exact local solution, and the call says so
/// ([`LocalSolve::Approximate`] where `δ` exceeds [`LOCAL_TOLERANCE`]). Newton converges
/// only on exact calls, so the converged states are those of [`LOCAL_TOLERANCE`]; the
/// iterates before take fewer material updates (module docs, "Local solve").
const PREDICTED_LOCAL_TOLERANCE: f64 = 1e-4;

/// The least strain scale of [`LOCAL_TOLERANCE`]: the round-off of a unit stretch. At an
/// unstrained element (scale 0) started a round-off away from its parameters' solution 0
/// (a prediction from a strained memory), the quadratically shrinking steps would
/// otherwise never pass (they stall at denormals: "last step 1e-323").
const STRAIN_ROUND_OFF: f64 = f64::EPSILON;

/// Length of a solid-shell's memory ([`Element::memory_len`]): a mark (1 once written),
/// the enhanced parameters and nodal displacements of the last linearisation, and
/// `P = K_αα⁻¹ K_αu` there (column-major).
pub const MEMORY: usize = MEMORY_P.end;

/// Where each part of the memory ([`MEMORY`]) lies, after the mark at 0.
const MEMORY_ALPHA: std::ops::Range<usize> = 1..1 + ENHANCED_PARAMETERS;
const MEMORY_U: std::ops::Range<usize> = MEMORY_ALPHA.end..MEMORY_ALPHA.end + DOFS;
const MEMORY_P: std::ops::Range<usize> = MEMORY_U.end..MEMORY_U.end + ENHANCED_PARAMETERS * DOFS;

/// The solid-shell hexahedron; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SolidShell {
    /// Finite strain (total Lagrangian, log-strain material update) or small strain.
    pub finite: bool,
    /// Gauss points through the thickness, `1..=MAX_THICKNESS_POINTS`.
    pub thickness_points: usize,
    /// The four in-plane EAS modes besides the thickness mode.
    pub membrane_modes: bool,
}

/// Which hexahedron a model uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ElementKind {
    /// The 8-node hexahedron of the strain theory (B-bar small strain, F-bar finite).
    #[default]
    Hexahedron,
    /// The solid-shell ([`SolidShell`]).
    SolidShell,
}

impl ElementKind {
    /// The script name: "hexahedron" or "solid_shell".
    pub fn name(self) -> &'static str {
        match self {
            ElementKind::Hexahedron => "hexahedron",
            ElementKind::SolidShell => "solid_shell",
        }
    }

    /// From the script name; errors name the value and the choices.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "hexahedron" => Ok(ElementKind::Hexahedron),
            "solid_shell" => Ok(ElementKind::SolidShell),
            other => Err(Error::input(
                "element",
                format!("\"{other}\""),
                "must be \"hexahedron\" or \"solid_shell\"",
            )),
        }
    }
}

/// Checks a thickness-point count from the settings.
pub fn check_thickness_points(n: usize) -> Result<usize> {
    if (1..=MAX_THICKNESS_POINTS).contains(&n) {
        Ok(n)
    } else {
        Err(Error::input(
            "thickness_points",
            n,
            &format!("must be a whole number from 1 to {MAX_THICKNESS_POINTS}"),
        ))
    }
}

const fn shell_table<const N: usize>(finite: bool) -> [SolidShell; N] {
    let mut t = [SolidShell {
        finite,
        thickness_points: 0,
        membrane_modes: true,
    }; N];
    let mut i = 0;
    while i < N {
        t[i].thickness_points = i;
        i += 1;
    }
    t
}

static SMALL_SHELLS: [SolidShell; MAX_THICKNESS_POINTS + 1] = shell_table(false);
static FINITE_SHELLS: [SolidShell; MAX_THICKNESS_POINTS + 1] = shell_table(true);

/// The element a model's settings select: the hexahedron of the strain theory
/// ([`super::hexahedron`]) or the solid-shell with `thickness_points` points through the
/// thickness. Errors: a thickness-point count out of range.
pub fn select(
    kind: ElementKind,
    theory: super::StrainTheory,
    fbar: bool,
    thickness_points: usize,
) -> Result<&'static dyn Element<DOFS>> {
    match kind {
        ElementKind::Hexahedron => Ok(super::hexahedron(theory, fbar)),
        ElementKind::SolidShell => {
            let n = check_thickness_points(thickness_points)?;
            Ok(match theory {
                super::StrainTheory::Small => &SMALL_SHELLS[n],
                super::StrainTheory::Finite => &FINITE_SHELLS[n],
            })
        }
    }
}

/// Checks that every element of `mesh` stands in its through-thickness node columns
/// ([`Mesh::columns`]) with nodes 4-7 one step above nodes 0-3, as the solid-shell needs
/// (its `ζ` axis is the thickness direction). Errors name the fault and the element.
pub fn check_columns(mesh: &Mesh) -> Result<()> {
    if mesh.columns().is_empty() {
        let why = mesh
            .columns_fault()
            .map(|f| format!(": {f}"))
            .unwrap_or_default();
        return Err(Error::Input(format!(
            "element \"solid_shell\": the mesh has no through-thickness node columns{why} (a \
             block mesh has them, also after mesh.map, and an imported or merged sheet of \
             hexahedra stacked through its thickness); the solid-shell takes its thickness \
             direction from them"
        )));
    }
    let mut place = vec![None; mesh.node_count()];
    for (c, col) in mesh.columns().iter().enumerate() {
        for (k, &n) in col.iter().enumerate() {
            place[n] = Some((c, k));
        }
    }
    for (e, hex) in mesh.hexes.iter().enumerate() {
        for a in 0..4 {
            let (lo, hi) = (hex[a], hex[a + 4]);
            let ok = matches!((place[lo], place[hi]),
                (Some((c0, k0)), Some((c1, k1))) if c0 == c1 && k1 == k0 + 1);
            if !ok {
                return Err(Error::Input(format!(
                    "element {e}: element \"solid_shell\" needs its edge from local node {a} \
                     (node {lo}) to local node {} (node {hi}) to be one step up a \
                     through-thickness node column; it is not",
                    a + 4
                )));
            }
        }
    }
    Ok(())
}

/// The through-thickness rule of `n` points on `[-1, 1]`, ascending: for odd `n >= 5`
/// equally spaced points (the faces and the mid-surface among them) with a Newton-Cotes
/// rule on each half (composite Simpson, closed by the 3/8 rule when a half has an odd
/// number of intervals), Simpson for `n = 3`, Gauss-Legendre otherwise. Why: in plastic
/// bending the stress changes sign at the mid-surface, so the moment integrand `σ z` has a
/// kink there; a rule with the kink as a panel boundary integrates each half exactly up to
/// cubics, while 5 Gauss points across it miss the fully plastic moment `∫|z| dz` by 5.5 %.
/// All are exact for the elastic bending stiffness (`∫z² dz`, and `∫z³` for tapered
/// elements).
pub fn thickness_rule(n: usize) -> (Vec<f64>, Vec<f64>) {
    if n == 3 {
        return (vec![-1.0, 0.0, 1.0], vec![1.0 / 3.0, 4.0 / 3.0, 1.0 / 3.0]);
    }
    if n < 5 || n % 2 == 0 {
        return gauss_legendre(n);
    }
    // Each half has m intervals of width h: composite Simpson, closed by the 3/8 rule on
    // the last three intervals when m is odd; both exact for cubics.
    let m = (n - 1) / 2;
    let h = 1.0 / m as f64;
    let mut half = vec![0.0; m + 1];
    let simpson = if m % 2 == 0 { m } else { m - 3 };
    for i in (0..simpson).step_by(2) {
        half[i] += h / 3.0;
        half[i + 1] += 4.0 * h / 3.0;
        half[i + 2] += h / 3.0;
    }
    if simpson < m {
        for (k, c) in [1.0, 3.0, 3.0, 1.0].iter().enumerate() {
            half[simpson + k] += 3.0 * h / 8.0 * c;
        }
    }
    let x = (0..n).map(|i| -1.0 + i as f64 * h).collect();
    let mut w = vec![0.0; n];
    for (i, wi) in half.iter().enumerate() {
        w[m + i] += wi;
        w[m - i] += wi;
    }
    (x, w)
}

/// Gauss-Legendre points and weights on `[-1, 1]`, ascending (Newton on the Legendre
/// recurrence; exact to round-off).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = Vec::with_capacity(n);
    let mut w = Vec::with_capacity(n);
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (p, dp) = legendre(n, z);
            let dz = p / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        let (_, dp) = legendre(n, z);
        x.push(z);
        w.push(2.0 / ((1.0 - z * z) * dp * dp));
    }
    x.reverse();
    w.reverse();
    (x, w)
}

/// The Legendre polynomial `P_n(z)` and its derivative (three-term recurrence).
fn legendre(n: usize, z: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, z);
    for k in 2..=n {
        let kf = k as f64;
        let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
        p0 = p1;
        p1 = p2;
    }
    if n == 1 {
        (z, 1.0)
    } else {
        (p1, n as f64 * (z * p1 - p0) / (z * z - 1.0))
    }
}

/// In-plane natural coordinates of point `q` (corner order 0-3).
pub(super) fn in_plane(q: usize) -> (f64, f64) {
    let c = crate::mesh::HEX_CORNERS[q];
    (c[0] * GAUSS, c[1] * GAUSS)
}

/// Tying locations of one thickness level: 0-3 the in-plane points, 4-7 the corner lines
/// (E₃₃), 8-9 `(∓1, 0)` (E₂₃), 10-11 `(0, ∓1)` (E₁₃).
pub(super) const LOCATIONS: usize = 12;

pub(super) fn location(l: usize) -> (f64, f64) {
    match l {
        0..=3 => in_plane(l),
        4..=7 => {
            let c = crate::mesh::HEX_CORNERS[l - 4];
            (c[0], c[1])
        }
        8 => (-1.0, 0.0),
        9 => (1.0, 0.0),
        10 => (0.0, -1.0),
        _ => (0.0, 1.0),
    }
}

/// The sampling of covariant component `c` at in-plane point `q`: `(location, weight)`
/// pairs, `len` of them.
pub(super) fn samples(q: usize, c: usize) -> ([(usize, f64); 4], usize) {
    let (xi, eta) = in_plane(q);
    let mut s = [(0, 0.0); 4];
    match c {
        2 => {
            for (i, out) in s.iter_mut().enumerate() {
                let k = crate::mesh::HEX_CORNERS[i];
                *out = (4 + i, 0.25 * (1.0 + k[0] * xi) * (1.0 + k[1] * eta));
            }
            (s, 4)
        }
        4 => {
            s[0] = (8, 0.5 * (1.0 - xi));
            s[1] = (9, 0.5 * (1.0 + xi));
            (s, 2)
        }
        5 => {
            s[0] = (10, 0.5 * (1.0 - eta));
            s[1] = (11, 0.5 * (1.0 + eta));
            (s, 2)
        }
        _ => {
            s[0] = (q, 1.0);
            (s, 1)
        }
    }
}

/// What one integration point keeps between the local iterations and the assembly.
struct Point {
    /// Cartesian Green-Lagrange strain from the displacements alone (engineering shear).
    strain: Voigt,
    /// `∂E/∂u` (6 x 24).
    b: SMatrix<f64, 6, DOFS>,
    /// Covariant-to-Cartesian map of engineering strain vectors.
    t: Tangent,
    /// EAS modes (Cartesian, engineering shear), one column per parameter (zero columns
    /// for inactive parameters).
    modes: Tangent,
    /// Reference volume weight.
    dv: f64,
    /// Compatible deformation gradient at the point (for the Cauchy stress and the
    /// rotation measure of the step control).
    f: Mat3,
    /// Thickness level and in-plane index.
    level: usize,
    q: usize,
}

/// Natural derivatives at the tying locations of every thickness level, kept from
/// [`SolidShell::points`] for the geometric stiffness.
type LevelDerivatives = [[Vec3; NODES]; LOCATIONS];

/// A stretch-excess `h` with `(I + h)ᵀ(I + h) = I + a` (`a = 2E` symmetric) for the
/// log-strain material, which depends on `C` only: `I + h` is the upper Cholesky factor of
/// `C`, formed without round-off against `I` (`√(1 + x) - 1 = x / (1 + √(1 + x))`). Three
/// square roots, where `U - I` needs an eigen-decomposition. Errors: `C` not positive
/// definite (an inverted material) or not finite.
pub(super) fn cholesky_excess(a: &Mat3) -> Result<Mat3> {
    if !a.iter().all(|v| v.is_finite()) {
        return Err(Error::no_convergence(
            crate::error::Failure::Local,
            "non-finite enhanced strain",
        ));
    }
    let mut h = Mat3::zeros();
    // Row i of R = I + h: R_ii = √(C_ii - Σ_{k<i} R_ki²), R_ij = (C_ij - Σ_{k<i} R_ki R_kj) / R_ii.
    for i in 0..3 {
        let mut excess = a[(i, i)];
        for k in 0..i {
            excess -= h[(k, i)] * h[(k, i)];
        }
        if excess.is_nan() || excess <= -1.0 {
            return Err(Error::no_convergence(
                crate::error::Failure::Local,
                format!(
                    "enhanced strain with a non-positive stretch {} (inverted material)",
                    1.0 + excess
                ),
            ));
        }
        let r = (1.0 + excess).sqrt();
        h[(i, i)] = excess / (1.0 + r);
        for j in i + 1..3 {
            let mut c = 0.5 * (a[(i, j)] + a[(j, i)]);
            for k in 0..i {
                c -= h[(k, i)] * h[(k, j)];
            }
            h[(i, j)] = c / r;
        }
    }
    Ok(h)
}

/// The Cauchy stress of the PK2 stress `s` at the enhanced Green-Lagrange strain `e`
/// (engineering shears), oriented by the compatible deformation gradient `f`:
/// `σ = Q F̃ S F̃ᵀ Qᵀ / det F̃`, `F̃ = I + h` the Cholesky stretch of `C = I + 2E`
/// ([`cholesky_excess`]) and `Q` the rotation of the polar decomposition of `f F̃⁻¹`. Why
/// not `f S fᵀ / det f`: the compatible `f` lacks the enhanced thickness strain, which in
/// bending is the Poisson contraction `∓ν κ z`: pushing forward with it put the faces'
/// von Mises stress 3.5 % off the yield stress at a bending radius of 20 thicknesses. The
/// stretch is the material's, the rotation the element's (objective). `Q` by Higham's
/// iteration `X ← (X + X⁻ᵀ)/2`, quadratic, 3-5 steps from a near-rotation.
pub(super) fn cauchy_stress(f: &Mat3, e: &Voigt, s: &Voigt) -> Result<Voigt> {
    let stretch = Mat3::identity() + cholesky_excess(&(strain_to_tensor(e) * 2.0))?;
    let inverse = stretch.try_inverse().ok_or_else(|| {
        Error::no_convergence(crate::error::Failure::Local, "singular enhanced stretch")
    })?;
    let mut q = f * inverse;
    for _ in 0..20 {
        let Some(inv) = q.try_inverse() else {
            return Err(Error::no_convergence(
                crate::error::Failure::Local,
                "singular deformation gradient in the stress output",
            ));
        };
        let next = (q + inv.transpose()) * 0.5;
        let change = (next - q).norm();
        q = next;
        if change < 1e-12 {
            break;
        }
    }
    let qf = q * stretch;
    Ok(stress_from_tensor(
        &(qf * stress_to_tensor(s) * qf.transpose() / stretch.determinant()),
    ))
}

/// What one element call's local solve did, for [`counts`]: material updates of all its
/// points (local iterations, halved retries included) and its first step over the strain
/// scale.
#[derive(Default)]
struct Tally {
    updates: usize,
    first_step: Option<f64>,
}

/// Columns of the combined operator `[B | M]` of a point: its displacements' and its
/// enhanced parameters' strains.
const WIDE: usize = DOFS + ENHANCED_PARAMETERS;

/// A tangent `ℂ` is taken as symmetric where `|ℂ - ℂᵀ| <= SYMMETRY_TOLERANCE |ℂ|`
/// (largest entries): the round-off of a symmetric (hyperelastic or associative) tangent.
const SYMMETRY_TOLERANCE: f64 = 1e-12;

/// The four tangent blocks of an element, `Σ_p dv_p [B_p | M_p]ᵀ ℂ_p [B_p | M_p]`
/// (`WIDE x WIDE`, column-major; `K_uu`, `K_uα`, `K_αu`, `K_αα` its corners). Each point adds
/// the rank-6 product `[B | M]ᵀ W` with `W = dv ℂ [B | M]`, column by column as six
/// contiguous multiply-adds over the rows (`rows[r]` is row `r` of `[B | M]`, stored as a
/// row so that those loops vectorise). With every point's `ℂ` symmetric the sum is
/// symmetric and only its upper triangle is computed (`WIDE (WIDE + 1) / 2` of the
/// `WIDE²` entries: 0.52 of the work), then mirrored.
struct TangentBlocks {
    k: [f64; WIDE * WIDE],
}

impl TangentBlocks {
    fn sum(points: &[Point], tangents: &[Tangent]) -> Self {
        let symmetric = tangents
            .iter()
            .all(|c| (c - c.transpose()).amax() <= SYMMETRY_TOLERANCE * c.amax());
        let mut blocks = Self {
            k: [0.0; WIDE * WIDE],
        };
        for (point, c) in points.iter().zip(tangents) {
            blocks.add(point, c, symmetric);
        }
        if symmetric {
            for j in 0..WIDE {
                for i in 0..j {
                    blocks.k[i * WIDE + j] = blocks.k[j * WIDE + i];
                }
            }
        }
        blocks
    }

    fn entry(&self, i: usize, j: usize) -> f64 {
        self.k[j * WIDE + i]
    }

    /// Adds one point's product. Where the processor has AVX2 the same code runs compiled
    /// for it (four lanes instead of two), chosen at run time: the same products and sums
    /// in the same order (no fused multiply-add), so both give the same bits.
    fn add(&mut self, point: &Point, c: &Tangent, upper: bool) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2 (checked just above).
            unsafe { self.add_avx2(point, c, upper) };
            return;
        }
        self.add_portable(point, c, upper);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn add_avx2(&mut self, point: &Point, c: &Tangent, upper: bool) {
        self.add_portable(point, c, upper);
    }

    #[inline(always)]
    fn add_portable(&mut self, point: &Point, c: &Tangent, upper: bool) {
        let rows: [[f64; WIDE]; 6] = std::array::from_fn(|r| {
            std::array::from_fn(|i| {
                if i < DOFS {
                    point.b[(r, i)]
                } else {
                    point.modes[(r, i - DOFS)]
                }
            })
        });
        let mut w = [[0.0; WIDE]; 6];
        for (r, out) in w.iter_mut().enumerate() {
            let cr: [f64; 6] = std::array::from_fn(|t| c[(r, t)] * point.dv);
            for (j, o) in out.iter_mut().enumerate() {
                *o = cr[0] * rows[0][j]
                    + cr[1] * rows[1][j]
                    + cr[2] * rows[2][j]
                    + cr[3] * rows[3][j]
                    + cr[4] * rows[4][j]
                    + cr[5] * rows[5][j];
            }
        }
        for j in 0..WIDE {
            let len = if upper { j + 1 } else { WIDE };
            let col = &mut self.k[j * WIDE..j * WIDE + len];
            let wj: [f64; 6] = std::array::from_fn(|r| w[r][j]);
            for (i, out) in col.iter_mut().enumerate() {
                *out += rows[0][i] * wj[0]
                    + rows[1][i] * wj[1]
                    + rows[2][i] * wj[2]
                    + rows[3][i] * wj[3]
                    + rows[4][i] * wj[4]
                    + rows[5][i] * wj[5];
            }
        }
    }
}

/// `K_αα⁻¹ rhs` for the `ne` active enhanced parameters (identity rows for the inactive
/// ones, whose modes and right-hand sides are zero).
fn solve_enhanced<const C: usize>(
    mut k_aa: SMatrix<f64, ENHANCED_PARAMETERS, ENHANCED_PARAMETERS>,
    ne: usize,
    rhs: &SMatrix<f64, ENHANCED_PARAMETERS, C>,
) -> Result<SMatrix<f64, ENHANCED_PARAMETERS, C>> {
    for m in ne..ENHANCED_PARAMETERS {
        k_aa[(m, m)] = 1.0;
    }
    k_aa.lu().solve(rhs).ok_or_else(|| {
        Error::no_convergence(
            crate::error::Failure::Local,
            "singular enhanced-strain stiffness",
        )
    })
}

/// The through-thickness rule of `n` points, computed once per `n`.
fn cached_rule(n: usize) -> &'static (Vec<f64>, Vec<f64>) {
    static RULES: std::sync::OnceLock<Vec<(Vec<f64>, Vec<f64>)>> = std::sync::OnceLock::new();
    &RULES.get_or_init(|| (0..=MAX_THICKNESS_POINTS).map(thickness_rule).collect())[n]
}

impl SolidShell {
    /// Number of active EAS parameters.
    pub(super) fn modes(&self) -> usize {
        if self.membrane_modes {
            6
        } else {
            2
        }
    }

    /// The reference quantities and displacement strains of every point, and the natural
    /// derivatives at the tying locations of every level.
    fn points(
        &self,
        x: &[Vec3; NODES],
        u: &[Vec3; NODES],
    ) -> Result<(Vec<Point>, Vec<LevelDerivatives>)> {
        let n = self.thickness_points;
        let (zeta, wz) = cached_rule(n);
        let centre = jacobian(x, &Vec3::zeros());
        let j0 = centre.determinant();
        let inv0 = match centre.try_inverse() {
            Some(inv) if j0 > 0.0 && j0.is_finite() => inv,
            _ => {
                return Err(Error::input(
                    "Jacobian determinant at the element centre",
                    j0,
                    "must be > 0 (inverted or degenerate element)",
                ))
            }
        };
        let contra: [Vec3; 3] = std::array::from_fn(|i| inv0.row(i).transpose());
        let len: [f64; 3] = std::array::from_fn(|i| centre.column(i).norm());
        let n3 = contra[2].normalize();
        let tensor_mode = |m: Mat3| strain_from_tensor(&m);
        let thickness_mode = tensor_mode(n3 * n3.transpose());
        let m11 = tensor_mode(contra[0] * contra[0].transpose() * (len[0] * len[0]));
        let m22 = tensor_mode(contra[1] * contra[1].transpose() * (len[1] * len[1]));
        let g12 = contra[0] * contra[1].transpose() * (len[0] * len[1]);
        let m12 = tensor_mode((g12 + g12.transpose()) * 0.5);
        let mut levels = Vec::with_capacity(n);
        let mut jacobians = Vec::with_capacity(n);
        let mut dets = [0.0; 4 * MAX_THICKNESS_POINTS];
        for (k, &z) in zeta.iter().enumerate() {
            let dn: LevelDerivatives = std::array::from_fn(|l| {
                let (xi, eta) = location(l);
                shape_derivatives(&Vec3::new(xi, eta, z))
            });
            let j: [Mat3; LOCATIONS] = std::array::from_fn(|l| {
                (0..NODES).fold(Mat3::zeros(), |m, a| m + x[a] * dn[l][a].transpose())
            });
            for q in 0..4 {
                dets[4 * k + q] = j[q].determinant();
            }
            levels.push(dn);
            jacobians.push(j);
        }
        // Column means of ζ and ζ² (weights w j), so that the thickness modes have zero
        // mean along every column.
        let column_mean = |f: &dyn Fn(f64) -> f64| -> [f64; 4] {
            std::array::from_fn(|q| {
                let (mut num, mut den) = (0.0, 0.0);
                for k in 0..n {
                    num += wz[k] * f(zeta[k]) * dets[4 * k + q];
                    den += wz[k] * dets[4 * k + q];
                }
                num / den
            })
        };
        let zeta_bar = column_mean(&|z| z);
        let zeta2_bar = column_mean(&|z| z * z);
        let mut points = Vec::with_capacity(4 * n);
        for (k, &z) in zeta.iter().enumerate() {
            let dn = &levels[k];
            let js = &jacobians[k];
            let ds: [Mat3; LOCATIONS] = std::array::from_fn(|l| {
                (0..NODES).fold(Mat3::zeros(), |m, a| m + u[a] * dn[l][a].transpose())
            });
            for q in 0..4 {
                let p = 4 * k + q;
                let jp = js[q];
                let det = dets[p];
                let inv = match jp.try_inverse() {
                    Some(inv) if det > 0.0 && det.is_finite() => inv,
                    _ => {
                        return Err(Error::input(
                            &format!("Jacobian determinant at integration point {p}"),
                            det,
                            "must be > 0 (inverted or degenerate element)",
                        ))
                    }
                };
                let mut e_cov = Voigt::zeros();
                let mut b_cov = SMatrix::<f64, 6, DOFS>::zeros();
                for (c, &(al, be)) in COMPONENTS.iter().enumerate() {
                    let s = if al == be { 0.5 } else { 1.0 };
                    let (list, count) = samples(q, c);
                    for &(l, phi) in &list[..count] {
                        let (ga, gb) = (js[l].column(al), js[l].column(be));
                        let (da, db) = (ds[l].column(al), ds[l].column(be));
                        let mut value = ga.dot(&db) + da.dot(&gb);
                        let (cur_a, cur_b) = if self.finite {
                            value += da.dot(&db);
                            (ga + da, gb + db)
                        } else {
                            (ga.into_owned(), gb.into_owned())
                        };
                        e_cov[c] += phi * s * value;
                        for a in 0..NODES {
                            let v = (cur_b * dn[l][a][al] + cur_a * dn[l][a][be]) * (phi * s);
                            for kk in 0..3 {
                                b_cov[(c, 3 * a + kk)] += v[kk];
                            }
                        }
                    }
                }
                let mut t = Tangent::zeros();
                for m in 0..6 {
                    let mut unit = Voigt::zeros();
                    unit[m] = 1.0;
                    let cart = inv.transpose() * strain_to_tensor(&unit) * inv;
                    t.set_column(m, &strain_from_tensor(&cart));
                }
                let (xi, eta) = in_plane(q);
                let scale = j0 / det;
                let mut modes = Tangent::zeros();
                modes.set_column(0, &(thickness_mode * (z - zeta_bar[q])));
                modes.set_column(1, &(thickness_mode * (z * z - zeta2_bar[q])));
                if self.membrane_modes {
                    modes.set_column(2, &(m11 * (scale * xi)));
                    modes.set_column(3, &(m22 * (scale * eta)));
                    modes.set_column(4, &(m12 * (scale * xi)));
                    modes.set_column(5, &(m12 * (scale * eta)));
                }
                let h = ds[q] * inv;
                points.push(Point {
                    strain: t * e_cov,
                    b: t * b_cov,
                    t,
                    modes,
                    dv: wz[k] * det,
                    f: Mat3::identity() + h,
                    level: k,
                    q,
                });
            }
        }
        Ok((points, levels))
    }

    /// The material at `point` with the EAS parameters `alpha`: PK2 (or small-strain)
    /// stress and tangent; writes the material's part of `trial` ([`Self::finish_point`]
    /// completes it once `alpha` has converged).
    fn material_at(
        &self,
        point: &Point,
        alpha: &SVector<f64, ENHANCED_PARAMETERS>,
        committed: &PointState,
        trial: &mut PointState,
        material: &dyn Material,
    ) -> Result<(Voigt, Tangent)> {
        let e = point.strain + point.modes * alpha;
        if self.finite {
            let h = cholesky_excess(&(strain_to_tensor(&e) * 2.0))?;
            let resp = material.update_finite_displacement_gradient(&h, committed, trial)?;
            Ok((resp.pk2, resp.tangent))
        } else {
            let kin = Kinematics {
                strain: e,
                deformation_gradient: point.f,
            };
            let c = material.update(&kin, committed, trial)?;
            Ok((trial.stress, c))
        }
    }

    /// Solves `r_α(u, α) = 0` for the enhanced parameters by Newton's method from `alpha`
    /// (module docs) until the next step `δ` is below [`LOCAL_TOLERANCE`], leaving the
    /// last iterate in `alpha`, its stresses and tangents in `stresses` and `tangents`,
    /// its material states in `trial`, and returning `δ` (not taken). With `damped`,
    /// a step that raises `|r_α|` (or leaves the material's domain) is halved and retried,
    /// down to [`MIN_LOCAL_STEP`] of it: `-K_αα⁻¹ r_α` is a descent direction of `|r_α|²`,
    /// so some fraction of it always lowers the residual. Full steps are tried first
    /// (the caller): they are quadratic from nearby and need no extra evaluation, and
    /// from far away (an extrapolated first iterate) they can overshoot into material
    /// inversion or wander, where the halved steps still get through.
    #[allow(clippy::too_many_arguments)]
    fn solve_enhanced_parameters(
        &self,
        points: &[Point],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
        strain_scale: f64,
        damped: bool,
        (max_steps, tolerance): (usize, f64),
        alpha: &mut Modes,
        stresses: &mut [Voigt],
        tangents: &mut [Tangent],
        tally: &mut Tally,
    ) -> Result<(Modes, LocalSolve)> {
        let ne = self.modes();
        // The last Newton step taken: the parameters it started from, the step, the
        // residual norm there and the fraction of the step taken.
        let mut last: Option<(Modes, Modes, f64, f64)> = None;
        let mut newton_steps = 0;
        loop {
            let mut r_a = Modes::zeros();
            let mut k_aa = SMatrix::<f64, ENHANCED_PARAMETERS, ENHANCED_PARAMETERS>::zeros();
            let mut failed = None;
            tally.updates += 1;
            for (p, point) in points.iter().enumerate() {
                match self.material_at(point, alpha, &committed[p], &mut trial[p], material) {
                    Ok((s, c)) => {
                        r_a.gemv_tr(point.dv, &point.modes, &s, 1.0);
                        let cm = c * point.modes;
                        k_aa.gemm_tr(point.dv, &point.modes, &cm, 1.0);
                        stresses[p] = s;
                        tangents[p] = c;
                    }
                    Err(e) => {
                        failed = Some(prefix(e, &format!("integration point {p}")));
                        break;
                    }
                }
            }
            let norm = r_a.norm();
            // Damped: a step that raised the residual (or left the material's domain) is
            // halved and retried.
            if let Some((from, step, norm_before, fraction)) = last.filter(|_| damped) {
                let scale = strain_scale.max(from.amax());
                let raised = failed.is_some() || !(norm <= norm_before);
                if raised && fraction > MIN_LOCAL_STEP && fraction * step.amax() > 1e-9 * scale {
                    let fraction = 0.5 * fraction;
                    *alpha = from - step * fraction;
                    last = Some((from, step, norm_before, fraction));
                    continue;
                }
            }
            if let Some(e) = failed {
                tally.first_step.get_or_insert(f64::INFINITY);
                return Err(e);
            }
            let step = solve_enhanced(k_aa, ne, &r_a)?;
            let size = step.amax();
            let scale = strain_scale.max(alpha.amax()).max(STRAIN_ROUND_OFF);
            tally.first_step.get_or_insert(size / scale);
            if size <= tolerance * scale {
                let solve = if size <= LOCAL_TOLERANCE * scale {
                    LocalSolve::Exact
                } else {
                    LocalSolve::Approximate
                };
                return Ok((step, solve));
            }
            if newton_steps >= max_steps || !size.is_finite() {
                return Err(Error::no_convergence(
                    crate::error::Failure::Local,
                    format!(
                        "enhanced-strain parameters not converged after {newton_steps} local \
                     iterations (last step {size:e})"
                    ),
                ));
            }
            last = Some((*alpha, step, norm, 1.0));
            newton_steps += 1;
            *alpha -= step;
        }
    }

    /// The output part of a converged point's `trial`: the stress `s` (finite strain: its
    /// Cauchy stress, [`cauchy_stress`]), `F` and the enhanced parameters.
    fn finish_point(
        &self,
        point: &Point,
        s: &Voigt,
        alpha: &SVector<f64, ENHANCED_PARAMETERS>,
        trial: &mut PointState,
    ) -> Result<()> {
        if self.finite {
            let e = point.strain + point.modes * alpha;
            trial.stress = cauchy_stress(&point.f, &e, s)?;
        } else {
            trial.stress = *s;
        }
        trial.deformation_gradient = point.f;
        trial.enhanced = (*alpha).into();
        Ok(())
    }

    /// Adds the geometric stiffness `Σ_c S^c ∂²E_c/∂u²` of every point to `k`: the
    /// covariant stresses are gathered per tying location and thickness level as
    /// `A_loc` (3 x 3), then `g_ab += ∂N_aᵀ A_loc ∂N_b` once per location.
    fn add_geometric(
        &self,
        points: &[Point],
        levels: &[LevelDerivatives],
        stresses: &[Voigt],
        k: &mut SMatrix<f64, DOFS, DOFS>,
    ) {
        let mut gathered = vec![[Mat3::zeros(); LOCATIONS]; levels.len()];
        for (point, s) in points.iter().zip(stresses) {
            let s_cov = point.t.transpose() * s * point.dv;
            let a = &mut gathered[point.level];
            for (c, &(al, be)) in COMPONENTS.iter().enumerate() {
                let half = if al == be { 0.5 } else { 1.0 };
                let (list, count) = samples(point.q, c);
                for &(l, phi) in &list[..count] {
                    let coef = s_cov[c] * phi * half;
                    a[l][(al, be)] += coef;
                    a[l][(be, al)] += coef;
                }
            }
        }
        let mut g = [[0.0; NODES]; NODES];
        for (a_level, dn) in gathered.iter().zip(levels) {
            for (a_loc, dn) in a_level.iter().zip(dn) {
                if a_loc.iter().all(|v| *v == 0.0) {
                    continue;
                }
                let adn: [Vec3; NODES] = std::array::from_fn(|b| a_loc * dn[b]);
                for a in 0..NODES {
                    for b in 0..NODES {
                        g[a][b] += dn[a].dot(&adn[b]);
                    }
                }
            }
        }
        for a in 0..NODES {
            for b in 0..NODES {
                for d in 0..3 {
                    k[(3 * a + d, 3 * b + d)] += g[a][b];
                }
            }
        }
    }

    pub(super) fn check(&self, committed: &[PointState], trial: &[PointState]) -> Result<()> {
        check_thickness_points(self.thickness_points)?;
        let np = self.point_count();
        for (what, len) in [("committed", committed.len()), ("trial", trial.len())] {
            if len != np {
                return Err(Error::input(
                    &format!("length of {what}"),
                    len,
                    &format!("must be {np} for this solid-shell"),
                ));
            }
        }
        Ok(())
    }
}

impl Element<DOFS> for SolidShell {
    fn node_count(&self) -> usize {
        NODES
    }

    fn point_count(&self) -> usize {
        4 * self.thickness_points
    }

    fn evaluate(
        &self,
        ref_coords: &[Vec3],
        u: &[Vec3],
        committed: &[PointState],
        trial: &mut [PointState],
        material: &dyn Material,
    ) -> Result<ElementResponse<DOFS>> {
        response_through_into(self, ref_coords, u, committed, trial, material)
    }

    /// The enhanced parameters start from those `trial` carries when they are finite (else
    /// the committed ones, which an unseeded `trial`, a copy of `committed`, carries), and
    /// are solved to [`LOCAL_TOLERANCE`]: the result is the same function of
    /// `(u, committed)` whatever the start, to round-off.
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
        // Without a memory there is no prediction: always exact.
        let mut memory = [f64::NAN; MEMORY];
        self.evaluate_remembering(
            ref_coords,
            u,
            committed,
            trial,
            material,
            &mut memory,
            force,
            stiffness,
        )
        .map(|_| ())
    }

    fn memory_len(&self) -> usize {
        MEMORY
    }

    /// Remembers, with the stiffness, the enhanced parameters, the displacements and
    /// `P = K_αα⁻¹ K_αu`; the next call starts its local iteration from the linearised
    /// `α - P (u' - u)` (module docs, "Local solve"), and from the remembered `α` where
    /// that fails.
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
        super::hex8::check_len("force", force.len(), DOFS)?;
        if let Some(k) = &stiffness {
            super::hex8::check_len("stiffness", k.len(), DOFS * DOFS)?;
        }
        super::hex8::check_len("memory", memory.len(), MEMORY)?;
        self.check(committed, trial)?;
        let x = nodes_array("ref_coords", ref_coords)?;
        let u = nodes_array("u", u)?;
        let (points, levels) = self.points(&x, &u)?;
        let ne = self.modes();
        let u_flat = SVector::<f64, DOFS>::from_fn(|i, _| u[i / 3][i % 3]);
        let remembered = memory[0] == 1.0;
        let mut unpredicted = Modes::zeros();
        if remembered {
            unpredicted.copy_from_slice(&memory[MEMORY_ALPHA]);
        } else {
            let start = if trial[0].enhanced.iter().all(|a| a.is_finite()) {
                trial[0].enhanced
            } else {
                committed[0].enhanced
            };
            unpredicted.as_mut_slice()[..ne].copy_from_slice(&start[..ne]);
        }
        let predicted = remembered.then(|| {
            let u_then = SVector::<f64, DOFS>::from_column_slice(&memory[MEMORY_U]);
            let p = SMatrix::<f64, ENHANCED_PARAMETERS, DOFS>::from_column_slice(&memory[MEMORY_P]);
            unpredicted - p * (u_flat - u_then)
        });
        let strain_scale = points.iter().map(|p| p.strain.amax()).fold(0.0, f64::max);
        let np = points.len();
        let mut stresses = [Voigt::zeros(); 4 * MAX_THICKNESS_POINTS];
        let mut tangents = [Tangent::zeros(); 4 * MAX_THICKNESS_POINTS];
        let mut tally = Tally::default();
        let mut local = |damped: bool, limits: (usize, f64), alpha: &mut Modes| {
            self.solve_enhanced_parameters(
                &points,
                committed,
                trial,
                material,
                strain_scale,
                damped,
                limits,
                alpha,
                &mut stresses,
                &mut tangents,
                &mut tally,
            )
        };
        // Full steps from the prediction, then from the remembered (or given) start, then
        // halved ones from there (doc of `solve_enhanced_parameters`).
        let mut alpha = predicted.unwrap_or(unpredicted);
        let predicted_limits = (PREDICTED_LOCAL_ITERATIONS, PREDICTED_LOCAL_TOLERANCE);
        let from_prediction =
            predicted.and_then(|_| local(false, predicted_limits, &mut alpha).ok());
        let limits = (MAX_LOCAL_ITERATIONS, LOCAL_TOLERANCE);
        let with_stiffness = stiffness.is_some();
        let (outcome, kind) = match from_prediction {
            Some(done) => (Ok(done), CallKind::Predicted),
            None => {
                let restart = if predicted.is_some() {
                    CallKind::Restarted
                } else {
                    CallKind::Cold
                };
                alpha = unpredicted;
                match local(false, limits, &mut alpha) {
                    Ok(done) => (Ok(done), restart),
                    Err(full_steps) => {
                        alpha = unpredicted;
                        let halved = local(true, limits, &mut alpha).map_err(|_| full_steps);
                        (halved, CallKind::Halved)
                    }
                }
            }
        };
        let kind = if outcome.is_ok() {
            kind
        } else {
            CallKind::Failed
        };
        let first_step = predicted.and(tally.first_step);
        counts::record(kind, with_stiffness, tally.updates, first_step);
        let (delta, solve) = outcome?;
        // The last step to first order: `α - δ`, `S - ℂ M δ` (LOCAL_TOLERANCE).
        for ((point, s), c) in points.iter().zip(&mut stresses).zip(&tangents) {
            *s -= c * (point.modes * delta);
        }
        alpha -= delta;
        let force: &mut [f64; DOFS] = force.try_into().expect("length checked");
        let mut f = SVector::<f64, DOFS>::zeros();
        for ((point, s), state) in points.iter().zip(&stresses).zip(trial.iter_mut()) {
            f.gemv_tr(point.dv, &point.b, s, 1.0);
            self.finish_point(point, s, &alpha, state)?;
        }
        force.copy_from_slice(f.as_slice());
        let Some(k_out) = stiffness else {
            return Ok(solve);
        };
        let blocks = TangentBlocks::sum(&points, &tangents[..np]);
        let mut k = SMatrix::<f64, DOFS, DOFS>::from_fn(|i, j| blocks.entry(i, j));
        let k_ua =
            SMatrix::<f64, DOFS, ENHANCED_PARAMETERS>::from_fn(|i, j| blocks.entry(i, DOFS + j));
        let k_au =
            SMatrix::<f64, ENHANCED_PARAMETERS, DOFS>::from_fn(|i, j| blocks.entry(DOFS + i, j));
        let k_aa = SMatrix::<f64, ENHANCED_PARAMETERS, ENHANCED_PARAMETERS>::from_fn(|i, j| {
            blocks.entry(DOFS + i, DOFS + j)
        });
        if self.finite {
            self.add_geometric(&points, &levels, &stresses[..np], &mut k);
        }
        let correction = solve_enhanced(k_aa, ne, &k_au)?;
        k.gemm(-1.0, &k_ua, &correction, 1.0);
        k_out.copy_from_slice(k.as_slice());
        memory[0] = 1.0;
        memory[MEMORY_ALPHA].copy_from_slice(alpha.as_slice());
        memory[MEMORY_U].copy_from_slice(u_flat.as_slice());
        memory[MEMORY_P].copy_from_slice(correction.as_slice());
        Ok(solve)
    }

    fn point_volumes(&self, ref_coords: &[Vec3]) -> Result<Vec<f64>> {
        let x = nodes_array("ref_coords", ref_coords)?;
        let (zeta, wz) = cached_rule(self.thickness_points);
        let mut out = Vec::with_capacity(self.point_count());
        for (k, z) in zeta.iter().enumerate() {
            for q in 0..4 {
                let (xi, eta) = in_plane(q);
                let det = jacobian(&x, &Vec3::new(xi, eta, *z)).determinant();
                if !(det > 0.0 && det.is_finite()) {
                    return Err(Error::input(
                        &format!("Jacobian determinant at integration point {}", 4 * k + q),
                        det,
                        "must be > 0 (inverted or degenerate element)",
                    ));
                }
                out.push(wz[k] * det);
            }
        }
        Ok(out)
    }

    /// Under finite strain, `∫ ψ(T) dV₀` with the log-space stress (Hencky energy).
    fn strain_energy(
        &self,
        ref_coords: &[Vec3],
        states: &[PointState],
        material: &dyn Material,
    ) -> Result<f64> {
        let finite = self.finite;
        self.integrate(ref_coords, states, &|s| {
            if finite {
                material.elastic_energy_density(&PointState {
                    stress: s.log_stress,
                    ..*s
                })
            } else {
                material.elastic_energy_density(s)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tangent blocks equal the four products `Σ dv Xᵀ ℂ Y` (X, Y each B or M) formed
    /// one by one: to round-off with symmetric tangents (upper triangle mirrored), and with
    /// a non-symmetric one among them (the full product, `K_αu ≠ K_uαᵀ`).
    #[test]
    fn tangent_blocks_equal_the_four_products() {
        // Values in [-1, 1] without a pattern the products could hide.
        let mut k = 0.0_f64;
        let mut next = || {
            k += 1.0;
            (k * 12.9898).sin()
        };
        let points: Vec<Point> = (0..7)
            .map(|i| Point {
                strain: Voigt::zeros(),
                b: SMatrix::from_fn(|_, _| next()),
                t: Tangent::identity(),
                modes: Tangent::from_fn(|_, _| next()),
                dv: 0.5 + 0.1 * i as f64,
                f: Mat3::identity(),
                level: 0,
                q: 0,
            })
            .collect();
        let symmetric: Vec<Tangent> = (0..7)
            .map(|_| {
                let a = Tangent::from_fn(|_, _| next());
                a * a.transpose() + Tangent::identity()
            })
            .collect();
        let mut skew = symmetric.clone();
        skew[4][(0, 3)] += 0.5;
        for (tangents, mirrored) in [(&symmetric, true), (&skew, false)] {
            let blocks = TangentBlocks::sum(&points, tangents);
            let mut k = SMatrix::<f64, DOFS, DOFS>::zeros();
            let mut k_ua = SMatrix::<f64, DOFS, ENHANCED_PARAMETERS>::zeros();
            let mut k_au = SMatrix::<f64, ENHANCED_PARAMETERS, DOFS>::zeros();
            let mut k_aa = Tangent::zeros();
            for (p, c) in points.iter().zip(tangents) {
                k += p.b.transpose() * c * p.b * p.dv;
                k_ua += p.b.transpose() * c * p.modes * p.dv;
                k_au += p.modes.transpose() * c * p.b * p.dv;
                k_aa += p.modes.transpose() * c * p.modes * p.dv;
            }
            let scale = k.amax();
            let mut worst: f64 = 0.0;
            for i in 0..WIDE {
                for j in 0..WIDE {
                    let expected = match (i < DOFS, j < DOFS) {
                        (true, true) => k[(i, j)],
                        (true, false) => k_ua[(i, j - DOFS)],
                        (false, true) => k_au[(i - DOFS, j)],
                        (false, false) => k_aa[(i - DOFS, j - DOFS)],
                    };
                    worst = worst.max((blocks.entry(i, j) - expected).abs() / scale);
                }
            }
            assert!(worst < 1e-14, "mirrored {mirrored}: {worst:e}");
            let asymmetry = (0..DOFS)
                .flat_map(|i| (0..ENHANCED_PARAMETERS).map(move |j| (i, j)))
                .map(|(i, j)| (blocks.entry(i, DOFS + j) - blocks.entry(DOFS + j, i)).abs())
                .fold(0.0, f64::max);
            assert_eq!(asymmetry == 0.0, mirrored, "{asymmetry:e}");
        }
    }

    /// The rules integrate what they must: Gauss-Legendre exactly up to degree 2n - 1, the
    /// odd Newton-Cotes rules (n >= 5) cubics in `|z|` on each half exactly (`|z|`, the
    /// fully plastic moment, is the point of using them), all `z²`, weights sum to 2.
    #[test]
    fn thickness_rules() {
        for n in 1..=MAX_THICKNESS_POINTS {
            let (x, w) = gauss_legendre(n);
            for d in 0..2 * n {
                let exact = if d % 2 == 0 {
                    2.0 / (d as f64 + 1.0)
                } else {
                    0.0
                };
                let sum: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(d as i32)).sum();
                assert!((sum - exact).abs() < 1e-13, "Gauss {n}, degree {d}: {sum}");
            }
            assert!(x.windows(2).all(|p| p[0] < p[1]));
            let (x, w) = thickness_rule(n);
            let sum =
                |f: &dyn Fn(f64) -> f64| -> f64 { x.iter().zip(&w).map(|(x, w)| w * f(*x)).sum() };
            assert!((sum(&|_| 1.0) - 2.0).abs() < 1e-14);
            if n >= 2 {
                assert!((sum(&|z| z * z) - 2.0 / 3.0).abs() < 1e-14, "{n}");
            }
            if n >= 5 && n % 2 == 1 {
                assert!((sum(&|z| z.abs()) - 1.0).abs() < 1e-14, "{n}");
                let cubic = |z: f64| z.abs().powi(3) - 2.0 * z * z + z.abs();
                assert!((sum(&cubic) - (0.5 - 4.0 / 3.0 + 1.0)).abs() < 1e-13, "{n}");
                assert_eq!((x[0], x[n / 2], x[n - 1]), (-1.0, 0.0, 1.0));
            }
        }
        assert!(check_thickness_points(0).is_err() && check_thickness_points(13).is_err());
    }
}
