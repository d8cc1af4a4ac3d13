//! # kinematics — finger chains of a real hand
//!
//! Pure library (no I/O, no clocks, no threads) for hands whose fingers are
//! serial chains of revolute joints (SPEC §14): reading a hand description,
//! and the per-tick kinematics of a chain, allocation-free after
//! construction (fixed-size nalgebra types).
//!
//! ## Frames and conventions
//! - **Hand frame**: the frame of the hand section's `frame` link (default
//!   the URDF root). TriFingerPro: `base_link`, the arena centre on the
//!   floor, z up, `finger_0` along +y, the other fingers turned −120° and
//!   −240° about z (upstream `doc/world_frame_and_joint_axes.rst`).
//!   Unlike SPEC §1.1's free-fingertip hand, the origin is not the object
//!   centre: the object's centre O is a point of the hand frame given in
//!   the hand section (§14.1).
//! - **Joints**: positive $q_i$ turns right-handed about the joint's URDF
//!   axis; $q = 0$ is the URDF's zero pose (TriFingerPro: every finger
//!   pointing straight down). SI units, radians.
//! - **Tip**: a sphere of radius r centred at the tip frame's origin (the
//!   forward-kinematics point). Its **pole** p (tip coordinates) is the
//!   centre of its contactable patch; TriFingerPro: $-z$ of the tip frame,
//!   the hemisphere below it ([`patch`]).
//! - **Contact**: $n$ is the object's outward unit normal at a contact;
//!   a grasping tip has its centre at $c = O + (R + r)n$.
//!
//! ## Modules
//! - [`description`], [`section`], [`error`]: URDF + hand section → chains
//!   (§14.4).
//! - [`chain`]: fixed-size chain, forward kinematics $(R_k(q), c_k(q))$ and
//!   the Jacobians $J_v$, $J_\omega$ (§14.1).
//! - [`ik_closed`]: closed-form IK of TriFingerPro-like 3-joint fingers;
//!   [`ik_dls`]: damped least squares for any chain (§14.3).
//! - [`patch`]: the tip patch; [`capsule`]: link capsules and clearances;
//!   [`torque`]: the torque box $\tau = J_v^\top f + g(q)$ (§14.1).
//! - [`rolling`]: the rolling law of a 3-joint finger (§14.2); [`mod@carry`]:
//!   a grasp carried by the object's turn under it, how far it can go
//!   within the limits, and the axis a pair turns about without spin.
//! - [`sweep`]: how far a finger's parts travel between two
//!   configurations (what a sampled check needs between its samples).
//! - [`workspace`]: the normals a finger can grasp at (§14.1), and the
//!   gap between two fingers.
//! - [`mod@transfer`]: a free finger's way from one contact to another, clear
//!   of the object and of the other fingers (§14.3).
//!
//! ```
//! use kinematics::{Chain, ClosedFormIk, HandDescription};
//! # let urdf = include_str!("../../deploy/hands/trifingerpro/trifingerpro.urdf");
//! # let section = include_str!("../../deploy/hands/trifingerpro/hand.toml");
//! let hand = HandDescription::parse(urdf, section)?;
//! let chain = Chain::<3>::from_description(&hand.fingers[0], hand.joint_limit_margin)?;
//! let q = nalgebra::Vector3::new(0.0, 0.9, -1.7);
//! let s = chain.forward(&q);
//! let ik = ClosedFormIk::new(&chain).expect("TriFingerPro structure");
//! let back = ik.solve(&s.tip_centre(), &q).expect("reachable");
//! assert!((back - q).norm() < 1e-9);
//! # Ok::<(), kinematics::DescriptionError>(())
//! ```

pub mod capsule;
pub mod carry;
pub mod chain;
pub mod description;
pub mod error;
pub mod frame;
pub mod ik_closed;
pub mod ik_dls;
pub mod patch;
pub mod rolling;
pub mod section;
pub mod sweep;
pub mod torque;
pub mod transfer;
pub mod workspace;

pub use capsule::{Capsule, LinkCapsule};
pub use carry::{
    Bound, Carrier, CarrierError, GraspLimits, Range, Scan, carry, carry_pair, carry_range,
    carry_range_with, no_spin_axis,
};
pub use chain::{CapsuleSet, Chain, ChainState, MAX_CAPSULES};
pub use description::{
    Body, FingerDescription, Friction, HandDescription, JointDescription, JointLimits, LoadError,
    Object,
};
pub use error::DescriptionError;
pub use frame::Frame;
pub use ik_closed::{Branches, ClosedFormIk, IkError, NotClosedForm};
pub use ik_dls::{DlsParams, DlsResult};
pub use patch::TipPatch;
pub use rolling::{RollingRates, rolling_rates};
pub use sweep::{parts_travel, reach_radii};
pub use torque::{gravity_torques, joint_torques, max_force_scale};
pub use transfer::{Obstacle, Transfer, TransferError, TransferLimits, transfer};
pub use workspace::{FingerGap, Margins, Reach, Workspace, finger_gap, reach, sphere_grid};
