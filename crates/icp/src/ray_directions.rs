//! The unit directions of a scan geometry's rays, computed once for every scan
//! prepared with them.
//!
//! A scan whose kept readings are not evenly spaced (any scan with a reading
//! missing: most real ones) needs the exact `(cos, sin)` of each kept ray, and so
//! does the mixed-pixel test at depth edges. They depend on the angle table alone:
//! [`PreparedScan::with_rays`](crate::PreparedScan::with_rays) takes them from here
//! instead of a `sin_cos` per ray and scan (the same values, bit for bit).

/// A ray angle table and the `(cos, sin)` of each of its angles.
#[derive(Debug, Clone, PartialEq)]
pub struct RayDirections {
    angles: Vec<f64>,
    directions: Vec<[f64; 2]>,
}

impl RayDirections {
    /// The directions of the rays `angles` (rad, sensor frame).
    pub fn new(angles: &[f64]) -> Self {
        RayDirections {
            angles: angles.to_vec(),
            directions: angles
                .iter()
                .map(|a| {
                    let (s, c) = a.sin_cos();
                    [c, s]
                })
                .collect(),
        }
    }

    /// The ray angles (rad).
    pub fn angles(&self) -> &[f64] {
        &self.angles
    }

    /// `(cos, sin)` of each angle.
    pub(crate) fn directions(&self) -> &[[f64; 2]] {
        &self.directions
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directions_are_the_angles_sin_cos() {
        let angles: Vec<f64> = (0..681).map(|i| -2.086 + i as f64 * 0.006_135_9).collect();
        let rays = RayDirections::new(&angles);
        assert_eq!(rays.angles(), &angles[..]);
        for (a, d) in angles.iter().zip(rays.directions()) {
            assert_eq!(d[0].to_bits(), a.cos().to_bits());
            assert_eq!(d[1].to_bits(), a.sin().to_bits());
        }
    }
}
