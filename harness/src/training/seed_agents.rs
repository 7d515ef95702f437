//! Agents for training-seed studies (`--train-seeds`): one independently trained agent
//! per seed, trained in parallel (rayon) and cached on disk under a file name that hashes
//! everything that determines the agent (training map contents, episodes, seed, training
//! configuration, crate version and a fingerprint of the training code), so a rerun
//! loads instead of retraining and a changed input never reuses a stale agent.

use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_sim::Map;

use crate::episodes::methods::check_compatible;
use crate::error::Error;
use crate::progress::{Message, Progress};
use crate::training::{TrainConfig, train_with_progress};

/// Most training seeds one run accepts (each agent takes seconds to train).
pub const MAX_TRAIN_SEEDS: usize = 1000;

/// Default folder of the agent cache.
pub const DEFAULT_CACHE: &str = "out/agents";

/// A list of training seeds: parsed from `1..10` (inclusive), `1,3,5` or `1..3,7`, or
/// given as a list; non-empty, at most [`MAX_TRAIN_SEEDS`], each seed once. In a request
/// (serde) it is that text or a list of numbers, and is written as the list.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "SeedsGiven", into = "Vec<u64>")]
pub struct TrainSeeds(pub Vec<u64>);

/// Training seeds as a request gives them: text to parse, or the list.
#[derive(serde::Deserialize)]
#[serde(untagged)]
enum SeedsGiven {
    Text(String),
    List(Vec<u64>),
}

impl TryFrom<SeedsGiven> for TrainSeeds {
    type Error = String;
    fn try_from(given: SeedsGiven) -> Result<Self, String> {
        match given {
            SeedsGiven::Text(s) => s.parse(),
            SeedsGiven::List(seeds) => TrainSeeds::new(seeds),
        }
    }
}

impl From<TrainSeeds> for Vec<u64> {
    fn from(seeds: TrainSeeds) -> Vec<u64> {
        seeds.0
    }
}

impl TrainSeeds {
    /// The seeds `seeds` if they are a list one run accepts: at least one, at most
    /// [`MAX_TRAIN_SEEDS`], each once.
    pub fn new(seeds: Vec<u64>) -> Result<Self, String> {
        if seeds.is_empty() {
            return Err("no seed; give at least one training seed".into());
        }
        if seeds.len() > MAX_TRAIN_SEEDS {
            return Err(format!("{} seeds; at most {MAX_TRAIN_SEEDS}", seeds.len()));
        }
        let mut sorted = seeds.clone();
        sorted.sort_unstable();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("seed {} is listed twice", w[0]));
        }
        Ok(TrainSeeds(seeds))
    }
}

impl std::str::FromStr for TrainSeeds {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let hint = "expected seeds like 1..10 (inclusive), 1,3,5 or 1..3,7";
        let number = |t: &str| {
            t.trim()
                .parse::<u64>()
                .map_err(|_| format!("'{}' is not a seed (a whole number >= 0); {hint}", t.trim()))
        };
        let mut seeds = Vec::new();
        for part in s.split(',') {
            if part.trim().is_empty() {
                return Err(format!("'{s}': empty entry; {hint}"));
            }
            match part.split_once("..") {
                Some((a, b)) => {
                    let (a, b) = (number(a)?, number(b.strip_prefix('=').unwrap_or(b))?);
                    if a > b {
                        return Err(format!("'{}': the range runs backwards; {hint}", part.trim()));
                    }
                    if b - a >= MAX_TRAIN_SEEDS as u64 {
                        return Err(format!("'{}': more than {MAX_TRAIN_SEEDS} seeds", part.trim()));
                    }
                    seeds.extend(a..=b);
                }
                None => seeds.push(number(part)?),
            }
            if seeds.len() > MAX_TRAIN_SEEDS {
                return Err(format!("'{s}': more than {MAX_TRAIN_SEEDS} seeds"));
            }
        }
        TrainSeeds::new(seeds).map_err(|e| format!("'{s}': {e}"))
    }
}

/// A trained agent and where it came from.
#[derive(Debug, Clone)]
pub struct Agent {
    /// Its training seed (None for an agent file whose metadata does not say).
    pub train_seed: Option<u64>,
    /// Its training episodes (None when unknown).
    pub train_episodes: Option<u64>,
    /// The trained learners.
    pub bundle: AgentBundle,
}

impl Agent {
    /// Wraps a bundle, reading its seed and episodes from the metadata training wrote.
    pub fn from_bundle(bundle: AgentBundle) -> Self {
        let meta = |k: &str| bundle.meta.get(k).and_then(|v| v.parse().ok());
        Self {
            train_seed: meta("seed"),
            train_episodes: meta("episodes"),
            bundle,
        }
    }
}

/// The cache key of the agent `cfg` trains on `map`: a hash of the map's contents, the
/// training configuration (episodes, seed, Q-learning, priors, Bayesian RL, tau_c), the
/// crate version and the fingerprint of the training code (build.rs).
pub fn cache_key(map: &Map, cfg: &TrainConfig) -> Result<String, Error> {
    let parts = serde_json::json!({
        "map": map,
        "episodes": cfg.episodes,
        "seed": cfg.seed,
        "q": cfg.q,
        "priors": cfg.priors,
        "bayes": cfg.bayes,
        "tau_c": cfg.tau_c,
        "timeout_as": cfg.timeout_as,
        "version": env!("CARGO_PKG_VERSION"),
        "code": env!("UNFORESEEN_TRAINING_FINGERPRINT"),
    });
    let text = serde_json::to_string(&parts)?;
    Ok(format!("{:016x}", unforeseen_env::seeds::episode_seed(0, &text, 0)))
}

/// Where the cache keeps that agent: `DIR/<map>-seed<S>-<episodes>ep-<key>.ron`.
pub fn cache_path(dir: &Path, map: &Map, cfg: &TrainConfig) -> Result<PathBuf, Error> {
    let safe: String = map
        .name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let key = cache_key(map, cfg)?;
    Ok(dir.join(format!("{safe}-seed{}-{}ep-{key}.ron", cfg.seed, cfg.episodes)))
}

/// Loads a cached agent if present and valid: it parses, was stored under the same key,
/// and fits the map's state space. Anything else is a miss (reported as a warning to
/// `progress`, then retrained).
fn load_cached(path: &Path, map: &Map, key: &str, progress: &dyn Progress) -> Option<AgentBundle> {
    if !path.exists() {
        return None;
    }
    let checked = crate::training::agent_file::load(path)
        .map_err(|e| e.full_message())
        .and_then(|bundle| {
            if bundle.meta.get("cache_key").map(String::as_str) != Some(key) {
                return Err("its cache key differs from its file name".to_string());
            }
            check_compatible(&bundle, map).map_err(|e| e.full_message())?;
            Ok(bundle)
        });
    match checked {
        Ok(bundle) => Some(bundle),
        Err(e) => {
            progress.message(
                Message::Warning,
                &format!("agent cache: ignoring {} ({e}); retraining", path.display()),
            );
            None
        }
    }
}

/// Trains one agent per seed on `map` with `base`'s configuration (its seed replaced),
/// in parallel on the current rayon pool, or loads it from `cache` when a valid copy is
/// there (and stores fresh ones there, atomically). Agents come back in seed order, and
/// each depends only on its own seed, so results do not depend on the thread count.
/// One phase of `progress` (`training N agents`, one step per training episode, a loaded
/// agent counting all of its episodes), with one [`Message::Item`] per agent.
pub fn train_agents(
    map: &Map,
    seeds: &[u64],
    base: &TrainConfig,
    cache: Option<&Path>,
    progress: &dyn Progress,
) -> Result<Vec<Agent>, Error> {
    progress.phase(
        &format!("training {} agents", seeds.len()),
        base.episodes * seeds.len() as u64,
    );
    let agents = seeds
        .par_iter()
        .map(|&seed| {
            let cfg = TrainConfig { seed, ..base.clone() };
            let key = cache_key(map, &cfg)?;
            let path = cache.map(|dir| cache_path(dir, map, &cfg)).transpose()?;
            if let Some(bundle) = path.as_deref().and_then(|p| load_cached(p, map, &key, progress)) {
                progress.advance(cfg.episodes);
                let from = path.as_deref().map(Path::display);
                progress.message(
                    Message::Item,
                    &format!("agent seed {seed}: loaded {}", from.expect("cached")),
                );
                return Ok(Agent::from_bundle(bundle));
            }
            let started = Instant::now();
            let (mut bundle, _) = train_with_progress(map, &cfg, progress)?;
            bundle.meta.insert("cache_key".into(), key);
            let saved = match &path {
                Some(p) => {
                    crate::training::agent_file::save(p, &bundle)?;
                    format!(" -> {}", p.display())
                }
                None => String::new(),
            };
            progress.message(
                Message::Item,
                &format!(
                    "agent seed {seed}: trained {} episodes on '{}' in {:.1} s{saved}",
                    cfg.episodes,
                    map.name,
                    started.elapsed().as_secs_f64()
                ),
            );
            Ok(Agent::from_bundle(bundle))
        })
        .collect::<Result<Vec<_>, Error>>()?;
    progress.finish();
    Ok(agents)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<Vec<u64>, String> {
        s.parse::<TrainSeeds>().map(|t| t.0)
    }

    #[test]
    fn seeds_parse_as_ranges_lists_and_mixes() {
        assert_eq!(parse("1..10").unwrap(), (1..=10).collect::<Vec<_>>());
        assert_eq!(parse("1,3,5").unwrap(), [1, 3, 5]);
        assert_eq!(parse("1..3,7").unwrap(), [1, 2, 3, 7]);
        assert_eq!(parse(" 4 ").unwrap(), [4]);
        assert_eq!(parse("0..=2").unwrap(), [0, 1, 2]);
        assert_eq!(parse("5..5").unwrap(), [5]);
    }

    #[test]
    fn bad_seeds_say_what_is_wrong() {
        for (bad, needle) in [
            ("", "empty"),
            ("1,,2", "empty"),
            ("a", "'a' is not a seed"),
            ("-1", "not a seed"),
            ("3..1", "backwards"),
            ("1..", "'' is not a seed"),
            ("1,2,1", "listed twice"),
            ("1..3,2", "listed twice"),
            ("0..5000", "more than 1000"),
        ] {
            let err = parse(bad).unwrap_err();
            assert!(err.contains(needle), "{bad:?}: {err}");
        }
    }

    #[test]
    fn the_cache_key_follows_every_input() {
        let map = crate::maps::load("intersection").unwrap();
        let cfg = TrainConfig::new(100, 1);
        let key = cache_key(&map, &cfg).unwrap();
        assert_eq!(key, cache_key(&map, &cfg).unwrap());
        assert_ne!(key, cache_key(&map, &TrainConfig::new(101, 1)).unwrap());
        assert_ne!(key, cache_key(&map, &TrainConfig::new(100, 2)).unwrap());
        let mut q = cfg.clone();
        q.q.alpha = 0.2;
        assert_ne!(key, cache_key(&map, &q).unwrap());
        let mut other = map.clone();
        other.reward.goal += 1.0;
        assert_ne!(key, cache_key(&other, &cfg).unwrap());
        let path = cache_path(Path::new("c"), &map, &cfg).unwrap();
        assert_eq!(path, Path::new("c").join(format!("intersection-seed1-100ep-{key}.ron")));
    }
}
