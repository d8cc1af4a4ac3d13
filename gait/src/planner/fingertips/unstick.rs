//! Ways out of two-finger grasps from which no gait helps (SPEC §4.3),
//! on the still object: the regrasps the fingertips offer when the search
//! finds no other child (its turns about other axes come first).
//!
//! - Roll one grasping finger on the still object to a better contact,
//!   keeping the pair force-closure at every instant ([`roll_escapes`]).
//! - When both contacts sit at their roll limits, place the free finger so
//!   that the three contacts are force-closure, spin the two fingertips
//!   back to roll zero (spin is allowed in a three-finger hard-contact
//!   grasp, SPEC §1.2, §2.4) and lift the free finger again ([`unwind`]);
//!   under load one finger at a time, the spinner pushing along its
//!   normal only while the other two carry the rest ([`unwind_loaded`]).

use nalgebra::Vector3;

use super::super::candidates::Candidates;
use super::super::geometry::{BOUNDARY_EPS, Geometry};
use super::super::load::PairLoad;
use super::super::search::split;
use super::{StillAction, lift_finger, place_finger};
use crate::HandConfig;
use crate::contact::{ContactGeometry, ContactState};
use crate::grasp::grip::{CARRY_BITS, GripModel, spin_bit};
use crate::grasp::hold::Accel;
use crate::grasp::planar::three_hard_certificate;
use crate::hand_state::HandState;
use crate::rolling::{RollGoal, RollLimits, RollingPath, plan_roll};

/// Paper Theory 1 for a pair of contact normals: some candidate placement
/// of the free finger is force-closure with one of them, clear of both,
/// and holds the load with it (SPEC §1.3 I1'; rotating about `axis` next,
/// or at rest).
pub fn theory1(
    g: &Geometry,
    cand: &Candidates,
    load: &PairLoad,
    axis: Option<&Vector3<f64>>,
    free: usize,
    ca: &Vector3<f64>,
    cb: &Vector3<f64>,
) -> bool {
    let sep = g.cos_sep_contact - BOUNDARY_EPS;
    cand.points[free].iter().any(|c| {
        c.dot(ca) <= sep
            && c.dot(cb) <= sep
            && ((g.is_good_pair(c, ca) && load.holds(c, ca, axis))
                || (g.is_good_pair(c, cb) && load.holds(c, cb, axis)))
    })
}

/// Samples per rolling-path segment at which the pair and clearance are
/// checked (the path itself guarantees hemisphere and roll limits).
const PATH_SAMPLES: usize = 64;

/// Rolling paths of one grasping finger, on the still object, to a contact
/// where Theory 1 holds; nearest targets first, at most `keep`.
pub fn roll_escapes(
    g: &Geometry,
    cand: &Candidates,
    load: &PairLoad,
    config: &HandConfig,
    hand: &HandState,
    keep: usize,
) -> Vec<(usize, RollingPath)> {
    let Some((pair, free)) = split(hand) else {
        return Vec::new();
    };
    let cg = ContactGeometry::from_config(config);
    let limits = RollLimits::from_config(config, false);
    let mut out = Vec::new();
    for (xi, &x) in pair.iter().enumerate() {
        let y = pair[1 - xi];
        let cx = hand.fingers[x].contact_normal();
        let cy = hand.fingers[y].contact_normal();
        let Ok(contact) = ContactState::from_finger(&hand.fingers[x], hand.object, &cg) else {
            continue;
        };
        let rel = contact.relative();
        let sep = g.cos_sep_contact - BOUNDARY_EPS;
        let mut targets: Vec<(f64, Vector3<f64>)> = cand.points[x]
            .iter()
            .filter(|t| g.is_good_pair(t, &cy) && t.dot(&cy) <= sep && load.holds(t, &cy, None))
            .filter(|t| theory1(g, cand, load, None, free, t, &cy))
            .map(|t| (-t.dot(&cx), *t))
            .collect();
        targets.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, t) in targets.iter().take(12) {
            let goal = RollGoal {
                target: hand.object.inverse() * t,
                final_roll: None,
            };
            let Ok(path) = plan_roll(&cg, &rel, &goal, &limits) else {
                continue;
            };
            if path_ok(g, load, hand, x, y, free, &path) {
                out.push((x, path));
                break;
            }
        }
        if out.len() >= keep {
            break;
        }
    }
    out
}

/// Whether the rolling contact of finger `x` stays in its cone,
/// force-closure with `y` and clear of the other fingertips.
fn path_ok(
    g: &Geometry,
    load: &PairLoad,
    hand: &HandState,
    x: usize,
    y: usize,
    free: usize,
    path: &RollingPath,
) -> bool {
    let q_o = hand.object;
    let cy = hand.fingers[y].contact_normal();
    let others = [hand.fingers[y].center, hand.fingers[free].center];
    let n = PATH_SAMPLES * path.len().max(1);
    (0..=n).all(|i| {
        let s = path.length() * i as f64 / n as f64;
        let c = q_o * path.eval(s).contact;
        g.in_cone(x, &c)
            && g.is_fc_pair(&c, &cy)
            && load.holds(&c, &cy, None)
            && others
                .iter()
                .all(|o| (c * g.contact_radius - o).norm() >= g.min_center_distance)
    })
}

/// What [`unwind`] does and where it ends.
#[derive(Debug, Clone)]
pub struct Unwound {
    /// Place the free finger, spin, spin, lift it.
    pub actions: Vec<StillAction>,
    /// The two-finger state afterwards (same contacts, rolls near zero).
    pub hand: HandState,
}

/// The three-finger unwind (module docs), if a placement of the free finger
/// makes the three contacts force-closure (planar certificate at θ − margin/2)
/// and both spins are possible.
///
/// With `spin` false (under load, SPEC §1.3 I1': a contact spinning on the
/// object has no friction left, its coupled cone used up by the spin's
/// torsion, and the other two cannot carry the weight alone) the fingers
/// do not spin: the free finger is placed and lifted again, a relocation
/// that the escapes start from.
pub fn unwind(
    g: &Geometry,
    cand: &Candidates,
    grip: &GripModel,
    config: &HandConfig,
    hand: &HandState,
    spin: bool,
) -> Option<Unwound> {
    let (pair, free) = split(hand)?;
    let (ca, cb) = (
        hand.fingers[pair[0]].contact_normal(),
        hand.fingers[pair[1]].contact_normal(),
    );
    let theta = (config.model.friction_angle_deg - 0.5 * config.model.fc_margin_deg).to_radians();
    let sep = g.cos_sep_contact - BOUNDARY_EPS;
    let from = hand.fingers[free].center.normalize();
    // The force-closure placement nearest to where the free finger is.
    let contact = cand.points[free]
        .iter()
        .filter(|c| c.dot(&ca) <= sep && c.dot(&cb) <= sep)
        .filter(|c| three_hard_certificate(&[ca, cb, **c], theta).is_some_and(|m| m > 1e-6))
        .filter(|c| {
            // The three, hard contacts, hold the load while the pair spins
            // (SPEC §1.3 I1').
            let hold = grip.hold();
            hold.triple(&[ca, cb, **c], &hold.loads(Accel::None))
                .feasible
        })
        .max_by(|a, b| a.dot(&from).total_cmp(&b.dot(&from)))?;
    let mut h = *hand;
    place_finger(g, &mut h, free, contact, 0.0);
    let mut actions = vec![StillAction::Place {
        finger: free,
        contact: *contact,
        roll: 0.0,
    }];
    let cg = ContactGeometry::from_config(config);
    for &k in pair.iter().filter(|_| spin) {
        let f = h.fingers[k];
        let state = ContactState::from_finger(&f, h.object, &cg).ok()?;
        let mut path = RollingPath::new(cg, state.relative());
        path.push_spin_roll(-f.roll).ok()?;
        if path.margins().max_abs_roll > g.roll_limit + 1e-9 {
            return None;
        }
        let end = path.eval(path.length());
        h.fingers[k] = end.finger_state(&h.object, &cg);
        actions.push(StillAction::Path(k, Box::new(path)));
    }
    lift_finger(g, &mut h, free);
    actions.push(StillAction::Lift(free));
    Some(Unwound { actions, hand: h })
}

/// Rolls smaller than this are not worth a spin \[rad\].
const UNWIND_MIN_ROLL: f64 = 1e-3;

/// The unwind under load (SPEC §1.3 I1'): the free finger touches down
/// where the three contacts hold the load at rest and, for each grasping
/// finger in turn, with that finger spinning — pushing along its normal
/// only, its cone used up by the spin's torsion, while the other two
/// carry the rest ([`crate::grasp::HoldModel::spinning`]); the fingers that
/// can spin back to roll zero do, one after the other, and the free finger
/// lifts again. `None` if no finger can spin.
pub fn unwind_loaded(
    g: &Geometry,
    cand: &Candidates,
    grip: &GripModel,
    config: &HandConfig,
    hand: &HandState,
) -> Option<Unwound> {
    let (pair, free) = split(hand)?;
    let (ca, cb) = (
        hand.fingers[pair[0]].contact_normal(),
        hand.fingers[pair[1]].contact_normal(),
    );
    let sep = g.cos_sep_contact - BOUNDARY_EPS;
    let cg = ContactGeometry::from_config(config);
    // The spins each finger would make (path), if its roll is worth one.
    let spins: Vec<(usize, RollingPath)> = pair
        .iter()
        .filter(|&&k| hand.fingers[k].roll.abs() >= UNWIND_MIN_ROLL)
        .filter_map(|&k| {
            let f = hand.fingers[k];
            let state = ContactState::from_finger(&f, hand.object, &cg).ok()?;
            let mut path = RollingPath::new(cg, state.relative());
            path.push_spin_roll(-f.roll).ok()?;
            (path.margins().max_abs_roll <= g.roll_limit + 1e-9).then_some((k, path))
        })
        .collect();
    if spins.is_empty() {
        return None;
    }
    let from = hand.fingers[free].center.normalize();
    // The placement that lets the most fingers spin; among those, the one
    // where the spinners need to press least (a spinner's torsional
    // friction twists the object: MuJoCo's soft contacts let the others
    // slip when it is large), then the nearest.
    // (fingers that can spin, their mask, largest push, nearness, contact,
    // state after the placement)
    let mut best: Option<(u32, u8, f64, f64, Vector3<f64>, HandState)> = None;
    for c in cand.points[free]
        .iter()
        .filter(|c| c.dot(&ca) <= sep && c.dot(&cb) <= sep)
    {
        let mut h = *hand;
        place_finger(g, &mut h, free, c, 0.0);
        if !grip.carried_with(&h, Accel::None, CARRY_BITS).feasible {
            continue;
        }
        let (mut mask, mut push) = (0u8, 0.0f64);
        for (k, _) in &spins {
            let g = grip.carried_with(&h, Accel::None, CARRY_BITS | spin_bit(*k));
            if g.feasible {
                mask |= 1 << k;
                push = push.max(g.normal[*k]);
            }
        }
        let (n, near) = (mask.count_ones(), c.dot(&from));
        let better = |b: &(u32, u8, f64, f64, Vector3<f64>, HandState)| {
            n > b.0 || (n == b.0 && (push < b.2 - 1e-6 || (push <= b.2 + 1e-6 && near > b.3)))
        };
        if n > 0 && best.as_ref().is_none_or(better) {
            best = Some((n, mask, push, near, *c, h));
        }
    }
    let (_, mask, _, _, contact, mut h) = best?;
    let mut actions = vec![StillAction::Place {
        finger: free,
        contact,
        roll: 0.0,
    }];
    for (k, path) in spins.into_iter().filter(|(k, _)| mask & (1 << k) != 0) {
        h.fingers[k] = path.eval(path.length()).finger_state(&h.object, &cg);
        actions.push(StillAction::Spin(k, Box::new(path)));
    }
    lift_finger(g, &mut h, free);
    actions.push(StillAction::Lift(free));
    Some(Unwound { actions, hand: h })
}

/// Where three fingers already grasp: each finger whose roll is worth it
/// spins back to roll zero on the still object while the other two carry
/// — without a load freely (spin is allowed with three hard contacts,
/// SPEC §1.2); under load (`loaded`) pushing along its normal only, the
/// other two holding the rest, and only where that holds. `None` if no
/// finger can.
pub fn unwind_triple(
    g: &Geometry,
    grip: &GripModel,
    config: &HandConfig,
    hand: &HandState,
    loaded: bool,
) -> Option<Unwound> {
    if hand.grasping().1 != 3 {
        return None;
    }
    let cg = ContactGeometry::from_config(config);
    let mut h = *hand;
    let mut actions = Vec::new();
    for k in 0..3 {
        let f = h.fingers[k];
        if f.roll.abs() < UNWIND_MIN_ROLL {
            continue;
        }
        if loaded
            && !grip
                .carried_with(&h, Accel::None, CARRY_BITS | spin_bit(k))
                .feasible
        {
            continue;
        }
        let Ok(state) = ContactState::from_finger(&f, h.object, &cg) else {
            continue;
        };
        let mut path = RollingPath::new(cg, state.relative());
        if path.push_spin_roll(-f.roll).is_err()
            || path.margins().max_abs_roll > g.roll_limit + 1e-9
        {
            continue;
        }
        h.fingers[k] = path.eval(path.length()).finger_state(&h.object, &cg);
        actions.push(if loaded {
            StillAction::Spin(k, Box::new(path))
        } else {
            StillAction::Path(k, Box::new(path))
        });
    }
    (!actions.is_empty()).then_some(Unwound { actions, hand: h })
}
