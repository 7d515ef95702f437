//! Limits on what one run may ask for, the same through every front (the command line,
//! the Python package): checked here, named by field.

use crate::error::Error;

/// Evaluation episodes per method and map unless a job is given a number (`eval`,
/// `compare`, `batch`).
pub const DEFAULT_EPISODES: u64 = 100;

/// Most episodes one run may ask for: a million takes about an hour per method and map
/// here, and each episode keeps a result in memory; run more as shards or seeds.
pub const MAX_EPISODES: u64 = 1_000_000;

/// Most worker threads one run may ask for (`--jobs`, Python's `jobs`, a driver's
/// threads): more only spends time starting threads on any machine this runs on.
pub const MAX_JOBS: usize = 256;

/// `n` if it is an episode count one run may ask for (1..=[`MAX_EPISODES`]), else an
/// [`Error::OutOfRange`] naming `field` (`episodes`, `train_episodes`, ...).
pub fn check_episodes(field: &str, n: u64) -> Result<u64, Error> {
    if (1..=MAX_EPISODES).contains(&n) {
        Ok(n)
    } else {
        Err(Error::OutOfRange {
            field: field.to_string(),
            value: n.to_string(),
            expected: format!("1..={MAX_EPISODES}"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn episode_counts_out_of_range_name_the_field() {
        assert_eq!(check_episodes("episodes", 5).unwrap(), 5);
        assert_eq!(check_episodes("episodes", MAX_EPISODES).unwrap(), MAX_EPISODES);
        let e = check_episodes("train_episodes", 0).unwrap_err();
        assert_eq!(e.to_string(), "train_episodes 0: expected 1..=1000000");
        assert!(e.is_user_input());
        assert!(check_episodes("episodes", MAX_EPISODES + 1).is_err());
    }
}
