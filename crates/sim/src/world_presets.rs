//! The preset worlds: a Khepera arena, an office floor, a long featureless corridor and
//! a warehouse hall for fast robots.

use crate::error::SimError;
use crate::world::{Segment, World};

/// Names accepted by [`World::preset`].
pub const WORLD_NAMES: [&str; 6] = [
    "khepera-arena",
    "office",
    "corridor",
    "hall",
    "office-cluttered",
    "hall-cluttered",
];

impl World {
    /// A preset world by name: `khepera-arena`, `office`, `corridor`, `hall`, or the
    /// realistic `office-cluttered` and `hall-cluttered`.
    pub fn preset(name: &str) -> Result<World, SimError> {
        match name {
            "khepera-arena" | "arena" | "khepera_arena" => Ok(World::khepera_arena()),
            "office" => Ok(World::office()),
            "corridor" => Ok(World::corridor()),
            "hall" | "warehouse" => Ok(World::hall()),
            "office-cluttered" => Ok(World::office_cluttered()),
            "hall-cluttered" => Ok(World::hall_cluttered()),
            _ => Err(SimError::UnknownName {
                what: "world",
                name: name.to_string(),
                known: WORLD_NAMES.join(", "),
            }),
        }
    }

    /// A 3 m × 2.5 m walled arena (corner at the origin) with two boxes, a pillar and
    /// a short partition sticking out of the south wall, placed so that no two
    /// headings see the same picture (no symmetric ambiguity for scan matching).
    pub fn khepera_arena() -> World {
        let mut s = rect(0.0, 0.0, 3.0, 2.5);
        s.extend(rect(0.60, 1.60, 1.00, 1.90)); // box
        s.extend(rect(1.90, 0.80, 2.00, 0.90)); // pillar
        s.extend(rect(2.30, 1.50, 2.55, 2.00)); // tall box
        s.push(Segment::new([1.5, 0.0], [1.5, 0.35])); // partition stub
        World::new("khepera-arena", s).with_home([1.5, 1.25])
    }

    /// A 10 m × 8 m office floor: three rooms to the north behind a wall with doors,
    /// an open-plan area to the south split by a half wall, desks, a cabinet, a
    /// pillar, a table and a bookshelf.
    pub fn office() -> World {
        let mut s = rect(0.0, 0.0, 10.0, 8.0);
        // Wall between the open area and the rooms, with three 0.9 m doors.
        for (x0, x1) in [(0.0, 1.5), (2.4, 5.0), (5.9, 8.0), (8.9, 10.0)] {
            s.push(Segment::new([x0, 5.0], [x1, 5.0]));
        }
        // Room dividers.
        s.push(Segment::new([3.5, 5.0], [3.5, 8.0]));
        s.push(Segment::new([7.0, 5.0], [7.0, 8.0]));
        // Half wall in the open area.
        s.push(Segment::new([6.0, 0.0], [6.0, 3.0]));
        // Furniture.
        s.extend(rect(1.0, 0.8, 2.6, 1.6)); // desk
        s.extend(rect(3.2, 0.8, 4.8, 1.6)); // desk
        s.extend(rect(7.5, 1.0, 9.0, 1.8)); // desk
        s.extend(rect(0.0, 3.0, 0.5, 4.0)); // cabinet against the west wall
        s.extend(rect(4.35, 3.35, 4.65, 3.65)); // pillar
        s.extend(rect(1.0, 6.2, 2.2, 7.0)); // table, west room
        s.extend(rect(9.5, 5.5, 10.0, 7.5)); // bookshelf, east room
        s.extend(rect(4.6, 7.2, 5.8, 8.0)); // sideboard, middle room
        World::new("office", s).with_home([3.0, 2.5])
    }

    /// A 40 m × 2 m corridor with nothing in it: from inside, every pose along the
    /// corridor sees the same two parallel walls (ends beyond the 4 m laser range),
    /// so scan matching cannot observe motion along it.
    pub fn corridor() -> World {
        World::new("corridor", rect(0.0, 0.0, 40.0, 2.0)).with_home([20.0, 1.0])
    }

    /// A 20 m × 12 m warehouse hall for robots driving at 0.5 m/s: shelf rows, pillars,
    /// crates, a partition and two slanted corners, placed irregularly so that a 4 m
    /// range finder sees several surfaces from anywhere inside and no two places look
    /// alike.
    pub fn hall() -> World {
        let mut s = rect(0.0, 0.0, 20.0, 12.0);
        // Slanted corners.
        s.push(Segment::new([0.0, 9.8], [2.2, 12.0]));
        s.push(Segment::new([17.6, 0.0], [20.0, 2.1]));
        // Shelf rows.
        s.extend(rect(2.0, 9.4, 6.2, 10.1));
        s.extend(rect(8.0, 1.4, 8.7, 5.2));
        s.extend(rect(12.6, 9.0, 17.0, 9.6));
        s.extend(rect(16.4, 3.0, 17.1, 6.4));
        // Pillars.
        for (x, y) in [
            (4.5, 5.5),
            (11.0, 7.2),
            (14.2, 3.6),
            (3.2, 2.6),
            (11.8, 1.9),
            (10.3, 3.9),
        ] {
            s.extend(rect(x - 0.2, y - 0.2, x + 0.2, y + 0.2));
        }
        // Crates.
        s.extend(rect(6.3, 6.9, 7.5, 7.8));
        s.extend(rect(18.6, 9.2, 20.0, 10.6));
        s.extend(rect(0.0, 5.2, 0.8, 6.6));
        s.extend(rect(12.6, 4.9, 13.5, 5.6));
        // A partition hanging from the north wall.
        s.push(Segment::new([9.8, 12.0], [9.8, 9.6]));
        World::new("hall", s).with_home([10.0, 6.0])
    }
}

/// The four sides of the axis-aligned rectangle `[x0, x1] × [y0, y1]`.
fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Segment> {
    vec![
        Segment::new([x0, y0], [x1, y0]),
        Segment::new([x1, y0], [x1, y1]),
        Segment::new([x1, y1], [x0, y1]),
        Segment::new([x0, y1], [x0, y0]),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_have_the_announced_sizes() {
        assert_eq!(World::khepera_arena().bounds(), [0.0, 0.0, 3.0, 2.5]);
        assert_eq!(World::office().bounds(), [0.0, 0.0, 10.0, 8.0]);
        assert_eq!(World::corridor().bounds(), [0.0, 0.0, 40.0, 2.0]);
        assert_eq!(World::hall().bounds(), [0.0, 0.0, 20.0, 12.0]);
        for n in WORLD_NAMES {
            assert_eq!(World::preset(n).unwrap().name(), n);
        }
        assert!(World::preset("moon").is_err());
    }

    #[test]
    fn office_doors_connect_the_rooms() {
        let w = World::office();
        for x in [1.95, 5.45, 8.45] {
            let c = w.path_clearance([x, 4.0], [x, 5.7]);
            assert!(c >= 0.44, "door at {x}: {c}");
        }
        assert_eq!(w.path_clearance([3.0, 4.0], [3.0, 6.0]), 0.0);
    }
}
