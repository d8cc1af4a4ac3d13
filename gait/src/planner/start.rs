//! Getting from the start state to a two-finger grasp (SPEC §4.3, paper §3.2
//! and Fig. 4 frames 1–2).
//!
//! Two fingers grasping: nothing to do. Three fingers grasping: lift one whose
//! removal leaves a force-closure pair. If no pair is force-closure (the
//! paper's start: three fingers 120° apart on the equator), first roll two
//! contacts apart along their great circle, each by half the missing angle
//! (paper §3.1, Fig. 1), a little past the force-closure margin, while the
//! third finger holds; then lift the third.

use nalgebra::Vector3;

use super::geometry::{Geometry, angle_between};
use super::plan::{GreatCircleRoll, Motion, Step, StepKind};
use super::search::lift_finger;
use super::timing::DurationModel;
use crate::state::{FingerMode, HandState};

/// Something done before the search's first segment.
#[derive(Debug, Clone, PartialEq)]
pub enum PrefixAction {
    /// Fingers roll on the still object (time-synchronised).
    Roll([Option<GreatCircleRoll>; 3]),
    /// A finger leaves the object.
    Lift(usize),
    /// A free finger touches down at a contact with a roll preset.
    Place {
        /// Finger.
        finger: usize,
        /// Unit contact normal.
        contact: Vector3<f64>,
        /// Roll τ at touchdown.
        roll: f64,
    },
    /// A finger follows a rolling path (rolls and spins) on the still object.
    Path(usize, Box<crate::rolling::RollingPath>),
}

/// A way to reach a two-finger grasp from the start state.
#[derive(Debug, Clone)]
pub struct Start {
    /// State after the prefix.
    pub hand: HandState,
    /// The prefix, in order.
    pub actions: Vec<PrefixAction>,
    /// Its execution time \[s\].
    pub cost: f64,
}

/// Number of samples along a roll at which its invariants are checked (on
/// top of the exact end-point checks).
const ROLL_SAMPLES: usize = 64;

/// The ways to reach a two-finger grasp (empty if none was found).
pub fn starts(g: &Geometry, timing: &DurationModel, hand: &HandState, extra: f64) -> Vec<Start> {
    match hand.grasping().1 {
        2 => vec![Start {
            hand: *hand,
            actions: Vec::new(),
            cost: 0.0,
        }],
        3 => {
            let mut out = Vec::new();
            for lose in 0..3 {
                let (i, j) = others(lose);
                let ci = hand.fingers[i].contact_normal();
                let cj = hand.fingers[j].contact_normal();
                if g.is_fc_pair(&ci, &cj) {
                    let mut h = *hand;
                    lift_finger(g, &mut h, lose);
                    out.push(Start {
                        hand: h,
                        actions: vec![PrefixAction::Lift(lose)],
                        cost: timing.vertical + timing.handover,
                    });
                }
            }
            if out.is_empty() {
                for lose in 0..3 {
                    if let Some(s) = roll_apart(g, timing, hand, lose, extra) {
                        out.push(s);
                    }
                }
            }
            out
        }
        _ => Vec::new(),
    }
}

fn others(k: usize) -> (usize, usize) {
    match k {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// Rolls the two fingers other than `lose` apart to a force-closure angle
/// (plus `extra`), then lifts `lose`. `None` if an invariant would break.
fn roll_apart(
    g: &Geometry,
    timing: &DurationModel,
    hand: &HandState,
    lose: usize,
    extra: f64,
) -> Option<Start> {
    let (i, j) = others(lose);
    let ci = hand.fingers[i].contact_normal();
    let cj = hand.fingers[j].contact_normal();
    let axis = ci.cross(&cj);
    if axis.norm() < 1e-9 {
        return None;
    }
    let w = axis.normalize();
    let half = 0.5 * (g.fc_min_angle + extra - angle_between(&ci, &cj));
    if half <= 0.0 {
        return None;
    }
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
    }
    let mut after = step.eval(&dofs.length, &[0.0; 3]).state;
    if !g.is_fc_pair(
        &after.fingers[i].contact_normal(),
        &after.fingers[j].contact_normal(),
    ) {
        return None;
    }
    let roll_time = timing.roll(dofs.length[0].max(dofs.length[1]));
    lift_finger(g, &mut after, lose);
    Some(Start {
        hand: after,
        actions: vec![PrefixAction::Roll(rolls), PrefixAction::Lift(lose)],
        cost: roll_time + timing.vertical + timing.handover,
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
    for a in 0..3 {
        for b in a + 1..3 {
            if (s.fingers[a].center - s.fingers[b].center).norm() < g.min_center_distance {
                return false;
            }
        }
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
