//! Helpers shared by the integration tests (included with `mod common;`).

#![allow(dead_code)]

use unforeseen_sim::{Action, Snapshot, StepOutcome, World};

/// Run one episode with a policy that sees the snapshot at each decision tick.
/// Returns the snapshots (the initial one first) and the final outcome.
pub fn run(world: &mut World, mut policy: impl FnMut(&Snapshot) -> Action) -> (Vec<Snapshot>, StepOutcome) {
    let mut snaps = vec![world.snapshot()];
    loop {
        let a = policy(snaps.last().expect("non-empty"));
        let out = world.step(a);
        snaps.push(world.snapshot());
        if out.done() {
            return (snaps, out);
        }
    }
}

/// The paper's careful driver: slow down whenever a pedestrian is on the
/// crosswalk at a decision tick, otherwise speed up.
pub fn brake_for_pedestrians(s: &Snapshot) -> Action {
    if s.pedestrian_on_crosswalk() {
        Action::SlowDown
    } else {
        Action::SpeedUp
    }
}
