//! Hill's 1948 orthotropic quadratic yield function (von Mises as a special case).
//!
//! In the orthotropy axes (x = rolling direction, y = transverse, z = normal) and with
//! the Voigt stress `σ = [σxx, σyy, σzz, σxy, σyz, σzx]` (tensor shear components):
//!
//! ```text
//! φ(σ)² = F (σyy-σzz)² + G (σzz-σxx)² + H (σxx-σyy)² + 2L σyz² + 2M σzx² + 2N σxy²
//!       = σᵀ P σ,
//!
//!     | G+H  -H   -G   0   0   0  |
//!     | -H   F+H  -F   0   0   0  |
//! P = | -G   -F   F+G  0   0   0  |        (rows xx, yy, zz, xy, yz, zx)
//!     |  0    0    0   2N  0   0  |
//!     |  0    0    0   0   2L  0  |
//!     |  0    0    0   0   0   2M |
//! ```
//!
//! and the yield condition `f = φ(σ) - σ_y(ε̄p) <= 0`. Von Mises is `F = G = H = 1/2`,
//! `L = M = N = 3/2`. Associative flow gives the plastic strain rate (Voigt, engineering
//! shear) `ε̇p = λ̇ n`, `n = ∂φ/∂σ = Pσ/φ`; since `φ` is homogeneous of degree one,
//! `σ·ε̇p = λ̇ φ`, so the plastic multiplier `λ̇` is the rate of the equivalent plastic
//! strain work-conjugate to `φ`.
//!
//! # Orthotropy axes
//!
//! By default the axes are the global ones (rolling direction x, sheet normal z).
//! [`Hill48::with_rolling_angle`] turns the rolling direction by an angle about z (the
//! sheet normal): with `Q = [RD, TD, ND]` (columns, global components) the stress in the
//! orthotropy axes is `Qᵀ σ Q = T_σ σ` (Voigt), so the global matrix is `T_σᵀ P T_σ`.
//! Under finite kinematics the yield function acts on the log-space stress of the
//! Lagrangian (reference) frame, so these axes are material axes: they follow the body's
//! rotation exactly (see `material::log_strain`).

use super::{stress_from_tensor, stress_to_tensor, Tangent, Voigt};
use crate::{Error, Result};

/// Hill48 yield function with coefficients `F, G, H, L, M, N`; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hill48 {
    f: f64,
    g: f64,
    h: f64,
    l: f64,
    m: f64,
    n: f64,
    /// Angle of the rolling direction from x about z (radians).
    angle: f64,
    /// `φ² = σᵀ p σ` in global axes (cached: the return mapping uses it in every step).
    p: Tangent,
}

impl Hill48 {
    /// From the coefficients. All finite; `L, M, N > 0`; and `φ` positive definite on
    /// deviatoric stresses, i.e. `F+G, G+H, H+F > 0` and `FG + GH + HF > 0` (individual
    /// `F, G, H` may be negative, as some fitted sheets need).
    pub fn new(f: f64, g: f64, h: f64, l: f64, m: f64, n: f64) -> Result<Self> {
        for (name, v) in [("F", f), ("G", g), ("H", h), ("L", l), ("M", m), ("N", n)] {
            if !v.is_finite() {
                return Err(Error::input(&format!("Hill48 {name}"), v, "must be finite"));
            }
        }
        for (name, v) in [("L", l), ("M", m), ("N", n)] {
            if v <= 0.0 {
                return Err(Error::input(&format!("Hill48 {name}"), v, "must be > 0"));
            }
        }
        for (name, v) in [("F + G", f + g), ("G + H", g + h), ("H + F", h + f)] {
            if v <= 0.0 {
                return Err(Error::input(
                    &format!("Hill48 {name}"),
                    v,
                    "must be > 0 (positive yield function)",
                ));
            }
        }
        let det = f * g + g * h + h * f;
        if det <= 0.0 {
            return Err(Error::input(
                "Hill48 F*G + G*H + H*F",
                det,
                "must be > 0 (positive yield function)",
            ));
        }
        Ok(Hill48::unchecked(f, g, h, l, m, n))
    }

    fn unchecked(f: f64, g: f64, h: f64, l: f64, m: f64, n: f64) -> Self {
        let mut hill = Hill48 {
            f,
            g,
            h,
            l,
            m,
            n,
            angle: 0.0,
            p: Tangent::zeros(),
        };
        hill.p = hill.axis_matrix();
        hill
    }

    /// The same material with its rolling direction at `angle` (radians, finite) from x,
    /// turned about z (the sheet normal); see the module docs.
    pub fn with_rolling_angle(self, angle: f64) -> Result<Self> {
        if !angle.is_finite() {
            return Err(Error::input(
                "rolling-direction angle",
                angle,
                "must be finite",
            ));
        }
        let (s, c) = angle.sin_cos();
        let q = crate::geometry::Mat3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        let t = Tangent::from_fn(|i, m| {
            let mut e = Voigt::zeros();
            e[m] = 1.0;
            stress_from_tensor(&(q.transpose() * stress_to_tensor(&e) * q))[i]
        });
        Ok(Hill48 {
            angle,
            p: t.transpose() * self.axis_matrix() * t,
            ..self
        })
    }

    /// Angle of the rolling direction from x (radians).
    pub fn rolling_angle(&self) -> f64 {
        self.angle
    }

    /// Von Mises: `F = G = H = 1/2`, `L = M = N = 3/2`, `φ = sqrt(3/2 s:s)`.
    pub fn von_mises() -> Self {
        Hill48::unchecked(0.5, 0.5, 0.5, 1.5, 1.5, 1.5)
    }

    /// From the Lankford coefficients `r0, r45, r90` (finite, `> 0`), rolling direction
    /// along x, normalised so that `φ = σxx` in uniaxial tension along x (`G + H = 1`):
    /// the hardening curve is then the rolling-direction tension curve.
    ///
    /// ```text
    /// F = r0 / (r90 (1 + r0)),   G = 1 / (1 + r0),   H = r0 / (1 + r0),
    /// N = (r0 + r90)(1 + 2 r45) / (2 r90 (1 + r0)),   L = M = 3/2.
    /// ```
    ///
    /// The out-of-plane shear coefficients `L, M` cannot be identified from in-plane
    /// tests; 3/2 is the isotropic (von Mises) value, the usual default for sheets.
    pub fn from_lankford(r0: f64, r45: f64, r90: f64) -> Result<Self> {
        for (name, v) in [("r0", r0), ("r45", r45), ("r90", r90)] {
            if !v.is_finite() {
                return Err(Error::input(
                    &format!("Lankford {name}"),
                    v,
                    "must be finite",
                ));
            }
            if v <= 0.0 {
                return Err(Error::input(&format!("Lankford {name}"), v, "must be > 0"));
            }
        }
        Hill48::new(
            r0 / (r90 * (1.0 + r0)),
            1.0 / (1.0 + r0),
            r0 / (1.0 + r0),
            1.5,
            1.5,
            (r0 + r90) * (1.0 + 2.0 * r45) / (2.0 * r90 * (1.0 + r0)),
        )
    }

    /// The coefficients `[F, G, H, L, M, N]`.
    pub fn coefficients(&self) -> [f64; 6] {
        [self.f, self.g, self.h, self.l, self.m, self.n]
    }

    /// The matrix `P` with `φ² = σᵀPσ` in global axes (see the module docs).
    pub fn matrix(&self) -> Tangent {
        self.p
    }

    /// `P` in the orthotropy axes.
    fn axis_matrix(&self) -> Tangent {
        let (f, g, h) = (self.f, self.g, self.h);
        let mut p = Tangent::zeros();
        p[(0, 0)] = g + h;
        p[(1, 1)] = f + h;
        p[(2, 2)] = f + g;
        p[(0, 1)] = -h;
        p[(1, 0)] = -h;
        p[(1, 2)] = -f;
        p[(2, 1)] = -f;
        p[(0, 2)] = -g;
        p[(2, 0)] = -g;
        p[(3, 3)] = 2.0 * self.n;
        p[(4, 4)] = 2.0 * self.l;
        p[(5, 5)] = 2.0 * self.m;
        p
    }

    /// Equivalent stress `φ(σ) = sqrt(σᵀPσ)`.
    pub fn equivalent_stress(&self, stress: &Voigt) -> f64 {
        stress.dot(&(self.p * stress)).max(0.0).sqrt()
    }

    /// A short description for logs.
    pub fn describe(&self) -> String {
        let rd = if self.angle == 0.0 {
            String::new()
        } else {
            format!(" RD at {} deg", self.angle.to_degrees())
        };
        format!(
            "Hill48 F={} G={} H={} L={} M={} N={}{rd}",
            self.f, self.g, self.h, self.l, self.m, self.n
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::von_mises;

    #[test]
    fn von_mises_special_case() {
        let s = Voigt::new(120.0, -30.0, 45.0, 20.0, -70.0, 11.0);
        let vm = Hill48::von_mises();
        assert!((vm.equivalent_stress(&s) - von_mises(&s)).abs() < 1e-12);
        assert_eq!(Hill48::from_lankford(1.0, 1.0, 1.0).unwrap(), vm);
        // Hydrostatic stress does not yield.
        let p = Voigt::new(5.0, 5.0, 5.0, 0.0, 0.0, 0.0);
        assert!(
            Hill48::from_lankford(0.7, 1.3, 2.1)
                .unwrap()
                .equivalent_stress(&p)
                < 1e-12
        );
    }

    #[test]
    fn lankford_normalisation_and_directional_yield() {
        let (r0, r45, r90) = (0.7, 1.3, 2.1);
        let hill = Hill48::from_lankford(r0, r45, r90).unwrap();
        // φ = σ in tension along the rolling direction.
        let sx = Voigt::new(100.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        assert!((hill.equivalent_stress(&sx) - 100.0).abs() < 1e-12);
        // Along 90°: σ90/σ0 = sqrt(r90 (1 + r0) / (r0 (1 + r90))).
        let sy = Voigt::new(0.0, 100.0, 0.0, 0.0, 0.0, 0.0);
        let ratio = 100.0 / hill.equivalent_stress(&sy);
        let expect = (r90 * (1.0 + r0) / (r0 * (1.0 + r90))).sqrt();
        assert!((ratio - expect).abs() < 1e-12);
    }

    /// Turning the rolling direction by α turns the directional yield stresses with it:
    /// the sheet rotated by α, loaded at β + α, behaves as the original loaded at β.
    #[test]
    fn rolling_angle_rotates_the_axes() {
        let hill = Hill48::from_lankford(0.7, 1.3, 2.1).unwrap();
        let alpha = 0.4;
        let turned = hill.with_rolling_angle(alpha).unwrap();
        let uniaxial = |angle: f64| {
            let (s, c) = angle.sin_cos();
            Voigt::new(c * c, s * s, 0.0, c * s, 0.0, 0.0) * 100.0
        };
        for beta in [0.0, 0.3, std::f64::consts::FRAC_PI_4, 1.2] {
            let a = hill.equivalent_stress(&uniaxial(beta));
            let b = turned.equivalent_stress(&uniaxial(beta + alpha));
            assert!((a - b).abs() < 1e-12, "{beta}: {a} {b}");
        }
        assert!(hill.with_rolling_angle(f64::NAN).is_err());
    }

    #[test]
    fn invalid_parameters_are_errors_naming_the_value() {
        let msg = |r: Result<Hill48>| r.unwrap_err().to_string();
        assert!(msg(Hill48::from_lankford(0.0, 1.0, 1.0)).contains("Lankford r0 = 0 must be > 0"));
        assert!(
            msg(Hill48::from_lankford(1.0, -1.0, 1.0)).contains("Lankford r45 = -1 must be > 0")
        );
        assert!(msg(Hill48::from_lankford(1.0, 1.0, f64::NAN))
            .contains("Lankford r90 = NaN must be finite"));
        assert!(msg(Hill48::new(0.5, 0.5, 0.5, 0.0, 1.5, 1.5)).contains("Hill48 L = 0 must be > 0"));
        assert!(
            msg(Hill48::new(0.5, 0.5, 0.5, 1.5, 1.5, -1.0)).contains("Hill48 N = -1 must be > 0")
        );
        assert!(msg(Hill48::new(-0.5, 0.5, 0.5, 1.5, 1.5, 1.5))
            .contains("Hill48 F + G = 0 must be > 0"));
        let m = msg(Hill48::new(-0.4, 0.5, 0.5, 1.5, 1.5, 1.5));
        assert!(
            m.contains("Hill48 F*G + G*H + H*F = -0.15") && m.contains("must be > 0"),
            "{m}"
        );
        assert!(msg(Hill48::new(f64::INFINITY, 0.5, 0.5, 1.5, 1.5, 1.5))
            .contains("Hill48 F = inf must be finite"));
        // A negative F with a positive-definite φ is accepted.
        assert!(Hill48::new(-0.1, 0.5, 0.5, 1.5, 1.5, 1.5).is_ok());
    }
}
