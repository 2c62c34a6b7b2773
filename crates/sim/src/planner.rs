//! Trajectory generation: a planner that, from the true pose, commands wheel speeds.
//!
//! - [`TrajectoryKind::Mixed`]: random waypoints reached by straight runs (spin to
//!   face, then drive), by arcs (pure pursuit along the circle through the waypoint),
//!   plus spins in place and pauses. Every path is checked against the world first, so
//!   the robot keeps at least [`MotionLimits::clearance`] from the walls.
//! - [`TrajectoryKind::StraightOnly`]: back and forth along one straight line.
//! - [`TrajectoryKind::SpinOnly`]: rotations in place only.
//! - [`TrajectoryKind::IdenticalTurns`]: driving (forward and backward, at varying
//!   speeds) along one circle, so every motion has the same curvature.
//! - [`TrajectoryKind::NoSpins`]: like a person driving the robot around with a
//!   joystick: straight runs and arcs of varied curvature (radius at least
//!   [`MotionLimits::turn_radius`]) and speed, mostly forward, a few short pauses,
//!   never a spin in place. Each run is checked against the world first; a robot facing a wall
//!   backs out along an arc.
//!
//! The degenerate kinds command wheel speeds in a fixed ratio; since both motors have
//! the same lag, the ratio holds at every instant and the motion really is degenerate.

use crate::error::SimError;
use crate::kinematics::{arc_motion, RobotParams};
use crate::world::World;
use odocal_geom::{sin_over_x, wrap_angle, Pose2};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Which kind of motion the robot performs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrajectoryKind {
    /// Straight runs, arcs, spins and pauses toward random waypoints.
    Mixed,
    /// Back and forth on one straight line (excites neither b nor the radii' ratio).
    StraightOnly,
    /// Rotation in place only (no translation).
    SpinOnly,
    /// Always the same curvature (one circle).
    IdenticalTurns,
    /// Straights and arcs of varied curvature and speed, no spins in place (a
    /// joystick drive).
    NoSpins,
}

/// Names accepted by [`TrajectoryKind::from_name`].
pub const TRAJECTORY_NAMES: [&str; 5] = [
    "mixed",
    "straight-only",
    "spin-only",
    "identical-turns",
    "no-spins",
];

impl TrajectoryKind {
    /// The kind named `mixed`, `straight-only`, `spin-only`, `identical-turns` or
    /// `no-spins`.
    pub fn from_name(name: &str) -> Result<Self, SimError> {
        match name {
            "mixed" => Ok(TrajectoryKind::Mixed),
            "straight-only" | "straight" => Ok(TrajectoryKind::StraightOnly),
            "spin-only" | "spin" => Ok(TrajectoryKind::SpinOnly),
            "identical-turns" => Ok(TrajectoryKind::IdenticalTurns),
            "no-spins" => Ok(TrajectoryKind::NoSpins),
            _ => Err(SimError::UnknownName {
                what: "trajectory",
                name: name.to_string(),
                known: TRAJECTORY_NAMES.join(", "),
            }),
        }
    }

    /// The kind's name as accepted by [`TrajectoryKind::from_name`].
    pub fn name(&self) -> &'static str {
        match self {
            TrajectoryKind::Mixed => "mixed",
            TrajectoryKind::StraightOnly => "straight-only",
            TrajectoryKind::SpinOnly => "spin-only",
            TrajectoryKind::IdenticalTurns => "identical-turns",
            TrajectoryKind::NoSpins => "no-spins",
        }
    }
}

/// Speed limits and safety margins of the planner.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MotionLimits {
    /// Largest forward speed (m/s).
    pub max_speed: f64,
    /// Largest turn rate (rad/s).
    pub max_turn_rate: f64,
    /// Smallest distance (m) the planned paths keep from any wall.
    pub clearance: f64,
    /// Radius (m) of the circle driven by [`TrajectoryKind::IdenticalTurns`], and
    /// the smallest turning radius of [`TrajectoryKind::NoSpins`].
    pub turn_radius: f64,
}

impl Default for MotionLimits {
    /// Khepera-like: 0.1 m/s, 1 rad/s, 0.3 m from walls, 0.35 m turning circle.
    fn default() -> Self {
        MotionLimits {
            max_speed: 0.1,
            max_turn_rate: 1.0,
            clearance: 0.3,
            turn_radius: 0.35,
        }
    }
}

impl MotionLimits {
    /// Checks that the limits are positive and finite.
    pub fn validate(&self) -> Result<(), SimError> {
        for (field, v) in [
            ("motion.max_speed", self.max_speed),
            ("motion.max_turn_rate", self.max_turn_rate),
            ("motion.clearance", self.clearance),
            ("motion.turn_radius", self.turn_radius),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(SimError::InvalidConfig {
                    field,
                    value: v.to_string(),
                    expected: "a positive finite number",
                });
            }
        }
        Ok(())
    }
}

/// One manoeuvre of the plan.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Maneuver {
    /// Stand still until the given time (s).
    Pause { until: f64 },
    /// Rotate in place to a world heading at up to `rate` rad/s.
    Spin { target: f64, rate: f64 },
    /// Pure pursuit to a point at up to `speed` m/s.
    /// Stops early if the clearance falls below `floor` (m).
    Pursue {
        goal: [f64; 2],
        speed: f64,
        floor: f64,
    },
    /// Drive at constant body velocity `(v, v·curvature)` until the given time.
    /// Stops early if the clearance falls below `floor` (m).
    Cruise {
        v: f64,
        curvature: f64,
        until: f64,
        floor: f64,
    },
    /// Drive straight (forward or backward) until the position along the fixed line
    /// reaches `target` (m).
    Straight { target: f64, speed: f64 },
}

/// How close (rad) a spin has to get to its target heading.
const SPIN_TOLERANCE: f64 = 0.01;
/// How close (m) pure pursuit has to get to its goal.
const GOAL_TOLERANCE: f64 = 0.02;
/// How long (s) the no-spins drive stands still before changing direction.
const REVERSING_PAUSE: f64 = 1.0;
/// Longest time (s) a manoeuvre may take before it is abandoned and re-planned.
const MANEUVER_TIMEOUT: f64 = 40.0;

/// Chooses wheel-speed commands from the true pose (see the module documentation).
#[derive(Debug, Clone)]
pub struct Planner {
    kind: TrajectoryKind,
    limits: MotionLimits,
    robot: RobotParams,
    rng: ChaCha8Rng,
    queue: VecDeque<Maneuver>,
    started: f64,
    /// For straight-only: the line's origin, unit direction and free length (m).
    line: Option<([f64; 2], [f64; 2], f64)>,
    /// For identical turns: the signed curvature of the circle (1/m).
    circle_curvature: f64,
    /// Where the mixed trajectory has been planning from.
    visits: VisitGrid,
    /// For no-spins: whether the last run went backward.
    backing: bool,
}

/// Counts of planning positions per 0.5 m cell.
#[derive(Debug, Clone, Default)]
struct VisitGrid {
    counts: std::collections::HashMap<(i64, i64), u32>,
}

impl VisitGrid {
    const CELL: f64 = 0.5;

    fn key(p: [f64; 2]) -> (i64, i64) {
        (
            (p[0] / Self::CELL).floor() as i64,
            (p[1] / Self::CELL).floor() as i64,
        )
    }

    fn record(&mut self, p: [f64; 2]) {
        *self.counts.entry(Self::key(p)).or_insert(0) += 1;
    }

    fn count(&self, p: [f64; 2]) -> u32 {
        self.counts.get(&Self::key(p)).copied().unwrap_or(0)
    }
}

impl Planner {
    /// Chooses a start pose in `world` for this kind of trajectory and returns the
    /// planner with it. `robot` converts body velocities to wheel speeds.
    pub fn new(
        kind: TrajectoryKind,
        limits: MotionLimits,
        robot: RobotParams,
        world: &World,
        home: [f64; 2],
        mut rng: ChaCha8Rng,
    ) -> Result<(Self, Pose2), SimError> {
        let mut line = None;
        let mut circle_curvature = 1.0 / limits.turn_radius;
        let start = match kind {
            TrajectoryKind::Mixed | TrajectoryKind::SpinOnly | TrajectoryKind::NoSpins => {
                let p = free_point(world, home, limits.clearance + 0.1, &mut rng)?;
                Pose2::new(
                    p[0],
                    p[1],
                    rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
                )
            }
            TrajectoryKind::StraightOnly => {
                let (pose, length) = straight_line(world, home, limits.clearance, &mut rng)?;
                let (s, c) = pose.theta.sin_cos();
                line = Some(([pose.x, pose.y], [c, s], length));
                pose
            }
            TrajectoryKind::IdenticalTurns => {
                let (pose, curvature) = circle_start(world, home, &limits, &mut rng)?;
                circle_curvature = curvature;
                pose
            }
        };
        let planner = Planner {
            kind,
            limits,
            robot,
            rng,
            queue: VecDeque::new(),
            started: 0.0,
            line,
            circle_curvature,
            visits: VisitGrid::default(),
            backing: false,
        };
        Ok((planner, start))
    }

    /// The wheel-speed command `[ω_L, ω_R]` (rad/s) at time `t` (s) for the robot at
    /// `pose`.
    pub fn command(&mut self, t: f64, pose: &Pose2, world: &World) -> [f64; 2] {
        for _ in 0..8 {
            if self.queue.is_empty() {
                self.plan(t, pose, world);
                self.started = t;
            }
            let Some(m) = self.queue.front().copied() else {
                break;
            };
            if t - self.started > MANEUVER_TIMEOUT {
                self.queue.clear();
                continue;
            }
            match self.follow(m, t, pose, world) {
                Some(w) => return w,
                None => {
                    self.queue.pop_front();
                    self.started = t;
                }
            }
        }
        [0.0; 2]
    }

    /// Wheel speeds for manoeuvre `m`, or `None` when it is complete.
    fn follow(&self, m: Maneuver, t: f64, pose: &Pose2, world: &World) -> Option<[f64; 2]> {
        let lim = &self.limits;
        match m {
            Maneuver::Pause { until } => (t < until).then_some([0.0; 2]),
            Maneuver::Spin { target, rate } => {
                let e = wrap_angle(target - pose.theta);
                if e.abs() < SPIN_TOLERANCE {
                    return None;
                }
                let omega = e.signum() * rate.min(2.5 * e.abs() + 0.05);
                Some(self.robot.wheel_speeds(0.0, omega))
            }
            Maneuver::Pursue { goal, speed, floor } => {
                let g = pose.inverse().transform_point(goal);
                let d2 = g[0] * g[0] + g[1] * g[1];
                let d = d2.sqrt();
                if d < GOAL_TOLERANCE || g[0] <= 0.0 {
                    return None;
                }
                // Emergency stop: a wall closer than planned.
                if world.clearance([pose.x, pose.y]) < floor {
                    return None;
                }
                let curvature = 2.0 * g[1] / d2;
                let mut v = speed.min(0.8 * d + 0.01);
                if curvature.abs() * v > lim.max_turn_rate {
                    v = lim.max_turn_rate / curvature.abs();
                }
                Some(self.robot.wheel_speeds(v, v * curvature))
            }
            Maneuver::Cruise {
                v,
                curvature,
                until,
                floor,
            } => (t < until && world.clearance([pose.x, pose.y]) >= floor)
                .then(|| self.robot.wheel_speeds(v, v * curvature)),
            Maneuver::Straight { target, speed } => {
                let (origin, dir, _) = self.line?;
                let along = (pose.x - origin[0]) * dir[0] + (pose.y - origin[1]) * dir[1];
                let e = target - along;
                if e.abs() < 0.005 {
                    return None;
                }
                let v = e.signum() * speed.min(0.8 * e.abs() + 0.005);
                Some(self.robot.wheel_speeds(v, 0.0))
            }
        }
    }

    /// Appends the next manoeuvres to the (empty) queue.
    fn plan(&mut self, t: f64, pose: &Pose2, world: &World) {
        let lim = self.limits;
        let pause = |rng: &mut ChaCha8Rng, lo: f64, hi: f64| Maneuver::Pause {
            until: t + rng.random_range(lo..hi),
        };
        match self.kind {
            TrajectoryKind::Mixed => self.plan_mixed(t, pose, world),
            TrajectoryKind::NoSpins => self.plan_no_spins(t, pose, world),
            TrajectoryKind::SpinOnly => {
                let angle = self.rng.random_range(0.3..3.5) * random_sign(&mut self.rng);
                let rate = self.rng.random_range(0.3..=lim.max_turn_rate);
                self.queue.push_back(Maneuver::Spin {
                    target: wrap_angle(pose.theta + angle),
                    rate,
                });
                let p = pause(&mut self.rng, 0.1, 0.8);
                self.queue.push_back(p);
            }
            TrajectoryKind::StraightOnly => {
                let length = self.line.map(|l| l.2).unwrap_or(0.0);
                let target = self.rng.random_range(0.0..=length);
                let speed = self.rng.random_range(0.03..=lim.max_speed);
                self.queue.push_back(Maneuver::Straight { target, speed });
                let p = pause(&mut self.rng, 0.1, 0.8);
                self.queue.push_back(p);
            }
            TrajectoryKind::IdenticalTurns => {
                // The circle's curvature is fixed by the start (its sign by the seed):
                // keep driving on it, forward mostly, sometimes backward.
                let curvature = self.circle_curvature;
                let speed_limit = lim.max_speed.min(lim.max_turn_rate / curvature.abs());
                let v = self.rng.random_range(0.3 * speed_limit..=speed_limit);
                let v = if self.rng.random_bool(0.2) { -v } else { v };
                let until = t + self.rng.random_range(1.0..6.0);
                self.queue.push_back(Maneuver::Cruise {
                    v,
                    curvature,
                    until,
                    floor: 0.0,
                });
                let p = pause(&mut self.rng, 0.1, 0.8);
                self.queue.push_back(p);
            }
        }
    }

    fn plan_mixed(&mut self, t: f64, pose: &Pose2, world: &World) {
        let lim = self.limits;
        let here = [pose.x, pose.y];
        let roll: f64 = self.rng.random();
        if roll < 0.12 {
            let until = t + self.rng.random_range(0.2..1.2);
            self.queue.push_back(Maneuver::Pause { until });
            return;
        }
        if roll < 0.27 {
            let angle = self.rng.random_range(0.5..3.0) * random_sign(&mut self.rng);
            let rate = self.rng.random_range(0.3..=lim.max_turn_rate);
            self.queue.push_back(Maneuver::Spin {
                target: wrap_angle(pose.theta + angle),
                rate,
            });
            return;
        }
        let speed = self.rng.random_range(0.03..=lim.max_speed);
        let want_arc = self.rng.random_bool(0.6);
        // Relax the clearance if the robot is closer than planned (after slip, say).
        let needed = lim.clearance.min(world.clearance(here) - 0.01).max(0.05);
        let floor = 0.66 * needed;
        // Among a few reachable goals, head for the least visited place (exploration).
        self.visits.record(here);
        let mut best: Option<(u32, [f64; 2], bool, f64)> = None;
        let mut found = 0;
        for _ in 0..300 {
            let r = self.rng.random_range(0.3..2.5);
            let a = self
                .rng
                .random_range(-std::f64::consts::PI..std::f64::consts::PI);
            let goal = [here[0] + r * a.cos(), here[1] + r * a.sin()];
            if world.clearance(goal) < needed {
                continue;
            }
            let local = pose.inverse().transform_point(goal);
            let bearing = local[1].atan2(local[0]);
            let arc_ok =
                want_arc && bearing.abs() < 1.2 && arc_clearance(world, pose, local) >= needed;
            let line_ok = !want_arc && world.path_clearance(here, goal) >= needed;
            if !(arc_ok || line_ok) {
                continue;
            }
            let visits = self.visits.count(goal);
            if best.is_none_or(|b| visits < b.0) {
                best = Some((visits, goal, arc_ok, bearing));
            }
            found += 1;
            if found == 6 {
                break;
            }
        }
        if let Some((_, goal, arc, bearing)) = best {
            if !arc {
                let rate = self.rng.random_range(0.3..=lim.max_turn_rate);
                self.queue.push_back(Maneuver::Spin {
                    target: wrap_angle(pose.theta + bearing),
                    rate,
                });
            }
            self.queue
                .push_back(Maneuver::Pursue { goal, speed, floor });
            return;
        }
        // Nothing reachable this way: turn around and try again.
        self.queue.push_back(Maneuver::Spin {
            target: wrap_angle(pose.theta + self.rng.random_range(1.0..3.0)),
            rate: 0.5 * lim.max_turn_rate,
        });
    }
}

impl Planner {
    /// One run of the joystick drive ([`TrajectoryKind::NoSpins`]): among a few runs
    /// (straight or arc, forward or now and then backward) that keep the clearance,
    /// the one ending in the least visited place; backward runs too when no forward
    /// one is free; the freest run tried when none keeps the full clearance.
    fn plan_no_spins(&mut self, t: f64, pose: &Pose2, world: &World) {
        let lim = self.limits;
        let here = [pose.x, pose.y];
        if self.rng.random_bool(0.06) {
            let until = t + self.rng.random_range(0.3..1.5);
            self.queue.push_back(Maneuver::Pause { until });
            return;
        }
        let needed = lim.clearance.min(world.clearance(here) - 0.01).max(0.05);
        let floor = 0.66 * needed;
        self.visits.record(here);
        let max_curvature = 1.0 / lim.turn_radius;
        // Runs as (v, curvature, until).
        let mut best: Option<(u32, (f64, f64, f64))> = None;
        let mut freest: Option<(f64, (f64, f64, f64))> = None;
        let mut found = 0;
        for attempt in 0..400 {
            let backward = attempt >= 200 || self.rng.random_bool(0.08);
            let curvature = if self.rng.random_bool(0.3) {
                0.0
            } else {
                self.rng.random_range(0.05..=max_curvature) * random_sign(&mut self.rng)
            };
            let speed = self
                .rng
                .random_range(0.15 * lim.max_speed..=lim.max_speed)
                .min(lim.max_turn_rate / curvature.abs().max(1e-9));
            let duration = self.rng.random_range(1.0..4.0);
            let v = if backward { -speed } else { speed };
            // Checked half a second further: the motors' lag carries the robot on.
            let clearance = path_clearance_along(world, pose, v * (duration + 0.5), curvature);
            let run = (v, curvature, t + duration);
            if freest.is_none_or(|f| clearance > f.0) {
                freest = Some((clearance, run));
            }
            if clearance < needed {
                continue;
            }
            let end = pose.compose(&arc_motion(v * duration, v * duration * curvature, 1.0));
            let visits = self.visits.count([end.x, end.y]);
            if best.is_none_or(|b| visits < b.0) {
                best = Some((visits, run));
            }
            found += 1;
            if found == 6 {
                break;
            }
        }
        let cruise = |(v, curvature, until): (f64, f64, f64), floor: f64| Maneuver::Cruise {
            v,
            curvature,
            until,
            floor,
        };
        let (run, floor) = match (best, freest) {
            (Some((_, run)), _) => (run, floor),
            (None, Some((clearance, run))) if clearance > 0.05 => (run, 0.0),
            _ => {
                self.queue.push_back(Maneuver::Pause { until: t + 0.5 });
                return;
            }
        };
        let (v, curvature, until) = run;
        if (v < 0.0) != self.backing {
            // Stop before changing direction, as a driver does: both wheels slow down
            // together, so the robot never pivots on the way through zero speed.
            self.queue.push_back(Maneuver::Pause {
                until: t + REVERSING_PAUSE,
            });
            self.backing = v < 0.0;
            self.queue
                .push_back(cruise((v, curvature, until + REVERSING_PAUSE), floor));
        } else {
            self.queue.push_back(cruise(run, floor));
        }
    }
}

/// The smallest clearance along the circular arc, tangent to the robot's heading,
/// from the robot to the goal at `local` (robot frame).
fn arc_clearance(world: &World, pose: &Pose2, local: [f64; 2]) -> f64 {
    let d2 = local[0] * local[0] + local[1] * local[1];
    let d = d2.sqrt();
    let curvature = 2.0 * local[1] / d2;
    let bearing = local[1].atan2(local[0]);
    let length = d / sin_over_x(bearing);
    path_clearance_along(world, pose, length, curvature)
}

/// The smallest clearance along the arc of signed `length` (m; negative: backward)
/// and `curvature` (1/m) from `pose`, tangent to its heading.
fn path_clearance_along(world: &World, pose: &Pose2, length: f64, curvature: f64) -> f64 {
    let n = (length.abs() / 0.05).ceil().max(1.0) as usize;
    let mut prev = [pose.x, pose.y];
    let mut worst = f64::INFINITY;
    for i in 1..=n {
        let s = length * i as f64 / n as f64;
        let p = pose.compose(&arc_motion(s, s * curvature, 1.0));
        let q = [p.x, p.y];
        worst = worst.min(world.path_clearance(prev, q));
        prev = q;
    }
    worst
}

fn random_sign(rng: &mut ChaCha8Rng) -> f64 {
    if rng.random_bool(0.5) {
        1.0
    } else {
        -1.0
    }
}

/// A random point with at least `clearance` to the walls, in sight of `home` (so that
/// it is in the same free space, not inside an obstacle).
fn free_point(
    world: &World,
    home: [f64; 2],
    clearance: f64,
    rng: &mut ChaCha8Rng,
) -> Result<[f64; 2], SimError> {
    let [x0, y0, x1, y1] = world.bounds();
    for _ in 0..20_000 {
        let p = [rng.random_range(x0..=x1), rng.random_range(y0..=y1)];
        if world.clearance(p) >= clearance && world.path_clearance(home, p) > 0.0 {
            return Ok(p);
        }
    }
    Err(SimError::NoFreeSpace {
        world: world.name().to_string(),
        reason: format!("no point with {clearance} m clearance in sight of {home:?}"),
    })
}

/// A start pose and the free length (m) ahead of it, for straight-only runs: the best
/// of many random candidates, at most 2.5 m.
fn straight_line(
    world: &World,
    home: [f64; 2],
    clearance: f64,
    rng: &mut ChaCha8Rng,
) -> Result<(Pose2, f64), SimError> {
    let mut best: Option<(Pose2, f64)> = None;
    for _ in 0..200 {
        let p = free_point(world, home, clearance + 0.05, rng)?;
        let a = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let mut length: f64 = 0.0;
        while length < 2.5 {
            let next = length + 0.05;
            let q = [p[0] + next * a.cos(), p[1] + next * a.sin()];
            if world.path_clearance(p, q) < clearance {
                break;
            }
            length = next;
        }
        if best.is_none_or(|b| length > b.1) {
            best = Some((Pose2::new(p[0], p[1], a), length));
        }
        if length >= 2.5 {
            break;
        }
    }
    match best {
        Some(b) if b.1 >= 0.5 => Ok(b),
        _ => Err(SimError::NoFreeSpace {
            world: world.name().to_string(),
            reason: format!("no straight line of 0.5 m with {clearance} m clearance"),
        }),
    }
}

/// A start pose on a circle of radius `turn_radius` that lies in free space with the
/// clearance; the robot's heading is tangent to it.
/// Returns the pose and the circle's signed curvature (positive: turning left).
fn circle_start(
    world: &World,
    home: [f64; 2],
    lim: &MotionLimits,
    rng: &mut ChaCha8Rng,
) -> Result<(Pose2, f64), SimError> {
    let r = lim.turn_radius;
    let c = free_point(world, home, r + lim.clearance, rng)?;
    let phi = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
    let left = rng.random_bool(0.5);
    let p = [c[0] + r * phi.cos(), c[1] + r * phi.sin()];
    // Counter-clockwise motion (turning left) has the centre on the left.
    let heading = if left {
        phi + std::f64::consts::FRAC_PI_2
    } else {
        phi - std::f64::consts::FRAC_PI_2
    };
    let curvature = if left { 1.0 / r } else { -1.0 / r };
    Ok((Pose2::new(p[0], p[1], heading), curvature))
}
