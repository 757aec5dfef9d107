//! Tools of revolution about the z axis from a 2-D profile of lines and circular arcs in
//! the meridian half-plane `(r, z)`, made of exact rational Bézier patches.
//!
//! A profile point `(r, z)` revolved by the angle `theta` is `(r cos theta, r sin theta, z)`.
//! The ring is the exact rational quadratic circle (weights `1, cos(s/2), 1` over a sweep
//! `s`, middle control direction of length `1 / cos(s/2)`), so revolving a profile control
//! point `(r_j, z_j)` of weight `v_j` about ring control direction `d_i` of weight `u_i`
//! gives the control point `r_j d_i + z_j e_z` of weight `u_i v_j`: a line becomes a
//! degree 2 x 1 patch (cone, cylinder or flat annulus), an arc a degree 2 x 2 patch (torus
//! piece). Both are the surface of revolution exactly (to round-off).
//!
//! A flat piece reaching the axis (a punch nose) would make the revolved patch degenerate
//! at the pole, so a disk of radius `a` is covered instead by the flat square
//! `[-a/2, a/2]^2` and four flat ruled patches between each side of the square and the 90°
//! arc of the disk facing it. The side is written as the central projection of the arc
//! (a projective map of its homogeneous control points: `(X, Y, W) -> (s X, s Y, X)` for
//! the side `x = s`), so every ruling is radial and the patches are regular.
//!
//! Orientation: the tool's material is on the left of the profile as traversed in the
//! `(r, z)` plane, so its outward normal is the profile tangent turned to the right,
//! `(t_z, -t_r)`. Whole tools use four 90° quarters; a quarter tool (the plan quadrant
//! `x >= 0, y >= 0`, as the square cup's) one patch per segment over -10° .. 100°, so that
//! nodes on the symmetry planes project into patch interiors.

use super::bezier::{circular_arc, BezierPatch};
use super::*;
use crate::{Error, Result};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// A piece of a profile in the meridian half-plane `(r, z)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Segment {
    /// Straight from `from` to `to`, each `[r, z]`.
    Line { from: [f64; 2], to: [f64; 2] },
    /// Circular arc of `radius` about `centre` `[r, z]`, from the angle `start` (radians,
    /// from +r towards +z) over `sweep` (signed: > 0 counter-clockwise), |sweep| <= 120°.
    Arc {
        centre: [f64; 2],
        radius: f64,
        start: f64,
        sweep: f64,
    },
}

/// Whole tool or the plan quadrant `x >= 0, y >= 0` with a 10° margin on each side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Revolution {
    Full,
    Quarter,
}

/// Angular margin of a quarter tool past each symmetry plane.
const QUARTER_MARGIN: f64 = 10.0 * std::f64::consts::PI / 180.0;

impl Segment {
    /// Point at `t` in [0, 1] (arcs by angle).
    pub fn point(&self, t: f64) -> [f64; 2] {
        match *self {
            Segment::Line { from, to } => [
                from[0] + t * (to[0] - from[0]),
                from[1] + t * (to[1] - from[1]),
            ],
            Segment::Arc {
                centre,
                radius,
                start,
                sweep,
            } => {
                let a = start + t * sweep;
                [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
            }
        }
    }

    /// Unit tangent at `t` in the direction of travel.
    pub fn tangent(&self, t: f64) -> [f64; 2] {
        match *self {
            Segment::Line { from, to } => {
                let (dr, dz) = (to[0] - from[0], to[1] - from[1]);
                let l = dr.hypot(dz);
                [dr / l, dz / l]
            }
            Segment::Arc { start, sweep, .. } => {
                let a = start + t * sweep;
                let s = sweep.signum();
                [-s * a.sin(), s * a.cos()]
            }
        }
    }

    /// Closest point of the segment to `p` (exact), for checks and tests.
    pub fn closest(&self, p: [f64; 2]) -> [f64; 2] {
        match *self {
            Segment::Line { from, to } => {
                let (dr, dz) = (to[0] - from[0], to[1] - from[1]);
                let t = ((p[0] - from[0]) * dr + (p[1] - from[1]) * dz) / (dr * dr + dz * dz);
                self.point(t.clamp(0.0, 1.0))
            }
            Segment::Arc {
                centre,
                start,
                sweep,
                ..
            } => {
                let a = (p[1] - centre[1]).atan2(p[0] - centre[0]);
                // Angle of p relative to the start, in the direction of the sweep.
                let tau = std::f64::consts::TAU;
                let rel = ((a - start) * sweep.signum()).rem_euclid(tau);
                let t = rel / sweep.abs();
                if t <= 1.0 {
                    self.point(t)
                } else {
                    // Past the end: the nearer end point.
                    let (e0, e1) = (self.point(0.0), self.point(1.0));
                    let d = |q: [f64; 2]| (q[0] - p[0]).hypot(q[1] - p[1]);
                    if d(e0) <= d(e1) {
                        e0
                    } else {
                        e1
                    }
                }
            }
        }
    }

    /// Profile control points `(r, z)` and weights.
    fn controls(&self) -> Result<(Vec<[f64; 2]>, Vec<f64>)> {
        match *self {
            Segment::Line { from, to } => Ok((vec![from, to], vec![1.0, 1.0])),
            Segment::Arc {
                centre,
                radius,
                start,
                sweep,
            } => {
                let rho = positive_length("profile arc radius", radius)?;
                let s = sweep.signum();
                let p = Vec3::new(start.cos(), start.sin(), 0.0) * rho;
                let q = Vec3::new(-start.sin(), start.cos(), 0.0) * (rho * s);
                let (pts, w) = circular_arc("profile arc sweep", p, q, sweep.abs())?;
                Ok((
                    pts.iter()
                        .map(|v| [centre[0] + v.x, centre[1] + v.y])
                        .collect(),
                    w.to_vec(),
                ))
            }
        }
    }
}

/// The patches of the profile revolved about the z axis. Every point of the profile must
/// have r > 0 except flat (constant z) lines that start on the axis, which become disks.
/// Consecutive segments must join (to 1e-9 of the profile's size).
pub fn revolve(profile: &[Segment], extent: Revolution) -> Result<Vec<BezierPatch>> {
    if profile.is_empty() {
        return Err(Error::input("profile segment count", 0, "must be >= 1"));
    }
    let size = profile
        .iter()
        .flat_map(|s| [s.point(0.0), s.point(1.0)])
        .fold(0.0_f64, |m, p| m.max(p[0].abs()).max(p[1].abs()))
        .max(f64::MIN_POSITIVE);
    for (k, w) in profile.windows(2).enumerate() {
        let (a, b) = (w[0].point(1.0), w[1].point(0.0));
        if (a[0] - b[0]).hypot(a[1] - b[1]) > 1e-9 * size {
            return Err(Error::Input(format!(
                "profile segment {} ends at ({}, {}) but segment {} starts at ({}, {})",
                k,
                a[0],
                a[1],
                k + 1,
                b[0],
                b[1]
            )));
        }
    }
    let rings: Vec<(f64, f64)> = match extent {
        Revolution::Full => (0..4).map(|k| (k as f64 * FRAC_PI_2, FRAC_PI_2)).collect(),
        Revolution::Quarter => vec![(-QUARTER_MARGIN, FRAC_PI_2 + 2.0 * QUARTER_MARGIN)],
    };
    let mut patches = Vec::new();
    for (k, seg) in profile.iter().enumerate() {
        let t = seg.tangent(0.5);
        let outward2 = [t[1], -t[0]];
        if let Segment::Line { from, to } = *seg {
            if from[1] == to[1] && (from[0] == 0.0 || to[0] == 0.0) {
                let radius = from[0].max(to[0]);
                patches.extend(disk(radius, from[1], outward2[1])?);
                continue;
            }
        }
        let (pts, wv) = seg.controls()?;
        if let Some(p) = pts.iter().find(|p| !(p[0] > 0.0) || !p[1].is_finite()) {
            return Err(Error::Input(format!(
                "profile segment {k}: control point (r, z) = ({}, {}) must have r > 0 (only a \
                 flat line may start on the axis)",
                p[0], p[1]
            )));
        }
        for &(start, sweep) in &rings {
            let e1 = Vec3::new(start.cos(), start.sin(), 0.0);
            let e2 = Vec3::new(-start.sin(), start.cos(), 0.0);
            let (ring, wu) = circular_arc("revolution sweep", e1, e2, sweep)?;
            let mut points = Vec::new();
            let mut weights = Vec::new();
            for (d, u) in ring.iter().zip(wu) {
                for (q, v) in pts.iter().zip(&wv) {
                    points.push(d * q[0] + Vec3::z() * q[1]);
                    weights.push(u * v);
                }
            }
            let mid = start + 0.5 * sweep;
            let outward = Vec3::new(
                outward2[0] * mid.cos(),
                outward2[0] * mid.sin(),
                outward2[1],
            );
            patches.push(BezierPatch::new(2, pts.len() - 1, points, weights)?.oriented(&outward));
        }
    }
    Ok(patches)
}

/// The flat disk of `radius` at height `z`, normal along `+z` times the sign of `nz`:
/// a square and four radial ruled patches (module documentation).
fn disk(radius: f64, z: f64, nz: f64) -> Result<Vec<BezierPatch>> {
    let a = positive_length("disk radius", radius)?;
    let s = 0.5 * a;
    let outward = Vec3::new(0.0, 0.0, nz.signum());
    let mut patches = vec![BezierPatch::parallelogram(
        Vec3::new(-s, -s, z),
        Vec3::new(2.0 * s, 0.0, 0.0),
        Vec3::new(0.0, 2.0 * s, 0.0),
    )?
    .oriented(&outward)];
    for k in 0..4 {
        let facing = k as f64 * FRAC_PI_2;
        let (c, sn) = (facing.cos(), facing.sin());
        // Arc from facing - 45° to facing + 45°, in the frame where it faces +x.
        let start = -FRAC_PI_4;
        let p = Vec3::new(start.cos(), start.sin(), 0.0) * a;
        let q = Vec3::new(-start.sin(), start.cos(), 0.0) * a;
        let (arc, w) = circular_arc("disk arc", p, q, FRAC_PI_2)?;
        let turn = |v: Vec3| Vec3::new(c * v.x - sn * v.y, sn * v.x + c * v.y, z);
        let mut points = Vec::new();
        let mut weights = Vec::new();
        for (pt, wi) in arc.iter().zip(w) {
            // Central projection onto the side x = s: point (s, s y / x), weight w x / s.
            points.push(turn(Vec3::new(s, s * pt.y / pt.x, 0.0)));
            weights.push(wi * pt.x / s);
            points.push(turn(*pt));
            weights.push(wi);
        }
        patches.push(BezierPatch::new(2, 1, points, weights)?.oriented(&outward));
    }
    Ok(patches)
}

/// Round punch: flat nose at `z = level` (normal -z) of radius `radius - nose_radius`,
/// the nose radius, a cylindrical wall of `wall_height` above it.
pub fn round_punch(
    radius: f64,
    nose_radius: f64,
    wall_height: f64,
    level: f64,
) -> Result<Vec<Segment>> {
    let r = positive_length("round punch radius", radius)?;
    let rn = positive_length("round punch nose radius", nose_radius)?;
    let h = positive_length("round punch wall height", wall_height)?;
    if !(rn < r) {
        return Err(Error::input(
            "round punch nose radius",
            rn,
            &format!("must be < the punch radius {r} (the flat nose must keep a positive radius)"),
        ));
    }
    Ok(vec![
        Segment::Line {
            from: [0.0, level],
            to: [r - rn, level],
        },
        Segment::Arc {
            centre: [r - rn, level + rn],
            radius: rn,
            start: -FRAC_PI_2,
            sweep: FRAC_PI_2,
        },
        Segment::Line {
            from: [r, level + rn],
            to: [r, level + rn + h],
        },
    ])
}

/// Round die: flat top at `z = level` (normal +z) from `flat_extent` in to the entry
/// radius, the entry radius down into the opening of radius `opening_radius`, a wall of
/// `wall_depth` below it.
pub fn round_die(
    opening_radius: f64,
    entry_radius: f64,
    flat_extent: f64,
    wall_depth: f64,
    level: f64,
) -> Result<Vec<Segment>> {
    let r = positive_length("round die opening radius", opening_radius)?;
    let re = positive_length("round die entry radius", entry_radius)?;
    let d = positive_length("round die wall depth", wall_depth)?;
    if !(flat_extent > r + re) {
        return Err(Error::input(
            "round die flat extent",
            flat_extent,
            &format!("must be > opening radius + entry radius = {}", r + re),
        ));
    }
    Ok(vec![
        Segment::Line {
            from: [flat_extent, level],
            to: [r + re, level],
        },
        Segment::Arc {
            centre: [r + re, level - re],
            radius: re,
            start: FRAC_PI_2,
            sweep: FRAC_PI_2,
        },
        Segment::Line {
            from: [r, level - re],
            to: [r, level - re - d],
        },
    ])
}

/// Flat blankholder: the annulus `inner_radius <= r <= outer_radius` at `z = level`,
/// normal -z (a sharp, open inner edge).
pub fn round_holder(inner_radius: f64, outer_radius: f64, level: f64) -> Result<Vec<Segment>> {
    let ri = positive_length("round holder inner radius", inner_radius)?;
    if !(outer_radius > ri) {
        return Err(Error::input(
            "round holder outer radius",
            outer_radius,
            &format!("must be > the inner radius {ri}"),
        ));
    }
    Ok(vec![Segment::Line {
        from: [ri, level],
        to: [outer_radius, level],
    }])
}

#[cfg(test)]
mod tests {
    use super::super::testutil::Rng;
    use super::*;

    /// Exact distance data of a point to the surface of revolution of `profile`: foot and
    /// signed gap (positive on the outward side) from the closest profile point in the
    /// point's meridian plane.
    fn analytic(profile: &[Segment], x: &Vec3) -> (Vec3, f64) {
        let r = x.x.hypot(x.y);
        let p = [r, x.z];
        let (mut best, mut foot, mut seg) = (f64::INFINITY, [0.0; 2], 0);
        for (k, s) in profile.iter().enumerate() {
            let q = s.closest(p);
            let d = (q[0] - p[0]).hypot(q[1] - p[1]);
            if d < best {
                (best, foot, seg) = (d, q, k);
            }
        }
        let t = match profile[seg] {
            Segment::Line { .. } => profile[seg].tangent(0.5),
            Segment::Arc { centre, .. } => {
                let a = (foot[1] - centre[1]).atan2(foot[0] - centre[0]);
                let Segment::Arc { sweep, .. } = profile[seg] else {
                    unreachable!()
                };
                [-sweep.signum() * a.sin(), sweep.signum() * a.cos()]
            }
        };
        let n2 = [t[1], -t[0]];
        let sign = ((p[0] - foot[0]) * n2[0] + (p[1] - foot[1]) * n2[1]).signum();
        let (c, s) = if r > 0.0 {
            (x.x / r, x.y / r)
        } else {
            (1.0, 0.0)
        };
        (Vec3::new(foot[0] * c, foot[0] * s, foot[1]), sign * best)
    }

    fn check(profile: &[Segment], extent: Revolution, band: f64, seed: u64) -> (f64, f64) {
        let surface = PatchSurface::new(revolve(profile, extent).unwrap()).unwrap();
        let mut rng = Rng::new(seed);
        let (mut worst_gap, mut worst_foot) = (0.0_f64, 0.0_f64);
        let mut n = 0;
        while n < 10_000 {
            // A profile point, revolved to a random angle, moved off along the normal.
            let seg =
                &profile[(rng.uniform(0.0, profile.len() as f64) as usize).min(profile.len() - 1)];
            let t = rng.uniform(0.02, 0.98);
            let q = seg.point(t);
            let tg = seg.tangent(t);
            let d = rng.uniform(-band, band);
            let (r, z) = (q[0] + d * tg[1], q[1] - d * tg[0]);
            let theta = match extent {
                Revolution::Full => rng.uniform(0.0, std::f64::consts::TAU),
                Revolution::Quarter => rng.uniform(0.0, FRAC_PI_2),
            };
            if r <= 0.0 {
                continue;
            }
            let x = Vec3::new(r * theta.cos(), r * theta.sin(), z);
            let (foot, gap) = analytic(profile, &x);
            let p = surface.project(&x, None).expect("projection");
            worst_gap = worst_gap.max((p.gap - gap).abs());
            worst_foot = worst_foot.max((p.foot - foot).norm());
            n += 1;
        }
        (worst_gap, worst_foot)
    }

    #[test]
    fn round_tools_are_the_exact_surfaces_of_revolution() {
        // The cylindrical cup's tools (mm): punch 25 with nose 5, die 26.5 with entry 5.
        let punch = round_punch(25.0, 5.0, 20.0, 1.0).unwrap();
        let die = round_die(26.5, 5.0, 60.0, 20.0, 0.0).unwrap();
        let holder = round_holder(31.5, 60.0, 1.0).unwrap();
        for (name, profile, band) in [
            ("punch", &punch, 2.0),
            ("die", &die, 2.0),
            ("holder", &holder, 2.0),
        ] {
            for (extent, seed) in [(Revolution::Full, 7), (Revolution::Quarter, 11)] {
                let (gap, foot) = check(profile, extent, band, seed);
                println!("{name} {extent:?}: worst gap error {gap:e}, worst foot error {foot:e}");
                assert!(
                    gap < 1e-10 && foot < 1e-9,
                    "{name} {extent:?}: gap {gap:e}, foot {foot:e}"
                );
            }
            // Seams: closed (gap) and tangent (G1: no kink), from the seam report.
            let s = PatchSurface::new(revolve(profile, Revolution::Full).unwrap()).unwrap();
            let seams = s.seams();
            assert!(
                seams.worst_gap < 1e-10,
                "{name}: seam gap {}",
                seams.worst_gap
            );
            assert!(
                seams.worst_kink < 1e-7,
                "{name}: seam kink {}",
                seams.worst_kink
            );
        }
    }

    #[test]
    fn bad_profiles_are_refused() {
        assert!(round_punch(10.0, 10.0, 5.0, 0.0)
            .unwrap_err()
            .to_string()
            .contains("< the punch radius"));
        assert!(round_die(10.0, 2.0, 11.0, 5.0, 0.0).is_err());
        let gap = [
            Segment::Line {
                from: [1.0, 0.0],
                to: [2.0, 0.0],
            },
            Segment::Line {
                from: [2.5, 0.0],
                to: [3.0, 1.0],
            },
        ];
        assert!(revolve(&gap, Revolution::Full)
            .unwrap_err()
            .to_string()
            .contains("segment 1 starts"));
        let axis = [Segment::Line {
            from: [0.0, 0.0],
            to: [1.0, 1.0],
        }];
        assert!(revolve(&axis, Revolution::Full)
            .unwrap_err()
            .to_string()
            .contains("r > 0"));
    }
}
