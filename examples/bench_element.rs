//! Microseconds per F-bar hexahedron evaluation (log-strain material at 8 points):
//! `cargo run --release --example bench_element [-- EVALUATIONS]`.
//!
//! Times, in one process and interleaved round by round (so drift of a shared machine hits
//! all alike), the original kernel (`hex8_fbar_reference`, "before"), the tuned kernel with
//! the tangent ("after") and without it (residual only, as a line-search trial), each
//! elastic (Hencky, small strain) and plastic (Hill48 + Swift, yielding at every point),
//! on a distorted element. Prints the median over rounds of the time per evaluation, and
//! checks that the kernels agree (largest force and tangent difference, relative).
//!
//! Times are the thread's own CPU time (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), so that
//! other processes sharing the machine do not inflate them; wall time where that clock is
//! missing. Run pinned (`taskset -c 1`) for a stable cache.
use std::hint::black_box;
use std::time::Instant;

#[path = "bench_support/mod.rs"]
mod bench_support;
use bench_support::{clock, thread_cpu_seconds, Uniform, ROUNDS};
use tribo::element::{hex8_fbar_reference, Element, Hex8FBar};
use tribo::geometry::Vec3;
use tribo::material::{ElastoPlastic, Hardening, Hill48, LinearElastic, Material, PointState};
use tribo::mesh::HEX_CORNERS;

fn main() {
    let evaluations = bench_support::evaluations(20_000);
    let mut uniform = Uniform::new(7);
    let mut next = || uniform.next();
    let x: [Vec3; 8] = std::array::from_fn(|a| {
        let c = HEX_CORNERS[a];
        Vec3::new(c[0] + 1.0, c[1] + 1.0, c[2] + 1.0) * 0.5
            + Vec3::new(next(), next(), next()) * 0.15
    });
    let direction: [Vec3; 8] = std::array::from_fn(|_| Vec3::new(next(), next(), next()));
    let elastic = LinearElastic::new(70e3, 0.33).unwrap();
    let plastic = ElastoPlastic::new(
        elastic,
        Hill48::from_lankford(0.7, 1.3, 2.1).unwrap(),
        Hardening::swift(500.0, 0.01, 0.22).unwrap(),
    );
    let el = Hex8FBar::default();
    let cases: [(&str, &dyn Material, f64); 2] =
        [("elastic", &elastic, 1e-4), ("plastic", &plastic, 0.05)];
    let wall = Instant::now();
    let which = if thread_cpu_seconds().is_some() {
        "thread CPU time"
    } else {
        "wall time"
    };
    println!(
        "F-bar hexahedron, 8 points, {evaluations} evaluations x {ROUNDS} rounds; median us per element ({which})"
    );
    println!(
        "{:<8} {:>10} {:>10} {:>10} {:>8} {:>10} {:>10}",
        "material", "before", "after", "residual", "ratio", "d force", "d tangent"
    );
    for (name, material, scale) in cases {
        let u = direction.map(|d| d * scale);
        let committed = [PointState::default(); 8];
        let mut trial = committed;
        let old =
            hex8_fbar_reference::evaluate(&el, &x, &u, &committed, &mut trial, material).unwrap();
        if name == "plastic" {
            assert!(
                trial.iter().all(|t| t.eq_plastic_strain > 0.0),
                "must yield"
            );
        }
        let new = el
            .evaluate(&x, &u, &committed, &mut trial, material)
            .unwrap();
        let d_force = (new.force - old.force).amax() / old.force.amax();
        let d_tangent = (new.stiffness - old.stiffness).amax() / old.stiffness.amax();
        let mut force = [0.0; 24];
        let mut stiffness = vec![0.0; 576];
        let mut times = [Vec::new(), Vec::new(), Vec::new()];
        for _ in 0..ROUNDS {
            for (kernel, t) in times.iter_mut().enumerate() {
                let start = clock(&wall);
                for _ in 0..evaluations {
                    let u = black_box(&u);
                    match kernel {
                        0 => {
                            black_box(
                                hex8_fbar_reference::evaluate(
                                    &el, &x, u, &committed, &mut trial, material,
                                )
                                .unwrap(),
                            );
                        }
                        1 => el
                            .evaluate_into(
                                &x,
                                u,
                                &committed,
                                &mut trial,
                                material,
                                &mut force,
                                Some(&mut stiffness),
                            )
                            .unwrap(),
                        _ => el
                            .evaluate_into(
                                &x, u, &committed, &mut trial, material, &mut force, None,
                            )
                            .unwrap(),
                    }
                    black_box((&force, &stiffness));
                }
                t.push((clock(&wall) - start) / evaluations as f64 * 1e6);
            }
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let [before, after, residual] = times.map(|mut v| median(&mut v));
        println!(
            "{name:<8} {before:>10.2} {after:>10.2} {residual:>10.2} {:>8.2} {d_force:>10.1e} {d_tangent:>10.1e}",
            before / after
        );
    }
}
