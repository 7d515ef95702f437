//! Every kind of figure, drawn from real and from awkward data (long episodes, long
//! labels, many series, flat series, one agent and several), has no overlapping and no
//! cut-off text (estimated from the SVG's `<text>` elements: `svg_text`). The figures
//! the README's commands write are checked the same way in `readme`.

use unforeseen_agent::params::ScaledParams;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::episodes::trace;
use unforeseen_harness::fixtures;
use unforeseen_harness::reports::figures::{
    BarPanel, BarRow, Series, bar_key, filmstrip, grouped_bars, line_panels, theta_trace,
};

use unforeseen_harness::fixtures::svg_text::assert_text_fits;

#[test]
fn theta_traces_of_short_and_long_episodes_fit() {
    let dir = tempfile::tempdir().unwrap();
    let actions = ["speed up", "maintain", "slow down"];
    for (n, measured) in [(1u32, true), (5, true), (17, true), (45, true), (80, true), (12, false)] {
        let ticks: Vec<_> = (0..n)
            .map(|t| {
                let theta = measured.then_some(f64::from(t % 7) / 7.0);
                (t, theta, t % 3 == 1, actions[(t % 3) as usize].to_string())
            })
            .collect();
        let path = dir.path().join(format!("theta_{n}_{measured}.svg"));
        theta_trace(
            &path,
            "scaled on a_rather_long_map_name: normalized surprise",
            &ticks,
            0.2,
        )
        .unwrap();
        assert_text_fits(&path);
    }
}

#[test]
fn line_panels_with_long_labels_and_many_series_fit() {
    let dir = tempfile::tempdir().unwrap();
    let colors = [plotters::style::BLUE, plotters::style::RED];
    let labels: Vec<String> = (0..14)
        .map(|i| format!("scenario_{i} / scaled / continual, horizon={i}, epsilon=0.{i}"))
        .collect();
    let many: Vec<Series<'_>> = labels
        .iter()
        .enumerate()
        .map(|(i, label)| Series {
            label,
            points: (0..10usize).map(|x| (x as f64 * 0.1, (i * x) as f64)).collect(),
            color: colors[i % 2],
        })
        .collect();
    let flat = vec![Series {
        label: "flat at 1",
        points: vec![(0.1, 1.0), (0.3, 1.0)],
        color: colors[0],
    }];
    let single = vec![Series {
        label: "",
        points: vec![(3.0, 0.5)],
        color: colors[1],
    }];
    let path = dir.path().join("lines.svg");
    line_panels(
        &path,
        "x as named in the panel title (each point: mean over training seeds)",
        &[
            ("success rate vs EFE mat-vecs per tick (reasoning compute)", many),
            ("flat", flat),
            ("one point, no key", single),
            ("empty", Vec::new()),
        ],
    )
    .unwrap();
    assert_text_fits(&path);
}

#[test]
fn grouped_bars_for_one_and_several_agents_fit() {
    let dir = tempfile::tempdir().unwrap();
    let labels: Vec<String> = [
        "q-learning",
        "bayes-rl",
        "scaled",
        "bayes-rl-factored",
        "scaled-always",
        "scaled-no-learning",
    ]
    .map(String::from)
    .to_vec();
    for (agents, methods) in [(1usize, 3usize), (10, 6)] {
        let labels = &labels[..methods];
        let panel = |title, scale: f64| BarPanel {
            title,
            labels,
            ours: (0..methods).map(|i| scale * (i as f64 - 1.0)).collect(),
            interval: (0..methods)
                .map(|i| (agents > 1).then_some((scale * (i as f64 - 1.2), scale * (i as f64 - 0.8))))
                .collect(),
            paper: (0..methods).map(|i| (i < 3).then_some(scale * 0.5)).collect(),
        };
        let rows: Vec<BarRow<'_>> = [true, false]
            .into_iter()
            .map(|paper| BarRow {
                title:
                    "zero-shot protocol: every method starts every test episode from its trained state (paper Fig. 8)"
                        .into(),
                key: bar_key(agents, paper),
                panels: vec![
                    panel("train reward (training map)", 80.0),
                    panel("test reward (test map)", 40.0),
                    panel("success rate (test map)", 0.5),
                    panel("inference rate (test map)", 0.4),
                ],
            })
            .collect();
        let path = dir.path().join(format!("bars_{agents}.svg"));
        grouped_bars(&path, &rows).unwrap();
        assert_text_fits(&path);
    }
}

#[test]
fn filmstrips_of_real_episodes_fit() {
    let dir = tempfile::tempdir().unwrap();
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    for method in [Method::Scaled, Method::QLearning] {
        let (_, ticks) = trace(
            fixtures::bundle(),
            &ScaledParams::default(),
            method,
            &jaywalk,
            11,
            Protocol::ZeroShot,
            0,
        )
        .unwrap();
        let path = dir.path().join(format!("filmstrip_{method}.svg"));
        let title = format!(
            "{method} on jaywalk, seed 11: reached the destination after 17 ticks (from above, one strip per decision tick)"
        );
        filmstrip(&path, &title, &jaywalk, &ticks).unwrap();
        assert_text_fits(&path);
        let svg = std::fs::read_to_string(&path).unwrap();
        for words in ["car, reasoning on this tick", "pedestrian", "crosswalk", "light green"] {
            assert!(svg.contains(words), "the filmstrip's key explains {words:?}");
        }
    }
}

#[test]
fn the_committed_figures_fit() {
    let dir = unforeseen_harness::fixtures::repo_path("docs/figures");
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap().flatten() {
        if entry.path().extension().is_some_and(|e| e == "svg") {
            assert_text_fits(&entry.path());
            checked += 1;
        }
    }
    assert!(checked > 0, "docs/figures has figures");
}
