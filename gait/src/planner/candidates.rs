//! Candidate contact points in each finger's workspace cone (SPEC §4,
//! `planner.candidate_spacing_deg`): the cone centre plus rings every `spacing` degrees, computed once
//! per configuration.

use nalgebra::Vector3;

use super::geometry::{Geometry, any_perpendicular, rotation};

/// Candidate contact normals for the three fingers.
#[derive(Debug, Clone)]
pub struct Candidates {
    /// `points[k]`: unit contact normals inside finger k's cone (with margin).
    pub points: [Vec<Vector3<f64>>; 3],
    /// `partners[a][b][i]`: indices j of `points[b]` that form a
    /// force-closure pair (Fact 3 with margin) with `points[a][i]`.
    pub partners: [[Vec<Vec<u16>>; 3]; 3],
}

impl Candidates {
    /// Builds the grids. Points lie strictly inside the cone with margin.
    pub fn new(g: &Geometry, spacing_deg: f64) -> Self {
        let spacing = spacing_deg.to_radians();
        let points = std::array::from_fn(|k| {
            let d = g.base[k];
            let e1 = any_perpendicular(&d);
            let mut pts = vec![d];
            // Rings at j·spacing, the last one just inside the boundary.
            let max_ring = g.cone_half_angle - 1e-6;
            let rings = (max_ring / spacing).floor() as usize;
            let mut ring_angles: Vec<f64> = (1..=rings).map(|j| j as f64 * spacing).collect();
            if max_ring - rings as f64 * spacing > 0.35 * spacing {
                ring_angles.push(max_ring);
            }
            for alpha in ring_angles {
                let n = ((std::f64::consts::TAU * alpha.sin() / spacing).round() as usize).max(6);
                let off = rotation(&e1, alpha) * d;
                for i in 0..n {
                    let phi = std::f64::consts::TAU * i as f64 / n as f64;
                    pts.push(rotation(&d, phi) * off);
                }
            }
            pts
        });
        let partners = std::array::from_fn(|a| {
            std::array::from_fn(|b| {
                if a == b {
                    return Vec::new();
                }
                let pa: &Vec<Vector3<f64>> = &points[a];
                let pb: &Vec<Vector3<f64>> = &points[b];
                pa.iter()
                    .map(|c| {
                        (0..pb.len())
                            .filter(|&j| g.is_good_pair(c, &pb[j]))
                            .map(|j| j as u16)
                            .collect()
                    })
                    .collect()
            })
        });
        Self { points, partners }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;

    #[test]
    fn grids_fill_the_cones() {
        let g = Geometry::new(&HandConfig::default());
        let c = Candidates::new(&g, 6.0);
        for k in 0..3 {
            let n = c.points[k].len();
            assert!((250..400).contains(&n), "{n} points");
            for p in &c.points[k] {
                assert!((p.norm() - 1.0).abs() < 1e-12);
                assert!(g.in_cone(k, p));
            }
        }
    }
}
