//! The force-driven vehicle model (`dynamics: Forces`, docs/ARCHITECTURE.md §2): what
//! the tyres, the brakes and the air do to the car in one physics sub-step, as one net
//! longitudinal force that the world applies to the car's Rapier body.
//!
//! ```text
//! drive   F_d = min(drive_force, power / v)        (speed up; maintain as needed)
//! brake   F_b: the demand, after `brake_dead_time`, through a first-order lag
//!         F_b ← D + (F_b − D)·exp(−h / brake_lag)
//! tyres   F_x = clamp(F_d − F_b, −μ m g, μ m g)     (μ: mean of the two axles' road)
//! road    F_r = rolling_resistance · m g,  air  F_a = ½ ρ C_d A v²
//! net     F = F_x − F_r − F_a, never reversing the car
//! ```
//!
//! Locking: a brake force above the friction limit locks the wheels, and a locked wheel
//! slides with the road's μ (one coefficient for grip and slide, no anti-lock gain or
//! loss), so the car decelerates at μ g plus rolling resistance and drag. "Maintain" is a
//! cruise controller holding the speed the tick began with, within the drive and brake
//! forces available; `max_speed` is a governor that the drive never pushes past.

use std::collections::VecDeque;

use crate::map::{Dynamics, Vehicle};

/// What the driver asks of the drive train for one sub-step (one of the paper's three
/// actions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Pedal {
    /// Full drive ("speed up").
    Drive,
    /// Full brake demand ("slow down").
    Brake,
    /// Hold this speed, m/s ("maintain"), within the drive and brake forces.
    Cruise(f64),
}

/// Gravitational acceleration, m/s².
pub const GRAVITY: f64 = 9.81;

/// The car's drive train and brakes under `dynamics: Forces`: constants taken from the
/// map once, and the brake actuator's state.
#[derive(Debug, Clone)]
pub(crate) struct Drivetrain {
    mass: f64,
    drive_force: f64,
    power: f64,
    brake_force: f64,
    governor: f64,
    /// Rolling resistance force, N.
    rolling: f64,
    /// ½ ρ C_d A, kg/m.
    drag: f64,
    /// exp(−h / brake_lag): the share of the old brake force kept after a sub-step.
    lag_keep: f64,
    /// Brake demands on their way through the dead time, one per sub-step (oldest first).
    delayed: VecDeque<f64>,
    /// The brake force acting now, N.
    brake: f64,
    h: f64,
}

impl Drivetrain {
    /// The drive train of `v` stepped every `h` seconds, brakes released.
    pub(crate) fn new(v: &Vehicle, air_density: f64, h: f64) -> Drivetrain {
        let lag_keep = if v.brake_lag > 0.0 {
            (-h / v.brake_lag).exp()
        } else {
            0.0
        };
        let dead_steps = (v.brake_dead_time / h).round() as usize;
        Drivetrain {
            mass: v.mass,
            drive_force: v.drive_force,
            power: v.power,
            brake_force: v.brake_force,
            governor: v.max_speed,
            rolling: v.rolling_resistance * v.mass * GRAVITY,
            drag: 0.5 * air_density * v.drag_coefficient * v.frontal_area,
            lag_keep,
            delayed: VecDeque::from(vec![0.0; dead_steps]),
            brake: 0.0,
            h,
        }
    }

    /// The largest drive force at speed `v`: `min(drive_force, power / v)`.
    fn drive_limit(&self, v: f64) -> f64 {
        if v > 0.0 {
            self.drive_force.min(self.power / v)
        } else {
            self.drive_force
        }
    }

    /// Rolling resistance plus drag at speed `v`, N.
    fn resistance(&self, v: f64) -> f64 {
        self.rolling + self.drag * v * v
    }

    /// The net longitudinal force on the car for the coming sub-step, N, with `pedal`
    /// held, `v` the car's speed and `mu` the friction under its wheels; advances the
    /// brake actuator by one sub-step.
    pub(crate) fn force(&mut self, pedal: Pedal, v: f64, mu: f64) -> f64 {
        let (m, h) = (self.mass, self.h);
        let resistance = self.resistance(v);
        let limit = self.drive_limit(v);
        let (drive, demand) = match pedal {
            Pedal::Drive => (limit, 0.0),
            Pedal::Brake => (0.0, self.brake_force),
            Pedal::Cruise(cruise) => {
                let need = m * (cruise - v) / h + resistance;
                if need >= 0.0 {
                    (need.min(limit), 0.0)
                } else {
                    (0.0, (-need).min(self.brake_force))
                }
            }
        };
        let drive = drive.min((m * (self.governor - v) / h + resistance).max(0.0));
        let demand = match self.delayed.pop_front() {
            Some(due) => {
                self.delayed.push_back(demand);
                due
            }
            None => demand,
        };
        self.brake = demand + (self.brake - demand) * self.lag_keep;
        let grip = mu * m * GRAVITY;
        let net = (drive - self.brake).clamp(-grip, grip) - resistance;
        // Brakes, tyres and air hold a car; they never push it backwards.
        net.max(-m * v.max(0.0) / h)
    }
}

/// The distance, m, in which the car stops from `speed` when "slow down" starts now
/// on a road of friction `mu`: under `Ideal` `v² / 2b`; under `Forces` the dead time at
/// `speed`, then the brake's lag phase up to the friction limit, then the
/// friction-limited deceleration (`v₁² / 2 a`), without rolling resistance and drag
/// (which only shorten it).
pub fn stopping_distance(v: &Vehicle, speed: f64, mu: f64) -> f64 {
    match v.dynamics {
        Dynamics::Ideal => speed * speed / (2.0 * v.max_brake),
        Dynamics::Forces => {
            let full = v.brake_force / v.mass;
            let cap = full.min(mu * GRAVITY);
            let tau = v.brake_lag;
            let dead = speed * v.brake_dead_time;
            if tau <= 0.0 {
                return dead + speed * speed / (2.0 * cap);
            }
            // During the lag the deceleration is full·(1 − e^(−t/τ)).
            let lost = |t: f64| full * (t - tau * (1.0 - (-t / tau).exp()));
            let covered = |t: f64| speed * t - full * (t * t / 2.0 - tau * t + tau * tau * (1.0 - (-t / tau).exp()));
            // The lag reaches the friction limit at t1 (never when the brakes cannot lock).
            let t1 = if full > cap {
                -tau * (1.0 - cap / full).ln()
            } else {
                f64::INFINITY
            };
            if t1.is_finite() && lost(t1) < speed {
                let v1 = speed - lost(t1);
                return dead + covered(t1) + v1 * v1 / (2.0 * cap);
            }
            // The car stops within the lag phase: bisect for the time it does.
            let (mut lo, mut hi) = (0.0, speed / full + tau);
            for _ in 0..80 {
                let mid = (lo + hi) / 2.0;
                if lost(mid) < speed { lo = mid } else { hi = mid }
            }
            dead + covered(hi)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn forces() -> Vehicle {
        Vehicle {
            dynamics: Dynamics::Forces,
            ..Vehicle::default()
        }
    }

    /// Worked by hand: 9 m/s, no lag, 7500 N on 1500 kg (5 m/s²) on dry road:
    /// 0.1 s × 9 m/s + 81 / 10 = 0.9 + 8.1 m; on μ = 0.2 the road gives 1.962 m/s²:
    /// 0.9 + 81 / 3.924 = 21.542 m.
    #[test]
    fn stopping_distance_without_lag_is_worked_by_hand() {
        let v = Vehicle {
            brake_lag: 0.0,
            ..forces()
        };
        assert!((stopping_distance(&v, 9.0, 0.8) - 9.0).abs() < 1e-9);
        assert!((stopping_distance(&v, 9.0, 0.2) - 21.542_202).abs() < 1e-5);
    }

    /// The lag adds less than a lag's time constant at full speed (the brake force
    /// reaches most of its demand within τ), and more than nothing.
    #[test]
    fn the_lag_phase_costs_less_than_tau_at_full_speed() {
        let no_lag = stopping_distance(
            &Vehicle {
                brake_lag: 0.0,
                ..forces()
            },
            9.0,
            0.8,
        );
        let lag = stopping_distance(&forces(), 9.0, 0.8);
        assert!(lag > no_lag && lag < no_lag + 9.0 * 0.2, "{no_lag} {lag}");
    }

    #[test]
    fn ideal_stopping_distance_is_the_papers() {
        assert_eq!(stopping_distance(&Vehicle::default(), 9.0, 0.8), 81.0 / 6.0);
    }

    /// A car at rest with no demand feels no force: brakes and rolling resistance hold
    /// it, they do not push it backwards.
    #[test]
    fn a_car_at_rest_stays_at_rest() {
        let mut d = Drivetrain::new(&forces(), 1.2, 1.0 / 60.0);
        for _ in 0..120 {
            assert_eq!(d.force(Pedal::Brake, 0.0, 0.8), 0.0);
        }
    }
}
