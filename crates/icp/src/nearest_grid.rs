//! The nearest reference point of any position, in constant time: a dense grid whose
//! cells within a radius of the reference points hold the index of the point nearest
//! to the cell's centre. Built once per reference scan of the sparse matcher
//! (`sparse_fallback`), where the correlative search looks up the same points
//! thousands of times.

/// Most cells of one grid: beyond, the cells grow (memory bounded whatever the ranges).
const MAX_CELLS: usize = 1 << 21;

/// No reference point within the radius of this cell.
const EMPTY: u32 = u32::MAX;

/// Nearest-point lookup table over a set of 2-D points.
#[derive(Debug, Clone)]
pub(crate) struct NearestGrid {
    origin: [f64; 2],
    cell: f64,
    columns: usize,
    rows: usize,
    nearest: Vec<u32>,
}

impl NearestGrid {
    /// A grid of `cell`-sized cells (at least: larger when the points spread too far
    /// for [`MAX_CELLS`]) covering the points `points` to `radius` around them;
    /// non-finite points are left out.
    pub fn new(points: &[[f64; 2]], cell: f64, radius: f64) -> Self {
        let finite = || {
            points
                .iter()
                .filter(|p| p[0].is_finite() && p[1].is_finite())
        };
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in finite() {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a] - radius);
                hi[a] = hi[a].max(p[a] + radius);
            }
        }
        if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
            return NearestGrid {
                origin: [0.0; 2],
                cell: 1.0,
                columns: 0,
                rows: 0,
                nearest: Vec::new(),
            };
        }
        let mut cell = cell;
        let extent = [hi[0] - lo[0], hi[1] - lo[1]];
        let cells = |c: f64| ((extent[0] / c).ceil() + 1.0) * ((extent[1] / c).ceil() + 1.0);
        while cells(cell) > MAX_CELLS as f64 {
            cell *= 2.0;
        }
        let columns = (extent[0] / cell).ceil() as usize + 1;
        let rows = (extent[1] / cell).ceil() as usize + 1;
        let mut nearest = vec![EMPTY; columns * rows];
        let mut best = vec![f32::INFINITY; columns * rows];
        // A cell is stamped when its centre is within the radius and half a diagonal
        // (cells larger than the radius still hold their points).
        let reach_m = radius + cell * std::f64::consts::FRAC_1_SQRT_2;
        let reach = (reach_m / cell).ceil() as isize;
        for (i, p) in points.iter().enumerate() {
            if !(p[0].is_finite() && p[1].is_finite()) {
                continue;
            }
            let cx = ((p[0] - lo[0]) / cell).floor() as isize;
            let cy = ((p[1] - lo[1]) / cell).floor() as isize;
            for y in (cy - reach).max(0)..=(cy + reach).min(rows as isize - 1) {
                for x in (cx - reach).max(0)..=(cx + reach).min(columns as isize - 1) {
                    let centre = [
                        lo[0] + (x as f64 + 0.5) * cell,
                        lo[1] + (y as f64 + 0.5) * cell,
                    ];
                    let d2 = (centre[0] - p[0]).powi(2) + (centre[1] - p[1]).powi(2);
                    let k = y as usize * columns + x as usize;
                    if d2 <= reach_m * reach_m && (d2 as f32) < best[k] {
                        best[k] = d2 as f32;
                        nearest[k] = i as u32;
                    }
                }
            }
        }
        NearestGrid {
            origin: lo,
            cell,
            columns,
            rows,
            nearest,
        }
    }

    /// The index of the point nearest to the centre of `p`'s cell, if one is within
    /// the radius (plus half a cell's diagonal) of that centre.
    #[inline]
    pub fn nearest(&self, p: [f64; 2]) -> Option<usize> {
        self.at(self.column(p[0])?, self.row(p[1])?)
    }

    /// The column of the cells at abscissa `x`, if the grid covers it (not for NaN).
    /// With [`NearestGrid::row`] and [`NearestGrid::at`] it is [`NearestGrid::nearest`]
    /// in parts, for callers that look up every combination of a few abscissae and
    /// ordinates (the correlative search's translations).
    #[inline]
    pub fn column(&self, x: f64) -> Option<usize> {
        let x = (x - self.origin[0]) / self.cell;
        (x >= 0.0 && x < self.columns as f64).then_some(x as usize)
    }

    /// The row of the cells at ordinate `y`, if the grid covers it (not for NaN).
    #[inline]
    pub fn row(&self, y: f64) -> Option<usize> {
        let y = (y - self.origin[1]) / self.cell;
        (y >= 0.0 && y < self.rows as f64).then_some(y as usize)
    }

    /// The point nearest to the centre of the cell at `column`, `row` (from
    /// [`NearestGrid::column`] and [`NearestGrid::row`]), if one is within reach.
    #[inline]
    pub fn at(&self, column: usize, row: usize) -> Option<usize> {
        let k = self.nearest[row * self.columns + column];
        (k != EMPTY).then_some(k as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_nearest_point_within_the_radius_only() {
        let points = [[0.0, 0.0], [1.0, 0.0], [f64::NAN, 0.0], [0.0, 1.0]];
        let grid = NearestGrid::new(&points, 0.01, 0.3);
        assert_eq!(grid.nearest([0.1, 0.05]), Some(0));
        assert_eq!(grid.nearest([0.8, -0.1]), Some(1));
        assert_eq!(grid.nearest([0.02, 0.9]), Some(3));
        assert_eq!(grid.nearest([0.5, 0.5]), None);
        assert_eq!(grid.nearest([0.33, 0.0]), None);
        assert_eq!(grid.nearest([f64::NAN, 0.0]), None);
        assert_eq!(grid.nearest([-5.0, 0.0]), None);
    }

    #[test]
    fn column_row_and_cell_are_nearest_in_parts() {
        let points: Vec<[f64; 2]> = (0..40)
            .map(|i| [0.05 * i as f64, (0.3 * i as f64).sin()])
            .collect();
        let grid = NearestGrid::new(&points, 0.02, 0.15);
        for i in -60..260 {
            for j in -70..70 {
                let p = [0.0087 * i as f64, 0.0191 * j as f64];
                let parts = grid
                    .column(p[0])
                    .zip(grid.row(p[1]))
                    .and_then(|(c, r)| grid.at(c, r));
                assert_eq!(parts, grid.nearest(p), "{p:?}");
            }
        }
        assert_eq!(grid.column(f64::NAN), None);
        assert_eq!(grid.row(f64::INFINITY), None);
    }

    #[test]
    fn far_flung_points_keep_the_grid_bounded() {
        let grid = NearestGrid::new(&[[0.0, 0.0], [1e6, 1e6]], 0.01, 0.3);
        assert!(grid.nearest.len() <= MAX_CELLS);
        assert_eq!(grid.nearest([1e6, 1e6]), Some(1));
        assert!(NearestGrid::new(&[], 0.01, 0.3)
            .nearest([0.0, 0.0])
            .is_none());
    }
}
