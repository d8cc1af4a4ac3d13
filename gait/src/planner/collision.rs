//! Fingertip clearance along planned motions (SPEC §1.3 I4).
//!
//! Free fingertips travel on arcs of the transfer shell; grasping fingertips
//! sweep circles when the object turns. Distances between centres follow from
//! the angle between their directions (law of cosines), and the angle along a
//! rotation is a sinusoid ([`Sinusoid`]), so static checks are exact.

use nalgebra::Vector3;

use super::geometry::{Geometry, Sinusoid};
use super::plan::FreePath;
use crate::hand_state::{FingerMode, HandState};

/// Whether centres at `p` and `q` are far enough apart.
pub fn clear(g: &Geometry, p: &Vector3<f64>, q: &Vector3<f64>) -> bool {
    (p - q).norm() >= g.min_center_distance
}

/// Whether every two fingertip centres of `s` are far enough apart.
pub fn centers_clear(g: &Geometry, s: &HandState) -> bool {
    (0..3).all(|a| (a + 1..3).all(|b| clear(g, &s.fingers[a].center, &s.fingers[b].center)))
}

/// Smallest cosine of the angle between directions that keeps a fingertip at
/// radius `rp` clear of one at radius `rq`.
fn max_cos(g: &Geometry, rp: f64, rq: f64) -> f64 {
    let d = g.min_center_distance;
    (rp * rp + rq * rq - d * d) / (2.0 * rp * rq)
}

/// Whether a free finger moving along `path` stays clear of the fixed
/// fingertip centres `others` (exact for arcs and radial moves).
pub fn path_clear(g: &Geometry, path: &FreePath, others: &[Vector3<f64>]) -> bool {
    match *path {
        FreePath::Radial { dir, from, to } => {
            // The distance to a fixed point along a ray is convex in the
            // radius: checking the ends and the closest point suffices.
            others.iter().all(|q| {
                let (lo, hi) = (from.min(to), from.max(to));
                let foot = dir.dot(q).clamp(lo, hi);
                clear(g, &(dir * foot), q)
            })
        }
        FreePath::Arc {
            from,
            axis,
            angle,
            radius,
        } => others.iter().all(|q| {
            let rq = q.norm();
            let s = Sinusoid::new(&axis, &from, &(q / rq));
            s.max_on(angle) <= max_cos(g, radius, rq)
        }),
    }
}

/// Whether the grasping fingertips of `hand`, carried by a rotation about
/// `axis` through `angle`, stay clear of a free fingertip travelling along
/// `path` at the same time — whatever the timing of either (conservative:
/// every point of the path against the whole sweep).
pub fn sweep_clear(
    g: &Geometry,
    hand: &HandState,
    free: usize,
    axis: &Vector3<f64>,
    angle: f64,
    path: Option<&FreePath>,
) -> bool {
    let p0 = hand.fingers[free].center;
    const SAMPLES: usize = 48;
    for (k, f) in hand.fingers.iter().enumerate() {
        if k == free || f.mode != FingerMode::Grasping {
            continue;
        }
        let c = f.center.normalize();
        let rc = f.center.norm();
        let ok = |p: &Vector3<f64>, slack: f64| {
            let rp = p.norm();
            let s = Sinusoid::new(axis, &c, &(p / rp));
            // Moving a point by `slack` along the path changes its angle to
            // anything by at most slack / rp.
            let worst = s.max_on(angle);
            let limit = (max_cos(g, rp, rc).acos() + slack / rp).cos();
            worst <= limit
        };
        match path {
            None => {
                if !ok(&p0, 0.0) {
                    return false;
                }
            }
            Some(path) => {
                let len = path.length();
                let step = len / SAMPLES as f64;
                for i in 0..=SAMPLES {
                    let (p, _) = path.at(step * i as f64);
                    if !ok(&p, 0.5 * step) {
                        return false;
                    }
                }
            }
        }
    }
    true
}

/// Centres of every finger except `skip`.
pub fn other_centers(hand: &HandState, skip: usize) -> ([Vector3<f64>; 2], usize) {
    let mut out = [Vector3::zeros(); 2];
    let mut n = 0;
    for (k, f) in hand.fingers.iter().enumerate() {
        if k != skip && n < 2 {
            out[n] = f.center;
            n += 1;
        }
    }
    (out, n)
}

/// Whether the pair of contacts stays clear of each other and of the third
/// finger while the object turns (the pair is rigid, so only the third
/// finger matters when it is free).
pub fn rotation_clear(g: &Geometry, hand: &HandState, axis: &Vector3<f64>, angle: f64) -> bool {
    match (0..3).find(|&k| hand.fingers[k].mode == FingerMode::Free) {
        Some(free) => sweep_clear(g, hand, free, axis, angle, None),
        None => true,
    }
}
