//! Per-axis tables of fresh placements: for every candidate contact, how a
//! finger would touch down there to carry the object about the axis next,
//! and how far it could then (SPEC §4, "The search").

use nalgebra::Vector3;

use super::super::geometry::BOUNDARY_EPS;
use super::super::hand_model::HandModel;

/// Fresh placements about one axis.
pub struct Fresh<T> {
    /// The unit axis.
    pub axis: Vector3<f64>,
    /// Per finger, per candidate: the range \[rad\].
    pub range: [Vec<f64>; 3],
    /// Per finger, per candidate: how it touches.
    pub touch: [Vec<T>; 3],
    /// The longest turn any pair of fresh placements allows (with
    /// `pairs`), or any single one: the time-to-go estimate's segment.
    pub best: f64,
}

impl<T: Copy> Fresh<T> {
    /// Builds the table; `pairs`: the bound over pairs of placements (a
    /// tighter estimate, ~100 µs), else over single placements.
    pub fn new<H: HandModel<Touch = T>>(hand: &H, axis: &Vector3<f64>, pairs: bool) -> Self {
        let mut best: f64 = 0.0;
        let mut range: [Vec<f64>; 3] = Default::default();
        let mut touch: [Vec<T>; 3] = Default::default();
        for k in 0..3 {
            let cand = hand.candidates(k);
            range[k].reserve(cand.len());
            touch[k].reserve(cand.len());
            for c in cand {
                let (t, r) = hand.touch_for(k, c, axis);
                let r = (r - BOUNDARY_EPS).max(0.0);
                best = best.max(r);
                range[k].push(r);
                touch[k].push(t);
            }
        }
        if pairs {
            let mut best_pair: f64 = 0.0;
            for a in 0..3 {
                for b in a + 1..3 {
                    for (i, &ra) in range[a].iter().enumerate() {
                        if ra <= best_pair {
                            continue;
                        }
                        let rb = hand
                            .partners(a, b, i)
                            .iter()
                            .map(|&j| range[b][j as usize])
                            .fold(0.0, f64::max);
                        best_pair = best_pair.max(ra.min(rb));
                    }
                }
            }
            if best_pair > 0.0 {
                best = best_pair;
            }
        }
        Self {
            axis: *axis,
            range,
            touch,
            best,
        }
    }
}
