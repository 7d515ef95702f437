//! Micro-benchmark of `--set` on 10 keys: the parameter table's typed setters against the
//! serde round trip it used before (each key: serialize the whole `ScaledParams` to a
//! `serde_json::Value` to read the field's type, serialize it again, replace the field,
//! deserialize the whole back and check it), reproduced here as a closure so that both
//! are measured side by side in one run.
//!
//! Run with `cargo bench --features bench --bench params`. See BENCHMARKS.md for the figures.

use criterion::{Criterion, criterion_group, criterion_main};
use serde_json::Value;
use std::hint::black_box;
use unforeseen_agent::param_table;
use unforeseen_agent::params::ScaledParams;

// The benches' shared setup; this bench takes only criterion's configuration from it.
#[allow(dead_code)]
mod common;
use common::criterion_config;

/// Ten settings of different types: numbers, counts, `inf`, an enum, a switch, a factor
/// name and a dotted key.
const SETS: [(&str, &str); 10] = [
    ("omega", "0.3"),
    ("epsilon", "0.1"),
    ("horizon", "2"),
    ("gate_memory", "inf"),
    ("scaling_mode", "closed-form"),
    ("learning", "false"),
    ("vmp_max_iters", "16"),
    ("gate_factor", "v"),
    ("tie_tolerance", "0.02"),
    ("gate.handback", "theta"),
];

/// Today's path: `set_str` per key.
fn typed(p: &mut ScaledParams) {
    for (k, v) in SETS {
        p.set_str(k, v).expect("valid setting");
    }
}

/// The round trip of before, per key: `get` serialized the whole to read the field's
/// current type, the text became the JSON value that type calls for, the range was looked
/// up on a fresh default (`bound_of`), then `set_value` serialized the whole again,
/// replaced the field, deserialized the whole and checked it.
fn serde_round_trip(p: &mut ScaledParams) {
    for (key, text) in SETS {
        let k = param_table::lookup(key).expect("known key");
        let current = serde_json::to_value(&*p).expect("serializable")[&k.group][&k.name].clone();
        let value = match current {
            Value::Bool(_) => Value::Bool(matches!(text, "true" | "yes" | "1")),
            Value::Number(n) if n.is_u64() => Value::from(text.parse::<u64>().expect("whole number")),
            Value::Number(_) => match text.parse::<f64>().expect("number") {
                x if x.is_finite() => Value::from(x),
                _ => Value::String(text.to_string()),
            },
            _ => Value::String(text.to_string()),
        };
        black_box(ScaledParams::default());
        let mut tree = serde_json::to_value(&*p).expect("serializable");
        tree[&k.group][&k.name] = value;
        let next: ScaledParams = serde_json::from_value(tree).expect("valid setting");
        next.check_ref().expect("in range");
        *p = next;
    }
}

/// `set_10_keys/typed` and `set_10_keys/serde_round_trip`: the ten settings applied to
/// the defaults (a clone of them, included in both).
fn set_10_keys(c: &mut Criterion) {
    let base = ScaledParams::default();
    let (mut a, mut b) = (base.clone(), base.clone());
    typed(&mut a);
    serde_round_trip(&mut b);
    assert_eq!(a, b, "both paths set the same parameters");
    let mut g = c.benchmark_group("set_10_keys");
    g.bench_function("typed", |bench| {
        bench.iter(|| {
            let mut p = base.clone();
            typed(&mut p);
            black_box(p)
        })
    });
    g.bench_function("serde_round_trip", |bench| {
        bench.iter(|| {
            let mut p = base.clone();
            serde_round_trip(&mut p);
            black_box(p)
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = criterion_config();
    targets = set_10_keys
}
criterion_main!(benches);
