//! Deep-drawing tools made of exact rational Bézier patches: a rounded-square punch, a die
//! with a rounded-square opening, a flat blankholder with an opening.
//!
//! All three are symmetric under a quarter turn about the z axis, so each builder makes the
//! pieces of the plan quadrant `x >= 0, y >= 0` and either turns copies of them about z
//! ([`Extent::Full`]) or extends the straight pieces by a margin past the symmetry planes
//! `x = 0` and `y = 0` ([`Extent::Quarter`]), so that nodes on those planes project into
//! patch interiors instead of onto open edges.
//!
//! Profiles are exact: straight walls are bilinear patches, edge radii along straight sides
//! are cylinder pieces (degree 2 x 1), radii along plan corners are torus pieces (2 x 2).
//! A flat region with a rounded boundary is covered without degenerate patches by
//! overlapping flat patches: two rectangles, and in the corner a ruled degree 2 x 1 patch
//! between the corner arc and a straight segment written as a rational quadratic with the
//! arc's weights. The segment is placed so that the patch is regular (no ruling tangent to
//! the arc) and lies inside the rectangles' union except for the corner region it has to
//! cover. Overlapping coplanar patches share plane and normal, so the projection is the
//! same whichever one answers.
//!
//! Conventions (the square-cup script uses them): the sheet lies between `z = 0` and
//! `z = t`. The die is below it (flat top at `z = level`, outward normal `+z`, opening
//! going down), the punch above it (flat nose at `z = level`, outward normal `-z`), the
//! blankholder above the flange (flat face at `z = level`, normal `-z`).

use super::bezier::BezierPatch;
use super::*;
use crate::{Error, Result};
use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};

/// Whole tool, or the quadrant `x >= 0, y >= 0` extended by `margin` past `x = 0`, `y = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extent {
    Full,
    Quarter { margin: f64 },
}

impl Extent {
    /// Where the straight pieces start: `-margin` for a quarter, `0` for the full tool.
    fn start(&self) -> Result<f64> {
        match *self {
            Extent::Full => Ok(0.0),
            Extent::Quarter { margin } if margin.is_finite() && margin >= 0.0 => Ok(-margin),
            Extent::Quarter { margin } => {
                Err(Error::input("quarter tool margin", margin, "must be >= 0"))
            }
        }
    }

    /// The quadrant's pieces, turned about z by 90°, 180°, 270° for the full tool.
    fn complete(&self, quadrant: Vec<BezierPatch>) -> Vec<BezierPatch> {
        match self {
            Extent::Quarter { .. } => quadrant,
            Extent::Full => {
                let mut all = quadrant.clone();
                for k in 1..4 {
                    let (s, c) = match k {
                        1 => (1.0, 0.0),
                        2 => (0.0, -1.0),
                        _ => (-1.0, 0.0),
                    };
                    let r = Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
                    all.extend(quadrant.iter().map(|p| p.transformed(&r, &Vec3::zeros())));
                }
                all
            }
        }
    }
}

/// Rounded-square punch: nose flat at `z = level` (normal `-z`), nose profile radius,
/// plan corner radius, then a vertical wall of height `wall_height` above the profile
/// radius.
#[derive(Clone, Copy, Debug)]
pub struct PunchSpec {
    pub side: f64,
    pub plan_corner_radius: f64,
    pub nose_radius: f64,
    pub wall_height: f64,
    pub level: f64,
}

/// Die with a rounded-square opening: flat top at `z = level` (normal `+z`) from the entry
/// radius out to `|x|, |y| <= flat_extent`, entry profile radius, then a vertical wall of
/// depth `wall_depth` below the entry radius.
#[derive(Clone, Copy, Debug)]
pub struct DieSpec {
    pub opening_side: f64,
    pub plan_corner_radius: f64,
    pub entry_radius: f64,
    pub flat_extent: f64,
    pub wall_depth: f64,
    pub level: f64,
}

/// Flat blankholder at `z = level` (normal `-z`) with a rounded-square opening, out to
/// `|x|, |y| <= flat_extent`. The opening's edge is an open (sharp) edge.
#[derive(Clone, Copy, Debug)]
pub struct BlankholderSpec {
    pub opening_side: f64,
    pub plan_corner_radius: f64,
    pub flat_extent: f64,
    pub level: f64,
}

impl PunchSpec {
    /// NUMISHEET'93 square cup punch (side 70, plan corner 10, nose radius 8, mm) with 50 mm
    /// of wall, nose at `z = thickness` (on a sheet lying on `z = 0`).
    pub fn numisheet93(thickness: f64) -> PunchSpec {
        PunchSpec {
            side: 70.0,
            plan_corner_radius: 10.0,
            nose_radius: 8.0,
            wall_height: 50.0,
            level: thickness,
        }
    }
}

impl DieSpec {
    /// NUMISHEET'93 die (opening 74, plan corner 12, entry radius 8, mm), top at `z = 0`,
    /// flat to 80 mm from the centre (the blank's half side is 75), 50 mm of wall.
    pub fn numisheet93() -> DieSpec {
        DieSpec {
            opening_side: 74.0,
            plan_corner_radius: 12.0,
            entry_radius: 8.0,
            flat_extent: 80.0,
            wall_depth: 50.0,
            level: 0.0,
        }
    }
}

impl BlankholderSpec {
    /// Blankholder over the NUMISHEET'93 die's flat top: opening 74 + 2 x 8 = 90 with plan
    /// corner 12 + 8 = 20 (where the entry radius ends), face at `z = thickness`.
    pub fn numisheet93(thickness: f64) -> BlankholderSpec {
        BlankholderSpec {
            opening_side: 90.0,
            plan_corner_radius: 20.0,
            flat_extent: 80.0,
            level: thickness,
        }
    }
}

fn finite(what: &str, v: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::input(what, v, "must be finite"))
    }
}

/// `a < b` with a message naming both.
fn require_less(what_a: &str, a: f64, what_b: &str, b: f64) -> Result<()> {
    if a < b {
        Ok(())
    } else {
        Err(Error::input(
            what_a,
            a,
            &format!("must be < {what_b} = {b}"),
        ))
    }
}

/// Flat patch over `[x0, x1] x [y0, y1]` at height `z` with normal `normal_z * e_z`.
fn rectangle(x: [f64; 2], y: [f64; 2], z: f64, normal_z: f64) -> Result<BezierPatch> {
    let p = BezierPatch::parallelogram(
        Vec3::new(x[0], y[0], z),
        Vec3::new(x[1] - x[0], 0.0, 0.0),
        Vec3::new(0.0, y[1] - y[0], 0.0),
    )?;
    Ok(p.oriented(&Vec3::new(0.0, 0.0, normal_z)))
}

/// Ruled flat patch (degree 2 x 1) at height `z` between the quarter arc of radius `r`
/// around `(c, c)` (from `(c + r, c)` to `(c, c + r)`) and the segment from `c + a` to
/// `c + b` (plan offsets), parametrised with the arc's weights.
fn corner_filler(
    c: f64,
    r: f64,
    a: [f64; 2],
    b: [f64; 2],
    z: f64,
    normal_z: f64,
) -> Result<BezierPatch> {
    let at = |dx: f64, dy: f64| Vec3::new(c + dx, c + dy, z);
    let arc = [at(r, 0.0), at(r, r), at(0.0, r)];
    let line = [
        at(a[0], a[1]),
        at(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])),
        at(b[0], b[1]),
    ];
    let w = [1.0, FRAC_1_SQRT_2, 1.0];
    let mut points = Vec::new();
    let mut weights = Vec::new();
    for i in 0..3 {
        points.push(arc[i]);
        points.push(line[i]);
        weights.extend([w[i], w[i]]);
    }
    Ok(BezierPatch::new(2, 1, points, weights)?.oriented(&Vec3::new(0.0, 0.0, normal_z)))
}

/// Quadrant of the flat region inside a rounded square of half side `half` and corner
/// radius `r`, from `start` (<= 0) on, at height `z`.
fn flat_inside(half: f64, r: f64, start: f64, z: f64, normal_z: f64) -> Result<Vec<BezierPatch>> {
    if r == 0.0 {
        return Ok(vec![rectangle([start, half], [start, half], z, normal_z)?]);
    }
    let c = half - r;
    // The filler's segment ends at (c + r/2, c - r) and (c - r, c + r/2): inside the
    // rectangles if c - r >= start.
    if c - r < start {
        return Err(Error::input(
            "flat region corner radius",
            r,
            &format!("must be <= half its half side {half} (the corner filler needs room)"),
        ));
    }
    Ok(vec![
        rectangle([start, half], [start, c], z, normal_z)?,
        rectangle([start, c], [start, half], z, normal_z)?,
        corner_filler(c, r, [0.5 * r, -r], [-r, 0.5 * r], z, normal_z)?,
    ])
}

/// Quadrant of the flat region outside a rounded square (half side `half`, corner radius
/// `r`) and inside `|x|, |y| <= extent`, from `start` on, at height `z`.
fn flat_outside(
    half: f64,
    r: f64,
    extent: f64,
    start: f64,
    z: f64,
    normal_z: f64,
) -> Result<Vec<BezierPatch>> {
    // The corner filler's segment reaches out to half + r/2.
    let reach = half + 0.5 * r;
    if extent <= reach {
        return Err(Error::input(
            "flat extent",
            extent,
            &format!("must be > {reach} (the opening's half side + half its corner radius)"),
        ));
    }
    let mut patches = vec![
        rectangle([half, extent], [start, extent], z, normal_z)?,
        rectangle([start, extent], [half, extent], z, normal_z)?,
    ];
    if r > 0.0 {
        let c = half - r;
        patches.push(corner_filler(
            c,
            r,
            [1.5 * r, r],
            [r, 1.5 * r],
            z,
            normal_z,
        )?);
    }
    Ok(patches)
}

fn check_positive(pairs: &[(&str, f64)]) -> Result<()> {
    for (what, v) in pairs {
        positive_length(what, *v)?;
    }
    Ok(())
}

/// Patches of a rounded-square punch (see [`PunchSpec`]). The plan corner radius must
/// exceed the nose radius (the nose corner is a torus with tube-centre radius
/// `plan_corner - nose`), and the side must exceed twice the plan corner radius.
pub fn punch_patches(spec: &PunchSpec, extent: Extent) -> Result<Vec<BezierPatch>> {
    let PunchSpec {
        side,
        plan_corner_radius: rc,
        nose_radius: rn,
        wall_height,
        level: z0,
    } = *spec;
    check_positive(&[
        ("punch side", side),
        ("punch plan corner radius", rc),
        ("punch nose radius", rn),
        ("punch wall height", wall_height),
    ])?;
    finite("punch level", z0)?;
    require_less("punch nose radius", rn, "the plan corner radius", rc)?;
    let half = 0.5 * side;
    require_less("punch plan corner radius", rc, "half the side", half)?;
    let y0 = extent.start()?;
    let k = half - rc;
    let length = k - y0;
    let mut q = flat_inside(half - rn, rc - rn, y0, z0, -1.0)?;
    // Nose radius along the sides: from -z round to the outward side normal.
    q.push(BezierPatch::quarter_cylinder(
        Vec3::new(half - rn, k, z0 + rn),
        -Vec3::y(),
        -Vec3::z(),
        0.0,
        rn,
        length,
    )?);
    q.push(BezierPatch::quarter_cylinder(
        Vec3::new(y0, half - rn, z0 + rn),
        Vec3::x(),
        -Vec3::z(),
        0.0,
        rn,
        length,
    )?);
    // Nose radius at the plan corner: the outer lower quarter of the tube.
    q.push(BezierPatch::quarter_torus(
        Vec3::new(k, k, z0 + rn),
        Vec3::z(),
        Vec3::x(),
        0.0,
        -FRAC_PI_2,
        rc - rn,
        rn,
    )?);
    let top = z0 + rn;
    q.push(
        BezierPatch::parallelogram(
            Vec3::new(half, y0, top),
            Vec3::new(0.0, length, 0.0),
            Vec3::new(0.0, 0.0, wall_height),
        )?
        .oriented(&Vec3::x()),
    );
    q.push(
        BezierPatch::parallelogram(
            Vec3::new(y0, half, top),
            Vec3::new(length, 0.0, 0.0),
            Vec3::new(0.0, 0.0, wall_height),
        )?
        .oriented(&Vec3::y()),
    );
    q.push(BezierPatch::quarter_cylinder(
        Vec3::new(k, k, top),
        Vec3::z(),
        Vec3::x(),
        0.0,
        rc,
        wall_height,
    )?);
    Ok(extent.complete(q))
}

/// Patches of a die with a rounded-square opening (see [`DieSpec`]).
pub fn die_patches(spec: &DieSpec, extent: Extent) -> Result<Vec<BezierPatch>> {
    let DieSpec {
        opening_side,
        plan_corner_radius: rc,
        entry_radius: re,
        flat_extent,
        wall_depth,
        level: z0,
    } = *spec;
    check_positive(&[
        ("die opening side", opening_side),
        ("die plan corner radius", rc),
        ("die entry radius", re),
        ("die flat extent", flat_extent),
        ("die wall depth", wall_depth),
    ])?;
    finite("die level", z0)?;
    let half = 0.5 * opening_side;
    require_less("die plan corner radius", rc, "half the opening side", half)?;
    let y0 = extent.start()?;
    let k = half - rc;
    let length = k - y0;
    let mut q = flat_outside(half + re, rc + re, flat_extent, y0, z0, 1.0)?;
    // Entry radius along the sides: from the opening (-x or -y) round to +z.
    q.push(BezierPatch::quarter_cylinder(
        Vec3::new(half + re, y0, z0 - re),
        Vec3::y(),
        -Vec3::x(),
        0.0,
        re,
        length,
    )?);
    q.push(BezierPatch::quarter_cylinder(
        Vec3::new(k, half + re, z0 - re),
        -Vec3::x(),
        -Vec3::y(),
        0.0,
        re,
        length,
    )?);
    // Entry radius at the plan corner: the inner (saddle) upper quarter of the tube,
    // minor angle from +z (90°) to towards the axis (180°).
    q.push(BezierPatch::quarter_torus(
        Vec3::new(k, k, z0 - re),
        Vec3::z(),
        Vec3::x(),
        0.0,
        FRAC_PI_2,
        rc + re,
        re,
    )?);
    let bottom = z0 - re - wall_depth;
    q.push(
        BezierPatch::parallelogram(
            Vec3::new(half, y0, bottom),
            Vec3::new(0.0, length, 0.0),
            Vec3::new(0.0, 0.0, wall_depth),
        )?
        .oriented(&-Vec3::x()),
    );
    q.push(
        BezierPatch::parallelogram(
            Vec3::new(y0, half, bottom),
            Vec3::new(length, 0.0, 0.0),
            Vec3::new(0.0, 0.0, wall_depth),
        )?
        .oriented(&-Vec3::y()),
    );
    // The opening's corner wall faces its axis.
    q.push(
        BezierPatch::quarter_cylinder(
            Vec3::new(k, k, bottom),
            Vec3::z(),
            Vec3::x(),
            0.0,
            rc,
            wall_depth,
        )?
        .flipped(),
    );
    Ok(extent.complete(q))
}

/// Patches of a flat blankholder with a rounded-square opening (see [`BlankholderSpec`]).
pub fn blankholder_patches(spec: &BlankholderSpec, extent: Extent) -> Result<Vec<BezierPatch>> {
    let BlankholderSpec {
        opening_side,
        plan_corner_radius: rc,
        flat_extent,
        level: z0,
    } = *spec;
    check_positive(&[
        ("blankholder opening side", opening_side),
        ("blankholder flat extent", flat_extent),
    ])?;
    finite("blankholder level", z0)?;
    if !(rc.is_finite() && rc >= 0.0) {
        return Err(Error::input(
            "blankholder plan corner radius",
            rc,
            "must be >= 0",
        ));
    }
    let half = 0.5 * opening_side;
    if rc > half {
        return Err(Error::input(
            "blankholder plan corner radius",
            rc,
            &format!("must be <= half the opening side {half}"),
        ));
    }
    let q = flat_outside(half, rc, flat_extent, extent.start()?, z0, -1.0)?;
    Ok(extent.complete(q))
}

/// A flat rectangle `corner + s edge_u + t edge_v`, `s, t` in `[0, 1]`, normal along
/// `edge_u x edge_v`.
pub fn flat_rectangle(corner: Vec3, edge_u: Vec3, edge_v: Vec3) -> Result<BezierPatch> {
    BezierPatch::parallelogram(corner, edge_u, edge_v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `min |S_u x S_v| / max` over a fine grid: > 0 means no degenerate point.
    fn regularity(p: &BezierPatch) -> f64 {
        let n = 40;
        let areas: Vec<f64> = (0..=n)
            .flat_map(|i| (0..=n).map(move |j| (i as f64 / n as f64, j as f64 / n as f64)))
            .map(|(u, v)| {
                let e = p.evaluate(u, v);
                e.su.cross(&e.sv).norm()
            })
            .collect();
        let max = areas.iter().cloned().fold(0.0, f64::max);
        areas.iter().cloned().fold(f64::INFINITY, f64::min) / max
    }

    #[test]
    fn corner_fillers_are_regular_and_flat() {
        for (half, r) in [(27.0, 2.0), (45.0, 20.0), (10.0, 5.0)] {
            let inside = flat_inside(half, r, -1.0, 0.81, -1.0).unwrap();
            let outside = flat_outside(half, r, half + r, -1.0, 0.0, 1.0).unwrap();
            for (p, nz) in [(&inside[2], -1.0), (&outside[2], 1.0)] {
                assert!(regularity(p) > 0.05, "filler nearly degenerate");
                let mut rng = crate::geometry::testutil::Rng::new(3);
                for _ in 0..50 {
                    let e = p.evaluate(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
                    let n = p.normal(&e).unwrap();
                    assert!((n - Vec3::new(0.0, 0.0, nz)).norm() < 1e-15);
                }
            }
        }
    }

    #[test]
    fn bad_dimensions_are_refused_with_the_parameter_named() {
        let punch = PunchSpec {
            side: 70.0,
            plan_corner_radius: 8.0,
            nose_radius: 8.0,
            wall_height: 50.0,
            level: 0.81,
        };
        let err = punch_patches(&punch, Extent::Full).unwrap_err().to_string();
        assert!(
            err.contains("punch nose radius = 8 must be < the plan corner radius = 8"),
            "{err}"
        );
        let die = DieSpec {
            opening_side: 74.0,
            plan_corner_radius: 12.0,
            entry_radius: 8.0,
            flat_extent: 40.0,
            wall_depth: 50.0,
            level: 0.0,
        };
        let err = die_patches(&die, Extent::Full).unwrap_err().to_string();
        assert!(err.contains("flat extent = 40 must be > 55"), "{err}");
        let err = die_patches(&die, Extent::Quarter { margin: -1.0 })
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("quarter tool margin = -1 must be >= 0"),
            "{err}"
        );
    }
}
