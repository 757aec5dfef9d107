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
    /// Newton did not converge; every converged frame written so far is kept. `kind` says
    /// why and `cycling` whether some node's contact status cycled, so that callers
    /// (studies, summary.json, the step control) never read the message.
    #[error("no convergence: {message}")]
    NoConvergence {
        kind: Failure,
        cycling: bool,
        message: String,
    },
    /// The run was asked to stop (a signal): the last converged state is kept.
    #[error("interrupted: {0}")]
    Interrupted(String),
    /// A file could not be read or written.
    #[error("I/O error on {path}: {message}")]
    Io { path: String, message: String },
}

/// Why an iteration did not converge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Failure {
    /// Newton's iteration budget ran out without growth of the residual.
    Stalled,
    /// Newton's merit grew over consecutive iterations, or its force residual a millionfold.
    Diverged,
    /// In a model with force-controlled tools, the force residual grew past its limit after
    /// two Newton steps (`newton`, `FORCE_GROWTH_LIMIT`).
    ForceGrowth,
    /// A residual became non-finite.
    NonFinite,
    /// No line-search trial along the Newton step could be evaluated.
    LineSearch,
    /// A local solve failed: a material's return map, an element's enhanced strains, an
    /// inverted element, a force-controlled tool that cannot be seated.
    Local,
    /// The linear solver failed (singular or non-finite system).
    LinearSolver,
    /// An error that no smaller increment cures (bad input, a script function, I/O),
    /// reported as the run's stop.
    Unrecoverable,
}

impl Failure {
    /// The name summary.json and studies use.
    pub fn name(self) -> &'static str {
        match self {
            Failure::Stalled => "stalled",
            Failure::Diverged => "diverged",
            Failure::ForceGrowth => "force_growth",
            Failure::NonFinite => "non_finite",
            Failure::LineSearch => "line_search",
            Failure::Local => "local",
            Failure::LinearSolver => "linear_solver",
            Failure::Unrecoverable => "unrecoverable",
        }
    }
}

impl Error {
    /// A failure to converge of the given kind, without status cycling.
    pub fn no_convergence(kind: Failure, message: impl Into<String>) -> Self {
        Error::NoConvergence {
            kind,
            cycling: false,
            message: message.into(),
        }
    }

    /// The kind of failure to converge this error is (a linear solver's failure is
    /// [`Failure::LinearSolver`]; any other error [`Failure::Unrecoverable`]), and whether
    /// some contact status cycled.
    pub fn failure(&self) -> (Failure, bool) {
        match self {
            Error::NoConvergence { kind, cycling, .. } => (*kind, *cycling),
            Error::LinearSolver(_) => (Failure::LinearSolver, false),
            _ => (Failure::Unrecoverable, false),
        }
    }

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
