//! One fault policy (SPEC §6.3, §6.4): every cause the executor detects —
//! a measurement that disagrees with the command, an invariant near its
//! limit in the measured state, a commanded state that breaks an
//! invariant, a trajectory the generator refuses, a re-based state that is
//! invalid — goes through [`FaultPolicy::decide`], which says what it
//! leads to: plan the goal again from the measured state, a safe hold, or
//! nothing. (The shape follows copper-rs' `monitoring.rs`: one function
//! returns a decision, the caller carries it out.)
//!
//! | cause | phase | decision |
//! |---|---|---|
//! | anything | safe hold | ignore (the first fault is the one reported) |
//! | contact drift (measured) | moving, stopping, planning, holding | replan, unless a recovery is under way or the goal's replans are spent: safe hold |
//! | invariant near its limit (measured) | moving | as a contact drift |
//! | invariant near its limit (measured) | not moving | ignore (only a moving hand is guarded) |
//! | any other measured fault (missing, non-finite, object or finger not following) | any but safe hold | safe hold |
//! | commanded state breaks an invariant, trajectory refused, re-based state invalid | any but safe hold | safe hold |
//! | the plant: lost, lying, out of sequence, its own fault, a contact lost, its timing contract missed | any but safe hold | safe hold |

use super::Mode;
use super::lifecycle::FaultKind;

/// Where a cause was seen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Source {
    /// The measurement disagrees with the command (`feedback`).
    Measurement,
    /// The measured state, while moving, is near an invariant's limit
    /// (`guard`); the kind names the invariant.
    NearLimit,
    /// The commanded state breaks an invariant (checked every tick).
    ExecutorCommand,
    /// The trajectory generator refused an input.
    Trajectory,
    /// The measured state a recovery re-based on breaks an invariant.
    Rebase,
    /// The plant itself: it is lost, lies, went out of sequence or reports
    /// a fault of its own.
    Plant,
}

/// A detected cause: what, and where it was seen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Cause {
    /// What (as the fault it is or would become).
    pub kind: FaultKind,
    /// Where it was seen.
    pub source: Source,
}

impl Cause {
    /// A cause of `kind` seen at `source`.
    pub const fn new(kind: FaultKind, source: Source) -> Self {
        Self { kind, source }
    }
}

/// What a cause leads to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Decision {
    /// Stop smoothly, re-base the estimate on the measurement and plan the
    /// goal again from there (module `recovery`).
    Replan,
    /// Brake to rest and hold the grasp until reset.
    SafeHold,
    /// Nothing to do.
    Ignore,
}

/// The policy and its one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FaultPolicy {
    /// Recoveries allowed per goal (`feedback.max_replans`).
    pub max_replans: u32,
}

impl FaultPolicy {
    /// The decision for `cause` seen in `phase`, after `replans` recoveries
    /// of the current goal, `recovering` being true while an earlier
    /// recovery has not yet re-based (module docs, the table).
    pub fn decide(&self, cause: Cause, phase: Mode, replans: u32, recovering: bool) -> Decision {
        if phase == Mode::SafeHold {
            return Decision::Ignore;
        }
        let recoverable = match cause.source {
            Source::Measurement => cause.kind == FaultKind::ContactDrift,
            Source::NearLimit if phase != Mode::Moving => return Decision::Ignore,
            Source::NearLimit => true,
            Source::ExecutorCommand | Source::Trajectory | Source::Rebase | Source::Plant => false,
        };
        if recoverable && !recovering && replans < self.max_replans {
            Decision::Replan
        } else {
            Decision::SafeHold
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Decision::*;
    use FaultKind as K;
    use Mode as P;
    use Source as S;

    /// The module's table, row by row: (kind, source, phase, replans so
    /// far, recovering) → decision, with `max_replans` = 2.
    #[test]
    fn the_policy_table() {
        let policy = FaultPolicy { max_replans: 2 };
        #[rustfmt::skip]
        let table = [
            // Already in safe hold: nothing more.
            (K::ContactDrift, S::Measurement, P::SafeHold, 0, false, Ignore),
            (K::MissingMeasurement, S::Measurement, P::SafeHold, 0, false, Ignore),
            (K::ForceClosure, S::ExecutorCommand, P::SafeHold, 0, false, Ignore),
            (K::Trajectory, S::Trajectory, P::SafeHold, 0, false, Ignore),
            // A drift is recovered in every other phase, within the budget.
            (K::ContactDrift, S::Measurement, P::Moving, 0, false, Replan),
            (K::ContactDrift, S::Measurement, P::Stopping, 1, false, Replan),
            (K::ContactDrift, S::Measurement, P::Planning, 0, false, Replan),
            (K::ContactDrift, S::Measurement, P::Holding, 1, false, Replan),
            // ... but not twice at once, nor past the budget.
            (K::ContactDrift, S::Measurement, P::Stopping, 0, true, SafeHold),
            (K::ContactDrift, S::Measurement, P::Moving, 2, false, SafeHold),
            // Near a limit: like a drift while moving, else nothing.
            (K::Workspace, S::NearLimit, P::Moving, 0, false, Replan),
            (K::ForceClosure, S::NearLimit, P::Moving, 1, false, Replan),
            (K::Collision, S::NearLimit, P::Moving, 2, false, SafeHold),
            (K::Workspace, S::NearLimit, P::Moving, 0, true, SafeHold),
            (K::Workspace, S::NearLimit, P::Stopping, 0, false, Ignore),
            (K::Workspace, S::NearLimit, P::Holding, 0, false, Ignore),
            // Other measured faults: safe hold at once.
            (K::MissingMeasurement, S::Measurement, P::Holding, 0, false, SafeHold),
            (K::BadMeasurement, S::Measurement, P::Moving, 0, false, SafeHold),
            (K::ObjectTracking, S::Measurement, P::Moving, 0, false, SafeHold),
            (K::FingerTracking, S::Measurement, P::Stopping, 0, false, SafeHold),
            // The command or the generator broken, or a bad re-base.
            (K::ForceClosure, S::ExecutorCommand, P::Moving, 0, false, SafeHold),
            (K::Workspace, S::ExecutorCommand, P::Holding, 0, false, SafeHold),
            (K::Contact, S::ExecutorCommand, P::Planning, 0, false, SafeHold),
            (K::Trajectory, S::Trajectory, P::Stopping, 0, false, SafeHold),
            (K::ContactDrift, S::Rebase, P::Stopping, 0, false, SafeHold),
            // The plant.
            (K::PlantLost, S::Plant, P::Moving, 0, false, SafeHold),
            (K::PlantInvalid, S::Plant, P::Holding, 0, false, SafeHold),
            (K::PlantSequence, S::Plant, P::Planning, 0, false, SafeHold),
            (K::PlantFault, S::Plant, P::Stopping, 0, false, SafeHold),
            (K::ContactLost, S::Measurement, P::Moving, 0, false, SafeHold),
            (K::PlantLost, S::Plant, P::SafeHold, 0, false, Ignore),
            (K::PlantTiming, S::Plant, P::Moving, 0, false, SafeHold),
        ];
        for (kind, source, phase, replans, recovering, want) in table {
            let got = policy.decide(Cause::new(kind, source), phase, replans, recovering);
            assert_eq!(
                got, want,
                "{kind:?} from {source:?} in {phase:?} after {replans} (recovering {recovering})"
            );
        }
        // With no replans allowed, a drift holds at once.
        let none = FaultPolicy { max_replans: 0 };
        let drift = Cause::new(K::ContactDrift, S::Measurement);
        assert_eq!(none.decide(drift, P::Moving, 0, false), SafeHold);
    }
}
