//! What a batch run does, computed before any agent is needed: its configuration
//! ([`BatchConfig`]) and its plan ([`Plan`]: the units, the shard, the identity and the
//! lines `--resume` keeps).

use std::collections::BTreeSet;
use std::ops::Range;
use std::path::Path;

use crate::episodes::methods::Method;
use crate::episodes::protocol::Protocol;
use crate::error::Error;
use crate::training::seed_agents::Agent;

use super::identity::RunIdentity;
use super::results_file::{KeptLine, resume_lines};
use super::scenario::Scenario;
use super::sweep::ParamSet;
use super::units::{Shard, Unit, units};

/// Everything a batch run needs.
pub struct BatchConfig<'a> {
    /// Trained agents; a unit runs the agent whose training seed it names.
    pub agents: &'a [Agent],
    /// The training-seed axis of the units, in order (`[agent's seed]` for one agent).
    /// With a shard, `agents` needs only the seeds of that shard's units.
    pub train_seeds: &'a [Option<u64>],
    /// Scenarios in order.
    pub scenarios: &'a [Scenario],
    /// Methods in order.
    pub methods: &'a [Method],
    /// Parameter sets in order.
    pub params: &'a [ParamSet],
    /// Protocols in order.
    pub protocols: &'a [Protocol],
    /// Episodes per unit.
    pub episodes: u64,
    /// Evaluation seed.
    pub seed: u64,
    /// Worker threads.
    pub jobs: usize,
    /// Optional shard.
    pub shard: Option<Shard>,
    /// What determines the agents, for the run's identity: an agent file's content hash
    /// ([`agent_file_identity`](super::agent_file_identity)) or the training recipe ([`trained_agents_identity`](super::trained_agents_identity)).
    /// Two runs with the same text here run the same agents.
    pub agents_identity: String,
}

impl BatchConfig<'_> {
    /// The identity of this run (the first line of its results file).
    pub fn identity(&self) -> RunIdentity {
        RunIdentity::new(
            self.scenarios,
            self.methods,
            self.params,
            self.protocols,
            self.train_seeds,
            self.episodes,
            self.seed,
            &self.agents_identity,
        )
    }

    /// All units of the run, in canonical order.
    pub fn units(&self) -> Result<Vec<Unit>, Error> {
        units(
            self.scenarios.len(),
            self.methods,
            self.params,
            self.protocols,
            self.train_seeds,
        )
    }

    /// Plans the run into results file `out` (reading the lines `resume` keeps, see
    /// [`resume_lines`]). Uses everything but [`BatchConfig::agents`], so it can say
    /// which agents are needed before they are trained ([`Plan::train_seeds_to_run`]).
    pub fn plan(&self, out: &Path, resume: bool) -> Result<Plan, Error> {
        let units = self.units()?;
        let shard = self.shard.map_or(0..units.len(), |s| s.range(units.len()));
        let identity = self.identity();
        let kept = if resume {
            resume_lines(out, &identity, &units, self.scenarios)?
        } else {
            Vec::new()
        };
        Ok(Plan {
            identity,
            units,
            shard,
            kept,
        })
    }
}

/// A batch run planned before anything runs ([`BatchConfig::plan`]).
#[derive(Debug, Clone)]
pub struct Plan {
    /// The run's identity (the first line of its results file).
    pub identity: RunIdentity,
    /// Every unit of the run, in canonical order.
    pub units: Vec<Unit>,
    /// The positions of the units this run's shard takes (all of them without a shard).
    pub shard: Range<usize>,
    /// The lines of the results file that `--resume` keeps, in file order.
    pub kept: Vec<KeptLine>,
}

impl Plan {
    /// The units still to run: the shard's, less those whose lines are kept.
    pub fn todo(&self) -> Vec<&Unit> {
        let done: BTreeSet<usize> = self.kept.iter().map(|l| l.parsed.unit).collect();
        self.units[self.shard.clone()]
            .iter()
            .filter(|u| !done.contains(&u.index))
            .collect()
    }

    /// The training seeds of the units still to run that run an agent (not a scripted
    /// method's), in the order of the run's training seeds: the agents the run needs. A
    /// run of scripted methods only needs none.
    pub fn train_seeds_to_run(&self) -> Vec<u64> {
        let todo = self.todo();
        self.identity
            .train_seeds
            .iter()
            .flatten()
            .copied()
            .filter(|&s| todo.iter().any(|u| u.train_seed == Some(s) && !u.method.is_scripted()))
            .collect()
    }
}
