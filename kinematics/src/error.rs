//! The one error type of reading a hand description.
//!
//! Every variant names what the user wrote (the key of the hand section,
//! the URDF link or joint) so that its one-line message says what to fix.
//! These errors happen once, when a description is read; nothing on the
//! per-tick path returns them.

use thiserror::Error;

/// What is wrong with a hand description (URDF plus hand section).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DescriptionError {
    /// The URDF is not well-formed or not URDF (urdf-rs's message).
    #[error("URDF: {0}")]
    Urdf(String),
    /// The hand section is not valid TOML or has an unknown or mistyped key
    /// (the toml crate's message, which names the key and line).
    #[error("hand section: {0}")]
    Section(String),
    /// A link named in the hand section is not in the URDF.
    #[error("`{key}`: no link `{link}` in the URDF")]
    UnknownLink {
        /// The hand-section key, e.g. `finger\[1\].tip`.
        key: String,
        /// The link named there.
        link: String,
    },
    /// A finger's tip link is not a descendant of its base link.
    #[error("finger `{finger}`: tip link `{tip}` is not below base link `{base}` in the URDF tree")]
    TipNotBelowBase {
        /// Finger name.
        finger: String,
        /// Its tip link.
        tip: String,
        /// Its base link.
        base: String,
    },
    /// A finger's base link is not below the hand frame through fixed joints only.
    #[error(
        "finger `{finger}`: base link `{base}` is not fixed below the hand frame `{frame}` (joint `{joint}`)"
    )]
    BaseNotFixed {
        /// Finger name.
        finger: String,
        /// Its base link.
        base: String,
        /// The hand frame link.
        frame: String,
        /// The offending joint (moving, or missing: the base is not below the frame).
        joint: String,
    },
    /// A joint between base and tip is neither revolute nor fixed.
    #[error(
        "finger `{finger}`: joint `{joint}` is {kind}; a finger chain has revolute (and fixed) joints only"
    )]
    NonRevoluteJoint {
        /// Finger name.
        finger: String,
        /// Joint name.
        joint: String,
        /// Its URDF type.
        kind: String,
    },
    /// A revolute joint's `<limit>` is missing or unusable.
    #[error("joint `{joint}`: {problem}")]
    BadLimit {
        /// Joint name.
        joint: String,
        /// What is wrong, e.g. "no `<limit>`, or lower ≥ upper".
        problem: &'static str,
    },
    /// A revolute joint's axis is zero or not finite.
    #[error("joint `{joint}`: axis must be a finite non-zero vector")]
    BadAxis {
        /// Joint name.
        joint: String,
    },
    /// A finger chain has no revolute joint.
    #[error("finger `{finger}`: no revolute joint between `{base}` and `{tip}`")]
    NoJoints {
        /// Finger name.
        finger: String,
        /// Base link.
        base: String,
        /// Tip link.
        tip: String,
    },
    /// Neither the URDF (a sphere on the tip link at its origin) nor the
    /// hand section (`tip_radius`) gives the tip radius.
    #[error(
        "finger `{finger}`: no tip radius (set `tip_radius`, or give the tip link `{tip}` a collision sphere at its origin)"
    )]
    NoTipRadius {
        /// Finger name.
        finger: String,
        /// Tip link.
        tip: String,
    },
    /// A number of the hand section is out of its range.
    #[error("`{key}` = {value}: {requirement}")]
    BadValue {
        /// The key.
        key: String,
        /// The value given.
        value: f64,
        /// What it must be.
        requirement: &'static str,
    },
    /// The hand section has no `[\[finger\]]`, or two fingers share a name.
    #[error("hand section: {0}")]
    Fingers(&'static str),
    /// A finger has more collision primitives than a fixed-size chain holds.
    #[error("finger `{finger}`: {count} collision primitives, at most {max}")]
    TooManyCapsules {
        /// Finger name.
        finger: String,
        /// Primitives found.
        count: usize,
        /// Capacity ([`crate::MAX_CAPSULES`]).
        max: usize,
    },
    /// A fixed-size chain was asked for with another joint count.
    #[error("finger `{finger}` has {found} revolute joints, this chain type has {expected}")]
    JointCount {
        /// Finger name.
        finger: String,
        /// Joints the type holds.
        expected: usize,
        /// Joints the finger has.
        found: usize,
    },
}
