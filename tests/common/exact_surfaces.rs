//! The analytic surfaces of the CAD fixtures in closed form, for tests that check an
//! imported face point by point: each gives the signed distance of a point to the exact
//! surface and the surface's documented unit normal there (out of cylinders, cones,
//! spheres and tubes; along the frame's z for planes). Surfaces sit in a `Frame`: origin
//! `o` and orthonormal axes, z the axis of revolution or the plane's normal.

use tribo::cad::Face;
use tribo::geometry::Vec3;

pub struct Frame {
    pub o: Vec3,
    pub x: Vec3,
    pub y: Vec3,
    pub z: Vec3,
}

impl Frame {
    /// The right-handed frame of origin `o`, axis `z` and first axis `x` (both unit and
    /// orthogonal).
    pub fn new(o: Vec3, x: Vec3, z: Vec3) -> Frame {
        Frame {
            o,
            x,
            y: z.cross(&x),
            z,
        }
    }

    /// Axial coordinate `h`, radius `rho` and unit radial direction of `p`.
    pub fn cylindrical(&self, p: Vec3) -> (f64, f64, Vec3) {
        let d = p - self.o;
        let h = d.dot(&self.z);
        let radial = d - self.z * h;
        (h, radial.norm(), radial.normalize())
    }
}

/// Distance of `p` to the exact surface and the surface's documented normal there.
pub type Exact = Box<dyn Fn(Vec3) -> (f64, Vec3)>;

/// The plane through the frame's origin, normal z.
pub fn plane(f: Frame) -> Exact {
    Box::new(move |p| ((p - f.o).dot(&f.z), f.z))
}

/// The cylinder of radius `r` about the frame's z axis.
pub fn cylinder(f: Frame, r: f64) -> Exact {
    Box::new(move |p| {
        let (_, rho, e) = f.cylindrical(p);
        (rho - r, e)
    })
}

/// The cone of radius `r0` at h = 0 opening by the half angle `a` (radians) along z.
pub fn cone(f: Frame, r0: f64, a: f64) -> Exact {
    Box::new(move |p| {
        let (h, rho, e) = f.cylindrical(p);
        (
            (rho - r0 - h * a.tan()) * a.cos(),
            e * a.cos() - f.z * a.sin(),
        )
    })
}

/// The sphere of radius `r` about the frame's origin.
pub fn sphere(f: Frame, r: f64) -> Exact {
    Box::new(move |p| ((p - f.o).norm() - r, (p - f.o).normalize()))
}

/// A tube of radius `r` about the circle of radius `big` in the frame's xy plane (a torus,
/// or a spindle torus when `big < r`): normal out of the tube.
pub fn tube(f: Frame, big: f64, r: f64) -> Exact {
    Box::new(move |p| {
        let (h, rho, e) = f.cylindrical(p);
        let to = e * (rho - big) + f.z * h;
        (to.norm() - r, to.normalize())
    })
}

/// `S_u x S_v` by central differences (step 1e-6 of the domain: error ~1e-12 relative),
/// reversed if the face is.
pub fn face_normal(face: &Face, u: f64, v: f64) -> Vec3 {
    let [du, dv] = face.surface.domain();
    let (hu, hv) = (1e-6 * (du[1] - du[0]), 1e-6 * (dv[1] - dv[0]));
    let su = face.surface.point(u + hu, v) - face.surface.point(u - hu, v);
    let sv = face.surface.point(u, v + hv) - face.surface.point(u, v - hv);
    let n = su.cross(&sv).normalize();
    if face.flip {
        -n
    } else {
        n
    }
}

/// Checks a face's parameter box `got` against `want` to `tol`: u is an angle on every
/// surface of revolution, taken modulo a turn, and so is v where `v_is_angle`.
pub fn assert_parameter_box(
    kind: &str,
    got: [[f64; 2]; 2],
    want: [[f64; 2]; 2],
    v_is_angle: bool,
    tol: f64,
) {
    let tau = std::f64::consts::TAU;
    for d in 0..2 {
        for k in 0..2 {
            let mut off = got[d][k] - want[d][k];
            if d == 0 || v_is_angle {
                off -= tau * (off / tau).round();
            }
            assert!(off.abs() < tol, "{kind}: {got:?} against {want:?}");
        }
    }
}
