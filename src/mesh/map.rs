//! A mesh carried through a map of its reference coordinates: curved shells (cylinders,
//! spheres, roofs) made from a block.

use super::Mesh;
use crate::geometry::Vec3;
use crate::{Error, Result};

impl Mesh {
    /// The mesh with every node moved to `f(node)`, keeping the connectivity, the node
    /// sets and the through-thickness columns. `f` may fail (a script error); the result
    /// is checked by [`Mesh::validate`], whose errors name the element and corner an
    /// orientation-reversing or collapsing map inverted. Cost: one call of `f` per node.
    pub fn map(&self, mut f: impl FnMut(Vec3) -> Result<Vec3>) -> Result<Mesh> {
        let mut mapped = self.clone();
        for (i, p) in mapped.nodes.iter_mut().enumerate() {
            let q = f(*p)?;
            if !q.iter().all(|c| c.is_finite()) {
                return Err(Error::input(
                    &format!(
                        "mapped coordinates of node {i} (from ({}, {}, {}))",
                        p.x, p.y, p.z
                    ),
                    format!("({}, {}, {})", q.x, q.y, q.z),
                    "must be finite",
                ));
            }
            *p = q;
        }
        mapped.validate().map_err(|e| match e {
            Error::Input(m) => Error::Input(format!("mesh.map: {m}")),
            other => other,
        })?;
        Ok(mapped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block bent into a quarter cylinder: node sets and columns carried over, the
    /// column lengths are the (unchanged) thickness, the nodes lie on the radii.
    #[test]
    fn map_keeps_sets_and_columns() {
        let m = Mesh::block(Vec3::zeros(), Vec3::new(1.0, 2.0, 0.1), [4, 2, 1]).unwrap();
        let r0 = 10.0;
        let bent = m
            .map(|p| {
                let (a, r) = (p.x * std::f64::consts::FRAC_PI_2, r0 + p.z);
                Ok(Vec3::new(r * a.sin(), p.y, r * a.cos()))
            })
            .unwrap();
        assert_eq!(bent.node_set("x-").unwrap(), m.node_set("x-").unwrap());
        assert_eq!(bent.columns(), m.columns());
        for t in bent.column_thicknesses(|_| Vec3::zeros()) {
            assert!((t - 0.1).abs() < 1e-12);
        }
        for &n in bent.node_set("z-").unwrap() {
            let p = bent.nodes[n];
            assert!(((p.x * p.x + p.z * p.z).sqrt() - r0).abs() < 1e-12);
        }
        // A mirror inverts every element: refused, naming the element.
        let err = m
            .map(|p| Ok(Vec3::new(-p.x, p.y, p.z)))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("mesh.map") && err.contains("element 0"),
            "{err}"
        );
        let err = m
            .map(|p| Ok(Vec3::new(p.x / (p.x - 0.5), p.y, p.z)))
            .unwrap_err()
            .to_string();
        assert!(err.contains("must be finite"), "{err}");
    }
}
