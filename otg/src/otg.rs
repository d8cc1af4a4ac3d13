//! The online generator: recalculates when the input changes and samples the
//! trajectory every control cycle (SPEC.md §5, §6.1). No allocation.

use crate::calculator::Calculator;
use crate::error::{Field, InputDefect, OtgError};
use crate::input::Input;
use crate::trajectory::Trajectory;

/// Progress of a trajectory after an [`Otg::update`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// The trajectory is running.
    Working,
    /// The target has been reached (the sample time passed the duration).
    Finished,
}

/// The state for the next control cycle, and the trajectory it comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Output<const N: usize> {
    /// Position after this cycle.
    pub new_position: [f64; N],
    /// Velocity after this cycle.
    pub new_velocity: [f64; N],
    /// Acceleration after this cycle.
    pub new_acceleration: [f64; N],
    /// Jerk during this cycle's end.
    pub new_jerk: [f64; N],
    /// Time since the start of the current trajectory \[s\].
    pub time: f64,
    /// Whether this update recalculated the trajectory.
    pub new_calculation: bool,
    /// The current trajectory.
    pub trajectory: Trajectory<N>,
}

impl<const N: usize> Default for Output<N> {
    fn default() -> Self {
        Self {
            new_position: [0.0; N],
            new_velocity: [0.0; N],
            new_acceleration: [0.0; N],
            new_jerk: [0.0; N],
            time: 0.0,
            new_calculation: false,
            trajectory: Trajectory::default(),
        }
    }
}

impl<const N: usize> Output<N> {
    /// Makes the new state the input's current state (the usual loop).
    pub fn pass_to_input(&self, input: &mut Input<N>) {
        input.current_position = self.new_position;
        input.current_velocity = self.new_velocity;
        input.current_acceleration = self.new_acceleration;
    }
}

/// Jerk-limited online trajectory generator for `N` DoFs with control cycle
/// `delta_time`.
#[derive(Clone, Copy, Debug)]
pub struct Otg<const N: usize> {
    delta_time: f64,
    calculator: Calculator<N>,
    current: Option<Input<N>>,
}

impl<const N: usize> Otg<N> {
    /// A generator with control cycle `delta_time` \[s\] (finite, > 0).
    pub fn new(delta_time: f64) -> Result<Self, OtgError> {
        if !(delta_time.is_finite() && delta_time > 0.0) {
            return Err(OtgError::InvalidInput {
                dof: 0,
                field: Field::DeltaTime,
                problem: InputDefect::OutOfRange,
            });
        }
        Ok(Self {
            delta_time,
            calculator: Calculator::default(),
            current: None,
        })
    }

    /// The control cycle \[s\].
    pub fn delta_time(&self) -> f64 {
        self.delta_time
    }

    /// Forgets the last input: the next update recalculates.
    pub fn reset(&mut self) {
        self.current = None;
    }

    /// Validates `input` and calculates its trajectory into `trajectory`.
    pub fn calculate(
        &mut self,
        input: &Input<N>,
        trajectory: &mut Trajectory<N>,
    ) -> Result<(), OtgError> {
        input.validate(false)?;
        self.calculator
            .calculate(input, trajectory, self.delta_time)
    }

    /// Takes `trajectory`, calculated for `input` by [`Otg::calculate`] on
    /// a generator with this cycle, as the next [`Otg::update`] with
    /// `input` would have calculated it: that update samples it without
    /// recalculating (its `new_calculation` stays false). For a caller that
    /// calculates off its real-time thread; the samples are the same.
    pub fn adopt(&mut self, input: &Input<N>, trajectory: &Trajectory<N>, output: &mut Output<N>) {
        self.current = Some(*input);
        output.trajectory = *trajectory;
        output.time = 0.0;
    }

    /// One control cycle: recalculates if `input` differs from the last
    /// one, then samples the trajectory one cycle further. On an error the
    /// output is left unchanged (the caller keeps its last setpoint).
    pub fn update(
        &mut self,
        input: &Input<N>,
        output: &mut Output<N>,
    ) -> Result<Progress, OtgError> {
        output.new_calculation = false;
        if self.current.as_ref() != Some(input) {
            self.calculate(input, &mut output.trajectory)?;
            self.current = Some(*input);
            output.time = 0.0;
            output.new_calculation = true;
        }
        output.time += self.delta_time;
        let s = output.trajectory.at_time(output.time);
        output.new_position = s.position;
        output.new_velocity = s.velocity;
        output.new_acceleration = s.acceleration;
        output.new_jerk = s.jerk;
        if let Some(cur) = self.current.as_mut() {
            output.pass_to_input(cur);
        }
        Ok(if output.time > output.trajectory.duration {
            Progress::Finished
        } else {
            Progress::Working
        })
    }
}
