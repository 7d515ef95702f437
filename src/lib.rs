//! # unforeseen (the command line)
//!
//! The `unforeseen` program: [`cli`] parses the arguments (clap), draws progress bars
//! (indicatif), cleans up on Ctrl-C (ctrlc), prints, and decides messages and exit
//! codes. Everything it runs is the harness library, [`unforeseen_harness`], which the
//! Python package (`python/`) calls too; this crate adds only the front.
//!
//! `docs/ARCHITECTURE.md` in the repository describes the layout, the data flow and the
//! equations, with the paper's sections.

pub mod cli;
