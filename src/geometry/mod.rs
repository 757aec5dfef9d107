//! Rigid tool surfaces and the closest-point query that the contact layer asks of them.
//!
//! Every surface answers one question (parry style): where is the closest point of the
//! surface to a point `x`, what is the outward normal there, how far is `x` from it
//! (signed, positive outside the tool), and how does the normal change when `x` moves.
//! The contact operator treats all surfaces alike through [`RigidSurface`].

use nalgebra::{Matrix3, Vector3};

pub mod analytic_nurbs;
pub mod bezier;
pub mod builders;
pub mod bvh;
mod check;
pub mod cylinder;
pub mod kdop;
pub mod nurbs;
pub mod patch_surface;
pub mod patch_table;
pub mod plane;
pub mod revolution;
pub mod sphere;
#[cfg(test)]
pub(crate) mod testutil;
pub mod trim;

pub(crate) use check::{finite_vec3, fmt_vec3, positive_length, unit_vec3};

pub use bezier::{BezierPatch, PatchPoint};
pub use cylinder::Cylinder;
pub use patch_surface::seams::SeamReport;
pub use patch_surface::PatchSurface;
pub use plane::Plane;
pub use sphere::Sphere;

pub type Vec3 = Vector3<f64>;
pub type Mat3 = Matrix3<f64>;

/// Where on a multi-piece surface a foot point lies (patch index and parameters); used to
/// warm-start the next projection. Analytic surfaces ignore it.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SurfaceHint {
    pub patch: usize,
    pub u: f64,
    pub v: f64,
}

/// Result of the closest-point projection of a point `x` on a surface.
#[derive(Clone, Copy, Debug)]
pub struct Projection {
    /// Foot point P_proj on the surface.
    pub foot: Vec3,
    /// Unit outward normal of the tool at the foot point.
    pub normal: Vec3,
    /// Signed normal distance d_n = n . (x - P_proj): > 0 outside the tool, < 0 penetrating.
    pub gap: f64,
    /// Gradient of the normal with respect to the projected point: G_ij = d n_i / d x_j,
    /// at fixed tool pose. Zero for a plane; for a sphere of radius R, (I - n n^T)/(R + d_n).
    pub normal_gradient: Mat3,
    /// Location on the surface (for warm starts).
    pub hint: SurfaceHint,
}

/// A rigid surface in its own reference frame (the tool's pose is applied by the caller).
pub trait RigidSurface: std::fmt::Debug {
    /// Closest-point projection of `x`. `hint` is the previous foot point of the same node,
    /// if any. Returns `None` where the projection is undefined (a point on a cylinder's
    /// axis, a sphere's centre): the caller treats such a node as far from contact.
    fn project(&self, x: &Vec3, hint: Option<&SurfaceHint>) -> Option<Projection>;

    /// A short human-readable description ("cylinder r=5 ...") for logs and errors.
    fn describe(&self) -> String;

    /// The patch surface behind this surface, if it is one (for its seam report).
    fn as_patch_surface(&self) -> Option<&PatchSurface> {
        None
    }

    /// What the surface is if it is analytic (for its display surface).
    fn analytic_shape(&self) -> Option<AnalyticShape> {
        None
    }
}

/// An analytic surface's defining data (normals and axes unit), for display.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnalyticShape {
    /// Outward `normal`.
    Plane {
        point: Vec3,
        normal: Vec3,
    },
    Cylinder {
        axis_point: Vec3,
        axis: Vec3,
        radius: f64,
    },
    Sphere {
        centre: Vec3,
        radius: f64,
    },
}
