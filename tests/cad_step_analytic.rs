//! STEP faces on analytic surfaces, as OpenCascade writes them
//! (tests/data/cad/generate_analytic_faces.py): each face's NURBS lies on the exact surface
//! the generator made, and its outward normal is the one src/cad/step_analytic.rs documents.
//!
//! The exact surfaces below use the generator's numbers (its module docs): the frame
//! origin (1, 2, 3), axis along (0.2, -0.3, 1), reference direction (1, 0.1, 0.04) made
//! orthogonal to the axis. Tolerance 1e-9 mm: the file holds 13 significant digits of
//! coordinates of size ~10 (1e-12 mm), and the NURBS forms are exact, so anything above
//! rounding is a wrong surface.

mod common;

use common::exact_surfaces::{
    assert_parameter_box, cone, cylinder, face_normal, plane, sphere, tube, Exact, Frame,
};
use tribo::cad::step::faces_from_step;
use tribo::cad::{tool_surface, Face, ImportOptions};
use tribo::geometry::{RigidSurface, Vec3};

fn faces(name: &str) -> Vec<Face> {
    let path = format!("{}/tests/data/cad/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    faces_from_step(name, &text).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The generator's frame.
fn frame() -> Frame {
    let z = Vec3::new(0.2, -0.3, 1.0).normalize();
    let v = Vec3::new(1.0, 0.1, 0.04);
    Frame::new(Vec3::new(1.0, 2.0, 3.0), (v - z * v.dot(&z)).normalize(), z)
}

fn exact(kind: &str) -> Exact {
    let f = frame();
    match kind {
        "plane" => plane(f),
        "cylinder" | "band" => cylinder(f, 4.0),
        "offset" => cylinder(f, 5.5),
        "cone" => cone(f, 3.0, 0.4),
        "sphere" => sphere(f, 5.0),
        "torus" => tube(f, 5.0, 2.0),
        "spindle" => tube(f, 2.0, 5.0),
        // The ellipse (semi-axes 1.5 along the radius, 1 along the axis) about the circle
        // of radius 4, turned: distance to first order |F| / |grad F|.
        "revolution" => Box::new(move |p| {
            let (h, rho, e) = f.cylindrical(p);
            let value = ((rho - 4.0) / 1.5).powi(2) + h * h - 1.0;
            let grad = e * (2.0 * (rho - 4.0) / 2.25) + f.z * (2.0 * h);
            (value / grad.norm(), grad.normalize())
        }),
        // The circle of radius 3 in the frame's plane, extruded along d: slide p back
        // along d onto the plane; the normal is C' x d with C' the circle's tangent.
        "extrusion" => Box::new(move |p| {
            let d = Vec3::new(0.3, 0.2, 1.0).normalize();
            let q = p - f.o - d * ((p - f.o).dot(&f.z) / d.dot(&f.z));
            let tangent = f.z.cross(&q.normalize());
            let n = tangent.cross(&d).normalize();
            ((q.norm() - 3.0) * n.dot(&q.normalize()), n)
        }),
        _ => unreachable!(),
    }
}

const KINDS: [&str; 10] = [
    "plane",
    "cylinder",
    "band",
    "cone",
    "sphere",
    "torus",
    "spindle",
    "revolution",
    "extrusion",
    "offset",
];

/// Every face's surface, sampled on a 41 x 41 grid of its parameter box, lies on the
/// exact surface to 1e-9 mm, and its outward normal is the documented one (OpenCascade
/// writes these faces with same_sense true, so it is the surface's `S_u x S_v`).
#[test]
fn each_analytic_kind_is_its_exact_surface_with_the_documented_normal() {
    for kind in KINDS {
        let faces = faces(&format!("analytic_{kind}.step"));
        assert_eq!(faces.len(), 1, "{kind}");
        let face = &faces[0];
        assert!(!face.flip, "{kind}: same_sense true");
        let surface = exact(kind);
        let [u, v] = face.surface.domain();
        let (mut worst, mut worst_normal) = (0.0f64, 0.0f64);
        for i in 0..=40 {
            for j in 0..=40 {
                let a = u[0] + (u[1] - u[0]) * (0.01 + 0.98 * i as f64 / 40.0);
                let b = v[0] + (v[1] - v[0]) * (0.01 + 0.98 * j as f64 / 40.0);
                let (distance, normal) = surface(face.surface.point(a, b));
                worst = worst.max(distance.abs());
                worst_normal = worst_normal.max((face_normal(face, a, b) - normal).norm());
            }
        }
        eprintln!(
            "{kind}: domain {u:?} x {v:?}, worst distance {worst:.1e}, normal {worst_normal:.1e}"
        );
        // OpenCascade writes the spindle torus as a SURFACE_OF_REVOLUTION of a polynomial
        // degree-6 B-spline approximating the profile circle to ~1e-7 (its own
        // approximation; the revolution itself is exact, as "revolution" shows at 1e-9).
        let tol = if kind == "spindle" { 1e-6 } else { 1e-9 };
        assert!(worst < tol, "{kind}: {worst}");
        // Central differences of step 1e-6 on a domain of size ~5: error ~1e-10.
        assert!(worst_normal < 1e-6, "{kind}: normal off by {worst_normal}");
    }
}

/// The faces' parameter boxes are the generator's, so the surfaces run in STEP's
/// `(u, v)`: angles up to a turn; the cone's `v` is ISO 10303-42's height, which is the
/// generator's slant length (OpenCascade's `v`) times `cos 0.4`.
#[test]
fn parameter_boxes_are_those_the_generator_gave() {
    let tau = std::f64::consts::TAU;
    let c = 0.4f64.cos();
    let cases = [
        ("cylinder", [[0.3, 4.0], [-1.0, 2.5]]),
        ("band", [[0.0, tau], [0.0, 3.0]]),
        ("cone", [[0.3, 4.0], [-c, 2.5 * c]]),
        ("sphere", [[0.3, 4.0], [-1.0, 1.2]]),
        ("torus", [[0.3, 4.0], [-1.0, 2.5]]),
        ("extrusion", [[0.5, 3.0], [0.0, 2.5]]),
        ("offset", [[0.3, 4.0], [-1.0, 2.5]]),
    ];
    for (kind, want) in cases {
        let got = faces(&format!("analytic_{kind}.step"))[0].surface.domain();
        // The file's 12 to 15 digits; angles (all of u, a torus's v) modulo a turn.
        assert_parameter_box(kind, got, want, kind == "torus" || kind == "sphere", 1e-9);
    }
}

/// The holed plane as a tool: feet lie on the plane and never in the hole (radius 1.5
/// about (1, 0.5) of the plane's frame); a point above the hole has no foot on this face,
/// one above the plate beside it its foot straight below.
#[test]
fn the_plane_face_has_its_hole() {
    let f = frame();
    let tool = tool_surface(
        "analytic_plane.step",
        faces("analytic_plane.step"),
        &ImportOptions::default(),
    )
    .unwrap();
    let centre = f.o + f.x * 1.0 + f.y * 0.5;
    let mut none_above_hole = 0;
    for k in 0..400 {
        let angle = k as f64 * 0.1;
        let rho = 3.0 * (k as f64 + 0.5) / 400.0;
        let above = centre + (f.x * angle.cos() + f.y * angle.sin()) * rho + f.z * 0.3;
        match tool.project(&above, None) {
            None => {
                assert!(rho < 1.5 + 1e-9, "no foot at {rho} from the hole's centre");
                none_above_hole += 1;
            }
            Some(p) => {
                assert!(
                    (p.foot - f.o).dot(&f.z).abs() < 1e-9,
                    "foot off the plane: {p:?}"
                );
                let from_centre = (p.foot - centre).norm();
                assert!(
                    from_centre > 1.5 - 1e-9,
                    "foot inside the hole at {from_centre}"
                );
                if rho > 1.5 + 1e-9 {
                    assert!(
                        (p.gap - 0.3).abs() < 1e-9 && (p.normal - f.z).norm() < 1e-12,
                        "{p:?}"
                    );
                }
            }
        }
    }
    assert!(none_above_hole > 100, "{none_above_hole}");
}
