//! Richardson extrapolation from three meshes, with the observed order, a check of the
//! asymptotic range and a grid-convergence-index (GCI) uncertainty.
//!
//! Meshes 1 (finest), 2, 3 (coarsest) of representative sizes h1 < h2 < h3 give values
//! f1, f2, f3 of one quantity. With r21 = h2 / h1, r32 = h3 / h2, e21 = f2 - f1,
//! e32 = f3 - f2 and s = sign(e32 / e21), the observed order p solves (Celik et al., "Procedure
//! for estimation and reporting of uncertainty due to discretization in CFD applications",
//! J. Fluids Eng. 130, 2008)
//!
//! ```text
//! p ln r21 = ln|e32 / e21| + q(p),   q(p) = ln((r21^p - s) / (r32^p - s))
//! ```
//!
//! (q = 0 for a constant ratio, so p = ln(e32 / e21) / ln r). For f_h = f0 + C h^p this is
//! exact, and the extrapolated value
//!
//! ```text
//! f_ext = (r21^p f1 - f2) / (r21^p - 1)
//! ```
//!
//! is f0. The sequence is taken as asymptotic when it converges monotonically (the
//! convergence ratio R = e21 / e32 lies in (0, 1)) and p lies in the stated band; then the
//! uncertainty is Roache's three-mesh GCI, U = 1.25 |f_ext - f1| (= 1.25 |e21| / (r21^p - 1)).
//! Otherwise p is replaced by an assumed order, f_ext comes from the two finest meshes, and
//! U = 3 |f_ext - f1| (Roache's factor for two meshes or an unproven order). With the formal
//! order as the assumed one and a band such as [0.5, 2.1] for a second-order method, this is
//! the rule of Eca and Hoekstra (J. Comput. Phys. 262, 2014) for observed orders above the
//! formal one: a coarse mesh outside the asymptotic range makes the observed order too high,
//! and trusting it would shrink both the correction and the band. U is a band around
//! the fine solution f1 that should hold the exact value; it also bounds the error of f_ext,
//! which lies inside it.
//!
//! Cost: a bisection of at most [`MAX_BISECTIONS`] steps for a non-constant ratio, O(1)
//! otherwise.

use serde::{Deserialize, Serialize};

/// Safety factor of the GCI when three meshes show the asymptotic range (Roache).
pub const SAFETY_ASYMPTOTIC: f64 = 1.25;
/// Safety factor when the order is assumed (two meshes, or a sequence not asymptotic).
pub const SAFETY_ASSUMED: f64 = 3.0;
/// Bisection steps for the observed order of a non-constant ratio (2^-60 of the bracket).
pub const MAX_BISECTIONS: usize = 60;
/// Widest order searched for a non-constant ratio.
const ORDER_BRACKET: (f64, f64) = (1e-6, 50.0);

/// One mesh of a sequence: its representative cell size and the value it gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    pub h: f64,
    pub value: f64,
}

/// How the order is judged and what replaces it when the meshes do not show it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OrderRule {
    /// The observed order must lie in [min, max] for the sequence to count as asymptotic.
    pub min: f64,
    pub max: f64,
    /// The order used when the sequence is not asymptotic.
    pub assumed: f64,
}

/// The extrapolated value of one quantity and how far it can be trusted.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Extrapolation {
    /// The extrapolated value f_ext.
    pub value: f64,
    /// The order used: observed when `asymptotic`, else the assumed one.
    pub order: f64,
    /// The order the three meshes show (None: no finite order, e.g. two equal values).
    pub observed_order: Option<f64>,
    /// Convergence ratio R = e21 / e32: in (0, 1) monotone, < 0 oscillating, >= 1 diverging.
    pub convergence_ratio: f64,
    /// Monotone convergence with the observed order inside the rule's band.
    pub asymptotic: bool,
    /// Why the sequence is or is not taken as asymptotic, in words.
    pub verdict: String,
    /// GCI band around the finest mesh's value: |exact - f1| <= this (absolute).
    pub uncertainty: f64,
    /// `uncertainty / |value|`.
    pub relative_uncertainty: f64,
    /// |f1 - f_ext| / |f_ext|: the finest mesh's own estimated error.
    pub finest_error: f64,
}

/// r^p, the factor the error falls by when the mesh is refined by r.
fn gain(r: f64, p: f64) -> f64 {
    r.powf(p)
}

/// Observed order of three meshes (see the module doc), or None when the differences give no
/// finite order (a zero difference, or no root for a non-constant ratio).
pub fn observed_order(fine: Level, medium: Level, coarse: Level) -> Option<f64> {
    let (e21, e32) = (medium.value - fine.value, coarse.value - medium.value);
    if e21 == 0.0 || e32 == 0.0 || !(e21 / e32).is_finite() {
        return None;
    }
    let (r21, r32) = (medium.h / fine.h, coarse.h / medium.h);
    let s = (e32 / e21).signum();
    let log_ratio = (e32 / e21).abs().ln();
    if (r21 - r32).abs() <= 1e-12 * r21 {
        let p = log_ratio / r21.ln();
        return (p.is_finite() && p > 0.0).then_some(p);
    }
    // g(p) = p ln r21 - ln|e32/e21| - q(p); a root in the bracket by bisection.
    let g = |p: f64| {
        let q = ((gain(r21, p) - s) / (gain(r32, p) - s)).ln();
        p * r21.ln() - log_ratio - q
    };
    let (mut lo, mut hi) = ORDER_BRACKET;
    let (mut g_lo, g_hi) = (g(lo), g(hi));
    if !(g_lo.is_finite() && g_hi.is_finite()) || g_lo.signum() == g_hi.signum() {
        return None;
    }
    for _ in 0..MAX_BISECTIONS {
        let mid = 0.5 * (lo + hi);
        let g_mid = g(mid);
        if !g_mid.is_finite() {
            return None;
        }
        if g_mid.signum() == g_lo.signum() {
            lo = mid;
            g_lo = g_mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Extrapolates one quantity from three meshes, given finest first. Errors when the sizes
/// are not strictly increasing or not finite.
pub fn extrapolate(levels: [Level; 3], rule: OrderRule) -> Result<Extrapolation, String> {
    let [fine, medium, coarse] = levels;
    let sizes_ok = levels
        .iter()
        .all(|l| l.h.is_finite() && l.h > 0.0 && l.value.is_finite());
    if !(sizes_ok && fine.h < medium.h && medium.h < coarse.h) {
        return Err(format!(
            "a Richardson extrapolation needs three finite values on meshes of strictly growing size, finest first; got h = {}, {}, {}",
            fine.h, medium.h, coarse.h
        ));
    }
    let (e21, e32) = (medium.value - fine.value, coarse.value - medium.value);
    let ratio = if e32 == 0.0 { f64::INFINITY } else { e21 / e32 };
    let observed = observed_order(fine, medium, coarse);
    let verdict_of = |p: Option<f64>| -> Result<String, String> {
        if e21 == 0.0 {
            return Err("the two finest meshes give the same value".into());
        }
        if ratio < 0.0 {
            return Err(format!("oscillating (R = {ratio:.3} < 0)"));
        }
        if ratio >= 1.0 {
            return Err(format!("not converging (R = {ratio:.3} >= 1)"));
        }
        match p {
            None => Err("no finite observed order".into()),
            Some(p) if p < rule.min || p > rule.max => Err(format!(
                "observed order {p:.2} outside [{}, {}]",
                rule.min, rule.max
            )),
            Some(p) => Ok(format!(
                "monotone (R = {ratio:.3}), observed order {p:.2} in [{}, {}]",
                rule.min, rule.max
            )),
        }
    };
    let (asymptotic, order, safety, verdict) = match verdict_of(observed) {
        Ok(v) => (true, observed.unwrap_or(rule.assumed), SAFETY_ASYMPTOTIC, v),
        Err(why) => (
            false,
            rule.assumed,
            SAFETY_ASSUMED,
            format!("not asymptotic: {why}; order {} assumed", rule.assumed),
        ),
    };
    let r21 = medium.h / fine.h;
    let value = (gain(r21, order) * fine.value - medium.value) / (gain(r21, order) - 1.0);
    let uncertainty = safety * (value - fine.value).abs();
    Ok(Extrapolation {
        value,
        order,
        observed_order: observed,
        convergence_ratio: ratio,
        asymptotic,
        verdict,
        uncertainty,
        relative_uncertainty: uncertainty / value.abs(),
        finest_error: (fine.value - value).abs() / value.abs(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const RULE: OrderRule = OrderRule {
        min: 0.5,
        max: 3.0,
        assumed: 1.0,
    };

    fn manufactured(f0: f64, c: f64, p: f64, h: [f64; 3]) -> [Level; 3] {
        h.map(|h| Level {
            h,
            value: f0 + c * h.powf(p),
        })
    }

    #[test]
    fn constant_ratio_recovers_value_and_order_to_round_off() {
        for (f0, c, p) in [(5.4, 0.3, 2.0), (35_000.0, -900.0, 1.3), (2.9, 0.05, 0.8)] {
            let e = extrapolate(manufactured(f0, c, p, [1.0, 2.0, 4.0]), RULE).unwrap();
            assert!(e.asymptotic, "{}", e.verdict);
            // Round-off: the differences e21, e32 carry ~1e-16 |f| each, amplified by
            // 1 / (r^p - 1) and 1 / ln r.
            assert!((e.order - p).abs() < 1e-9, "p {} against {p}", e.order);
            assert!(
                (e.value - f0).abs() < 1e-11 * f0.abs(),
                "f0 {} against {f0}",
                e.value
            );
            // GCI: 1.25 times the finest mesh's true error.
            let true_error = (c * 1f64.powf(p)).abs();
            assert!((e.uncertainty - 1.25 * true_error).abs() < 1e-9 * true_error);
        }
    }

    #[test]
    fn non_constant_ratio_recovers_value_and_order() {
        // The study's in-plane sizes 50/48, 50/25, 50/12: ratios 1.92 and 2.08.
        let h = [50.0 / 48.0, 50.0 / 25.0, 50.0 / 12.0];
        for (f0, c, p) in [(5.4, 0.3, 2.0), (35_000.0, -900.0, 1.3), (2.9, 0.05, 0.8)] {
            let e = extrapolate(manufactured(f0, c, p, h), RULE).unwrap();
            assert!(e.asymptotic, "{}", e.verdict);
            // The bisection stops at 2^-60 of the bracket (4e-17 * 50); round-off dominates.
            assert!((e.order - p).abs() < 1e-9, "p {} against {p}", e.order);
            assert!(
                (e.value - f0).abs() < 1e-11 * f0.abs(),
                "f0 {} against {f0}",
                e.value
            );
        }
    }

    #[test]
    fn oscillating_sequence_is_flagged_and_falls_back_to_the_assumed_order() {
        let levels = [(1.0, 10.1), (2.0, 9.8), (4.0, 10.5)].map(|(h, value)| Level { h, value });
        let e = extrapolate(levels, RULE).unwrap();
        assert!(!e.asymptotic);
        assert!(e.verdict.contains("oscillating"), "{}", e.verdict);
        assert_eq!(e.order, 1.0);
        // Order 1, ratio 2: f_ext = 2 f1 - f2; U = 3 |f_ext - f1|.
        assert!((e.value - 10.4).abs() < 1e-12);
        assert!((e.uncertainty - 0.9).abs() < 1e-12);
    }

    #[test]
    fn diverging_and_out_of_band_sequences_are_flagged() {
        let diverging = [(1.0, 1.0), (2.0, 2.0), (4.0, 2.5)].map(|(h, value)| Level { h, value });
        let e = extrapolate(diverging, RULE).unwrap();
        assert!(
            !e.asymptotic && e.verdict.contains("not converging"),
            "{}",
            e.verdict
        );
        // Order 5 (R = 1/32): converging, but far faster than the elements can.
        let steep = extrapolate(manufactured(1.0, 0.01, 5.0, [1.0, 2.0, 4.0]), RULE).unwrap();
        assert!(
            !steep.asymptotic && steep.verdict.contains("outside"),
            "{}",
            steep.verdict
        );
        assert!((steep.observed_order.unwrap() - 5.0).abs() < 1e-9);
        assert_eq!(steep.order, 1.0);
    }

    #[test]
    fn bad_sizes_are_refused_by_name() {
        let levels = [(2.0, 1.0), (1.0, 2.0), (4.0, 3.0)].map(|(h, value)| Level { h, value });
        let err = extrapolate(levels, RULE).unwrap_err();
        assert!(err.contains("strictly growing size"), "{err}");
    }
}
