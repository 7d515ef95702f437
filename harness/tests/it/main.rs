//! The harness's end-to-end tests, one module per subject, in one test binary: episodes,
//! methods, protocols and figures run through the library, with no command line. Modules
//! share one small trained agent (`unforeseen_harness::fixtures::bundle`).

mod crosswalk;
mod end_to_end;
mod figures;
mod fuzz;
mod golden;
mod junction_pictures;
mod protocols;
mod safety;
