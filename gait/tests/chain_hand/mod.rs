//! Shared by the tests on TriFingerPro's chains: the planner's settings
//! for the shipped hand holding the tennis ball, its model and planner,
//! and a start grasp. (Each test binary declares `common`, the kinematics
//! tests' module with the shipped description, beside this one.)
#![allow(dead_code)]

use gait::planner::chains::ChainHand;
use gait::planner::chains::model::ChainModel;
use gait::planner::chains::planner::ChainPlanner;
use gait::{FingerMode, HandConfig, HandState};
use kinematics::HandDescription;
use nalgebra::{UnitQuaternion, Vector3};

use crate::common;

/// Motion limits for a hand this size: the ball turns at up to 1 rad/s,
/// a free tip travels at up to 0.1 m/s, 15 mm above the ball; 3000
/// expansions a plan.
pub fn config() -> HandConfig {
    let mut c = HandConfig::default();
    c.limits.fingertip.velocity = 0.1;
    c.limits.fingertip.acceleration = 1.0;
    c.limits.fingertip.jerk = 10.0;
    c.planner.transfer_height = 0.015;
    c.planner.max_expansions = 3000;
    c
}

/// The chain hand of a description, with the tests' margins.
pub fn hand_of(d: &HandDescription) -> ChainHand {
    ChainHand::new(d, common::LIMITS).expect("TriFingerPro is a chain hand")
}

/// The shipped hand.
pub fn hand() -> ChainHand {
    hand_of(&common::hand())
}

/// The planner's model of the shipped hand.
pub fn model() -> ChainModel {
    ChainModel::new(hand(), &config())
}

/// The planner of a description's hand.
pub fn planner_with(d: &HandDescription) -> ChainPlanner {
    ChainPlanner::new(ChainModel::new(hand_of(d), &config()))
}

/// The planner of the shipped hand.
pub fn planner() -> ChainPlanner {
    planner_with(&common::hand())
}

/// Finger 0 near the ball's top, finger 1 below the equator on its side,
/// finger 2 above it on the other: pairs (0, 1) and (1, 2) are
/// force-closure and hold the ball, so either outer finger can lift.
pub fn start(m: &ChainModel) -> HandState {
    let normals = [
        Vector3::new(-0.07, 0.07, 1.0),
        Vector3::new(0.55, -0.57, -0.61),
        Vector3::new(-0.64, 0.66, 0.40),
    ];
    let mut s = HandState::paper_start(&config());
    for (k, f) in s.fingers.iter_mut().enumerate() {
        let r = m.hand().object().radius + m.hand().chain(k).tip_radius;
        f.mode = FingerMode::Grasping;
        f.center = normals[k].normalize() * r;
    }
    s.object = UnitQuaternion::identity();
    s
}
