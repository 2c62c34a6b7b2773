//! A world made of line segments (walls, obstacle edges), with ray casting and the
//! clearance queries the trajectory planner uses to keep the robot off the walls.

use crate::surfaces::{Surface, Walker};
use serde::{Deserialize, Serialize};

/// A wall: the straight segment from `a` to `b` (m, world frame).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// First end point `[x, y]` (m).
    pub a: [f64; 2],
    /// Second end point `[x, y]` (m).
    pub b: [f64; 2],
}

impl Segment {
    /// The segment from `a` to `b`.
    pub fn new(a: [f64; 2], b: [f64; 2]) -> Self {
        Segment { a, b }
    }

    /// Euclidean distance (m) from point `p` to the closest point of the segment.
    pub fn distance_to_point(&self, p: [f64; 2]) -> f64 {
        let e = sub(self.b, self.a);
        let len2 = dot(e, e);
        let s = if len2 > 0.0 {
            (dot(sub(p, self.a), e) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [self.a[0] + s * e[0], self.a[1] + s * e[1]];
        norm(sub(p, q))
    }

    /// Distance (m) along the ray from `origin` in unit direction `dir` to this
    /// segment, or `None` when the ray misses it (parallel rays never hit).
    pub fn ray_hit(&self, origin: [f64; 2], dir: [f64; 2]) -> Option<f64> {
        let e = sub(self.b, self.a);
        let denom = cross(dir, e);
        if denom == 0.0 {
            return None;
        }
        let ao = sub(self.a, origin);
        let t = cross(ao, e) / denom;
        let s = cross(ao, dir) / denom;
        if t > 0.0 && (0.0..=1.0).contains(&s) {
            Some(t)
        } else {
            None
        }
    }

    /// Smallest distance (m) between this segment and the segment `p`–`q`
    /// (0 when they cross).
    pub fn distance_to_segment(&self, p: [f64; 2], q: [f64; 2]) -> f64 {
        if segments_cross(self.a, self.b, p, q) {
            return 0.0;
        }
        let other = Segment::new(p, q);
        self.distance_to_point(p)
            .min(self.distance_to_point(q))
            .min(other.distance_to_point(self.a))
            .min(other.distance_to_point(self.b))
    }
}

/// A planar world: a set of wall segments, with a name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct World {
    name: String,
    segments: Vec<Segment>,
    /// Bounding box of all segments: `[min_x, min_y, max_x, max_y]`.
    bounds: [f64; 4],
    /// A point known to be in the free space where the robot drives.
    home: [f64; 2],
    /// What each segment is made of, by segment index (see [`World::with_surfaces`]);
    /// empty (every segment a matte wall) in the plain worlds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    surfaces: Vec<Surface>,
    /// People walking about (see [`World::with_walkers`]); none in the plain worlds.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    walkers: Vec<Walker>,
}

impl World {
    /// A world from its segments. An empty list gives an empty world (rays never hit).
    pub fn new(name: impl Into<String>, segments: Vec<Segment>) -> Self {
        let mut bounds = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for s in &segments {
            for p in [s.a, s.b] {
                bounds[0] = bounds[0].min(p[0]);
                bounds[1] = bounds[1].min(p[1]);
                bounds[2] = bounds[2].max(p[0]);
                bounds[3] = bounds[3].max(p[1]);
            }
        }
        if segments.is_empty() {
            bounds = [0.0; 4];
        }
        let home = [0.5 * (bounds[0] + bounds[2]), 0.5 * (bounds[1] + bounds[3])];
        World {
            name: name.into(),
            segments,
            bounds,
            home,
            surfaces: Vec::new(),
            walkers: Vec::new(),
        }
    }

    /// The same world with `home` as its reference free point (default: the centre of
    /// the bounding box). Start poses are drawn in sight of it, so that the robot starts
    /// in the drivable space, not inside an obstacle.
    pub fn with_home(mut self, home: [f64; 2]) -> Self {
        self.home = home;
        self
    }

    /// The reference free point (see [`World::with_home`]).
    pub fn home(&self) -> [f64; 2] {
        self.home
    }

    /// The world's name (the preset name for presets).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// All wall segments.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// The people walking in the world (see [`World::with_walkers`]).
    pub fn walkers(&self) -> &[Walker] {
        &self.walkers
    }

    pub(crate) fn surface_list(&self) -> &[Surface] {
        &self.surfaces
    }

    pub(crate) fn set_surfaces(&mut self, surfaces: Vec<Surface>) {
        self.surfaces = surfaces;
    }

    pub(crate) fn set_walkers(&mut self, walkers: Vec<Walker>) {
        self.walkers = walkers;
    }

    /// Bounding box of the walls: `[min_x, min_y, max_x, max_y]` (m).
    pub fn bounds(&self) -> [f64; 4] {
        self.bounds
    }

    /// Distance (m) from `origin` along the ray at `angle` (rad, world frame) to the
    /// first wall, if one is hit within `max_range`.
    pub fn cast_ray(&self, origin: [f64; 2], angle: f64, max_range: f64) -> Option<f64> {
        let (s, c) = angle.sin_cos();
        first_hit(&self.segments, origin, [c, s], max_range)
    }

    /// Casts a fan of rays from `origin`: ray `i` at world angle `angles[i] + heading`.
    /// Returns, per ray, the distance to the first wall, or `f64::INFINITY` when no wall
    /// is hit within `max_range`. Only segments within `max_range` of `origin` are tested.
    pub fn cast_fan(
        &self,
        origin: [f64; 2],
        heading: f64,
        angles: &[f64],
        max_range: f64,
    ) -> Vec<f64> {
        let near: Vec<Segment> = self
            .segments
            .iter()
            .filter(|s| s.distance_to_point(origin) <= max_range)
            .copied()
            .collect();
        angles
            .iter()
            .map(|&a| {
                let (s, c) = (a + heading).sin_cos();
                first_hit(&near, origin, [c, s], max_range).unwrap_or(f64::INFINITY)
            })
            .collect()
    }

    /// Distance (m) from point `p` to the nearest wall (infinite in an empty world).
    pub fn clearance(&self, p: [f64; 2]) -> f64 {
        self.segments
            .iter()
            .map(|s| s.distance_to_point(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// Smallest distance (m) from any point of the straight path `p`–`q` to a wall
    /// (0 when the path crosses a wall).
    pub fn path_clearance(&self, p: [f64; 2], q: [f64; 2]) -> f64 {
        self.segments
            .iter()
            .map(|s| s.distance_to_segment(p, q))
            .fold(f64::INFINITY, f64::min)
    }
}

/// The first intersection of a ray with a list of segments, within `max_range`.
fn first_hit(segments: &[Segment], origin: [f64; 2], dir: [f64; 2], max_range: f64) -> Option<f64> {
    let mut best = f64::INFINITY;
    for s in segments {
        if let Some(t) = s.ray_hit(origin, dir) {
            if t < best {
                best = t;
            }
        }
    }
    (best <= max_range).then_some(best)
}

/// True when the closed segments `a`–`b` and `c`–`d` intersect (touching counts).
fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let d1 = cross(sub(b, a), sub(c, a));
    let d2 = cross(sub(b, a), sub(d, a));
    let d3 = cross(sub(d, c), sub(a, c));
    let d4 = cross(sub(d, c), sub(b, c));
    ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn norm(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> World {
        World::new(
            "square",
            vec![
                Segment::new([0.0, 0.0], [2.0, 0.0]),
                Segment::new([2.0, 0.0], [2.0, 2.0]),
                Segment::new([2.0, 2.0], [0.0, 2.0]),
                Segment::new([0.0, 2.0], [0.0, 0.0]),
            ],
        )
    }

    #[test]
    fn rays_hit_the_nearest_wall() {
        let w = square();
        let r = w.cast_ray([0.5, 1.0], 0.0, 4.0).unwrap();
        assert!((r - 1.5).abs() < 1e-12);
        let r = w.cast_ray([0.5, 1.0], std::f64::consts::PI, 4.0).unwrap();
        assert!((r - 0.5).abs() < 1e-12);
        // Diagonal towards the corner (2, 2) from (1, 1).
        let r = w
            .cast_ray([1.0, 1.0], std::f64::consts::FRAC_PI_4, 4.0)
            .unwrap();
        assert!((r - 2f64.sqrt()).abs() < 1e-12);
        assert!(w.cast_ray([0.5, 1.0], 0.0, 1.0).is_none());
    }

    #[test]
    fn fan_agrees_with_single_rays() {
        let w = square();
        let angles: Vec<f64> = (0..50).map(|i| -2.0 + 0.08 * i as f64).collect();
        let fan = w.cast_fan([0.7, 1.3], 0.4, &angles, 4.0);
        for (a, r) in angles.iter().zip(&fan) {
            let single = w.cast_ray([0.7, 1.3], a + 0.4, 4.0).unwrap();
            assert!((single - r).abs() < 1e-12);
        }
    }

    #[test]
    fn clearances() {
        let w = square();
        assert!((w.clearance([0.5, 1.0]) - 0.5).abs() < 1e-12);
        assert!((w.path_clearance([0.5, 1.0], [1.5, 1.0]) - 0.5).abs() < 1e-12);
        assert!((w.path_clearance([0.5, 0.3], [1.5, 1.0]) - 0.3).abs() < 1e-12);
        assert_eq!(w.path_clearance([1.0, 1.0], [3.0, 1.0]), 0.0);
    }
}
