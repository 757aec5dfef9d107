//! Tools read from CAD files made by OpenCascade (tests/data/cad/make_numisheet93_tools.py)
//! against the std-lib's exact Bézier builders of the same NUMISHEET'93 punch and die.

use tribo::cad::iges::faces_from_iges;
use tribo::cad::step::faces_from_step;
use tribo::cad::{tool_surface, ImportOptions};
use tribo::geometry::builders::{die_patches, punch_patches, DieSpec, Extent, PunchSpec};
use tribo::geometry::{PatchSurface, Projection, RigidSurface, Vec3};

fn data(name: &str) -> (String, String) {
    let path = format!("{}/tests/data/cad/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    (name.to_string(), text)
}

fn iges_tool(name: &str, options: &ImportOptions) -> PatchSurface {
    let (source, text) = data(name);
    let faces = faces_from_iges(&source, &text).unwrap();
    tool_surface(&source, faces, options).unwrap()
}

fn step_tool(name: &str) -> PatchSurface {
    let (source, text) = data(name);
    let faces = faces_from_step(&source, &text).unwrap();
    tool_surface(&source, faces, &ImportOptions::default()).unwrap()
}

/// The punch and die of a format: NURBS-converted IGES or STEP, or the IGES or STEP of
/// OCC's own analytic faces (IGES: planes and surfaces of revolution; STEP: planes,
/// cylinders, tori).
fn cad_tool(format: &str, which: &str) -> PatchSurface {
    match format {
        "igs" => iges_tool(&format!("{which}_nurbs.igs"), &ImportOptions::default()),
        "igs-analytic" => iges_tool(&format!("{which}_analytic.igs"), &ImportOptions::default()),
        "igs-brep" => iges_tool(&format!("{which}_brep.igs"), &ImportOptions::default()),
        "igs-brep-nurbs" => iges_tool(
            &format!("{which}_nurbs_brep.igs"),
            &ImportOptions::default(),
        ),
        "step-analytic" => step_tool(&format!("{which}_analytic.step")),
        _ => step_tool(&format!("{which}_nurbs.step")),
    }
}

/// xorshift64*: deterministic points.
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let r = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        lo + (hi - lo) * ((r >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// Largest foot, normal and gap differences between the two surfaces at `points`.
fn worst_difference(a: &dyn RigidSurface, b: &dyn RigidSurface, points: &[Vec3]) -> [f64; 3] {
    worst_difference_within(a, b, points, 1e-8)
}

fn worst_difference_within(
    a: &dyn RigidSurface,
    b: &dyn RigidSurface,
    points: &[Vec3],
    tol: f64,
) -> [f64; 3] {
    let mut worst = [0.0f64; 3];
    for x in points {
        let (p, q): (Projection, Projection) = (
            a.project(x, None)
                .unwrap_or_else(|| panic!("no foot on {} for {x:?}", a.describe())),
            b.project(x, None)
                .unwrap_or_else(|| panic!("no foot on {} for {x:?}", b.describe())),
        );
        let d = [
            (p.foot - q.foot).norm(),
            (p.normal - q.normal).norm(),
            (p.gap - q.gap).abs(),
        ];
        for k in 0..3 {
            if d[k] > worst[k] {
                worst[k] = d[k];
            }
        }
        assert!(
            d.iter().all(|&e| e < tol),
            "x = {x:?}\n reference {q:?}\n imported  {p:?}"
        );
    }
    worst
}

/// Points at signed distance `[-2, 5]` mm along the reference surface's normal from random
/// surface points that `keep` accepts.
fn points_around(
    reference: &PatchSurface,
    n: usize,
    seed: u64,
    keep: impl Fn(&Vec3) -> bool,
) -> Vec<Vec3> {
    let mut rng = Rng(seed);
    let patches = reference.patches();
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let k = (rng.uniform(0.0, patches.len() as f64) as usize).min(patches.len() - 1);
        let e = patches[k].evaluate(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
        let Some(normal) = patches[k].normal(&e) else {
            continue;
        };
        if !keep(&e.point) {
            continue;
        }
        out.push(e.point + normal * rng.uniform(-2.0, 5.0));
    }
    out
}

#[test]
fn imported_punch_equals_the_bezier_builder() {
    for format in [
        "igs",
        "igs-analytic",
        "igs-brep",
        "igs-brep-nurbs",
        "step",
        "step-analytic",
    ] {
        punch_equals_the_builder(format);
    }
}

#[test]
fn imported_die_equals_the_bezier_builder_also_above_its_opening() {
    for format in ["igs", "igs-analytic", "igs-brep", "step", "step-analytic"] {
        die_equals_the_builder(format);
    }
}

fn punch_equals_the_builder(format: &str) {
    let imported = cad_tool(format, "punch");
    let spec = PunchSpec::numisheet93(0.0);
    let reference = PatchSurface::new(punch_patches(&spec, Extent::Full).unwrap()).unwrap();
    // The CAD punch is a closed solid (a top face at z = 58); the builder's wall is open
    // there: compare below z = 40.
    let points = points_around(&reference, 10_000, 91, |p| p.z < 40.0);
    // The punch's corner blends are spindle tori (major 2, minor 8), which OpenCascade's
    // STEP writer puts as a SURFACE_OF_REVOLUTION of a polynomial degree-6 B-spline that
    // approximates the profile arc to ~1.2e-7 mm: read exactly, it is the file's surface.
    let tol = if format == "step-analytic" {
        1e-6
    } else {
        1e-8
    };
    let worst = worst_difference_within(&imported, &reference, &points, tol);
    eprintln!("punch ({format}): worst foot, normal, gap differences {worst:?}");
    let seams = imported.seams();
    assert!(seams.worst_gap < tol, "{seams:?}");
}

fn die_equals_the_builder(format: &str) {
    let imported = cad_tool(format, "die");
    let reference =
        PatchSurface::new(die_patches(&DieSpec::numisheet93(), Extent::Full).unwrap()).unwrap();
    // The CAD die is a 160 x 160 block 58 deep; the builder's flat top ends at |x|, |y| = 80
    // and its wall at z = -58: compare away from the block's sides and bottom.
    let mut points = points_around(&reference, 10_000, 92, |p| {
        p.x.abs().max(p.y.abs()) < 70.0 && p.z > -40.0
    });
    // Above the opening, where the top face's untrimmed plane would give a foot straight
    // below: the trim sends it to the entry radius or the wall instead.
    let mut rng = Rng(93);
    for _ in 0..2_000 {
        points.push(Vec3::new(
            rng.uniform(-40.0, 40.0),
            rng.uniform(-40.0, 40.0),
            rng.uniform(0.2, 6.0),
        ));
    }
    let worst = worst_difference(&imported, &reference, &points);
    eprintln!("die ({format}): worst foot, normal, gap differences {worst:?}");
}

/// No foot of the die's top face lies inside its opening (the rounded square where the
/// entry radius starts: half side 37 + 8, plan corner 12 + 8), from any point.
#[test]
fn trimmed_faces_give_no_foot_outside_their_trims() {
    for format in ["igs", "igs-analytic", "igs-brep", "step", "step-analytic"] {
        no_foot_in_the_opening(format);
    }
}

fn no_foot_in_the_opening(format: &str) {
    let die = cad_tool(format, "die");
    let inside_opening = |p: &Vec3| {
        let (ax, ay, c) = (p.x.abs(), p.y.abs(), 25.0);
        ax < 45.0 && ay < 45.0 && (ax < c || ay < c || (ax - c).hypot(ay - c) < 20.0)
    };
    let mut rng = Rng(94);
    let mut on_top = 0;
    for _ in 0..10_000 {
        let x = Vec3::new(
            rng.uniform(-90.0, 90.0),
            rng.uniform(-90.0, 90.0),
            rng.uniform(-5.0, 10.0),
        );
        let p = die.project(&x, None).unwrap();
        if p.foot.z.abs() < 1e-12 {
            on_top += 1;
            assert!(
                !inside_opening(&Vec3::new(p.foot.x, p.foot.y, 0.0)) || {
                    let (ax, ay) = (p.foot.x.abs(), p.foot.y.abs());
                    // On the opening's rim (where the entry radius meets the top) both agree.
                    (ax.max(ay) - 45.0).abs() < 1e-7
                        || ((ax - 25.0).hypot(ay - 25.0) - 20.0).abs() < 1e-7
                },
                "x = {x:?}: foot {:?} on the top face inside its opening",
                p.foot
            );
        }
    }
    assert!(on_top > 1000, "{on_top} feet on the top face");
    // The same patches without their trims: points above the opening find the plane.
    let untrimmed = PatchSurface::new(die.patches().to_vec()).unwrap();
    let p = untrimmed.project(&Vec3::new(3.0, -4.0, 2.0), None).unwrap();
    assert!(inside_opening(&p.foot) && p.foot.z.abs() < 1e-12, "{p:?}");
}

#[test]
fn flip_reverses_normals_and_gaps() {
    let plain = iges_tool("punch_nurbs.igs", &ImportOptions::default());
    let flipped = iges_tool(
        "punch_nurbs.igs",
        &ImportOptions {
            flip: true,
            ..Default::default()
        },
    );
    for x in [
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(40.0, 3.0, 20.0),
        Vec3::new(33.0, 33.0, 2.0),
    ] {
        let (p, q) = (
            plain.project(&x, None).unwrap(),
            flipped.project(&x, None).unwrap(),
        );
        assert!(p.gap > 0.0, "{x:?} is outside the punch: {p:?}");
        assert!((p.gap + q.gap).abs() < 1e-12 && (p.normal + q.normal).norm() < 1e-12);
    }
    let moved = iges_tool(
        "punch_nurbs.igs",
        &ImportOptions {
            translate: Vec3::new(0.0, 0.0, 0.81),
            faces: None,
            flip: false,
            ..Default::default()
        },
    );
    let p = moved.project(&Vec3::new(1.0, 2.0, -1.0), None).unwrap();
    assert!((p.gap - 1.81).abs() < 1e-12, "{p:?}");
}

/// The global section's units: the same file in inches is 25.4 times larger.
#[test]
fn iges_units_come_from_the_global_section() {
    let (_, text) = data("punch_nurbs.igs");
    let inches = text.replacen(",1.,2,2HMM,", ",1.,1,2HIN,", 1);
    assert_ne!(inches, text);
    let mm = iges_tool("punch_nurbs.igs", &ImportOptions::default());
    let faces = faces_from_iges("punch_in.igs", &inches).unwrap();
    let big = tool_surface("punch_in.igs", faces, &ImportOptions::default()).unwrap();
    for x in [
        Vec3::new(1.0, 2.0, -1.0),
        Vec3::new(40.0, 3.0, 20.0),
        Vec3::new(33.0, 33.0, 2.0),
    ] {
        let (p, q) = (
            mm.project(&x, None).unwrap(),
            big.project(&(x * 25.4), None).unwrap(),
        );
        assert!((q.foot - p.foot * 25.4).norm() < 1e-9 && (q.gap - 25.4 * p.gap).abs() < 1e-9);
    }
    let bad = text.replacen(",1.,2,2HMM,", ",1.,0,2HMM,", 1);
    let e = faces_from_iges("bad_units.igs", &bad)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bad_units.igs:4: global parameter 14 (units flag) = 0 is not an IGES unit"),
        "{e}"
    );
}

type Reader = fn(&str, &str) -> tribo::Result<Vec<tribo::cad::Face>>;

/// The message refusing `text` as read by `read` (reading or making the tool).
fn refused_by(read: Reader, name: &str, text: &str) -> String {
    match read(name, text) {
        Ok(faces) => match tool_surface(name, faces, &ImportOptions::default()) {
            Ok(_) => panic!("{name} was accepted"),
            Err(e) => e.to_string(),
        },
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_files_are_refused_naming_what_and_where() {
    let (_, good) = data("punch_nurbs.igs");
    let lines: Vec<&str> = good.lines().collect();
    // Truncated: the last 300 lines lost.
    let cut = lines[..lines.len() - 300].join("\n");
    let e = refusal("cut.igs", &cut);
    assert!(
        e.contains(&format!(
            "cut.igs:{}: the file ends without its terminate (T) section: it is truncated",
            lines.len() - 300
        )),
        "{e}"
    );
    // A 144 whose surface pointer names a 126 curve (D line 11) instead of its 128.
    let p_line = lines
        .iter()
        .position(|l| l.starts_with("144,5,1,0,7;"))
        .unwrap();
    let mut wrong = lines.clone();
    let replaced = lines[p_line].replacen("144,5,1,0,7; ", "144,11,1,0,7;", 1);
    wrong[p_line] = &replaced;
    let e = refusal("wrong.igs", &wrong.join("\n"));
    assert!(
        e.contains("wrong.igs:")
            && e.contains("entity 144 (trimmed surface) at D line")
            && e.contains("its surface pointer names entity 126 (rational B-spline curve)"),
        "{e}"
    );
    // A damaged number in a surface's parameter data.
    let mut damaged = lines.clone();
    let p128 = lines
        .iter()
        .position(|l| l.starts_with("128,1,1,1,1,"))
        .unwrap();
    let bad = lines[p128].replacen("128,1,1,1,1,", "128,1,1,x,1,", 1);
    damaged[p128] = &bad;
    let e = refusal("damaged.igs", &damaged.join("\n"));
    assert!(
        e.contains(&format!(
            "damaged.igs:{}: entity 128 (rational B-spline surface)",
            p128 + 1
        )) && e.contains("parameter 3 (M1, degree in u) is not a number"),
        "{e}"
    );
    // A face on a surface type still not read: the first surface of revolution (120) of
    // the analytic punch made a ruled surface (118), in its directory entry and its data.
    let (_, analytic) = data("punch_analytic.igs");
    let lines: Vec<&str> = analytic.lines().collect();
    let d = lines
        .iter()
        .position(|l| l.starts_with("     120") && l.as_bytes()[72] == b'D')
        .unwrap();
    let p = lines
        .iter()
        .position(|l| l.starts_with("120,") && l.as_bytes()[72] == b'P')
        .unwrap();
    let (d118, p118) = (
        lines[d].replacen("     120", "     118", 1),
        lines[p].replacen("120,", "118,", 1),
    );
    let mut ruled = lines.clone();
    ruled[d] = &d118;
    ruled[p] = &p118;
    let e = refusal("ruled.igs", &ruled.join("\n"));
    assert!(
        e.contains(&format!(
            "ruled.igs:{}: entity 118 (ruled surface) at D line {}: this surface type is not read",
            d + 1,
            d + 1
        )) && e.contains("BRepBuilderAPI_NurbsConvert"),
        "{e}"
    );
    // A directory entry made a 510 BRep face (read since issue 49) over a 120's data: the
    // disagreement is named at the entity.
    let d510 = lines[d].replacen("     120", "     510", 1);
    let mut brep = lines.clone();
    brep[d] = &d510;
    let e = refusal("brep.igs", &brep.join("\n"));
    assert!(
        e.contains(&format!("entity 510 (face) at D line {}", d + 1))
            && e.contains("does not start with the entity type 510"),
        "{e}"
    );
    // Not IGES at all.
    let e = refusal("notes.igs", "punch and die\n");
    assert!(
        e.contains("notes.igs:1: not a fixed-format ASCII IGES line"),
        "{e}"
    );
    // A face index beyond the file's faces.
    let faces = faces_from_iges("punch_nurbs.igs", &good).unwrap();
    let count = faces.len();
    let e = tool_surface(
        "punch_nurbs.igs",
        faces,
        &ImportOptions {
            faces: Some(vec![count]),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains(&format!(
            "punch_nurbs.igs: face index = {count} must be < the file's face count {count}"
        )),
        "{e}"
    );
}

fn refusal(name: &str, text: &str) -> String {
    refused_by(faces_from_iges, name, text)
}

fn step_refusal(name: &str, text: &str) -> String {
    refused_by(faces_from_step, name, text)
}

#[test]
fn bad_step_files_are_refused_naming_what_and_where() {
    let (_, good) = data("punch_nurbs.step");
    let lines: Vec<&str> = good.lines().collect();
    let cut = lines[..lines.len() / 2].join("\n");
    let e = step_refusal("cut.step", &cut);
    assert!(e.contains("cut.step:") && e.contains("truncated"), "{e}");
    // The first face's surface reference pointing at one of its points instead.
    let face_line = lines
        .iter()
        .position(|l| l.starts_with("#17 = ADVANCED_FACE("))
        .unwrap();
    let mut wrong = lines.clone();
    let replaced = lines[face_line].replacen(",#31,", ",#32,", 1);
    wrong[face_line] = &replaced;
    let e = step_refusal("wrong.step", &wrong.join("\n"));
    assert!(
        e.contains(&format!("wrong.step:{}: #17 (ADVANCED_FACE): its surface #32 is a CARTESIAN_POINT, which is not read", face_line + 1)),
        "{e}"
    );
    // A surface kind that is not read, named with the kinds that are.
    let (_, analytic) = data("punch_analytic.step");
    let face_line = 1 + analytic
        .lines()
        .position(|l| l.starts_with("#17 = ADVANCED_FACE("))
        .unwrap();
    let unread = analytic.replacen(
        "#32 = PLANE('',#33);",
        "#32 = CURVE_BOUNDED_SURFACE('',#33);",
        1,
    );
    let e = step_refusal("punch_analytic.step", &unread);
    assert!(
        e.contains(&format!("punch_analytic.step:{}: #17 (ADVANCED_FACE): its surface #32 is a CURVE_BOUNDED_SURFACE, which is not read (read: PLANE, CYLINDRICAL_SURFACE", face_line)),
        "{e}"
    );
    let e = step_refusal("notes.step", "punch and die\n");
    assert!(e.contains("notes.step:1: no DATA section"), "{e}");
}

/// The punch placed in an assembly (tests/data/cad/punch_assembly.step: OCC's XCAF writer,
/// the part rotated by 30 degrees about z then moved by (5, -3, 2.5)) imports at that pose:
/// it equals the builder's punch moved the same way, at 10^4 points.
#[test]
fn a_part_placed_in_a_step_assembly_imports_at_its_pose() {
    let imported = step_tool("punch_assembly.step");
    let (s, c) = 30f64.to_radians().sin_cos();
    let rotation = tribo::geometry::Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    let shift = Vec3::new(5.0, -3.0, 2.5);
    let placed: Vec<_> = punch_patches(&PunchSpec::numisheet93(0.0), Extent::Full)
        .unwrap()
        .iter()
        .map(|p| p.transformed(&rotation, &shift))
        .collect();
    let reference = PatchSurface::new(placed).unwrap();
    let points = points_around(&reference, 10_000, 95, |p| p.z < 40.0 + 2.5);
    let worst = worst_difference(&imported, &reference, &points);
    eprintln!("punch placed in an assembly (step): worst foot, normal, gap {worst:?}");
    // The part's own faces, unplaced, are elsewhere.
    let unplaced = step_tool("punch_nurbs.step");
    let x = Vec3::new(40.0, 0.0, 20.0);
    let (a, b) = (
        imported.project(&x, None).unwrap(),
        unplaced.project(&x, None).unwrap(),
    );
    assert!((a.foot - b.foot).norm() > 1.0, "{a:?} {b:?}");
}

/// A 190 plane surface (location 116 `(0, 0, 5)`, normal 123 `(0, 0, 2)`) trimmed by a
/// square of model-space 110 lines (`|x|, |y| <= 10`): read as a 108 plane is, the exact
/// plane `z = 5` inside the square (foot, normal and gap to round-off), no foot outside.
#[test]
fn a_190_plane_surface_trimmed_by_a_square_is_the_exact_plane() {
    let plane = iges_tool("plane_surface_190.igs", &ImportOptions::default());
    let mut rng = Rng(190);
    let (mut inside, mut outside) = (0, 0);
    for _ in 0..2000 {
        let x = Vec3::new(
            rng.uniform(-15.0, 15.0),
            rng.uniform(-15.0, 15.0),
            rng.uniform(-3.0, 12.0),
        );
        let within = x.x.abs() < 10.0 - 1e-9 && x.y.abs() < 10.0 - 1e-9;
        match plane.project(&x, None) {
            Some(p) if within => {
                inside += 1;
                assert!(
                    (p.foot - Vec3::new(x.x, x.y, 5.0)).norm() < 1e-12,
                    "{x:?} {p:?}"
                );
                assert!((p.normal - Vec3::z()).norm() < 1e-12, "{x:?} {p:?}");
                assert!((p.gap - (x.z - 5.0)).abs() < 1e-12, "{x:?} {p:?}");
            }
            // Outside the square: no foot, or one on its rim (the closest trimmed point).
            Some(p) => {
                let rim = p.foot.x.abs().max(p.foot.y.abs());
                assert!(
                    (rim - 10.0).abs() < 1e-9,
                    "x = {x:?}: foot {:?} off the rim",
                    p.foot
                );
                outside += 1;
            }
            None => {
                assert!(!within, "x = {x:?}: no foot inside the square");
                outside += 1;
            }
        }
    }
    assert!(
        inside > 500 && outside > 500,
        "{inside} inside, {outside} outside"
    );
}

/// 122 tabulated cylinders (generatrix `(0, 0, 20)`) trimmed in IGES's normalised `(u, v)`
/// by `[0.25, 0.75]^2`: from a 110 line `x = -10 + 20 u` (the plane `y = 0`, trim
/// `|x| <= 5`) and from a 100 half circle of radius 10 (angle `pi u`, trim `pi/4..3pi/4`),
/// both `z` in `[5, 15]`. Inside the trim the foot is the exact surface's (foot, normal and
/// gap to 1e-12); every foot lies on the exact surface inside the trim.
#[test]
fn a_122_tabulated_cylinder_is_the_exact_extrusion_trimmed_in_normalised_parameters() {
    use std::f64::consts::PI;
    for name in ["line", "arc"] {
        let tool = iges_tool(
            &format!("tabulated_cylinder_122_{name}.igs"),
            &ImportOptions::default(),
        );
        // (exact foot, whether it lies inside the trim) of a point.
        let exact = |x: &Vec3| -> (Vec3, bool) {
            let z_in = (5.0..=15.0).contains(&x.z);
            if name == "line" {
                (Vec3::new(x.x, 0.0, x.z), z_in && x.x.abs() <= 5.0)
            } else {
                let r = x.x.hypot(x.y);
                let a = x.y.atan2(x.x);
                (
                    Vec3::new(10.0 * x.x / r, 10.0 * x.y / r, x.z),
                    z_in && (PI / 4.0..=3.0 * PI / 4.0).contains(&a),
                )
            }
        };
        let mut rng = Rng(122);
        let (mut inside, mut feet) = (0, 0);
        for _ in 0..2000 {
            let x = if name == "line" {
                Vec3::new(
                    rng.uniform(-9.0, 9.0),
                    rng.uniform(-3.0, 3.0),
                    rng.uniform(0.0, 20.0),
                )
            } else {
                let (r, a) = (rng.uniform(6.0, 14.0), rng.uniform(0.0, PI));
                Vec3::new(r * a.cos(), r * a.sin(), rng.uniform(0.0, 20.0))
            };
            let (foot, within) = exact(&x);
            let margin = exact(&(x + Vec3::new(1e-7, 1e-7, 1e-7))).1
                == exact(&(x - Vec3::new(1e-7, 1e-7, 1e-7))).1;
            match tool.project(&x, None) {
                Some(p) => {
                    feet += 1;
                    let (on, in_trim) = exact(&p.foot);
                    assert!(
                        (on - p.foot).norm() < 1e-12,
                        "{name}: foot {:?} off",
                        p.foot
                    );
                    let rim =
                        exact(&(p.foot * (1.0 + 1e-9))).1 || exact(&(p.foot * (1.0 - 1e-9))).1;
                    assert!(
                        in_trim || rim,
                        "{name}: x = {x:?}: foot {:?} outside the trim",
                        p.foot
                    );
                    assert!(
                        (p.normal.norm() - 1.0).abs() < 1e-12
                            && (x - p.foot - p.normal * p.gap).norm() < 1e-12,
                        "{name}: x = {x:?}: {p:?}"
                    );
                    if within && margin {
                        inside += 1;
                        assert!((p.foot - foot).norm() < 1e-12, "{name}: x = {x:?}: {p:?}");
                    }
                }
                None => assert!(
                    !(within && margin),
                    "{name}: x = {x:?}: no foot in the trim"
                ),
            }
        }
        assert!(
            inside > 200 && feet >= inside,
            "{name}: {inside} inside, {feet} feet"
        );
    }
}
