//! An invariant near its limit (SPEC §6.3): the *measured* state, while the
//! hand moves, must keep part of each planning margin to the invariant's
//! true limit.
//!
//! Plans keep the commanded state inside margins (SPEC §1.3): workspace
//! cones shrunk by `workspace_margin_deg`, two-finger force closure by
//! `fc_margin_deg` (Fact 3), fingertips `fingertip_clearance` apart. A real
//! hand does not follow the command exactly, and its tracking error uses up
//! those margins. When the measured state keeps less than
//! `feedback.limit_guard` of a margin for [`GUARD_TICKS`] ticks in a row
//! (one noisy sample does not stop a hand), the executor stops the motion
//! smoothly and replans (module [`recovery`], like a contact drift; the
//! same `feedback.max_replans` budget). The stop lets a lagging finger
//! catch up; the replan starts from the commanded fingertips. A hand that
//! keeps running into the guard after that needs larger margins (or
//! better tracking): once the budget is spent it is a fault.
//!
//! Three grasping fingers are not guarded for force closure: their
//! closed-form slacks are not distances to the three-finger boundary
//! (SPEC §3.2), so a fraction of a margin means nothing there.
//!
//! The check (one invariant evaluation) runs only when the measurement
//! differs from the command; the embedded kinematic hand never pays for it,
//! and with its tolerances a tracking or drift fault comes first anyway.
//!
//! [`recovery`]: super::recovery

use super::lifecycle::FaultKind;
use crate::HandConfig;
use crate::hand::{InvariantChecker, Unit};
use crate::hand_state::{FingerMode, HandState};
use crate::planner::chains::ChainHand;
use crate::sim::Measurement;

use super::feedback::NOT_A_FINGER;

/// Consecutive ticks near a limit that stop the motion.
pub const GUARD_TICKS: u8 = 3;

/// The margins and the fraction of them the measured state must keep.
#[derive(Debug, Clone, Copy)]
pub struct LimitGuard {
    /// Fraction of each margin that must remain (0: off).
    keep: f64,
    /// Workspace margin \[rad\].
    workspace: f64,
    /// Force-closure margin \[rad\] (two-finger grasps, Fact 3).
    force_closure: f64,
    /// Fingertip clearance \[m\].
    clearance: f64,
    /// Consecutive ticks found near a limit so far.
    near_ticks: u8,
}

impl LimitGuard {
    /// From the configuration; on a chain hand (`chains`), its margins:
    /// the joint-limit margin for the workspace, the finger gap for the
    /// clearance (SPEC §14.1).
    pub fn new(config: &HandConfig, chains: Option<&ChainHand>) -> Self {
        let m = &config.model;
        let (workspace, clearance) = match chains {
            Some(h) => (h.chain(0).margin, h.limits().finger_gap),
            None => (m.workspace_margin_deg.to_radians(), m.fingertip_clearance),
        };
        Self {
            keep: config.feedback.limit_guard,
            workspace,
            force_closure: m.fc_margin_deg.to_radians(),
            clearance,
            near_ticks: 0,
        }
    }

    /// One tick's verdict: the invariant (and finger) the measured state
    /// `m` has been near the limit of for [`GUARD_TICKS`] ticks in a row,
    /// if any. Only a `moving` hand is checked (anything else restarts the
    /// count). `cmd` is the commanded state `m` is compared with.
    pub fn observe(
        &mut self,
        moving: bool,
        checker: &mut InvariantChecker,
        cmd: &HandState,
        m: &Measurement,
    ) -> Option<(FaultKind, u8)> {
        let near = if moving {
            self.check(checker, cmd, m)
        } else {
            None
        };
        self.near_ticks = if near.is_some() {
            self.near_ticks + 1
        } else {
            0
        };
        if self.near_ticks < GUARD_TICKS {
            return None;
        }
        self.near_ticks = 0;
        near
    }

    /// The invariant (and finger) the measured state `m` is near the limit
    /// of this tick, if any.
    fn check(
        &self,
        checker: &mut InvariantChecker,
        cmd: &HandState,
        m: &Measurement,
    ) -> Option<(FaultKind, u8)> {
        if self.keep <= 0.0 {
            return None;
        }
        let exact = m.object == cmd.object
            && (0..cmd.fingers.len()).all(|k| m.fingers[k].center == cmd.fingers[k].center);
        if exact {
            // The command is checked every tick already.
            return None;
        }
        let mut measured = *cmd;
        measured.object = m.object;
        for (k, f) in measured.fingers.iter_mut().enumerate() {
            f.center = m.fingers[k].center;
            f.orientation = m.fingers[k].orientation;
        }
        let r = checker.check(&measured).ok()?;
        // Slacks are measured from (limit − margin): the true limit is at
        // −margin, and "near" is closer to it than `keep` of the margin.
        let near = |slack: f64, margin: f64| slack < -(1.0 - self.keep) * margin;
        for (k, f) in r.fingers.iter().enumerate() {
            if f.mode == FingerMode::Grasping && near(f.workspace.slack, self.workspace) {
                return Some((FaultKind::Workspace, k as u8));
            }
        }
        let fc = &r.force_closure;
        if fc.grasping == 2
            && fc.check.unit == Unit::Radian
            && near(fc.check.slack, self.force_closure)
        {
            return Some((FaultKind::ForceClosure, NOT_A_FINGER));
        }
        for (p, c) in r.collisions.iter().enumerate() {
            if near(c.slack, self.clearance) {
                return Some((FaultKind::Collision, crate::hand::PAIRS[p].0 as u8));
            }
        }
        None
    }
}
