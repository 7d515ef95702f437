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

/// Largest model file `inspect --model` reads (bytes): a single-factor model of at most
/// 1024 states and 64 actions is far smaller.
pub const MAX_MODEL_BYTES: u64 = 64 << 20;

/// The text of the model file `path` (`inspect --model`): a regular file (a pipe or a
/// device such as `/dev/zero` would be read forever) of at most [`MAX_MODEL_BYTES`],
/// UTF-8 text; else an [`Error::ModelFile`] naming the problem.
pub fn read_model_file(path: &std::path::Path) -> Result<String, Error> {
    use std::io::Read;
    let bad = |problem: String| Error::ModelFile {
        path: path.to_path_buf(),
        problem,
    };
    let meta = std::fs::metadata(path).map_err(|e| bad(format!("cannot read ({e})")))?;
    if !meta.is_file() {
        return Err(bad(
            "not a regular file (a folder, a pipe, a device); give a model JSON file".into(),
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| bad(format!("cannot read ({e})")))?;
    let mut bytes = Vec::new();
    file.take(MAX_MODEL_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| bad(format!("cannot read ({e})")))?;
    if bytes.len() as u64 > MAX_MODEL_BYTES {
        return Err(bad(format!(
            "larger than {MAX_MODEL_BYTES} bytes; a single-factor model is far smaller"
        )));
    }
    String::from_utf8(bytes).map_err(|_| bad("not text (invalid UTF-8); give a model JSON file".into()))
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
