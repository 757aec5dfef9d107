//! Validation of user-supplied geometric parameters, shared by the surfaces and the tool
//! layer. Every failure names the parameter and its value (see [`crate::Error::input`]).

use super::Vec3;
use crate::{Error, Result};

/// `(x, y, z)` with the shortest exact float text, for error messages and `describe()`.
pub(crate) fn fmt_vec3(v: &Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

/// `v` itself if all its components are finite.
pub(crate) fn finite_vec3(what: &str, v: &Vec3) -> Result<Vec3> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(*v)
    } else {
        Err(Error::input(what, fmt_vec3(v), "must be finite"))
    }
}

/// The unit vector along `v`; `v` must be finite and non-zero.
pub(crate) fn unit_vec3(what: &str, v: &Vec3) -> Result<Vec3> {
    finite_vec3(what, v)?;
    let largest = v.amax();
    if largest == 0.0 {
        return Err(Error::input(what, fmt_vec3(v), "must be non-zero"));
    }
    // Scaling by the largest component first keeps |v|^2 from underflowing for tiny v.
    Ok((v / largest).normalize())
}

/// `r` itself if it is finite and strictly positive.
pub(crate) fn positive_length(what: &str, r: f64) -> Result<f64> {
    if !r.is_finite() {
        Err(Error::input(what, r, "must be finite"))
    } else if r <= 0.0 {
        Err(Error::input(what, r, "must be > 0"))
    } else {
        Ok(r)
    }
}
