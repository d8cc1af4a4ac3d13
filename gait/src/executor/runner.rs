//! Times one plan step with the trajectory generator (SPEC §5, §6.1).
//!
//! A step's path parameters run from 0 to their lengths, rest to rest, time
//! synchronised. A stop switches the generator to its velocity interface
//! with target velocity 0 from the current state: the motion comes to rest
//! jerk-limited along the same path, with position, velocity and
//! acceleration continuous.

use otg::{ControlInterface, Input, Otg, OtgError, Output, Progress};

use crate::config::LimitsConfig;
use crate::planner::timing::{StepProfile, step_input};
use crate::planner::{MAX_DOFS, Step};

/// Path-parameter state of the running step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathState {
    /// Positions s.
    pub position: [f64; MAX_DOFS],
    /// Velocities ṡ.
    pub velocity: [f64; MAX_DOFS],
    /// Accelerations s̈.
    pub acceleration: [f64; MAX_DOFS],
}

/// The trajectory generator applied to one step at a time.
#[derive(Debug, Clone)]
pub struct StepRunner {
    otg: Otg<MAX_DOFS>,
    input: Input<MAX_DOFS>,
    output: Output<MAX_DOFS>,
    lengths: [f64; MAX_DOFS],
    stopping: bool,
    calculations: u64,
}

impl StepRunner {
    /// A runner for control period `dt`.
    pub fn new(dt: f64) -> Result<Self, OtgError> {
        Ok(Self {
            otg: Otg::new(dt)?,
            input: Input::new([1.0; MAX_DOFS], [1.0; MAX_DOFS], [1.0; MAX_DOFS]),
            output: Output::default(),
            lengths: [0.0; MAX_DOFS],
            stopping: false,
            calculations: 0,
        })
    }

    /// Prepares `step` from rest at parameter 0 under `limits`, with its
    /// trajectory from `profile` when that was calculated for the same
    /// input (else the first [`StepRunner::advance`] calculates it).
    pub fn start(&mut self, step: &Step, limits: &LimitsConfig, profile: Option<&StepProfile>) {
        self.input = step_input(step, limits);
        self.lengths = self.input.target_position;
        self.output = Output::default();
        self.stopping = false;
        self.otg.reset();
        if let Some(p) = profile
            && p.input == self.input
        {
            self.otg.adopt(&self.input, &p.trajectory, &mut self.output);
        }
    }

    /// Trajectories calculated by [`StepRunner::advance`] so far: the
    /// steps started without a matching profile, and the stops.
    pub fn calculations(&self) -> u64 {
        self.calculations
    }

    /// One control period; returns whether the motion has come to rest at
    /// its end (or at its stop).
    pub fn advance(&mut self) -> Result<Progress, OtgError> {
        let status = self.otg.update(&self.input, &mut self.output)?;
        self.calculations += u64::from(self.output.new_calculation);
        self.output.pass_to_input(&mut self.input);
        Ok(status)
    }

    /// Current path state.
    pub fn state(&self) -> PathState {
        PathState {
            position: self.input.current_position,
            velocity: self.input.current_velocity,
            acceleration: self.input.current_acceleration,
        }
    }

    /// Whether a stop is in progress.
    pub fn stopping(&self) -> bool {
        self.stopping
    }

    /// Brings the motion to rest as fast as the limits allow, along the
    /// step's path. If braking would carry a parameter past the end of its
    /// path, the planned motion (which ends at rest there) continues
    /// instead. Returns whether a stop was started.
    pub fn stop(&mut self) -> Result<bool, OtgError> {
        if self.stopping {
            return Ok(true);
        }
        let mut inp = self.input;
        inp.control_interface = ControlInterface::Velocity;
        inp.target_velocity = [0.0; MAX_DOFS];
        inp.target_acceleration = [0.0; MAX_DOFS];
        let mut traj = self.output.trajectory;
        self.otg.calculate(&inp, &mut traj)?;
        let end = traj.at_time(traj.duration).position;
        let overshoots = (0..MAX_DOFS)
            .any(|i| inp.enabled[i] && (end[i] > self.lengths[i] + 1e-12 || end[i] < -1e-12));
        if overshoots {
            return Ok(false);
        }
        self.input = inp;
        self.stopping = true;
        Ok(true)
    }

    /// Time left in the current trajectory \[s\].
    pub fn time_left(&self) -> f64 {
        (self.output.trajectory.duration - self.output.time).max(0.0)
    }
}
