//! The two evaluation protocols (docs/ARCHITECTURE.md §5). Every output names the one it ran under.
//!
//! * **zero-shot** (the paper's Fig. 8 table, the default of `compare`): every method
//!   starts every test episode from its trained state; nothing carries over between
//!   test episodes, so the episodes are independent and run in parallel.
//! * **continual** (the paper's Fig. 9 setting): what a method learns carries over from
//!   one test episode to the next; episodes run in order on one controller.
//!
//! A method that does not learn across episodes ([`Method::learns_across_episodes`]) gives
//! identical results under both; it is run once and reported as covering both.

use serde::{Deserialize, Serialize};
use unforeseen_agent::params::ScaledParams;

use crate::episodes::methods::Method;

/// How test episodes relate to each other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Protocol {
    /// Every test episode starts from the trained state (fresh controller per episode).
    ZeroShot,
    /// Learning carries over from one test episode to the next, in order.
    Continual,
}

impl Protocol {
    /// Both protocols, in the order tables print them.
    pub const ALL: [Protocol; 2] = [Protocol::ZeroShot, Protocol::Continual];

    /// The name used on the command line and in result files.
    pub fn name(self) -> &'static str {
        match self {
            Protocol::ZeroShot => "zero-shot",
            Protocol::Continual => "continual",
        }
    }

    /// One line saying what the protocol is (for listings such as `--help`).
    pub fn summary(self) -> &'static str {
        match self {
            Protocol::ZeroShot => "Every test episode starts from the trained state (fresh controller per episode)",
            Protocol::Continual => "Learning carries over from one test episode to the next, in order",
        }
    }

    /// One line saying what the protocol means, for printed tables.
    pub fn meaning(self) -> &'static str {
        match self {
            Protocol::ZeroShot => "every method starts every test episode from its trained state (paper Fig. 8)",
            Protocol::Continual => {
                "what a method learns carries over from one test episode to the next, in order (paper Fig. 9)"
            }
        }
    }

    /// The name map files give the protocol in an expectation (`protocol: Continual`).
    pub fn map_name(self) -> &'static str {
        match self {
            Protocol::ZeroShot => "ZeroShot",
            Protocol::Continual => "Continual",
        }
    }

    /// The protocol a map file names ([`Protocol::map_name`]), if any.
    pub fn from_map_name(name: &str) -> Option<Protocol> {
        Protocol::ALL.into_iter().find(|p| p.map_name() == name)
    }

    /// The protocol `method` really needs: a method that does not learn across episodes
    /// runs zero-shot (fresh controllers, in parallel) whatever was asked, since both
    /// protocols give it identical results.
    pub fn effective(self, method: Method, params: &ScaledParams) -> Self {
        if method.learns_across_episodes(params) {
            self
        } else {
            Protocol::ZeroShot
        }
    }
}

impl std::fmt::Display for Protocol {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::fmt::Display for ProtocolChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A protocol name that is neither of [`Protocol::ALL`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{given}' is not a protocol; expected one of {}", Protocol::ALL.map(Protocol::name).join(", "))]
pub struct UnknownProtocol {
    /// The name given.
    pub given: String,
}

impl std::str::FromStr for Protocol {
    type Err = UnknownProtocol;
    /// Parses a protocol by [`Protocol::name`].
    fn from_str(s: &str) -> Result<Self, UnknownProtocol> {
        Protocol::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| UnknownProtocol { given: s.to_string() })
    }
}

/// The protocols a run asks for (`batch`, `compare`): one of them, or both.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProtocolChoice {
    /// Only zero-shot.
    ZeroShot,
    /// Only continual.
    Continual,
    /// Zero-shot, then continual.
    #[default]
    Both,
}

impl ProtocolChoice {
    /// Every choice, in the order listings give them.
    pub const ALL: [ProtocolChoice; 3] = [
        ProtocolChoice::ZeroShot,
        ProtocolChoice::Continual,
        ProtocolChoice::Both,
    ];

    /// The name of the choice in requests and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ProtocolChoice::ZeroShot => "zero-shot",
            ProtocolChoice::Continual => "continual",
            ProtocolChoice::Both => "both",
        }
    }

    /// One line saying what the choice runs (for listings such as `--help`).
    pub fn summary(self) -> &'static str {
        match self {
            ProtocolChoice::ZeroShot => "Only zero-shot",
            ProtocolChoice::Continual => "Only continual",
            ProtocolChoice::Both => "Zero-shot, then continual",
        }
    }

    /// The chosen protocols, zero-shot first.
    pub fn protocols(self) -> Vec<Protocol> {
        match self {
            ProtocolChoice::ZeroShot => vec![Protocol::ZeroShot],
            ProtocolChoice::Continual => vec![Protocol::Continual],
            ProtocolChoice::Both => Protocol::ALL.to_vec(),
        }
    }
}

impl std::str::FromStr for ProtocolChoice {
    type Err = String;
    /// Parses a choice by [`ProtocolChoice::name`].
    fn from_str(s: &str) -> Result<Self, String> {
        ProtocolChoice::ALL.into_iter().find(|p| p.name() == s).ok_or_else(|| {
            format!(
                "'{s}' is not a protocol choice; expected one of {}",
                ProtocolChoice::ALL.map(ProtocolChoice::name).join(", ")
            )
        })
    }
}

/// The protocols among `asked` under which one run of `method` is reported: all of them
/// when the method does not learn across episodes (its results are identical under
/// each), otherwise just `protocol`.
pub fn covered(method: Method, params: &ScaledParams, protocol: Protocol, asked: &[Protocol]) -> Vec<Protocol> {
    if method.learns_across_episodes(params) {
        vec![protocol]
    } else {
        asked.to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_learners_run_zero_shot_and_cover_every_protocol_asked() {
        let p = ScaledParams::default();
        assert_eq!(Protocol::Continual.effective(Method::QLearning, &p), Protocol::ZeroShot);
        assert_eq!(Protocol::Continual.effective(Method::BayesRl, &p), Protocol::Continual);
        assert_eq!(
            covered(Method::ScaledNoLearning, &p, Protocol::ZeroShot, &Protocol::ALL),
            Protocol::ALL
        );
        assert_eq!(
            covered(Method::Scaled, &p, Protocol::Continual, &Protocol::ALL),
            [Protocol::Continual]
        );
        assert_eq!("continual".parse::<Protocol>(), Ok(Protocol::Continual));
        assert!(
            "both"
                .parse::<Protocol>()
                .unwrap_err()
                .to_string()
                .contains("zero-shot, continual")
        );
        assert_eq!(serde_json::to_string(&Protocol::ZeroShot).unwrap(), "\"zero-shot\"");
    }
}
