//! `trace --html FILE` writes one self-contained page (nothing fetched: no address, no
//! external script, style or image) that carries every tick of the episode, the same
//! figures as `trace.csv`, and keeps the SVG filmstrip beside it.

use std::process::Command;
use unforeseen_harness::fixtures;

/// The JSON the page embeds for its script.
fn embedded_episode(page: &str) -> serde_json::Value {
    let start_tag = "<script type=\"application/json\" id=\"episode\">";
    let start = page.find(start_tag).expect("the episode's data") + start_tag.len();
    let end = start + page[start..].find("</script>").expect("closed data script");
    serde_json::from_str(&page[start..end]).expect("valid JSON")
}

#[test]
fn trace_html_is_self_contained_and_carries_every_tick() {
    let dir = tempfile::tempdir().unwrap();
    let agent = dir.path().join("agent.ron");
    unforeseen_harness::training::agent_file::save(&agent, fixtures::bundle()).unwrap();
    let html = dir.path().join("replay").join("episode.html");
    let out = Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(["trace", "--map", "jaywalk", "--seed", "11", "-q", "--agent"])
        .arg(&agent)
        .arg("--out")
        .arg(dir.path().join("trace"))
        .arg("--html")
        .arg(&html)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("episode.html"), "says where the page went:\n{stdout}");
    assert!(
        dir.path().join("trace").join("filmstrip.svg").is_file(),
        "the filmstrip stays"
    );

    let page = std::fs::read_to_string(&html).unwrap();
    let lower = page.to_lowercase();
    for external in [
        "http://",
        "https://",
        "src=",
        "href=",
        "@import",
        "url(",
        "fetch(",
        "xmlhttprequest",
    ] {
        assert!(
            !lower.contains(external),
            "the page refers to something outside it: {external:?}"
        );
    }
    assert!(lower.starts_with("<!doctype html>") && lower.trim_end().ends_with("</html>"));
    for part in [
        "<svg id=\"scene\"",
        "<svg id=\"timeline\"",
        "type=\"range\"",
        "id=\"play\"",
    ] {
        assert!(page.contains(part), "the page has {part:?}");
    }

    // Every tick, as trace.csv has the decided ones (the page adds the final frame).
    let csv = std::fs::read_to_string(dir.path().join("trace").join("trace.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv.lines().skip(1).map(|l| l.split(',').collect()).collect();
    let episode = embedded_episode(&page);
    let ticks = episode["ticks"].as_array().unwrap();
    assert_eq!(
        ticks.len(),
        rows.len() + 1,
        "one frame per decided tick and the final one"
    );
    for (tick, row) in ticks.iter().zip(&rows) {
        assert_eq!(tick["step"].as_u64().unwrap().to_string(), row[0]);
        assert_eq!(tick["action"].as_str().unwrap(), row[5]);
        assert_eq!(tick["reasoned"].as_bool().unwrap(), row[6] == "reasoning");
        let car_x: f64 = row[12].parse().unwrap();
        assert!((tick["car_x"].as_f64().unwrap() - car_x).abs() < 1e-3);
        match tick["theta"].as_f64() {
            Some(theta) => assert!((theta - row[8].parse::<f64>().unwrap()).abs() < 1e-6),
            None => assert_eq!(row[8], "-"),
        }
        assert!(tick["pedestrians"].is_array() && tick["light"].is_string());
    }
    assert!(
        ticks.last().unwrap()["action"].is_null(),
        "the final frame takes no action"
    );
    assert!(episode["epsilon"].as_f64().is_some() && episode["scene"]["goal_x"].as_f64().is_some());
    // Written atomically: no temporary file left beside it.
    let names: Vec<_> = std::fs::read_dir(html.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("episode.html")]);
}

#[test]
fn names_in_the_page_cannot_end_its_script() {
    let map = unforeseen_harness::maps::load("jaywalk").unwrap();
    let (_, ticks) = unforeseen_harness::episodes::trace(
        fixtures::bundle(),
        &Default::default(),
        unforeseen_harness::episodes::Method::QLearning,
        &map,
        3,
        unforeseen_harness::episodes::Protocol::ZeroShot,
        0,
    )
    .unwrap();
    let title = "a </script><script>alert(1)</script> & \"quoted\" title";
    let page = unforeseen_harness::reports::replay_html(title, "ended", &map, &ticks, 0.2).unwrap();
    assert_eq!(
        page.matches("</script>").count(),
        2,
        "only the page's own two scripts end"
    );
    assert!(!page.contains("<script>alert"));
    assert_eq!(
        embedded_episode(&page)["title"].as_str(),
        Some(title),
        "the data keep the title as it was"
    );
}

/// The frame of the tick that entered the crosswalk on red says so (never-brake on
/// red_on_approach runs the red light every episode), and no other frame does.
#[test]
fn the_replay_marks_the_tick_that_ran_the_red_light() {
    let dir = tempfile::tempdir().unwrap();
    let agent = dir.path().join("agent.ron");
    unforeseen_harness::training::agent_file::save(&agent, fixtures::bundle()).unwrap();
    let html = dir.path().join("episode.html");
    let map = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("maps/red_light/red_on_approach.ron");
    let out = Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(["trace", "--method", "never-brake", "-q", "--map"])
        .arg(&map)
        .arg("--agent")
        .arg(&agent)
        .arg("--out")
        .arg(dir.path().join("trace"))
        .arg("--html")
        .arg(&html)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let page = std::fs::read_to_string(&html).unwrap();
    let episode = embedded_episode(&page);
    let ticks = episode["ticks"].as_array().unwrap();
    let flagged: Vec<usize> = (0..ticks.len())
        .filter(|&i| ticks[i]["red_light"].as_bool().unwrap())
        .collect();
    assert_eq!(flagged, vec![7], "the tick 7..8 s enters the crosswalk on red");
    assert!(page.contains("ran a red light"));
}
