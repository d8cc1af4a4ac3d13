//! Rolling paths of one fingertip on the still object (SPEC.md §2.4,
//! paper §3.2, Fig. 2–3).
//!
//! Every path is a sequence of [`RollSegment`]s, each a constant relative
//! angular velocity of the fingertip about an axis fixed in the object
//! frame. Under such a motion everything is closed-form (SPEC §2.3 with
//! ω_o = 0): the fingertip turns about the axis k, its centre direction n
//! turns about k at r/(R + r) of that rate, and the roll rate k·a_f is
//! constant. A [`SegmentKind::Roll`] segment (k ⊥ n) moves both contact
//! points along great circles (Theory 2); a [`SegmentKind::Spin`] segment
//! (k ∥ n) turns the fingertip about the contact normal — allowed only in a
//! three-finger hard-contact grasp (SPEC §1.2), which is why it is its own
//! kind and the planner takes `allow_spin`.
//!
//! The path parameter s is the fingertip's rotation angle relative to the
//! object \[rad\], so |ω_f − ω_o| = ṡ on every segment and the rolling-rate
//! limit of SPEC §5 bounds ṡ directly. [`RollingPath::eval`] returns the
//! state and its s-derivatives at any s, exactly, without allocating; rates
//! are discontinuous at segment ends (the fingertip must be at rest there).
//!
//! - [`segment`]: segments and their exact evaluation;
//! - [`path`]: the fixed-capacity path, its margins and path builders;
//! - [`fig2`]: the paper's longitude–equator–longitude path and its
//!   closed-form reach;
//! - [`mod@plan_roll`]: the single-finger rolling planner.

pub mod fig2;
pub mod path;
pub mod plan_roll;
pub mod segment;

pub use fig2::{Turn, fig2_reach, fig2_roll_for};
pub use path::{MAX_SEGMENTS, PathError, PathMargins, RollingPath};
pub use plan_roll::{RollGoal, RollLimits, RollPlanError, plan_roll};
pub use segment::{PathSample, RollSegment, SegmentKind, Waypoint};
