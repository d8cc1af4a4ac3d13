//! The per-tick invariant check (SPEC.md §1.3).

use core::f64::consts::PI;

use nalgebra::Vector3;

use super::chain_check::ChainLimits;
use super::chain_hand::ChainHand;
use super::invariant_report::{
    Check, FcMethod, FingerReport, ForceClosureCheck, InvariantReport, PAIRS, SlipCheck,
    SlipReport, Unit,
};
use super::limits::{Bound, FingertipLimits};
use crate::grasp::facts::angle_between;
use crate::grasp::planar::three_hard_certificate;
use crate::grasp::{ClosureMargin, ConicSolver, Contact, ContactKind};
use crate::hand_state::{FingerMode, FingerState, HandState};
use crate::{ConfigError, HandConfig};

/// Why a state could not be checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum StateError {
    /// The object orientation has a non-finite component.
    #[error("object orientation is not finite")]
    ObjectNotFinite,
    /// A finger's centre, orientation or roll has a non-finite component.
    #[error("finger {finger} state is not finite")]
    FingerNotFinite {
        /// Finger index.
        finger: u8,
    },
    /// A fingertip centre is at the object centre (no contact direction).
    #[error("finger {finger} centre is at the object centre")]
    CentreAtOrigin {
        /// Finger index.
        finger: u8,
    },
}

/// The last conic verdict and the contact normals it was computed for.
type ConicCache = (
    [Vector3<f64>; 3],
    Result<ClosureMargin, crate::grasp::GraspError>,
);

/// Checks every invariant of SPEC §1.3 for a hand state.
///
/// Which limit each invariant uses (SPEC §1.3):
/// - I1: force closure *with margin* δ = `model.fc_margin_deg`: two
///   grasping fingers by Fact 3 (soft, separation > π − 2θ + δ); three by,
///   in order, "some pair passes Fact 3 on its own", Fact 4 at θ − δ/2,
///   the planar certificate ([`crate::grasp::planar`]) at θ − δ/2, and if
///   none of them certifies force closure, the exact conic test at
///   θ − δ/2 (t* > 0) — unless the conic fallback is switched off
///   ([`InvariantChecker::set_conic_fallback`]), in which case the state
///   fails I1. Friction angle θ − δ/2 is what makes all tests one notion
///   of "margin δ". Fewer than two grasping fingers fail.
/// - I2: contacts and free fingertip directions within β − workspace
///   margin of d_k; free fingertip centres in R + r < |p| ≤ R + r + δR.
/// - I3: fingertip contact in the closed hemisphere; |τ| ≤ γ (the roll
///   margin is for planning, [`Bound::Margin`]).
/// - I4: fingertip centres at least 2r + clearance apart.
/// - I5 (state part): grasping fingertips touch, ||p| − (R + r)| ≤
///   contact tolerance (the object centre is O by construction). The
///   no-slip part needs two states: [`InvariantChecker::check_slip`].
///
/// Closed limits pass within [`super::SLACK_TOLERANCE`] of the boundary;
/// force closure and the inner shell bound are strict.
///
/// # Cost (`cargo bench -p gait --bench hand`)
/// A whole check costs about 0.3–0.5 µs (median) when a closed form
/// decides, and at most a few µs when the planar certificate has to run;
/// none of it allocates. The planar certificate finds every force-closure
/// triple the conic test finds (no miss on the seeded sweeps; it can only
/// miss grasps whose margin vanishes) — and on those sweeps no
/// force-closure triple even needed it beyond a Fact 3 pair or Fact 4 —
/// so the conic test runs only on three-finger states that are *not*
/// force-closure with margin, i.e. that already violate I1, to say by how
/// much. It re-solves a prebuilt Clarabel problem: about 60–100 µs and one
/// 404-byte allocation inside clarabel per solve (the `grasp` module
/// docs); the result is cached while the three contact normals stay bit
/// for bit the same. A real-time caller that needs a hard bound switches
/// the fallback off: then nothing ever allocates, the verdict is the same,
/// and a failing three-finger state reports the best closed-form slack.
#[derive(Debug)]
pub struct InvariantChecker {
    model: FingertipLimits,
    conic: ConicSolver,
    cache: Option<ConicCache>,
    conic_solves: u64,
    conic_fallback: bool,
    /// A chain hand's limits in place of the fingertips' (boxed: a hand
    /// description is a few kilobytes the fingertip checker does not
    /// carry).
    chains: Option<Box<ChainLimits>>,
}

fn finger_finite(f: &FingerState) -> bool {
    f.center.iter().all(|v| v.is_finite())
        && f.orientation.coords.iter().all(|v| v.is_finite())
        && f.roll.is_finite()
}

/// Validates the numbers of a state before any geometry is done on it.
pub fn validate_state(state: &HandState) -> Result<(), StateError> {
    if !state.object.coords.iter().all(|v| v.is_finite()) {
        return Err(StateError::ObjectNotFinite);
    }
    for (k, f) in state.fingers.iter().enumerate() {
        if !finger_finite(f) {
            return Err(StateError::FingerNotFinite { finger: k as u8 });
        }
        if f.center.norm() <= 1e-12 {
            return Err(StateError::CentreAtOrigin { finger: k as u8 });
        }
    }
    Ok(())
}

impl InvariantChecker {
    /// Validates `config`, builds the model and the conic problem for three
    /// hard contacts (allocates; afterwards only a conic re-solve does, see
    /// the type docs).
    pub fn new(config: &HandConfig) -> Result<Self, ConfigError> {
        let model = FingertipLimits::new(config)?;
        let mut conic = ConicSolver::new(model.margin_friction());
        // The model is validated, so the build cannot fail for bad data;
        // if Clarabel refused anyway, the first conic check reports
        // ConicFailed instead of panicking.
        let _ = conic.prepare(&[ContactKind::Hard; 3]);
        Ok(Self {
            model,
            conic,
            cache: None,
            conic_solves: 0,
            conic_fallback: true,
            chains: None,
        })
    }

    /// The checker of a hand of finger chains (SPEC §14.1): force closure
    /// and contact as for the fingertips (`config` holds the hand's
    /// friction and radii, as `ChainModel` (the chain planner's model)
    /// sets them), the chain's limits in place of the fingertips'
    /// ([`ChainLimits`]).
    pub fn for_chains(config: &HandConfig, hand: ChainHand) -> Result<Self, ConfigError> {
        let mut c = Self::new(config)?;
        c.chains = Some(Box::new(ChainLimits::new(hand)));
        Ok(c)
    }

    /// The chain hand's limits and the joints of the state checked last
    /// (`None` for free fingertips).
    pub fn chain_limits(&self) -> Option<&ChainLimits> {
        self.chains.as_deref()
    }

    /// See [`Self::chain_limits`].
    pub fn chain_limits_mut(&mut self) -> Option<&mut ChainLimits> {
        self.chains.as_deref_mut()
    }

    /// Whether three-finger states without a closed-form or planar
    /// certificate go to the conic test (default) or simply fail I1 (no
    /// solver on the path: bounded cost, never allocates).
    pub fn set_conic_fallback(&mut self, on: bool) {
        self.conic_fallback = on;
    }

    /// See [`Self::set_conic_fallback`].
    pub fn conic_fallback(&self) -> bool {
        self.conic_fallback
    }

    /// The model.
    pub fn model(&self) -> &FingertipLimits {
        &self.model
    }

    /// How many conic solves this checker has run (for diagnostics and
    /// for tests of how rare they are).
    pub fn conic_solves(&self) -> u64 {
        self.conic_solves
    }

    /// Checks I1–I4 and the state part of I5 (see the type docs); on a
    /// chain hand, with the limits of SPEC §14.1 ([`ChainLimits`]).
    pub fn check(&mut self, state: &HandState) -> Result<InvariantReport, StateError> {
        validate_state(state)?;
        let m = self.model;
        let fingers = core::array::from_fn(|k| finger_report(&m, k, &state.fingers[k]));
        let collisions = PAIRS.map(|(i, j)| {
            Check::closed(
                m.collision_slack(&state.fingers[i].center, &state.fingers[j].center),
                Unit::Metre,
            )
        });
        let mut report = InvariantReport {
            force_closure: self.force_closure(state),
            fingers,
            collisions,
            chains: false,
        };
        if let Some(c) = &mut self.chains {
            c.apply(state, &mut report);
        }
        Ok(report)
    }

    /// I1 alone.
    pub fn force_closure(&mut self, state: &HandState) -> ForceClosureCheck {
        let (idx, n) = state.grasping();
        let normal = |k: usize| state.fingers[k].contact_normal();
        let grasping = n as u8;
        match n {
            0 | 1 => ForceClosureCheck {
                check: Check::open(n as f64 - 2.0, Unit::Contacts),
                method: FcMethod::TooFewContacts,
                grasping,
            },
            2 => ForceClosureCheck {
                check: Check::open(
                    self.model.pair_fc_slack(&normal(idx[0]), &normal(idx[1])),
                    Unit::Radian,
                ),
                method: FcMethod::Fact3 {
                    pair: [idx[0] as u8, idx[1] as u8],
                },
                grasping,
            },
            _ => self.three_finger(idx.map(normal), idx, grasping),
        }
    }

    fn three_finger(
        &mut self,
        n: [Vector3<f64>; 3],
        idx: [usize; 3],
        grasping: u8,
    ) -> ForceClosureCheck {
        let m = &self.model;
        let mut best = (f64::NEG_INFINITY, [0u8; 2]);
        for (a, b) in PAIRS {
            let s = m.pair_fc_slack(&n[a], &n[b]);
            if s > best.0 {
                best = (s, [idx[a] as u8, idx[b] as u8]);
            }
        }
        if best.0 > 0.0 {
            return ForceClosureCheck {
                check: Check::open(best.0, Unit::Radian),
                method: FcMethod::Fact3 { pair: best.1 },
                grasping,
            };
        }
        let f4 = m.fact4_slack(&n);
        if f4 > 0.0 {
            return ForceClosureCheck {
                check: Check::open(f4, Unit::Radian),
                method: FcMethod::Fact4,
                grasping,
            };
        }
        let theta = m.friction_angle() - 0.5 * m.fc_margin();
        if let Some(margin) = three_hard_certificate(&n, theta) {
            return ForceClosureCheck {
                check: Check::open(margin, Unit::Radian),
                method: FcMethod::Planar,
                grasping,
            };
        }
        let closed_best = best.0.max(f4);
        if !self.conic_fallback {
            return ForceClosureCheck {
                check: Check {
                    pass: false,
                    slack: closed_best.min(0.0),
                    unit: Unit::Radian,
                },
                method: FcMethod::NoCertificate,
                grasping,
            };
        }
        let result = match &self.cache {
            Some((key, r)) if bits_equal(key, &n) => *r,
            _ => {
                self.conic_solves += 1;
                let r = self.conic.margin(&n.map(Contact::hard));
                self.cache = Some((n, r));
                r
            }
        };
        let (check, method) = match result {
            Ok(ClosureMargin {
                rank, t_star: None, ..
            }) => (
                Check::open(f64::from(rank) - 6.0, Unit::Rank),
                FcMethod::RankDeficient,
            ),
            Ok(ClosureMargin {
                t_star: Some(t), ..
            }) => (Check::open(t, Unit::NormalisedForce), FcMethod::Conic),
            Err(_) => (
                Check {
                    pass: false,
                    slack: closed_best.min(0.0),
                    unit: Unit::Radian,
                },
                FcMethod::ConicFailed,
            ),
        };
        ForceClosureCheck {
            check,
            method,
            grasping,
        }
    }

    /// I5 no-slip between two consecutive states, for every finger that
    /// grasps in both: the contact points on object and fingertip travelled
    /// equal arcs, |R Δ_o − r Δ_f| ≤ slip tolerance, with Δ_o the angle
    /// between the object-frame contacts Q_oᵀ n and Δ_f between the
    /// fingertip-frame contacts Q_fᵀ(−n) (SPEC §2.3). If either state has
    /// fewer than three grasping fingers the grasp is soft and spin about
    /// the normal is forbidden too: the relative rotation of fingertip
    /// w.r.t. object over the step, projected on the contact normal, must
    /// stay within slip tolerance / r. Both are step-size-consistent to
    /// second order (meant for consecutive control ticks).
    pub fn check_slip(&self, prev: &HandState, next: &HandState) -> Result<SlipReport, StateError> {
        validate_state(prev)?;
        validate_state(next)?;
        let m = &self.model;
        let tol = m.config().model.slip_tolerance;
        let soft = prev.grasping().1 < 3 || next.grasping().1 < 3;
        let fingers = core::array::from_fn(|k| {
            let (a, b) = (&prev.fingers[k], &next.fingers[k]);
            if a.mode != FingerMode::Grasping || b.mode != FingerMode::Grasping {
                return None;
            }
            let (oa, ob) = (prev.object_contact(k), next.object_contact(k));
            let d_o = angle_between(&oa, &ob);
            let d_f = angle_between(&a.fingertip_contact(), &b.fingertip_contact());
            let arc = Check::closed(
                tol - (m.object_radius() * d_o - m.fingertip_radius() * d_f).abs(),
                Unit::Metre,
            );
            let spin = soft.then(|| {
                let rel_a = prev.object.inverse() * a.orientation;
                let rel_b = next.object.inverse() * b.orientation;
                let step = (rel_b * rel_a.inverse()).scaled_axis();
                let normal = (oa + ob).normalize();
                let spin = if normal.iter().all(|v| v.is_finite()) {
                    step.dot(&normal)
                } else {
                    PI
                };
                Check::closed(tol / m.fingertip_radius() - spin.abs(), Unit::Radian)
            });
            Some(SlipCheck { arc, spin })
        });
        Ok(SlipReport { fingers })
    }
}

fn bits_equal(a: &[Vector3<f64>; 3], b: &[Vector3<f64>; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| {
        x.iter()
            .zip(y.iter())
            .all(|(u, v)| u.to_bits() == v.to_bits())
    })
}

fn finger_report(m: &FingertipLimits, k: usize, f: &FingerState) -> FingerReport {
    let roll = Some(Check::closed(
        m.roll_slack(f.roll, Bound::Limit),
        Unit::Radian,
    ));
    let workspace = Check::closed(m.workspace_slack(k, &f.center, Bound::Margin), Unit::Radian);
    match f.mode {
        FingerMode::Grasping => FingerReport {
            mode: f.mode,
            workspace,
            shell: None,
            contact: Some(Check::closed(m.contact_slack(&f.center), Unit::Metre)),
            hemisphere: Some(Check::closed(
                m.hemisphere_slack(&f.fingertip_contact()),
                Unit::Radian,
            )),
            roll,
            links: None,
        },
        FingerMode::Free => {
            let d = f.center.norm();
            let inner = d - m.contact_radius();
            let outer = m.shell_outer_radius() - d;
            FingerReport {
                mode: f.mode,
                workspace,
                shell: Some(Check {
                    pass: inner > 0.0 && outer >= -super::SLACK_TOLERANCE,
                    slack: inner.min(outer),
                    unit: Unit::Metre,
                }),
                contact: None,
                hemisphere: None,
                roll,
                links: None,
            }
        }
    }
}
