//! The forming limit curve (FLC) and the formability zones of a sheet point.
//!
//! # Forming limit curve
//!
//! All strains are true (logarithmic) in-plane principal strains of the mid-surface, minor
//! `ε2` and major `ε1 >= ε2`. The curve gives the limit major strain `ε1*(ε2)`.
//!
//! * **Keeler-Brazier (NADDRG)**, the default, from the Swift exponent `n` and the initial
//!   sheet thickness `t` in mm (S. P. Keeler and W. G. Brazier, "Relationship between
//!   laboratory material characterization and press-shop formability", Microalloying 75,
//!   1977, pp. 517-530; the form below is the one of the AHSS Application Guidelines,
//!   "Forming Limit Curves"). The plane-strain intercept, an engineering strain in percent,
//!   is `FLC0 = (23.3 + 14.13 t) n / 0.21`; with `e0 = FLC0 / 100`:
//!   - left side (`ε2 < 0`): a line of constant thinning in true strain,
//!     `ε1* = ln(1 + e0) - ε2`;
//!   - right side (`ε2 >= 0`): slope 0.6 in engineering strains, `e1 = e0 + 0.6 e2`, i.e.
//!     `ε1* = ln(1 + e0 + 0.6 (exp(ε2) - 1))`.
//!   Both give `ln(1 + e0)` at `ε2 = 0`, so the curve is continuous.
//! * **A table** of `(ε2, ε1*)` points given by the script (setting `flc`), strictly
//!   increasing in `ε2`: linear interpolation between the points, the end segments
//!   extended beyond them (a single point is a horizontal line).
//!
//! The **margin** of a point is the distance to the curve in major strain,
//! `m = ε1*(ε2) - ε1`: positive below the curve, zero on it, negative beyond it.
//!
//! # Zones
//!
//! The first that applies, with the thresholds of [`Thresholds`] (defaults in brackets):
//!
//! | code | zone | condition | colour |
//! |---|---|---|---|
//! | 6 | crack | `m < 0` | red `#d62728` |
//! | 5 | risk of crack | `0 <= m < safety_margin` (0.1) | yellow `#f0c419` |
//! | 4 | excessive thinning | thinning `> thinning_limit` (25 %) | orange `#ff7f0e` |
//! | 3 | wrinkling tendency | `ε2 < 0` and `ln(t/t0) > wrinkle_limit` (0.02) | purple `#6a3d9a` |
//! | 1 | insufficient stretch | `|ε1| < stretch_limit` and `|ε2| < stretch_limit` (0.02) | grey `#9e9e9e` |
//! | 2 | compression | `ε2 < 0` and `ln(t/t0) > 0` | blue `#5fa8d3` |
//! | 0 | safe | otherwise | green `#2ca02c` |
//!
//! Codes grow with severity, so the worst zone of a part is its largest code. Without a
//! curve (no table and no Swift law) the crack and risk zones are never reached.

use crate::{Error, Result};

/// A forming limit curve in true strains (module doc).
#[derive(Clone, Debug, PartialEq)]
pub enum Flc {
    /// Keeler-Brazier from the Swift exponent and the thickness in mm.
    KeelerBrazier { n: f64, thickness_mm: f64 },
    /// `(minor, major)` points, minor strictly increasing.
    Table(Vec<[f64; 2]>),
}

impl Flc {
    /// Millimetres per length unit of the script's `units.length` (`""`, the default, is
    /// mm: the engine is unit-free and its shipped models are in mm), for the Keeler-Brazier
    /// curve's thickness, which its authors fitted in mm; None for a name not listed here.
    pub fn millimetres_per(unit: &str) -> Option<f64> {
        match unit.trim() {
            "" | "mm" => Some(1.0),
            "m" => Some(1000.0),
            "cm" => Some(10.0),
            "um" | "µm" | "micron" => Some(1e-3),
            "in" | "inch" => Some(25.4),
            _ => None,
        }
    }

    /// The Keeler-Brazier curve; `n >= 0` and `thickness_mm > 0`, both finite.
    pub fn keeler_brazier(n: f64, thickness_mm: f64) -> Result<Flc> {
        if !(n.is_finite() && n >= 0.0) {
            return Err(Error::input(
                "FLC hardening exponent n",
                n,
                "must be finite and >= 0",
            ));
        }
        if !(thickness_mm.is_finite() && thickness_mm > 0.0) {
            return Err(Error::input(
                "FLC sheet thickness",
                thickness_mm,
                "must be finite and > 0 (mm)",
            ));
        }
        Ok(Flc::KeelerBrazier { n, thickness_mm })
    }

    /// A table of `[minor, major]` points: at least one, finite, minor strictly increasing.
    pub fn table(points: Vec<[f64; 2]>) -> Result<Flc> {
        if points.is_empty() {
            return Err(Error::Input(
                "flc: the table has no point ([minor, major] pairs)".into(),
            ));
        }
        for (i, p) in points.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(Error::Input(format!(
                    "flc: point {i} = {p:?} must be finite"
                )));
            }
            if i > 0 && p[0] <= points[i - 1][0] {
                return Err(Error::Input(format!(
                    "flc: point {i} has minor strain {} not above the previous point's {}; the \
                     points must be in strictly increasing minor strain",
                    p[0],
                    points[i - 1][0]
                )));
            }
        }
        Ok(Flc::Table(points))
    }

    /// The plane-strain intercept `FLC0` of Keeler-Brazier, engineering strain in percent.
    pub fn keeler_brazier_flc0_pct(n: f64, thickness_mm: f64) -> f64 {
        (23.3 + 14.13 * thickness_mm) * n / 0.21
    }

    /// The limit major strain `ε1*` at minor strain `minor`.
    pub fn major_limit(&self, minor: f64) -> f64 {
        match self {
            Flc::KeelerBrazier { n, thickness_mm } => {
                let e0 = Self::keeler_brazier_flc0_pct(*n, *thickness_mm) / 100.0;
                if minor < 0.0 {
                    e0.ln_1p() - minor
                } else {
                    (e0 + 0.6 * minor.exp_m1()).ln_1p()
                }
            }
            Flc::Table(p) => interpolate(p, minor),
        }
    }

    /// `ε1*(minor) - major`: negative beyond the curve.
    pub fn margin(&self, major: f64, minor: f64) -> f64 {
        self.major_limit(minor) - major
    }

    /// For summary.json and the charts.
    pub fn describe(&self) -> serde_json::Value {
        match self {
            Flc::KeelerBrazier { n, thickness_mm } => serde_json::json!({
                "kind": "Keeler-Brazier (NADDRG)",
                "n": n,
                "thickness_mm": thickness_mm,
                "flc0_pct": Self::keeler_brazier_flc0_pct(*n, *thickness_mm),
                "flc0_true": self.major_limit(0.0),
            }),
            Flc::Table(p) => serde_json::json!({ "kind": "table", "points": p }),
        }
    }
}

/// Piecewise-linear through `p`, its end segments extended.
fn interpolate(p: &[[f64; 2]], x: f64) -> f64 {
    if p.len() == 1 {
        return p[0][1];
    }
    let k = p.partition_point(|q| q[0] <= x).clamp(1, p.len() - 1);
    let (a, b) = (p[k - 1], p[k]);
    a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0])
}

/// The zone thresholds (module doc), all settable.
#[derive(Clone, Debug, PartialEq)]
pub struct Thresholds {
    /// Risk of crack within this margin below the FLC (major strain).
    pub safety_margin: f64,
    /// Excessive thinning beyond this thinning, percent.
    pub thinning_limit: f64,
    /// Insufficient stretch while both principal strains are smaller in magnitude.
    pub stretch_limit: f64,
    /// Wrinkling tendency beyond this thickening strain `ln(t/t0)` under `ε2 < 0`.
    pub wrinkle_limit: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds {
            safety_margin: 0.1,
            thinning_limit: 25.0,
            stretch_limit: 0.02,
            wrinkle_limit: 0.02,
        }
    }
}

/// A formability zone; the discriminant is the code written in the frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Zone {
    Safe = 0,
    InsufficientStretch = 1,
    Compression = 2,
    Wrinkling = 3,
    ExcessiveThinning = 4,
    RiskOfCrack = 5,
    Crack = 6,
}

impl Zone {
    /// Every zone, by code.
    pub const ALL: [Zone; 7] = [
        Zone::Safe,
        Zone::InsufficientStretch,
        Zone::Compression,
        Zone::Wrinkling,
        Zone::ExcessiveThinning,
        Zone::RiskOfCrack,
        Zone::Crack,
    ];

    pub fn code(self) -> u8 {
        self as u8
    }

    /// The zone's name in summary.json and the charts.
    pub fn name(self) -> &'static str {
        match self {
            Zone::Safe => "safe",
            Zone::InsufficientStretch => "insufficient_stretch",
            Zone::Compression => "compression",
            Zone::Wrinkling => "wrinkling_tendency",
            Zone::ExcessiveThinning => "excessive_thinning",
            Zone::RiskOfCrack => "risk_of_crack",
            Zone::Crack => "crack",
        }
    }

    /// The zone's colour in the charts (module doc).
    pub fn colour(self) -> &'static str {
        match self {
            Zone::Safe => "#2ca02c",
            Zone::InsufficientStretch => "#9e9e9e",
            Zone::Compression => "#5fa8d3",
            Zone::Wrinkling => "#6a3d9a",
            Zone::ExcessiveThinning => "#ff7f0e",
            Zone::RiskOfCrack => "#f0c419",
            Zone::Crack => "#d62728",
        }
    }
}

/// The strain state of one sheet point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheetPoint {
    pub major: f64,
    pub minor: f64,
    /// `ln(t / t0)`.
    pub thickness_strain: f64,
    /// `100 (1 - t / t0)`.
    pub thinning_pct: f64,
}

/// The zone of `p` given its FLC margin (`None`: no curve), module doc's table.
pub fn zone(p: &SheetPoint, margin: Option<f64>, t: &Thresholds) -> Zone {
    match margin {
        Some(m) if m < 0.0 => return Zone::Crack,
        Some(m) if m < t.safety_margin => return Zone::RiskOfCrack,
        _ => {}
    }
    if p.thinning_pct > t.thinning_limit {
        Zone::ExcessiveThinning
    } else if p.minor < 0.0 && p.thickness_strain > t.wrinkle_limit {
        Zone::Wrinkling
    } else if p.major.abs() < t.stretch_limit && p.minor.abs() < t.stretch_limit {
        Zone::InsufficientStretch
    } else if p.minor < 0.0 && p.thickness_strain > 0.0 {
        Zone::Compression
    } else {
        Zone::Safe
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeler_brazier_intercept_and_branches() {
        // n = 0.21, t = 1 mm: FLC0 = 23.3 + 14.13 = 37.43 % (engineering).
        let flc = Flc::keeler_brazier(0.21, 1.0).unwrap();
        let e0: f64 = 0.3743;
        assert!((flc.major_limit(0.0) - e0.ln_1p()).abs() < 1e-15);
        // Left: constant thinning, slope -1 in true strain.
        assert!((flc.major_limit(-0.2) - (e0.ln_1p() + 0.2)).abs() < 1e-15);
        // Right: slope 0.6 in engineering strain at e2 = 10 %.
        let e1 = flc.major_limit(0.1_f64.ln_1p()).exp_m1();
        assert!((e1 - (e0 + 0.06)).abs() < 1e-14, "{e1}");
        // Continuous at the plane-strain point (the two branches meet).
        assert!((flc.major_limit(-1e-15) - flc.major_limit(0.0)).abs() < 1e-14);
    }

    #[test]
    fn a_point_on_the_curve_has_margin_zero() {
        let table = Flc::table(vec![[-0.2, 0.5], [0.0, 0.3], [0.3, 0.45]]).unwrap();
        for flc in [table, Flc::keeler_brazier(0.18, 0.81).unwrap()] {
            for minor in [-0.3, -0.1, 0.0, 0.15, 0.4] {
                let on = flc.major_limit(minor);
                assert_eq!(flc.margin(on, minor), 0.0, "{flc:?} at {minor}");
                assert!(flc.margin(on + 1e-9, minor) < 0.0);
            }
        }
        let t = Flc::table(vec![[-0.2, 0.5], [0.0, 0.3], [0.3, 0.45]]).unwrap();
        assert!((t.major_limit(-0.1) - 0.4).abs() < 1e-15);
        assert!(
            (t.major_limit(0.6) - 0.6).abs() < 1e-14,
            "the last segment extended"
        );
    }

    #[test]
    fn bad_tables_are_refused_by_point() {
        let e = Flc::table(vec![[0.0, 0.3], [0.0, 0.4]])
            .unwrap_err()
            .to_string();
        assert!(e.contains("point 1"), "{e}");
        let e = Flc::table(vec![[f64::NAN, 0.3]]).unwrap_err().to_string();
        assert!(e.contains("point 0"), "{e}");
        assert!(Flc::table(vec![]).is_err());
        assert!(Flc::keeler_brazier(0.2, 0.0).is_err());
    }

    /// Each boundary at its threshold: on the threshold the milder zone, just past it the
    /// severer one.
    #[test]
    fn zone_boundaries_at_their_thresholds() {
        let t = Thresholds::default();
        let p = |major, minor, ts: f64| SheetPoint {
            major,
            minor,
            thickness_strain: ts,
            thinning_pct: 100.0 * (1.0 - ts.exp()),
        };
        let safe = p(0.1, 0.05, -0.15);
        assert_eq!(zone(&safe, Some(0.0), &t), Zone::RiskOfCrack);
        assert_eq!(zone(&safe, Some(-1e-12), &t), Zone::Crack);
        assert_eq!(zone(&safe, Some(0.1), &t), Zone::Safe);
        assert_eq!(zone(&safe, Some(0.1 - 1e-12), &t), Zone::RiskOfCrack);
        let mut thin = safe;
        thin.thinning_pct = 25.0;
        assert_eq!(zone(&thin, None, &t), Zone::Safe);
        thin.thinning_pct = 25.0 + 1e-9;
        assert_eq!(zone(&thin, None, &t), Zone::ExcessiveThinning);
        assert_eq!(zone(&p(0.1, -0.12, 0.02), None, &t), Zone::Compression);
        assert_eq!(
            zone(&p(0.1, -0.12, 0.02 + 1e-12), None, &t),
            Zone::Wrinkling
        );
        assert_eq!(zone(&p(0.1, -0.12, 0.0), None, &t), Zone::Safe);
        assert_eq!(zone(&p(0.02, 0.0, -0.02), None, &t), Zone::Safe);
        assert_eq!(
            zone(&p(0.02 - 1e-12, 0.0, -0.02), None, &t),
            Zone::InsufficientStretch
        );
        assert_eq!(zone(&p(0.01, -0.02, 0.01), None, &t), Zone::Compression);
        assert_eq!(
            zone(&p(0.01, -0.02 + 1e-12, 0.01), None, &t),
            Zone::InsufficientStretch
        );
        let codes: Vec<u8> = Zone::ALL.iter().map(|z| z.code()).collect();
        assert_eq!(codes, (0..7).collect::<Vec<u8>>());
    }
}
