//! Microseconds per solid-shell evaluation (finite strain, 2 x 2 in-plane and 5 points
//! through the thickness, six EAS modes): `cargo run --release --example bench_solid_shell
//! [-- EVALUATIONS [THICKNESS_POINTS]]`.
//!
//! Three calls, each elastic (Hencky) and plastic (Hill48 + Swift, yielding at every
//! point), on a distorted thin element: a first call (no memory: the local EAS iteration
//! from the committed parameters, solved to the tight tolerance) with the tangent; a call
//! predicted from the memory of a nearby linearisation (as in Newton's iterations after
//! the first) with the tangent; and the same predicted call for the residual only (a
//! line-search trial). Prints the fastest of the rounds of the time per evaluation, in the
//! thread's own CPU time. Run pinned (`taskset -c 1`) for a stable cache.
//!
//! Against it, interleaved round by round, the F-bar hexahedron (8 points) with its tangent
//! on the same element and displacements, and the ratio of the predicted call with the
//! tangent to it: with `THICKNESS_POINTS` 2 (Gauss) both have 8 points, the kernels
//! compared at equal integration points (issue 50's goal: within 1.5x).
use std::hint::black_box;
use std::time::Instant;

#[path = "bench_support/mod.rs"]
mod bench_support;
use bench_support::{clock, Uniform, ROUNDS};
use tribo::element::{solid_shell, Element, ElementKind, Hex8FBar, StrainTheory};
use tribo::geometry::Vec3;
use tribo::material::{ElastoPlastic, Hardening, Hill48, LinearElastic, Material, PointState};
use tribo::mesh::HEX_CORNERS;

fn main() {
    let evaluations = bench_support::evaluations(5_000);
    let mut uniform = Uniform::new(11);
    let mut next = || uniform.next();
    // A 2 x 2 x 0.2 cell, its corners moved by up to 5 % of the cell.
    let x: [Vec3; 8] = std::array::from_fn(|a| {
        let c = HEX_CORNERS[a];
        Vec3::new(c[0] + 1.0, c[1] + 1.0, 0.1 * (c[2] + 1.0))
            + Vec3::new(next(), next(), 0.1 * next()) * 0.05
    });
    let direction: [Vec3; 8] = std::array::from_fn(|_| Vec3::new(next(), next(), next()));
    let nearby: [Vec3; 8] = std::array::from_fn(|_| Vec3::new(next(), next(), next()));
    let elastic = LinearElastic::new(210e3, 0.3).unwrap();
    let plastic = ElastoPlastic::new(
        elastic,
        Hill48::from_lankford(1.79, 1.51, 2.27).unwrap(),
        Hardening::swift(576.79, 0.01658, 0.3593).unwrap(),
    );
    let thickness_points = std::env::args()
        .nth(2)
        .map(|s| s.parse().expect("THICKNESS_POINTS must be a number"))
        .unwrap_or(solid_shell::DEFAULT_THICKNESS_POINTS);
    let el: &dyn Element<24> = solid_shell::select(
        ElementKind::SolidShell,
        StrainTheory::Finite,
        true,
        thickness_points,
    )
    .unwrap();
    let fbar = Hex8FBar::default();
    let np = el.point_count();
    let cases: [(&str, &dyn Material, f64); 2] =
        [("elastic", &elastic, 2e-4), ("plastic", &plastic, 0.02)];
    let wall = Instant::now();
    println!(
        "solid-shell, {np} points, {evaluations} evaluations x {ROUNDS} rounds; fastest round, us per element"
    );
    println!(
        "{:<8} {:>10} {:>10} {:>10} {:>10} {:>16}",
        "material", "first", "predicted", "residual", "F-bar", "predicted/F-bar"
    );
    for (name, material, scale) in cases {
        let u: Vec<Vec3> = direction.iter().map(|d| d * scale).collect();
        // The memory of a linearisation at displacements 1e-3 of the step away.
        let u_then: Vec<Vec3> = u
            .iter()
            .zip(&nearby)
            .map(|(u, n)| u + n * (1e-3 * scale))
            .collect();
        let committed = vec![PointState::default(); np];
        let mut trial = committed.clone();
        let mut force = [0.0; 24];
        let mut stiffness = vec![0.0; 576];
        let mut memory_then = vec![f64::NAN; el.memory_len()];
        el.evaluate_remembering(
            &x,
            &u_then,
            &committed,
            &mut trial,
            material,
            &mut memory_then,
            &mut force,
            Some(&mut stiffness),
        )
        .unwrap();
        if name == "plastic" {
            assert!(
                trial.iter().all(|t| t.eq_plastic_strain > 0.0),
                "must yield at every point"
            );
        }
        let mut memory = memory_then.clone();
        let fbar_committed = [PointState::default(); 8];
        let mut fbar_trial = fbar_committed;
        fbar.evaluate_into(
            &x,
            &u,
            &fbar_committed,
            &mut fbar_trial,
            material,
            &mut force,
            Some(&mut stiffness),
        )
        .unwrap();
        if name == "plastic" {
            assert!(
                fbar_trial.iter().all(|t| t.eq_plastic_strain > 0.0),
                "the F-bar element must yield at every point too"
            );
        }
        let mut times = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
        for _ in 0..ROUNDS {
            for (kernel, t) in times.iter_mut().enumerate() {
                let start = clock(&wall);
                for _ in 0..evaluations {
                    let u = black_box(&u);
                    match kernel {
                        0 => {
                            trial.clone_from(&committed);
                            el.evaluate_into(
                                &x,
                                u,
                                &committed,
                                &mut trial,
                                material,
                                &mut force,
                                Some(&mut stiffness),
                            )
                            .unwrap()
                        }
                        3 => fbar
                            .evaluate_into(
                                &x,
                                u,
                                &fbar_committed,
                                &mut fbar_trial,
                                material,
                                &mut force,
                                Some(&mut stiffness),
                            )
                            .unwrap(),
                        _ => {
                            memory.copy_from_slice(&memory_then);
                            el.evaluate_remembering(
                                &x,
                                u,
                                &committed,
                                &mut trial,
                                material,
                                &mut memory,
                                &mut force,
                                (kernel == 1).then_some(&mut stiffness[..]),
                            )
                            .map(|_| ())
                            .unwrap()
                        }
                    }
                    black_box((&force, &stiffness));
                }
                t.push((clock(&wall) - start) / evaluations as f64 * 1e6);
            }
        }
        // The fastest round: interference from a shared machine only adds time.
        let [first, predicted, residual, fbar_us] =
            times.map(|v| v.iter().copied().fold(f64::INFINITY, f64::min));
        println!(
            "{name:<8} {first:>10.2} {predicted:>10.2} {residual:>10.2} {fbar_us:>10.2} {:>16.2}",
            predicted / fbar_us
        );
    }
}
