//! Where a free finger goes down (SPEC §4, "The search"): substitutions
//! (placed with one of the pair while the other lifts) and placements
//! that make three fingers grasp, each side's candidates ranked.

use nalgebra::Vector3;

use super::super::geometry::angle_between;
use super::super::hand_model::{Action, HandModel};
use super::Search;
use super::expand::contacts;
use super::node::{Deferred, Last, Node};

/// Most children kept per substitution side (`planner.branching` ≤ this).
const MAX_BRANCHING: usize = 16;

/// Seconds of travel one radian of usable rotation range is worth when
/// ranking placements (a longer segment saves later gaits).
const RANGE_WEIGHT: f64 = 2.0;

/// The `k` lowest-scored candidates offered so far, lowest first (equal
/// scores in the order offered).
struct Shortlist {
    top: [(f64, usize); MAX_BRANCHING],
    n: usize,
    k: usize,
}

impl Shortlist {
    /// Room for `planner.branching` candidates (at most [`MAX_BRANCHING`]).
    fn new(branching: usize) -> Self {
        Self {
            top: [(f64::INFINITY, usize::MAX); MAX_BRANCHING],
            n: 0,
            k: branching.min(MAX_BRANCHING),
        }
    }

    /// The score a candidate must beat to enter (+∞ while there is room).
    fn bar(&self) -> f64 {
        if self.n < self.k {
            f64::INFINITY
        } else {
            self.top[self.n - 1].0
        }
    }

    /// Enters candidate `i` with `score` (below [`Shortlist::bar`]); the
    /// last one drops out when the list is full.
    fn enter(&mut self, score: f64, i: usize) {
        let pos = self.top[..self.n].partition_point(|(s, _)| *s <= score);
        let end = (self.n + 1).min(self.k);
        self.top.copy_within(pos..end - 1, pos + 1);
        self.top[pos] = (score, i);
        self.n = end;
    }

    /// The candidates, lowest score first.
    fn chosen(&self) -> impl Iterator<Item = usize> + '_ {
        self.top[..self.n].iter().map(|t| t.1)
    }
}

impl<H: HandModel> Search<'_, '_, H> {
    /// Substitutions: the free finger placed with one of the pair, the
    /// other lifted (two gaits).
    pub(super) fn substitutions(&mut self, idx: u32, node: &Node, pair: [usize; 2], z: usize) {
        let fi = self.fresh_index(&node.rem.axis);
        let from = self.hand.hover_dir(&node.hand, z);
        let t = *self.hand.timing();
        for keep_i in 0..2 {
            let (keep, lose) = (pair[keep_i], pair[1 - keep_i]);
            let c_keep = node.hand.fingers[keep].contact_normal();
            let c_lose = node.hand.fingers[lose].contact_normal();
            let chosen =
                self.placements(fi, node.rem.angle, z, (keep, lose), &c_keep, &c_lose, &from);
            for &i in chosen.iter().flatten() {
                let contact = self.hand.candidates(z)[i];
                let touch = self.fresh[fi].touch[z][i];
                let mut hand = node.hand;
                self.hand.place(&mut hand, z, &contact, touch);
                self.hand.lift(&mut hand, lose);
                let travel = (t.transfer(angle_between(&from, &contact)) - node.prev_turn).max(0.0);
                let cost = travel + 2.0 * t.vertical + t.handover;
                let place = Action::Place {
                    finger: z,
                    contact,
                    touch,
                };
                let lift = Action::Lift { finger: lose };
                self.child(
                    idx,
                    node,
                    hand,
                    node.rem,
                    cost,
                    0.0,
                    Last::Gait,
                    (place, Some(lift)),
                );
            }
        }
    }

    /// The placements of the free finger `z` to expand (force-closure
    /// with finger `keep`'s contact and holding the load with it, clear of
    /// both contacts): the best `branching` by score (rotation allowed,
    /// then travel) among those after which `lose` could come back and
    /// replace `keep` next; the best overall; and the quickest to reach.
    /// The load's limit on a placement's turn only lowers its score, so
    /// placements are scored in order of their score without it and the
    /// scoring stops where none left can make a list.
    #[allow(clippy::too_many_arguments)]
    fn placements(
        &self,
        fi: usize,
        rem: f64,
        z: usize,
        (keep, lose): (usize, usize),
        c_keep: &Vector3<f64>,
        c_lose: &Vector3<f64>,
        from: &Vector3<f64>,
    ) -> [Option<usize>; MAX_BRANCHING + 2] {
        let h = self.hand;
        let fresh = &self.fresh[fi];
        let cand = h.candidates(z);
        let flexible = |i: usize| {
            let back = h.candidates(lose);
            h.partners(z, lose, i)
                .iter()
                .any(|&j| h.apart((lose, &back[j as usize]), (keep, c_keep)))
        };
        // (score without the load's limit, candidate, range, travel)
        let mut list: Vec<(f64, usize, f64, f64)> = Vec::with_capacity(64);
        let mut quick = (f64::NEG_INFINITY, usize::MAX);
        h.resting_partners(keep, c_keep, z, &mut |i, exact| {
            let c = &cand[i];
            // The new pair must hold the load at rest where the contact
            // really is (SPEC §1.3 I1').
            if h.good_pair(c, c_keep)
                && h.apart((z, c), (keep, c_keep))
                && h.apart((z, c), (lose, c_lose))
                && (exact || h.pair_holds((keep, c_keep), (z, c), None))
            {
                let d = from.dot(c);
                // A turn beyond what is left is worth nothing.
                let range = fresh.range[z][i].min(rem);
                let travel = h.timing().transfer_cos(d);
                list.push((-range * RANGE_WEIGHT + travel, i, range, travel));
                if d > quick.0 {
                    quick = (d, i);
                }
            }
            true
        });
        list.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut top = Shortlist::new(self.params.branching);
        let mut best = (f64::INFINITY, usize::MAX);
        let load = h.load_active();
        for &(upper, i, range, travel) in &list {
            if upper >= top.bar() && upper >= best.0 {
                break;
            }
            // The pair's turn ends where it stops holding the load.
            let range = if load {
                self.hold_range((keep, c_keep), (z, &cand[i]), &fresh.axis, range)
            } else {
                range
            };
            let score = -range * RANGE_WEIGHT + travel;
            if score < best.0 {
                best = (score, i);
            }
            if score < top.bar() && flexible(i) {
                top.enter(score, i);
            }
        }
        let mut out = [None; MAX_BRANCHING + 2];
        for (o, i) in out.iter_mut().zip(top.chosen()) {
            *o = Some(i);
        }
        let mut n = top.n;
        for extra in [best.1, quick.1] {
            if extra != usize::MAX && !out[..n].contains(&Some(extra)) {
                out[n] = Some(extra);
                n += 1;
            }
        }
        out
    }

    /// Placements of the free finger `z` that make three fingers grasp,
    /// where no gait can follow the pair: those that make a force-closure
    /// pair with a grasping finger whose plane the three could tilt onto
    /// the weight soonest (the tilt about their chord that brings the
    /// weight into their plane, ranked with the travel), each checked to
    /// hold the load at rest when it comes up. On a hand whose pairs do
    /// not turn, ranked instead by the three's turn toward the goal (the
    /// least of the fingers' own ranges) now and after the grasping finger
    /// that binds first is placed anew, which needs a force-closure pair
    /// of the new finger with the other one.
    pub(super) fn places(&mut self, idx: u32, node: &Node, pair: [usize; 2], z: usize) {
        let fi = self.fresh_index(&node.rem.axis);
        let h = self.hand;
        let from = h.hover_dir(&node.hand, z);
        let (ca, cb) = contacts(&node.hand, pair);
        let down = h.weight_direction();
        let mut top = Shortlist::new(self.params.branching);
        // Where only three fingers turn, a placement is for the turns of
        // the three: as far as the least of the fingers' own ranges (the
        // two grasping asked once) — now, and after the finger that binds
        // is placed anew, which needs the new finger to make a pair with
        // the other.
        let still = !h.pairs_turn();
        let own = if still {
            let axis = &node.rem.axis;
            [
                h.touch_for(pair[0], &ca, axis).1.min(node.rem.angle),
                h.touch_for(pair[1], &cb, axis).1.min(node.rem.angle),
            ]
        } else {
            [0.0; 2]
        };
        // The grasping finger that binds first, and the other one's
        // contact and range.
        let (other_c, other_r) = if own[0] <= own[1] {
            (cb, own[1])
        } else {
            (ca, own[0])
        };
        for (i, c) in h.candidates(z).iter().enumerate() {
            if !(h.apart((z, c), (pair[0], &ca)) && h.apart((z, c), (pair[1], &cb))) {
                continue;
            }
            let tilt = [ca, cb]
                .iter()
                .filter(|x| h.good_pair(c, x))
                .map(|x| level_tilt(c, x, &down).abs())
                .fold(f64::INFINITY, f64::min);
            if !tilt.is_finite() {
                continue;
            }
            let worth = if still {
                let rz = self.fresh[fi].range[z][i].min(node.rem.angle);
                let now = rz.min(own[0]).min(own[1]);
                let next = if h.good_pair(c, &other_c) {
                    rz.min(other_r)
                } else {
                    0.0
                };
                -0.5 * (now + next)
            } else {
                tilt
            };
            let score = worth * RANGE_WEIGHT + h.timing().transfer_cos(from.dot(c));
            if score < top.bar() {
                top.enter(score, i);
            }
        }
        let t = *h.timing();
        for i in top.chosen() {
            let c = h.candidates(z)[i];
            let travel = (t.transfer(angle_between(&from, &c)) - node.prev_turn).max(0.0);
            let d = Deferred::Place {
                finger: z,
                cand: i as u32,
                fresh: fi as u32,
            };
            self.defer(idx, node, d, travel + t.vertical + t.handover);
        }
    }
}

/// The tilt about the chord of the pair at `a`, `b` (about the unit chord
/// u from b to a, right-handed) that brings the direction `down` into the
/// pair's plane through the centre, nearest zero, in (−π/2, π/2]: the
/// plane's normal ν turns as ν cos t + (u × ν) sin t.
fn level_tilt(a: &Vector3<f64>, b: &Vector3<f64>, down: &Vector3<f64>) -> f64 {
    let u = (a - b).normalize();
    let Some(nu) = a.cross(b).try_normalize(1e-12) else {
        return 0.0;
    };
    let (p, q) = (down.dot(&nu), down.dot(&u.cross(&nu)));
    // p cos t + q sin t = 0.
    let t = (-p).atan2(q);
    let half = std::f64::consts::FRAC_PI_2;
    if t > half {
        t - std::f64::consts::PI
    } else if t <= -half {
        t + std::f64::consts::PI
    } else {
        t
    }
}
