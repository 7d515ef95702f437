//! Which failures are input the user can fix (a map, an agent file, a parameter, a
//! results file, ...) rather than failures of the machine or of a component, over a
//! whole chain of causes: the command line exits with 2 for these, the Python package
//! raises `ValueError`.

use crate::error::{Error, StreamError};
use crate::maps::MapLookupError;

/// Whether `err` or anything in its chain of causes is input the user can fix: an
/// [`Error`] for which [`Error::is_user_input`] holds, a map that cannot be found or
/// loaded ([`MapLookupError`], [`unforeseen_sim::MapError`]) or a bad
/// deployment stream ([`StreamError`]). The command line exits with 2 for these and the
/// Python package raises `ValueError`; anything else is a failure of the machine or of a
/// component.
pub fn in_chain(err: &(dyn std::error::Error + 'static)) -> bool {
    let mut cause = Some(err);
    while let Some(e) = cause {
        let bad_input = e.downcast_ref::<Error>().is_some_and(Error::is_user_input)
            || e.is::<MapLookupError>()
            || e.is::<StreamError>()
            || e.is::<unforeseen_sim::MapError>();
        if bad_input {
            return true;
        }
        cause = e.source();
    }
    false
}
