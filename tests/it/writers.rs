//! Every writer keeps the README's promise ("Bad input"), on the command line (issue 49;
//! the Python front: python/tests/test_writers.py):
//!
//! * a file that exists at an output and is not of the writer's own kind (recognised by
//!   its content) is refused with exit 2, naming the file and what it holds, and left
//!   byte for byte as it was; `--force` replaces it; a file of the writer's own kind
//!   from an earlier run is replaced (the table-driven [`no_writer_replaces_a_file_of_another_kind`]);
//! * a refusal changes nothing: `batch --resume`, `search --resume` and `merge` refuse
//!   before removing the earlier run's summary or figure;
//! * a partial results file is plotted only when asked (`plot-sweep --partial`);
//! * the agent cache and every output are checked before any training;
//! * names are bounded at load and no long cell crashes a table; `inspect --model`
//!   refuses a pipe and a device; `trace --episode +5` is refused.

use std::path::{Path, PathBuf};
use std::process::Output;

use super::common::{assert_exit, output_text, run_cli};
use unforeseen_harness::fixtures::{TINY_MAP, tiny_agent_text};

const SPACE: &str = "maps/spaces/jaywalk.ron";

/// What a file holds, for the table of foreign files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Map,
    Space,
    Agent,
    Results,
    Summary,
    Candidates,
    Estimates,
    EstimateSummary,
    Model,
    Stream,
    Html,
    Svg,
    ModelRun,
}

impl Kind {
    const ALL: [Kind; 13] = [
        Kind::Map,
        Kind::Space,
        Kind::Agent,
        Kind::Results,
        Kind::Summary,
        Kind::Candidates,
        Kind::Estimates,
        Kind::EstimateSummary,
        Kind::Model,
        Kind::Stream,
        Kind::Html,
        Kind::Svg,
        Kind::ModelRun,
    ];

    /// What the refusal says the file holds.
    fn held(self) -> &'static str {
        match self {
            Kind::Map => "holds a map",
            Kind::Space => "holds a search space",
            Kind::Agent => "holds an agent file",
            Kind::Results => "holds a batch's results",
            Kind::Summary => "holds a batch's summary",
            Kind::Candidates => "holds a search's candidates",
            Kind::Estimates => "holds an estimate's draws",
            Kind::EstimateSummary => "holds an estimate's summary",
            Kind::Model => "holds a planning model",
            Kind::Stream => "holds a deployment stream",
            Kind::Html => "holds an HTML page",
            Kind::Svg => "holds an SVG figure",
            Kind::ModelRun => "holds a gated run's summary",
        }
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A folder with the tiny map, the tiny agent, and one real file of every [`Kind`],
/// each written by the command that writes that kind (or shipped in maps/).
struct Foreign {
    dir: tempfile::TempDir,
    files: Vec<(Kind, PathBuf)>,
}

impl Foreign {
    fn new() -> Foreign {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path().to_path_buf();
        std::fs::write(d.join("tiny.ron"), TINY_MAP).unwrap();
        std::fs::write(d.join("agent.ron"), tiny_agent_text()).unwrap();
        let f = Foreign { dir, files: Vec::new() };
        let results = f.path("results.jsonl");
        let made = run(&f.batch_args(&results, &["--set", "horizon=1,2", "--episodes", "2"]));
        assert!(matches!(made.status.code(), Some(0 | 1)), "{}", output_text(&made));
        let search = f.path("search");
        assert_exit(&run(&search_args(&search, &[])), 0, &[]);
        let estimate = f.path("estimate");
        assert_exit(&run(&estimate_args(&estimate, &[])), 0, &[]);
        let model = f.path("model.json");
        assert_exit(
            &run_cli(&[
                "export-model",
                "--agent",
                &f.p("agent.ron"),
                "--obs",
                "1,1,1,1",
                "--out",
                s(&model),
            ]),
            0,
            &[],
        );
        let model_run = f.path("model_run.json");
        assert_exit(&run(&run_model_args(&model_run, &[])), 0, &[]);
        let trace = f.path("trace");
        let html = f.path("page.html");
        assert_exit(&run(&f.trace_args(&trace, &["--html", s(&html)])), 0, &[]);
        let copy = |name: &str, from: &str| {
            std::fs::copy(from, d.join(name)).unwrap();
            d.join(name)
        };
        let files = vec![
            (Kind::Map, copy("map.ron", "maps/jaywalk.ron")),
            (Kind::Space, copy("space.ron", SPACE)),
            (Kind::Agent, f.path("agent.ron")),
            (Kind::Results, results.clone()),
            (Kind::Summary, unforeseen_harness::runs::outputs::summary_path(&results)),
            (Kind::Candidates, search.join("candidates.jsonl")),
            (Kind::Estimates, estimate.join("estimate.jsonl")),
            (Kind::EstimateSummary, estimate.join("summary.json")),
            (Kind::Model, model),
            (Kind::Stream, copy("stream.ron", "maps/streams/deployment.ron")),
            (Kind::Html, html),
            (Kind::Svg, trace.join("theta.svg")),
            (Kind::ModelRun, model_run),
        ];
        for (kind, p) in &files {
            assert!(p.is_file(), "{kind:?}: {} was written", p.display());
        }
        Foreign { files, ..f }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn p(&self, name: &str) -> String {
        self.path(name).display().to_string()
    }

    fn file(&self, kind: Kind) -> &Path {
        &self.files.iter().find(|(k, _)| *k == kind).unwrap().1
    }

    fn batch_args(&self, out: &Path, extra: &[&str]) -> Vec<String> {
        let mut a: Vec<String> = ["batch", &self.p("tiny.ron"), "--agent", &self.p("agent.ron")]
            .map(String::from)
            .to_vec();
        a.extend(["--jobs", "1", "--quiet", "--out", s(out)].map(String::from));
        if !extra.contains(&"--seed") {
            a.extend(["--seed".into(), "5".into()]);
        }
        if !extra.contains(&"--episodes") {
            a.extend(["--episodes".into(), "1".into()]);
        }
        a.extend(extra.iter().map(|x| x.to_string()));
        a
    }

    fn trace_args(&self, out: &Path, extra: &[&str]) -> Vec<String> {
        let mut a: Vec<String> = [
            "trace",
            "--map",
            &self.p("tiny.ron"),
            "--agent",
            &self.p("agent.ron"),
            "-q",
        ]
        .map(String::from)
        .to_vec();
        a.extend(["--out".into(), s(out).into()]);
        a.extend(extra.iter().map(|x| x.to_string()));
        a
    }
}

fn search_args(out: &Path, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "search",
        "--method",
        "never-brake",
        "--budget",
        "2",
        "--episodes",
        "1",
        "--seed",
        "9",
        "--jobs",
        "1",
        "--space",
        SPACE,
        "--out",
        s(out),
    ]
    .map(String::from)
    .to_vec();
    a.extend(extra.iter().map(|x| x.to_string()));
    a
}

/// An estimate of never-brake on the jaywalk space, its smallest budget of one episode
/// per draw, into `out`.
fn estimate_args(out: &Path, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "estimate",
        "--method",
        "never-brake",
        "--budget",
        "50",
        "--episodes",
        "1",
        "--jobs",
        "1",
        "-q",
        "--space",
        SPACE,
        "--out",
        s(out),
    ]
    .map(String::from)
    .to_vec();
    a.extend(extra.iter().map(|x| x.to_string()));
    a
}

/// `run-model` on the shipped T-maze model and world, its summary written to `out`.
fn run_model_args(out: &Path, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "run-model",
        "--model",
        "examples/models/tmaze_model.json",
        "--env",
        "examples/models/tmaze_env.json",
        "--episodes",
        "2",
        "--steps",
        "3",
        "--out",
        s(out),
    ]
    .map(String::from)
    .to_vec();
    a.extend(extra.iter().map(|x| x.to_string()));
    a
}

/// [`search_args`] with the run seed `seed` (another search than the default's).
fn search_seeded(out: &Path, seed: &str, extra: &[&str]) -> Vec<String> {
    let mut a = search_args(out, extra);
    let i = a.iter().position(|x| x == "--seed").unwrap();
    a[i + 1] = seed.into();
    a
}

fn run(args: &[String]) -> Output {
    run_cli(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// A writer of the command line: its name, the outputs a foreign file is put at (a
/// file name inside its `--out` folder, or `""` for `--out` itself, or a suffix such as
/// `.summary.json` beside it) with the kind it writes there (`None`: a kind that is not
/// in [`Kind::ALL`], e.g. a CSV table), and the command given `--out` and extra flags.
struct Writer {
    name: &'static str,
    folder: bool,
    outputs: &'static [(&'static str, Option<Kind>)],
    args: fn(&Foreign, &Path, &[&str]) -> Vec<String>,
}

fn writers() -> Vec<Writer> {
    vec![
        Writer {
            name: "train",
            folder: false,
            outputs: &[("", Some(Kind::Agent))],
            args: |f, out, x| {
                let mut a: Vec<String> = [
                    "train",
                    "--map",
                    &f.p("tiny.ron"),
                    "--episodes",
                    "2",
                    "--seed",
                    "1",
                    "-q",
                ]
                .map(String::from)
                .to_vec();
                a.extend(["--out".into(), s(out).into()]);
                a.extend(x.iter().map(|x| x.to_string()));
                a
            },
        },
        Writer {
            name: "export-model",
            folder: false,
            outputs: &[("", Some(Kind::Model))],
            args: |f, out, x| {
                let mut a: Vec<String> = [
                    "export-model",
                    "--agent",
                    &f.p("agent.ron"),
                    "--obs",
                    "1,1,1,1",
                    "--out",
                    s(out),
                ]
                .map(String::from)
                .to_vec();
                a.extend(x.iter().map(|x| x.to_string()));
                a
            },
        },
        Writer {
            name: "plot-sweep",
            folder: false,
            outputs: &[("", Some(Kind::Svg))],
            args: |f, out, x| {
                let mut a: Vec<String> = ["plot-sweep", s(f.file(Kind::Results)), "--out", s(out)]
                    .map(String::from)
                    .to_vec();
                a.extend(x.iter().map(|x| x.to_string()));
                a
            },
        },
        Writer {
            name: "trace --html",
            folder: false,
            outputs: &[("", Some(Kind::Html))],
            args: |f, out, x| {
                let dir = out.with_extension("trace-dir");
                let mut extra = vec!["--html", s(out)];
                extra.extend(x);
                f.trace_args(&dir, &extra)
            },
        },
        Writer {
            name: "trace",
            folder: true,
            outputs: &[
                ("trace.csv", None),
                ("theta.svg", Some(Kind::Svg)),
                ("filmstrip.svg", Some(Kind::Svg)),
            ],
            args: |f, out, x| f.trace_args(out, x),
        },
        Writer {
            name: "eval",
            folder: true,
            outputs: &[("eval.json", None)],
            args: |f, out, x| {
                let mut a: Vec<String> = ["eval", "--map", &f.p("tiny.ron"), "--agent", &f.p("agent.ron")]
                    .map(String::from)
                    .to_vec();
                a.extend(["--episodes", "1", "-q", "--out", s(out)].map(String::from));
                a.extend(x.iter().map(|x| x.to_string()));
                a
            },
        },
        Writer {
            name: "compare",
            folder: true,
            outputs: &[
                ("compare.json", None),
                ("compare.csv", None),
                ("compare_seeds.csv", None),
                ("compare.svg", Some(Kind::Svg)),
            ],
            args: |f, out, x| {
                let mut a: Vec<String> = ["compare", "--agent", &f.p("agent.ron"), "--train-map", &f.p("tiny.ron")]
                    .map(String::from)
                    .to_vec();
                a.extend(["--test-map".into(), f.p("tiny.ron")]);
                a.extend(["--episodes", "1", "--protocol", "zero-shot", "-q", "--out", s(out)].map(String::from));
                a.extend(x.iter().map(|x| x.to_string()));
                a
            },
        },
        Writer {
            name: "learn",
            folder: true,
            outputs: &[
                ("learn.csv", None),
                ("learn.json", None),
                ("learn.svg", Some(Kind::Svg)),
            ],
            args: |f, out, x| {
                let mut a: Vec<String> = ["learn", "--map", &f.p("tiny.ron"), "--agent", &f.p("agent.ron")]
                    .map(String::from)
                    .to_vec();
                a.extend(["--episodes", "2", "-q", "--out", s(out)].map(String::from));
                a.extend(x.iter().map(|x| x.to_string()));
                a
            },
        },
        Writer {
            name: "batch",
            folder: false,
            outputs: &[("", Some(Kind::Results)), (".summary.json", Some(Kind::Summary))],
            args: |f, out, x| f.batch_args(out, x),
        },
        Writer {
            name: "merge",
            folder: false,
            outputs: &[("", Some(Kind::Results)), (".summary.json", Some(Kind::Summary))],
            args: |f, out, x| {
                let mut a: Vec<String> = ["merge", s(f.file(Kind::Results)), "--out", s(out)]
                    .map(String::from)
                    .to_vec();
                a.extend(x.iter().map(|x| x.to_string()));
                a
            },
        },
        Writer {
            name: "search",
            folder: true,
            outputs: &[
                ("candidates.jsonl", Some(Kind::Candidates)),
                ("candidates.jsonl.part", Some(Kind::Candidates)),
                ("summary.json", None),
                ("search.svg", Some(Kind::Svg)),
            ],
            args: |_, out, x| search_args(out, x),
        },
        Writer {
            name: "estimate",
            folder: true,
            outputs: &[
                ("estimate.jsonl", Some(Kind::Estimates)),
                ("estimate.jsonl.part", Some(Kind::Estimates)),
                ("summary.json", Some(Kind::EstimateSummary)),
            ],
            args: |_, out, x| estimate_args(out, x),
        },
        Writer {
            name: "run-model",
            folder: false,
            outputs: &[("", Some(Kind::ModelRun))],
            args: |_, out, x| run_model_args(out, x),
        },
    ]
}

/// Where the writer's `--out` goes in `scratch` and where its output `name` lands.
fn place(w: &Writer, scratch: &Path, name: &str) -> (PathBuf, PathBuf) {
    if w.folder {
        let out = scratch.join("o");
        (out.clone(), out.join(name))
    } else {
        let out = scratch.join("r.jsonl");
        let target = if name.is_empty() {
            out.clone()
        } else {
            unforeseen_harness::runs::outputs::summary_path(&out)
        };
        (out, target)
    }
}

/// The table-driven test of the issue: every writer, every output it writes, every
/// kind of file it does not write there; each refused (exit 2, the file named with what
/// it holds) and left byte for byte; then `--force` replaces it.
#[test]
fn no_writer_replaces_a_file_of_another_kind() {
    let f = Foreign::new();
    let mut cases = 0;
    let mut failed = Vec::new();
    for w in writers() {
        for &(name, own) in w.outputs {
            for kind in Kind::ALL.into_iter().filter(|k| Some(*k) != own) {
                cases += 1;
                let scratch = tempfile::tempdir().unwrap();
                let (out, target) = place(&w, scratch.path(), name);
                std::fs::create_dir_all(target.parent().unwrap()).unwrap();
                std::fs::copy(f.file(kind), &target).unwrap();
                let before = std::fs::read(&target).unwrap();
                let r = run(&(w.args)(&f, &out, &[]));
                let text = output_text(&r);
                let file_name = target.file_name().unwrap().to_str().unwrap();
                let refused = r.status.code() == Some(2) && text.contains(file_name) && text.contains(kind.held());
                let kept = std::fs::read(&target).ok().as_deref() == Some(before.as_slice());
                if !(refused && kept) {
                    failed.push(format!(
                        "{} with {kind:?} at {file_name}: exit {:?}, {}: {}",
                        w.name,
                        r.status.code(),
                        if kept { "kept" } else { "REPLACED" },
                        text.lines().find(|l| l.contains("error")).unwrap_or("(no error)")
                    ));
                }
            }
        }
    }
    eprintln!("{cases} cases (writer, output, foreign kind), {} failed", failed.len());
    assert!(
        failed.is_empty(),
        "{} of {cases} cases failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
}

/// `--force` replaces a foreign file, and a file of the writer's own kind from an
/// earlier run is replaced without it, on every writer.
#[test]
fn force_replaces_a_foreign_file_and_an_earlier_runs_file_is_replaced() {
    let f = Foreign::new();
    let mut failed = Vec::new();
    // Exit 1 is the tiny agent failing the map's expectations (batch, merge): not a refusal.
    let ok = |r: &Output| matches!(r.status.code(), Some(0 | 1)) && !output_text(r).contains("panicked");
    for w in writers() {
        let (name, _) = w.outputs[0];
        let scratch = tempfile::tempdir().unwrap();
        let (out, target) = place(&w, scratch.path(), name);
        std::fs::create_dir_all(target.parent().unwrap()).unwrap();
        std::fs::copy(f.file(Kind::Map), &target).unwrap();
        let r = run(&(w.args)(&f, &out, &["--force"]));
        if !ok(&r) || std::fs::read(&target).unwrap() == std::fs::read(f.file(Kind::Map)).unwrap() {
            failed.push(format!("{} --force: {}", w.name, output_text(&r)));
            continue;
        }
        let again = run(&(w.args)(&f, &out, &[]));
        if !ok(&again) {
            failed.push(format!(
                "{} over its own earlier output: {}",
                w.name,
                output_text(&again)
            ));
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// Every file under `dir` (recursively) with its bytes, the lock files aside.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut all = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if !p.to_string_lossy().ends_with("lock") {
                all.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
    }
    all.sort();
    all
}

fn assert_unchanged(before: &[(PathBuf, Vec<u8>)], dir: &Path, what: &str) {
    let after = snapshot(dir);
    let names = |s: &[(PathBuf, Vec<u8>)]| s.iter().map(|(p, _)| p.display().to_string()).collect::<Vec<_>>();
    assert_eq!(names(before), names(&after), "{what}: the files changed");
    for ((p, a), (_, b)) in before.iter().zip(&after) {
        assert!(a == b, "{what}: {} changed", p.display());
    }
}

#[test]
fn a_refused_batch_resume_keeps_the_earlier_summary() {
    let f = Foreign::new();
    let dir = f.path("runs");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("r.jsonl");
    let first = run(&f.batch_args(&out, &["--episodes", "2"]));
    assert!(matches!(first.status.code(), Some(0 | 1)), "{}", output_text(&first));
    assert!(unforeseen_harness::runs::outputs::summary_path(&out).is_file());
    let before = snapshot(&dir);
    // Another run's settings.
    assert_exit(
        &run(&f.batch_args(&out, &["--episodes", "3", "--resume"])),
        2,
        &["episodes"],
    );
    assert_unchanged(&before, &dir, "batch --resume --episodes 3");
    // A hand-edited line.
    let text = std::fs::read_to_string(&out).unwrap();
    let edited = text.replacen("\"success_rate\":", "\"success_rate\":-3.0,\"x\":", 1);
    assert_ne!(edited, text);
    std::fs::write(&out, edited).unwrap();
    let before = snapshot(&dir);
    let r = run(&f.batch_args(&out, &["--episodes", "2", "--resume"]));
    assert_eq!(r.status.code(), Some(2), "{}", output_text(&r));
    assert_unchanged(&before, &dir, "batch --resume over an edited line");
}

#[test]
fn a_refused_search_resume_keeps_the_earlier_set() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("s");
    assert_exit(&run(&search_args(&out, &[])), 0, &[]);
    assert!(out.join("summary.json").is_file() && out.join("search.svg").is_file());
    let before = snapshot(&out);
    let r = run(&search_seeded(&out, "8", &["--resume"]));
    assert_eq!(r.status.code(), Some(2), "{}", output_text(&r));
    assert!(
        output_text(&r).contains("seed: the file has 9, this run 8"),
        "{}",
        output_text(&r)
    );
    assert_unchanged(&before, &out, "search --resume --seed 8");
}

/// A full disk partway through a search (the `fault-injection` hook failing the N-th
/// append of the streamed candidates with `ENOSPC`), over an earlier search's set in
/// `--out`: exit 1 naming the file, and the earlier set byte for byte; `--resume` then
/// completes the run from the part, to the set an uninterrupted run writes.
#[test]
fn a_full_disk_during_a_search_keeps_the_earlier_set() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("s");
    let fresh = d.path().join("fresh");
    assert_exit(&run(&search_seeded(&fresh, "8", &[])), 0, &[]);
    assert_exit(&run(&search_args(&out, &[])), 0, &[]);
    let before = snapshot(&out);
    assert!(before.len() >= 3, "{before:?}");
    let part = out.join("candidates.jsonl.part");
    for at in 0..2 {
        let r = std::process::Command::new(env!("CARGO_BIN_EXE_unforeseen"))
            .args(search_seeded(&out, "8", &[]))
            .env("UNFORESEEN_FULL_DISK_AT_APPEND", at.to_string())
            .output()
            .unwrap();
        let text = output_text(&r);
        assert_eq!(r.status.code(), Some(1), "full disk at append {at}: {text}");
        assert!(
            text.contains("candidates.jsonl.part") && text.contains("No space left"),
            "{text}"
        );
        let kept: Vec<_> = snapshot(&out).into_iter().filter(|(p, _)| *p != part).collect();
        assert!(kept == before, "full disk at append {at}: the earlier set changed");
        assert!(part.is_file(), "the part stays for --resume");
    }
    assert_exit(&run(&search_seeded(&out, "8", &["--resume"])), 0, &[]);
    assert!(!part.exists(), "the part is committed with the set");
    let untimed = |dir: &Path| -> Vec<String> {
        std::fs::read_to_string(dir.join("candidates.jsonl"))
            .unwrap()
            .lines()
            .map(|l| {
                let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
                v.as_object_mut().unwrap().remove("timing_us_per_tick");
                v.to_string()
            })
            .collect()
    };
    assert_eq!(
        untimed(&out),
        untimed(&fresh),
        "the resumed run is the uninterrupted one"
    );
}

#[test]
fn a_refused_merge_keeps_the_earlier_merge() {
    let f = Foreign::new();
    let parts: Vec<PathBuf> = (1..=2).map(|i| f.path(&format!("p{i}.jsonl"))).collect();
    for (i, p) in parts.iter().enumerate() {
        let shard = format!("{}/2", i + 1);
        let r = run(&f.batch_args(p, &["--set", "horizon=1,2", "--shard", &shard]));
        assert!(matches!(r.status.code(), Some(0 | 1)), "{}", output_text(&r));
    }
    let other = f.path("other.jsonl");
    let r = run(&f.batch_args(&other, &["--set", "horizon=1,2", "--shard", "2/2", "--episodes", "2"]));
    assert!(matches!(r.status.code(), Some(0 | 1)), "{}", output_text(&r));
    let dir = f.path("merged");
    std::fs::create_dir_all(&dir).unwrap();
    let m = dir.join("m.jsonl");
    let merge = |ps: &[&Path]| {
        let mut a = vec!["merge".to_string()];
        a.extend(ps.iter().map(|p| s(p).to_string()));
        a.extend(["--out".into(), s(&m).into()]);
        run(&a)
    };
    let r = merge(&[&parts[0], &parts[1]]);
    assert!(matches!(r.status.code(), Some(0 | 1)), "{}", output_text(&r));
    assert!(unforeseen_harness::runs::outputs::summary_path(&m).is_file());
    let before = snapshot(&dir);
    for (what, ps) in [
        ("a gap", vec![parts[0].as_path()]),
        ("a part of another run", vec![parts[0].as_path(), other.as_path()]),
        (
            "a part given twice",
            vec![parts[0].as_path(), parts[1].as_path(), parts[1].as_path()],
        ),
    ] {
        assert_exit(&merge(&ps), 2, &[]);
        assert_unchanged(&before, &dir, what);
    }
}

/// A results file cut short: `plot-sweep` refuses it, listing the missing units, unless
/// `--partial`.
#[test]
fn plot_sweep_refuses_a_partial_run_unless_asked() {
    let f = Foreign::new();
    let full = std::fs::read_to_string(f.file(Kind::Results)).unwrap();
    let lines: Vec<&str> = full.lines().collect();
    assert!(lines.len() >= 4, "{full}");
    let short = f.path("short.jsonl");
    std::fs::write(&short, lines[..lines.len() - 1].join("\n") + "\n").unwrap();
    let cut = f.path("cut.jsonl");
    std::fs::write(&cut, &full[..full.len() - 5]).unwrap();
    let svg = f.path("sweep.svg");
    for partial in [&short, &cut] {
        let r = run_cli(&["plot-sweep", s(partial), "--out", s(&svg)]);
        assert_exit(&r, 2, &["missing", "unit", "--partial"]);
        assert!(!svg.exists(), "nothing plotted");
        let r = run_cli(&["plot-sweep", s(partial), "--partial", "--out", s(&svg)]);
        assert_exit(&r, 0, &["missing", "unit"]);
        assert!(svg.is_file());
        std::fs::remove_file(&svg).unwrap();
    }
    assert_exit(
        &run_cli(&["plot-sweep", s(f.file(Kind::Results)), "--out", s(&svg)]),
        0,
        &[],
    );
}

/// A `--cache` that is a file is refused before any training, with exit 2.
#[test]
fn a_bad_cache_is_refused_before_any_training() {
    let f = Foreign::new();
    let cache = f.file(Kind::Map);
    let out = f.path("c.jsonl");
    let seeds = ["--train-seeds", "1..2", "--train-episodes", "50", "--cache", s(cache)];
    let batch = run_cli(
        &[
            &["batch", &f.p("tiny.ron"), "--episodes", "1", "--out", s(&out)],
            &seeds[..],
        ]
        .concat(),
    );
    assert_exit(&batch, 2, &["--cache", "map.ron"]);
    assert!(!output_text(&batch).contains("training"), "{}", output_text(&batch));
    assert!(!out.exists());
    let o = f.path("cmp");
    let compare = run_cli(
        &[
            &[
                "compare",
                "--train-map",
                &f.p("tiny.ron"),
                "--test-map",
                &f.p("tiny.ron"),
            ],
            &seeds[..],
            &["--episodes", "1", "--protocol", "zero-shot", "--out", s(&o)],
        ]
        .concat(),
    );
    assert_exit(&compare, 2, &["--cache", "map.ron"]);
    assert!(!output_text(&compare).contains("training"), "{}", output_text(&compare));
    assert_eq!(
        std::fs::read(cache).unwrap(),
        std::fs::read("maps/jaywalk.ron").unwrap()
    );
}

/// A map whose name is 70,000 characters long is refused at load (check-map, batch,
/// compare --test-map), and a 100,000-digit `--set` value never panics a table.
#[test]
fn long_names_are_refused_at_load_and_tables_never_panic() {
    let d = tempfile::tempdir().unwrap();
    let map = d.path().join("long.ron");
    let named = TINY_MAP.replacen("name: \"tiny\"", &format!("name: \"{}\"", "n".repeat(70_000)), 1);
    assert_ne!(named, TINY_MAP);
    std::fs::write(&map, named).unwrap();
    let agent = d.path().join("agent.ron");
    std::fs::write(&agent, tiny_agent_text()).unwrap();
    assert_exit(&run_cli(&["check-map", s(&map)]), 2, &["name", "long.ron"]);
    let out = d.path().join("r.jsonl");
    let b = run_cli(&[
        "batch",
        s(&map),
        "--method",
        "never-brake",
        "--episodes",
        "1",
        "-q",
        "--out",
        s(&out),
    ]);
    assert_exit(&b, 2, &["name", "long.ron"]);
    assert!(!out.exists(), "refused before writing");
    let c = run_cli(&[
        "compare",
        "--agent",
        s(&agent),
        "--test-map",
        s(&map),
        "--episodes",
        "1",
        "--protocol",
        "zero-shot",
        "--out",
        s(&d.path().join("c")),
    ]);
    assert_exit(&c, 2, &["name", "long.ron"]);
    assert!(!d.path().join("c").exists(), "refused before writing");
    let omega = format!("omega=1.{}", "0".repeat(100_000));
    let tiny = d.path().join("tiny.ron");
    std::fs::write(&tiny, TINY_MAP).unwrap();
    let b = run_cli(&[
        "batch",
        s(&tiny),
        "--agent",
        s(&agent),
        "--method",
        "scaled",
        "--episodes",
        "1",
        "-q",
        "--set",
        &omega,
        "--out",
        s(&d.path().join("o.jsonl")),
    ]);
    assert!(
        matches!(b.status.code(), Some(0..=2)),
        "exit {:?}: {}",
        b.status.code(),
        output_text(&b)
    );
    assert!(!output_text(&b).contains("panicked"), "{}", output_text(&b));
}

/// Runs the binary with `args`; `None` when it has not ended within `secs` (then killed).
fn run_within(args: &[&str], secs: u64) -> Option<Output> {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while start.elapsed() < std::time::Duration::from_secs(secs) {
        if child.try_wait().unwrap().is_some() {
            return Some(child.wait_with_output().unwrap());
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

#[cfg(unix)]
#[test]
fn inspect_refuses_a_pipe_and_a_device() {
    let d = tempfile::tempdir().unwrap();
    let fifo = d.path().join("model.json");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    for model in [s(&fifo), "/dev/zero"] {
        let r = run_within(&["inspect", "--model", model], 30)
            .unwrap_or_else(|| panic!("inspect --model {model} never ended"));
        assert_exit(&r, 2, &[model, "not a regular file"]);
    }
}

#[test]
fn trace_episode_with_a_sign_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let (map, agent) = (d.path().join("tiny.ron"), d.path().join("agent.ron"));
    std::fs::write(&map, TINY_MAP).unwrap();
    std::fs::write(&agent, tiny_agent_text()).unwrap();
    let out = d.path().join("t");
    let r = run_cli(&[
        "trace",
        "--episode",
        "+5",
        "--map",
        s(&map),
        "--agent",
        s(&agent),
        "--out",
        s(&out),
    ]);
    assert_exit(&r, 2, &["--episode"]);
    assert!(!out.exists());
}

/// The files of an output set in `dirs` (hidden files and locks aside), by name.
fn set_files(dirs: &[PathBuf]) -> std::collections::BTreeMap<String, Vec<u8>> {
    let mut all = std::collections::BTreeMap::new();
    for d in dirs {
        for (p, bytes) in snapshot(d) {
            let name = p.strip_prefix(d).unwrap().display().to_string();
            if !name.starts_with('.') && !name.ends_with("lock") {
                all.insert(format!("{}/{name}", d.file_name().unwrap().to_string_lossy()), bytes);
            }
        }
    }
    all
}

/// Hidden files left in `dirs` (temporaries, journals).
fn leftovers(dirs: &[PathBuf]) -> Vec<String> {
    dirs.iter()
        .filter_map(|d| std::fs::read_dir(d).ok())
        .flat_map(|r| r.flatten().map(|e| e.file_name().to_string_lossy().into_owned()))
        .filter(|n| n.starts_with(".unforeseen-") || n.starts_with(".tmp"))
        .collect()
}

/// Kills the job `args(seed)` at every rename of its output set in `dirs`, over the set
/// of an earlier run (seed 7), and finds, once the folders are recovered (what the next
/// run into them does), the old set or the new set, never a mix, and no temporary left.
/// A file is "old" when it is the earlier run's and differs from an uninterrupted new
/// run's; "new" when it differs from the earlier run's. Returns the kills made.
fn no_kill_mixes_a_set(name: &str, dirs: &[PathBuf], renames: usize, args: &dyn Fn(&str) -> Vec<String>) -> usize {
    let clean = || {
        for d in dirs {
            let _ = std::fs::remove_dir_all(d);
        }
    };
    let exit_ok = |r: &Output| matches!(r.status.code(), Some(0 | 1));
    clean();
    let r = run(&args("8"));
    assert!(exit_ok(&r), "{name}: {}", output_text(&r));
    let fresh = set_files(dirs);
    clean();
    let r = run(&args("7"));
    assert!(exit_ok(&r), "{name}: {}", output_text(&r));
    let old = set_files(dirs);
    assert!(old.len() >= 2, "{name}: {old:?}");
    let mut kills = 0;
    for at in 0..renames {
        // The earlier set back in place.
        clean();
        for (f, bytes) in &old {
            let (top, rest) = f.split_once('/').unwrap();
            let dir = dirs
                .iter()
                .find(|d| d.file_name().unwrap().to_string_lossy() == top)
                .unwrap();
            let path = dir.join(rest);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, bytes).unwrap();
        }
        let r = std::process::Command::new(env!("CARGO_BIN_EXE_unforeseen"))
            .args(args("8"))
            .env("UNFORESEEN_KILL_AT_RENAME", at.to_string())
            .output()
            .unwrap();
        assert_eq!(
            r.status.code(),
            None,
            "{name}: killed before rename {at}: {}",
            output_text(&r)
        );
        for d in dirs {
            unforeseen_harness::files::recover(d).unwrap();
        }
        let now = set_files(dirs);
        let is_old = |f: &String| now.get(f) == old.get(f) && fresh.get(f) != old.get(f);
        let is_new = |f: &String| now.get(f) != old.get(f);
        let olds: Vec<&String> = now.keys().filter(|f| is_old(f)).collect();
        let news: Vec<&String> = now.keys().filter(|f| is_new(f)).collect();
        assert!(
            olds.is_empty() || news.is_empty(),
            "{name}, killed before rename {at}: a mix: {olds:?} of the earlier run beside {news:?} of the new one"
        );
        assert!(
            leftovers(dirs).is_empty(),
            "{name}, rename {at}: {:?} left",
            leftovers(dirs)
        );
        kills += 1;
    }
    kills
}

/// Every multi-file job killed before each rename of its set (the `fault-injection`
/// hook of `unforeseen_harness::files`): compare, learn, trace with --html in another folder,
/// batch and merge (results and summary), search.
#[test]
fn a_kill_between_two_renames_leaves_the_old_set_or_the_new_one() {
    let f = Foreign::new();
    let mut kills = 0;
    let o = f.path("o");
    let h = f.path("h");
    let tiny = f.p("tiny.ron");
    let agent = f.p("agent.ron");
    let common = |cmd: &str, seed: &str| -> Vec<String> {
        [cmd, "--agent", &agent, "--seed", seed, "-q", "--out", s(&o)]
            .map(String::from)
            .to_vec()
    };
    kills += no_kill_mixes_a_set("compare", std::slice::from_ref(&o), 4, &|seed| {
        let mut a = common("compare", seed);
        a.extend(
            [
                "--train-map",
                &tiny,
                "--test-map",
                &tiny,
                "--episodes",
                "2",
                "--protocol",
                "zero-shot",
            ]
            .map(String::from),
        );
        a
    });
    kills += no_kill_mixes_a_set("learn", std::slice::from_ref(&o), 3, &|seed| {
        let mut a = common("learn", seed);
        a.extend(["--map", &tiny, "--episodes", "3"].map(String::from));
        a
    });
    kills += no_kill_mixes_a_set("trace --html", &[o.clone(), h.clone()], 4, &|seed| {
        let mut a = common("trace", seed);
        let page = h.join("page.html");
        a.extend(["--map".into(), tiny.clone(), "--html".into(), s(&page).into()]);
        a
    });
    let r = f.path("r");
    let results = r.join("r.jsonl");
    kills += no_kill_mixes_a_set("batch", std::slice::from_ref(&r), 2, &|seed| {
        f.batch_args(&results, &["--seed", seed, "--episodes", "2"])
    });
    let parts = f.path("parts");
    std::fs::create_dir_all(&parts).unwrap();
    for seed in ["7", "8"] {
        let made = run(&f.batch_args(&parts.join(format!("p{seed}.jsonl")), &["--seed", seed]));
        assert!(matches!(made.status.code(), Some(0 | 1)), "{}", output_text(&made));
    }
    kills += no_kill_mixes_a_set("merge", std::slice::from_ref(&r), 2, &|seed| {
        ["merge", s(&parts.join(format!("p{seed}.jsonl"))), "--out", s(&results)]
            .map(String::from)
            .to_vec()
    });
    kills += no_kill_mixes_a_set("search", std::slice::from_ref(&o), 3, &|seed| {
        search_seeded(&o, seed, &[])
    });
    eprintln!("{kills} kills (job, rename), none left a mix");
}
