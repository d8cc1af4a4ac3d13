//! A sufficient test of the torque box (SPEC §14.1 "Forces"), without its
//! cone program: the closed-form grip forces of §3.3
//! ([`crate::grasp::hold::HoldModel`]: two soft contacts, or three hard
//! ones) for each load scenario, checked against every constraint of the
//! torque box's program — each scenario balanced (by construction), each
//! contact force in its friction cone (the soft contact's elliptic cone
//! with its torsion), at least `min_grip` along the normal, and every
//! joint's torque J_pᵀF + J_ωᵀM + g within its effort. Forces that meet
//! the cones and the floor are a feasible point of that program, so the
//! largest share of an effort they need bounds its optimum u* from above:
//! where that bound is ≤ 1 the grasp holds; where it is not, or the forces
//! miss a cone, it says nothing, and the planner and the plan check ask
//! the program ([`super::certify::grasp_share`]). The verdict of the two
//! together is the program's: the planner's searches and plans are the
//! same, found with fewer cone programs.

use nalgebra::Vector3;

use super::ChainHand;
use super::certify::CheckParams;
use crate::HandConfig;
use crate::grasp::hold::{Accel, HoldModel};
use crate::hand_state::{FINGERS, HandState};

/// Slack for rounding in the cone and effort tests (relative).
const ROUNDING: f64 = 1e-9;

/// The closed forms of the hand's object and friction, the floor
/// `params.min_grip`, and no disturbance (the torque box's loads are the
/// weight and the acceleration's torque only).
fn hold_model(hand: &ChainHand, params: &CheckParams) -> HoldModel {
    let mut c = HandConfig::default();
    c.model.object_radius = hand.object().radius;
    c.model.fingertip_radius = hand.chain(0).tip_radius;
    c.model.friction_angle_deg = hand.friction_mu().atan().to_degrees();
    c.load.object_mass = hand.object().mass;
    c.load.gravity = (*hand.gravity()).into();
    c.load.min_grip = params.min_grip;
    c.load.disturbance_force = 0.0;
    c.load.disturbance_torque = 0.0;
    HoldModel::new(&c)
}

/// The largest share of a motor's effort the closed-form forces need to
/// hold the grasp of `state` (at `joints`), turning about `axis` at the
/// acceleration limit or at rest — an upper bound of the torque box's u*
/// (module docs); `None` where those forces are no feasible point (a
/// cone, the floor, no closed form, a finger's joints unknown).
pub fn closed_form_share(
    hand: &ChainHand,
    state: &HandState,
    joints: &[Option<Vector3<f64>>; FINGERS],
    axis: Option<&Vector3<f64>>,
    params: &CheckParams,
) -> Option<f64> {
    let (idx, count) = state.grasping();
    if !(2..=3).contains(&count) {
        return None;
    }
    let hold = hold_model(hand, params);
    let weight = hand.gravity() * hand.object().mass;
    let accel = axis.map_or(Vector3::zeros(), |a| {
        a * (hand.inertia() * params.max_acceleration)
    });
    let n: [Vector3<f64>; FINGERS] = std::array::from_fn(|k| state.fingers[k].center.normalize());
    let mut statics = [None; FINGERS];
    for &k in &idx[..count] {
        statics[k] = Some(hand.statics(k, &joints[k]?, &n[k]));
    }
    let mu = hand.friction_mu();
    let mu_t = hand.friction_torsion();
    let signs: &[f64] = if axis.is_some() { &[1.0, -1.0] } else { &[0.0] };
    let mut share: f64 = 0.0;
    for &sign in signs {
        let loads = hold.loads_with_weight(weight, Accel::Known(accel * sign));
        let h = if count == 3 {
            hold.triple(&[n[0], n[1], n[2]], &loads)
        } else {
            hold.pair(&[n[idx[0]], n[idx[1]]], &loads)
        };
        if h.capped || !h.max_peak.is_finite() {
            return None;
        }
        for (j, &k) in idx[..count].iter().enumerate() {
            let (f, torsion) = (h.force[j], if count == 3 { 0.0 } else { h.torsion[j] });
            let normal = f.dot(&-n[k]);
            if normal < params.min_grip * (1.0 - ROUNDING) {
                return None;
            }
            let tangential = f + n[k] * normal;
            let scaled = torsion * mu / mu_t;
            let cone = tangential.norm_squared() + scaled * scaled;
            if cone > (mu * normal).powi(2) * (1.0 + ROUNDING) {
                return None;
            }
            let s = statics[k]?;
            let tau = s.force_to_torque * f + s.moment_to_torque * (-n[k] * torsion) + s.bias;
            for i in 0..3 {
                share = share.max(tau[i].abs() / s.limit[i]);
            }
        }
    }
    Some(share)
}
