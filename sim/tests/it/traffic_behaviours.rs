//! The other vehicles' behaviours for the unforeseen (issue 45): a red-light runner, a
//! car stalled in the box, a lead car braking hard (within the tyres), an oncoming
//! left-turner that does not yield, and entry on a dark signal as at an all-way stop.

use unforeseen_sim::{Action, Aspect, LightPhase, Map, Route, Snapshot, VehicleSnapshot, World};

use crate::common::run;

fn load(text: &str) -> Map {
    Map::from_str_named("b.ron", text, &|_| None).unwrap_or_else(|e| panic!("{e}"))
}

fn snaps(map: &Map, mut policy: impl FnMut(&Snapshot) -> Action) -> (Vec<Snapshot>, bool) {
    let mut world = World::from_map(map, 1);
    let (s, out) = run(&mut world, &mut policy);
    (s, out.collision)
}

fn of(s: &Snapshot, route: Route) -> Option<VehicleSnapshot> {
    s.vehicles.iter().copied().find(|v| v.route == route)
}

/// A red-runner from the south crosses its stop line on its red (the car's green); a
/// careful one beside it stays at its line.
#[test]
fn a_red_runner_enters_on_red() {
    let map = load(
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), vehicle: (start_speed: 0.0), junction: (), traffic: [
            (route: FromSouth, start: 30.0, behaviour: RunsRed), (route: FromNorth, start: 30.0)], episode: (max_steps: 15))",
    );
    let (s, _) = snaps(&map, |_| Action::SlowDown);
    let entered_on_red = s.iter().any(|x| {
        x.signals.cross == Aspect::Lit(LightPhase::Red)
            && of(x, Route::FromSouth).is_some_and(|v| v.past_stop_line > 5.0)
    });
    assert!(entered_on_red);
    let careful = of(s.last().unwrap(), Route::FromNorth).unwrap();
    assert!(
        careful.speed < 1e-3 && careful.past_stop_line.abs() <= 0.5,
        "{careful:?}"
    );
}

/// A stalled car stops dead in the box and stays; the car's lead behind it queues.
#[test]
fn a_stalled_car_stays_in_the_box() {
    let map = load(
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), vehicle: (start_speed: 0.0), junction: (), traffic: [
            (route: Lead, start: 50.0, speed: (6.0, 6.0), behaviour: Stalls(at: 9.0))], episode: (max_steps: 30))",
    );
    let (s, _) = snaps(&map, |_| Action::SlowDown);
    let v = of(s.last().unwrap(), Route::Lead).unwrap();
    // Its front stands past 9 m from the stop line (x = 63), inside the box (x 69..76).
    assert!(v.speed == 0.0 && (9.0..=13.0).contains(&v.past_stop_line), "{v:?}");
    assert!(v.x > 69.0 && v.x < 76.0, "{v:?}");
}

/// A lead car braking hard decelerates as asked, but never beyond the tyres: μ g with
/// the road's μ (0.8 by default: 7.85 m/s²; 0.4 on a wet road: 3.92 m/s²).
#[test]
fn a_hard_stop_is_within_the_tyres() {
    for (mu, decel, want) in [(0.8, 6.0, 6.0), (0.8, 9.0, 0.8 * 9.81), (0.4, 6.0, 0.4 * 9.81)] {
        let map = load(&format!(
            "Map(road: (friction: {mu}), light: (cycle: [(phase: Green, duration: 3600.0)]), vehicle: (start_speed: 0.0), traffic: [
                (route: Lead, start: 20.0, speed: (12.0, 12.0), behaviour: BrakesHard(after: 0.5, decel: {decel}, hold: 60.0))], episode: (max_steps: 6))"
        ));
        let (s, _) = snaps(&map, |_| Action::SlowDown);
        let speeds: Vec<f64> = s.iter().filter_map(|x| of(x, Route::Lead)).map(|v| v.speed).collect();
        // The tick from 1 s to 2 s lies wholly in the hard stop (it starts 0.5 s after
        // appearing at t = 0 and lasts at least 12 / 7.85 = 1.5 s).
        let seen = speeds[0] - speeds[1];
        assert!(
            (seen - want).abs() < 1e-6,
            "μ {mu}, asked {decel}: {seen} m/s² ({speeds:?})"
        );
    }
}

/// The map of an oncoming left-turner meeting the car in the box on its green.
fn left_turner(behaviour: &str) -> Map {
    load(&format!(
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), vehicle: (start_speed: 9.0), junction: (), traffic: [
            (route: OncomingLeft, start: 64.0, speed: (9.0, 9.0), behaviour: {behaviour})])"
    ))
}

/// A careful left-turner waits at the box for the car; one that does not yield turns
/// across its path, and the car driving on hits it.
#[test]
fn a_left_turner_that_does_not_yield_turns_across_the_car() {
    let (s, crash) = snaps(&left_turner("Careful"), |_| Action::SpeedUp);
    assert!(!crash);
    // It slowed for the car and kept out of the box (its turn begins 1 m past its stop
    // line at x = 77) while the car's front was short of the box's far edge (x = 76).
    for x in s.iter().skip(1).filter(|x| x.car_x < 76.0) {
        let v = of(x, Route::OncomingLeft).unwrap_or_else(|| panic!("t = {}", x.time));
        assert!(v.past_stop_line <= 1.05, "t = {}: {v:?}", x.time);
    }
    let slowest = (s.iter().filter_map(|x| of(x, Route::OncomingLeft)))
        .map(|v| v.speed)
        .fold(f64::INFINITY, f64::min);
    assert!(slowest < 6.0, "{slowest}");
    let (_, crash) = snaps(&left_turner("DoesNotYield"), |_| Action::SpeedUp);
    assert!(crash);
    // Braking early, the car lets it turn.
    let (_, crash) = snaps(&left_turner("DoesNotYield"), |x| {
        if x.car_x < 35.0 {
            Action::Maintain
        } else {
            Action::SlowDown
        }
    });
    assert!(!crash);
}

/// On a dark signal a careful vehicle stops at its line (below 0.5 m/s within 1.5 m of
/// it), stands 1 s, and goes.
#[test]
fn on_a_dark_signal_a_careful_vehicle_stops_then_goes() {
    let map = load(
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), vehicle: (start_speed: 0.0), junction: (outages: [(start: AtTime(0.0), duration: 3600.0)]), traffic: [
            (route: FromSouth, start: 30.0)], episode: (max_steps: 20))",
    );
    let (s, _) = snaps(&map, |_| Action::SlowDown);
    let track: Vec<VehicleSnapshot> = s.iter().filter_map(|x| of(x, Route::FromSouth)).collect();
    let stood = track
        .iter()
        .any(|v| v.speed < 0.5 && (-1.5..=0.5).contains(&v.past_stop_line));
    let went = track.iter().any(|v| v.past_stop_line > 10.0);
    assert!(stood && went, "{track:?}");
    assert!(s.iter().skip(1).all(|x| x.signals.dark()));
}

/// The car sees a vehicle in its path: the red-runner once past its stop line in the box,
/// a lead car in its lane, but not oncoming traffic in its own lane.
#[test]
fn a_vehicle_in_the_path_is_an_obstacle() {
    let map = load(
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), vehicle: (start_speed: 0.0), junction: (), traffic: [
            (route: FromSouth, start: 30.0, behaviour: RunsRed), (route: Oncoming, start: 10.0)], episode: (max_steps: 8))",
    );
    let (s, _) = snaps(&map, |_| Action::SlowDown);
    for x in &s {
        let runner = of(x, Route::FromSouth);
        // In the box, or before its line at y = -4.5 too fast to stop at 2 x 2 m/s².
        let in_box = runner.is_some_and(|v| {
            (v.y + v.length / 2.0 > -3.5 && v.y - v.length / 2.0 < 3.5)
                || (v.past_stop_line < 0.0 && v.speed * v.speed > 8.0 * -v.past_stop_line)
        });
        assert_eq!(x.vehicle_in_path, in_box, "t = {}: {runner:?}", x.time);
        assert_eq!(x.obstacle_in_path(), in_box);
    }
    assert!(s.iter().any(|x| x.vehicle_in_path));
    let lead = load(
        "Map(vehicle: (start_speed: 0.0), traffic: [(route: Lead, start: 10.0, speed: (0.1, 0.1))], episode: (max_steps: 3))",
    );
    let (s, _) = snaps(&lead, |_| Action::SlowDown);
    assert!(s.iter().skip(1).all(|x| x.vehicle_in_path));
}

/// A standing car in the car's lane whose rear is before the box's far side blocks the
/// box: it is in the car's path however far ahead, until the car reaches the box.
#[test]
fn a_stalled_car_in_the_box_is_seen_from_afar() {
    let map = load(
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), vehicle: (start_speed: 0.0), junction: (), traffic: [
            (route: Lead, start: 50.0, speed: (6.0, 6.0), behaviour: Stalls(at: 9.0))], episode: (max_steps: 30))",
    );
    let (s, _) = snaps(&map, |_| Action::SlowDown);
    let last = s.last().unwrap();
    let v = of(last, Route::Lead).unwrap();
    // The car stands at x = 0, more than 60 m behind it: beyond the 10 m it would see a
    // moving lead car at, yet the stalled car is in its path.
    assert!(v.speed == 0.0 && v.x - v.length / 2.0 - last.car_x > 60.0, "{v:?}");
    assert!(last.vehicle_in_path);
}

/// A crossing car that cannot stop for its red before its line does not stop in the box:
/// once it has run 0.5 m past its line it clears the junction.
#[test]
fn a_car_that_overruns_its_line_on_red_clears_the_box() {
    // The cross street turns red (the road green) 2.6 s in, with the car from the south
    // 4 m before its line at 10 m/s: too close to stop there even at 9 m/s².
    let map = load(
        "Map(light: (offset: Fixed(0.0), cycle: [(phase: Red, duration: 2.6), (phase: Green, duration: 3600.0)]), vehicle: (start_speed: 0.0),
            junction: (cross: Cycle([(phase: Green, duration: 2.6), (phase: Red, duration: 3600.0)])), traffic: [
            (route: FromSouth, start: 30.0, speed: (10.0, 10.0))], episode: (max_steps: 10))",
    );
    let (s, _) = snaps(&map, |_| Action::SlowDown);
    let track: Vec<VehicleSnapshot> = s.iter().filter_map(|x| of(x, Route::FromSouth)).collect();
    assert!(track.iter().any(|v| v.past_stop_line > 20.0), "{track:?}");
    // Never standing inside the box (y within the road, |y| < 3.5).
    assert!(!track.iter().any(|v| v.speed < 0.05 && v.y.abs() < 3.5), "{track:?}");
}

/// An oncoming car signalling a left turn is in the car's path while it comes on within
/// 30 m of its turn, before it turns; a careful one slowing to a stop for the car is not.
#[test]
fn an_oncoming_left_turner_is_seen_before_it_turns() {
    let (s, _) = snaps(&left_turner("DoesNotYield"), |_| Action::SlowDown);
    let seen_before_turning = s.iter().any(|x| {
        x.vehicle_in_path && of(x, Route::OncomingLeft).is_some_and(|v| v.past_stop_line < 0.0 && v.speed > 1.0)
    });
    assert!(seen_before_turning);
}
