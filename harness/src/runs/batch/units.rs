//! Units of work and shards: every (scenario, method, parameter set, protocol, training
//! seed) in the canonical order, and the contiguous slice of it one shard runs.

use crate::episodes::methods::Method;
use crate::episodes::protocol::{Protocol, covered};
use crate::error::Error;

use super::result_line::UnitKey;
use super::scenario::Scenario;
use super::sweep::ParamSet;

/// The methods a batch runs unless told otherwise: the paper's three and the scripted
/// references (so every map reports whether it is survivable and dangerous).
pub const DEFAULT_METHODS: [Method; 5] = [
    Method::QLearning,
    Method::BayesRl,
    Method::Scaled,
    Method::BrakeOnPedestrian,
    Method::NeverBrake,
];

/// One unit of work.
#[derive(Debug, Clone)]
pub struct Unit {
    /// Position in the canonical order.
    pub index: usize,
    /// Index into the scenarios.
    pub scenario: usize,
    /// Method.
    pub method: Method,
    /// Parameter set.
    pub params: ParamSet,
    /// The protocol the unit runs under.
    pub protocol: Protocol,
    /// Every protocol asked that the unit's results hold for (more than `protocol` only
    /// for a method that does not learn across episodes).
    pub covers: Vec<Protocol>,
    /// Training seed of the agent it runs.
    pub train_seed: Option<u64>,
}

impl Unit {
    /// The unit's identity, as its result line's [`ResultLine::key`](super::ResultLine::key) gives it.
    pub fn key(&self, scenarios: &[Scenario]) -> UnitKey {
        (
            scenarios[self.scenario].name().to_string(),
            self.method.name().to_string(),
            self.params.label(),
            self.protocol,
            self.train_seed,
        )
    }
}

/// All units in canonical order: scenarios, then methods, then parameter sets, then
/// protocols (one unit for a method that does not learn across episodes), then
/// training seeds (innermost, so one configuration's seeds are contiguous).
pub fn units(
    n_scenarios: usize,
    methods: &[Method],
    params: &[ParamSet],
    protocols: &[Protocol],
    train_seeds: &[Option<u64>],
) -> Result<Vec<Unit>, Error> {
    let mut out = Vec::new();
    // Parameter sets change only the scaled agent: every other method runs once, with the
    // defaults, instead of repeating identical rows for every point of a sweep.
    let defaults = [ParamSet(Vec::new())];
    for scenario in 0..n_scenarios {
        for &method in methods {
            let params = if method.is_scaled() { params } else { &defaults[..] };
            for p in params {
                let scaled = p.scaled_params()?;
                let mut seen: Vec<Protocol> = Vec::new();
                for &protocol in protocols {
                    let covers = covered(method, &scaled, protocol, protocols);
                    if seen.iter().any(|s| covers.contains(s)) {
                        continue; // already covered by an earlier unit
                    }
                    seen.extend(&covers);
                    for &train_seed in train_seeds {
                        out.push(Unit {
                            index: out.len(),
                            scenario,
                            method,
                            params: p.clone(),
                            protocol,
                            covers: covers.clone(),
                            train_seed,
                        });
                    }
                }
            }
        }
    }
    Ok(out)
}

/// A shard `i/n` (1-based): the contiguous slice `[(i-1)U/n, iU/n)` of `U` units
/// ([`Shard::range`]), or every `n`-th item from the `i`-th ([`Shard::deals`]). In a
/// request (serde) it is the text `i/n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct Shard {
    /// 1-based shard number.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("'{s}': expected I/N with 1 <= I <= N, e.g. 2/8");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        // Digits only, as episode counts: `" 1/2"` and `+1/2` are refused.
        let whole = |t: &str| -> Result<usize, String> {
            if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
                return Err(bad());
            }
            t.parse().map_err(|_| bad())
        };
        let (index, count) = (whole(i)?, whole(n)?);
        if count == 0 || index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl TryFrom<String> for Shard {
    type Error = String;
    fn try_from(s: String) -> Result<Self, String> {
        s.parse()
    }
}

impl From<Shard> for String {
    fn from(s: Shard) -> String {
        format!("{}/{}", s.index, s.count)
    }
}

impl Shard {
    /// The range of unit positions this shard runs.
    pub fn range(self, total: usize) -> std::ops::Range<usize> {
        ((self.index - 1) * total / self.count)..(self.index * total / self.count)
    }

    /// Whether item `index` (0-based) is this shard's when the items are dealt in turn:
    /// `index ≡ i − 1 (mod n)`.
    pub fn deals(self, index: usize) -> bool {
        index % self.count == self.index - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_digits_only() {
        assert_eq!("2/8".parse::<Shard>(), Ok(Shard { index: 2, count: 8 }));
        for bad in [" 1/2", "1/ 2", "+1/2", "1/2 ", "0/2", "3/2", "1/0", "1", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad:?}");
        }
    }
}
