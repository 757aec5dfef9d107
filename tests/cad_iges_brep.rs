//! IGES BRep faces (510 in 514 shells of 186 solids, or alone) as OpenCascade writes them
//! in BRep mode (tests/data/cad/make_iges_brep.py): each analytic kind (190 plane, 192
//! cylinder, 194 cone, 196 sphere, 198 torus and spindle torus) is read as its exact
//! surface, with the normal src/cad/iges_brep.rs documents and the generator's parameter
//! box; the holed plane keeps its hole; faces on what is not read are refused naming the
//! entity. (The punch and die, read from BRep IGES, equal the built-in tools in
//! tests/cad_import.rs.)
//!
//! The exact surfaces use the generator's numbers: frame origin (1, 2, 3), axis
//! (0.6, 0, 0.8), reference direction (0, 1, 0), all of which IGES's ten digits write
//! exactly, as the radii and the cone's 30 degrees. Tolerance 1e-9 mm: the arcs' 124
//! matrices and end points carry ten digits of numbers of size ~5 (~1e-9 relative), and
//! the NURBS forms are exact, so anything above that is a wrong surface.

mod common;

use common::exact_surfaces::{
    assert_parameter_box, cone, cylinder, face_normal, plane, sphere, tube, Exact, Frame,
};
use tribo::cad::iges::faces_from_iges;
use tribo::cad::{choose_faces, tool_surface, Face, Facing, ImportOptions};
use tribo::geometry::{RigidSurface, Vec3};

fn text(name: &str) -> String {
    let path = format!("{}/tests/data/cad/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap()
}

fn faces(name: &str) -> Vec<Face> {
    faces_from_iges(name, &text(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The generator's frame.
fn frame() -> Frame {
    Frame::new(
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::y(),
        Vec3::new(0.6, 0.0, 0.8),
    )
}

fn exact(kind: &str) -> Exact {
    let f = frame();
    match kind {
        "plane" => plane(f),
        "cylinder" => cylinder(f, 4.0),
        "cone" => cone(f, 3.0, 30f64.to_radians()),
        "sphere" => sphere(f, 5.0),
        "torus" => tube(f, 5.0, 2.0),
        "spindle" => tube(f, 2.0, 5.0),
        _ => unreachable!(),
    }
}

const KINDS: [&str; 6] = ["plane", "cylinder", "cone", "sphere", "torus", "spindle"];

/// Every face's surface, sampled on a 41 x 41 grid of its parameter box, lies on the
/// exact surface to 1e-9 mm, and its normal is the documented one (a 510 no shell lists
/// keeps its surface's `S_u x S_v`: out of the cylinder, cone, sphere and tube, along the
/// plane's normal).
#[test]
fn each_brep_surface_kind_is_its_exact_surface_with_the_documented_normal() {
    for kind in KINDS {
        let faces = faces(&format!("brep_{kind}.igs"));
        assert_eq!(faces.len(), 1, "{kind}");
        let face = &faces[0];
        assert!(!face.flip, "{kind}: a face in no shell");
        assert!(face.trim.is_some(), "{kind}: trimmed by its loop");
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
        assert!(worst < 1e-9, "{kind}: {worst}");
        // Central differences of step 1e-6 on a domain of size ~5: error ~1e-10.
        assert!(worst_normal < 1e-6, "{kind}: normal off by {worst_normal}");
    }
}

/// The faces' parameter boxes are the generator's in this reader's `(u, v)` (angles in
/// radians, modulo a turn): the cone's `v` is the height, the generator's slant length
/// (OpenCascade's `v`) times `cos 30`. The boxes come from the edges inverted onto the
/// surfaces, so this checks the inversion; ten digits through it: 1e-8.
#[test]
fn parameter_boxes_are_those_the_generator_gave() {
    let c = 30f64.to_radians().cos();
    let cases = [
        ("cylinder", [[0.3, 4.0], [-1.0, 2.5]]),
        ("cone", [[0.3, 4.0], [-c, 2.5 * c]]),
        ("sphere", [[0.3, 4.0], [-1.0, 1.2]]),
        ("torus", [[0.3, 4.0], [-1.0, 2.5]]),
        ("spindle", [[0.3, 4.0], [-1.0, 1.0]]),
    ];
    for (kind, want) in cases {
        let got = faces(&format!("brep_{kind}.igs"))[0].surface.domain();
        assert_parameter_box(kind, got, want, kind == "torus" || kind == "spindle", 1e-8);
    }
}

/// The holed plane as a tool: points above the hole (radius 1.5 about (1, 0.5) of the
/// frame) have no foot, points above the plate beside it their foot straight below.
#[test]
fn the_brep_plane_face_has_its_hole() {
    let f = frame();
    let name = "brep_plane.igs";
    let tool = tool_surface(name, faces(name), &ImportOptions::default()).unwrap();
    let centre = f.o + f.x * 1.0 + f.y * 0.5;
    let (mut none, mut some) = (0, 0);
    for k in 0..400 {
        let angle = k as f64 * 0.1;
        let rho = 3.0 * (k as f64 + 0.5) / 400.0;
        let above = centre + (f.x * angle.cos() + f.y * angle.sin()) * rho + f.z * 0.3;
        match tool.project(&above, None) {
            None => {
                assert!(rho < 1.5 + 1e-9, "no foot at {rho} from the hole's centre");
                none += 1;
            }
            Some(p) => {
                assert!((p.foot - f.o).dot(&f.z).abs() < 1e-9, "{p:?}");
                assert!(
                    (p.foot - centre).norm() > 1.5 - 1e-9,
                    "foot in the hole: {p:?}"
                );
                if rho > 1.5 + 1e-9 {
                    assert!((p.gap - 0.3).abs() < 1e-9 && (p.normal - f.z).norm() < 1e-9);
                }
                some += 1;
            }
        }
    }
    // Half the radii lie inside the hole (1.5 of 3): both cases are exercised.
    assert!(
        none > 150 && some > 150,
        "{none} without a foot, {some} with"
    );
}

/// The punch's faces come from its one shell with the flags that turn them out of the
/// solid: the nose (the face with the lowest centre) faces down, the top up.
#[test]
fn shell_flags_turn_the_punch_faces_out_of_the_solid() {
    let faces = faces("punch_brep.igs");
    assert_eq!(faces.len(), 18);
    let centre_normal = |f: &Face| {
        let [u, v] = f.surface.domain();
        let (a, b) = (0.5 * (u[0] + u[1]), 0.5 * (v[0] + v[1]));
        (f.surface.point(a, b), face_normal(f, a, b))
    };
    let (low, high) = faces.iter().map(centre_normal).fold(
        (None::<(Vec3, Vec3)>, None::<(Vec3, Vec3)>),
        |(lo, hi), c| {
            (
                Some(lo.filter(|l| l.0.z <= c.0.z).unwrap_or(c)),
                Some(hi.filter(|h| h.0.z >= c.0.z).unwrap_or(c)),
            )
        },
    );
    let (low, high) = (low.unwrap(), high.unwrap());
    assert!(
        low.0.z.abs() < 1e-9 && (low.1 + Vec3::z()).norm() < 1e-9,
        "{low:?}"
    );
    assert!((high.0.z - 58.0).abs() < 1e-9 && (high.1 - Vec3::z()).norm() < 1e-9);
}

/// Faces of a BRep file are chosen by the direction they face as STEP's are
/// (tests/cad_face_choice.rs, same die): facing +z within 10 degrees, the top alone (at
/// z = 0); within 90, the top and the 8 faces of the entry radius (z in [-8, 0]).
#[test]
fn brep_die_faces_are_chosen_by_facing() {
    let die = faces("die_brep.igs");
    assert_eq!(die.len(), 22);
    let choose = |angle: f64| {
        let options = ImportOptions {
            facing: Some(Facing::new(Vec3::z(), angle, "test").unwrap()),
            ..ImportOptions::default()
        };
        choose_faces("die_brep.igs", die.clone(), &options).unwrap()
    };
    let z_range = |f: &Face| {
        let [[u0, u1], [v0, v1]] = f.surface.domain();
        let mut r = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..9 {
            for j in 0..9 {
                let p = f.surface.point(
                    u0 + (u1 - u0) * i as f64 / 8.0,
                    v0 + (v1 - v0) * j as f64 / 8.0,
                );
                r = (r.0.min(p.z), r.1.max(p.z));
            }
        }
        r
    };
    let top = choose(10.0);
    assert_eq!(top.len(), 1);
    let (lo, hi) = z_range(&top[0]);
    assert!(
        lo.abs() < 1e-12 && hi.abs() < 1e-12,
        "top at z = 0: {lo} {hi}"
    );
    let up = choose(90.0);
    assert_eq!(up.len(), 9);
    for f in &up {
        let (lo, hi) = z_range(f);
        assert!(
            lo > -8.0 - 1e-9 && hi < 1e-9,
            "{}: z in [{lo}, {hi}]",
            f.origin
        );
    }
}

/// What is not read is refused naming the entity, its type and D line (the file's line),
/// and the fix: a 510 whose surface pointer names a point, or whose loop pointer names
/// its surface.
#[test]
fn brep_faces_on_what_is_not_read_are_refused_naming_it() {
    let good = text("brep_cylinder.igs");
    // The 510's data "510,3,..." names the 192 (directory pointer 3); make it name the
    // 116 (pointer 5).
    let bad = good.replacen("510,3,", "510,5,", 1);
    assert_ne!(bad, good);
    let e = faces_from_iges("bad.igs", &bad).unwrap_err().to_string();
    assert!(
        e.contains("entity 510 (face) at D line ")
            && e.contains(": its surface is entity 116 (point) at D line ")
            && e.contains("(read: 128, 190, 192, 194, 196, 198)")
            && e.contains("BRepBuilderAPI_NurbsConvert"),
        "{e}"
    );
    // The face's loop pointer naming its surface instead of a 508.
    let bad = good.replacen("510,3,1,1,11;", "510,3,1,1,3; ", 1);
    assert_ne!(bad, good);
    let e = faces_from_iges("loop.igs", &bad).unwrap_err().to_string();
    assert!(
        e.contains("entity 510 (face) at D line ")
            && e.contains(
                ": its loop pointer names entity 192 (right circular cylindrical surface)"
            ),
        "{e}"
    );
}
