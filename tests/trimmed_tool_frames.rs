//! Issue 49: trimmed tools drawn as they are in the frames (src/output/trim_tessellation.rs),
//! on the NUMISHEET'93 tools as OpenCascade writes them (tests/data/cad/*_analytic.step,
//! made by make_numisheet93_tools.py):
//!
//! - the die's top face (z = 0, the 160 x 160 square less the opening: a rounded square of
//!   half side 37 + 8 = 45 and plan corner radius 12 + 8 = 20, where the entry radius of 8
//!   meets the top) is drawn with no vertex inside the opening, no cell centroid in it
//!   deeper than the chord tolerance, and the face's area to within that tolerance times
//!   the curved trims' length;
//! - the punch's working side (flat nose at z = 0, nose radius 8, plan half side 35 and
//!   corner radius 10) is drawn within the punch's outline: the flat nose within its edge
//!   (half side 27, corner radius 2), the nose radius within the plan outline and z in
//!   [0, 8].

use std::sync::Arc;
use tribo::cad::step::faces_from_step;
use tribo::cad::{tool_surface, Facing, ImportOptions};
use tribo::geometry::Vec3;
use tribo::output::{tool_frame, DisplayRegion, Frame};
use tribo::tool::{Pose, Tool};

fn text(name: &str) -> String {
    let path = format!("{}/tests/data/cad/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(path).unwrap()
}

/// The faces of `file` facing `direction` within `angle` degrees, as one tool, drawn at the
/// identity pose with chord tolerance `tolerance`.
fn drawn(file: &str, direction: [f64; 3], angle: f64, tolerance: Option<f64>) -> Frame {
    let faces = faces_from_step(file, &text(file)).unwrap();
    let options = ImportOptions {
        facing: Some(
            Facing::new(
                Vec3::new(direction[0], direction[1], direction[2]),
                angle,
                "test",
            )
            .unwrap(),
        ),
        ..ImportOptions::default()
    };
    let surface = tool_surface(file, faces, &options).unwrap();
    let tool = Tool::new("tool", Arc::new(surface));
    let region = DisplayRegion::around(&[]);
    let frame = tool_frame(&tool, &Pose::identity(), &region, tolerance).unwrap();
    frame.validate().unwrap();
    frame
}

/// Signed distance of (x, y) into the rounded square of half side `h` and corner radius
/// `r` centred at the origin: positive inside, negative outside.
fn depth_in_rounded_square(h: f64, r: f64, x: f64, y: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let c = h - r;
    if ax > c && ay > c {
        r - (ax - c).hypot(ay - c)
    } else {
        h - ax.max(ay)
    }
}

/// Area of the rounded square.
fn rounded_square_area(h: f64, r: f64) -> f64 {
    4.0 * h * h - (4.0 - std::f64::consts::PI) * r * r
}

/// Every cell of the frame as its corner points (quadrilaterals and triangles).
fn cells(frame: &Frame) -> Vec<Vec<Vec3>> {
    let at = |i: &usize| Vec3::from(frame.points[*i]);
    (frame.quads.iter().map(|q| q.iter().map(at).collect()))
        .chain(frame.triangles.iter().map(|t| t.iter().map(at).collect()))
        .collect()
}

/// Area of a planar or nearly planar cell (a fan of triangles from its first corner).
fn area(cell: &[Vec3]) -> f64 {
    (1..cell.len() - 1)
        .map(|k| 0.5 * (cell[k] - cell[0]).cross(&(cell[k + 1] - cell[0])).norm())
        .sum()
}

fn centroid(cell: &[Vec3]) -> Vec3 {
    cell.iter().fold(Vec3::zeros(), |a, p| a + p) / cell.len() as f64
}

/// The die's top face, with the default tolerance and with 0.05 mm and 0.005 mm.
#[test]
fn the_die_top_face_is_drawn_with_its_opening_as_a_hole() {
    let (outer, hole, corner) = (80.0, 45.0, 20.0);
    let exact = 4.0 * outer * outer - rounded_square_area(hole, corner);
    // The curved trims: the opening's four corner arcs.
    let curved = std::f64::consts::TAU * corner;
    // The default: 1e-3 of the top patch's diagonal (at least the face's, 160 sqrt 2).
    let default = tribo::output::TRIM_TOLERANCE * 160.0 * 2f64.sqrt();
    let mut errors = Vec::new();
    for (tolerance, bound) in [(None, default), (Some(0.05), 0.05), (Some(0.005), 0.005)] {
        let frame = drawn("die_analytic.step", [0.0, 0.0, 1.0], 10.0, tolerance);
        assert!(
            !frame.triangles.is_empty(),
            "the holed face is triangulated"
        );
        for p in &frame.points {
            // 1e-9 mm: the vertices are points of the exact trimming curves, evaluated.
            assert!(
                p[2].abs() < 1e-9 && p[0].abs().max(p[1].abs()) <= outer + 1e-9,
                "vertex {p:?} off the top face"
            );
            let d = depth_in_rounded_square(hole, corner, p[0], p[1]);
            assert!(d <= 1e-9, "vertex {p:?} inside the opening by {d}");
        }
        let mut drawn_area = 0.0;
        for cell in cells(&frame) {
            let c = centroid(&cell);
            let d = depth_in_rounded_square(hole, corner, c.x, c.y);
            // A cell can reach into the opening only by a chord's sagitta, at most the
            // tolerance (the default one is relative to the patch, which may exceed the
            // face: 2 x its bound is allowed there).
            assert!(
                d <= 2.0 * bound,
                "cell centroid {c} inside the opening by {d}"
            );
            drawn_area += area(&cell);
        }
        // Chords of the opening's arcs cut caps of area (2/3) c s <= (2/3) c tolerance off
        // the opening: the drawn area exceeds the face's by at most that over the arcs.
        let error = drawn_area - exact;
        assert!(
            error > -1e-6 && error <= 2.0 * bound * curved,
            "tolerance {tolerance:?}: drawn area {drawn_area} vs exact {exact}"
        );
        errors.push(error);
    }
    // Ten times finer chords: the area error falls (about 10 x: it goes as the sagitta).
    assert!(errors[2] < 0.2 * errors[1], "area errors {errors:?}");
}

/// The punch's working side (facing down within 89 degrees: the flat nose, the nose
/// radius' cylinders and tori), drawn within its outline; the flat nose alone within its
/// edge, with the area of its rounded square.
#[test]
fn the_punch_nose_is_drawn_within_its_edge() {
    let frame = drawn("punch_analytic.step", [0.0, 0.0, -1.0], 89.0, Some(0.01));
    for p in &frame.points {
        let d = depth_in_rounded_square(35.0, 10.0, p[0], p[1]);
        assert!(
            d >= -1e-9 && p[2] >= -1e-9 && p[2] <= 8.0 + 1e-9,
            "vertex {p:?} outside the punch's outline (by {d}) or off its nose radius"
        );
    }
    let nose = drawn("punch_analytic.step", [0.0, 0.0, -1.0], 1.0, Some(0.01));
    assert!(
        !nose.triangles.is_empty(),
        "the rounded nose is triangulated"
    );
    let mut drawn_area = 0.0;
    for p in &nose.points {
        let d = depth_in_rounded_square(27.0, 2.0, p[0], p[1]);
        assert!(
            d >= -1e-9 && p[2].abs() < 1e-9,
            "nose vertex {p:?} outside its edge by {}",
            -d
        );
    }
    for cell in cells(&nose) {
        let c = centroid(&cell);
        assert!(depth_in_rounded_square(27.0, 2.0, c.x, c.y) > 0.0, "{c}");
        drawn_area += area(&cell);
    }
    // The nose's edge is convex: its chords cut the corner arcs' caps, at most
    // (2/3) c tolerance each, 2 pi 2 x 0.01 in all.
    let exact = rounded_square_area(27.0, 2.0);
    let error = exact - drawn_area;
    assert!(
        error > -1e-6 && error <= 0.01 * std::f64::consts::TAU * 2.0,
        "nose area {drawn_area} vs {exact}"
    );
}
