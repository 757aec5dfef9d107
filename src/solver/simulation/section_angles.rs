//! The springback angles of a drawn channel's cross-section (NUMISHEET'93 2D draw bending's
//! measures): theta1 (bottom against wall), theta2 (wall against flange) and rho (the wall's
//! radius of curvature), loaded and released.
//!
//! A section is a polyline of nodes in order along the channel (from its middle outwards),
//! read in the x-z plane (plane strain along y): `p_i = (x_i, z_i)` of the loaded shape (kept
//! where loading ended, `springback.rs`) and of the committed one. Its segments are classed
//! on the loaded shape by their slope `s_i = asin(|dz| / |dp|)`:
//!
//! ```text
//! bottom  the segments from node 0 on while s < 10 deg (before the wall)
//! wall    from the first to the last segment with s > 60 deg (within 30 deg of vertical)
//! flange  after the wall, the first run of segments with s < 10 deg
//! ```
//!
//! Each run's chord (first to last node, unit vector) gives a direction `b`, `w`, `f`; the
//! same nodes give the released directions. Then
//!
//! ```text
//! theta1 = 180 - acos(b . w)    (90 deg for a vertical wall, larger when the channel opens)
//! theta2 = acos(-w . f)         (90 deg for a vertical wall and a flat flange; none when
//!                                no flat flange is left)
//! rho    = |AB| |BC| |CA| / (2 area(ABC))   the circle through the wall run's first,
//!                                middle and last nodes (none for three collinear nodes)
//! ```
//!
//! O(nodes). The classification is the one scripts/u_channel_springback.rhai used in
//! script before this module (same thresholds, same run rules).

use crate::solver::simulation::Simulation;
use crate::{Error, Result};

/// Runs of the section (node indices along it, first and last; `None` when absent).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SectionRuns {
    pub bottom: (usize, usize),
    pub wall: (usize, usize),
    pub flange: Option<(usize, usize)>,
}

/// The angles (degrees) and the wall's radius of one shape.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SectionShape {
    pub theta1: f64,
    pub theta2: Option<f64>,
    pub rho: Option<f64>,
}

/// The section's runs and its measures loaded and released.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SectionAngles {
    pub runs: SectionRuns,
    pub loaded: SectionShape,
    pub released: SectionShape,
}

/// Slope of a segment (degrees from horizontal) below which it is bottom or flange.
const FLAT_DEG: f64 = 10.0;
/// Slope above which a segment is wall.
const WALL_DEG: f64 = 60.0;

/// The runs of `p` (module doc); an error if the section has no wall.
pub fn runs(p: &[[f64; 2]]) -> Result<SectionRuns> {
    if p.len() < 3 {
        return Err(Error::Input(format!(
            "section_angles: a section needs at least 3 nodes (given {})",
            p.len()
        )));
    }
    let mut bottom = (0, 0);
    let mut wall: Option<(usize, usize)> = None;
    let mut flange: Option<(usize, usize)> = None;
    for i in 0..p.len() - 1 {
        let d = unit(p[i], p[i + 1])?;
        let slope = d[1].abs().asin().to_degrees();
        if wall.is_none() && slope < FLAT_DEG && bottom.1 == i {
            bottom.1 = i + 1;
        }
        if slope > WALL_DEG {
            wall = Some((wall.map_or(i, |w| w.0), i + 1));
        }
        if let Some(w) = wall {
            if slope < FLAT_DEG && i >= w.1 {
                match &mut flange {
                    None => flange = Some((i, i + 1)),
                    Some(f) if f.1 == i => f.1 = i + 1,
                    Some(_) => {}
                }
            }
        }
    }
    let wall = wall.ok_or_else(|| {
        Error::Input(format!(
            "section_angles: no segment of the loaded section is steeper than {WALL_DEG} degrees (no wall)"
        ))
    })?;
    if bottom.1 == 0 {
        return Err(Error::Input(format!(
            "section_angles: the loaded section's first segment is steeper than {FLAT_DEG} degrees (no bottom)"
        )));
    }
    Ok(SectionRuns {
        bottom,
        wall,
        flange,
    })
}

/// theta1, theta2, rho of the shape `p` with the runs `r`.
pub fn shape(p: &[[f64; 2]], r: &SectionRuns) -> Result<SectionShape> {
    let b = unit(p[r.bottom.0], p[r.bottom.1])?;
    let w = unit(p[r.wall.0], p[r.wall.1])?;
    let angle = |u: [f64; 2], v: [f64; 2]| (u[0] * v[0] + u[1] * v[1]).clamp(-1.0, 1.0).acos();
    let theta2 = match r.flange {
        Some((a, c)) => {
            let f = unit(p[a], p[c])?;
            Some(angle([-w[0], -w[1]], f).to_degrees())
        }
        None => None,
    };
    let mid = (r.wall.0 + r.wall.1) / 2;
    Ok(SectionShape {
        theta1: 180.0 - angle(b, w).to_degrees(),
        theta2,
        rho: circumradius(p[r.wall.0], p[mid], p[r.wall.1]),
    })
}

/// The measures of a section given loaded and released (module doc).
pub fn measure(loaded: &[[f64; 2]], released: &[[f64; 2]]) -> Result<SectionAngles> {
    let runs = runs(loaded)?;
    Ok(SectionAngles {
        runs,
        loaded: shape(loaded, &runs)?,
        released: shape(released, &runs)?,
    })
}

fn unit(a: [f64; 2], b: [f64; 2]) -> Result<[f64; 2]> {
    let (dx, dz) = (b[0] - a[0], b[1] - a[1]);
    let l = dx.hypot(dz);
    if l > 0.0 && l.is_finite() {
        Ok([dx / l, dz / l])
    } else {
        Err(Error::Input(format!(
            "section_angles: two successive nodes of the section coincide at ({}, {})",
            a[0], a[1]
        )))
    }
}

/// The radius of the circle through `a`, `b`, `c`; `None` for collinear points (relative
/// area below 1e-12 of the squared sides' product: a straight wall).
fn circumradius(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Option<f64> {
    let ab = (b[0] - a[0]).hypot(b[1] - a[1]);
    let bc = (c[0] - b[0]).hypot(c[1] - b[1]);
    let ca = (a[0] - c[0]).hypot(a[1] - c[1]);
    let area2 = ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs();
    (area2 > 1e-12 * ab * ca).then(|| ab * bc * ca / (2.0 * area2))
}

impl Simulation {
    /// The section measures of the nodes `nodes` (in order along the section) between the
    /// loaded shape and the committed one (module doc); an error before loading has ended
    /// or for a node outside the mesh.
    pub fn section_angles(&self, nodes: &[usize]) -> Result<SectionAngles> {
        let Some(loaded) = &self.loaded_shape else {
            return Err(Error::Input(
                "section_angles: loading has not ended yet (no step that ramps a tool off or releases the sheet has started)".into(),
            ));
        };
        let n = self.model.mesh.nodes.len();
        if let Some((i, &bad)) = nodes.iter().enumerate().find(|(_, &k)| k >= n) {
            return Err(Error::Input(format!(
                "section_angles: node {bad} (entry {i}) is not in the mesh ({n} nodes)"
            )));
        }
        let now = self.node_positions();
        let xz = |shape: &[crate::geometry::Vec3]| -> Vec<[f64; 2]> {
            nodes.iter().map(|&k| [shape[k].x, shape[k].z]).collect()
        };
        measure(&xz(loaded), &xz(&now))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A U profile built from known angles: bottom along x, a wall arc of radius `rho`
    /// leaving the bottom at `theta1` and a flange at `theta2` to the wall's end chord.
    fn profile(theta1: f64, rho: f64, theta2: f64) -> Vec<[f64; 2]> {
        let mut p: Vec<[f64; 2]> = (0..=5).map(|i| [i as f64, 0.0]).collect();
        // The wall: 6 segments on a circle of radius rho whose chord from its first to
        // its last node makes the angle theta1 with the bottom (inside the channel),
        // spanning 20 degrees of arc.
        let chord_dir = (180.0 - theta1).to_radians(); // direction of the wall chord
        let span = 20f64.to_radians();
        let start = p[5];
        let chord = 2.0 * rho * (span / 2.0).sin();
        // Centre to the right of the chord (the wall bulges to the left, into the
        // channel); nodes at equal angles along the arc, swept clockwise from the start.
        let (ux, uz) = (chord_dir.cos(), chord_dir.sin());
        let mid = [start[0] + ux * chord / 2.0, start[1] + uz * chord / 2.0];
        let h = rho * (span / 2.0).cos();
        let centre = [mid[0] + uz * h, mid[1] - ux * h];
        let a0 = (start[1] - centre[1]).atan2(start[0] - centre[0]);
        for k in 1..=6 {
            let a = a0 - span * k as f64 / 6.0;
            p.push([centre[0] + rho * a.cos(), centre[1] + rho * a.sin()]);
        }
        // The flange: at theta2 to the wall chord, i.e. the direction -w turned
        // counterclockwise by theta2 (outward, 5 degrees below horizontal for 100 / 95).
        let phi = (-uz).atan2(-ux) + theta2.to_radians();
        let end = *p.last().unwrap();
        for k in 1..=4 {
            p.push([end[0] + k as f64 * phi.cos(), end[1] + k as f64 * phi.sin()]);
        }
        p
    }

    #[test]
    fn a_known_u_profile_gives_its_angles_and_radius() {
        // theta1 100 deg, the wall on a 50 mm circle, the flange at 95 deg to the wall's
        // chord (5 degrees below horizontal, flat by the 10 degree rule).
        let loaded = profile(100.0, 50.0, 95.0);
        let released = profile(104.0, 30.0, 93.0);
        let m = measure(&loaded, &released).unwrap();
        assert_eq!(m.runs.bottom, (0, 5));
        assert_eq!(m.runs.wall, (5, 11));
        assert_eq!(m.runs.flange, Some((11, 15)));
        // Closed-form values to round-off of a few trigonometric evaluations on lengths of
        // order 10 (1e-9).
        for (shape, (t1, rho, t2)) in [
            (m.loaded, (100.0, 50.0, 95.0)),
            (m.released, (104.0, 30.0, 93.0)),
        ] {
            assert!((shape.theta1 - t1).abs() < 1e-9, "{shape:?}");
            assert!((shape.rho.unwrap() - rho).abs() < 1e-9, "{shape:?}");
            assert!((shape.theta2.unwrap() - t2).abs() < 1e-9, "{shape:?}");
        }
    }

    #[test]
    fn a_straight_wall_has_no_radius_and_a_section_without_wall_is_an_error() {
        let p = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0, 2.0], [1.0, 3.0]];
        let m = measure(&p, &p).unwrap();
        assert_eq!(m.loaded.rho, None);
        assert!((m.loaded.theta1 - 90.0).abs() < 1e-12);
        assert_eq!(m.loaded.theta2, None, "no flange after the wall");
        let flat = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.1], [3.0, 0.1]];
        let err = measure(&flat, &flat).unwrap_err().to_string();
        assert!(err.contains("no wall"), "{err}");
    }
}
