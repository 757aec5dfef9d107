//! Issue 49: choosing the faces of a STEP tool (src/cad/select.rs) by the direction they
//! face, by name, and the orientation rule with `ORIENTED_FACE` (src/cad/step_topology.rs),
//! on the NUMISHEET'93 die as OpenCascade writes it (tests/data/cad/die_analytic.step: a
//! 160 x 160 block, top at z = 0, bottom at z = -58, with a rounded-square opening whose top
//! edge is rounded by an entry radius of 8: 22 faces = top, 4 cylinders and 4 tori of the
//! entry radius, 4 planes and 4 cylinders of the opening's wall, 4 sides, bottom).

use tribo::cad::step::faces_from_step;
use tribo::cad::{choose_faces, Face, Facing, ImportOptions};
use tribo::geometry::Vec3;

fn text(name: &str) -> String {
    let path = format!("{}/tests/data/cad/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(path).unwrap()
}

fn die() -> Vec<Face> {
    faces_from_step("die_analytic.step", &text("die_analytic.step")).unwrap()
}

fn facing(d: [f64; 3], angle: f64) -> Option<Facing> {
    Some(Facing::new(Vec3::new(d[0], d[1], d[2]), angle, "test").unwrap())
}

/// z of the face's surface over a 9 x 9 grid of its parameter box: (min, max).
fn z_range(face: &Face) -> (f64, f64) {
    let [[u0, u1], [v0, v1]] = face.surface.domain();
    let mut r = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..9 {
        for j in 0..9 {
            let p = face.surface.point(
                u0 + (u1 - u0) * i as f64 / 8.0,
                v0 + (v1 - v0) * j as f64 / 8.0,
            );
            r = (r.0.min(p.z), r.1.max(p.z));
        }
    }
    r
}

/// The outward normal at the middle of the parameter box, by central differences (step
/// 1e-6 of the box: ~1e-12 relative), independently of the library's own.
fn centre_normal(face: &Face) -> Vec3 {
    let [[u0, u1], [v0, v1]] = face.surface.domain();
    let (u, v, hu, hv) = (
        0.5 * (u0 + u1),
        0.5 * (v0 + v1),
        1e-6 * (u1 - u0),
        1e-6 * (v1 - v0),
    );
    let su = face.surface.point(u + hu, v) - face.surface.point(u - hu, v);
    let sv = face.surface.point(u, v + hv) - face.surface.point(u, v - hv);
    let n = su.cross(&sv).normalize();
    if face.flip {
        -n
    } else {
        n
    }
}

/// Facing +z within 10 degrees: the top face alone (a plane at z = 0); within 90 degrees
/// (the default: n . d > 0) the top and the 8 faces of the entry radius, which span
/// z in [-8, 0]; the walls (horizontal normals) and the bottom are left. With `flip` the
/// bottom (z = -58) is the one face that faces +z.
#[test]
fn the_die_faces_facing_up_are_its_top_and_entry_radius() {
    let choose = |d, angle, flip| {
        let options = ImportOptions {
            facing: facing(d, angle),
            flip,
            ..ImportOptions::default()
        };
        choose_faces("die", die(), &options).unwrap()
    };
    assert_eq!(die().len(), 22);
    let top = choose([0.0, 0.0, 1.0], 10.0, false);
    assert_eq!(top.len(), 1);
    let (lo, hi) = z_range(&top[0]);
    assert!(
        lo.abs() < 1e-12 && hi.abs() < 1e-12,
        "top at z = 0: {lo} {hi}"
    );
    assert!((centre_normal(&top[0]) - Vec3::z()).norm() < 1e-9);

    let up = choose([0.0, 0.0, 1.0], 90.0, false);
    assert_eq!(up.len(), 9);
    for f in &up {
        let (lo, hi) = z_range(f);
        assert!(
            lo > -8.0 - 1e-9 && hi < 1e-9,
            "{}: z in [{lo}, {hi}]",
            f.origin
        );
        assert!(centre_normal(f).z > 0.5, "{}", f.origin);
    }
    // The 13 others face sideways or down at their centres.
    for f in die() {
        if !up.iter().any(|g| g.origin == f.origin) {
            assert!(centre_normal(&f).z < 1e-9, "{}", f.origin);
        }
    }
    let flipped = choose([0.0, 0.0, 1.0], 10.0, true);
    assert_eq!(flipped.len(), 1);
    let (lo, hi) = z_range(&flipped[0]);
    assert!(
        (lo + 58.0).abs() < 1e-9 && (hi + 58.0).abs() < 1e-9,
        "bottom: {lo} {hi}"
    );
    // Nothing faces +x and -z at once within 10 degrees: a clear error.
    let options = ImportOptions {
        facing: facing([1.0, 0.0, -1.0], 10.0),
        ..ImportOptions::default()
    };
    let e = choose_faces("die", die(), &options)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("none of the 22 faces") && e.contains("10 degrees"),
        "{e}"
    );
    assert!(Facing::new(Vec3::zeros(), 10.0, "f").is_err());
    assert!(Facing::new(Vec3::z(), 0.0, "f").is_err());
}

/// The die with a named solid and a named top face (in memory: OpenCascade writes ''):
/// a face answers to its own name and to its solid's; an unknown name is an error that
/// lists the names there are.
#[test]
fn faces_are_chosen_by_their_own_or_their_solid_name() {
    let named = text("die_analytic.step")
        .replace("MANIFOLD_SOLID_BREP('',", "MANIFOLD_SOLID_BREP('die',")
        .replace("#17 = ADVANCED_FACE('',", "#17 = ADVANCED_FACE('top',");
    let faces = faces_from_step("named.step", &named).unwrap();
    let by = |names: &[&str]| {
        let options = ImportOptions {
            names: Some(names.iter().map(|s| s.to_string()).collect()),
            ..ImportOptions::default()
        };
        choose_faces("named.step", faces.clone(), &options)
    };
    let top = by(&["top"]).unwrap();
    assert_eq!(top.len(), 1);
    assert!(top[0].origin.starts_with("#17 "), "{}", top[0].origin);
    assert_eq!(by(&["die"]).unwrap().len(), 22);
    let e = by(&["punch"]).unwrap_err().to_string();
    assert!(e.contains("'punch'") && e.contains("die, top"), "{e}");
    // The unnamed file says that it names nothing.
    let options = ImportOptions {
        names: Some(vec!["top".into()]),
        ..ImportOptions::default()
    };
    let e = choose_faces("die", die(), &options)
        .unwrap_err()
        .to_string();
    assert!(e.contains("names none"), "{e}");
}

/// A shell that lists its face through `ORIENTED_FACE(.., .F.)` uses it reversed: the
/// outward normal turns over; through `.T.` it stays; the ORIENTED_FACE's and the shell's
/// names reach the face.
#[test]
fn an_oriented_face_with_orientation_false_reverses_the_normal() {
    let original = text("analytic_plane.step");
    assert!(original.contains("#16 = OPEN_SHELL('',(#17));"));
    let with = |flag: &str| {
        let edited = original.replace(
            "#16 = OPEN_SHELL('',(#17));",
            &format!(
                "#16 = OPEN_SHELL('sheet',(#9000));\n#9000 = ORIENTED_FACE('o',*,#17,{flag});"
            ),
        );
        let faces = faces_from_step("oriented.step", &edited).unwrap();
        assert_eq!(faces.len(), 1);
        faces.into_iter().next().unwrap()
    };
    let plain = faces_from_step("plane.step", &original).unwrap().remove(0);
    let n = centre_normal(&plain);
    let reversed = with(".F.");
    assert!((centre_normal(&reversed) + n).norm() < 1e-12);
    let kept = with(".T.");
    assert!((centre_normal(&kept) - n).norm() < 1e-12);
    let mut names = kept.names.clone();
    names.sort();
    assert_eq!(names, ["o", "sheet"]);
}
