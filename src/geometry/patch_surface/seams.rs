//! Load-time check of a patch surface: do adjacent patches meet with continuous position
//! and normal, and do they face the same way?
//!
//! Every patch edge is sampled (`EDGE_SAMPLES + 1` points per edge, corners included). A
//! sample `p` of patch `k` is on a seam with patch `j != k` if the closest point of `j` is
//! within `SEAM_DETECT` of the surface size; it then contributes the position gap
//! `|p - S_j|` and the kink `angle(n_k(p), n_j(S_j))` (patch normals, also where the foot
//! is on `j`'s own edge). A sample near no other patch lies on a free edge of the tool.
//! Overlapping coplanar patches (the builders' flat regions) meet with zero gap and kink.
//!
//! Two patches whose normals differ by more than `OPPOSITE_ANGLE` at a seam face opposite
//! ways: one of them is inward-facing. The surface is refused, naming the patch that
//! disagrees with most of its neighbours (the majority orientation decides).

use super::PatchSurface;
use crate::geometry::*;
use crate::{Error, Result};

const EDGE_SAMPLES: usize = 16;
/// Seam detection radius, relative to the surface size: far above the round-off of the
/// projection (1e-14), far below any intended gap between separate parts of a tool.
const SEAM_DETECT: f64 = 1e-5;
/// Normals more than 135° apart across a seam: opposite orientation, not a sharp edge
/// (a genuine crease that sharp would be a knife edge no forming tool has).
const OPPOSITE_ANGLE: f64 = 0.75 * std::f64::consts::PI;

/// Worst gap and kink across the seams of a patch surface.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SeamReport {
    /// Largest distance between an edge sample and the neighbouring patch.
    pub worst_gap: f64,
    pub worst_gap_at: Vec3,
    /// Largest angle (radians) between the normals of two patches at a seam.
    pub worst_kink: f64,
    pub worst_kink_at: Vec3,
    /// Edge samples that lie on a seam, and on a free edge.
    pub seam_points: usize,
    pub free_points: usize,
}

/// Angle between unit vectors, accurate also near 0 and pi.
fn angle(a: &Vec3, b: &Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Samples the edges of every patch (see the module docs). Errs if two patches meeting at
/// a seam face opposite ways.
pub fn seam_report(surface: &PatchSurface) -> Result<SeamReport> {
    let patches = surface.patches();
    let detect = SEAM_DETECT * surface.scale();
    let mut report = SeamReport::default();
    // (patch, neighbour, where, angle) of every seam sample with opposite normals.
    let mut opposite: Vec<(usize, usize, Vec3, f64)> = Vec::new();
    let n = EDGE_SAMPLES as f64;
    for (k, patch) in patches.iter().enumerate() {
        for edge in 0..4 {
            for i in 0..=EDGE_SAMPLES {
                let t = i as f64 / n;
                let (u, v) = match edge {
                    0 => (0.0, t),
                    1 => (1.0, t),
                    2 => (t, 0.0),
                    _ => (t, 1.0),
                };
                let e = patch.evaluate(u, v);
                let Some(nk) = patch.normal(&e) else {
                    continue; // a pole: no normal to compare
                };
                let p = e.point;
                let mut on_seam = false;
                surface.nearest_patches(&p, detect, |j, _| {
                    if j == k {
                        return detect;
                    }
                    let loc = surface.closest_on_patch(j, &p, None);
                    if loc.dist > detect {
                        return detect;
                    }
                    on_seam = true;
                    if loc.dist > report.worst_gap {
                        report.worst_gap = loc.dist;
                        report.worst_gap_at = p;
                    }
                    if let Some(nj) = patches[j].normal(&loc.e) {
                        let a = angle(&nk, &nj);
                        if a > OPPOSITE_ANGLE {
                            opposite.push((k, j, p, a));
                        } else if a > report.worst_kink {
                            report.worst_kink = a;
                            report.worst_kink_at = p;
                        }
                    }
                    detect
                });
                if on_seam {
                    report.seam_points += 1;
                } else {
                    report.free_points += 1;
                }
            }
        }
    }
    if let Some(&(k, j, p, a)) = worst_offender(&opposite, patches.len()) {
        return Err(Error::input(
            &format!("bezier patch {k} orientation"),
            "inward",
            &format!(
                "is refused: its normal is opposite to that of its neighbour patch {j} at \
                 {} (normals {:.1}° apart); flip patch {k} so that all normals point out of \
                 the tool",
                fmt_vec3(&p),
                a.to_degrees()
            ),
        ));
    }
    Ok(report)
}

/// The opposite-orientation sample of the patch that disagrees with the most neighbours.
fn worst_offender(
    opposite: &[(usize, usize, Vec3, f64)],
    count: usize,
) -> Option<&(usize, usize, Vec3, f64)> {
    let mut disagreements = vec![std::collections::BTreeSet::new(); count];
    for &(k, j, _, _) in opposite {
        disagreements[k].insert(j);
    }
    let worst = (0..count).max_by_key(|&k| (disagreements[k].len(), std::cmp::Reverse(k)))?;
    opposite.iter().find(|o| o.0 == worst)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::BezierPatch;
    use std::f64::consts::FRAC_PI_2;

    fn cylinder(flip: Option<usize>) -> Result<PatchSurface> {
        let patches = (0..4)
            .map(|q| {
                let p = BezierPatch::quarter_cylinder(
                    Vec3::zeros(),
                    Vec3::z(),
                    Vec3::x(),
                    q as f64 * FRAC_PI_2,
                    2.0,
                    3.0,
                )
                .unwrap();
                if Some(q) == flip {
                    p.flipped()
                } else {
                    p
                }
            })
            .collect();
        PatchSurface::new(patches)
    }

    #[test]
    fn smooth_cylinder_has_no_gap_no_kink_and_free_ends() {
        let s = cylinder(None).unwrap();
        let r = s.seams();
        assert!(r.worst_gap < 1e-13 && r.worst_kink < 1e-13, "{r:?}");
        // Per patch: 2 seam edges (17 samples each) and 2 free ends whose 2 corner
        // samples touch the neighbour: 34 + 4 on seams, 30 free.
        assert_eq!((r.seam_points, r.free_points), (4 * 38, 4 * 30));
    }

    #[test]
    fn flipped_patch_is_named() {
        let err = cylinder(Some(2)).unwrap_err().to_string();
        assert!(
            err.contains("bezier patch 2 orientation = inward is refused"),
            "{err}"
        );
        assert!(err.contains("flip patch 2"), "{err}");
    }

    #[test]
    fn kink_and_gap_are_measured() {
        // Two unit squares hinged along x = 1 with a 30° fold, the second lifted by 1e-7.
        let a = BezierPatch::parallelogram(Vec3::zeros(), Vec3::x(), Vec3::y()).unwrap();
        let fold = 30f64.to_radians();
        let b = BezierPatch::parallelogram(
            Vec3::new(1.0, 0.0, 1e-7),
            Vec3::new(fold.cos(), 0.0, fold.sin()),
            Vec3::y(),
        )
        .unwrap();
        let s = PatchSurface::new(vec![a, b]).unwrap();
        let r = s.seams();
        assert!((r.worst_kink - fold).abs() < 1e-12, "{r:?}");
        assert!((r.worst_gap - 1e-7).abs() < 1e-12, "{r:?}");
    }
}
