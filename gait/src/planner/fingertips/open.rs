//! Rolling a pair of the three grasping fingertips apart (SPEC §4.3,
//! paper §3.2 and Fig. 4 frames 1–2): the regrasp offered when three
//! fingers grasp and no pair of them is force-closure (the paper's start:
//! three fingers 120° apart on the equator) or holds the load.
//!
//! The two fingers other than the one that will lift roll their contacts
//! apart along their common great circle, each by half the missing angle
//! (paper §3.1, Fig. 1), a little past the force-closure margin, while the
//! third holds. Under load (SPEC §1.3 I1') the pair must open until it
//! holds the weight — at the paper start beyond one great-circle roll's
//! reach, so each finger rolls there in up to three legs
//! ([`super::super::zigzag`]); the opening that holds at rest is offered
//! beside the one that also holds turning about the next rotation's axis.

use nalgebra::Vector3;

use super::super::collision;
use super::super::geometry::{Geometry, angle_between, rotation};
use super::super::load::{self, PairLoad};
use super::super::plan::{GreatCircleRoll, Motion, Step, StepKind};
use super::super::timing::DurationModel;
use super::super::zigzag::ZigzagCache;
use super::{StillAction, lift_finger};
use crate::HandConfig;
use crate::contact::{ContactGeometry, ContactState};
use crate::grasp::grip::GripModel;
use crate::grasp::hold::Accel;
use crate::hand_state::{FingerMode, HandState};
use crate::rolling::{RollGoal, RollLimits, SegmentKind, plan_roll};

/// A pair rolled apart: the three-finger state after it, the rolls, their
/// time, and whether they needed several legs.
#[derive(Debug, Clone)]
pub struct Opened {
    /// State after the rolls (three fingers still grasp).
    pub hand: HandState,
    /// The rolls, in order.
    pub actions: Vec<StillAction>,
    /// Their execution time \[s\].
    pub cost: f64,
    /// Whether a finger rolled in several legs (beyond one great circle).
    pub legs: bool,
}

/// Number of samples along a roll at which its invariants are checked (on
/// top of the exact end-point checks).
const ROLL_SAMPLES: usize = 64;
// The plan check's samples are among these (the load is tested at them).
const _: () = assert!(ROLL_SAMPLES.is_multiple_of(load::ROLL_SAMPLES));

/// The ways to roll the two fingers other than `lose` apart so that `lose`
/// can lift (empty if none was found). Under load (SPEC §1.3 I1') the pair
/// left must hold it: the roll goes on until it does (turning about any
/// axis when the cones allow, else at rest); beyond one great-circle
/// roll's reach in several legs. `extra`: the opening beyond the
/// force-closure margin aimed for at least. Nothing here depends on the
/// goal: what rolls from a state are searched once and kept.
#[allow(clippy::too_many_arguments)]
pub fn open(
    g: &Geometry,
    timing: &DurationModel,
    load: &PairLoad,
    grip: &GripModel,
    config: &HandConfig,
    zigzags: &ZigzagCache,
    hand: &HandState,
    lose: usize,
    extra: f64,
) -> Vec<Opened> {
    let mut out = Vec::new();
    for want in holding_extras(g, load, grip, hand, lose, extra) {
        match roll_apart(g, timing, load.active().then_some(grip), hand, lose, want) {
            Some(s) if pair_holds(g, load, grip, &s.hand, lose) => out.push(s),
            // Beyond a great-circle roll's reach (the fingertip
            // hemisphere): rolling paths of several legs.
            _ => out.extend(
                roll_paths_apart(g, timing, grip, config, zigzags, hand, lose, want)
                    .filter(|s| pair_holds(g, load, grip, &s.hand, lose)),
            ),
        }
    }
    out
}

/// A lower bound of the time of any opening for `lose` to lift: the
/// great-circle roll to the force-closure margin \[s\].
pub fn bound(g: &Geometry, timing: &DurationModel, hand: &HandState, lose: usize) -> f64 {
    let (i, j) = others(lose);
    let ci = hand.fingers[i].contact_normal();
    let cj = hand.fingers[j].contact_normal();
    let half = 0.5 * (g.fc_min_angle - angle_between(&ci, &cj)).max(0.0);
    timing.roll(half * g.contact_radius / g.fingertip_radius)
}

/// The least extra separations (≥ `extra`, 1° steps) after which the pair
/// the roll apart leaves holds the load turning about any axis, and the
/// smaller one after which it holds the load at rest (the search then
/// relocates the free finger before it rotates: a shorter roll may pay);
/// just `extra` if nothing does.
fn holding_extras(
    g: &Geometry,
    load: &PairLoad,
    grip: &GripModel,
    hand: &HandState,
    lose: usize,
    extra: f64,
) -> Vec<f64> {
    if !load.active() {
        return vec![extra];
    }
    let (i, j) = others(lose);
    let ci = hand.fingers[i].contact_normal();
    let cj = hand.fingers[j].contact_normal();
    let w = ci.cross(&cj);
    if w.norm() < 1e-9 {
        return vec![extra];
    }
    let w = w.normalize();
    let base = g.fc_min_angle - angle_between(&ci, &cj);
    let step = 1f64.to_radians();
    let pair_at = |x: f64| {
        let half = 0.5 * (base + x);
        (rotation(&w, -half) * ci, rotation(&w, half) * cj)
    };
    let in_cones = |a: &Vector3<f64>, b: &Vector3<f64>| g.in_cone(i, a) && g.in_cone(j, b);
    let mut rotating = None;
    let mut x = extra;
    while x < std::f64::consts::PI - g.fc_min_angle {
        let (a, b) = pair_at(x);
        if !in_cones(&a, &b) {
            break;
        }
        if load.holds_turning(&a, &b) {
            rotating = Some(x);
            break;
        }
        x += step;
    }
    let mut x = extra;
    while x < rotating.unwrap_or(std::f64::consts::PI - g.fc_min_angle) {
        let (a, b) = pair_at(x);
        if !in_cones(&a, &b) {
            break;
        }
        let mut h = *hand;
        h.fingers[i].center = a * g.contact_radius;
        h.fingers[j].center = b * g.contact_radius;
        lift_finger(g, &mut h, lose);
        if grip.carried_with(&h, Accel::None, 0b111).feasible {
            return rotating.into_iter().chain([x]).collect();
        }
        x += step;
    }
    rotating.map_or_else(|| vec![extra], |x| vec![x])
}

/// Whether the pair left when `lose` lifts from `hand` holds the load,
/// turning about any axis or at least at rest (exact).
fn pair_holds(
    g: &Geometry,
    load: &PairLoad,
    grip: &GripModel,
    hand: &HandState,
    lose: usize,
) -> bool {
    if !load.active() {
        return true;
    }
    let (i, j) = others(lose);
    let (a, b) = (
        hand.fingers[i].contact_normal(),
        hand.fingers[j].contact_normal(),
    );
    if load.holds_turning(&a, &b) {
        return true;
    }
    let mut h = *hand;
    lift_finger(g, &mut h, lose);
    grip.carried_with(&h, Accel::None, 0b111).feasible
}

/// Samples per rolling path at which [`roll_paths_apart`] checks the three
/// fingers (the plan's exact check samples every step again).
const PATH_SAMPLES: usize = 6;

/// Like [`roll_apart`], beyond a great-circle roll's reach (the fingertip
/// hemisphere, SPEC §2.4): each of the two fingers rolls in great-circle
/// legs to half the separation wanted while the other fingers hold — the
/// quickest three legs found ([`super::super::zigzag`]), else the rolling
/// planner's Fig. 2 paths (paper Fig. 3) — the two fingers in the
/// quickest order of their legs ([`pair_legs`]). Every sample keeps the three in their cones, clear of each other,
/// force-closure (Fact 4 or a force-closure pair) and holding the load as
/// hard contacts.
#[allow(clippy::too_many_arguments)]
fn roll_paths_apart(
    g: &Geometry,
    timing: &DurationModel,
    grip: &GripModel,
    config: &HandConfig,
    zigzags: &ZigzagCache,
    hand: &HandState,
    lose: usize,
    extra: f64,
) -> Option<Opened> {
    let (i, j, w, half) = opening(g, hand, lose, extra)?;
    let targets = [
        rotation(&w, -half) * hand.fingers[i].contact_normal(),
        rotation(&w, half) * hand.fingers[j].contact_normal(),
    ];
    // The quickest legs found (zigzag), else the rolling planner's Fig. 2
    // paths; each must pass the three-finger checks.
    if let Some(z) = zigzag_legs(g, timing, zigzags, hand, [i, j], &targets)
        && let Some(s) = roll_legs_apart(g, grip, timing, hand, [i, j], &z)
    {
        return Some(s);
    }
    let legs = fig2_legs(g, config, hand, [i, j], &targets)?;
    roll_legs_apart(g, grip, timing, hand, [i, j], &legs)
}

/// Each rolling finger's legs to its target by [`zigzag`].
fn zigzag_legs(
    g: &Geometry,
    timing: &DurationModel,
    zigzags: &ZigzagCache,
    hand: &HandState,
    fingers: [usize; 2],
    targets: &[Vector3<f64>; 2],
) -> Option<[Vec<GreatCircleRoll>; 2]> {
    let mut legs: [Vec<GreatCircleRoll>; 2] = [Vec::new(), Vec::new()];
    for (slot, (&k, target)) in fingers.iter().zip(targets).enumerate() {
        let f = &hand.fingers[k];
        let z = zigzags.zigzag(
            g,
            timing,
            k,
            &f.contact_normal(),
            &f.pole_axis(),
            f.roll,
            target,
        )?;
        legs[slot] = z
            .legs
            .iter()
            .flatten()
            .map(|l| GreatCircleRoll {
                finger: k,
                axis: l.axis,
                angle: l.angle,
            })
            .collect();
    }
    Some(legs)
}

/// Each rolling finger's legs to its target: the rolling planner's path
/// (paper Fig. 3), which must be pure great-circle rolls.
fn fig2_legs(
    g: &Geometry,
    config: &HandConfig,
    hand: &HandState,
    fingers: [usize; 2],
    targets: &[Vector3<f64>; 2],
) -> Option<[Vec<GreatCircleRoll>; 2]> {
    let cg = ContactGeometry::from_config(config);
    let limits = RollLimits::from_config(config, true);
    let ratio = g.contact_radius / g.fingertip_radius;
    let mut legs: [Vec<GreatCircleRoll>; 2] = [Vec::new(), Vec::new()];
    for (slot, (&k, target)) in fingers.iter().zip(targets).enumerate() {
        let state = ContactState::from_finger(&hand.fingers[k], hand.object, &cg).ok()?;
        let goal = RollGoal {
            target: hand.object.inverse() * target,
            final_roll: None,
        };
        let path = plan_roll(&cg, &state.relative(), &goal, &limits).ok()?;
        for seg in path.segments() {
            if seg.kind != SegmentKind::Roll {
                return None;
            }
            legs[slot].push(GreatCircleRoll {
                finger: k,
                axis: hand.object * seg.axis,
                angle: seg.length / ratio,
            });
        }
    }
    Some(legs)
}

/// The two fingers' legs, rolled in the quickest order of [`pair_legs`]
/// (else the i-th legs together), every sample checked (docs of
/// [`roll_paths_apart`]).
fn roll_legs_apart(
    g: &Geometry,
    grip: &GripModel,
    timing: &DurationModel,
    hand: &HandState,
    [i, j]: [usize; 2],
    legs: &[Vec<GreatCircleRoll>; 2],
) -> Option<Opened> {
    let ratio = g.contact_radius / g.fingertip_radius;
    let tip_angles = legs
        .each_ref()
        .map(|l| l.iter().map(|r| r.angle.abs() * ratio).collect());
    let paired = pair_legs(&tip_angles, |x| timing.roll(x));
    roll_paired(g, grip, timing, hand, [i, j], legs, &paired).or_else(|| {
        // A sample of the quickest order fails its check: the legs side by
        // side, as found.
        let side_by_side: Vec<_> = (0..legs[0].len().max(legs[1].len()))
            .map(|n| {
                [
                    (n < legs[0].len()).then_some(n),
                    (n < legs[1].len()).then_some(n),
                ]
            })
            .collect();
        (side_by_side != paired)
            .then(|| roll_paired(g, grip, timing, hand, [i, j], legs, &side_by_side))
            .flatten()
    })
}

/// The order in which two fingers roll their legs: each step rolls the
/// next leg of one finger, or of both at once (time-synchronised, as long
/// as the longer one), every leg once and in order. Of those orders, the
/// quickest, when a step takes `time` of its longer fingertip rotation
/// (rest to rest): an alignment of the two sequences, found by dynamic
/// programming over where each finger has got to (rolling the i-th legs
/// together makes a short leg wait for the other finger's long one).
fn pair_legs(tips: &[Vec<f64>; 2], time: impl Fn(f64) -> f64) -> Vec<[Option<usize>; 2]> {
    let (na, nb) = (tips[0].len(), tips[1].len());
    // best[x][y]: quickest time having rolled x legs of the first finger
    // and y of the second, and the step that got there.
    let mut best = vec![vec![(f64::INFINITY, [None; 2]); nb + 1]; na + 1];
    best[0][0].0 = 0.0;
    for x in 0..=na {
        for y in 0..=nb {
            let t = best[x][y].0;
            let mut relax = |x2: usize, y2: usize, step: [Option<usize>; 2], dt: f64| {
                if t + dt < best[x2][y2].0 {
                    best[x2][y2] = (t + dt, step);
                }
            };
            if x < na {
                relax(x + 1, y, [Some(x), None], time(tips[0][x]));
            }
            if y < nb {
                relax(x, y + 1, [None, Some(y)], time(tips[1][y]));
            }
            if x < na && y < nb {
                relax(
                    x + 1,
                    y + 1,
                    [Some(x), Some(y)],
                    time(tips[0][x].max(tips[1][y])),
                );
            }
        }
    }
    let (mut x, mut y) = (na, nb);
    let mut steps = Vec::with_capacity(na + nb);
    while x + y > 0 {
        let step = best[x][y].1;
        steps.push(step);
        x -= usize::from(step[0].is_some());
        y -= usize::from(step[1].is_some());
    }
    steps.reverse();
    steps
}

/// [`roll_legs_apart`] in the order `paired` ([`pair_legs`]).
#[allow(clippy::too_many_arguments)]
fn roll_paired(
    g: &Geometry,
    grip: &GripModel,
    timing: &DurationModel,
    hand: &HandState,
    [i, j]: [usize; 2],
    legs: &[Vec<GreatCircleRoll>; 2],
    paired: &[[Option<usize>; 2]],
) -> Option<Opened> {
    let ratio = g.contact_radius / g.fingertip_radius;
    let hold = grip.hold();
    let loads = hold.loads(Accel::None);
    let mut h = *hand;
    let mut actions = Vec::with_capacity(paired.len() + 1);
    let mut cost = 0.0;
    for [a, b] in paired {
        let mut rolls = [None; 3];
        rolls[0] = a.map(|n| legs[0][n]);
        rolls[1] = b.map(|n| legs[1][n]);
        let step = Step {
            kind: StepKind::Roll,
            start: h,
            motion: Motion::Roll { rolls, ratio },
            duration: 0.0,
            handover: None,
        };
        let dofs = step.dofs();
        for sample in 0..=PATH_SAMPLES {
            let lam = sample as f64 / PATH_SAMPLES as f64;
            let x = step.eval(&dofs.length.map(|l| l * lam), &[0.0; 3]).state;
            for k in [i, j] {
                let f = &x.fingers[k];
                if !g.in_cone(k, &f.contact_normal()) || f.fingertip_contact().z < -1e-9 {
                    return None;
                }
            }
            if !collision::centers_clear(g, &x) {
                return None;
            }
            let nn = x.fingers.map(|f| f.contact_normal());
            let fc = fact4(g, &nn[0], &nn[1], &nn[2])
                || (0..3).any(|a| g.is_fc_pair(&nn[a], &nn[(a + 1) % 3]));
            if !fc || !hold.triple(&nn, &loads).feasible {
                return None;
            }
        }
        cost += timing.roll(dofs.length[0].max(dofs.length[1]));
        h = step.eval(&dofs.length, &[0.0; 3]).state;
        actions.push(StillAction::Roll(rolls));
    }
    if !g.is_fc_pair(
        &h.fingers[i].contact_normal(),
        &h.fingers[j].contact_normal(),
    ) || h.fingers.iter().any(|f| f.roll.abs() > g.roll_limit + 1e-9)
    {
        return None;
    }
    Some(Opened {
        hand: h,
        legs: actions.len() > 1,
        actions,
        cost,
    })
}

fn others(k: usize) -> (usize, usize) {
    match k {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// The two fingers other than `lose` (i, j), the unit normal w of their
/// plane and the half angle each must roll to open their separation to a
/// force-closure angle plus `extra`; `None` when they are (anti)parallel
/// or already far enough apart.
fn opening(
    g: &Geometry,
    hand: &HandState,
    lose: usize,
    extra: f64,
) -> Option<(usize, usize, Vector3<f64>, f64)> {
    let (i, j) = others(lose);
    let ci = hand.fingers[i].contact_normal();
    let cj = hand.fingers[j].contact_normal();
    let axis = ci.cross(&cj);
    if axis.norm() < 1e-9 {
        return None;
    }
    let half = 0.5 * (g.fc_min_angle + extra - angle_between(&ci, &cj));
    (half > 0.0).then(|| (i, j, axis.normalize(), half))
}

/// Rolls the two fingers other than `lose` apart to a force-closure angle
/// (plus `extra`). `None` if an invariant would break — with `grip`, the
/// load held by the three at every sample too.
fn roll_apart(
    g: &Geometry,
    timing: &DurationModel,
    grip: Option<&GripModel>,
    hand: &HandState,
    lose: usize,
    extra: f64,
) -> Option<Opened> {
    let (i, j, w, half) = opening(g, hand, lose, extra)?;
    // c_j = Rot(w, α) c_i: turning c_i by −δ and c_j by +δ opens the angle.
    let rolls = {
        let mut r = [None; 3];
        r[0] = Some(GreatCircleRoll {
            finger: i,
            axis: w,
            angle: -half,
        });
        r[1] = Some(GreatCircleRoll {
            finger: j,
            axis: w,
            angle: half,
        });
        r
    };
    let ratio = g.contact_radius / g.fingertip_radius;
    let step = Step {
        kind: StepKind::Roll,
        start: *hand,
        motion: Motion::Roll { rolls, ratio },
        duration: 0.0,
        handover: None,
    };
    let dofs = step.dofs();
    for sample in 0..=ROLL_SAMPLES {
        let lam = sample as f64 / ROLL_SAMPLES as f64;
        let s = dofs.length.map(|l| l * lam);
        let state = step.eval(&s, &[0.0; 3]).state;
        if !roll_state_ok(g, &state, [i, j]) {
            return None;
        }
        // Under load the three carry it while two roll: as hard contacts,
        // at the samples of the plan's check (`load::check_steps`).
        if sample.is_multiple_of(ROLL_SAMPLES / load::ROLL_SAMPLES)
            && grip.is_some_and(|m| !m.triple(&state, Accel::None).feasible)
        {
            return None;
        }
    }
    let after = step.eval(&dofs.length, &[0.0; 3]).state;
    if !g.is_fc_pair(
        &after.fingers[i].contact_normal(),
        &after.fingers[j].contact_normal(),
    ) {
        return None;
    }
    Some(Opened {
        hand: after,
        actions: vec![StillAction::Roll(rolls)],
        cost: timing.roll(dofs.length[0].max(dofs.length[1])),
        legs: false,
    })
}

/// Invariants a three-finger state must keep while two fingers roll:
/// cones, fingertip hemisphere and roll limit for the rolling fingers,
/// clearance, and force closure by Fact 4 (paper §3.1).
fn roll_state_ok(g: &Geometry, s: &HandState, rolling: [usize; 2]) -> bool {
    for &k in &rolling {
        let f = &s.fingers[k];
        if f.mode != FingerMode::Grasping || !g.in_cone(k, &f.contact_normal()) {
            return false;
        }
        if f.fingertip_contact().z < 0.0 || f.roll.abs() > g.roll_limit {
            return false;
        }
    }
    if !collision::centers_clear(g, s) {
        return false;
    }
    let n = s.fingers.map(|f| f.contact_normal());
    fact4(g, &n[0], &n[1], &n[2])
}

/// Fact 4 (paper §3.1): three hard contacts on a sphere are force-closure if
/// their triangle is acute and O is closer than R sin θ to its plane.
/// (Normalised by R: the plane distance is compared with sin θ.)
pub fn fact4(g: &Geometry, a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> bool {
    let acute = |p: &Vector3<f64>, q: &Vector3<f64>, r: &Vector3<f64>| (q - p).dot(&(r - p)) > 0.0;
    if !(acute(a, b, c) && acute(b, c, a) && acute(c, a, b)) {
        return false;
    }
    let normal = (b - a).cross(&(c - a));
    let dist = normal.dot(a).abs() / normal.norm();
    dist < g.friction_angle.sin()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Time of the steps `p` over the fingertip rotations `tips`.
    fn cost(tips: &[Vec<f64>; 2], p: &[[Option<usize>; 2]], time: impl Fn(f64) -> f64) -> f64 {
        p.iter()
            .map(|[a, b]| {
                time(
                    a.map_or(0.0, |n| tips[0][n])
                        .max(b.map_or(0.0, |n| tips[1][n])),
                )
            })
            .sum()
    }

    #[test]
    fn legs_are_paired_in_the_quickest_order() {
        // A zigzag with a short first leg beside one without it (as found
        // after a three-finger turn): side by side, the short leg waits for
        // the other finger's long one and every later leg is mismatched.
        let timing = DurationModel::new(&HandConfig::default());
        let time = |x: f64| timing.roll(x);
        let tips = [vec![0.05, 1.6, 1.1], vec![1.6, 1.1]];
        let paired = pair_legs(&tips, time);
        assert_eq!(
            paired,
            vec![[Some(0), None], [Some(1), Some(0)], [Some(2), Some(1)]]
        );
        let side_by_side = [[Some(0), Some(0)], [Some(1), Some(1)], [Some(2), None]];
        assert!(cost(&tips, &paired, time) + 0.3 < cost(&tips, &side_by_side, time));
        // Every leg once, in order, on random lengths; never slower than
        // side by side.
        for seed in 0..200u32 {
            let mut x = seed.wrapping_mul(2_654_435_761);
            let mut next = || {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                f64::from(x % 1000) / 500.0
            };
            let (na, nb) = (1 + (seed % 3) as usize, 1 + (seed / 3 % 3) as usize);
            let tips = [
                (0..na).map(|_| next()).collect(),
                (0..nb).map(|_| next()).collect(),
            ];
            let p = pair_legs(&tips, time);
            for (side, n) in [(0, na), (1, nb)] {
                let order: Vec<usize> = p.iter().filter_map(|s| s[side]).collect();
                assert_eq!(order, (0..n).collect::<Vec<_>>(), "seed {seed}");
            }
            let side: Vec<[Option<usize>; 2]> = (0..na.max(nb))
                .map(|n| [(n < na).then_some(n), (n < nb).then_some(n)])
                .collect();
            assert!(
                cost(&tips, &p, time) <= cost(&tips, &side, time) + 1e-12,
                "seed {seed}"
            );
        }
    }
}
