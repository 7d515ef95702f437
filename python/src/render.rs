//! What `render()` shows: a top-down frame drawn with tiny-skia (road tinted by its
//! friction with its surface patches, sidewalks, lane line, crosswalk, destination line,
//! the light in its colour, the car, pedestrians; on a map with a junction also the cross
//! street with its lanes, sidewalks, crosswalks and stop lines, every signal head, and the
//! other vehicles, as `unforeseen_harness::reports::junction_scene` lays them out), and a
//! one-line text picture of the same.

use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Transform};
use unforeseen_harness::reports::{FRONT_BAND, Lamp, junction_scene, vehicle_quad};
use unforeseen_sim::{LightPhase, Map, Snapshot};

/// The road's colour at friction `mu`: the dry asphalt's dark grey at μ 0.8 and above,
/// shading to blue as the road gets slippery (ice, μ ≤ 0.1, the bluest), as the
/// filmstrip tints it (`unforeseen_harness::reports::figures::surface_tint`).
fn asphalt(mu: f64) -> [u8; 3] {
    let slip = ((0.8 - mu) / 0.7).clamp(0.0, 1.0);
    let mix = |dry: f64, slick: f64| (dry + (slick - dry) * slip).round() as u8;
    [mix(70.0, 150.0), mix(70.0, 185.0), mix(75.0, 215.0)]
}

/// The colour a head shows `lamp` in (a dark head: near black).
fn lamp_rgb(lamp: Lamp) -> [u8; 3] {
    match lamp {
        Lamp::Green => [40, 200, 60],
        Lamp::Amber => [250, 170, 20],
        Lamp::Red => [220, 30, 30],
        Lamp::Walk => [235, 235, 235],
        Lamp::DontWalk => [255, 110, 0],
        Lamp::Dark => [55, 55, 55],
    }
}

/// The other vehicles' colour: teal.
const VEHICLE: [u8; 3] = [20, 150, 140];
/// A vehicle's front band (its windscreen: where it heads).
const VEHICLE_FRONT: [u8; 3] = [150, 235, 225];
/// A vehicle in the car's path (`VehicleSnapshot::in_path`): raspberry.
const VEHICLE_IN_PATH: [u8; 3] = [200, 30, 90];
/// The front band of a vehicle in the car's path.
const VEHICLE_IN_PATH_FRONT: [u8; 3] = [255, 170, 200];
/// Sidewalks.
const SIDEWALK: [u8; 3] = [190, 190, 180];
/// Crosswalk stripes and stop lines.
const MARKING: [u8; 3] = [240, 240, 240];
/// Lane lines.
const LANE_LINE: [u8; 3] = [230, 230, 230];

/// Pixels per metre of a frame unless asked otherwise: the default maps' frames are then
/// about 1080x130 pixels, the car 45 pixels long and a pedestrian 12 pixels across.
pub const DEFAULT_SCALE: f32 = 10.0;

/// A frame of `snap` on `map` at `scale` pixels per metre: `(rgb bytes, height, width)`.
/// Both sides are even (video encoders' 4:2:0 chroma needs it). A map without a junction
/// gives the straight road's frame, `road.sidewalk_width + 1` m either side of it; one
/// with a junction reaches `JunctionScene::reach` across the road, to show the cross
/// street's approaches.
pub fn frame(map: &Map, snap: &Snapshot, scale: f32) -> (Vec<u8>, usize, usize) {
    let road = &map.road;
    let junction = junction_scene(map);
    let half = road.half_width() as f32;
    let y_top = match &junction {
        Some(j) => j.reach as f32,
        None => half + road.sidewalk_width as f32 + 1.0,
    };
    let x_lo = (map.vehicle.start_x - map.vehicle.length).min(road.goal_x) as f32 - 2.0;
    let x_hi = road.goal_x as f32 + map.vehicle.max_speed as f32 * map.episode.decision_dt as f32 + 2.0;
    let even = |v: f32| (v.ceil().max(2.0) as u32).next_multiple_of(2);
    let (width, height) = (even((x_hi - x_lo) * scale), even(2.0 * y_top * scale));
    let Some(mut pix) = Pixmap::new(width, height) else {
        return (Vec::new(), 0, 0);
    };
    // Map (x, y) to pixels: x to the right, y up.
    let px = |x: f32| (x - x_lo) * scale;
    let py = |y: f32| (y_top - y) * scale;
    let rect = |pix: &mut Pixmap, x0: f32, y0: f32, x1: f32, y1: f32, rgb: [u8; 3]| {
        let (l, r) = (px(x0.min(x1)), px(x0.max(x1)));
        let (t, b) = (py(y0.max(y1)), py(y0.min(y1)));
        if let Some(rc) = Rect::from_ltrb(l, t, r.max(l + 1.0), b.max(t + 1.0)) {
            pix.fill_rect(rc, &paint(rgb), Transform::identity(), None);
        }
    };
    let disc = |pix: &mut Pixmap, x: f32, y: f32, r: f32, rgb: [u8; 3]| {
        if let Some(path) = PathBuilder::from_circle(px(x), py(y), (r * scale).max(1.5)) {
            pix.fill_path(&path, &paint(rgb), FillRule::Winding, Transform::identity(), None);
        }
    };
    let quad = |pix: &mut Pixmap, corners: [(f64, f64); 4], rgb: [u8; 3]| {
        let mut pb = PathBuilder::new();
        for (i, (x, y)) in corners.into_iter().enumerate() {
            let (x, y) = (px(x as f32), py(y as f32));
            if i == 0 { pb.move_to(x, y) } else { pb.line_to(x, y) }
        }
        pb.close();
        if let Some(path) = pb.finish() {
            pix.fill_path(&path, &paint(rgb), FillRule::Winding, Transform::identity(), None);
        }
    };
    // Whether the stretch of road from x `a` to `b` overlaps the junction's box (where
    // the road's lane lines stop).
    let box_x = junction
        .as_ref()
        .map(|j| (j.junction_box.x0 as f32, j.junction_box.x1 as f32));
    let in_box = |a: f32, b: f32| box_x.is_some_and(|(x0, x1)| b > x0 && a < x1);
    pix.fill(Color::from_rgba8(96, 140, 80, 255));
    let sidewalk = road.sidewalk_width as f32;
    rect(&mut pix, x_lo, half, x_hi, half + sidewalk, SIDEWALK);
    rect(&mut pix, x_lo, -half - sidewalk, x_hi, -half, SIDEWALK);
    if let Some(j) = &junction {
        let (k0, k1) = (j.cross_kerbs.0 as f32, j.cross_kerbs.1 as f32);
        let sw = j.cross_sidewalk as f32;
        rect(&mut pix, k0 - sw, -y_top, k0, y_top, SIDEWALK);
        rect(&mut pix, k1, -y_top, k1 + sw, y_top, SIDEWALK);
    }
    rect(&mut pix, x_lo, -half, x_hi, half, asphalt(road.friction));
    if let Some(j) = &junction {
        let (k0, k1) = (j.cross_kerbs.0 as f32, j.cross_kerbs.1 as f32);
        rect(&mut pix, k0, -y_top, k1, y_top, asphalt(road.friction));
    }
    for patch in &snap.surface {
        let (from, to) = ((patch.from as f32).max(x_lo), (patch.to as f32).min(x_hi));
        if from < to {
            rect(&mut pix, from, -half, to, half, asphalt(patch.friction));
        }
    }
    // Lane lines: dashed white between lanes (not across the box).
    for lane in 1..road.lanes {
        let y = -half + lane as f32 * road.lane_width as f32;
        let mut x = x_lo;
        while x < x_hi {
            let end = (x + 2.0).min(x_hi);
            if !in_box(x, end) {
                rect(&mut pix, x, y - 0.08, end, y + 0.08, LANE_LINE);
            }
            x += 4.0;
        }
    }
    if let Some(j) = &junction {
        for &lx in &j.cross_lane_lines {
            let lx = lx as f32;
            for side in [-1.0f32, 1.0] {
                let mut y = half;
                while y < y_top {
                    let end = (y + 2.0).min(y_top);
                    rect(&mut pix, lx - 0.08, side * y, lx + 0.08, side * end, LANE_LINE);
                    y += 4.0;
                }
            }
        }
    }
    // Crosswalk: zebra stripes across the road.
    let (cx, cw) = (map.crosswalk.x as f32, map.crosswalk.width as f32);
    let mut y = -half;
    while y < half {
        rect(&mut pix, cx - cw / 2.0, y, cx + cw / 2.0, (y + 0.5).min(half), MARKING);
        y += 1.0;
    }
    if let Some(j) = &junction {
        // The other arms' crosswalks: stripes along the street each crosses.
        for (arm, r) in &j.crosswalks {
            let (x0, x1, y0, y1) = (r.x0 as f32, r.x1 as f32, r.y0 as f32, r.y1 as f32);
            if arm.on_road() {
                let mut y = y0;
                while y < y1 {
                    rect(&mut pix, x0, y, x1, (y + 0.5).min(y1), MARKING);
                    y += 1.0;
                }
            } else {
                let mut x = x0;
                while x < x1 {
                    rect(&mut pix, x, y0, (x + 0.5).min(x1), y1, MARKING);
                    x += 1.0;
                }
            }
        }
        for [(ax, ay), (bx, by)] in &j.stop_lines {
            let (ax, ay, bx, by) = (*ax as f32, *ay as f32, *bx as f32, *by as f32);
            if ax == bx {
                rect(&mut pix, ax - 0.2, ay, ax + 0.2, by, MARKING);
            } else {
                rect(&mut pix, ax, ay - 0.2, bx, ay + 0.2, MARKING);
            }
        }
    }
    // Destination line.
    let gx = road.goal_x as f32;
    rect(&mut pix, gx - 0.15, -half, gx + 0.15, half, [240, 200, 40]);
    // The car's light, on the near sidewalk before the crosswalk (its head: dark in an
    // outage; without a junction always the light the car reads).
    let (lx, ly) = (cx - cw / 2.0 - 1.0, -half - sidewalk / 2.0);
    disc(&mut pix, lx, ly, 0.8, [20, 20, 20]);
    disc(&mut pix, lx, ly, 0.6, lamp_rgb(Lamp::of_aspect(snap.signals.road)));
    // The other heads: vehicle heads round, pedestrian heads square.
    for h in junction.iter().flat_map(|j| &j.heads) {
        let (x, y, rgb) = (h.x as f32, h.y as f32, lamp_rgb(h.lamp(&snap.signals)));
        if h.pedestrian() {
            rect(&mut pix, x - 0.55, y - 0.55, x + 0.55, y + 0.55, [20, 20, 20]);
            rect(&mut pix, x - 0.4, y - 0.4, x + 0.4, y + 0.4, rgb);
        } else {
            disc(&mut pix, x, y, 0.8, [20, 20, 20]);
            disc(&mut pix, x, y, 0.6, rgb);
        }
    }
    // The other vehicles, oriented, their front band lighter.
    for v in &snap.vehicles {
        let (body, front) = if v.in_path {
            (VEHICLE_IN_PATH, VEHICLE_IN_PATH_FRONT)
        } else {
            (VEHICLE, VEHICLE_FRONT)
        };
        quad(&mut pix, vehicle_quad(v, 0.0, v.length), body);
        quad(&mut pix, vehicle_quad(v, v.length - FRONT_BAND, v.length), front);
    }
    // The car: front bumper at car_x, in its lane.
    let v = &map.vehicle;
    let (front, lane_y) = (snap.car_x as f32, map.road.car_lane_y() as f32);
    let (len, w) = (v.length as f32, v.width as f32);
    rect(
        &mut pix,
        front - len,
        lane_y - w / 2.0,
        front,
        lane_y + w / 2.0,
        [40, 90, 220],
    );
    rect(
        &mut pix,
        front - 0.6,
        lane_y - w / 2.0,
        front,
        lane_y + w / 2.0,
        [150, 190, 255],
    );
    // Pedestrians: a dark ring around a bright disc, larger than life (0.6 m) so that
    // one reads at the default scale; orange on the crosswalk, magenta elsewhere.
    for p in &snap.pedestrians {
        let rgb = if p.on_crosswalk { [250, 120, 20] } else { [230, 60, 160] };
        disc(&mut pix, p.x as f32, p.y as f32, 0.6, [20, 20, 20]);
        disc(&mut pix, p.x as f32, p.y as f32, 0.45, rgb);
    }
    let rgb = pix
        .data()
        .chunks_exact(4)
        .flat_map(|px| [px[0], px[1], px[2]])
        .collect();
    (rgb, height as usize, width as usize)
}

fn paint(rgb: [u8; 3]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
    p.anti_alias = true;
    p
}

/// The light's name, as in infos.
pub fn light_name(light: LightPhase) -> &'static str {
    match light {
        LightPhase::Green => "green",
        LightPhase::Amber => "amber",
        LightPhase::Red => "red",
    }
}

/// One line: the road from the car's start to the destination in 60 characters (`C` the
/// car's front, `=` the crosswalk, `P` a pedestrian on it, `|` the destination; on a map
/// with a junction `+` its box, and on one with traffic `V` a vehicle on the road), then
/// the figures, e.g. `t=  3 [......C.......=P=..|] x=27.0 m v=9.0 m/s light green 9.0 s,
/// 1 pedestrian`; a map with a junction or traffic adds the cross street's head and the
/// vehicles, e.g. `, cross red, 2 vehicles (1 in path)` (`signals dark` in an outage).
pub fn ansi(map: &Map, snap: &Snapshot) -> String {
    const N: usize = 60;
    let x0 = map.vehicle.start_x.min(map.road.goal_x);
    let span = (map.road.goal_x - x0).max(1e-9);
    let cell = |x: f64| (((x - x0) / span) * (N - 1) as f64).round().clamp(0.0, (N - 1) as f64) as usize;
    let mut line = vec!['.'; N];
    let junction = junction_scene(map);
    if let Some(j) = &junction {
        line[cell(j.junction_box.x0)..=cell(j.junction_box.x1)].fill('+');
    }
    let cw = map.crosswalk.width / 2.0;
    line[cell(map.crosswalk.x - cw)..=cell(map.crosswalk.x + cw)].fill('=');
    line[N - 1] = '|';
    for p in &snap.pedestrians {
        if p.on_crosswalk {
            line[cell(p.x)] = 'P';
        }
    }
    let half = map.road.half_width();
    for v in &snap.vehicles {
        if v.y.abs() <= half && (x0..=map.road.goal_x).contains(&v.x) {
            line[cell(v.x)] = 'V';
        }
    }
    line[cell(snap.car_x)] = 'C';
    let n = snap.pedestrians.len();
    let mut text = format!(
        "t={:>3} [{}] x={:.1} m v={:.1} m/s light {} {:.1} s, {n} pedestrian{}",
        snap.step,
        line.into_iter().collect::<String>(),
        snap.car_x,
        snap.car_speed,
        light_name(snap.light),
        snap.light_time_left,
        if n == 1 { "" } else { "s" }
    );
    if junction.is_some() || !map.traffic.is_empty() {
        if snap.signals.dark() {
            text.push_str(", signals dark");
        } else if junction.is_some() {
            text.push_str(&format!(", cross {}", Lamp::of_aspect(snap.signals.cross).name()));
        }
        let (k, seen) = (snap.vehicles.len(), snap.vehicles.iter().filter(|v| v.in_path).count());
        text.push_str(&format!(
            ", {k} vehicle{} ({seen} in path)",
            if k == 1 { "" } else { "s" }
        ));
    }
    text
}
