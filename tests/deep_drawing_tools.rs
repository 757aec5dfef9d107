//! The deep-drawing tool builders make exact surfaces: the rounded-square punch and the die
//! with a rounded-square opening (NUMISHEET'93 square-cup dimensions) have seams without
//! gap or kink, and their projection equals the analytic distance to the tool solid.
//!
//! The analytic solids are offsets of prisms: the punch is the set of points within the
//! nose radius `r_n` of the prism `{plan in RS(h - r_n, r_c - r_n), z >= z0 + r_n}`, the die
//! the set within the entry radius `r_e` of `{plan outside RS(h + r_e, r_c + r_e),
//! z <= z0 - r_e}` (RS(h, r): rounded square of half side h, corner radius r). The signed
//! distance of a prism is exact from the plan and axial distances, so the tool's signed
//! distance is that minus the radius.

use tribo::geometry::builders::{
    blankholder_patches, die_patches, punch_patches, BlankholderSpec, DieSpec, Extent, PunchSpec,
};
use tribo::geometry::{PatchSurface, RigidSurface, Vec3};

const T: f64 = 0.81;

fn punch_spec() -> PunchSpec {
    PunchSpec::numisheet93(T)
}

fn die_spec() -> DieSpec {
    DieSpec::numisheet93()
}

/// Signed distance from plan point `(x, y)` to the rounded square RS(h, r) (< 0 inside).
fn rounded_square_sdf(x: f64, y: f64, h: f64, r: f64) -> f64 {
    let (qx, qy) = (x.abs() - (h - r), y.abs() - (h - r));
    let outside = (qx.max(0.0).powi(2) + qy.max(0.0).powi(2)).sqrt();
    outside + qx.max(qy).min(0.0) - r
}

/// Signed distance to a prism from its plan and axial signed distances (> 0 outside).
fn prism_sdf(plan: f64, axial: f64) -> f64 {
    (plan.max(0.0).powi(2) + axial.max(0.0).powi(2)).sqrt() + plan.max(axial).min(0.0)
}

fn punch_sdf(p: &Vec3) -> f64 {
    let s = punch_spec();
    let (h, rc, rn) = (0.5 * s.side, s.plan_corner_radius, s.nose_radius);
    let plan = rounded_square_sdf(p.x, p.y, h - rn, rc - rn);
    prism_sdf(plan, s.level + rn - p.z) - rn
}

fn die_sdf(p: &Vec3) -> f64 {
    let s = die_spec();
    let (h, rc, re) = (0.5 * s.opening_side, s.plan_corner_radius, s.entry_radius);
    let plan = -rounded_square_sdf(p.x, p.y, h + re, rc + re);
    prism_sdf(plan, p.z - (s.level - re)) - re
}

/// Deterministic uniform numbers (xorshift64*).
struct Rng(u64);
impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        lo + (hi - lo) * (bits as f64 / (1u64 << 53) as f64)
    }
}

/// 10^4 points in `box_lo..box_hi` with analytic signed distance in `band`: the surface's
/// gap equals it to 1e-10, and the foot lies on the analytic surface. Returns how many
/// points were inside the tool (gap < 0).
fn assert_matches_solid(
    surface: &PatchSurface,
    sdf: &dyn Fn(&Vec3) -> f64,
    box_lo: Vec3,
    box_hi: Vec3,
    band: (f64, f64),
    seed: u64,
) -> usize {
    let mut rng = Rng(seed);
    let (mut count, mut inside) = (0, 0);
    let mut hint = None;
    while count < 10_000 {
        let x = Vec3::new(
            rng.uniform(box_lo.x, box_hi.x),
            rng.uniform(box_lo.y, box_hi.y),
            rng.uniform(box_lo.z, box_hi.z),
        );
        let d = sdf(&x);
        if d < band.0 || d > band.1 {
            continue;
        }
        count += 1;
        let p = surface.project(&x, None).expect("projection defined");
        // Round-off of the Newton foot and of the sdf formulas at coordinates ~50: 1e-10.
        assert!(
            (p.gap - d).abs() < 1e-10,
            "x = {x:?}: gap {} vs analytic {d}",
            p.gap
        );
        assert!(sdf(&p.foot).abs() < 1e-10, "foot off the analytic surface");
        assert!(((x - p.foot) - p.normal * p.gap).norm() < 1e-10);
        // A warm start from the previous point's foot (often another patch) agrees.
        let warm = surface.project(&x, hint.as_ref()).unwrap();
        assert!((warm.gap - d).abs() < 1e-10 && (warm.normal - p.normal).norm() < 1e-9);
        hint = Some(p.hint);
        if d < 0.0 {
            inside += 1;
        }
    }
    inside
}

#[test]
fn punch_is_the_exact_rounded_square_punch() {
    for (extent, lo) in [
        (Extent::Full, Vec3::new(-40.0, -40.0, T - 3.0)),
        (
            Extent::Quarter { margin: 5.0 },
            Vec3::new(0.0, 0.0, T - 3.0),
        ),
    ] {
        let surface = PatchSurface::new(punch_patches(&punch_spec(), extent).unwrap()).unwrap();
        let r = surface.seams();
        println!(
            "punch {extent:?}: {} patches, {r:?}",
            surface.patches().len()
        );
        // Exact geometry: seams agree to round-off (coordinates ~50, 1e-16 relative).
        assert!(r.worst_kink < 1e-8, "normal jump {}", r.worst_kink);
        assert!(r.worst_gap < 1e-10, "gap {}", r.worst_gap);
        // Nose and wall below z0 + 20, away from the open top; depth inside up to 1 mm
        // (the projection is unique there), up to 5 mm outside.
        let inside = assert_matches_solid(
            &surface,
            &punch_sdf,
            lo,
            Vec3::new(40.0, 40.0, T + 20.0),
            (-1.0, 5.0),
            11,
        );
        assert!(inside > 500, "too few points inside the punch: {inside}");
    }
}

#[test]
fn die_is_the_exact_die_with_rounded_square_opening() {
    for (extent, lo) in [
        (Extent::Full, Vec3::new(-70.0, -70.0, -20.0)),
        (Extent::Quarter { margin: 5.0 }, Vec3::new(0.0, 0.0, -20.0)),
    ] {
        let surface = PatchSurface::new(die_patches(&die_spec(), extent).unwrap()).unwrap();
        let r = surface.seams();
        println!("die {extent:?}: {} patches, {r:?}", surface.patches().len());
        assert!(r.worst_kink < 1e-8, "normal jump {}", r.worst_kink);
        assert!(r.worst_gap < 1e-10, "gap {}", r.worst_gap);
        // Within 2 mm of the die (entry radius 8, opening wall radius 12 at its corners:
        // the projection is unique), flat top out to 70 of 80, wall down to -20 of -58.
        let inside = assert_matches_solid(
            &surface,
            &die_sdf,
            lo,
            Vec3::new(70.0, 70.0, 5.0),
            (-2.0, 2.0),
            12,
        );
        assert!(inside > 2000, "too few points inside the die: {inside}");
    }
}

#[test]
fn blankholder_is_flat_with_its_opening() {
    let spec = BlankholderSpec::numisheet93(T);
    let surface = PatchSurface::new(blankholder_patches(&spec, Extent::Full).unwrap()).unwrap();
    assert!(surface.seams().worst_kink < 1e-12 && surface.seams().worst_gap < 1e-12);
    let mut rng = Rng(13);
    let mut checked = 0;
    for _ in 0..2000 {
        let x = Vec3::new(
            rng.uniform(-79.0, 79.0),
            rng.uniform(-79.0, 79.0),
            rng.uniform(T - 2.0, T + 0.5),
        );
        if rounded_square_sdf(x.x, x.y, 45.0, 20.0) < 1e-6 {
            continue; // over the opening: the foot is on the open edge
        }
        let p = surface.project(&x, None).unwrap();
        assert!((p.gap - (T - x.z)).abs() < 1e-12 && (p.normal + Vec3::z()).norm() < 1e-15);
        checked += 1;
    }
    assert!(checked > 1000);
    // Over the opening the rounded edge keeps the sheet outside the holder, even at or above
    // the face level (an open, sharp edge would judge such a point inside): the gap is the
    // distance to the edge's torus/cylinder, whose tube centre line is 5 mm above the face at
    // the flat's boundary (half side 45, plan corner 20).
    for (x, y, z) in [
        (42.0, 0.0, T),
        (42.0, 10.0, T + 0.3),
        (38.0, 38.0, T + 0.2),
        (0.0, 43.0, T - 0.1),
    ] {
        let p = surface.project(&Vec3::new(x, y, z), None).unwrap();
        let d = rounded_square_sdf(x, y, 45.0, 20.0); // < 0: plan distance inside the boundary
        let expected = (d * d + (T + 5.0 - z).powi(2)).sqrt() - 5.0;
        assert!(
            p.gap > 0.0 && (p.gap - expected).abs() < 1e-9,
            "({x}, {y}, {z}): gap {} expected {expected}",
            p.gap
        );
    }
}

/// The bounding-volume hierarchy only prunes: projections with and without it agree (foot,
/// normal, gap to round-off of equal-distance ties between overlapping flat patches) for
/// 10^4 random points around the full die, cold and warm started.
#[test]
fn bvh_gives_the_same_projections_as_the_full_search() {
    let patches = die_patches(&die_spec(), Extent::Full).unwrap();
    let with = PatchSurface::new(patches.clone()).unwrap();
    let without = PatchSurface::new(patches).unwrap().without_bvh();
    let mut rng = Rng(21);
    let mut hint = None;
    for _ in 0..10_000 {
        let x = Vec3::new(
            rng.uniform(-85.0, 85.0),
            rng.uniform(-85.0, 85.0),
            rng.uniform(-60.0, 10.0),
        );
        let previous = hint;
        for h in [None, previous.as_ref()] {
            let (a, b) = (with.project(&x, h), without.project(&x, h));
            match (a, b) {
                (Some(a), Some(b)) => {
                    assert!(
                        (a.foot - b.foot).norm() < 1e-12
                            && (a.normal - b.normal).norm() < 1e-12
                            && (a.gap - b.gap).abs() < 1e-12,
                        "x = {x:?}: {a:?} vs {b:?}"
                    );
                    hint = Some(a.hint);
                }
                (None, None) => {}
                _ => panic!("defined with one search only at {x:?}"),
            }
        }
    }
}

/// The 26-DOP test only skips patches that cannot hold a closer foot: projections with and
/// without it are identical, bit for bit (foot, normal, gap, normal gradient, patch and
/// parameters), for 10^4 random points around each of the quarter punch, die and blankholder
/// the square cup uses, and the full die, cold and warm started.
#[test]
fn hull_test_skips_no_closer_patch() {
    let tools = [
        punch_patches(&punch_spec(), Extent::Quarter { margin: 2.0 }).unwrap(),
        die_patches(&die_spec(), Extent::Quarter { margin: 2.0 }).unwrap(),
        blankholder_patches(
            &BlankholderSpec::numisheet93(0.81),
            Extent::Quarter { margin: 2.0 },
        )
        .unwrap(),
        die_patches(&die_spec(), Extent::Full).unwrap(),
    ];
    let mut rng = Rng(33);
    for patches in tools {
        let with = PatchSurface::new(patches.clone()).unwrap();
        let without = PatchSurface::new(patches).unwrap().without_hulls();
        let mut hint = None;
        let mut defined = 0;
        for _ in 0..10_000 {
            let x = Vec3::new(
                rng.uniform(-85.0, 85.0),
                rng.uniform(-85.0, 85.0),
                rng.uniform(-60.0, 40.0),
            );
            let previous = hint;
            for h in [None, previous.as_ref()] {
                match (with.project(&x, h), without.project(&x, h)) {
                    (Some(a), Some(b)) => {
                        assert!(
                            a.foot == b.foot
                                && a.normal == b.normal
                                && a.gap == b.gap
                                && a.normal_gradient == b.normal_gradient
                                && a.hint == b.hint,
                            "x = {x:?}: {a:?} vs {b:?}"
                        );
                        hint = Some(a.hint);
                        defined += 1;
                    }
                    (None, None) => {}
                    _ => panic!("defined with one search only at {x:?}"),
                }
            }
        }
        assert!(defined > 15_000, "{defined}");
    }
}
