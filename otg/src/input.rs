//! Input of the trajectory generator and its validation (SPEC.md §5).

use crate::brake::v_at_a_zero;
use crate::error::{Field, InputDefect, OtgError};

/// What the target prescribes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ControlInterface {
    /// Target position, velocity and acceleration.
    #[default]
    Position,
    /// Target velocity and acceleration only (the position is free).
    Velocity,
}

/// How the DoFs are synchronised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Synchronization {
    /// All DoFs finish at the same time.
    #[default]
    Time,
    /// Same time and, for collinear inputs, the same phases: a straight line.
    /// Falls back to time synchronisation when the input is not collinear.
    Phase,
    /// Every DoF moves time-optimally on its own.
    None,
}

/// Whether the duration is continuous or a multiple of the control cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DurationDiscretization {
    /// Any duration.
    #[default]
    Continuous,
    /// An integer multiple of the control cycle.
    Discrete,
}

/// Everything a trajectory calculation needs, for `N` degrees of freedom.
///
/// Kinematic limits are per DoF: `max_velocity > 0`, `max_acceleration > 0`,
/// `max_jerk > 0`, all finite; `min_velocity`/`min_acceleration` default to
/// the negated maxima and must be negative when given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Input<const N: usize> {
    /// Position or velocity interface.
    pub control_interface: ControlInterface,
    /// Synchronisation mode.
    pub synchronization: Synchronization,
    /// Continuous or discrete duration.
    pub duration_discretization: DurationDiscretization,
    /// Current position.
    pub current_position: [f64; N],
    /// Current velocity.
    pub current_velocity: [f64; N],
    /// Current acceleration.
    pub current_acceleration: [f64; N],
    /// Target position (ignored by the velocity interface).
    pub target_position: [f64; N],
    /// Target velocity.
    pub target_velocity: [f64; N],
    /// Target acceleration.
    pub target_acceleration: [f64; N],
    /// Maximum velocity (> 0).
    pub max_velocity: [f64; N],
    /// Maximum acceleration (> 0).
    pub max_acceleration: [f64; N],
    /// Maximum jerk (> 0).
    pub max_jerk: [f64; N],
    /// Minimum velocity (< 0); `None` means `-max_velocity`.
    pub min_velocity: Option<[f64; N]>,
    /// Minimum acceleration (< 0); `None` means `-max_acceleration`.
    pub min_acceleration: Option<[f64; N]>,
    /// Disabled DoFs keep their current state (constant acceleration).
    pub enabled: [bool; N],
    /// Lower bound of the trajectory duration \[s\].
    pub minimum_duration: Option<f64>,
}

impl<const N: usize> Input<N> {
    /// An input at rest at the origin with the given symmetric limits.
    pub fn new(max_velocity: [f64; N], max_acceleration: [f64; N], max_jerk: [f64; N]) -> Self {
        Self {
            control_interface: ControlInterface::Position,
            synchronization: Synchronization::Time,
            duration_discretization: DurationDiscretization::Continuous,
            current_position: [0.0; N],
            current_velocity: [0.0; N],
            current_acceleration: [0.0; N],
            target_position: [0.0; N],
            target_velocity: [0.0; N],
            target_acceleration: [0.0; N],
            max_velocity,
            max_acceleration,
            max_jerk,
            min_velocity: None,
            min_acceleration: None,
            enabled: [true; N],
            minimum_duration: None,
        }
    }

    /// Effective minimum velocity of DoF `i`.
    #[inline]
    pub fn v_min(&self, i: usize) -> f64 {
        self.min_velocity.map_or(-self.max_velocity[i], |m| m[i])
    }

    /// Effective minimum acceleration of DoF `i`.
    #[inline]
    pub fn a_min(&self, i: usize) -> f64 {
        self.min_acceleration
            .map_or(-self.max_acceleration[i], |m| m[i])
    }

    /// Checks the input: finite numbers, valid limits and a target that is
    /// reachable inside the limits. With `current_within_limits`, the
    /// current state must be inside the limits too (without it, a current
    /// state outside is allowed: a brake pre-trajectory recovers it).
    pub fn validate(&self, current_within_limits: bool) -> Result<(), OtgError> {
        let bad = |dof: usize, field: Field, problem: InputDefect| {
            Err(OtgError::InvalidInput {
                dof: dof as u16,
                field,
                problem,
            })
        };
        if let Some(t) = self.minimum_duration
            && !(t.is_finite() && t >= 0.0)
        {
            return bad(0, Field::MinimumDuration, InputDefect::OutOfRange);
        }
        let position = self.control_interface == ControlInterface::Position;
        for i in 0..N {
            if !self.enabled[i] {
                continue;
            }
            let (j, amax, amin) = (self.max_jerk[i], self.max_acceleration[i], self.a_min(i));
            let positive = |x: f64| x.is_finite() && x > 0.0;
            let negative = |x: f64| x.is_finite() && x < 0.0;
            if !positive(j) {
                return bad(i, Field::MaxJerk, InputDefect::OutOfRange);
            }
            if !positive(amax) {
                return bad(i, Field::MaxAcceleration, InputDefect::OutOfRange);
            }
            if !negative(amin) {
                return bad(i, Field::MinAcceleration, InputDefect::OutOfRange);
            }
            let (a0, af, v0, vf) = (
                self.current_acceleration[i],
                self.target_acceleration[i],
                self.current_velocity[i],
                self.target_velocity[i],
            );
            for (x, f) in [
                (a0, Field::CurrentAcceleration),
                (af, Field::TargetAcceleration),
                (v0, Field::CurrentVelocity),
                (vf, Field::TargetVelocity),
                (self.current_position[i], Field::CurrentPosition),
            ] {
                if !x.is_finite() {
                    return bad(i, f, InputDefect::NotFinite);
                }
            }
            if current_within_limits && !(amin..=amax).contains(&a0) {
                return bad(i, Field::CurrentAcceleration, InputDefect::ExceedsLimit);
            }
            if !(amin..=amax).contains(&af) {
                return bad(i, Field::TargetAcceleration, InputDefect::ExceedsLimit);
            }
            if !position {
                continue;
            }
            if !self.target_position[i].is_finite() {
                return bad(i, Field::TargetPosition, InputDefect::NotFinite);
            }
            let (vmax, vmin) = (self.max_velocity[i], self.v_min(i));
            if !positive(vmax) {
                return bad(i, Field::MaxVelocity, InputDefect::OutOfRange);
            }
            if !negative(vmin) {
                return bad(i, Field::MinVelocity, InputDefect::OutOfRange);
            }
            if current_within_limits {
                if !(vmin..=vmax).contains(&v0) {
                    return bad(i, Field::CurrentVelocity, InputDefect::ExceedsLimit);
                }
                if (a0 > 0.0 && v_at_a_zero(v0, a0, j) > vmax)
                    || (a0 < 0.0 && v_at_a_zero(v0, a0, -j) < vmin)
                {
                    return bad(
                        i,
                        Field::CurrentAcceleration,
                        InputDefect::InevitablyExceeds,
                    );
                }
            }
            if !(vmin..=vmax).contains(&vf) {
                return bad(i, Field::TargetVelocity, InputDefect::ExceedsLimit);
            }
            // The target must be reachable from inside the velocity limits.
            if (af < 0.0 && v_at_a_zero(vf, af, j) > vmax)
                || (af > 0.0 && v_at_a_zero(vf, af, -j) < vmin)
            {
                return bad(i, Field::TargetAcceleration, InputDefect::InevitablyExceeds);
            }
        }
        Ok(())
    }
}
