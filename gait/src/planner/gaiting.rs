//! The paper's two finger-gaiting primitives (§2.1, SPEC §4.2) recognised
//! in the sequence of finished plan steps.
//!
//! - **Finger substitution**: a free finger k is placed, then a grasping
//!   finger i lifts; k has taken i's place in the grasp.
//! - **Finger rewind**: fingers of the grasping pair are moved back into
//!   their workspace with the free finger's help, and the pair grasps
//!   again. The paper's rewind of both fingers of the pair (i, j) with
//!   helper k is Place(k), Lift(j), Place(j), Lift(i), Place(i), Lift(k);
//!   rewinding one finger is Place(k), Lift(i), Place(i), Lift(k) (§2.1:
//!   "rewind f1 back to form a grasp with f2"). Both are substitutions in a
//!   row, without object motion, that end by lifting the helper they began
//!   by placing.
//!
//! So a rewind is reported as its substitutions and then as a rewind; no
//! substitution belongs to two rewinds. Object motion and rolling (a
//! Rotate or Roll step) break a chain of substitutions, and so does an
//! interruption (a new goal, a replan: [`GaitTracker::interrupt`]): a
//! rewind is one uninterrupted relocation. A substitution may have motion
//! between its Place and its Lift (paper §2.1: the new pair "can be used
//! to further move the object" before the lift), and a gait step in
//! flight when a goal is preempted still completes. A fault forgets
//! everything ([`GaitTracker::reset`]).
//!
//! Allocation-free and constant-time: the daemon runs it on the loop.

use crate::FINGERS;
use crate::planner::StepKind;

/// A recognised gait primitive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FingerGait {
    /// Finger `by` took the place of finger `left` in the grasp.
    Substitution {
        /// The finger that lifted.
        left: u8,
        /// The finger placed just before.
        by: u8,
    },
    /// The fingers in `relocated` were moved back into their workspace
    /// with `helper`'s help; the grasping pair is the one before, and
    /// `helper` is free again.
    Rewind {
        /// Bit k set when finger k was relocated (one or both of the pair).
        relocated: u8,
        /// The finger placed first and lifted last.
        helper: u8,
    },
}

/// What one finished step completed: at most a substitution and, with it,
/// a rewind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Completed {
    /// A substitution finished with this step.
    pub substitution: Option<FingerGait>,
    /// A rewind finished with this step (its last substitution is in
    /// `substitution`).
    pub rewind: Option<FingerGait>,
}

/// Recognises substitutions and rewinds in a stream of finished steps
/// (module docs).
#[derive(Debug, Clone, Copy, Default)]
pub struct GaitTracker {
    /// The finger placed since the last lift.
    placed: Option<u8>,
    /// Whether the object moved since that placement.
    moved: bool,
    /// Substitutions in the current chain.
    len: u32,
    /// Per finger: the chain index of the substitution that last placed it.
    placed_at: [Option<u32>; FINGERS],
    /// Per finger: the chain index of the substitution that last lifted it.
    lifted_at: [Option<u32>; FINGERS],
}

impl GaitTracker {
    /// A tracker with no history.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forgets everything (a fault: the motion stopped where it was).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Breaks the chain of substitutions (no rewind spans this point) but
    /// keeps a placement, whose lift is still a substitution.
    pub fn interrupt(&mut self) {
        *self = Self {
            placed: self.placed,
            moved: self.placed.is_some(),
            ..Self::default()
        };
    }

    /// A step of `kind` started. Object motion and rolling break a chain.
    pub fn started(&mut self, kind: StepKind) {
        if matches!(kind, StepKind::Rotate | StepKind::Roll) {
            self.interrupt();
        }
    }

    /// A step of `kind` moving `finger` ended where it was planned to.
    pub fn done(&mut self, kind: StepKind, finger: u8) -> Completed {
        match kind {
            StepKind::Place => {
                self.placed = Some(finger);
                self.moved = false;
                Completed::default()
            }
            StepKind::Lift => match self.placed.take() {
                Some(by) if by != finger && usize::from(by.max(finger)) < FINGERS => {
                    self.substituted(by, finger)
                }
                // No placement of another finger before it (e.g. a lift
                // from the three-finger start grasp): no substitution.
                _ => {
                    self.reset();
                    Completed::default()
                }
            },
            StepKind::Transfer | StepKind::Rotate | StepKind::Roll => Completed::default(),
        }
    }

    fn substituted(&mut self, by: u8, left: u8) -> Completed {
        let (b, l) = (usize::from(by), usize::from(left));
        let i = self.len;
        self.len += 1;
        // A placement from before object motion cannot begin a rewind.
        self.placed_at[b] = (!std::mem::take(&mut self.moved)).then_some(i);
        self.lifted_at[l] = Some(i);
        let substitution = Some(FingerGait::Substitution { left, by });
        // `left` grasps now, so the substitution that last placed it came
        // after any earlier lift of it: it has been the helper since.
        let Some(m) = self.placed_at[l] else {
            return Completed {
                substitution,
                rewind: None,
            };
        };
        let relocated = (0..FINGERS)
            .filter(|&f| f != l && self.lifted_at[f].is_some_and(|at| at >= m))
            .fold(0u8, |bits, f| bits | 1 << f);
        self.reset();
        Completed {
            substitution,
            rewind: Some(FingerGait::Rewind {
                relocated,
                helper: left,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use StepKind::{Lift, Place, Roll, Rotate, Transfer};

    fn run(t: &mut GaitTracker, steps: &[(StepKind, u8)]) -> Vec<FingerGait> {
        let mut out = Vec::new();
        for &(kind, finger) in steps {
            t.started(kind);
            let c = t.done(kind, finger);
            out.extend(c.substitution);
            out.extend(c.rewind);
        }
        out
    }

    fn sub(by: u8, left: u8) -> FingerGait {
        FingerGait::Substitution { left, by }
    }

    fn rewind(relocated: &[u8], helper: u8) -> FingerGait {
        FingerGait::Rewind {
            relocated: relocated.iter().fold(0, |b, f| b | 1 << f),
            helper,
        }
    }

    #[test]
    fn spec_rewind_of_both_fingers() {
        // SPEC §4.2 with (i, j, k) = (0, 1, 2).
        let steps = [
            (Transfer, 2),
            (Place, 2),
            (Lift, 1),
            (Transfer, 1),
            (Place, 1),
            (Lift, 0),
            (Transfer, 0),
            (Place, 0),
            (Lift, 2),
        ];
        let got = run(&mut GaitTracker::new(), &steps);
        let want = [sub(2, 1), sub(1, 0), sub(0, 2), rewind(&[0, 1], 2)];
        assert_eq!(got, want);
    }

    #[test]
    fn rewind_of_one_finger() {
        // Finger 0 moved back with finger 2's help; then a plain
        // substitution (2 replaces 1).
        let steps = [
            (Place, 2),
            (Lift, 0),
            (Place, 0),
            (Lift, 2),
            (Place, 2),
            (Lift, 1),
        ];
        let got = run(&mut GaitTracker::new(), &steps);
        assert_eq!(got, [sub(2, 0), sub(0, 2), rewind(&[0], 2), sub(2, 1)]);
    }

    #[test]
    fn a_substitution_then_a_rewind() {
        // 0 replaces 1 (pair 0, 2; free 1); then 2 is rewound with 1's help.
        let steps = [
            (Place, 0),
            (Lift, 1),
            (Place, 1),
            (Lift, 2),
            (Place, 2),
            (Lift, 1),
        ];
        let got = run(&mut GaitTracker::new(), &steps);
        assert_eq!(got, [sub(0, 1), sub(1, 2), sub(2, 1), rewind(&[2], 1)]);
    }

    #[test]
    fn passing_the_grasp_on_is_a_rewind_only_when_the_helper_leaves() {
        // 2 replaces 0, 0 replaces 1: no finger placed in the chain has
        // lifted again; then 1 replaces 2, the helper: the cycle closes
        // into the two-finger rewind.
        let mut t = GaitTracker::new();
        let got = run(&mut t, &[(Place, 2), (Lift, 0), (Place, 0), (Lift, 1)]);
        assert_eq!(got, [sub(2, 0), sub(0, 1)]);
        let got = run(&mut t, &[(Place, 1), (Lift, 2)]);
        assert_eq!(got, [sub(1, 2), rewind(&[0, 1], 2)]);
    }

    #[test]
    fn rewinds_do_not_share_substitutions() {
        // Alternating 2 ↔ 0: substitutions 1–2 and 3–4 are rewinds of
        // finger 0; 2–3 would be one of finger 2 if it could reuse 2.
        let cycle = [(Place, 2), (Lift, 0), (Place, 0), (Lift, 2)];
        let mut t = GaitTracker::new();
        let mut got = run(&mut t, &cycle);
        got.extend(run(&mut t, &cycle));
        let one = [sub(2, 0), sub(0, 2), rewind(&[0], 2)];
        assert_eq!(got, [one, one].concat());
    }

    #[test]
    fn object_motion_or_a_reset_breaks_the_chain() {
        let first = [(Place, 2), (Lift, 1)];
        for breaker in [Rotate, Roll] {
            let mut t = GaitTracker::new();
            run(&mut t, &first);
            let got = run(&mut t, &[(breaker, 255), (Place, 1), (Lift, 2)]);
            assert_eq!(got, [sub(1, 2)], "{breaker:?}");
            // Motion between a Place and its Lift: still a substitution,
            // but no start of a rewind.
            let mut t = GaitTracker::new();
            let got = run(
                &mut t,
                &[(Place, 2), (breaker, 255), (Lift, 1), (Place, 1), (Lift, 2)],
            );
            assert_eq!(got, [sub(2, 1), sub(1, 2)], "{breaker:?}");
        }
        let mut t = GaitTracker::new();
        run(&mut t, &first);
        t.reset();
        assert_eq!(run(&mut t, &[(Place, 1), (Lift, 2)]), [sub(1, 2)]);
        // An interruption (new goal, replan) breaks the chain too...
        let mut t = GaitTracker::new();
        run(&mut t, &first);
        t.interrupt();
        assert_eq!(run(&mut t, &[(Place, 1), (Lift, 2)]), [sub(1, 2)]);
        // ... but a gait in flight still completes its substitution.
        let mut t = GaitTracker::new();
        run(&mut t, &[(Place, 2)]);
        t.interrupt();
        assert_eq!(run(&mut t, &[(Lift, 1)]), [sub(2, 1)]);
        // A placement is forgotten too: a lift after a reset is no
        // substitution.
        let mut t = GaitTracker::new();
        run(&mut t, &[(Place, 2)]);
        t.reset();
        assert_eq!(run(&mut t, &[(Lift, 1)]), []);
    }

    #[test]
    fn lifts_from_three_fingers_and_bad_fingers_are_not_substitutions() {
        // From the paper's start (three grasping): lift one, place it back
        // elsewhere, lift another.
        let got = run(&mut GaitTracker::new(), &[(Lift, 0), (Place, 0), (Lift, 1)]);
        assert_eq!(got, [sub(0, 1)]);
        let got = run(&mut GaitTracker::new(), &[(Place, 1), (Lift, 1)]);
        assert_eq!(got, [], "the placed finger lifting again");
        let got = run(&mut GaitTracker::new(), &[(Place, 7), (Lift, 1)]);
        assert_eq!(got, [], "no such finger");
    }
}
