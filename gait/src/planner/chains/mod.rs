//! A hand of finger chains as the planner sees it (SPEC §14): three
//! 3-joint fingers with closed-form inverse kinematics (TriFingerPro and
//! hands like it), a sphere whose centre is a fixed point of the hand
//! frame, and the limits of §14.1 a grasp must keep.
//!
//! The hand itself ([`ChainHand`]: its chains, the joints of a tip
//! centre, its statics) is [`crate::hand`]'s; here is what planning on it
//! needs: its model behind the search's boundary ([`model`]), the plan's
//! steps ([`steps`]), the load along carries ([`carry_load`]), a quick sufficient
//! load test ([`quick_hold`]) and the planner ([`planner`]).
//!
//! [`certify`] is the exact check of a plan on chains: every sample of
//! every step against §14.1 and the load under the torque box.

pub mod carry_load;
pub mod certify;
pub mod model;
pub mod planner;
pub mod quick_hold;
pub mod steps;

pub use crate::hand::{ChainHand, ChainHandError};
