//! `--set KEY=VALUE` overrides of the scaled agent's parameters, used by the commands
//! and by sweeps ([`crate::batch::sweep`]). A bad key or value is an [`Error::Flag`]
//! naming the flag and, for a value out of range, the range and its reason.

use unforeseen_agent::params::{ActionSelection, GateBaseline, GateLearning, GateMode, RootStep, ScaledParams};

use crate::error::Error;

/// The keys `--set` accepts.
pub const KEYS: &[&str] = &[
    "omega",
    "epsilon",
    "gamma",
    "varsigma",
    "horizon",
    "kappa_pi",
    "vmp_window",
    "max_scaling_iters",
    "nu0",
    "nu_temperature",
    "learning_rate",
    "sample",
    "gate",
    "gate_factor",
    "gate_memory",
    "gate_learning",
    "gate_baseline",
    "persistence_ignores",
    "root_step",
];

/// Applies `KEY=VALUE` overrides in order, then checks the result (ranges and bounds
/// of [`ScaledParams::check`]).
pub fn apply(mut p: ScaledParams, sets: &[String]) -> Result<ScaledParams, Error> {
    for set in sets {
        let (key, value) = set.split_once('=').ok_or_else(|| {
            Error::flag(
                format!("--set {set}"),
                format!("expected KEY=VALUE, e.g. --set omega=0.425 (keys: {})", KEYS.join(", ")),
            )
        })?;
        set_one(&mut p, key.trim(), value.trim())?;
    }
    p.check()
        .map_err(|e| Error::flag(format!("--set {}", e.name), e.to_string()))?;
    Ok(p)
}

/// Sets one parameter by name.
pub fn set_one(p: &mut ScaledParams, key: &str, value: &str) -> Result<(), Error> {
    let flag = format!("--set {key}={value}");
    let float = || {
        value
            .parse::<f64>()
            .map_err(|_| Error::flag(&flag, format!("'{value}' is not a number")))
    };
    let int = || {
        value
            .parse::<usize>()
            .map_err(|_| Error::flag(&flag, format!("'{value}' is not a whole number")))
    };
    match key {
        "omega" => p.omega = float()?,
        "epsilon" => p.epsilon = float()?,
        "gamma" => p.gamma = float()?,
        "varsigma" => p.varsigma = float()?,
        "horizon" => p.horizon = int()?,
        "kappa_pi" => p.kappa_pi = float()?,
        "vmp_window" => p.vmp_window = int()?,
        "max_scaling_iters" => {
            p.max_scaling_iters =
                u32::try_from(int()?).map_err(|_| Error::flag(&flag, format!("at most {}", u32::MAX)))?
        }
        "nu0" => p.nu0 = float()?,
        "nu_temperature" => p.nu_temperature = float()?,
        "learning_rate" => p.learning_rate = float()?,
        "sample" => {
            p.action_selection = match value {
                "true" | "1" | "yes" => ActionSelection::Sample,
                "false" | "0" | "no" => ActionSelection::Mode,
                _ => return Err(Error::flag(&flag, "expected true or false")),
            }
        }
        "gate" => {
            p.gate = match value {
                "state" => GateMode::State,
                "one-step" => GateMode::OneStep,
                _ => return Err(Error::flag(&flag, "expected state or one-step")),
            }
        }
        "gate_factor" => p.gate_factor = value.to_string(),
        "gate_memory" => p.gate_memory = float()?,
        "gate_learning" => {
            p.gate_learning = match value {
                "endorsed" => GateLearning::Endorsed,
                "every" => GateLearning::Every,
                _ => return Err(Error::flag(&flag, "expected endorsed or every")),
            }
        }
        "gate_baseline" => {
            p.gate_baseline = match value {
                "endorsed" => GateBaseline::Endorsed,
                "none" => GateBaseline::None,
                _ => return Err(Error::flag(&flag, "expected endorsed or none")),
            }
        }
        "root_step" => {
            p.root_step = match value {
                "learned" => RootStep::Learned,
                "absorbing" => RootStep::Absorbing,
                _ => return Err(Error::flag(&flag, "expected learned or absorbing")),
            }
        }
        "persistence_ignores" => {
            p.persistence_ignores = if value == "none" {
                String::new()
            } else {
                value.to_string()
            }
        }
        _ => {
            return Err(Error::flag(
                format!("--set {key}"),
                format!("unknown parameter; known: {}", KEYS.join(", ")),
            ));
        }
    }
    Ok(())
}
