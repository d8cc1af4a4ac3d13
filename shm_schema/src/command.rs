//! client → daemon: [`Command`] (`commands` service) and its validation into a typed [`ValidCommand`].

use crate::codes::{CommandKind, GoalFrame, ReasonCode};
use iceoryx2::prelude::ZeroCopySend;

/// Accepted deviation of a goal quaternion's norm from 1. The daemon
/// renormalises; anything further off is a client bug, not rounding.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// Smallest motion-limit override the daemon accepts, as a fraction of the
/// configured limit: an override must lie in [`MIN_LIMIT_OVERRIDE_FRACTION`
/// × configured, configured]. Below it, a step could outlast the trajectory
/// generator's duration bound (7600 s); it is rejected with
/// `LimitBelowMinimum` (above the configured limit: `LimitAboveConfigured`).
pub const MIN_LIMIT_OVERRIDE_FRACTION: f64 = 0.01;

/// Number of motion-limit overrides in a goal (3 motion kinds × v, a, j).
pub const LIMIT_OVERRIDES: u32 = 9;

/// Velocity, acceleration and jerk limits of one motion kind (SPEC §5).
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::MotionLimits.v8")]
pub struct MotionLimits {
    /// Velocity limit (> 0), unit of the motion kind per second.
    pub velocity: f64,
    /// Acceleration limit (> 0), per second².
    pub acceleration: f64,
    /// Jerk limit (> 0), per second³.
    pub jerk: f64,
}

/// Which limit an override bit stands for: motion kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LimitKind {
    /// Object rotation [rad/s, rad/s², rad/s³]; mask bits 0–2.
    Object = 0,
    /// Fingertip translation [m/s, m/s², m/s³]; mask bits 3–5.
    Fingertip = 1,
    /// Fingertip rolling rate [rad/s, rad/s², rad/s³]; mask bits 6–8.
    Rolling = 2,
}

/// Which limit an override bit stands for: derivative.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LimitOrder {
    /// Velocity; bit offset 0 within the kind.
    Velocity = 0,
    /// Acceleration; bit offset 1.
    Acceleration = 1,
    /// Jerk; bit offset 2.
    Jerk = 2,
}

/// The `limit_mask` bit of one override: `1 << (3·kind + order)`.
pub const fn limit_bit(kind: LimitKind, order: LimitOrder) -> u32 {
    1 << (3 * kind as u32 + order as u32)
}

/// A command from a client: a reorientation goal, cancel, hold or reset
/// (SPEC §6.4, §7.3). Fields a command kind does not use must be zero.
///
/// Type name `gaitd::Command.v8`, 144 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Command.v8")]
pub struct Command {
    /// [`CommandKind`] code.
    pub kind: u32,
    /// [`GoalFrame`] code (goals only; 0 otherwise).
    pub frame: u32,
    /// Non-zero id the client chose for itself (e.g. at connect); goal ids
    /// are unique per client.
    pub client_id: u64,
    /// Any value the client chooses to match the [`Answer`](crate::Answer)
    /// (echoed); e.g. a counter.
    pub request_id: u64,
    /// Goal: the new goal's id (non-zero). Cancel: the goal to cancel, 0 =
    /// whichever is active. Hold, Reset: 0.
    pub goal_id: u64,
    /// Goal target quaternion [w, x, y, z] (unit, Hamilton); see `frame`.
    pub target: [f64; 4],
    /// Which of the nine overrides are set: bit `3·kind + order`
    /// (see [`limit_bit`]). Unset overrides must be 0.
    pub limit_mask: u32,
    /// Padding, must be 0.
    pub reserved: u32,
    /// Object rotation limit overrides [rad/s, rad/s², rad/s³].
    pub object_limits: MotionLimits,
    /// Fingertip translation limit overrides [m/s, m/s², m/s³].
    pub fingertip_limits: MotionLimits,
    /// Rolling-rate limit overrides [rad/s, rad/s², rad/s³].
    pub rolling_limits: MotionLimits,
}

const _: () = assert!(core::mem::size_of::<MotionLimits>() == 24);
const _: () = assert!(core::mem::size_of::<Command>() == Command::SIZE);
const _: () = assert!(core::mem::align_of::<Command>() == 8);

impl Command {
    /// All fields zero (not a valid command: kind 0).
    pub const ZERO: Command = Command {
        kind: 0,
        frame: 0,
        client_id: 0,
        request_id: 0,
        goal_id: 0,
        target: [0.0; 4],
        limit_mask: 0,
        reserved: 0,
        object_limits: MotionLimits {
            velocity: 0.0,
            acceleration: 0.0,
            jerk: 0.0,
        },
        fingertip_limits: MotionLimits {
            velocity: 0.0,
            acceleration: 0.0,
            jerk: 0.0,
        },
        rolling_limits: MotionLimits {
            velocity: 0.0,
            acceleration: 0.0,
            jerk: 0.0,
        },
    };

    /// Size of the payload in bytes.
    pub const SIZE: usize = 144;

    /// The command that `bytes` in shared memory encode, exactly as the
    /// daemon's subscriber sees another process's sample. Every bit pattern
    /// is a `Command` (integers and floats only, no implicit padding), which
    /// is why all meaning is checked by [`Command::validate`].
    pub fn from_bytes(bytes: &[u8; Self::SIZE]) -> Self {
        // SAFETY: Command is repr(C), exactly SIZE bytes, made of integers
        // and floats without implicit padding: any bytes are a valid value;
        // read_unaligned accepts the byte array's alignment of 1.
        unsafe { core::ptr::read_unaligned(bytes.as_ptr().cast::<Command>()) }
    }

    /// The command's bytes as they travel (native endianness).
    pub fn to_bytes(&self) -> [u8; Self::SIZE] {
        // SAFETY: same layout facts as in `from_bytes`; no padding means no
        // uninitialised bytes are read.
        unsafe { core::mem::transmute::<Command, [u8; Self::SIZE]>(*self) }
    }

    /// A reorientation goal with the configured limits.
    pub const fn goal(client_id: u64, goal_id: u64, frame: GoalFrame, target: [f64; 4]) -> Self {
        let mut c = Self::ZERO;
        c.kind = CommandKind::Goal.code();
        c.frame = frame.code();
        c.client_id = client_id;
        c.goal_id = goal_id;
        c.target = target;
        c
    }

    /// Cancel `goal_id` (0: whichever goal is active).
    pub const fn cancel(client_id: u64, goal_id: u64) -> Self {
        let mut c = Self::ZERO;
        c.kind = CommandKind::Cancel.code();
        c.client_id = client_id;
        c.goal_id = goal_id;
        c
    }

    /// Hold the grasp still (stops any motion).
    pub const fn hold(client_id: u64) -> Self {
        let mut c = Self::ZERO;
        c.kind = CommandKind::Hold.code();
        c.client_id = client_id;
        c
    }

    /// Clear a fault.
    pub const fn reset(client_id: u64) -> Self {
        let mut c = Self::ZERO;
        c.kind = CommandKind::Reset.code();
        c.client_id = client_id;
        c
    }

    /// Sets one limit override (goals only).
    pub fn with_limit(mut self, kind: LimitKind, order: LimitOrder, value: f64) -> Self {
        self.limit_mask |= limit_bit(kind, order);
        *self.limit_slot(kind, order) = value;
        self
    }

    fn limit_slot(&mut self, kind: LimitKind, order: LimitOrder) -> &mut f64 {
        let l = match kind {
            LimitKind::Object => &mut self.object_limits,
            LimitKind::Fingertip => &mut self.fingertip_limits,
            LimitKind::Rolling => &mut self.rolling_limits,
        };
        match order {
            LimitOrder::Velocity => &mut l.velocity,
            LimitOrder::Acceleration => &mut l.acceleration,
            LimitOrder::Jerk => &mut l.jerk,
        }
    }

    /// The nine override values in mask-bit order.
    fn limit_values(&self) -> [f64; LIMIT_OVERRIDES as usize] {
        let (o, f, r) = (
            &self.object_limits,
            &self.fingertip_limits,
            &self.rolling_limits,
        );
        [
            o.velocity,
            o.acceleration,
            o.jerk,
            f.velocity,
            f.acceleration,
            f.jerk,
            r.velocity,
            r.acceleration,
            r.jerk,
        ]
    }

    /// Checks every field and decodes the command (SPEC §7.3, §12: bad bytes
    /// are rejected with a reason and never reach the controller).
    ///
    /// Checks only what the bytes alone decide; the daemon adds the checks
    /// that need its state (duplicate ids, configured limits).
    pub fn validate(&self) -> Result<ValidCommand, ReasonCode> {
        let kind = CommandKind::try_from(self.kind).map_err(|_| ReasonCode::UnknownCommandKind)?;
        if self.reserved != 0 {
            return Err(ReasonCode::NonZeroReserved);
        }
        if self.client_id == 0 {
            return Err(ReasonCode::ZeroClientId);
        }
        let client_id = self.client_id;
        if kind != CommandKind::Goal {
            let unused_zero = self.frame == 0
                && self.limit_mask == 0
                && self.target.iter().all(|v| v.to_bits() == 0)
                && self.limit_values().iter().all(|v| v.to_bits() == 0);
            if !unused_zero {
                return Err(ReasonCode::NonZeroReserved);
            }
        }
        match kind {
            CommandKind::Goal => self.validate_goal().map(ValidCommand::Goal),
            CommandKind::Cancel => Ok(ValidCommand::Cancel {
                client_id,
                goal_id: self.goal_id,
            }),
            CommandKind::Hold | CommandKind::Reset if self.goal_id != 0 => {
                Err(ReasonCode::NonZeroReserved)
            }
            CommandKind::Hold => Ok(ValidCommand::Hold { client_id }),
            CommandKind::Reset => Ok(ValidCommand::Reset { client_id }),
        }
    }

    fn validate_goal(&self) -> Result<GoalRequest, ReasonCode> {
        let frame = GoalFrame::try_from(self.frame).map_err(|_| ReasonCode::UnknownGoalFrame)?;
        if self.goal_id == 0 {
            return Err(ReasonCode::ZeroGoalId);
        }
        match frame {
            GoalFrame::AxisAngle => check_axis_angle(&self.target)?,
            GoalFrame::Absolute | GoalFrame::Relative => check_unit_quaternion(&self.target)?,
        }
        let limits = self.validate_limits()?;
        Ok(GoalRequest {
            client_id: self.client_id,
            goal_id: self.goal_id,
            frame,
            target: self.target,
            limits,
        })
    }

    fn validate_limits(&self) -> Result<LimitOverrides, ReasonCode> {
        let mask = self.limit_mask;
        if mask >> LIMIT_OVERRIDES != 0 {
            return Err(ReasonCode::BadLimitMask);
        }
        let values = self.limit_values();
        let mut out = [None; LIMIT_OVERRIDES as usize];
        for (bit, (&v, slot)) in values.iter().zip(&mut out).enumerate() {
            if mask & (1 << bit) == 0 {
                if v.to_bits() != 0 {
                    return Err(ReasonCode::NonZeroReserved);
                }
            } else if !v.is_finite() {
                return Err(ReasonCode::NonFiniteLimit);
            } else if v <= 0.0 {
                return Err(ReasonCode::NonPositiveLimit);
            } else {
                *slot = Some(v);
            }
        }
        Ok(LimitOverrides { values: out })
    }
}

/// Largest angle an axis-angle goal may ask for \[rad\] (32 turns).
pub const MAX_AXIS_ANGLE: f64 = 64.0 * core::f64::consts::PI;

/// Checks an axis-angle target `[angle, x, y, z]`: finite angle of at most
/// [`MAX_AXIS_ANGLE`], finite axis of norm in [1e-6, 1e6].
pub fn check_axis_angle(t: &[f64; 4]) -> Result<(), ReasonCode> {
    if t.iter().any(|c| !c.is_finite()) || t[0].abs() > MAX_AXIS_ANGLE {
        return Err(ReasonCode::BadAxisAngle);
    }
    let n2 = t[1] * t[1] + t[2] * t[2] + t[3] * t[3];
    if !(1e-12..=1e12).contains(&n2) {
        return Err(ReasonCode::BadAxisAngle);
    }
    Ok(())
}

/// Checks that `q` is a finite, non-zero quaternion of norm 1 ±
/// [`QUATERNION_NORM_TOLERANCE`]. Huge components are refused before
/// squaring so that nothing overflows.
pub fn check_unit_quaternion(q: &[f64; 4]) -> Result<(), ReasonCode> {
    if q.iter().any(|c| !c.is_finite()) {
        return Err(ReasonCode::NonFiniteQuaternion);
    }
    if q.iter().any(|c| c.abs() > 2.0) {
        return Err(ReasonCode::NonUnitQuaternion);
    }
    let n2: f64 = q.iter().map(|c| c * c).sum();
    if n2 < 1e-12 {
        return Err(ReasonCode::ZeroQuaternion);
    }
    if (n2.sqrt() - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(ReasonCode::NonUnitQuaternion);
    }
    Ok(())
}

/// Decoded motion-limit overrides: `None` = use the configured limit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LimitOverrides {
    /// In mask-bit order (object v, a, j; fingertip v, a, j; rolling v, a, j).
    pub values: [Option<f64>; LIMIT_OVERRIDES as usize],
}

impl LimitOverrides {
    /// The override for one limit, if set.
    pub fn get(&self, kind: LimitKind, order: LimitOrder) -> Option<f64> {
        self.values[3 * kind as usize + order as usize]
    }
}

/// A reorientation goal that passed [`Command::validate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoalRequest {
    /// The sending client's id (non-zero).
    pub client_id: u64,
    /// Goal id (non-zero).
    pub goal_id: u64,
    /// Absolute or relative target.
    pub frame: GoalFrame,
    /// Target quaternion [w, x, y, z], norm within tolerance of 1 (not yet
    /// renormalised: that is the daemon's maths).
    pub target: [f64; 4],
    /// Limit overrides.
    pub limits: LimitOverrides,
}

/// A command whose bytes passed validation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ValidCommand {
    /// Reorientation goal.
    Goal(GoalRequest),
    /// Cancel the active goal (`goal_id` 0) or the named one.
    Cancel {
        /// Sender.
        client_id: u64,
        /// Goal to cancel, 0 = the active goal.
        goal_id: u64,
    },
    /// Hold still.
    Hold {
        /// Sender.
        client_id: u64,
    },
    /// Clear a fault.
    Reset {
        /// Sender.
        client_id: u64,
    },
}

impl ValidCommand {
    /// The command's kind.
    pub fn kind(&self) -> CommandKind {
        match self {
            ValidCommand::Goal(_) => CommandKind::Goal,
            ValidCommand::Cancel { .. } => CommandKind::Cancel,
            ValidCommand::Hold { .. } => CommandKind::Hold,
            ValidCommand::Reset { .. } => CommandKind::Reset,
        }
    }

    /// The sender's id.
    pub fn client_id(&self) -> u64 {
        match *self {
            ValidCommand::Goal(g) => g.client_id,
            ValidCommand::Cancel { client_id, .. }
            | ValidCommand::Hold { client_id }
            | ValidCommand::Reset { client_id } => client_id,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ID: [f64; 4] = [1.0, 0.0, 0.0, 0.0];

    #[test]
    fn bytes_round_trip() {
        let c = Command::goal(7, 9, GoalFrame::Relative, [0.5, -0.5, 0.5, -0.5]).with_limit(
            LimitKind::Object,
            LimitOrder::Jerk,
            3.0,
        );
        let b = c.to_bytes();
        assert_eq!(Command::from_bytes(&b), c);
        // Field offsets as LAYOUT.md documents them (little-endian hosts).
        assert_eq!(u32::from_ne_bytes(b[0..4].try_into().unwrap()), 1);
        assert_eq!(u64::from_ne_bytes(b[24..32].try_into().unwrap()), 9);
    }

    #[test]
    fn good_commands_pass() {
        let g = Command::goal(7, 1, GoalFrame::Absolute, ID).with_limit(
            LimitKind::Rolling,
            LimitOrder::Jerk,
            5.0,
        );
        match g.validate().unwrap() {
            ValidCommand::Goal(r) => {
                assert_eq!(
                    r.limits.get(LimitKind::Rolling, LimitOrder::Jerk),
                    Some(5.0)
                );
                assert_eq!(r.limits.get(LimitKind::Object, LimitOrder::Jerk), None);
                assert_eq!(g.limit_mask, 1 << 8);
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            Command::cancel(7, 0).validate(),
            Ok(ValidCommand::Cancel { goal_id: 0, .. })
        ));
        assert!(matches!(
            Command::hold(7).validate(),
            Ok(ValidCommand::Hold { client_id: 7 })
        ));
        assert!(matches!(
            Command::reset(7).validate(),
            Ok(ValidCommand::Reset { client_id: 7 })
        ));
    }

    #[test]
    fn bad_commands_get_their_reason() {
        let goal = |q| Command::goal(7, 1, GoalFrame::Relative, q);
        let cases = [
            (Command::ZERO, ReasonCode::UnknownCommandKind),
            (
                goal([f64::NAN, 0.0, 0.0, 0.0]),
                ReasonCode::NonFiniteQuaternion,
            ),
            (
                goal([f64::INFINITY, 0.0, 0.0, 0.0]),
                ReasonCode::NonFiniteQuaternion,
            ),
            (goal([0.0; 4]), ReasonCode::ZeroQuaternion),
            (goal([1e-7, 0.0, 0.0, 0.0]), ReasonCode::ZeroQuaternion),
            (
                goal([1e300, 1e300, 0.0, 0.0]),
                ReasonCode::NonUnitQuaternion,
            ),
            (goal([0.9, 0.0, 0.0, 0.0]), ReasonCode::NonUnitQuaternion),
            (
                Command {
                    frame: 9,
                    ..goal(ID)
                },
                ReasonCode::UnknownGoalFrame,
            ),
            (
                Command {
                    goal_id: 0,
                    ..goal(ID)
                },
                ReasonCode::ZeroGoalId,
            ),
            (
                Command {
                    client_id: 0,
                    ..goal(ID)
                },
                ReasonCode::ZeroClientId,
            ),
            (
                Command {
                    reserved: 1,
                    ..goal(ID)
                },
                ReasonCode::NonZeroReserved,
            ),
            (
                Command {
                    limit_mask: 1 << 9,
                    ..goal(ID)
                },
                ReasonCode::BadLimitMask,
            ),
            (
                goal(ID).with_limit(LimitKind::Object, LimitOrder::Velocity, 0.0),
                ReasonCode::NonPositiveLimit,
            ),
            (
                goal(ID).with_limit(LimitKind::Fingertip, LimitOrder::Acceleration, -1.0),
                ReasonCode::NonPositiveLimit,
            ),
            (
                goal(ID).with_limit(LimitKind::Object, LimitOrder::Jerk, f64::NAN),
                ReasonCode::NonFiniteLimit,
            ),
            (
                Command {
                    object_limits: MotionLimits {
                        velocity: 1.0,
                        ..Default::default()
                    },
                    ..goal(ID)
                },
                ReasonCode::NonZeroReserved,
            ),
            (
                Command {
                    target: ID,
                    ..Command::hold(7)
                },
                ReasonCode::NonZeroReserved,
            ),
            (
                Command {
                    goal_id: 3,
                    ..Command::hold(7)
                },
                ReasonCode::NonZeroReserved,
            ),
            (
                Command {
                    frame: 1,
                    ..Command::cancel(7, 0)
                },
                ReasonCode::NonZeroReserved,
            ),
        ];
        for (i, (c, want)) in cases.iter().enumerate() {
            assert_eq!(c.validate(), Err(*want), "case {i}: {c:?}");
        }
    }

    /// Seeded sweep over arbitrary bytes: validation never panics, and
    /// whatever passes satisfies every documented constraint.
    #[test]
    fn random_bytes_never_pass_invalid_values() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0x5eed);
        let mut passed = 0;
        for i in 0..200_000u32 {
            let mut c;
            // Mix fully random bytes with mostly-valid commands mutated in one field.
            if i % 2 == 0 {
                let mut bytes = [0u8; Command::SIZE];
                rng.fill(&mut bytes[..]);
                c = Command::from_bytes(&bytes);
            } else {
                c = Command::goal(
                    1 + rng.random_range(0..3),
                    1 + i as u64,
                    GoalFrame::Absolute,
                    ID,
                );
                let field = rng.random_range(0..6);
                let f = |r: &mut rand_chacha::ChaCha8Rng| f64::from_bits(r.random());
                match field {
                    0 => c.kind = rng.random_range(0..6),
                    1 => c.frame = rng.random_range(0..4),
                    2 => c.target[rng.random_range(0..4)] = f(&mut rng),
                    3 => c.limit_mask = rng.random_range(0..1024),
                    4 => c.object_limits.jerk = f(&mut rng),
                    _ => c.target = [rng.random(), rng.random(), rng.random(), rng.random()],
                }
            }
            if let Ok(v) = c.validate() {
                passed += 1;
                assert_ne!(v.client_id(), 0);
                if let ValidCommand::Goal(g) = v {
                    assert_ne!(g.goal_id, 0);
                    let n: f64 = g.target.iter().map(|x| x * x).sum::<f64>().sqrt();
                    assert!((n - 1.0).abs() <= QUATERNION_NORM_TOLERANCE);
                    for l in g.limits.values.into_iter().flatten() {
                        assert!(l.is_finite() && l > 0.0);
                    }
                }
            }
        }
        assert!(
            passed > 1000,
            "the sweep must also exercise the accepting path"
        );
    }
}
