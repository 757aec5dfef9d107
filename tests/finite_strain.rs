//! Finite-strain elastoplasticity (issue 5): Lagrangian log-strain Hill48/Swift material on
//! total-Lagrangian F-bar hexahedra. Uniaxial tension to 50% log strain against the exact
//! Swift curve, Lankford coefficients at 0/45/90 degrees, objectivity under a 90-degree
//! rigid rotation, Newton's rate on a plastic strip bent by a cylinder, and locking.

mod common;

use std::sync::Arc;

use tribo::element::{Element, Hex8FBar, StrainTheory};
use tribo::geometry::{Cylinder, Mat3, Vec3};
use tribo::material::{
    stress_to_tensor, ElastoPlastic, Hardening, Hill48, LinearElastic, Material, PointState,
};
use tribo::mesh::{Mesh, HEX_CORNERS};
use tribo::solver::{Model, Simulation};
use tribo::tool::ScalarSchedule;

const YOUNG: f64 = 70e3;
const POISSON: f64 = 0.33;
const SWIFT: (f64, f64, f64) = (500.0, 0.01, 0.22);
const LANKFORD: (f64, f64, f64) = (0.7, 1.3, 2.1);

fn hill_swift(angle: f64) -> ElastoPlastic {
    ElastoPlastic::new(
        LinearElastic::new(YOUNG, POISSON).unwrap(),
        Hill48::from_lankford(LANKFORD.0, LANKFORD.1, LANKFORD.2)
            .unwrap()
            .with_rolling_angle(angle)
            .unwrap(),
        Hardening::swift(SWIFT.0, SWIFT.1, SWIFT.2).unwrap(),
    )
}

fn swift(ep: f64) -> f64 {
    SWIFT.0 * (SWIFT.1 + ep).powf(SWIFT.2)
}

/// The exact uniaxial response of the model at total log strain `eps` along the rolling
/// direction: the log-space (Kirchhoff) stress solves `τ = C (ε0 + ε - τ/E)^n` (Hill48 is
/// normalised so that `φ = τ` along RD, the elastic log strain along x is `τ/E`), and the
/// Cauchy stress is `τ / J` with `J = exp(tr Ee) = exp((1 - 2ν) τ / E)` (the plastic flow
/// is isochoric). Returns (Cauchy stress, equivalent plastic strain).
fn exact_uniaxial(eps: f64) -> (f64, f64) {
    let mut tau = swift((eps - swift(0.0) / YOUNG).max(0.0));
    for _ in 0..100 {
        let ep = eps - tau / YOUNG;
        let g = tau - swift(ep);
        let dg = 1.0 + SWIFT.0 * SWIFT.2 * (SWIFT.1 + ep).powf(SWIFT.2 - 1.0) / YOUNG;
        tau -= g / dg;
    }
    let ep = eps - tau / YOUNG;
    (tau * (-(1.0 - 2.0 * POISSON) * tau / YOUNG).exp(), ep)
}

/// A unit cube of the Hill48 steel (rolling direction x) on the symmetry planes x-, y-,
/// z-, the face `face` moved along `component` linearly from 0 at t = 0 to `travel` at t = 1.
fn pulled_cube(face: &str, component: &str, travel: f64) -> Model {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
    let mut model = Model::new(mesh, Arc::new(hill_swift(0.0))).unwrap();
    model
        .prescribe(
            face,
            component,
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, travel)]).unwrap(),
        )
        .unwrap();
    for (set, c) in [("x-", "x"), ("y-", "y"), ("z-", "z")] {
        model
            .prescribe(set, c, ScalarSchedule::constant(0.0))
            .unwrap();
    }
    model
}

/// One unit cube, symmetry planes x-, y-, z-, the x+ face pulled to the stretch
/// `exp(0.5)` in 100 increments with its lateral faces free (finite kinematics, F-bar).
/// The Cauchy stress of every integration point against the exact curve, at every
/// increment past yield: within 1e-6 relative (the return mapping is exact for this
/// proportional path; what remains is the Newton tolerance 1e-10 and round-off).
/// Also the energy balance: support work = Hencky energy + plastic dissipation.
#[test]
fn uniaxial_tension_to_50_percent_follows_the_swift_curve() {
    let mut model = pulled_cube("x+", "x", 0.5f64.exp() - 1.0);
    model.settings.kinematics = StrainTheory::Finite;
    model.settings.increments = 100;
    model.settings.force_rel_tol = 1e-10;
    let mut sim = Simulation::new(model).unwrap();
    let mut worst: f64 = 0.0;
    let mut worst_ep: f64 = 0.0;
    let mut plastic_steps = 0;
    while !sim.is_finished() {
        let report = sim.step().unwrap();
        let eps = (1.0 + sim.displacement(7).x).ln();
        let (sigma, ep) = exact_uniaxial(eps);
        if ep <= 0.0 {
            continue;
        }
        plastic_steps += 1;
        for p in sim.points() {
            worst = worst.max((p.stress[0] - sigma).abs() / sigma);
            worst_ep = worst_ep.max((p.eq_plastic_strain - ep).abs() / ep);
            // Uniaxial: every other Cauchy component vanishes.
            assert!(p.stress.rows(1, 5).amax() < 1e-8 * sigma);
        }
        let _ = report;
    }
    // The balance closes to the trapezoidal rule's accuracy (exact for the elastic part;
    // the yield kink inside the first plastic increment costs most of it).
    assert!(sim.energy().relative_error.abs() < 1e-4);
    let eps = (1.0 + sim.displacement(7).x).ln();
    assert!((eps - 0.5).abs() < 1e-12);
    let e = sim.energy();
    println!(
        "Swift curve to 50%: worst relative stress error {worst:e}, eq. plastic strain {worst_ep:e}; \
         support work {:.6}, elastic {:.6}, plastic {:.6}, balance {:e}",
        e.support_work, e.elastic_energy, e.plastic_dissipation, e.relative_error
    );
    assert!(plastic_steps > 90);
    assert!(worst < 1e-6, "stress error {worst:e}");
    assert!(worst_ep < 1e-6, "plastic strain error {worst_ep:e}");
    // The plastic work of a proportional path is ∫ τ dεp along the Swift curve.
    assert!(e.plastic_dissipation > 0.9 * e.support_work);

    // Output: the thickness (z) of the sheet columns and its log strain, and the
    // equivalent plastic strain, as VTK fields.
    let frame = tribo::output::frame(&sim, tribo::output::Configuration::Current);
    let field = |name: &str, cells: bool| {
        let list = if cells {
            &frame.cell_data
        } else {
            &frame.point_data
        };
        list.iter()
            .find(|f| f.name == name)
            .unwrap_or_else(|| panic!("field {name}"))
            .values
            .clone()
    };
    let uz = sim.displacement(7).z;
    for (t, et) in field("thickness", false)
        .iter()
        .zip(field("thickness_strain", false))
    {
        assert!((t - (1.0 + uz)).abs() < 1e-14 && (et - (1.0 + uz).ln()).abs() < 1e-14);
    }
    assert!(uz < -0.1, "the sheet thins");
    let ep = exact_uniaxial(0.5).1;
    assert!((field("equivalent_plastic_strain", true)[0] - ep).abs() < 1e-9 * ep);
}

/// Uniaxial Cauchy stress along x at a material point driven by a symmetric stretch `U`
/// (no rotation): `U_xx = exp(ε)` prescribed, the other five Cauchy components zero,
/// solved by Newton with a finite-difference Jacobian (the driver only; the material uses
/// its own tangent nowhere here). Returns the committed state after each of `steps`
/// increments to `eps_max`.
fn uniaxial_point(m: &dyn Material, eps_max: f64, steps: usize) -> Vec<PointState> {
    let sym =
        |y: &[f64; 5], uxx: f64| Mat3::new(uxx, y[2], y[4], y[2], y[0], y[3], y[4], y[3], y[1]);
    let rows = |s: &tribo::material::Voigt| [s[1], s[2], s[3], s[4], s[5]];
    let mut committed = m.initial_state();
    let mut y = [1.0, 1.0, 0.0, 0.0, 0.0];
    let mut out = Vec::new();
    for k in 1..=steps {
        let uxx = (eps_max * k as f64 / steps as f64).exp();
        let eval = |y: &[f64; 5]| {
            let mut t = committed;
            m.update_finite(&sym(y, uxx), &committed, &mut t).unwrap();
            (rows(&t.stress), t)
        };
        let mut converged = None;
        for _ in 0..30 {
            let (r, t) = eval(&y);
            if r.iter().all(|v| v.abs() < 1e-9) {
                converged = Some(t);
                break;
            }
            let mut jac = nalgebra::SMatrix::<f64, 5, 5>::zeros();
            for j in 0..5 {
                let h = 1e-7;
                let (mut yp, mut ym) = (y, y);
                yp[j] += h;
                ym[j] -= h;
                let (rp, rm) = (eval(&yp).0, eval(&ym).0);
                for i in 0..5 {
                    jac[(i, j)] = (rp[i] - rm[i]) / (2.0 * h);
                }
            }
            let dy = jac
                .lu()
                .solve(&nalgebra::SVector::<f64, 5>::from(r))
                .unwrap();
            for j in 0..5 {
                y[j] -= dy[j];
            }
        }
        committed = converged.expect("uniaxial driver converged");
        out.push(committed);
    }
    out
}

/// Tension along x of a sheet whose rolling direction is at 0, 45 and 90 degrees to x, to
/// 20% log strain: the width/thickness plastic log-strain ratio `r = εp_yy / εp_zz` gives
/// back r0, r45, r90 within 1% (Hill48 predicts a constant r along a proportional path;
/// at finite strain the small shear of the 45-degree test tilts the axes slightly).
#[test]
fn tension_tests_give_back_the_lankford_coefficients() {
    let expected = [LANKFORD.0, LANKFORD.1, LANKFORD.2];
    for (deg, r_in) in [0.0f64, 45.0, 90.0].iter().zip(expected) {
        let m = hill_swift(deg.to_radians());
        let states = uniaxial_point(&m, 0.2, 40);
        let last = states.last().unwrap();
        let r = last.plastic_strain[1] / last.plastic_strain[2];
        println!(
            "RD at {deg} deg: r = {r:.6} (input {r_in}), error {:.2e}, eq. plastic strain {:.4}",
            (r - r_in).abs() / r_in,
            last.eq_plastic_strain
        );
        assert!(last.eq_plastic_strain > 0.15);
        assert!((r - r_in).abs() < 0.01 * r_in, "r at {deg} deg = {r}");
    }
}

/// Invariants `(I1, J2, det)` of a Cauchy stress.
fn invariants(s: &tribo::material::Voigt) -> [f64; 3] {
    let t = stress_to_tensor(s);
    let i1 = t.trace();
    let dev = t - Mat3::identity() * (i1 / 3.0);
    [i1, 0.5 * dev.component_mul(&dev).sum(), t.determinant()]
}

/// A distorted element is deformed non-uniformly into the plastic range (Hill48 with the
/// rolling direction at 30 degrees) in 5 increments, then turned rigidly by 90 degrees
/// about a skew axis in 10 increments: each point's Cauchy stress is rotated with the
/// body, `σ = R σ₀ Rᵀ` (so its invariants are unchanged), and the equivalent plastic
/// strain stays the same, to 1e-8 relative. The log-strain formulation is objective by
/// construction (E depends on C only); the tolerance allows round-off in the eigen-solver.
#[test]
fn rigid_rotation_of_a_plastic_element_is_objective() {
    let x: [Vec3; 8] = std::array::from_fn(|a| {
        let c = HEX_CORNERS[a];
        Vec3::new(c[0], c[1], c[2]) * 0.5
            + Vec3::new(0.07 * c[1] * c[2], -0.05 * c[0], 0.04 * c[0] * c[1])
    });
    let m = hill_swift(30f64.to_radians());
    let el = Hex8FBar::default();
    let f1 = Mat3::new(1.15, 0.05, 0.0, 0.02, 0.92, 0.03, 0.0, -0.04, 0.95);
    let pre: [Vec3; 8] = std::array::from_fn(|a| {
        let p = x[a];
        f1 * p - p + Vec3::new(0.01 * p.y * p.z, 0.02 * p.x * p.x, -0.015 * p.x * p.y)
    });
    let mut committed = [PointState::default(); 8];
    let mut trial = committed;
    for k in 1..=5 {
        let u = pre.map(|v| v * (k as f64 / 5.0));
        el.evaluate(&x, &u, &committed, &mut trial, &m).unwrap();
        committed = trial;
    }
    let before = committed;
    assert!(before.iter().all(|p| p.eq_plastic_strain > 0.01));
    let axis = nalgebra::Unit::new_normalize(Vec3::new(1.0, 2.0, -0.5));
    for k in 1..=10 {
        let r = nalgebra::Rotation3::from_axis_angle(
            &axis,
            std::f64::consts::FRAC_PI_2 * k as f64 / 10.0,
        )
        .into_inner();
        let u: [Vec3; 8] = std::array::from_fn(|a| r * (x[a] + pre[a]) - x[a]);
        el.evaluate(&x, &u, &committed, &mut trial, &m).unwrap();
        committed = trial;
        for (p, p0) in committed.iter().zip(&before) {
            let rotated = r * stress_to_tensor(&p0.stress) * r.transpose();
            let scale = p0.stress.amax();
            assert!((stress_to_tensor(&p.stress) - rotated).amax() < 1e-8 * scale);
            for (a, b) in invariants(&p.stress).iter().zip(invariants(&p0.stress)) {
                assert!((a - b).abs() <= 1e-8 * b.abs().max(scale.powi(3) * 1e-6));
            }
            assert!(
                (p.eq_plastic_strain - p0.eq_plastic_strain).abs() < 1e-8 * p0.eq_plastic_strain
            );
        }
    }
}

/// A plastic strip (half model: symmetry plane x = 0, plane strain, 10 mm half-length,
/// 1 mm thick, 20 x 3 cells) rests on a rigid cylinder (radius 5, axis along y under
/// x = 0, frictionless) and is bent over it by pulling its end x = 10 down by 3 mm in 40
/// increments, under finite kinematics: a plastic hinge forms over the cylinder and the
/// arm turns by about 0.3 rad.
///
/// Observed orders are taken over consecutive relative residuals inside (1e-10, 1e-2]:
/// below 1e-10 round-off (~1e-12 here) dominates, and above 1e-2 Newton is not yet in its
/// asymptotic range (the first iterate of an elastoplastic increment starts from the
/// elastic predictor, relative residual ~0.3, and points at the plastic front switch
/// between elastic and plastic in the first iterations), where a three-point estimate
/// mixes the two regimes. In that window the last observed order of every increment must
/// be at least 1.6 and their median at least 1.9, and where Newton's local model holds (|R| <= 1e-4) every
/// step must be quadratic with a bounded constant, `r⁺ <= 20 r²` (a linearly converging
/// Newton, `r⁺ = c r`, breaks any such bound as `r -> 0`: at r = 1e-8 it needs c < 2e-7).
/// Between 1e-4 and 1e-2 a step may still cross a point's yield or unloading switch and
/// contract only linearly (with the scalar return map: increments 35-36, 3.9e-4 -> 1.9e-5,
/// constant 125-281), which says nothing of the tangent. Measured with the scalar return map
/// (issue 13): largest constant below 1e-4 2.4, worst order 1.94, median 3.39 over 21
/// increments. Earlier measurement, with the 7 x 7 return map: worst 1.65 (increment 30,
/// residuals 4.4e-3, 3.6e-5, 1.3e-8 with
/// constants 1.9 and 10, contact statuses and the set of plastic points unchanged over these
/// iterations: a quadratic step whose constant grows while the plastic zone settles; the
/// three-point estimate reads such a step as a lower order). The worst order depends on
/// round-off through the path: before the strain was formed from `C - I` (issue 14) it was
/// 1.94 at another increment, and 1.78 before the line search.
#[test]
fn newton_is_quadratic_on_a_plastic_strip_bent_over_a_cylinder() {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(10.0, 1.0, 1.0), [20, 1, 3]).unwrap();
    let m = ElastoPlastic::new(
        LinearElastic::new(YOUNG, POISSON).unwrap(),
        Hill48::von_mises(),
        Hardening::swift(SWIFT.0, SWIFT.1, SWIFT.2).unwrap(),
    );
    let mut model = Model::new(mesh, Arc::new(m)).unwrap();
    let radius = 5.0;
    let cyl = Cylinder::new(Vec3::new(0.0, 0.0, -radius), Vec3::y(), radius).unwrap();
    let path = [(0.0, [0.0; 3]), (1.0, [0.0; 3])];
    model
        .add_tool(common::tool("die", cyl, &path, 0.0), "z-", None)
        .unwrap();
    model
        .prescribe("x-", "x", ScalarSchedule::constant(0.0))
        .unwrap();
    model
        .prescribe(
            "x+",
            "z",
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, -3.0)]).unwrap(),
        )
        .unwrap();
    for set in ["y-", "y+"] {
        model
            .prescribe(set, "y", ScalarSchedule::constant(0.0))
            .unwrap();
    }
    model.settings.kinematics = StrainTheory::Finite;
    model.settings.increments = 40;
    model.settings.max_iterations = 40;
    model.settings.max_cutbacks = 0;
    // From the committed state: the extrapolated start leaves too few iterations per
    // increment to read an order from.
    model.settings.extrapolate = false;
    model.settings.force_rel_tol = 1e-11;
    model.settings.contact_tol = 1e-11;
    let mut sim = Simulation::new(model).unwrap();
    sim.run(|_, _| Ok(())).unwrap();

    let mut worst = f64::INFINITY;
    let mut last_orders = Vec::new();
    let mut quadratic_constant: f64 = 0.0;
    for r in &sim.history {
        let res: Vec<f64> = r
            .residuals
            .iter()
            .map(|x| x.force_rel)
            .filter(|&x| x <= 1e-2)
            .collect();
        let orders = common::convergence_orders(&res, 1e-10);
        println!(
            "increment {:2}: {:2} iterations, orders {:.2?}, residuals {:?}",
            r.index,
            r.iterations,
            orders,
            r.residuals
                .iter()
                .map(|x| format!("{:.1e}", x.force_rel))
                .collect::<Vec<_>>()
        );
        if let Some(&last) = orders.last() {
            worst = worst.min(last);
            last_orders.push(last);
        }
        // The quadratic constant is read where Newton's local model holds (|R| <= 1e-4);
        // above it a step may cross a point's yield or unloading switch and contract only
        // linearly (increments 35-36: 3.9e-4 -> 1.9e-5), which says nothing of the tangent.
        for w in res.windows(2).filter(|w| w[0] <= 1e-4 && w[1] > 1e-10) {
            quadratic_constant = quadratic_constant.max(w[1] / (w[0] * w[0]));
        }
    }
    let measured = last_orders.len();
    last_orders.sort_by(f64::total_cmp);
    let median = last_orders.get(measured / 2).copied().unwrap_or(0.0);
    let ep = sim
        .points()
        .iter()
        .map(|p| p.eq_plastic_strain)
        .fold(0.0, f64::max);
    let end = sim.displacement(20);
    let turn = (-end.z / (10.0 + end.x)).atan();
    let e = sim.energy();
    println!(
        "{measured} increments with a measured order, worst {worst:.2}, median {median:.2}, \
         max r+/r^2 {quadratic_constant:.1}; max eq. plastic strain {ep:.4}, end displacement \
         {end:?}, arm rotation {turn:.3} rad; support work {:.4}, elastic {:.4}, plastic {:.4}, \
         balance {:e}",
        e.support_work, e.elastic_energy, e.plastic_dissipation, e.relative_error
    );
    assert!(ep > 0.05, "the strip yields");
    assert!(turn > 0.25, "large rotation");
    assert!(
        measured >= 10,
        "{measured} increments with a measured order"
    );
    assert!(
        quadratic_constant <= 20.0,
        "r+/r^2 up to {quadratic_constant}"
    );
    assert!(worst >= 1.6, "observed order {worst}");
    assert!(median >= 1.9, "median observed order {median}");
    // Support work = stored + dissipated, to the trapezoidal rule's accuracy.
    assert!(e.relative_error.abs() < 1e-3, "{}", e.relative_error);
}

/// A plane-strain cantilever 10 x 1 x 2 (y held on both faces) of `cells` cells, clamped at
/// x = 0, its tip face pulled down by `tip` over t in [0, 1].
fn cantilever(cells: [usize; 3], material: ElastoPlastic, tip: f64) -> Model {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::new(10.0, 1.0, 2.0), cells).unwrap();
    let mut model = Model::new(mesh, Arc::new(material)).unwrap();
    model
        .prescribe("x-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    for set in ["y-", "y+"] {
        model
            .prescribe(set, "y", ScalarSchedule::constant(0.0))
            .unwrap();
    }
    model
        .prescribe(
            "x+",
            "z",
            ScalarSchedule::new(vec![(0.0, 0.0), (1.0, -tip)]).unwrap(),
        )
        .unwrap();
    model
}

/// A plane-strain cantilever (length 10, depth 2, clamped at x = 0) of a nearly
/// incompressible (nu = 0.499) elastic-plastic von Mises material with weak linear
/// hardening, its tip face pulled down by 1.0 (far beyond the plastic limit load), finite
/// kinematics. Tip force of F-bar meshes 8x2, 16x4, 32x8 (cells along x and through the
/// depth) and of the fully integrated (no F-bar) 8x2 and 32x8 meshes.
///
/// Reference: Richardson extrapolation of the F-bar sequence, whose observed order
/// (log2 of the ratio of successive differences) must lie in [0.8, 1.6] (first-order
/// convergence of the plastic bending of linear elements). Measured: 34.81, 31.75, 30.35 ->
/// extrapolated 29.2; the coarse F-bar mesh is within 20% and the fine within 5% of it,
/// while the fully integrated meshes lock: 8x2 gives ~9x the reference, and refining does
/// not cure it (32x8: 247, still ~8x).
#[test]
fn fbar_does_not_lock_in_nearly_incompressible_plastic_bending() {
    let tip_force = |cells: [usize; 3], fbar: bool| {
        let m = ElastoPlastic::new(
            LinearElastic::new(YOUNG, 0.499).unwrap(),
            Hill48::von_mises(),
            Hardening::linear(200.0, 500.0).unwrap(),
        );
        let mut model = cantilever(cells, m, 1.0);
        model.settings.kinematics = StrainTheory::Finite;
        model.settings.fbar = fbar;
        model.settings.increments = 10;
        let nodes = model.nodes("x+").unwrap();
        let mut sim = Simulation::new(model).unwrap();
        sim.run(|_, _| Ok(())).unwrap();
        -sim.reaction(&nodes).unwrap().z
    };
    let coarse = tip_force([8, 1, 2], true);
    let medium = tip_force([16, 1, 4], true);
    let fine = tip_force([32, 1, 8], true);
    let locked = tip_force([8, 1, 2], false);
    let locked_fine = tip_force([32, 1, 8], false);
    let ratio = (coarse - medium) / (medium - fine);
    let order = ratio.log2();
    let reference = fine - (medium - fine) / (ratio - 1.0);
    println!(
        "tip force: F-bar 8x2 {coarse:.3}, 16x4 {medium:.3}, 32x8 {fine:.3} (order {order:.2}, \
         extrapolated {reference:.3}); fully integrated 8x2 {locked:.3}, 32x8 {locked_fine:.3}"
    );
    assert!((0.8..=1.6).contains(&order), "observed order {order}");
    assert!((coarse - reference).abs() < 0.2 * reference);
    assert!((fine - reference).abs() < 0.05 * reference);
    assert!(locked > 5.0 * reference, "8x2 without F-bar: {locked}");
    assert!(
        locked_fine > 5.0 * reference,
        "32x8 without F-bar: {locked_fine}"
    );
}

/// Energy balance with plastic dissipation under small strain: with the trapezoidal rule
/// for both the support work and the plastic dissipation, `½(σn + σn+1)·Δε` splits
/// exactly into the elastic energy change and `½(σn + σn+1)·Δεp`, so the balance closes
/// to the Newton tolerance on a plastic cantilever (B-bar, von Mises, Swift), although
/// most of the work is dissipated.
#[test]
fn small_strain_energy_balance_includes_plastic_dissipation() {
    let m = ElastoPlastic::new(
        LinearElastic::new(YOUNG, POISSON).unwrap(),
        Hill48::von_mises(),
        Hardening::swift(SWIFT.0, SWIFT.1, SWIFT.2).unwrap(),
    );
    let mut model = cantilever([8, 1, 2], m, 0.5);
    model.settings.increments = 10;
    model.settings.force_rel_tol = 1e-12;
    let mut sim = Simulation::new(model).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    let e = sim.energy();
    println!(
        "support work {:.6}, elastic {:.6}, plastic {:.6}, balance {:e}",
        e.support_work, e.elastic_energy, e.plastic_dissipation, e.relative_error
    );
    assert!(e.plastic_dissipation > e.elastic_energy, "mostly plastic");
    assert!(e.relative_error.abs() < 1e-9, "{}", e.relative_error);
}

/// The `equivalent_stress` cell field is the yield function's own equivalent stress
/// (Hill48's `φ` of the stress the material works in), which plastic points keep equal to
/// the yield stress: a unit cube of the Hill48 steel (r0, r45, r90 = 0.7, 1.3, 2.1) pulled
/// 10 % across the rolling direction, under finite and small strain. At every plastic
/// increment the field equals the Swift yield stress at the element's equivalent plastic
/// strain to 1e-8 (homogeneous: every point the same; the return mapping's tolerance),
/// while the von Mises stress, the uniaxial stress across the rolling direction, is
/// `1 / sqrt(F + H) = 1.28` times as large (Hill48 normalised along the rolling
/// direction, `G + H = 1`, `H = r0 / (1 + r0)`, `F = H / r90`; finite strain: divided by
/// `J`, within 0.5 %).
#[test]
fn equivalent_stress_field_is_the_yield_functions() {
    let (r0, r90) = (LANKFORD.0, LANKFORD.2);
    let h = r0 / (1.0 + r0);
    let across = 1.0 / (h / r90 + h).sqrt();
    for kinematics in [StrainTheory::Finite, StrainTheory::Small] {
        let mut model = pulled_cube("y+", "y", 0.1);
        model.settings.kinematics = kinematics;
        model.settings.increments = 20;
        model.settings.force_rel_tol = 1e-10;
        let mut sim = Simulation::new(model).unwrap();
        let mut plastic = 0;
        while !sim.is_finished() {
            sim.step().unwrap();
            let frame = tribo::output::frame(&sim, tribo::output::Configuration::Current);
            let cell = |name: &str| {
                frame
                    .cell_data
                    .iter()
                    .find(|f| f.name == name)
                    .unwrap_or_else(|| panic!("field {name}"))
                    .values[0]
            };
            let ep = cell("equivalent_plastic_strain");
            if ep <= 0.0 {
                continue;
            }
            plastic += 1;
            let equivalent = cell("equivalent_stress");
            let error = (equivalent - swift(ep)).abs() / swift(ep);
            let ratio = cell("von_mises") / equivalent;
            assert!(
                error < 1e-8,
                "{kinematics:?}: {equivalent} against {}",
                swift(ep)
            );
            assert!(
                (ratio / across - 1.0).abs() < 5e-3,
                "{kinematics:?}: von Mises / equivalent {ratio}, expected {across}"
            );
        }
        assert!(
            plastic >= 15,
            "{kinematics:?}: {plastic} plastic increments"
        );
    }
}

/// An element that inverts inside a Newton iterate makes the attempt fail as "no
/// convergence" (retryable: a smaller step may pass) and names the element, with the kind
/// prefix once, and says the failure came at the first iterate, before any Newton step: a
/// unit cube squashed through itself (by 1.5 times its height) in one increment with one
/// halving allowed, under finite strain.
#[test]
fn an_inverted_element_is_named_once_in_the_cutback_reason() {
    let mut model = pulled_cube("z+", "z", -1.5);
    model.settings.kinematics = StrainTheory::Finite;
    model.settings.increments = 1;
    model.settings.max_cutbacks = 1;
    let mut sim = Simulation::new(model).unwrap();
    let err = sim.step().unwrap_err().to_string();
    println!("{err}");
    assert!(
        err.contains("at the first iterate (extrapolated from the last increment): element 0"),
        "{err}"
    );
    assert_eq!(err.matches("no convergence").count(), 1, "{err}");
}
