//! What runs many episodes: scenario suites and sweeps ([`batch`]), deployment streams
//! ([`stream`]), the paper's comparison over agents and protocols ([`compare`]), the
//! merge of shard files ([`merge`]) and the search for fair failing scenarios
//! ([`search`]).

pub mod batch;
pub mod compare;
pub mod merge;
pub mod search;
pub mod stream;
