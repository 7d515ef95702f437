//! What `render()` shows: a top-down frame drawn with tiny-skia (road tinted by its
//! friction with its surface patches, sidewalks, lane line, crosswalk, destination line,
//! the light in its colour, the car, pedestrians), and a one-line text picture of the same.

use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Transform};
use unforeseen_sim::{LightPhase, Map, Snapshot};

/// The road's colour at friction `mu`: the dry asphalt's dark grey at μ 0.8 and above,
/// shading to blue as the road gets slippery (ice, μ ≤ 0.1, the bluest), as the
/// filmstrip tints it (`unforeseen_harness::reports::figures::surface_tint`).
fn asphalt(mu: f64) -> [u8; 3] {
    let slip = ((0.8 - mu) / 0.7).clamp(0.0, 1.0);
    let mix = |dry: f64, slick: f64| (dry + (slick - dry) * slip).round() as u8;
    [mix(70.0, 150.0), mix(70.0, 185.0), mix(75.0, 215.0)]
}

/// Pixels per metre of a frame unless asked otherwise: the default maps' frames are then
/// about 1080x130 pixels, the car 45 pixels long and a pedestrian 12 pixels across.
pub const DEFAULT_SCALE: f32 = 10.0;

/// A frame of `snap` on `map` at `scale` pixels per metre: `(rgb bytes, height, width)`.
/// Both sides are even (video encoders' 4:2:0 chroma needs it).
pub fn frame(map: &Map, snap: &Snapshot, scale: f32) -> (Vec<u8>, usize, usize) {
    let road = &map.road;
    let half = road.half_width() as f32;
    let y_top = half + road.sidewalk_width as f32 + 1.0;
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
    pix.fill(Color::from_rgba8(96, 140, 80, 255));
    let sidewalk = road.sidewalk_width as f32;
    rect(&mut pix, x_lo, half, x_hi, half + sidewalk, [190, 190, 180]);
    rect(&mut pix, x_lo, -half - sidewalk, x_hi, -half, [190, 190, 180]);
    rect(&mut pix, x_lo, -half, x_hi, half, asphalt(road.friction));
    for patch in &snap.surface {
        let (from, to) = ((patch.from as f32).max(x_lo), (patch.to as f32).min(x_hi));
        if from < to {
            rect(&mut pix, from, -half, to, half, asphalt(patch.friction));
        }
    }
    // Lane lines: dashed white between lanes.
    for lane in 1..road.lanes {
        let y = -half + lane as f32 * road.lane_width as f32;
        let mut x = x_lo;
        while x < x_hi {
            rect(&mut pix, x, y - 0.08, (x + 2.0).min(x_hi), y + 0.08, [230, 230, 230]);
            x += 4.0;
        }
    }
    // Crosswalk: zebra stripes across the road.
    let (cx, cw) = (map.crosswalk.x as f32, map.crosswalk.width as f32);
    let mut y = -half;
    while y < half {
        rect(
            &mut pix,
            cx - cw / 2.0,
            y,
            cx + cw / 2.0,
            (y + 0.5).min(half),
            [240, 240, 240],
        );
        y += 1.0;
    }
    // Destination line.
    let gx = road.goal_x as f32;
    rect(&mut pix, gx - 0.15, -half, gx + 0.15, half, [240, 200, 40]);
    // The light, on the near sidewalk before the crosswalk.
    let light = match snap.light {
        LightPhase::Green => [40, 200, 60],
        LightPhase::Amber => [250, 170, 20],
        LightPhase::Red => [220, 30, 30],
    };
    let (lx, ly) = (cx - cw / 2.0 - 1.0, -half - sidewalk / 2.0);
    disc(&mut pix, lx, ly, 0.8, [20, 20, 20]);
    disc(&mut pix, lx, ly, 0.6, light);
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
/// car's front, `=` the crosswalk, `P` a pedestrian on it, `|` the destination), then the
/// figures, e.g. `t=  3 [......C.......=P=..|] x=27.0 m v=9.0 m/s light green 9.0 s, 1 pedestrian`.
pub fn ansi(map: &Map, snap: &Snapshot) -> String {
    const N: usize = 60;
    let x0 = map.vehicle.start_x.min(map.road.goal_x);
    let span = (map.road.goal_x - x0).max(1e-9);
    let cell = |x: f64| (((x - x0) / span) * (N - 1) as f64).round().clamp(0.0, (N - 1) as f64) as usize;
    let mut line = vec!['.'; N];
    let cw = map.crosswalk.width / 2.0;
    line[cell(map.crosswalk.x - cw)..=cell(map.crosswalk.x + cw)].fill('=');
    line[N - 1] = '|';
    for p in &snap.pedestrians {
        if p.on_crosswalk {
            line[cell(p.x)] = 'P';
        }
    }
    line[cell(snap.car_x)] = 'C';
    let n = snap.pedestrians.len();
    format!(
        "t={:>3} [{}] x={:.1} m v={:.1} m/s light {} {:.1} s, {n} pedestrian{}",
        snap.step,
        line.into_iter().collect::<String>(),
        snap.car_x,
        snap.car_speed,
        light_name(snap.light),
        snap.light_time_left,
        if n == 1 { "" } else { "s" }
    )
}
