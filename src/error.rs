//! The one error type of the library. Every message names the input at fault and its value.

/// Errors returned by tribo. Library code never panics on user input: it returns one of these.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A user-supplied value is out of its valid range (names the parameter and the value).
    #[error("invalid input: {0}")]
    Input(String),
    /// A Rhai script failed: message carries file:line:column.
    #[error("script error: {0}")]
    Script(String),
    /// The linear solver failed (singular or non-finite matrix).
    #[error("linear solver: {0}")]
    LinearSolver(String),
    /// Newton did not converge; every converged frame written so far is kept.
    #[error("no convergence: {0}")]
    NoConvergence(String),
    /// The run was asked to stop (a signal): the last converged state is kept.
    #[error("interrupted: {0}")]
    Interrupted(String),
    /// A file could not be read or written.
    #[error("I/O error on {path}: {message}")]
    Io { path: String, message: String },
}

impl Error {
    /// `Error::input("Young's modulus", -1.0, "must be > 0")` -> "Young's modulus = -1 must be > 0".
    pub fn input(what: &str, value: impl std::fmt::Display, requirement: &str) -> Self {
        Error::Input(format!("{what} = {value} {requirement}"))
    }

    pub fn io(path: impl AsRef<std::path::Path>, err: impl std::fmt::Display) -> Self {
        Error::Io {
            path: path.as_ref().display().to_string(),
            message: err.to_string(),
        }
    }
}

pub type Result<T> = std::result::Result<T, Error>;
