//! Structured meshes graded as the field grades them: a block from explicit node lines per
//! axis, and the usual line of a contact benchmark, a uniform core with geometric growth
//! outward.
//!
//! # Core and growth
//!
//! [`core_and_growth`] makes the node coordinates of one axis: uniform cells of width `h`
//! on the core `[c0, c1]` (its length must be a whole number of cells), then on each side
//! cells growing outward geometrically, the `i`-th one (i = 1, 2, ...) of width `h r^i`,
//! so the `k`-th node beyond the core is at distance
//!
//! ```text
//! s_k = h r (r^k - 1) / (r - 1)        (h k when r = 1)
//! ```
//!
//! from it, up to the extent. The growth stops at the first node with `s_k >= L` (`L` the
//! distance from the core to the extent), which is moved onto the extent; when that last,
//! cut cell would be shorter than half its full width `h r^k`, it is merged into the
//! previous one instead (the node before it is dropped), so no sliver cell appears. A side
//! whose extent is the core's end has no growth (a half model on its symmetry plane).
//! Cost: O(nodes).

use super::Mesh;
use crate::{Error, Result};

/// Node coordinates along one axis: uniform cells of width `size` on `core`, geometric
/// growth by `ratio` outward to `extent` (see the module documentation).
///
/// Errors: non-finite input, `size <= 0`, `ratio < 1`, `extent` not containing `core`, a
/// core that is not a whole number of cells (to 1e-9 relative), more than 10^6 nodes.
pub fn core_and_growth(
    core: [f64; 2],
    size: f64,
    ratio: f64,
    extent: [f64; 2],
) -> Result<Vec<f64>> {
    for (what, v) in [
        ("core start", core[0]),
        ("core end", core[1]),
        ("extent start", extent[0]),
        ("extent end", extent[1]),
    ] {
        if !v.is_finite() {
            return Err(Error::input(
                &format!("graded line {what}"),
                v,
                "must be finite",
            ));
        }
    }
    if !(size.is_finite() && size > 0.0) {
        return Err(Error::input(
            "graded line core cell size",
            size,
            "must be finite and > 0",
        ));
    }
    if !(ratio.is_finite() && ratio >= 1.0) {
        return Err(Error::input(
            "graded line growth ratio",
            ratio,
            "must be finite and >= 1",
        ));
    }
    if !(core[0] < core[1]) {
        return Err(Error::input(
            "graded line core",
            format!("[{}, {}]", core[0], core[1]),
            "must have start < end",
        ));
    }
    if !(extent[0] <= core[0] && core[1] <= extent[1]) {
        return Err(Error::input(
            "graded line extent",
            format!("[{}, {}]", extent[0], extent[1]),
            &format!("must contain the core [{}, {}]", core[0], core[1]),
        ));
    }
    let cells = (core[1] - core[0]) / size;
    let n = cells.round();
    if (cells - n).abs() > 1e-9 * cells.max(1.0) || !(1.0..=1e6).contains(&n) {
        return Err(Error::input(
            "graded line core cell size",
            size,
            &format!(
                "must divide the core length {} into a whole number of cells (it gives {cells})",
                core[1] - core[0]
            ),
        ));
    }
    let n = n as usize;
    let below = growth(size, ratio, core[0] - extent[0])?;
    let above = growth(size, ratio, extent[1] - core[1])?;
    let mut x: Vec<f64> = below.iter().rev().map(|s| core[0] - s).collect();
    x.extend((0..=n).map(|k| core[0] + (core[1] - core[0]) * k as f64 / n as f64));
    x.extend(above.iter().map(|s| core[1] + s));
    // Exact ends.
    x[0] = extent[0];
    *x.last_mut().expect("at least two nodes") = extent[1];
    Ok(x)
}

/// Distances beyond the core's end of the growth nodes, the last one exactly `length`.
fn growth(h: f64, r: f64, length: f64) -> Result<Vec<f64>> {
    let mut s = Vec::new();
    if length == 0.0 {
        return Ok(s);
    }
    let (mut at, mut width) = (0.0, h);
    loop {
        width *= r;
        if s.len() > 1_000_000 {
            return Err(Error::input(
                "graded line extent",
                length,
                "needs more than 10^6 nodes",
            ));
        }
        if at + width >= length {
            if length - at < 0.5 * width && !s.is_empty() {
                s.pop();
            }
            s.push(length);
            return Ok(s);
        }
        at += width;
        s.push(at);
    }
}

impl Mesh {
    /// A structured block on explicit node lines: node (i, j, k) at `(x[i], y[j], z[k])`.
    /// Numbering, face sets "x-" ... "z+" and columns as [`Mesh::block_graded`].
    ///
    /// Errors: an axis with fewer than 2 coordinates, a coordinate not finite, a line not
    /// strictly increasing (naming the axis and index), more than
    /// [`super::MAX_BLOCK_NODES`] nodes.
    pub fn block_lines(x: &[f64], y: &[f64], z: &[f64]) -> Result<Mesh> {
        let lines = [x, y, z];
        for (d, line) in lines.iter().enumerate() {
            let axis = ["x", "y", "z"][d];
            if line.len() < 2 {
                return Err(Error::input(
                    &format!("number of {axis} coordinates"),
                    line.len(),
                    "must be >= 2",
                ));
            }
            for (i, v) in line.iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::input(&format!("{axis}[{i}]"), v, "must be finite"));
                }
                if i > 0 && !(line[i - 1] < *v) {
                    return Err(Error::input(
                        &format!("{axis}[{i}]"),
                        v,
                        &format!(
                            "must be > {axis}[{}] = {} (strictly increasing)",
                            i - 1,
                            line[i - 1]
                        ),
                    ));
                }
            }
        }
        let node_count = lines
            .iter()
            .try_fold(1usize, |acc, l| acc.checked_mul(l.len()))
            .filter(|&n| n <= super::MAX_BLOCK_NODES)
            .ok_or_else(|| {
                Error::input(
                    "node lines",
                    format!("{} x {} x {}", x.len(), y.len(), z.len()),
                    &format!("must give at most {} nodes", super::MAX_BLOCK_NODES),
                )
            })?;
        Ok(Mesh::grid(
            &[x.to_vec(), y.to_vec(), z.to_vec()],
            node_count,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec3;

    /// The peer's Hertz mesh family: uniform core of cell size hc on [-3.2, 3.2], growth
    /// 1.2 outward to +-20. The listed coordinates are computed here independently, from
    /// the closed form s_k = h r (r^k - 1)/(r - 1) of the definition (module doc) and the
    /// rule for the last cell, by counting the whole cells that fit.
    #[test]
    fn hertz_family_core_and_growth_matches_the_closed_form() {
        let (a, r, outer) = (3.2, 1.2_f64, 20.0);
        for hc in [0.8, 0.4, 0.2, 0.1, 0.05] {
            let got = core_and_growth([-a, a], hc, r, [-outer, outer]).unwrap();
            let s = |k: i32| hc * r * (r.powi(k) - 1.0) / (r - 1.0);
            let length = outer - a;
            // Whole growth cells that fit: the largest m with s_m < L.
            let m = (0..).find(|&k| s(k + 1) >= length).unwrap();
            let cut = length - s(m);
            let full = hc * r.powi(m + 1);
            let mut side: Vec<f64> = (1..=m).map(s).collect();
            if cut < 0.5 * full && m > 0 {
                side.pop();
            }
            side.push(length);
            let n = (2.0 * a / hc).round() as usize;
            let mut listed: Vec<f64> = side.iter().rev().map(|t| -a - t).collect();
            listed.extend((0..=n).map(|k| -a + hc * k as f64));
            listed.extend(side.iter().map(|t| a + t));
            assert_eq!(got.len(), listed.len(), "hc = {hc}");
            for (i, (g, l)) in got.iter().zip(&listed).enumerate() {
                // Round-off of sums of ~50 terms of size <= 20.
                assert!(
                    (g - l).abs() < 1e-12,
                    "hc = {hc}, node {i}: {g} against {l}"
                );
            }
            // Symmetric, exact ends, uniform core, growth ratio r between whole cells.
            assert_eq!((got[0], got[got.len() - 1]), (-outer, outer));
            for (g, h) in got.iter().zip(got.iter().rev()) {
                assert!((g + h).abs() < 1e-12);
            }
            let w: Vec<f64> = got.windows(2).map(|p| p[1] - p[0]).collect();
            let start = side.len();
            for k in start..start + n {
                assert!((w[k] - hc).abs() < 1e-12, "core cell {k}");
            }
            for k in start + n + 1..w.len() - 1 {
                assert!((w[k] / w[k - 1] - r).abs() < 1e-9, "growth cell {k}");
            }
        }
        // hc = 0.4: 16 core cells; the first node beyond the core is at 3.2 + 0.48.
        let x = core_and_growth([-a, a], 0.4, r, [-outer, outer]).unwrap();
        assert!(x.iter().any(|&v| (v - 3.68).abs() < 1e-12));
    }

    #[test]
    fn half_models_and_errors() {
        let x = core_and_growth([0.0, 1.0], 0.25, 1.5, [0.0, 3.0]).unwrap();
        assert_eq!(x[..5], [0.0, 0.25, 0.5, 0.75, 1.0]);
        assert_eq!(*x.last().unwrap(), 3.0);
        let e = |r: Result<Vec<f64>>| r.unwrap_err().to_string();
        assert!(e(core_and_growth([0.0, 1.0], 0.3, 1.2, [0.0, 2.0])).contains("whole number"));
        assert!(e(core_and_growth([0.0, 1.0], 0.25, 0.9, [0.0, 2.0])).contains(">= 1"));
        assert!(e(core_and_growth([0.0, 1.0], 0.25, 1.2, [0.5, 2.0])).contains("contain"));
        assert!(e(core_and_growth([0.0, 1.0], 0.0, 1.2, [0.0, 2.0])).contains("> 0"));
    }

    #[test]
    fn block_lines_equals_block_and_refuses_bad_lines() {
        let lines: Vec<f64> = (0..=4).map(|i| i as f64 * 0.5).collect();
        let m = Mesh::block_lines(&lines, &[0.0, 1.0], &[0.0, 0.5, 1.0]).unwrap();
        let b = Mesh::block(Vec3::zeros(), Vec3::new(2.0, 1.0, 1.0), [4, 1, 2]).unwrap();
        assert_eq!(m.nodes, b.nodes);
        assert_eq!(m.hexes, b.hexes);
        assert_eq!(m.node_set("z+").unwrap(), b.node_set("z+").unwrap());
        assert_eq!(m.columns(), b.columns());
        let e = Mesh::block_lines(&[0.0, 1.0, 1.0], &[0.0, 1.0], &[0.0, 1.0])
            .unwrap_err()
            .to_string();
        assert!(e.contains("x[2] = 1 must be > x[1]"), "{e}");
        assert!(Mesh::block_lines(&[0.0], &[0.0, 1.0], &[0.0, 1.0]).is_err());
        assert!(Mesh::block_lines(&[0.0, f64::NAN], &[0.0, 1.0], &[0.0, 1.0]).is_err());
    }
}
