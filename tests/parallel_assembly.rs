//! The element loop runs on several threads (setting `threads`); every element's response
//! is scattered in element order, so the results must be bit-for-bit those of one thread,
//! whatever the number of threads (including counts that leave blocks of unequal size).
//! The factorization uses the same threads on disjoint subtrees, with the same effect.
//! The strip has 84 elements, above the 64 below which the loop stays on one thread. The
//! solid-shell also keeps a memory per element between evaluations, split between the
//! threads like the states.

mod common;

use std::sync::Arc;
use tribo::element::{ElementKind, StrainTheory};
use tribo::geometry::{Cylinder, Vec3};
use tribo::material::{ElastoPlastic, Hardening, Hill48, LinearElastic};
use tribo::mesh::Mesh;
use tribo::solver::{Model, Simulation};
use tribo::tool::ScalarSchedule;

/// A plastic strip (finite strain, Hill48, Swift) pressed into a rough cylinder and dragged:
/// plastic flow and slip, so the integration-point states written by each thread matter.
fn strip(threads: usize, kinematics: StrainTheory, element: ElementKind) -> (Vec<f64>, Vec<usize>) {
    let cells = match element {
        ElementKind::Hexahedron => [21, 1, 4],
        ElementKind::SolidShell => [42, 2, 1],
    };
    let (x, its, _) = strip_of([10.0, 1.0, 1.0], cells, threads, kinematics, element);
    (x, its)
}

/// The strip of `size` on `cells`: its unknowns, Newton iterations per increment and how
/// many factorizations ran on several threads.
fn strip_of(
    size: [f64; 3],
    cells: [usize; 3],
    threads: usize,
    kinematics: StrainTheory,
    element: ElementKind,
) -> (Vec<f64>, Vec<usize>, usize) {
    let mesh = Mesh::block(Vec3::zeros(), Vec3::from(size), cells).unwrap();
    let material = ElastoPlastic::new(
        LinearElastic::new(70e3, 0.33).unwrap(),
        Hill48::from_lankford(0.7, 1.3, 2.1).unwrap(),
        Hardening::swift(500.0, 0.01, 0.22).unwrap(),
    );
    let mut model = Model::new(mesh, Arc::new(material)).unwrap();
    let cyl = Cylinder::new(Vec3::new(5.0, 0.0, 6.0 + 1e-3), Vec3::y(), 5.0).unwrap();
    let path = [
        (0.0, [0.0; 3]),
        (1.0, [0.0, 0.0, -0.3]),
        (2.0, [2.0, 0.0, -0.3]),
    ];
    model
        .add_tool(common::tool("roller", cyl, &path, 0.2), "z+", None)
        .unwrap();
    model
        .prescribe("z-", "xyz", ScalarSchedule::constant(0.0))
        .unwrap();
    for set in ["y-", "y+"] {
        model
            .prescribe(set, "y", ScalarSchedule::constant(0.0))
            .unwrap();
    }
    model.settings.kinematics = kinematics;
    model.settings.element = element;
    model.settings.end_time = 2.0;
    model.settings.increments = 8;
    model.settings.threads = threads;
    let mut sim = Simulation::new(model).unwrap();
    sim.run(|_, _| Ok(())).unwrap();
    let iterations = sim.history.iter().map(|r| r.iterations).collect();
    (
        sim.unknowns().to_vec(),
        iterations,
        sim.split_factorizations(),
    )
}

/// Both hexahedra: F-bar with the log-strain return mapping, and the small-strain B-bar
/// element's direct kernel; and the finite-strain solid-shell.
#[test]
fn results_do_not_depend_on_the_number_of_element_threads() {
    for (kinematics, element) in [
        (StrainTheory::Finite, ElementKind::Hexahedron),
        (StrainTheory::Small, ElementKind::Hexahedron),
        (StrainTheory::Finite, ElementKind::SolidShell),
    ] {
        let (one, its_one) = strip(1, kinematics, element);
        let plastic_or_moved = one.iter().any(|v| v.abs() > 1e-3);
        assert!(
            plastic_or_moved,
            "the strip must deform for the test to mean anything"
        );
        for threads in [2, 5] {
            let (many, its_many) = strip(threads, kinematics, element);
            assert_eq!(
                its_one, its_many,
                "{kinematics:?}, {threads} threads: Newton iterations differ"
            );
            let worst = one
                .iter()
                .zip(&many)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            // Same operations in the same order: not round-off close, identical.
            assert_eq!(
                worst, 0.0,
                "{kinematics:?}, {threads} threads: unknowns differ by {worst:e}"
            );
        }
    }
}

/// The factorization runs on the same threads (disjoint subtrees of its elimination tree at
/// once, `solver::symmetric_lu`, "Threads") once a factorization is large enough: a sheet
/// of 24 x 24 x 1 hexahedra (3,750 displacement unknowns; a plate's elimination tree
/// branches, a strip's is nearly a chain) under the roller gives the one-thread results
/// bit for bit on 2 and 3 threads, and its factorizations did run split.
#[test]
fn results_do_not_depend_on_the_number_of_factorization_threads() {
    let (size, cells) = ([10.0, 10.0, 1.0], [24, 24, 1]);
    let (one, its_one, split_one) = strip_of(
        size,
        cells,
        1,
        StrainTheory::Finite,
        ElementKind::Hexahedron,
    );
    assert_eq!(split_one, 0);
    assert!(one.iter().any(|v| v.abs() > 1e-3));
    for threads in [2, 3] {
        let (many, its_many, split) = strip_of(
            size,
            cells,
            threads,
            StrainTheory::Finite,
            ElementKind::Hexahedron,
        );
        println!("{threads} threads: {split} factorizations split");
        assert!(split > 0, "{threads} threads: no factorization ran split");
        assert_eq!(
            its_one, its_many,
            "{threads} threads: Newton iterations differ"
        );
        let identical = one
            .iter()
            .zip(&many)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(identical, "{threads} threads: unknowns differ");
    }
}
