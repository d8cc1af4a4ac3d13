//! What the invariant check reports (SPEC.md §1.3): per invariant, pass or
//! fail, which finger or pair, and the signed slack in natural units.

use crate::hand_state::{FINGERS, FingerMode};

/// Unit of a slack.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Unit {
    /// Radians.
    Radian,
    /// Metres.
    Metre,
    /// Tangential force per unit total normal force (the conic margin t*).
    NormalisedForce,
    /// Grasping contacts, relative to the two force closure needs.
    Contacts,
    /// Rank of the grasp map, relative to 6.
    Rank,
}

/// One evaluated constraint: signed slack (≥ 0 satisfied for closed
/// constraints) and the verdict, which also encodes strictness (open
/// bounds need slack > 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Check {
    /// Whether the constraint holds.
    pub pass: bool,
    /// Signed distance to the limit (negative: violated by that much).
    pub slack: f64,
    /// Unit of `slack`.
    pub unit: Unit,
}

impl Check {
    /// A closed constraint: passes when slack ≥ −[`super::SLACK_TOLERANCE`].
    pub fn closed(slack: f64, unit: Unit) -> Self {
        Self {
            pass: slack >= -super::SLACK_TOLERANCE,
            slack,
            unit,
        }
    }

    /// An open constraint: passes when slack > 0.
    pub fn open(slack: f64, unit: Unit) -> Self {
        Self {
            pass: slack > 0.0,
            slack,
            unit,
        }
    }
}

/// Which invariant (SPEC §1.3) a check belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Invariant {
    /// I1 force closure of the grasping fingers (with margin).
    ForceClosure,
    /// I2 contact point inside its workspace cone W_k (with margin).
    Workspace,
    /// I2 lifted fingertip inside its free-space shell (radial part).
    FreeSpace,
    /// I3 fingertip contact inside the fingertip hemisphere.
    Hemisphere,
    /// I3 |τ| ≤ γ.
    Roll,
    /// I4 no fingertip collision.
    Collision,
    /// I5 object centre fixed: a grasping fingertip touches, |p| = R + r.
    Contact,
    /// I5 no slip: equal arcs on object and fingertip.
    Slip,
    /// I5 no spin about the normal in a two-finger grasp.
    Spin,
    /// A chain finger's workspace (SPEC §14.1, replaces the cone W_k): a
    /// branch of its inverse kinematics puts the tip there inside the
    /// joint limits with the chain's margin.
    JointLimit,
    /// A chain finger's contact on its tip patch (SPEC §14.1, replaces
    /// the hemisphere and the roll limit).
    TipPatch,
    /// A chain finger's links clear of the object (SPEC §14.1).
    LinkClearance,
}

/// What a check is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Subject {
    /// The grasp as a whole.
    Grasp,
    /// One finger (0, 1, 2).
    Finger(u8),
    /// A pair of fingers.
    Pair(u8, u8),
}

/// A failed check, with where and by how much.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// The invariant.
    pub invariant: Invariant,
    /// Finger, pair or grasp.
    pub subject: Subject,
    /// Signed slack (negative or, for open bounds, zero).
    pub slack: f64,
    /// Unit of `slack`.
    pub unit: Unit,
}

/// How I1 was decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FcMethod {
    /// Fewer than two grasping fingers.
    TooFewContacts,
    /// Fact 3 with margin on this pair (two soft contacts; or, with three
    /// fingers, the pair holds on its own and the third carries no load).
    Fact3 {
        /// The two fingers.
        pair: [u8; 2],
    },
    /// Fact 4 at the margin friction angle θ − δ/2.
    Fact4,
    /// The planar certificate (explicit internal forces) at θ − δ/2; slack
    /// is the angular margin of the forces found \[rad\].
    Planar,
    /// No certificate and the conic fallback is off: counted as not
    /// force-closure; slack is the best closed-form slack (≤ 0) \[rad\].
    NoCertificate,
    /// The exact conic test (SPEC §3.2) at θ − δ/2; slack is t*. Reached
    /// only when no closed form or certificate shows force closure.
    Conic,
    /// The grasp map has rank < 6 (coincident contacts).
    RankDeficient,
    /// The conic solver gave no answer; counted as not force-closure, slack
    /// is the best closed-form slack.
    ConicFailed,
}

/// I1 result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceClosureCheck {
    /// Verdict and slack.
    pub check: Check,
    /// Which test decided.
    pub method: FcMethod,
    /// Number of grasping fingers.
    pub grasping: u8,
}

/// Per-finger results.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerReport {
    /// Grasping or free.
    pub mode: FingerMode,
    /// I2 workspace \[rad\]. Free fingertips: the cone with margin, of the
    /// contact normal (grasping) or of the fingertip-centre direction
    /// (free). Chains ([`Invariant::JointLimit`]): the joint-limit margin,
    /// beyond the chain's own, of the branch the finger is on (of the best
    /// branch where none is inside the limits; −π where none reaches).
    pub workspace: Check,
    /// I2: free fingers only, radial slack inside the shell \[m\] (open at
    /// R + r). Chains: the tip's height above the object (no outer bound:
    /// reach and clearance bound a chain's free tip).
    pub shell: Option<Check>,
    /// I5 object-centre part: grasping fingers only, contact tolerance −
    /// ||p| − (R + r)| \[m\].
    pub contact: Option<Check>,
    /// I3: grasping fingers only \[rad\]. Free fingertips: the hemisphere,
    /// asin(m_z). Chains ([`Invariant::TipPatch`]): the tip-patch margin
    /// beyond the hand's.
    pub hemisphere: Option<Check>,
    /// I3: γ − |τ| \[rad\]; `None` on chains (the joints set the tip's
    /// orientation: no roll to limit).
    pub roll: Option<Check>,
    /// Chains only: the finger's links off the object, beyond the hand's
    /// clearance \[m\] ([`Invariant::LinkClearance`]).
    pub links: Option<Check>,
}

/// Finger pairs in the order of [`InvariantReport::collisions`].
pub const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

/// The invariants of SPEC §1.3 for one hand state (of a chain hand, with
/// the limits of §14.1 in place of the fingertips' own).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InvariantReport {
    /// I1.
    pub force_closure: ForceClosureCheck,
    /// I2, I3, I5 (contact) per finger.
    pub fingers: [FingerReport; FINGERS],
    /// I4 per pair of [`PAIRS`] \[m\]: free fingertips, fingertip distance
    /// − (2r + clearance); chains, the gap between the two fingers' parts
    /// (link capsules and tips) − the hand's finger gap.
    pub collisions: [Check; 3],
    /// Whether the hand is one of finger chains (which limits the
    /// `fingers` checks are).
    pub chains: bool,
}

impl InvariantReport {
    /// Every check, in order I1, per finger (I2 workspace, I2 shell, I5
    /// contact, I3 hemisphere, I3 roll; chains: joint limits, shell,
    /// contact, tip patch, link clearance), then I4 pairs.
    pub fn checks(&self) -> impl Iterator<Item = (Invariant, Subject, Check)> + '_ {
        let fc = core::iter::once((
            Invariant::ForceClosure,
            Subject::Grasp,
            self.force_closure.check,
        ));
        let (workspace, tip) = if self.chains {
            (Invariant::JointLimit, Invariant::TipPatch)
        } else {
            (Invariant::Workspace, Invariant::Hemisphere)
        };
        let fingers = self.fingers.iter().enumerate().flat_map(move |(k, f)| {
            let s = Subject::Finger(k as u8);
            [
                Some((workspace, s, f.workspace)),
                f.shell.map(|c| (Invariant::FreeSpace, s, c)),
                f.contact.map(|c| (Invariant::Contact, s, c)),
                f.hemisphere.map(|c| (tip, s, c)),
                f.roll.map(|c| (Invariant::Roll, s, c)),
                f.links.map(|c| (Invariant::LinkClearance, s, c)),
            ]
            .into_iter()
            .flatten()
        });
        let pairs = self
            .collisions
            .iter()
            .zip(PAIRS)
            .map(|(c, (i, j))| (Invariant::Collision, Subject::Pair(i as u8, j as u8), *c));
        fc.chain(fingers).chain(pairs)
    }

    /// Every failed check, in the order of [`Self::checks`].
    pub fn violations(&self) -> impl Iterator<Item = Violation> + '_ {
        self.checks()
            .filter(|(_, _, c)| !c.pass)
            .map(|(invariant, subject, c)| Violation {
                invariant,
                subject,
                slack: c.slack,
                unit: c.unit,
            })
    }

    /// The first failed check, if any.
    pub fn first_violation(&self) -> Option<Violation> {
        self.violations().next()
    }

    /// Whether every invariant holds.
    pub fn ok(&self) -> bool {
        self.checks().all(|(_, _, c)| c.pass)
    }
}

/// I5 between two consecutive states, per finger grasping in both.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipCheck {
    /// Slip tolerance − |R Δ_o − r Δ_f| \[m\].
    pub arc: Check,
    /// Two-finger grasps only: slip tolerance / r − |spin| \[rad\].
    pub spin: Option<Check>,
}

/// I5 (no slip) between two consecutive states.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipReport {
    /// Per finger; `None` when it is not grasping in both states.
    pub fingers: [Option<SlipCheck>; FINGERS],
}

impl SlipReport {
    /// Every failed check.
    pub fn violations(&self) -> impl Iterator<Item = Violation> + '_ {
        self.fingers.iter().enumerate().flat_map(|(k, f)| {
            let s = Subject::Finger(k as u8);
            let arc = f.map(|f| (Invariant::Slip, f.arc));
            let spin = f.and_then(|f| f.spin).map(|c| (Invariant::Spin, c));
            [arc, spin]
                .into_iter()
                .flatten()
                .filter(|(_, c)| !c.pass)
                .map(move |(invariant, c)| Violation {
                    invariant,
                    subject: s,
                    slack: c.slack,
                    unit: c.unit,
                })
        })
    }

    /// Whether no grasping contact slipped.
    pub fn ok(&self) -> bool {
        self.violations().next().is_none()
    }
}
