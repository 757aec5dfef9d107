//! A 26-sided discrete-orientation polytope (26-DOP) around a point set: a lower bound of
//! the distance from a point to anything inside the set's convex hull, tighter than the
//! axis-aligned box for slanted or curved patches.
//!
//! # Bound
//!
//! The polytope is the intersection of 13 slabs `lo_d <= d . y <= hi_d`, one per direction
//! `d`: the 3 axes, the 6 face diagonals `(±1, ±1, 0) / √2` and the 4 body diagonals
//! `(±1, ±1, ±1) / √3` (one of each opposite pair). For a unit `d`, every `y` in the hull
//! has `|x - y| >= d . x - hi_d` and `>= lo_d - d . x`, so
//!
//! ```text
//! dist(x, hull) >= max_d max(d . x - hi_d, lo_d - d . x, 0).
//! ```
//!
//! The axes alone give the larger of the box's per-axis gaps (at most the box distance);
//! the diagonals add the slanted cuts, which is what prunes a quarter-cylinder fillet whose
//! box contains points far from the surface. A rational Bézier patch with positive weights
//! lies in the convex hull of its control points, so the bound holds for the patch.
//!
//! # Cost
//!
//! Construction `O(13 n)` for `n` points; a query 13 dot products.

use super::Vec3;

const S2: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// `1 / √3`.
const S3: f64 = 0.577_350_269_189_625_8;

/// The 13 slab directions, unit vectors.
const DIRECTIONS: [[f64; 3]; 13] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [S2, S2, 0.0],
    [S2, -S2, 0.0],
    [S2, 0.0, S2],
    [S2, 0.0, -S2],
    [0.0, S2, S2],
    [0.0, S2, -S2],
    [S3, S3, S3],
    [S3, S3, -S3],
    [S3, -S3, S3],
    [-S3, S3, S3],
];

/// The slabs `lo[d] <= DIRECTIONS[d] . y <= hi[d]` of a point set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kdop {
    lo: [f64; 13],
    hi: [f64; 13],
}

impl Kdop {
    /// The tightest slabs around `points` (an empty set gives an empty polytope, whose
    /// bound is infinite).
    pub fn around(points: &[Vec3]) -> Kdop {
        let mut k = Kdop {
            lo: [f64::INFINITY; 13],
            hi: [f64::NEG_INFINITY; 13],
        };
        for p in points {
            for (d, dir) in DIRECTIONS.iter().enumerate() {
                let s = dir[0] * p.x + dir[1] * p.y + dir[2] * p.z;
                k.lo[d] = k.lo[d].min(s);
                k.hi[d] = k.hi[d].max(s);
            }
        }
        k
    }

    /// A lower bound of the distance from `x` to every point of the hull (module docs);
    /// zero inside the polytope.
    pub fn distance_lower_bound(&self, x: &Vec3) -> f64 {
        let mut bound = 0.0f64;
        for (d, dir) in DIRECTIONS.iter().enumerate() {
            let s = dir[0] * x.x + dir[1] * x.y + dir[2] * x.z;
            bound = bound.max(s - self.hi[d]).max(self.lo[d] - s);
        }
        bound
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::testutil::Rng;

    /// For random point clouds and query points: the bound never exceeds the distance to any
    /// convex combination of the points (1e-12 for rounding), and is at least the largest
    /// per-axis gap of their box (the axes are among the slabs); inside the hull it is zero.
    #[test]
    fn bounds_the_distance_to_the_hull() {
        let mut rng = Rng::new(11);
        for _ in 0..200 {
            let n = 3 + (rng.uniform(0.0, 10.0) as usize);
            let centre = rng.vec3(5.0);
            let points: Vec<Vec3> = (0..n).map(|_| centre + rng.vec3(2.0)).collect();
            let k = Kdop::around(&points);
            let (lo, hi) = points.iter().fold(
                (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
                |(lo, hi), p| (lo.inf(p), hi.sup(p)),
            );
            for _ in 0..20 {
                let x = centre + rng.vec3(8.0);
                let bound = k.distance_lower_bound(&x);
                let axis_gap = (0..3)
                    .map(|i| (x[i] - hi[i]).max(lo[i] - x[i]))
                    .fold(0.0f64, f64::max);
                assert!(bound >= axis_gap - 1e-12, "{bound} < {axis_gap}");
                for _ in 0..50 {
                    let w: Vec<f64> = (0..n).map(|_| rng.uniform(0.0, 1.0)).collect();
                    let total: f64 = w.iter().sum();
                    let y = points
                        .iter()
                        .zip(&w)
                        .fold(Vec3::zeros(), |s, (p, wi)| s + p * (wi / total));
                    assert!(bound <= (x - y).norm() + 1e-12);
                    assert_eq!(Kdop::around(&points).distance_lower_bound(&y), 0.0);
                }
            }
        }
    }

    /// A quarter-circle arc's control triangle (0, 0), (1, 0), (1, 1) around the point
    /// (0, 1): the box says distance 0 (the point is a corner of the box), the diagonal slab
    /// `(x - y)/√2 >= 0` says at least 1/√2; the true distance to the arc (centre (0, 1),
    /// radius 1) is 1.
    #[test]
    fn diagonal_slabs_prune_what_the_box_cannot() {
        let points = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let x = Vec3::new(0.0, 1.0, 0.0);
        let bound = Kdop::around(&points).distance_lower_bound(&x);
        assert!((bound - S2).abs() < 1e-15, "{bound}");
    }
}
