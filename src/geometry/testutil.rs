//! Test helpers shared by the surface and tool tests: a deterministic random generator and
//! the checks every projection must pass.

use super::{Mat3, Projection, Vec3};

/// xorshift64* generator: deterministic, good enough to scatter test points.
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }

    fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in `[lo, hi)`.
    pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * unit
    }

    /// Uniform in the cube `[-half, half]^3`.
    pub(crate) fn vec3(&mut self, half: f64) -> Vec3 {
        Vec3::new(
            self.uniform(-half, half),
            self.uniform(-half, half),
            self.uniform(-half, half),
        )
    }

    /// Random unit vector (rejection sampling in the unit ball).
    pub(crate) fn unit_vec3(&mut self) -> Vec3 {
        loop {
            let v = self.vec3(1.0);
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
}

/// Invariants of any projection of `x`: unit normal, and `x - foot = gap * n`
/// (so `x - foot` is parallel to `n` and the gap is its signed length).
pub(crate) fn assert_projection_consistent(p: &Projection, x: &Vec3) {
    let scale = 1.0 + x.norm();
    assert!(
        (p.normal.norm() - 1.0).abs() < 1e-12,
        "normal not unit: {p:?}"
    );
    let residual = (x - p.foot) - p.normal * p.gap;
    assert!(
        residual.norm() < 1e-12 * scale,
        "x - foot not along n: {p:?}, x = {x:?}"
    );
}

/// Central finite differences of the projected normal, step `h` on each coordinate.
pub(crate) fn fd_normal_gradient(project: &dyn Fn(&Vec3) -> Option<Projection>, x: &Vec3) -> Mat3 {
    let h = 1e-6;
    let mut g = Mat3::zeros();
    for j in 0..3 {
        let (mut xp, mut xm) = (*x, *x);
        xp[j] += h;
        xm[j] -= h;
        // The step actually taken, after rounding of x +- h.
        let step = xp[j] - xm[j];
        let np = project(&xp).expect("projection defined at x + h").normal;
        let nm = project(&xm).expect("projection defined at x - h").normal;
        g.set_column(j, &((np - nm) / step));
    }
    g
}

/// `normal_gradient` at `x` equals the finite-difference gradient to relative error 1e-6.
pub(crate) fn assert_gradient_matches_fd(project: &dyn Fn(&Vec3) -> Option<Projection>, x: &Vec3) {
    let g = project(x).expect("projection defined").normal_gradient;
    let fd = fd_normal_gradient(project, x);
    let err = (fd - g).norm();
    assert!(
        err <= 1e-6 * g.norm(),
        "normal gradient at {x:?}: analytic {g:?}, finite differences {fd:?}, error {err:e}"
    );
}
