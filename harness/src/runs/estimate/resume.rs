//! `--resume`: the draws of an earlier run of the same request (its identity line
//! checked, [`crate::runs::resume`]), each line checked as this program writes it, each
//! draw against the one the run derives at its index when the run takes it
//! ([`Kept::check`]).

use std::collections::BTreeMap;
use std::path::Path;

use super::{Draw, EstimateIdentity, EstimateRequest};
use crate::error::Error;
use crate::runs::resume::{START_OVER, read_lines};
use crate::runs::search::{Candidate, SearchConfig};

/// A draw read back, with its line.
#[derive(Debug, Clone)]
pub(super) struct Kept {
    /// Its line in the file (1-based).
    line: usize,
    /// The draw.
    pub(super) draw: Draw,
}

/// The draws `path` holds for `--resume` of the estimate `r` (whose identity is
/// `identity`), by index. A draw in the file twice, line for line the same, is one draw
/// (shard files concatenated each hold the draws of the stages before theirs).
///
/// Refuses (naming the file and the line) what [`read_lines`] refuses, a line that is not
/// as this program writes it (an unknown or edited field, another spelling), a draw past
/// the budget, a draw whose figures do not fit the request (episodes per draw, failures
/// among them, a rejected draw's empty figures), and a draw in the file twice with other
/// contents.
pub(super) fn kept_draws(
    cfg: &SearchConfig<'_>,
    r: &EstimateRequest,
    identity: &EstimateIdentity,
    path: &Path,
) -> Result<BTreeMap<usize, Kept>, Error> {
    let bad = |line: usize, draw: usize, problem: String| Error::Results {
        path: path.to_path_buf(),
        problem: format!("--resume: line {line} (draw {draw}) {problem}; {START_OVER}"),
    };
    let mut kept: BTreeMap<usize, Kept> = BTreeMap::new();
    for l in read_lines::<EstimateIdentity, Draw>(path, "estimate", identity, "a draw line")? {
        let d = &l.parsed;
        if serde_json::to_string(d)? != l.raw.trim_end() {
            return Err(bad(
                l.line,
                d.draw,
                "is not a line this program writes (an unknown or edited field)".into(),
            ));
        }
        if d.draw >= r.budget {
            return Err(bad(l.line, d.draw, format!("is past the budget of {} draws", r.budget)));
        }
        if let Some(problem) = figures_problem(cfg, d) {
            return Err(bad(l.line, d.draw, problem));
        }
        if let Some(first) = kept.get(&d.draw) {
            if first.draw != *d {
                return Err(bad(
                    l.line,
                    d.draw,
                    format!(
                        "is in the file twice, line {} otherwise; remove one of them",
                        first.line
                    ),
                ));
            }
            continue;
        }
        kept.insert(
            d.draw,
            Kept {
                line: l.line,
                draw: l.parsed,
            },
        );
    }
    Ok(kept)
}

/// What is wrong with the figures of `d` as a draw of `cfg`: a rejected draw's are
/// empty; a valid one has the witnesses' verdict and `episodes` episodes per training
/// seed, at most all of them failed.
fn figures_problem(cfg: &SearchConfig<'_>, d: &Draw) -> Option<String> {
    let episodes = cfg.episodes * cfg.train_seeds.len() as u64;
    let margins = [
        d.min_clearance_m,
        d.min_ttc_s,
        d.min_stop_margin_m,
        d.min_vehicle_clearance_m,
        d.min_pet_s,
    ];
    let empty = d.fairness.is_none() && d.episodes == 0 && margins.iter().all(Option::is_none);
    if d.rejected.is_some() {
        return (!empty || d.failed != 0).then(|| "is rejected (no valid map) yet has figures".into());
    }
    if d.fairness.is_none() || d.episodes != episodes || d.failed > d.episodes {
        return Some(format!(
            "has {} episodes, {} failed, fairness {:?}: a draw of this estimate has {episodes} episodes, at most all \
             failed, and the witnesses' verdict",
            d.episodes, d.failed, d.fairness
        ));
    }
    None
}

impl Kept {
    /// The draw, when it is the one the run derives at its index: `candidate` of `stage`
    /// at the proposal's `density` (its stage, point, values, density and whether its map
    /// is valid); else an error naming the line of `path` it came from.
    pub(super) fn check(
        &self,
        cfg: &SearchConfig<'_>,
        stage: super::DrawStage,
        candidate: &Candidate,
        density: f64,
        path: &Path,
    ) -> Result<Draw, Error> {
        let expected = Draw::of(cfg, stage, candidate, density, None);
        let d = &self.draw;
        let differs = [
            ("stage", d.stage != expected.stage),
            ("point", d.point != expected.point),
            ("values", d.values != expected.values),
            ("density", d.density != expected.density),
            ("validity", d.rejected != expected.rejected),
        ];
        if let Some((what, _)) = differs.iter().find(|(_, differs)| *differs) {
            return Err(Error::Results {
                path: path.to_path_buf(),
                problem: format!(
                    "--resume: line {} (draw {}) is not the draw this estimate derives at that index: its {what} \
                     differs; {START_OVER}",
                    self.line, d.draw
                ),
            });
        }
        Ok(d.clone())
    }
}
