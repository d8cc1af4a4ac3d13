//! The hand model and its invariants (SPEC.md §1.1, §1.3).
//!
//! - [`FingertipLimits`]: the geometry of one validated [`crate::HandConfig`] —
//!   workspace cones W_k, the free-space shell, the fingertip hemisphere,
//!   the roll limit γ, fingertip collision, contact consistency and the
//!   force-closure closed forms with margin — as signed slacks in natural
//!   units, with [`Bound`] choosing the limit or the limit minus its margin.
//! - [`InvariantChecker`]: one call, [`InvariantChecker::check`], evaluates
//!   I1–I4 and the state part of I5 for a [`crate::HandState`] and returns
//!   an [`InvariantReport`] saying, per invariant, which finger or pair
//!   passes or fails and by how much; [`InvariantChecker::check_slip`] does
//!   the no-slip part of I5 between consecutive states.
//!
//! - [`ChainHand`]: a hand of three 3-joint finger chains (SPEC §14.1):
//!   chains, object, friction, the limits a grasp keeps, the joints of a
//!   tip centre.
//! - [`ChainLimits`]: for a hand of finger chains, the limits of SPEC
//!   §14.1 (joint limits, tip patch, link clearance, finger gaps) in place
//!   of the fingertips' workspace cone, hemisphere, roll and collision
//!   ([`InvariantChecker::for_chains`]).
//!
//! Everything here is allocation-free and deterministic. The only costly
//! path, the conic test for three fingers when the closed forms do not
//! decide, is owned and cached by the checker (`&mut self`).

mod chain_check;
mod chain_hand;
mod check;
mod invariant_report;
mod limits;

pub use chain_check::ChainLimits;
pub use chain_hand::{ChainHand, ChainHandError};
pub use check::{InvariantChecker, StateError, validate_state};
pub use invariant_report::{
    Check, FcMethod, FingerReport, ForceClosureCheck, Invariant, InvariantReport, PAIRS, SlipCheck,
    SlipReport, Subject, Unit, Violation,
};
pub use limits::{Bound, FingertipLimits, SLACK_TOLERANCE};
