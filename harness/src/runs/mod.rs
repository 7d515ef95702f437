//! What runs many episodes: one method's evaluation on a map or a stream ([`evaluate`]),
//! scenario suites and sweeps ([`batch`]), deployment streams
//! ([`stream`]), the paper's comparison over agents and protocols ([`compare`]),
//! test-time learning curves ([`learn`]), one episode step by step ([`trace`]), the
//! merge of shard files ([`merge`]), the reading back of a run's file for `--resume`
//! ([`resume`]), the search for fair failing scenarios
//! ([`search`]), the failure probabilities of a space with their intervals ([`estimate`])
//! and the methods given from outside the library, a Python policy, reported
//! as batch result lines ([`outside_methods`]); the guard all of them pass before any work ([`outputs`]: no output
//! replaces an input or another program's file, one writer at a time). Jobs are asked
//! for by typed requests ([`EvalRequest`](evaluate::EvalRequest),
//! [`CompareRequest`](compare::CompareRequest), [`BatchRequest`](batch::BatchRequest),
//! [`SearchRequest`](search::SearchRequest), [`EstimateRequest`](estimate::EstimateRequest),
//! [`LearnRequest`](learn::LearnRequest),
//! [`TraceRequest`](trace::TraceRequest)), read field by field from other fronts by
//! [`request`].

pub mod batch;
pub mod compare;
pub mod estimate;
pub mod evaluate;
pub mod file_kinds;
pub mod learn;
pub mod merge;
pub mod outputs;
pub mod outside_methods;
pub mod request;
pub mod resume;
pub mod search;
pub mod stream;
pub mod trace;
