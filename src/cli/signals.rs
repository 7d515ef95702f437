//! SIGINT and SIGTERM on the command line: the temporary files of atomic writes
//! ([`unforeseen_harness::files::write_atomic`]) delete themselves when dropped, but a signal ends the
//! process without dropping anything. [`install`] handles both (the `ctrlc` crate: the
//! handler runs on a thread of its own, not in signal context): it removes the
//! temporaries still open ([`unforeseen_harness::files::remove_temporaries`]) and exits with
//! 130 (128 + SIGINT, as a shell reports an interrupted process; for SIGTERM too).

/// Installs the handler (a failure to install it is ignored: the signals then end the
/// process as before).
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        unforeseen_harness::files::remove_temporaries();
        let _ = std::io::Write::write_all(&mut std::io::stderr(), b"interrupted\n");
        std::process::exit(130);
    });
}
