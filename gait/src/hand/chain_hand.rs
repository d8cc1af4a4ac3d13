//! A hand of three 3-joint finger chains with closed-form inverse
//! kinematics (TriFingerPro and hands like it; SPEC §14.1): its chains,
//! the object, gravity, friction and the limits a grasp keeps. The
//! planner's states ([`crate::HandState`]) put the object's centre at the
//! origin, as for the free fingertips: a finger's `center` is its tip
//! centre relative to O, (R + r)·n while it grasps, and its joints follow
//! from it ([`ChainHand::joints`]): of the closed-form branches inside
//! the joint limits, the one nearest a reference — the joints a moment
//! before, so that a finger moving along a path stays on its branch — or,
//! for a finger seen for the first time, the branch the workspace test
//! picks ([`kinematics::reach`]: inside the tip patch with the links
//! clear, the most joint-limit margin). Its tip orientation and roll in a
//! state are not used: the joints decide them.

use kinematics::{
    Chain, ClosedFormIk, DescriptionError, FingerGap, GraspLimits, HandDescription, NotClosedForm,
    Object,
};
use nalgebra::Vector3;

use crate::grasp::{FingerStatics, Friction, TorqueBoxSolver};
use crate::hand_state::FINGERS;

/// Why a chain hand could not be made from a description.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChainHandError {
    /// The description has not three fingers.
    #[error("a chain hand has three fingers; the description has {0}")]
    FingerCount(usize),
    /// A finger is not a 3-joint chain.
    #[error("finger {finger}: {source}")]
    Chain {
        /// The finger.
        finger: usize,
        /// What is wrong.
        source: DescriptionError,
    },
    /// A finger's structure has no closed-form inverse kinematics.
    #[error("finger {finger} has no closed-form inverse kinematics (not TriFingerPro-like)")]
    NotClosedForm {
        /// The finger.
        finger: usize,
    },
}

/// The hand (module docs).
#[derive(Debug, Clone)]
pub struct ChainHand {
    chains: [Chain<3>; FINGERS],
    iks: [ClosedFormIk; FINGERS],
    gaps: [FingerGap; 3],
    object: Object,
    gravity: Vector3<f64>,
    friction: kinematics::Friction,
    limits: GraspLimits,
}

impl ChainHand {
    /// The hand of a description, keeping `limits` (tip patch, link
    /// clearance, finger gap) beyond the joint limits' own margin.
    pub fn new(hand: &HandDescription, limits: GraspLimits) -> Result<Self, ChainHandError> {
        if hand.fingers.len() != FINGERS {
            return Err(ChainHandError::FingerCount(hand.fingers.len()));
        }
        let mut chains = Vec::with_capacity(FINGERS);
        for (finger, f) in hand.fingers.iter().enumerate() {
            let c = Chain::<3>::from_description(f, hand.joint_limit_margin)
                .map_err(|source| ChainHandError::Chain { finger, source })?;
            chains.push(c);
        }
        let chains: [Chain<3>; FINGERS] = std::array::from_fn(|k| chains[k]);
        let mut iks = Vec::with_capacity(FINGERS);
        for (finger, c) in chains.iter().enumerate() {
            let ik = ClosedFormIk::new(c)
                .map_err(|NotClosedForm| ChainHandError::NotClosedForm { finger })?;
            iks.push(ik);
        }
        let gaps = kinematics::carry::finger_gaps(&[&chains[0], &chains[1], &chains[2]]);
        Ok(Self {
            iks: std::array::from_fn(|k| iks[k]),
            chains,
            gaps,
            object: hand.object,
            gravity: hand.gravity,
            friction: hand.friction,
            limits,
        })
    }

    /// Finger `k`'s chain.
    pub fn chain(&self, k: usize) -> &Chain<3> {
        &self.chains[k]
    }

    /// The object (radius, mass, centre in the hand frame).
    pub fn object(&self) -> &Object {
        &self.object
    }

    /// The limits a grasp keeps beyond the joint limits' margin.
    pub fn limits(&self) -> &GraspLimits {
        &self.limits
    }

    /// The Coulomb coefficient μ of a tip on the object.
    pub fn friction_mu(&self) -> f64 {
        self.friction.mu
    }

    /// The torsional friction coefficient μ_t \[m\].
    pub fn friction_torsion(&self) -> f64 {
        self.friction.torsion
    }

    /// How finger `k` grasps at the outward unit normal `n` within the
    /// hand's margins, if it can (SPEC §14.1 "Workspace",
    /// [`kinematics::reach`]).
    pub fn reach(&self, k: usize, n: &Vector3<f64>) -> Option<kinematics::Reach> {
        kinematics::reach(
            &self.chains[k],
            &self.iks[k],
            &self.object,
            &self.gravity,
            n,
            &self.limits.margins,
        )
    }

    /// Gravity in the hand frame \[m/s²\].
    pub fn gravity(&self) -> &Vector3<f64> {
        &self.gravity
    }

    /// The gap test of two different fingers `a`, `b` (pairs left out in
    /// the zero pose already removed); its first side is the finger with
    /// the lower index.
    pub fn gap(&self, a: usize, b: usize) -> &FingerGap {
        debug_assert!(a != b && a < FINGERS && b < FINGERS);
        &self.gaps[(a + b).saturating_sub(1).min(2)]
    }

    /// The tip centre in the hand frame of a state's `center` (relative to
    /// the object's centre).
    pub fn tip_target(&self, center: &Vector3<f64>) -> Vector3<f64> {
        self.object.centre + center
    }

    /// Every finger grasping the object at the identity orientation, its
    /// tip centre on the outward normal `normals[k]` (any length) at
    /// R + r from the object's centre, the rest of the state as `config`'s
    /// start: a configured start grasp (whether the hand holds it is the
    /// planner's check of a start).
    pub fn grasp(&self, config: &crate::HandConfig, normals: &[[f64; 3]]) -> crate::HandState {
        let mut s = crate::HandState::paper_start(config);
        s.object = nalgebra::UnitQuaternion::identity();
        for (k, (f, n)) in s.fingers.iter_mut().zip(normals).enumerate() {
            f.mode = crate::FingerMode::Grasping;
            f.center =
                Vector3::from(*n).normalize() * (self.object.radius + self.chains[k].tip_radius);
        }
        s
    }

    /// Finger `k`'s joints with its tip centre at `center` (relative to
    /// the object's centre), on the branch nearest `reference` (module
    /// docs; `None`: the branch with the most joint-limit margin). `None`
    /// if no branch inside the joint limits puts the tip there.
    pub fn joints(
        &self,
        k: usize,
        center: &Vector3<f64>,
        reference: Option<&Vector3<f64>>,
    ) -> Option<Vector3<f64>> {
        let target = self.tip_target(center);
        let chain = &self.chains[k];
        match reference {
            Some(r) => self.iks[k].solve(&target, r).ok(),
            None => {
                // As the workspace test picks: the admissible branch (patch
                // and links clear too) with the most joint margin; else
                // the one with the most inside the limits.
                // (Iterated twice rather than collected: the per-tick
                // check asks this too, and a tick does not allocate.)
                let b = self.iks[k].branches(&target);
                let n = center.normalize();
                let inside = b.q[..b.len]
                    .iter()
                    .filter(|q| chain.limit_margin(q) >= 0.0)
                    .filter(|q| (chain.forward(q).tip_centre() - target).norm() <= 1e-9);
                let m = &self.limits.margins;
                let admissible = |q: &&Vector3<f64>| {
                    let s = chain.forward(q);
                    chain.patch.margin(&s.tip.rotation, &n) >= m.patch
                        && kinematics::workspace::object_clearance(chain, &s, &self.object)
                            >= m.clearance
                };
                let most = |a: &&Vector3<f64>, b: &&Vector3<f64>| {
                    chain.limit_margin(a).total_cmp(&chain.limit_margin(b))
                };
                inside
                    .clone()
                    .filter(admissible)
                    .max_by(most)
                    .or_else(|| inside.max_by(most))
                    .copied()
            }
        }
    }

    /// Finger `k`'s statics at joints `q` touching at the unit normal `n`:
    /// the torque box's input (SPEC §14.1 "Forces"), the links' weight
    /// included.
    pub fn statics(&self, k: usize, q: &Vector3<f64>, n: &Vector3<f64>) -> FingerStatics {
        let chain = &self.chains[k];
        let s = chain.forward(q);
        let jw = s.jacobian_w();
        let jp = s.jacobian_v() + n.cross_matrix() * jw * chain.tip_radius;
        FingerStatics {
            force_to_torque: jp.transpose(),
            moment_to_torque: jw.transpose(),
            bias: kinematics::gravity_torques(chain, &s, &self.gravity),
            limit: chain.effort(),
        }
    }

    /// Finger `k`'s joints with its tip centre at `center`, moving on from
    /// `before` (its joints a moment earlier): the branch nearest them,
    /// inside the limits or not ([`Self::nearest_branch`]); without
    /// `before`, the branch [`Self::joints`] picks for a finger seen for
    /// the first time.
    pub fn follow(
        &self,
        k: usize,
        center: &Vector3<f64>,
        before: Option<&Vector3<f64>>,
    ) -> Option<Vector3<f64>> {
        match before {
            Some(b) => self.nearest_branch(k, center, b),
            None => self.joints(k, center, None),
        }
    }

    /// Of the branches that put finger `k`'s tip at `center`, limits or
    /// not, the one nearest `reference` (each joint taken 2π-turn nearest
    /// it): where a finger moving along a path goes, inside its limits or
    /// not (`None` where no branch reaches).
    pub fn nearest_branch(
        &self,
        k: usize,
        center: &Vector3<f64>,
        reference: &Vector3<f64>,
    ) -> Option<Vector3<f64>> {
        let target = self.tip_target(center);
        let chain = &self.chains[k];
        let b = self.iks[k].branches(&target);
        let tau = std::f64::consts::TAU;
        b.q[..b.len]
            .iter()
            .filter(|q| (chain.forward(q).tip_centre() - target).norm() <= 1e-9)
            .map(|q| q.zip_map(reference, |q, r| q + tau * ((r - q) / tau).round()))
            .min_by(|a, b| (a - reference).norm().total_cmp(&(b - reference).norm()))
    }

    /// The best joint-limit margin \[rad\] of the branches that put finger
    /// `k`'s tip at `center` with no regard to the limits (negative where
    /// every branch is outside them; `None` where none reaches).
    pub fn best_limit_margin(&self, k: usize, center: &Vector3<f64>) -> Option<f64> {
        let target = self.tip_target(center);
        let chain = &self.chains[k];
        let b = self.iks[k].branches(&target);
        b.q[..b.len]
            .iter()
            .filter(|q| (chain.forward(q).tip_centre() - target).norm() <= 1e-9)
            .map(|q| chain.limit_margin(q))
            .max_by(f64::total_cmp)
    }

    /// The torque-box solver of the hand's friction.
    pub fn torque_box(&self) -> TorqueBoxSolver {
        TorqueBoxSolver::new(Friction {
            mu: self.friction.mu,
            mu_torsion: self.friction.torsion,
            object_radius: self.object.radius,
        })
    }

    /// The object's moment of inertia about O: a thin shell (a tennis
    /// ball), (2/3) m R² \[kg m²\].
    pub fn inertia(&self) -> f64 {
        2.0 / 3.0 * self.object.mass * self.object.radius * self.object.radius
    }
}
