//! Helpers of the command line's integration tests: running the built binary and
//! checking its exit and output. The trained agents and maps they share with the
//! harness's tests are `unforeseen_harness::fixtures`.

/// The built binary with `args`, run to completion.
pub fn run_cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(args)
        .output()
        .expect("run the binary")
}

/// A run's stdout then stderr, as text.
pub fn output_text(out: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// The run exited with `code`, did not panic, and its output contains every needle.
pub fn assert_exit(out: &std::process::Output, code: i32, needles: &[&str]) {
    let all = output_text(out);
    assert_eq!(out.status.code(), Some(code), "exit code {code} expected:\n{all}");
    assert!(!all.contains("panicked"), "panic:\n{all}");
    for n in needles {
        assert!(all.contains(n), "message should contain {n:?}:\n{all}");
    }
}
