//! # otg — jerk-limited online trajectory generation
//!
//! Pure library (no I/O, no clocks, no threads, no allocation after
//! construction) computing time-optimal, jerk-limited trajectories for N
//! degrees of freedom (SPEC.md §5), in the manner of Ruckig (Berscheid &
//! Kröger, RSS 2021).
//!
//! ```
//! use otg::{Input, Otg, Output, Progress};
//! let mut otg = Otg::<2>::new(0.001).unwrap();
//! let mut inp = Input::new([1.0, 1.0], [4.0, 4.0], [40.0, 40.0]);
//! inp.target_position = [0.5, -0.2];
//! let mut out = Output::default();
//! while otg.update(&inp, &mut out).unwrap() == Progress::Working {
//!     out.pass_to_input(&mut inp);
//! }
//! assert!((out.new_position[0] - 0.5).abs() < 1e-8);
//! ```

mod block;
mod brake;
mod calculator;
mod candidates;
mod error;
mod helpers;
mod input;
mod limits;
mod motion;
mod otg;
mod position_step1;
mod position_step1_reduced;
mod position_step2;
mod position_step2_flat;
mod position_step2_none;
mod position_step2_vel;
mod position_tails;
mod profile;
mod robust;
mod roots;
mod trajectory;
mod velocity;

pub use block::{Block, Interval};
pub use brake::Brake;
pub use calculator::Calculator;
pub use error::{Field, InputDefect, OtgError};
pub use helpers::{min_duration, rest_to_rest_duration};
pub use input::{ControlInterface, DurationDiscretization, Input, Synchronization};
pub use limits::{DofLimits, MAX_DURATION};
pub use motion::integrate;
pub use otg::{Otg, Output, Progress};
pub use profile::{ControlSigns, Direction, Profile, ReachedLimits};
pub use trajectory::{State, Trajectory};
