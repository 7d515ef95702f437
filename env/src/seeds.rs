//! Per-episode seeds derived from the run seed and the episode's identity, never from
//! thread or completion order, so results do not depend on `--jobs`: what every
//! episode's [`Env::reset`](crate::Env::reset) seed derives from, in the harness's jobs and
//! in the Gymnasium env alike, and the content hash of files and settings.

/// The run seed every job uses unless given one (`--seed`, Python's `seed`).
pub const DEFAULT_SEED: u64 = 7;

/// 64-bit FNV-1a over the parts, each followed by a separator byte.
fn fnv1a(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &b in part.iter().chain(std::iter::once(&0xff)) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// SplitMix64 finalizer: spreads nearby inputs over the whole 64-bit range.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Seed of episode `episode` of the stream named `stream` (e.g. a scenario name and a
/// phase such as `"train"`), under run seed `seed`.
pub fn episode_seed(seed: u64, stream: &str, episode: u64) -> u64 {
    mix(fnv1a(&[&seed.to_le_bytes(), stream.as_bytes(), &episode.to_le_bytes()]))
}

/// A 64-bit content hash of `bytes` as 16 hex digits (FNV-1a then SplitMix64): stable
/// across runs, builds and platforms, for telling files and settings apart (not for
/// security).
pub fn content_hash(bytes: &[u8]) -> String {
    format!("{:016x}", mix(fnv1a(&[bytes])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_depend_on_every_part_and_are_stable() {
        let a = episode_seed(7, "jaywalk", 0);
        assert_eq!(a, episode_seed(7, "jaywalk", 0));
        assert_ne!(a, episode_seed(8, "jaywalk", 0));
        assert_ne!(a, episode_seed(7, "jaywalk2", 0));
        assert_ne!(a, episode_seed(7, "jaywalk", 1));
        // Separators keep ("ab", "c") apart from ("a", "bc").
        assert_ne!(fnv1a(&[b"ab", b"c"]), fnv1a(&[b"a", b"bc"]));
    }
}
