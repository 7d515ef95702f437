//! Why a model in pymdp's layout was refused: each error names the array, the place and
//! what must hold.

use thiserror::Error;

/// A refused model, observation or action.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ModelError {
    /// A nested array whose rows differ in length.
    #[error("{array} is ragged: {place} has {found} entries, but {}", expected.map_or("it must be a number".to_string(), |e| format!("its siblings have {e}")))]
    Ragged {
        /// The array, e.g. `A[1]`.
        array: String,
        /// The offending row, e.g. `A[1][2]`.
        place: String,
        /// Its length.
        found: usize,
        /// The length of the first row at that depth (`None`: a number was expected).
        expected: Option<usize>,
    },
    /// A leaf that is not a number.
    #[error("{place} is {found}, must be a number")]
    NotANumber {
        /// The array.
        array: String,
        /// The entry.
        place: String,
        /// What was found.
        found: String,
    },
    /// A NaN or infinite entry.
    #[error("{array} entry {index:?} is {value}, must be finite")]
    NotFinite {
        /// The array.
        array: String,
        /// The entry's index.
        index: Vec<usize>,
        /// The value.
        value: f64,
    },
    /// A negative probability or concentration.
    #[error("{array} entry {index:?} is {value}, must be >= 0")]
    Negative {
        /// The array.
        array: String,
        /// The entry's index.
        index: Vec<usize>,
        /// The value.
        value: f64,
    },
    /// A distribution that does not sum to one, e.g. `B[1] column (s=3, u=0) sums to 0.7, must be 1`.
    #[error("{array} {column} sums to {sum}, must be 1 (within {tol:e})")]
    Unnormalised {
        /// The array.
        array: String,
        /// The column, e.g. `column (s=3, u=0)`.
        column: String,
        /// Its sum.
        sum: f64,
        /// The tolerance.
        tol: f64,
    },
    /// An axis of the wrong length or an array of the wrong rank.
    #[error("{array} {axis} has length {found}, must be {expected}: {why}")]
    Shape {
        /// The array.
        array: String,
        /// The axis, e.g. `axis 2` or `rank`.
        axis: String,
        /// What was found.
        found: usize,
        /// What must hold.
        expected: usize,
        /// The reason, e.g. `the number of states of factor 1`.
        why: String,
    },
    /// A dependency on a factor the model does not have.
    #[error("{array} lists factor {factor}, but the model has {n_factors} factors (0..{n_factors})")]
    MissingFactor {
        /// `A_dependencies[m]` or `B_dependencies[f]`.
        array: String,
        /// The factor named.
        factor: usize,
        /// How many factors B has.
        n_factors: usize,
    },
    /// More than the bound of what can be built.
    #[error("{what} is {size}, more than the bound {bound}: {why}")]
    TooLarge {
        /// What was counted, e.g. `the joint state space`.
        what: String,
        /// Its size.
        size: f64,
        /// The bound.
        bound: f64,
        /// Why the bound exists.
        why: &'static str,
    },
    /// Anything else that must hold (the message says what).
    #[error("{array}: {problem}")]
    Invalid {
        /// The array or argument.
        array: String,
        /// What is wrong and what must hold.
        problem: String,
    },
}

impl ModelError {
    pub(crate) fn invalid(array: impl Into<String>, problem: impl Into<String>) -> ModelError {
        ModelError::Invalid {
            array: array.into(),
            problem: problem.into(),
        }
    }
}
