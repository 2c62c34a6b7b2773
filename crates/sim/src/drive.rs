//! The robot's true motion: motors with a first-order lag toward the commanded wheel
//! speeds, integrated exactly.
//!
//! Time is cut into sub-steps of fixed length `h` (1 ms by default). In sub-step `k`
//! the command `c` is constant and each motor's speed follows
//! `ω(t) = c + (ω_k − c)·e^{−(t−t_k)/τ}`. The wheel turns by the exact integral of that
//! speed over the sub-step, and the wheel is modelled as turning at the constant mean
//! speed `ω̄_k = Δφ_k / h` during the sub-step, so that
//! - the wheel angles at sub-step boundaries are the exact integrals of the lagged
//!   speeds (encoders see exactly what the motors did), and
//! - the body moves along an exact circular arc in every sub-step
//!   ([`arc_motion`]), so the pose at any instant, inside a sub-step too, is exact for
//!   this piecewise-constant model with no integration error at all.
//!
//! Wheel slip scales the ground speed of each wheel by a factor (< 1 while slipping)
//! without changing the wheel rotation that the encoders count.

use crate::kinematics::{arc_motion, RobotParams};
use odocal_geom::Pose2;
use serde::{Deserialize, Serialize};

/// Motor model: lag time constant and integration sub-step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MotorConfig {
    /// Time constant τ (s) of the first-order lag toward the commanded wheel speed
    /// (0 = speeds jump to the command).
    pub time_constant: f64,
    /// Length of one sub-step (µs), during which the command and slip are constant.
    pub substep_us: u32,
    /// Lateral slip in turns (s): the body slides sideways, outward of the turn, at
    /// `v_y = −lateral_slip · v · ω` (a skid-steer rover's side slip; 0.05 s gives a
    /// 3° slip angle at 1 rad/s). 0 (the default): the wheels do not slide sideways.
    /// (Left out of the JSON when 0, so configurations written before it read and
    /// write back the same.)
    #[serde(default, skip_serializing_if = "is_zero")]
    pub lateral_slip: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl Default for MotorConfig {
    fn default() -> Self {
        MotorConfig {
            time_constant: 0.15,
            substep_us: 1000,
            lateral_slip: 0.0,
        }
    }
}

/// The robot's true state at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveState {
    /// Time since the start of the simulation (s).
    pub t: f64,
    /// Pose of the robot in the world (m, m, rad).
    pub pose: Pose2,
    /// Cumulative rotation of each wheel `[left, right]` since the start (rad).
    pub wheel_angles: [f64; 2],
    /// Wheel speeds `[left, right]` during the current sub-step (rad/s).
    pub wheel_speeds: [f64; 2],
}

/// Integrates the robot's motion sub-step by sub-step (see the module documentation).
#[derive(Debug, Clone)]
pub struct Drive {
    params: RobotParams,
    motors: MotorConfig,
    /// State at the start of the current sub-step.
    start: DriveState,
    /// Index of the current sub-step.
    step: u64,
    /// Motor speeds at the start of the current sub-step (the lag's state).
    motor_speeds: [f64; 2],
    /// Motor speeds at the end of the current sub-step.
    next_motor_speeds: [f64; 2],
    /// Mean wheel speeds over the current sub-step.
    mean: [f64; 2],
    /// Body velocities `(v, ω)` over the current sub-step (slip included).
    body: (f64, f64),
}

impl Drive {
    /// A robot at rest at `pose` at time 0.
    pub fn new(params: RobotParams, motors: MotorConfig, pose: Pose2) -> Self {
        let start = DriveState {
            t: 0.0,
            pose,
            wheel_angles: [0.0; 2],
            wheel_speeds: [0.0; 2],
        };
        let mut d = Drive {
            params,
            motors,
            start,
            step: 0,
            motor_speeds: [0.0; 2],
            next_motor_speeds: [0.0; 2],
            mean: [0.0; 2],
            body: (0.0, 0.0),
        };
        d.set_command([0.0; 2], [1.0; 2]);
        d
    }

    /// Length of a sub-step (s).
    pub fn substep(&self) -> f64 {
        self.motors.substep_us as f64 * 1e-6
    }

    /// Index of the current sub-step (it starts at `index · substep`).
    pub fn step_index(&self) -> u64 {
        self.step
    }

    /// Start time of the current sub-step in µs.
    pub fn step_start_us(&self) -> u64 {
        self.step * self.motors.substep_us as u64
    }

    /// The state at the start of the current sub-step.
    pub fn current(&self) -> DriveState {
        self.start
    }

    /// Sets the commanded wheel speeds `[ω_L, ω_R]` (rad/s) and the slip factors
    /// `[s_L, s_R]` (1 = no slip) for the current sub-step.
    pub fn set_command(&mut self, command: [f64; 2], slip: [f64; 2]) {
        let h = self.substep();
        let tau = self.motors.time_constant;
        for (i, &c) in command.iter().enumerate() {
            let w0 = self.motor_speeds[i];
            if tau > 0.0 {
                let decay = (-h / tau).exp();
                let increment = c * h + (w0 - c) * tau * (-(-h / tau).exp_m1());
                self.mean[i] = increment / h;
                self.next_motor_speeds[i] = c + (w0 - c) * decay;
            } else {
                self.mean[i] = c;
                self.next_motor_speeds[i] = c;
            }
        }
        self.start.wheel_speeds = self.mean;
        let ground = [self.mean[0] * slip[0], self.mean[1] * slip[1]];
        self.body = self.params.body_velocity(ground);
    }

    /// The exact state at `t_us` (µs since the start), which must lie within the
    /// current sub-step (its end included).
    pub fn state_at_us(&self, t_us: u64) -> DriveState {
        let t0 = self.step_start_us();
        debug_assert!(t_us >= t0 && t_us <= t0 + self.motors.substep_us as u64);
        let dt = (t_us - t0) as f64 * 1e-6;
        self.state_after(dt, t_us as f64 * 1e-6)
    }

    /// The exact state at `t_us` (µs since the start, fractional), which must lie
    /// within the current sub-step (its end included): the time of one ray of a sweep.
    pub fn state_at_fractional_us(&self, t_us: f64) -> DriveState {
        let t0 = self.step_start_us() as f64;
        debug_assert!(t_us >= t0 && t_us <= t0 + self.motors.substep_us as f64);
        self.state_after((t_us - t0) * 1e-6, t_us * 1e-6)
    }

    fn state_after(&self, dt: f64, t: f64) -> DriveState {
        let (v, omega) = self.body;
        let mut motion = arc_motion(v, omega, dt);
        if self.motors.lateral_slip != 0.0 {
            // A constant sideways velocity in the turning body frame adds the same arc
            // turned by 90°.
            let sideways = arc_motion(-self.motors.lateral_slip * v * omega, omega, dt);
            motion.x -= sideways.y;
            motion.y += sideways.x;
        }
        DriveState {
            t,
            pose: self.start.pose.compose(&motion),
            wheel_angles: [
                self.start.wheel_angles[0] + self.mean[0] * dt,
                self.start.wheel_angles[1] + self.mean[1] * dt,
            ],
            wheel_speeds: self.mean,
        }
    }

    /// Moves to the start of the next sub-step, keeping the current command until
    /// [`Drive::set_command`] is called again.
    pub fn finish_step(&mut self) {
        let h = self.substep();
        let next = self.step + 1;
        let t = next as f64 * self.motors.substep_us as f64 * 1e-6;
        self.start = self.state_after(h, t);
        self.step = next;
        self.motor_speeds = self.next_motor_speeds;
    }

    /// The motor speeds (rad/s) reached at the start of the current sub-step.
    pub fn motor_speeds(&self) -> [f64; 2] {
        self.motor_speeds
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(drive: &mut Drive, command: [f64; 2], steps: u64) {
        for _ in 0..steps {
            drive.set_command(command, [1.0; 2]);
            drive.finish_step();
        }
    }

    #[test]
    fn constant_speed_arc_matches_closed_form() {
        let p = RobotParams::khepera_iii();
        let motors = MotorConfig {
            time_constant: 0.0,
            substep_us: 1000,
            lateral_slip: 0.0,
        };
        let start = Pose2::new(0.3, -0.2, 2.5);
        let mut d = Drive::new(p, motors, start);
        let w = p.wheel_speeds(0.08, 0.7);
        run(&mut d, w, 10_000); // 10 s
        let s = d.current();
        let exact = start.compose(&arc_motion(0.08, 0.7, 10.0));
        assert!((s.pose.x - exact.x).abs() < 1e-12, "{} {}", s.pose, exact);
        assert!((s.pose.y - exact.y).abs() < 1e-12);
        assert!(odocal_geom::wrap_angle(s.pose.theta - exact.theta).abs() < 1e-12);
        assert!((s.wheel_angles[0] - 10.0 * w[0]).abs() < 1e-10);
        assert!((s.wheel_angles[1] - 10.0 * w[1]).abs() < 1e-10);
        // Inside a sub-step too.
        d.set_command(w, [1.0; 2]);
        let mid = d.state_at_us(10_000_400);
        let exact = start.compose(&arc_motion(0.08, 0.7, 10.0004));
        assert!((mid.pose.x - exact.x).abs() < 1e-12 && (mid.pose.y - exact.y).abs() < 1e-12);
    }

    #[test]
    fn lateral_slip_slides_outward_of_the_turn() {
        let p = RobotParams::khepera_iii();
        let (v, omega, k) = (0.1, 1.0, 0.05);
        let motors = MotorConfig {
            time_constant: 0.0,
            substep_us: 1000,
            lateral_slip: k,
        };
        let mut d = Drive::new(p, motors, Pose2::IDENTITY);
        let w = p.wheel_speeds(v, omega);
        run(&mut d, w, 3141); // just short of half a turn
        d.set_command(w, [1.0; 2]);
        let half_turn_us = std::f64::consts::PI / omega * 1e6;
        let s = d.state_at_fractional_us(half_turn_us);
        // The velocity (v, −k·v·ω) in the body frame: a circle of radius |V|/ω whose
        // centre is 90° left of a velocity turned right by β = atan(k·ω).
        let speed = v.hypot(k * v * omega);
        let beta = (k * omega).atan();
        let (x, y) = (
            2.0 * speed / omega * beta.sin(),
            2.0 * speed / omega * beta.cos(),
        );
        assert!((s.pose.x - x).abs() < 1e-9, "{} vs ({x}, {y})", s.pose);
        assert!((s.pose.y - y).abs() < 1e-9, "{} vs ({x}, {y})", s.pose);
        assert!(x > 0.009, "outward: {x}");
        // The wheels do not see it.
        assert!((s.wheel_angles[0] - w[0] * half_turn_us * 1e-6).abs() < 1e-9);
    }

    #[test]
    fn wheel_angles_are_exact_integrals_of_the_lag() {
        // From rest, constant command c: φ(t) = c·(t − τ(1 − e^{−t/τ})).
        let p = RobotParams::khepera_iii();
        let tau = 0.15;
        let motors = MotorConfig {
            time_constant: tau,
            substep_us: 1000,
            lateral_slip: 0.0,
        };
        let mut d = Drive::new(p, motors, Pose2::IDENTITY);
        let c = [3.0, -2.0];
        run(&mut d, c, 700);
        let t: f64 = 0.7;
        for (i, ci) in c.iter().enumerate() {
            let exact = ci * (t - tau * (1.0 - (-t / tau).exp()));
            assert!((d.current().wheel_angles[i] - exact).abs() < 1e-12);
        }
    }

    #[test]
    fn lagged_motion_converges_under_refinement() {
        // The 1 ms piecewise-constant model is within 1e-7 m of a 10 µs one over a
        // manoeuvre with large speed changes: the model is a fine discretisation of the
        // continuous lag, and its own integration is exact.
        let p = RobotParams::khepera_iii();
        let simulate = |substep_us: u32| {
            let motors = MotorConfig {
                time_constant: 0.15,
                substep_us,
                lateral_slip: 0.0,
            };
            let mut d = Drive::new(p, motors, Pose2::IDENTITY);
            let per_ms = 1000 / substep_us as u64;
            run(&mut d, p.wheel_speeds(0.1, 0.0), 400 * per_ms);
            run(&mut d, p.wheel_speeds(0.05, 1.0), 600 * per_ms);
            run(&mut d, p.wheel_speeds(0.0, -1.0), 500 * per_ms);
            run(&mut d, [0.0; 2], 500 * per_ms);
            d.current()
        };
        let coarse = simulate(1000);
        let fine = simulate(10);
        assert!((coarse.pose.x - fine.pose.x).abs() < 1e-7);
        assert!((coarse.pose.y - fine.pose.y).abs() < 1e-7);
        assert!((coarse.pose.theta - fine.pose.theta).abs() < 1e-7);
        for i in 0..2 {
            assert!((coarse.wheel_angles[i] - fine.wheel_angles[i]).abs() < 1e-10);
        }
        assert!(coarse.pose.translation_norm() > 0.05);
    }

    #[test]
    fn slip_moves_the_robot_less_but_not_the_wheels() {
        let p = RobotParams::khepera_iii();
        let motors = MotorConfig::default();
        let mut a = Drive::new(p, motors, Pose2::IDENTITY);
        let mut b = Drive::new(p, motors, Pose2::IDENTITY);
        let w = p.wheel_speeds(0.1, 0.0);
        for _ in 0..1000 {
            a.set_command(w, [1.0; 2]);
            a.finish_step();
            b.set_command(w, [0.5, 0.5]);
            b.finish_step();
        }
        assert_eq!(a.current().wheel_angles, b.current().wheel_angles);
        let ratio = b.current().pose.x / a.current().pose.x;
        assert!((ratio - 0.5).abs() < 1e-12);
    }
}
