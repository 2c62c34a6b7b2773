//! Realistic worlds: the office and the hall as real robots see them, with glass,
//! dark furniture, clutter (chair legs, boxes, bins) and people walking about. Made
//! for the realistic laser ([`crate::RealisticLaser`]); a plain laser sees their
//! glass and dark surfaces as ordinary walls.

use crate::surfaces::{Surface, Walker};
use crate::world::{Segment, World};

/// A world under construction: segments with their surfaces.
struct Builder {
    segments: Vec<Segment>,
    surfaces: Vec<Surface>,
}

impl Builder {
    /// Starts from `world`'s segments, all matte.
    fn from(world: &World) -> Self {
        let segments = world.segments().to_vec();
        let surfaces = vec![Surface::MATTE; segments.len()];
        Builder { segments, surfaces }
    }

    /// Gives the segments `range` (indices into the base world) the surface `s`.
    fn paint(&mut self, range: std::ops::Range<usize>, s: Surface) {
        for i in range {
            self.surfaces[i] = s;
        }
    }

    /// Adds the four sides of `[x0, x1] × [y0, y1]`, of surface `s`.
    fn rect(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, s: Surface) {
        let corners = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
        for k in 0..4 {
            self.segments
                .push(Segment::new(corners[k], corners[(k + 1) % 4]));
            self.surfaces.push(s);
        }
    }

    /// A chair: four 3 cm legs at the corners of a 0.45 m square centred at `(x, y)`,
    /// dark metal.
    fn chair(&mut self, x: f64, y: f64) {
        for (dx, dy) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let (cx, cy) = (x + 0.21 * dx, y + 0.21 * dy);
            self.rect(
                cx - 0.015,
                cy - 0.015,
                cx + 0.015,
                cy + 0.015,
                Surface::DARK,
            );
        }
    }

    fn build(self, name: &str, home: [f64; 2], walkers: Vec<Walker>) -> World {
        World::new(name, self.segments)
            .with_home(home)
            .with_surfaces(self.surfaces)
            .with_walkers(walkers)
    }
}

impl World {
    /// The office ([`World::office`]) as it really is: windows along the south wall
    /// (glass: rays leave the building), a glass partition between the open area and
    /// the middle room, dark desks and cabinet, chairs at the desks, boxes, a bin, and
    /// two people walking in the open area.
    pub fn office_cluttered() -> World {
        let mut b = Builder::from(&World::office());
        // Segment order of World::office: 0–3 outer walls (south, east, north, west),
        // 4–7 the wall with the doors, 8–9 room dividers, 10 the half wall, 11–22 the
        // three desks, 23–26 the cabinet, 27–30 the pillar, 31–34 the table, 35–38 the
        // bookshelf, 39–42 the sideboard.
        b.paint(0..1, Surface::GLASS);
        b.paint(5..6, Surface::GLASS);
        b.paint(11..27, Surface::DARK);
        for (x, y) in [(1.5, 0.45), (3.9, 2.0), (8.2, 2.25), (1.6, 5.8), (5.0, 6.6)] {
            b.chair(x, y);
        }
        b.rect(5.3, 0.1, 5.7, 0.5, Surface::MATTE); // box
        b.rect(9.4, 3.6, 9.8, 4.1, Surface::MATTE); // boxes
        b.rect(6.05, 3.6, 6.35, 3.9, Surface::DARK); // bin
        b.rect(0.1, 7.5, 0.4, 7.9, Surface::MATTE); // plant
        let walkers = vec![
            Walker {
                from: [0.8, 4.3],
                to: [5.5, 4.3],
                speed: 0.9,
                phase: 0.0,
            },
            Walker {
                from: [7.0, 2.8],
                to: [9.3, 4.4],
                speed: 0.6,
                phase: 2.5,
            },
        ];
        b.build("office-cluttered", [3.0, 2.5], walkers)
    }

    /// The hall ([`World::hall`]) as a lab building really is: windows along the south
    /// wall, dark crates and one dark shelf row, chairs, boxes and bins, and three
    /// people walking.
    pub fn hall_cluttered() -> World {
        let mut b = Builder::from(&World::hall());
        // Segment order of World::hall: 0–3 outer walls (south, east, north, west),
        // 4–5 slanted corners, 6–21 shelf rows, 22–45 pillars, 46–61 crates, 62 the
        // partition.
        b.paint(0..1, Surface::GLASS);
        b.paint(6..10, Surface::DARK);
        b.paint(46..62, Surface::DARK);
        for (x, y) in [(5.0, 9.0), (7.2, 6.4), (13.6, 8.6), (17.6, 4.6), (2.6, 3.2)] {
            b.chair(x, y);
        }
        b.rect(1.0, 0.2, 1.5, 0.7, Surface::MATTE); // boxes
        b.rect(19.2, 5.0, 19.8, 5.6, Surface::MATTE);
        b.rect(9.0, 11.3, 9.4, 11.7, Surface::DARK); // bin
        b.rect(14.6, 0.2, 15.0, 0.5, Surface::DARK);
        let walkers = vec![
            Walker {
                from: [3.0, 7.8],
                to: [9.0, 8.4],
                speed: 1.0,
                phase: 0.0,
            },
            Walker {
                from: [12.0, 2.6],
                to: [15.5, 7.8],
                speed: 0.8,
                phase: 4.0,
            },
            Walker {
                from: [18.2, 8.0],
                to: [18.2, 2.8],
                speed: 1.1,
                phase: 1.0,
            },
        ];
        b.build("hall-cluttered", [10.0, 6.0], walkers)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cluttered_worlds_keep_the_plain_walls_and_add_to_them() {
        for (plain, cluttered) in [
            (World::office(), World::office_cluttered()),
            (World::hall(), World::hall_cluttered()),
        ] {
            let n = plain.segments().len();
            assert_eq!(&cluttered.segments()[..n], plain.segments());
            assert!(cluttered.segments().len() > n + 60);
            assert_eq!(cluttered.bounds(), plain.bounds());
            assert!(cluttered.is_realistic());
            assert_eq!(cluttered.surface(0), Surface::GLASS);
            // The robot starts in free space.
            assert!(cluttered.clearance(cluttered.home()) > 0.5);
        }
        // The glass partition of the office is the wall piece (2.4, 5)–(5, 5).
        let w = World::office_cluttered();
        assert_eq!(w.segments()[5], Segment::new([2.4, 5.0], [5.0, 5.0]));
        assert_eq!(w.surface(5), Surface::GLASS);
        assert_eq!(w.surface(11), Surface::DARK);
        assert_eq!(w.segments()[11], Segment::new([1.0, 0.8], [2.6, 0.8]));
        let h = World::hall_cluttered();
        assert_eq!(h.segments()[46], Segment::new([6.3, 6.9], [7.5, 6.9]));
        assert_eq!(h.segments()[62], Segment::new([9.8, 12.0], [9.8, 9.6]));
    }
}
