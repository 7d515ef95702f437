//! One evaluation episode with every tick recorded (Figs. 6-7): what `trace`, the replay
//! page and the golden digests read.

use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_sim::Map;

use crate::episodes::evaluation::eval_seeds;
use crate::episodes::methods::{Method, check_compatible};
use crate::episodes::protocol::Protocol;
use crate::episodes::runner::{EpisodeResult, Tick, run_episode};
use crate::error::Error;

/// Runs evaluation episode `episode` of `method` (seeded as in [`run_agent_episodes`](crate::episodes::evaluation::run_agent_episodes)) with
/// its ticks recorded, and returns its result and ticks. Under the continual protocol the
/// controller first runs evaluation episodes `0..episode` in order and learns from them,
/// so the traced episode is exactly the one a continual evaluation meets at that index.
pub fn trace(
    bundle: &AgentBundle,
    params: &ScaledParams,
    method: Method,
    map: &Map,
    seed: u64,
    protocol: Protocol,
    episode: u64,
) -> Result<(EpisodeResult, Vec<Tick>), Error> {
    let mut env = Env::new(map, EnvConfig::default())?;
    check_compatible(bundle, map)?;
    let mut controller = method.controller(bundle, params, map)?;
    if protocol.effective(method, params) == Protocol::Continual {
        for ep in 0..episode {
            run_episode(&mut env, controller.as_mut(), eval_seeds(seed, map, method, ep), false)?;
        }
    }
    Ok(run_episode(
        &mut env,
        controller.as_mut(),
        eval_seeds(seed, map, method, episode),
        true,
    )?)
}
