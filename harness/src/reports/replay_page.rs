//! An episode replay to watch rather than read (`unforeseen trace --html FILE`): one
//! self-contained HTML file, inline SVG and a small inline script, no network. The
//! road seen from above (car, pedestrians, light) plays beside the normalized surprise
//! theta and the action of every tick (paper Figs. 6-7); a slider scrubs, a button
//! plays. Positions between two decision ticks are interpolated for display only; the
//! per-tick data are embedded as JSON (`<script type="application/json" id="episode">`),
//! the same figures as `trace.csv`. On a map with a junction the scene adds the cross
//! street, its crosswalks and the stop lines ([`crate::reports::junction_scene`]) and
//! every tick carries every signal head's state and the other vehicles' poses, which the
//! page animates.

use serde::Serialize;
use unforeseen_sim::{LightPhase, Map};

use crate::episodes::runner::Tick;
use crate::reports::scene::{JunctionScene, Lamp, Shows, junction_scene};

/// The road's geometry, in metres, as the replay draws it.
#[derive(Debug, Serialize)]
struct Scene {
    x0: f64,
    x1: f64,
    road_half: f64,
    sidewalk: f64,
    car_y: f64,
    car_length: f64,
    car_width: f64,
    crosswalk_x: f64,
    crosswalk_width: f64,
    goal_x: f64,
    light_x: f64,
    /// The road's colour: its friction's tint (`figures::surface_tint`).
    road_colour: String,
    /// The junction, if the map has one.
    junction: Option<JunctionView>,
}

/// A rectangle `[x0, y0, x1, y1]`, m.
type Area = [f64; 4];

/// The junction as the page draws it ([`JunctionScene`]).
#[derive(Debug, Serialize)]
struct JunctionView {
    /// How far across the road the scene reaches, m.
    reach: f64,
    junction_box: Area,
    /// x of the cross street's kerbs, m.
    cross_kerbs: (f64, f64),
    cross_sidewalk: f64,
    cross_lane_lines: Vec<f64>,
    /// (across the road, the rectangle) per crosswalk of the other arms.
    crosswalks: Vec<(bool, Area)>,
    stop_lines: Vec<[(f64, f64); 2]>,
    /// (x, y, which head it repeats: `road`, `cross`, `walk_road` or `walk_cross`) per
    /// head besides the car's.
    heads: Vec<(f64, f64, &'static str)>,
}

impl JunctionView {
    fn of(j: JunctionScene) -> JunctionView {
        let area = |r: unforeseen_sim::junction::Rect| [r.x0, r.y0, r.x1, r.y1];
        JunctionView {
            reach: j.reach,
            junction_box: area(j.junction_box),
            cross_kerbs: j.cross_kerbs,
            cross_sidewalk: j.cross_sidewalk,
            cross_lane_lines: j.cross_lane_lines,
            crosswalks: j.crosswalks.iter().map(|(arm, r)| (arm.on_road(), area(*r))).collect(),
            stop_lines: j.stop_lines,
            heads: (j.heads.iter())
                .map(|h| {
                    let shows = match h.shows {
                        Shows::Road => "road",
                        Shows::Cross => "cross",
                        Shows::WalkRoad => "walk_road",
                        Shows::WalkCross => "walk_cross",
                    };
                    (h.x, h.y, shows)
                })
                .collect(),
        }
    }
}

/// Every head at one tick, as [`Lamp::name`]s.
#[derive(Debug, Serialize)]
struct Heads {
    road: &'static str,
    cross: &'static str,
    walk_road: &'static str,
    walk_cross: &'static str,
}

/// One decision tick of the replay.
#[derive(Debug, Serialize)]
struct Frame {
    step: u32,
    time: f64,
    car_x: f64,
    speed: f64,
    light: &'static str,
    light_left: f64,
    /// (x, y, on the crosswalk) per pedestrian.
    pedestrians: Vec<(f64, f64, bool)>,
    /// (from, to, friction, CSS colour) per surface patch on the road at this tick.
    surface: Vec<(f64, f64, f64, String)>,
    /// Every signal head (the car's is `road`; dark in an outage, whatever `light` reads).
    signals: Heads,
    /// (x, y, heading rad, length, width, in the car's path) per other vehicle.
    vehicles: Vec<(f64, f64, f64, f64, f64, bool)>,
    /// Whether a vehicle is in the car's path.
    vehicle_in_path: bool,
    /// The action taken at this tick (none on the final frame).
    action: Option<String>,
    reasoned: bool,
    theta: Option<f64>,
    surprise_bits: Option<f64>,
    /// The discrete state (d, v, L, p).
    state: [usize; 4],
    reward: f64,
    /// This tick's action took the car into the crosswalk on red (a violation).
    red_light: bool,
    policy: Vec<f64>,
    psi: Option<Vec<f64>>,
}

/// The whole episode as embedded in the page.
#[derive(Debug, Serialize)]
struct Episode<'a> {
    title: &'a str,
    outcome: &'a str,
    epsilon: f64,
    decision_dt: f64,
    actions: [String; 3],
    scene: Scene,
    ticks: Vec<Frame>,
}

fn light_name(l: LightPhase) -> &'static str {
    match l {
        LightPhase::Green => "green",
        LightPhase::Amber => "amber",
        LightPhase::Red => "red",
    }
}

/// Escapes text for HTML element content and attribute values.
fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The replay page of an episode: `ticks` as `trace` records them (the last one is the
/// world after the final action), titled `title`, ending in `outcome`, against the
/// reasoning threshold `epsilon`.
pub fn replay_html(
    title: &str,
    outcome: &str,
    map: &Map,
    ticks: &[Tick],
    epsilon: f64,
) -> Result<String, crate::error::Error> {
    let road_half = f64::from(map.road.lanes) * map.road.lane_width / 2.0;
    let last = ticks.len().saturating_sub(1);
    let episode = Episode {
        title,
        outcome,
        epsilon,
        decision_dt: map.episode.decision_dt,
        actions: unforeseen_sim::Action::ALL.map(|a| a.to_string()),
        scene: Scene {
            x0: map.vehicle.start_x - map.vehicle.length - 2.0,
            x1: map.road.goal_x + 4.0,
            road_half,
            sidewalk: map.road.sidewalk_width,
            car_y: -road_half + map.road.lane_width / 2.0,
            car_length: map.vehicle.length,
            car_width: map.vehicle.width,
            crosswalk_x: map.crosswalk.x,
            crosswalk_width: map.crosswalk.width,
            goal_x: map.road.goal_x,
            light_x: map.crosswalk.x - map.crosswalk.width,
            road_colour: {
                let c = crate::reports::figures::surface_tint(map.road.friction);
                format!("rgb({},{},{})", c.0, c.1, c.2)
            },
            junction: junction_scene(map).map(JunctionView::of),
        },
        ticks: ticks
            .iter()
            .enumerate()
            .map(|(i, t)| Frame {
                step: t.step,
                time: t.snapshot.time,
                car_x: t.snapshot.car_x,
                speed: t.snapshot.car_speed,
                light: light_name(t.snapshot.light),
                light_left: t.snapshot.light_time_left,
                pedestrians: t
                    .snapshot
                    .pedestrians
                    .iter()
                    .map(|p| (p.x, p.y, p.on_crosswalk))
                    .collect(),
                surface: t
                    .snapshot
                    .surface
                    .iter()
                    .map(|p| {
                        let c = crate::reports::figures::surface_tint(p.friction);
                        (p.from, p.to, p.friction, format!("rgb({},{},{})", c.0, c.1, c.2))
                    })
                    .collect(),
                signals: {
                    let g = &t.snapshot.signals;
                    Heads {
                        road: Lamp::of_aspect(g.road).name(),
                        cross: Lamp::of_aspect(g.cross).name(),
                        walk_road: Lamp::of_walk(g.walk_road).name(),
                        walk_cross: Lamp::of_walk(g.walk_cross).name(),
                    }
                },
                vehicles: (t.snapshot.vehicles.iter())
                    .map(|v| (v.x, v.y, v.heading, v.length, v.width, v.in_path))
                    .collect(),
                vehicle_in_path: t.snapshot.vehicle_in_path,
                action: (i < last).then(|| t.action.to_string()),
                reasoned: t.reasoned && i < last,
                theta: t.theta.filter(|_| i < last),
                surprise_bits: t.surprise.filter(|_| i < last).map(|s| s / std::f64::consts::LN_2),
                state: [t.state.d, t.state.v, t.state.l, t.state.p],
                reward: t.reward,
                red_light: t.red_light,
                policy: t.policy.clone(),
                psi: t.psi.clone(),
            })
            .collect(),
    };
    // Inside <script>, "</script>" must never appear: '<', '>' and '&' occur only in JSON
    // strings, where their \u escapes mean the same.
    let json = serde_json::to_string(&episode)?
        .replace('<', "\\u003c")
        .replace('>', "\\u003e")
        .replace('&', "\\u0026");
    Ok(PAGE
        .replace("{{TITLE}}", &html_escape(title))
        .replace("{{OUTCOME}}", &html_escape(outcome))
        .replace("{{EPISODE}}", &json))
}

/// The page: styles, the scene and timeline SVGs (filled by the script), the controls.
const PAGE: &str = r##"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{{TITLE}}</title>
<style>
  body { font-family: sans-serif; margin: 16px 24px; color: #222; max-width: 1400px; }
  h1 { font-size: 20px; margin: 0 0 4px; }
  .sub { color: #555; margin: 0 0 12px; }
  .row { display: flex; flex-wrap: wrap; gap: 16px; align-items: flex-start; }
  .card { border: 1px solid #ccc; border-radius: 6px; padding: 8px 10px; background: #fff; }
  .card h2 { font-size: 14px; margin: 0 0 6px; color: #444; }
  #scene-card { flex: 3 1 640px; }
  #info-card { flex: 1 1 260px; }
  #timeline-card { flex: 1 1 100%; }
  svg { display: block; width: 100%; height: auto; }
  table { border-collapse: collapse; font-size: 14px; }
  td { padding: 2px 8px 2px 0; vertical-align: top; }
  td:first-child { color: #555; }
  .controls { display: flex; gap: 10px; align-items: center; margin: 12px 0; flex-wrap: wrap; }
  .controls input[type=range] { flex: 1 1 400px; }
  button, select { font-size: 14px; padding: 3px 10px; }
  .key { font-size: 13px; color: #333; display: flex; flex-wrap: wrap; gap: 4px 16px; margin-top: 6px; }
  .sw { display: inline-block; width: 14px; height: 10px; margin-right: 5px; vertical-align: middle; border: 1px solid #888; }
  .dot { border-radius: 50%; width: 10px; }
  .bar { display: inline-block; height: 10px; background: #4466cc; vertical-align: middle; }
  .mode-reasoning { color: #c06000; font-weight: bold; }
  .mode-habit { color: #2846e6; font-weight: bold; }
  .violation { color: #d01818; font-weight: bold; }
  .junction-key { display: none; }
  .has-junction .junction-key { display: inline; }
</style>
</head>
<body>
<h1>{{TITLE}}</h1>
<p class="sub">{{OUTCOME}}. Scrub with the slider, play with the button (or space; arrow keys step one tick).</p>
<div class="controls">
  <button id="play" type="button">Play</button>
  <button id="prev" type="button" title="previous tick">&#9664;</button>
  <button id="next" type="button" title="next tick">&#9654;</button>
  <input id="slider" type="range" min="0" max="0" step="0.01" value="0" aria-label="time in decision ticks">
  <label>speed <select id="speed">
    <option value="0.5">0.5&times;</option><option value="1" selected>1&times;</option>
    <option value="2">2&times;</option><option value="4">4&times;</option>
  </select></label>
  <span id="clock"></span>
</div>
<div class="row">
  <div class="card" id="scene-card">
    <h2>The intersection from above</h2>
    <svg id="scene"></svg>
    <div class="key">
      <span><span class="sw" style="background:#2846e6"></span>car acting on its habit (feed-forward)</span>
      <span><span class="sw" style="background:#e68c00"></span>car reasoning on this tick</span>
      <span><span class="sw dot" style="background:#000"></span>pedestrian</span>
      <span><span class="sw dot" style="background:#1db31d"></span><span class="sw dot" style="background:#ffaa00"></span><span class="sw dot" style="background:#e02020"></span>traffic light</span>
      <span><span class="sw" style="background:#f5f5f5"></span>crosswalk</span>
      <span><span class="sw" style="background:#000"></span>destination</span>
      <span><span class="sw" style="background:rgb(174,202,228)"></span>wet road (μ 0.4)</span>
      <span><span class="sw" style="background:rgb(150,200,245)"></span>ice (μ 0.1): road surface tinted by its friction</span>
      <span><span class="sw" style="border:2px solid #d01818"></span>car outlined red: that tick entered the crosswalk on red</span>
      <span class="junction-key"><span class="sw" style="background:#14968c"></span>vehicle</span>
      <span class="junction-key"><span class="sw" style="background:#c81e5a"></span>vehicle in the car's path</span>
      <span class="junction-key"><span class="sw dot" style="background:#464646"></span>head dark (outage)</span>
      <span class="junction-key"><span class="sw" style="background:#fff"></span><span class="sw" style="background:#ff6e00"></span>pedestrian head: walk, don't walk</span>
    </div>
  </div>
  <div class="card" id="info-card">
    <h2>This tick</h2>
    <table id="info"></table>
  </div>
  <div class="card" id="timeline-card">
    <h2>Normalized surprise theta = 1 - exp(-Omega S) and the action of every tick</h2>
    <svg id="timeline"></svg>
    <div class="key">
      <span><span class="sw" style="background:#4466cc;height:3px"></span>theta</span>
      <span><span class="sw" style="background:#e02020;height:2px"></span>threshold epsilon</span>
      <span><span class="sw" style="background:#f5c88a"></span>reasoning tick</span>
      <span><span class="sw" style="background:#8fd18f"></span>speed up</span>
      <span><span class="sw" style="background:#d0d0d0"></span>maintain</span>
      <span><span class="sw" style="background:#f09090"></span>slow down</span>
      <span><span class="sw" style="background:#d01818;height:4px"></span>entered the crosswalk on red</span>
      <span><span class="sw" style="background:#222;width:2px"></span>now</span>
    </div>
  </div>
</div>
<script type="application/json" id="episode">{{EPISODE}}</script>
<script>
"use strict";
const E = JSON.parse(document.getElementById("episode").textContent);
const T = E.ticks, N = T.length, S = E.scene;
const $ = (id) => document.getElementById(id);
// The SVG namespace, from an inline <svg> (the page names no address at all).
const NS = $("scene").namespaceURI;
function el(parent, name, attrs, text) {
  const e = document.createElementNS(NS, name);
  for (const k in attrs) e.setAttribute(k, attrs[k]);
  if (text !== undefined) e.textContent = text;
  parent.appendChild(e);
  return e;
}
const LIGHT = { green: "#1db31d", amber: "#ffaa00", red: "#e02020", walk: "#ffffff", dont_walk: "#ff6e00", dark: "#464646" };
const WALK = { walk: "walk", dont_walk: "don't walk", dark: "dark" };
const ACTION = { "speed up": "#8fd18f", "maintain": "#d0d0d0", "slow down": "#f09090" };

// The scene, in metres: x along the road, y up (SVG y down, so y is negated).
const J = S.junction;
if (J) document.body.classList.add("has-junction");
const half = J ? J.reach : S.road_half + S.sidewalk;
const scene = $("scene");
scene.setAttribute("viewBox", `${S.x0} ${-half} ${S.x1 - S.x0} ${2 * half}`);
// An area [x0, y0, x1, y1] in metres as an SVG rect.
const area = (parent, [x0, y0, x1, y1], attrs) =>
  el(parent, "rect", Object.assign({ x: x0, y: -y1, width: x1 - x0, height: y1 - y0 }, attrs));
el(scene, "rect", { x: S.x0, y: -half, width: S.x1 - S.x0, height: 2 * half, fill: "#bee1b4" });
el(scene, "rect", { x: S.x0, y: -S.road_half, width: S.x1 - S.x0, height: 2 * S.road_half, fill: S.road_colour });
if (J) area(scene, [J.cross_kerbs[0], -half, J.cross_kerbs[1], half], { fill: S.road_colour });
const surface = el(scene, "g", {});
el(scene, "line", { x1: S.x0, x2: S.x1, y1: 0, y2: 0, stroke: "#fff", "stroke-width": 0.15, "stroke-dasharray": "2 2" });
for (let y = -S.road_half; y < S.road_half - 0.01; y += 0.8)
  el(scene, "rect", { x: S.crosswalk_x - S.crosswalk_width / 2, y: y + 0.1, width: S.crosswalk_width, height: 0.5, fill: "#f5f5f5" });
if (J) {
  // The box covers the road's lane line; the cross street's lane lines stop at the road.
  area(scene, J.junction_box, { fill: S.road_colour });
  for (const x of J.cross_lane_lines)
    for (const [y0, y1] of [[-half, J.junction_box[1]], [J.junction_box[3], half]])
      el(scene, "line", { x1: x, x2: x, y1: -y0, y2: -y1, stroke: "#fff", "stroke-width": 0.15, "stroke-dasharray": "2 2" });
  for (const [acrossRoad, [x0, y0, x1, y1]] of J.crosswalks) {
    if (acrossRoad) for (let y = y0; y < y1 - 0.01; y += 0.8) area(scene, [x0, y + 0.1, x1, y + 0.6], { fill: "#f5f5f5" });
    else for (let x = x0; x < x1 - 0.01; x += 0.8) area(scene, [x + 0.1, y0, x + 0.6, y1], { fill: "#f5f5f5" });
  }
  for (const [[ax, ay], [bx, by]] of J.stop_lines)
    el(scene, "line", { x1: ax, y1: -ay, x2: bx, y2: -by, stroke: "#fff", "stroke-width": 0.4, class: "stop-line" });
}
el(scene, "rect", { x: S.goal_x - 0.3, y: -S.road_half, width: 0.3, height: 2 * S.road_half, fill: "#000" });
const light = el(scene, "circle", { cx: S.light_x, cy: S.road_half + S.sidewalk / 2, r: 0.8, stroke: "#333", "stroke-width": 0.1 });
// The other heads: vehicle heads round, pedestrian heads square; filled per tick.
const heads = (J ? J.heads : []).map(([x, y, shows]) => [shows, shows.startsWith("walk")
  ? el(scene, "rect", { x: x - 0.5, y: -y - 0.5, width: 1, height: 1, stroke: "#222", "stroke-width": 0.2, class: "head" })
  : el(scene, "circle", { cx: x, cy: -y, r: 0.8, stroke: "#333", "stroke-width": 0.1, class: "head" })]);
const vehicles = el(scene, "g", {});
const car = el(scene, "rect", { y: -S.car_y - S.car_width / 2, width: S.car_length, height: S.car_width, rx: 0.3 });
const peds = el(scene, "g", {});

// The timeline: theta per tick, epsilon, reasoning shading, the action strip, a cursor.
const tl = $("timeline");
const W = 1000, H = 240, L = 64, R = 12, TOP = 12, PH = 160, AY = TOP + PH + 30, AH = 22;
tl.setAttribute("viewBox", `0 0 ${W} ${H}`);
const span = Math.max(N - 1, 1);
// One cell per tick, the tick at the cell's centre.
const cell = (W - L - R) / N;
const X = (t) => L + cell * (t + 0.5);
const Y = (th) => TOP + PH * (1 - th);
for (let i = 0; i < N; i++) if (T[i].reasoned)
  el(tl, "rect", { x: X(i - 0.5), y: TOP, width: cell, height: PH, fill: "#f5c88a" });
for (const v of [0, 0.2, 0.4, 0.6, 0.8, 1]) {
  el(tl, "line", { x1: L, x2: W - R, y1: Y(v), y2: Y(v), stroke: "#e4e4e4" });
  el(tl, "text", { x: L - 6, y: Y(v) + 4, "text-anchor": "end", "font-size": 11 }, v.toFixed(1));
}
el(tl, "line", { x1: L, x2: W - R, y1: Y(E.epsilon), y2: Y(E.epsilon), stroke: "#e02020", "stroke-width": 1.5, "stroke-dasharray": "6 3" });
const pts = [];
for (let i = 0; i < N; i++) if (T[i].theta !== null) pts.push(`${X(i)},${Y(T[i].theta)}`);
if (pts.length) el(tl, "polyline", { points: pts.join(" "), fill: "none", stroke: "#4466cc", "stroke-width": 2 });
for (let i = 0; i < N; i++) if (T[i].theta !== null) el(tl, "circle", { cx: X(i), cy: Y(T[i].theta), r: 3, fill: "#4466cc" });
if (!pts.length) el(tl, "text", { x: (L + W - R) / 2, y: TOP + PH / 2, "text-anchor": "middle", "font-size": 13, fill: "#666" }, "this method measures no surprise");
const every = Math.ceil(N / 25);
for (let i = 0; i < N; i += every) el(tl, "text", { x: X(i), y: TOP + PH + 16, "text-anchor": "middle", "font-size": 11 }, String(i));
el(tl, "text", { x: L - 6, y: AY + AH / 2 + 4, "text-anchor": "end", "font-size": 11 }, "action");
for (let i = 0; i < N; i++) {
  const a = T[i].action;
  if (a === null) continue;
  const box = el(tl, "rect", { x: X(i - 0.5) + 1, y: AY, width: Math.max(cell - 2, 1), height: AH, fill: ACTION[a], rx: 2 });
  el(box, "title", {}, `tick ${i}: ${a}`);
  if (cell > 22) el(tl, "text", { x: X(i), y: AY + AH / 2 + 4, "text-anchor": "middle", "font-size": 10 }, a === "speed up" ? "up" : a === "slow down" ? "down" : "keep");
  if (T[i].red_light) {
    const mark = el(tl, "rect", { x: X(i - 0.5) + 1, y: AY + AH + 1, width: Math.max(cell - 2, 1), height: 4, fill: "#d01818", class: "red-light" });
    el(mark, "title", {}, `tick ${i}: entered the crosswalk on red`);
  }
}
const cursor = el(tl, "line", { y1: TOP - 4, y2: AY + AH + 4, stroke: "#222", "stroke-width": 2 });
tl.addEventListener("click", (ev) => {
  const r = tl.getBoundingClientRect();
  const x = (ev.clientX - r.left) * W / r.width;
  show(Math.min(Math.max((x - L) / cell - 0.5, 0), span));
});

const fmt = (x, d) => (x === null || x === undefined) ? "–" : x.toFixed(d);
const bars = (p) => p.map((v, k) => `<div title="${E.actions[k]}">${E.actions[k].padEnd(9, "\u00a0")} <span class="bar" style="width:${Math.round(80 * v)}px"></span> ${v.toFixed(2)}</div>`).join("");
function info(i) {
  const t = T[i];
  const mode = t.action === null ? "(end of the episode)"
    : t.reasoned ? '<span class="mode-reasoning">reasoning</span>' : '<span class="mode-habit">feed-forward (habit)</span>';
  const rows = [
    ["tick", `${t.step} of ${N - 1} (t = ${t.time.toFixed(1)} s)`],
    ["action", t.action === null ? "–" : t.action],
    ["mode", mode],
    ["theta", `${fmt(t.theta, 3)} (epsilon ${E.epsilon})`],
    ["surprise", t.surprise_bits === null ? "–" : `${t.surprise_bits.toFixed(2)} bits`],
    ["state", `d ${t.state[0]}, v ${t.state[1]}, L ${t.state[2]}, p ${t.state[3]}`],
    ["car", `x ${t.car_x.toFixed(1)} m, ${t.speed.toFixed(1)} m/s`],
    ["light", `${t.light}, ${t.light_left.toFixed(1)} s left`],
    ["pedestrians", String(t.pedestrians.length)],
    ["vehicles", `${t.vehicles.length} (${t.vehicles.filter((v) => v[5]).length} in the car's path)`],
    ...(J ? [["signals", `road ${t.signals.road}, cross ${t.signals.cross}; pedestrians: ${WALK[t.signals.walk_road]} across the road, ${WALK[t.signals.walk_cross]} across the cross street`]] : []),
    ["reward", t.reward.toFixed(2)],
    ["red light", t.red_light ? '<span class="violation">ran a red light: entered the crosswalk on red this tick</span>' : "–"],
  ];
  if (t.action !== null) rows.push(["policy acted on", bars(t.policy)]);
  if (t.psi) rows.push(["planner psi", bars(t.psi)]);
  $("info").innerHTML = rows.map(([k, v]) => `<tr><td>${k}</td><td>${v}</td></tr>`).join("");
}

let now = 0, shownTick = -1;
function show(t) {
  now = t;
  const i = Math.min(Math.floor(t), N - 1), j = Math.min(i + 1, N - 1), f = t - i;
  const a = T[i], b = T[j];
  const lerp = (p, q) => p + (q - p) * f;
  car.setAttribute("x", lerp(a.car_x, b.car_x) - S.car_length);
  car.setAttribute("fill", a.reasoned ? "#e68c00" : "#2846e6");
  car.setAttribute("stroke", a.red_light ? "#d01818" : "none");
  car.setAttribute("stroke-width", a.red_light ? 0.6 : 0);
  light.setAttribute("fill", LIGHT[a.signals.road]);
  for (const [shows, head] of heads) head.setAttribute("fill", LIGHT[a.signals[shows]]);
  vehicles.replaceChildren();
  const sameVehicles = a.vehicles.length === b.vehicles.length;
  a.vehicles.forEach((v, k) => {
    // Taken to be the same vehicle on the next tick when both ticks have as many.
    const w = sameVehicles ? b.vehicles[k] : v;
    let turn = w[2] - v[2];
    turn -= 2 * Math.PI * Math.round(turn / (2 * Math.PI));
    const [x, y, h] = [lerp(v[0], w[0]), lerp(v[1], w[1]), v[2] + turn * f];
    const [len, wid] = [v[3], v[4]];
    const g = el(vehicles, "g", { transform: `translate(${x} ${-y}) rotate(${-h * 180 / Math.PI})`, class: "vehicle" });
    el(g, "rect", { x: -len / 2, y: -wid / 2, width: len, height: wid, rx: 0.3, fill: v[5] ? "#c81e5a" : "#14968c" });
    el(g, "rect", { x: len / 2 - 0.6, y: -wid / 2, width: 0.6, height: wid, fill: "#fff", "fill-opacity": 0.6 });
  });
  surface.replaceChildren();
  for (const [from, to, mu, colour] of a.surface) {
    const x0 = Math.max(from, S.x0), x1 = Math.min(to, S.x1);
    const patch = el(surface, "rect", { x: x0, y: -S.road_half, width: Math.max(x1 - x0, 0), height: 2 * S.road_half, fill: colour });
    el(patch, "title", {}, `surface μ ${mu}`);
  }
  const same = a.pedestrians.length === b.pedestrians.length;
  peds.replaceChildren();
  a.pedestrians.forEach((p, k) => {
    const q = same ? b.pedestrians[k] : p;
    el(peds, "circle", { cx: lerp(p[0], q[0]), cy: -lerp(p[1], q[1]), r: 0.45, fill: "#000" });
  });
  cursor.setAttribute("x1", X(t));
  cursor.setAttribute("x2", X(t));
  $("slider").value = t;
  $("clock").textContent = `tick ${i} / ${N - 1}`;
  if (i !== shownTick) { info(i); shownTick = i; }
}

let playing = false, last = 0;
function frame(ms) {
  if (!playing) return;
  const dt = last ? (ms - last) / 1000 : 0;
  last = ms;
  const next = now + dt * Number($("speed").value) / E.decision_dt;
  if (next >= N - 1) { show(N - 1); setPlaying(false); return; }
  show(next);
  requestAnimationFrame(frame);
}
function setPlaying(p) {
  playing = p;
  $("play").textContent = p ? "Pause" : "Play";
  if (p) {
    if (now >= N - 1) show(0);
    last = 0;
    requestAnimationFrame(frame);
  }
}
$("slider").max = N - 1;
$("slider").addEventListener("input", (e) => { setPlaying(false); show(Number(e.target.value)); });
$("play").addEventListener("click", () => setPlaying(!playing));
$("prev").addEventListener("click", () => { setPlaying(false); show(Math.max(Math.ceil(now) - 1, 0)); });
$("next").addEventListener("click", () => { setPlaying(false); show(Math.min(Math.floor(now) + 1, N - 1)); });
document.addEventListener("keydown", (e) => {
  if (e.target.tagName === "SELECT") return;
  if (e.key === " ") { e.preventDefault(); setPlaying(!playing); }
  if (e.key === "ArrowLeft") { e.preventDefault(); $("prev").click(); }
  if (e.key === "ArrowRight") { e.preventDefault(); $("next").click(); }
});
// A moment to open at, e.g. replay.html#t=6 (in decision ticks).
const at = /t=([0-9.]+)/.exec(location.hash);
show(at ? Math.min(Number(at[1]), N - 1) : 0);
</script>
</body>
</html>
"##;
