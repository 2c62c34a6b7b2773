//! What a realistic world's walls are made of, and the people walking in it: surfaces
//! that return a laser ray only sometimes (dark paint, glass a ray may pass through)
//! and walkers whose two legs move between scans. The plain worlds have neither: every
//! segment is a matte wall and nothing moves.
//!
//! [`Scene`] is a world frozen at one instant near one point, which the realistic laser
//! (see [`crate::RealisticLaser`]) casts its rays into.

use crate::world::{Segment, World};
use serde::{Deserialize, Serialize};

/// What a segment is made of, as a laser sees it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Surface {
    /// Probability that a ray hitting the surface squarely, close by, returns (1 for
    /// a matte light wall, about 0.3 for dark paint or black plastic, about 0.1 for
    /// glass, which reflects back only near normal incidence).
    pub return_probability: f64,
    /// A ray that does not return passes through (glass) and may hit what lies behind;
    /// otherwise it is lost (a dark surface absorbs it).
    pub see_through: bool,
}

impl Surface {
    /// A matte light wall: every ray returns (up to the laser's range and incidence
    /// limits).
    pub const MATTE: Surface = Surface {
        return_probability: 1.0,
        see_through: false,
    };
    /// Dark paint, black furniture: 30 % of the rays return, the others are absorbed.
    pub const DARK: Surface = Surface {
        return_probability: 0.3,
        see_through: false,
    };
    /// A glass pane: 10 % of the rays return, the others pass through.
    pub const GLASS: Surface = Surface {
        return_probability: 0.1,
        see_through: true,
    };
    /// Trousers and shoes: most rays return.
    pub const CLOTH: Surface = Surface {
        return_probability: 0.8,
        see_through: false,
    };
}

/// A person walking back and forth between two points: two legs (cylinders) side by
/// side that swing along the direction of walking.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Walker {
    /// One end of the walk `[x, y]` (m).
    pub from: [f64; 2],
    /// The other end `[x, y]` (m).
    pub to: [f64; 2],
    /// Walking speed (m/s).
    pub speed: f64,
    /// Time offset along the walk (s), so that walkers do not move in step.
    pub phase: f64,
}

/// Radius of a leg (m).
const LEG_RADIUS: f64 = 0.06;
/// Half the distance between the legs, across the walking direction (m).
const LEG_HALF_SPACING: f64 = 0.1;
/// How far a leg swings ahead of the body and behind it (m), once per stride.
const LEG_SWING: f64 = 0.15;
/// Strides per second.
const STRIDE_HZ: f64 = 0.9;

impl Walker {
    /// Centres of the two legs at time `t` (s since the start of the run).
    pub fn legs(&self, t: f64) -> [[f64; 2]; 2] {
        let d = [self.to[0] - self.from[0], self.to[1] - self.from[1]];
        let len = d[0].hypot(d[1]);
        if len == 0.0 || self.speed <= 0.0 {
            let p = self.from;
            return [
                [p[0] - LEG_HALF_SPACING, p[1]],
                [p[0] + LEG_HALF_SPACING, p[1]],
            ];
        }
        let u = [d[0] / len, d[1] / len];
        // Back and forth: position along the walk in [0, len].
        let s = (self.speed * (t + self.phase)).rem_euclid(2.0 * len);
        let (s, dir) = if s <= len {
            (s, 1.0)
        } else {
            (2.0 * len - s, -1.0)
        };
        let c = [self.from[0] + s * u[0], self.from[1] + s * u[1]];
        let swing = LEG_SWING * (std::f64::consts::TAU * STRIDE_HZ * t).sin() * dir;
        let side = [-u[1] * LEG_HALF_SPACING, u[0] * LEG_HALF_SPACING];
        [
            [c[0] + side[0] + swing * u[0], c[1] + side[1] + swing * u[1]],
            [c[0] - side[0] - swing * u[0], c[1] - side[1] - swing * u[1]],
        ]
    }
}

impl World {
    /// The same world with `surfaces[i]` the surface of segment `i` (segments beyond
    /// the list are matte walls).
    pub fn with_surfaces(mut self, surfaces: Vec<Surface>) -> Self {
        self.set_surfaces(surfaces);
        self
    }

    /// The same world with people walking in it. Only the realistic laser sees them;
    /// the planner does not avoid them (the robot drives through them).
    pub fn with_walkers(mut self, walkers: Vec<Walker>) -> Self {
        self.set_walkers(walkers);
        self
    }

    /// The surface of segment `i`.
    pub fn surface(&self, i: usize) -> Surface {
        self.surface_list()
            .get(i)
            .copied()
            .unwrap_or(Surface::MATTE)
    }

    /// True when some segment is not a matte wall or someone walks: the world needs
    /// the realistic laser to show what it holds.
    pub fn is_realistic(&self) -> bool {
        !self.walkers().is_empty() || self.surface_list().iter().any(|s| *s != Surface::MATTE)
    }
}

/// One ray's first return: where it stopped and how squarely.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance (m) from the ray's origin.
    pub range: f64,
    /// The surface hit.
    pub surface: Surface,
    /// Cosine of the angle between the ray and the surface's normal (1 = square on).
    pub cos_incidence: f64,
}

/// A world frozen at one instant, restricted to what lies within reach of one point:
/// the segments with their surfaces and the walkers' legs.
#[derive(Debug, Clone)]
pub struct Scene {
    segments: Vec<(Segment, Surface)>,
    legs: Vec<[f64; 2]>,
}

impl Scene {
    /// The part of `world` within `reach` (m) of `centre` at time `t` (s since the
    /// start of the run).
    pub fn new(world: &World, centre: [f64; 2], reach: f64, t: f64) -> Self {
        let segments = world
            .segments()
            .iter()
            .enumerate()
            .filter(|(_, s)| s.distance_to_point(centre) <= reach)
            .map(|(i, s)| (*s, world.surface(i)))
            .collect();
        let legs = world
            .walkers()
            .iter()
            .flat_map(|w| w.legs(t))
            .filter(|c| (c[0] - centre[0]).hypot(c[1] - centre[1]) <= reach + LEG_RADIUS)
            .collect();
        Scene { segments, legs }
    }

    /// The first surface hit by the ray from `origin` along the unit vector `dir`
    /// farther than `after` (m) and within `max_range`.
    pub fn first_hit(
        &self,
        origin: [f64; 2],
        dir: [f64; 2],
        after: f64,
        max_range: f64,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut consider = |range: f64, surface: Surface, cos_incidence: f64| {
            if range > after && range <= max_range && best.is_none_or(|b| range < b.range) {
                best = Some(Hit {
                    range,
                    surface,
                    cos_incidence,
                });
            }
        };
        for (s, surface) in &self.segments {
            if let Some(t) = s.ray_hit(origin, dir) {
                let e = [s.b[0] - s.a[0], s.b[1] - s.a[1]];
                let cos = (dir[0] * e[1] - dir[1] * e[0]).abs() / e[0].hypot(e[1]);
                consider(t, *surface, cos);
            }
        }
        for c in &self.legs {
            let f = [origin[0] - c[0], origin[1] - c[1]];
            let b = f[0] * dir[0] + f[1] * dir[1];
            let disc = b * b - (f[0] * f[0] + f[1] * f[1] - LEG_RADIUS * LEG_RADIUS);
            if disc < 0.0 {
                continue;
            }
            let t = -b - disc.sqrt();
            let p = [f[0] + t * dir[0], f[1] + t * dir[1]];
            let cos = ((p[0] * dir[0] + p[1] * dir[1]) / LEG_RADIUS).abs();
            consider(t, Surface::CLOTH, cos.min(1.0));
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn room_with_glass() -> World {
        World::new(
            "glass",
            vec![
                Segment::new([1.0, -1.0], [1.0, 1.0]), // glass pane
                Segment::new([3.0, -1.0], [3.0, 1.0]), // wall behind
            ],
        )
        .with_surfaces(vec![Surface::GLASS])
    }

    #[test]
    fn rays_see_the_glass_and_what_is_behind() {
        let w = room_with_glass();
        assert!(w.is_realistic());
        assert_eq!(w.surface(1), Surface::MATTE);
        let scene = Scene::new(&w, [0.0, 0.0], 5.0, 0.0);
        let first = scene.first_hit([0.0, 0.0], [1.0, 0.0], 0.0, 5.0).unwrap();
        assert!((first.range - 1.0).abs() < 1e-12);
        assert_eq!(first.surface, Surface::GLASS);
        assert!((first.cos_incidence - 1.0).abs() < 1e-12);
        let behind = scene
            .first_hit([0.0, 0.0], [1.0, 0.0], first.range, 5.0)
            .unwrap();
        assert!((behind.range - 3.0).abs() < 1e-12);
        // At 60° from the normal.
        let d = [0.5, 3f64.sqrt() / 2.0];
        let h = scene.first_hit([0.0, -0.9], d, 0.0, 5.0).unwrap();
        assert!((h.cos_incidence - 0.5).abs() < 1e-12);
        assert!(!World::office().is_realistic());
    }

    #[test]
    fn walkers_go_back_and_forth_and_are_hit() {
        let w = Walker {
            from: [0.0, 0.0],
            to: [2.0, 0.0],
            speed: 1.0,
            phase: 0.0,
        };
        let mid = |t: f64| {
            let l = w.legs(t);
            [(l[0][0] + l[1][0]) / 2.0, (l[0][1] + l[1][1]) / 2.0]
        };
        assert!((mid(0.5)[0] - 0.5).abs() < 1e-12);
        assert!((mid(3.0)[0] - 1.0).abs() < 1e-12); // on the way back
        let legs = w.legs(0.0);
        assert!((legs[0][1] - 0.1).abs() < 1e-12 && (legs[1][1] + 0.1).abs() < 1e-12);
        let world = World::new("empty", vec![]).with_walkers(vec![w]);
        let scene = Scene::new(&world, [0.0, -3.0], 5.0, 0.0);
        // Looking north at the leg at (0, −0.1): the near side is at y = −0.16.
        let h = scene.first_hit([0.0, -3.0], [0.0, 1.0], 0.0, 5.0).unwrap();
        assert!(
            (h.range - (3.0 - 0.1 - LEG_RADIUS)).abs() < 1e-9,
            "{}",
            h.range
        );
        assert_eq!(h.surface, Surface::CLOTH);
        assert!(scene.first_hit([0.0, -3.0], [1.0, 0.0], 0.0, 5.0).is_none());
    }
}
