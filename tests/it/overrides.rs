//! `--set` overrides and the scaled agent's parameter table: every key is
//! settable and reads back, bad keys and values name what is allowed, the typed entry
//! point agrees with the text one, and a sweep counts equal values once (that a
//! parameter set by name reaches the agent, e.g. the closed form of Theorem 1, is the
//! agent's test: agent/tests/it/closed_form.rs).

use unforeseen_agent::param_decl::ParamValue;
use unforeseen_agent::param_table;
use unforeseen_agent::params::ScaledParams;
use unforeseen_harness::fixtures;
use unforeseen_harness::overrides::{apply, keys, set_one, set_value};
use unforeseen_harness::runs::batch::sweep;

/// A value other than the default for each key, as `--set` text and typed.
fn other_value(key: &str) -> (String, ParamValue) {
    match ScaledParams::default().get(key).unwrap() {
        ParamValue::Bool(b) => ((!b).to_string(), ParamValue::Bool(!b)),
        ParamValue::Int(n) => ("2".into(), ParamValue::Int(if n == 2 { 1 } else { 2 })),
        ParamValue::Number(x) => {
            let x = x / 4.0;
            (x.to_string(), ParamValue::Number(x))
        }
        ParamValue::Name(_) if key == "gate_factor" => ("v".into(), ParamValue::Name("v".into())),
        ParamValue::Name(_) if key == "persistence_ignores" => ("L".into(), ParamValue::Name("L".into())),
        ParamValue::Name(s) => {
            let e = apply(ScaledParams::default(), &[format!("{key}=?")])
                .unwrap_err()
                .to_string();
            let allowed = e.split("one of: ").nth(1).unwrap_or_else(|| panic!("{key}: {e}"));
            let x = allowed.split(", ").find(|v| **v != *s).unwrap().to_string();
            (x.clone(), ParamValue::Name(x))
        }
    }
}

#[test]
fn every_key_round_trips_and_the_typed_entry_point_agrees() {
    assert!(keys().len() >= 25, "{:?}", keys());
    for key in keys() {
        let (text, value) = other_value(key);
        let (text, value) = if key == "horizon" || value == ParamValue::Int(1) {
            ("1".to_string(), ParamValue::Int(1))
        } else {
            (text, value)
        };
        let set = apply(ScaledParams::default(), &[format!("{key}={text}")]).unwrap();
        assert_ne!(set, ScaledParams::default(), "{key}={text} changed nothing");
        assert_eq!(set.get(key).unwrap(), value, "{key} reads back");
        let mut typed = ScaledParams::default();
        set_value(&mut typed, key, value.clone()).unwrap();
        assert_eq!(typed, set, "{key}: typed and text differ");
        let dotted = param_table::lookup(key).unwrap().dotted();
        let mut by_dotted = ScaledParams::default();
        set_one(&mut by_dotted, &dotted, &text).unwrap();
        assert_eq!(by_dotted, set, "{dotted}");
    }
}

#[test]
fn unknown_keys_and_bad_values_name_the_key_and_the_allowed_values() {
    let err = |sets: &[&str]| {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        apply(ScaledParams::default(), &sets).unwrap_err().to_string()
    };
    // The library names the setting; the command line adds its flag's spelling.
    let e = err(&["colour=red"]);
    assert!(
        e.starts_with("colour: ") && !e.contains("--set") && e.contains("omega") && e.contains("vmp_max_iters"),
        "{e}"
    );
    let out = crate::common::run_cli(&["batch", "jaywalk", "--method", "never-brake", "--set", "colour=red"]);
    crate::common::assert_exit(&out, 2, &["error: --set colour: unknown parameter `colour`"]);
    let e = err(&["epsilon=2"]);
    assert!(
        e.starts_with("epsilon=2: parameter `epsilon`") && !e.contains("--set"),
        "{e}"
    );
    let e = err(&["scaling_mode=closed"]);
    assert!(
        e.contains("scaling_mode=closed") && e.contains("iterative, closed-form"),
        "{e}"
    );
    let e = err(&["gate=both"]);
    assert!(e.contains("state, one-step"), "{e}");
    let e = err(&["vmp_kappa=0"]);
    assert!(e.contains("vmp_kappa") && e.contains("(0, 1]"), "{e}");
    let e = err(&["vmp_max_iters=lots"]);
    assert!(
        e.contains("vmp_max_iters") && e.contains("whole number") && e.contains("1..=10000"),
        "{e}"
    );
    let e = err(&["horizon=9"]);
    assert!(e.contains("horizon") && e.contains("1..=8"), "{e}");
    let mut p = ScaledParams::default();
    let e = set_value(&mut p, "vmp_tol", ParamValue::Name("small".into()))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("vmp_tol") && e.contains("small") && e.contains("finite and > 0"),
        "{e}"
    );
    let e = set_value(&mut p, "no_such", ParamValue::Int(1))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no_such") && e.contains("scaling_mode"), "{e}");
}

/// `--set gate_factor` naming no factor of the model is refused when the agent is built
/// from the model, naming the key and the model's factors.
#[test]
fn factor_names_are_checked_against_the_model() {
    let bundle = fixtures::bundle();
    let p = apply(ScaledParams::default(), &["gate_factor=x".into()]).unwrap();
    let e = unforeseen_harness::episodes::scaled_agent(bundle, p)
        .unwrap_err()
        .to_string();
    assert!(e.contains("gate_factor") && e.contains("d, v, L, p"), "{e}");
    let p = apply(ScaledParams::default(), &["persistence_ignores=v".into()]).unwrap();
    let e = unforeseen_harness::episodes::scaled_agent(bundle, p)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("persistence_ignores") && e.contains("next-time parents of `p`"),
        "{e}"
    );
}

#[test]
fn sweeps_count_equal_values_once_in_first_occurrence_order() {
    let sets = sweep(&["omega=0.5,5e-1,0.25,0.50".into(), "horizon=2,1,2".into()]).unwrap();
    let labels: Vec<String> = sets.iter().map(|s| s.label()).collect();
    assert_eq!(
        labels,
        [
            "omega=0.5,horizon=2",
            "omega=0.5,horizon=1",
            "omega=0.25,horizon=2",
            "omega=0.25,horizon=1"
        ]
    );
    let e = sweep(&["epsilon=0.1".into(), "gate.epsilon=0.2".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("set twice"), "{e}");
}
