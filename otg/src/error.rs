//! Typed errors of the trajectory generator (no payload allocates).

use core::fmt;

/// Which input field is invalid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// `current_position`.
    CurrentPosition,
    /// `current_velocity`.
    CurrentVelocity,
    /// `current_acceleration`.
    CurrentAcceleration,
    /// `target_position`.
    TargetPosition,
    /// `target_velocity`.
    TargetVelocity,
    /// `target_acceleration`.
    TargetAcceleration,
    /// `max_velocity`.
    MaxVelocity,
    /// `min_velocity`.
    MinVelocity,
    /// `max_acceleration`.
    MaxAcceleration,
    /// `min_acceleration`.
    MinAcceleration,
    /// `max_jerk`.
    MaxJerk,
    /// `minimum_duration`.
    MinimumDuration,
    /// The control cycle of the generator.
    DeltaTime,
}

/// What is wrong with a field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputDefect {
    /// NaN or infinite.
    NotFinite,
    /// A limit with the wrong sign, zero, or non-finite; a negative duration.
    OutOfRange,
    /// The value lies outside its kinematic limits.
    ExceedsLimit,
    /// The velocity limit will be exceeded whatever the jerk does.
    InevitablyExceeds,
}

/// Why no trajectory was produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OtgError {
    /// An input field is invalid.
    InvalidInput {
        /// Index of the DoF (0 for global fields).
        dof: u16,
        /// The offending field.
        field: Field,
        /// What is wrong with it.
        problem: InputDefect,
    },
    /// No time-optimal profile was found for a DoF (Step 1).
    ExecutionTimeCalculation {
        /// Index of the DoF.
        dof: u16,
    },
    /// No profile of the synchronised duration was found for a DoF (Step 2).
    SynchronizationCalculation {
        /// Index of the DoF.
        dof: u16,
    },
    /// The synchronised duration exceeds [`crate::MAX_DURATION`].
    TrajectoryDuration,
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = match self {
            Field::CurrentPosition => "current position",
            Field::CurrentVelocity => "current velocity",
            Field::CurrentAcceleration => "current acceleration",
            Field::TargetPosition => "target position",
            Field::TargetVelocity => "target velocity",
            Field::TargetAcceleration => "target acceleration",
            Field::MaxVelocity => "max velocity",
            Field::MinVelocity => "min velocity",
            Field::MaxAcceleration => "max acceleration",
            Field::MinAcceleration => "min acceleration",
            Field::MaxJerk => "max jerk",
            Field::MinimumDuration => "minimum duration",
            Field::DeltaTime => "delta time",
        };
        f.write_str(s)
    }
}

impl fmt::Display for InputDefect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            InputDefect::NotFinite => "is not finite",
            InputDefect::OutOfRange => "is out of range",
            InputDefect::ExceedsLimit => "exceeds its limit",
            InputDefect::InevitablyExceeds => "inevitably leads past the velocity limit",
        })
    }
}

impl fmt::Display for OtgError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OtgError::InvalidInput {
                dof,
                field,
                problem,
            } => write!(f, "invalid input: DoF {dof} {field} {problem}"),
            OtgError::ExecutionTimeCalculation { dof } => {
                write!(f, "no time-optimal profile for DoF {dof}")
            }
            OtgError::SynchronizationCalculation { dof } => {
                write!(f, "no synchronised profile for DoF {dof}")
            }
            OtgError::TrajectoryDuration => {
                write!(f, "trajectory duration exceeds {} s", crate::MAX_DURATION)
            }
        }
    }
}

impl core::error::Error for OtgError {}
