//! A plan's route: the actions the search chose, and the pass of
//! [`super::alternatives::PASSES`] that found them — what `gaitctl plan`
//! and the daemon's trace header print.

use std::fmt;

use super::alternatives::{PASSES, Pass, Role};
use super::hand_model::{Action, HandModel, RegraspFor, Turn};
use crate::hand_state::HandState;

/// One action of a route.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RouteStep {
    /// The grasping fingers (two or three) turned the object.
    Turn {
        /// Why.
        why: Turn,
        /// How many fingers grasped.
        fingers: u8,
        /// Angle \[rad\].
        angle: f64,
    },
    /// A free finger touched down.
    Place {
        /// Finger.
        finger: u8,
    },
    /// A grasping finger lifted.
    Lift {
        /// Finger.
        finger: u8,
    },
    /// A motion on the still object.
    Regrasp {
        /// The hand's name for it.
        name: &'static str,
        /// What it was for.
        why: RegraspFor,
    },
}

/// The actions of a plan and the pass that found them.
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    /// The portfolio the plan was searched with ([`PASSES`], or
    /// [`super::alternatives::STILL_PAIR_PASSES`] on a hand whose pairs
    /// do not turn).
    pub passes: &'static [Pass],
    /// Index into `passes`.
    pub pass: usize,
    /// The actions, in order.
    pub steps: Vec<RouteStep>,
}

impl Default for Route {
    /// No actions, from the first of [`PASSES`].
    fn default() -> Self {
        Self {
            passes: &PASSES,
            pass: 0,
            steps: Vec::new(),
        }
    }
}

impl Route {
    /// The route of `actions` from `start`, found by pass `pass` of
    /// `passes`.
    pub fn new<H: HandModel>(
        passes: &'static [Pass],
        pass: usize,
        start: &HandState,
        hand: &H,
        actions: &[Action<H>],
    ) -> Self {
        let mut fingers = start.grasping().1 as u8;
        let steps = actions
            .iter()
            .map(|a| match a {
                Action::Rotate { angle, why, .. } => RouteStep::Turn {
                    why: *why,
                    fingers,
                    angle: *angle,
                },
                Action::Place { finger, .. } => {
                    fingers += 1;
                    RouteStep::Place {
                        finger: *finger as u8,
                    }
                }
                Action::Lift { finger } => {
                    fingers -= 1;
                    RouteStep::Lift {
                        finger: *finger as u8,
                    }
                }
                Action::Regrasp { regrasp, why } => RouteStep::Regrasp {
                    name: hand.regrasp_name(regrasp),
                    why: *why,
                },
            })
            .collect();
        Self {
            passes,
            pass,
            steps,
        }
    }

    /// Whether the plan turned about another axis, or regrasped a pair
    /// from which no gait could follow.
    pub fn escaped(&self) -> bool {
        self.steps.iter().any(|s| {
            matches!(
                s,
                RouteStep::Turn {
                    why: Turn::Detour,
                    ..
                } | RouteStep::Regrasp {
                    why: RegraspFor::Unstick,
                    ..
                }
            )
        })
    }

    /// How many steps of each kind: (turns, gaits, regrasps).
    pub fn counts(&self) -> (usize, usize, usize) {
        let turns = self
            .steps
            .iter()
            .filter(|s| matches!(s, RouteStep::Turn { .. }))
            .count();
        let regrasps = self
            .steps
            .iter()
            .filter(|s| matches!(s, RouteStep::Regrasp { .. }))
            .count();
        (turns, self.steps.len() - turns - regrasps, regrasps)
    }
}

impl fmt::Display for Route {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pass = self.passes.get(self.pass);
        let what = match pass.map(|p| (p.role, p.spins)) {
            Some((Role::Improve { .. }, _)) => "improved",
            Some((Role::Find, true)) => "spinning contacts",
            Some((Role::Find, false)) => "first found",
            None => "?",
        };
        write!(f, "pass {} ({what}):", self.pass + 1)?;
        if self.steps.is_empty() {
            return write!(f, " nothing to do");
        }
        let mut i = 0;
        while i < self.steps.len() {
            let sep = if i == 0 { " " } else { ", " };
            match self.steps[i] {
                RouteStep::Turn {
                    why,
                    fingers,
                    angle,
                } => {
                    let w = match why {
                        Turn::Toward => "turn",
                        Turn::Tilt => "tilt",
                        Turn::Detour => "detour",
                    };
                    write!(f, "{sep}{w} {:.0}° ({fingers} fingers)", angle.to_degrees())?;
                }
                // A placement followed by a lift is a substitution.
                RouteStep::Place { finger: p } => match self.steps.get(i + 1) {
                    Some(RouteStep::Lift { finger: l }) => {
                        write!(f, "{sep}substitute {p} for {l}")?;
                        i += 1;
                    }
                    _ => write!(f, "{sep}place {p}")?,
                },
                // A lift followed by the same finger's placement moves it
                // on the still object (a walk's step on finger chains).
                RouteStep::Lift { finger } => match self.steps.get(i + 1) {
                    Some(RouteStep::Place { finger: p }) if *p == finger => {
                        write!(f, "{sep}move {finger}")?;
                        i += 1;
                    }
                    _ => write!(f, "{sep}lift {finger}")?,
                },
                RouteStep::Regrasp { name, .. } => write!(f, "{sep}{name}")?,
            }
            i += 1;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn route(steps: Vec<RouteStep>) -> String {
        Route {
            steps,
            ..Route::default()
        }
        .to_string()
    }

    #[test]
    fn a_lift_and_the_same_fingers_placement_read_as_a_move() {
        let turn = RouteStep::Turn {
            why: Turn::Toward,
            fingers: 3,
            angle: 0.5,
        };
        let (lift, place) = (
            |finger| RouteStep::Lift { finger },
            |finger| RouteStep::Place { finger },
        );
        assert_eq!(
            route(vec![turn, lift(0), place(0), lift(1), place(1), turn]),
            "pass 1 (first found): turn 29° (3 fingers), move 0, move 1, turn 29° (3 fingers)"
        );
        // A placement then another finger's lift is a substitution.
        assert_eq!(
            route(vec![lift(2), place(2), lift(0), place(1), lift(2)]),
            "pass 1 (first found): move 2, lift 0, substitute 1 for 2"
        );
    }
}
