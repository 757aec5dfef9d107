//! Friction laws: how a contact node's friction coefficient follows from its history.
//!
//! The coefficient is evaluated explicitly from the committed history after each converged
//! increment (as in the paper) and held fixed during the next increment's Newton iterations.

use super::state::ContactNodeState;
use crate::{Error, Result};

/// A friction law; each tool carries its own.
#[derive(Clone, Debug)]
pub enum FrictionLaw {
    /// Classical Coulomb friction with a constant coefficient.
    Coulomb { mu: f64 },
}

impl FrictionLaw {
    /// Constant Coulomb friction, `mu >= 0` and finite.
    pub fn coulomb(mu: f64) -> Result<Self> {
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(Error::input(
                "friction coefficient mu",
                mu,
                "must be >= 0 and finite",
            ));
        }
        Ok(FrictionLaw::Coulomb { mu })
    }

    /// Frictionless contact.
    pub fn frictionless() -> Self {
        FrictionLaw::Coulomb { mu: 0.0 }
    }

    /// Friction coefficient for a node with the given committed history.
    pub fn mu(&self, _state: &ContactNodeState) -> f64 {
        match self {
            FrictionLaw::Coulomb { mu } => *mu,
        }
    }

    pub fn describe(&self) -> String {
        match self {
            FrictionLaw::Coulomb { mu } => format!("Coulomb mu = {mu}"),
        }
    }
}
