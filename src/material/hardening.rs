//! Isotropic hardening laws: the current yield stress `σ_y(ε̄p)` as a function of the
//! equivalent plastic strain `ε̄p` (work-conjugate to the yield function's equivalent
//! stress), and its slope `h = dσ_y/dε̄p` for the consistent tangent.

use crate::{Error, Result};

/// An isotropic hardening law `σ_y(ε̄p)`, defined for `ε̄p >= 0`.
///
/// Build with the validated constructors ([`Hardening::swift`], [`Hardening::voce`],
/// [`Hardening::linear`], [`Hardening::tabulated`]); they refuse parameters for which the
/// yield stress could be non-positive or softening (a decreasing `σ_y` makes the return
/// mapping non-unique and the local problem ill-posed).
#[derive(Clone, Debug, PartialEq)]
pub enum Hardening {
    /// Swift: `σ_y = C (ε0 + ε̄p)^n`, slope `h = C n (ε0 + ε̄p)^(n-1)`.
    /// The initial yield stress is `C ε0^n`; `ε0 > 0` keeps the slope finite at `ε̄p = 0`.
    Swift { c: f64, eps0: f64, n: f64 },
    /// Voce (saturation): `σ_y = s0 + Q (1 - exp(-b ε̄p))`, slope `h = Q b exp(-b ε̄p)`.
    Voce { s0: f64, q: f64, b: f64 },
    /// Linear: `σ_y = s0 + H ε̄p`, slope `h = H`.
    Linear { s0: f64, h: f64 },
    /// Piecewise linear through the points `(ε̄p_i, σ_i)`, strictly increasing in `ε̄p_i`.
    ///
    /// Extrapolation: below the first point the yield stress is flat at `σ_0`; beyond the
    /// last point the last segment's slope continues (a measured curve usually stops
    /// before the strains reached in forming, and a flat continuation would make the
    /// material perfectly plastic there, which localises unrealistically). A one-point
    /// table is perfectly plastic.
    Tabulated { strain: Vec<f64>, stress: Vec<f64> },
}

/// `Err` unless `value` is finite.
fn finite(what: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::input(what, value, "must be finite"))
    }
}

fn positive(what: &str, value: f64) -> Result<f64> {
    if finite(what, value)? > 0.0 {
        Ok(value)
    } else {
        Err(Error::input(what, value, "must be > 0"))
    }
}

fn non_negative(what: &str, value: f64) -> Result<f64> {
    if finite(what, value)? >= 0.0 {
        Ok(value)
    } else {
        Err(Error::input(what, value, "must be >= 0"))
    }
}

impl Hardening {
    /// Swift law `C (ε0 + ε̄p)^n`: `C > 0`, `ε0 > 0`, `n >= 0` (all finite).
    pub fn swift(c: f64, eps0: f64, n: f64) -> Result<Self> {
        Ok(Hardening::Swift {
            c: positive("Swift C", c)?,
            eps0: positive("Swift eps0", eps0)?,
            n: non_negative("Swift n", n)?,
        })
    }

    /// Voce law `s0 + Q (1 - exp(-b ε̄p))`: `s0 > 0`, `Q >= 0`, `b >= 0` (all finite).
    pub fn voce(s0: f64, q: f64, b: f64) -> Result<Self> {
        Ok(Hardening::Voce {
            s0: positive("Voce s0", s0)?,
            q: non_negative("Voce Q", q)?,
            b: non_negative("Voce b", b)?,
        })
    }

    /// Linear law `s0 + H ε̄p`: `s0 > 0`, `H >= 0` (finite).
    pub fn linear(s0: f64, h: f64) -> Result<Self> {
        Ok(Hardening::Linear {
            s0: positive("linear hardening s0", s0)?,
            h: non_negative("linear hardening H", h)?,
        })
    }

    /// Tabulated law through `(strain[i], stress[i])`: equal, non-zero lengths; strains
    /// finite, `>= 0` and strictly increasing; stresses finite, `> 0` and non-decreasing.
    pub fn tabulated(strain: Vec<f64>, stress: Vec<f64>) -> Result<Self> {
        if strain.is_empty() {
            return Err(Error::input(
                "hardening table length",
                0,
                "must be >= 1 (at least one (strain, stress) point)",
            ));
        }
        if strain.len() != stress.len() {
            return Err(Error::input(
                "hardening table stress count",
                stress.len(),
                &format!("must equal the strain count {}", strain.len()),
            ));
        }
        for (i, (&e, &s)) in strain.iter().zip(&stress).enumerate() {
            non_negative(&format!("hardening table strain[{i}]"), e)?;
            positive(&format!("hardening table stress[{i}]"), s)?;
            if i > 0 && e <= strain[i - 1] {
                return Err(Error::input(
                    &format!("hardening table strain[{i}]"),
                    e,
                    &format!(
                        "must be > strain[{}] = {} (strictly increasing)",
                        i - 1,
                        strain[i - 1]
                    ),
                ));
            }
            if i > 0 && s < stress[i - 1] {
                return Err(Error::input(
                    &format!("hardening table stress[{i}]"),
                    s,
                    &format!(
                        "must be >= stress[{}] = {} (no softening)",
                        i - 1,
                        stress[i - 1]
                    ),
                ));
            }
        }
        Ok(Hardening::Tabulated { strain, stress })
    }

    /// Yield stress `σ_y(ε̄p)` (`ε̄p < 0` is treated as 0).
    pub fn yield_stress(&self, eps_p: f64) -> f64 {
        let e = eps_p.max(0.0);
        match self {
            Hardening::Swift { c, eps0, n } => c * (eps0 + e).powf(*n),
            Hardening::Voce { s0, q, b } => s0 + q * (1.0 - (-b * e).exp()),
            Hardening::Linear { s0, h } => s0 + h * e,
            Hardening::Tabulated { strain, stress } => {
                let (i, slope) = segment(strain, stress, e);
                if e <= strain[0] {
                    stress[0]
                } else {
                    stress[i] + slope * (e - strain[i])
                }
            }
        }
    }

    /// Hardening slope `h = dσ_y/dε̄p` (right derivative at table kinks).
    pub fn slope(&self, eps_p: f64) -> f64 {
        let e = eps_p.max(0.0);
        match self {
            Hardening::Swift { c, eps0, n } => c * n * (eps0 + e).powf(n - 1.0),
            Hardening::Voce { q, b, .. } => q * b * (-b * e).exp(),
            Hardening::Linear { h, .. } => *h,
            Hardening::Tabulated { strain, stress } => {
                if e < strain[0] {
                    0.0
                } else {
                    segment(strain, stress, e).1
                }
            }
        }
    }

    /// `(σ_y, h)` at `ε̄p` in one call: the Swift law shares its power
    /// (`h = n σ_y / (ε0 + ε̄p)`, equal to [`slope`](Self::slope) to round-off); the others
    /// are the two functions.
    pub fn yield_stress_and_slope(&self, eps_p: f64) -> (f64, f64) {
        match self {
            Hardening::Swift { c, eps0, n } => {
                let x = eps0 + eps_p.max(0.0);
                let sy = c * x.powf(*n);
                (sy, n * sy / x)
            }
            _ => (self.yield_stress(eps_p), self.slope(eps_p)),
        }
    }

    /// The slope [`yield_stress_and_slope`](Self::yield_stress_and_slope) pairs with the
    /// yield stress `sy = σ_y(ε̄p)` a caller already has: the same bits, without the
    /// Swift law's second power.
    pub fn slope_given_yield_stress(&self, eps_p: f64, sy: f64) -> f64 {
        match self {
            Hardening::Swift { eps0, n, .. } => n * sy / (eps0 + eps_p.max(0.0)),
            _ => self.slope(eps_p),
        }
    }

    /// Initial yield stress `σ_y(0)`.
    pub fn initial_yield_stress(&self) -> f64 {
        self.yield_stress(0.0)
    }

    /// A short description for logs.
    pub fn describe(&self) -> String {
        match self {
            Hardening::Swift { c, eps0, n } => format!("Swift C={c} eps0={eps0} n={n}"),
            Hardening::Voce { s0, q, b } => format!("Voce s0={s0} Q={q} b={b}"),
            Hardening::Linear { s0, h } => format!("linear s0={s0} H={h}"),
            Hardening::Tabulated { strain, .. } => format!("tabulated ({} points)", strain.len()),
        }
    }
}

/// The table segment `(i, slope)` used at `e >= strain[0]`: the last `i` with
/// `strain[i] <= e` (clamped to the last segment, so beyond the table the last slope
/// continues). A one-point table has slope 0.
fn segment(strain: &[f64], stress: &[f64], e: f64) -> (usize, f64) {
    let n = strain.len();
    if n == 1 {
        return (0, 0.0);
    }
    let i = strain.partition_point(|&x| x <= e).clamp(1, n - 1) - 1;
    (i, (stress[i + 1] - stress[i]) / (strain[i + 1] - strain[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slope against central differences, away from table kinks and from ε̄p = 0 (where
    /// the law is clamped, so only the right derivative exists).
    fn check_slope(h: &Hardening, at: &[f64]) {
        for &e in at {
            let d = 1e-7;
            let fd = (h.yield_stress(e + d) - h.yield_stress(e - d)) / (2.0 * d);
            let s = h.slope(e);
            assert!(
                (fd - s).abs() <= 1e-6 * s.abs().max(1.0),
                "{h:?} at {e}: {s} vs {fd}"
            );
        }
    }

    /// What the return map's first iterate takes instead of a call: the yield stress it
    /// already has and [`Hardening::slope_given_yield_stress`], bit for bit the call's
    /// pair, for every law, at zero (and a negative round-off) and in the hardening range.
    #[test]
    fn slope_from_a_known_yield_stress_is_the_pairs_own() {
        let laws = [
            Hardening::swift(500.0, 0.01, 0.2).unwrap(),
            Hardening::swift(565.32, 0.007117, 0.2589).unwrap(),
            Hardening::voce(100.0, 50.0, 10.0).unwrap(),
            Hardening::linear(200.0, 1000.0).unwrap(),
            Hardening::tabulated(vec![0.0, 0.1, 0.3], vec![100.0, 150.0, 170.0]).unwrap(),
        ];
        for h in &laws {
            for e in [-1e-18, -0.0, 0.0, 1e-12, 0.003, 0.1, 0.3, 0.77] {
                let (sy, slope) = h.yield_stress_and_slope(e + 0.0);
                assert_eq!(h.yield_stress(e).to_bits(), sy.to_bits(), "{h:?} at {e}");
                assert_eq!(
                    h.slope_given_yield_stress(e, h.yield_stress(e)).to_bits(),
                    slope.to_bits(),
                    "{h:?} at {e}"
                );
            }
        }
    }

    #[test]
    fn laws_and_slopes() {
        let swift = Hardening::swift(500.0, 0.01, 0.2).unwrap();
        assert!((swift.yield_stress(0.0) - 500.0 * 0.01f64.powf(0.2)).abs() < 1e-12);
        assert!((swift.yield_stress(0.49) - 500.0 * 0.5f64.powf(0.2)).abs() < 1e-12);
        let voce = Hardening::voce(100.0, 50.0, 10.0).unwrap();
        assert!((voce.yield_stress(1e3) - 150.0).abs() < 1e-12);
        let lin = Hardening::linear(200.0, 1000.0).unwrap();
        assert_eq!(lin.yield_stress(0.1), 300.0);
        let tab = Hardening::tabulated(vec![0.0, 0.1, 0.3], vec![100.0, 150.0, 170.0]).unwrap();
        assert!((tab.yield_stress(0.05) - 125.0).abs() < 1e-12);
        assert!((tab.yield_stress(0.2) - 160.0).abs() < 1e-12);
        // Beyond the table: last slope (100) continues.
        assert!((tab.yield_stress(0.5) - 190.0).abs() < 1e-12);
        assert!((tab.slope(0.5) - 100.0).abs() < 1e-12);
        let flat = Hardening::tabulated(vec![0.0], vec![250.0]).unwrap();
        assert_eq!((flat.yield_stress(3.0), flat.slope(3.0)), (250.0, 0.0));
        let late = Hardening::tabulated(vec![0.1, 0.2], vec![100.0, 110.0]).unwrap();
        assert_eq!((late.yield_stress(0.0), late.slope(0.0)), (100.0, 0.0));
        check_slope(&swift, &[1e-5, 0.01, 0.3, 2.0]);
        check_slope(&voce, &[1e-5, 0.05, 0.4]);
        check_slope(&lin, &[1e-5, 0.5]);
        check_slope(&tab, &[0.05, 0.2, 0.5]);
        for law in [&swift, &voce, &lin, &tab] {
            for e in [0.0, 1e-5, 0.05, 0.2, 0.5] {
                let (sy, h) = law.yield_stress_and_slope(e);
                assert_eq!(sy, law.yield_stress(e), "{law:?} at {e}");
                assert!(
                    (h - law.slope(e)).abs() <= 1e-14 * h.abs(),
                    "{law:?} at {e}"
                );
            }
        }
    }

    #[test]
    fn invalid_parameters_are_errors_naming_the_value() {
        let msg = |r: Result<Hardening>| r.unwrap_err().to_string();
        assert!(msg(Hardening::swift(0.0, 0.01, 0.2)).contains("Swift C = 0 must be > 0"));
        assert!(msg(Hardening::swift(500.0, -0.1, 0.2)).contains("Swift eps0 = -0.1 must be > 0"));
        assert!(msg(Hardening::swift(500.0, 0.01, -1.0)).contains("Swift n = -1 must be >= 0"));
        assert!(msg(Hardening::swift(f64::NAN, 0.01, 0.2)).contains("Swift C = NaN must be finite"));
        assert!(msg(Hardening::voce(-1.0, 1.0, 1.0)).contains("Voce s0 = -1 must be > 0"));
        assert!(msg(Hardening::voce(1.0, -2.0, 1.0)).contains("Voce Q = -2 must be >= 0"));
        assert!(msg(Hardening::voce(1.0, 2.0, -3.0)).contains("Voce b = -3 must be >= 0"));
        assert!(msg(Hardening::linear(0.0, 1.0)).contains("linear hardening s0 = 0 must be > 0"));
        assert!(msg(Hardening::linear(1.0, -5.0)).contains("linear hardening H = -5 must be >= 0"));
        assert!(msg(Hardening::tabulated(vec![], vec![])).contains("hardening table length = 0"));
        assert!(msg(Hardening::tabulated(vec![0.0, 0.1], vec![1.0]))
            .contains("hardening table stress count = 1 must equal the strain count 2"));
        assert!(msg(Hardening::tabulated(
            vec![0.0, 0.1, 0.1],
            vec![1.0, 2.0, 3.0]
        ))
        .contains("hardening table strain[2] = 0.1 must be > strain[1] = 0.1"));
        assert!(msg(Hardening::tabulated(vec![0.0, 0.1], vec![2.0, 1.0]))
            .contains("hardening table stress[1] = 1 must be >= stress[0] = 2"));
        assert!(msg(Hardening::tabulated(vec![-0.1], vec![2.0]))
            .contains("hardening table strain[0] = -0.1 must be >= 0"));
        assert!(msg(Hardening::tabulated(vec![0.0], vec![0.0]))
            .contains("hardening table stress[0] = 0 must be > 0"));
    }
}
