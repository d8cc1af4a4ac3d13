//! The hand's geometric limits as signed slacks (SPEC.md §1.1, §1.3).
//!
//! Every predicate returns a *slack*: ≥ 0 inside, < 0 outside, in natural
//! units (radians for angles, metres for lengths), so callers can both
//! decide and say by how much. [`Bound`] selects the hard limit or the
//! limit shrunk by its configured margin (the planner plans inside the
//! margins; SPEC §1.3 states which invariant uses which, see
//! [`super::InvariantChecker`]).

use core::f64::consts::FRAC_PI_2;

use nalgebra::Vector3;

use crate::grasp::facts::{angle_between, fact3_slack, fact4_slack};
use crate::grasp::{Contact, Friction};
use crate::hand_state::{FINGERS, FingerMode, HandState};
use crate::{ConfigError, HandConfig};

/// Which limit a slack is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Bound {
    /// The physical limit itself (β, γ).
    Limit,
    /// The limit shrunk by its configured margin (β − workspace margin,
    /// γ − roll margin).
    Margin,
}

/// Absolute tolerance \[rad or m\] that closed limits allow for rounding:
/// a closed constraint passes when its slack is ≥ −SLACK_TOLERANCE.
pub const SLACK_TOLERANCE: f64 = 1e-9;

/// The free-fingertip hand's limits and the object, precomputed from a
/// validated [`HandConfig`] (SPEC §1.1). (The planner's view of a hand is
/// another thing: `crate::planner::hand_model::HandModel`.) Cheap to copy;
/// every method is pure and allocation-free.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingertipLimits {
    config: HandConfig,
    object_radius: f64,
    fingertip_radius: f64,
    contact_radius: f64,
    shell_outer: f64,
    base: [Vector3<f64>; FINGERS],
    workspace: f64,
    workspace_margin: f64,
    roll_limit: f64,
    roll_margin: f64,
    min_distance: f64,
    theta: f64,
    fc_margin: f64,
    friction: Friction,
    friction_margin: Friction,
}

impl FingertipLimits {
    /// Validates `config` and precomputes the model.
    pub fn new(config: &HandConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let m = &config.model;
        let base = m.finger_azimuth_deg.map(|deg| {
            let phi = deg.to_radians();
            Vector3::new(phi.cos(), phi.sin(), 0.0)
        });
        let friction = Friction::from_config(config);
        let fc_margin = m.fc_margin_deg.to_radians();
        Ok(Self {
            config: *config,
            object_radius: m.object_radius,
            fingertip_radius: m.fingertip_radius,
            contact_radius: m.object_radius + m.fingertip_radius,
            shell_outer: m.object_radius + m.fingertip_radius + m.free_space_height,
            base,
            workspace: m.workspace_half_angle_deg.to_radians(),
            workspace_margin: m.workspace_margin_deg.to_radians(),
            roll_limit: m.roll_limit_deg.to_radians(),
            roll_margin: m.roll_margin_deg.to_radians(),
            min_distance: 2.0 * m.fingertip_radius + m.fingertip_clearance,
            theta: m.friction_angle_deg.to_radians(),
            fc_margin,
            friction,
            friction_margin: friction.reduced(0.5 * fc_margin),
        })
    }

    /// The configuration this model was built from.
    pub fn config(&self) -> &HandConfig {
        &self.config
    }

    /// Object radius R \[m\].
    pub fn object_radius(&self) -> f64 {
        self.object_radius
    }

    /// Fingertip radius r \[m\].
    pub fn fingertip_radius(&self) -> f64 {
        self.fingertip_radius
    }

    /// Fingertip-centre distance of a touching finger, R + r \[m\].
    pub fn contact_radius(&self) -> f64 {
        self.contact_radius
    }

    /// Outer radius of the free-space shell, R + r + δR \[m\].
    pub fn shell_outer_radius(&self) -> f64 {
        self.shell_outer
    }

    /// Base direction d_k of finger k (unit, hand frame).
    pub fn base_direction(&self, finger: usize) -> Vector3<f64> {
        self.base[finger % FINGERS]
    }

    /// Workspace half angle β, or β − margin \[rad\].
    pub fn workspace_angle(&self, bound: Bound) -> f64 {
        match bound {
            Bound::Limit => self.workspace,
            Bound::Margin => self.workspace - self.workspace_margin,
        }
    }

    /// Roll limit γ, or γ − margin \[rad\].
    pub fn roll_limit(&self, bound: Bound) -> f64 {
        match bound {
            Bound::Limit => self.roll_limit,
            Bound::Margin => self.roll_limit - self.roll_margin,
        }
    }

    /// Friction angle θ \[rad\].
    pub fn friction_angle(&self) -> f64 {
        self.theta
    }

    /// Force-closure angle margin δ (on the separation of Fact 3) \[rad\].
    pub fn fc_margin(&self) -> f64 {
        self.fc_margin
    }

    /// The model's friction (μ = tan θ, μ_t, R).
    pub fn friction(&self) -> Friction {
        self.friction
    }

    /// Friction at θ − δ/2: force closure at it is force closure "with
    /// angle margin δ" (Fact 3's separation bound grows by exactly δ); the
    /// I1 check uses it for Fact 4 and the conic test.
    pub fn margin_friction(&self) -> Friction {
        self.friction_margin
    }

    /// Smallest allowed distance between fingertip centres, 2r + clearance \[m\].
    pub fn min_fingertip_distance(&self) -> f64 {
        self.min_distance
    }

    /// I2 workspace: (β \[− margin\]) − angle(c, d_k) \[rad\] for a direction
    /// `c` (contact normal or free fingertip direction; any length > 0).
    pub fn workspace_slack(&self, finger: usize, c: &Vector3<f64>, bound: Bound) -> f64 {
        self.workspace_angle(bound) - angle_between(c, &self.base_direction(finger))
    }

    /// I2 free space, radial part \[m\]: min(|p| − (R + r), R + r + δR − |p|).
    /// The inner bound is open (|p| = R + r is touching, not free).
    pub fn shell_slack(&self, p: &Vector3<f64>) -> f64 {
        let d = p.norm();
        (d - self.contact_radius).min(self.shell_outer - d)
    }

    /// I3 fingertip hemisphere: π/2 − angle(m, e_z) = asin(m_z) \[rad\] for
    /// the fingertip contact `m` (fingertip frame). The boundary (the
    /// fingertip equator) is allowed.
    pub fn hemisphere_slack(&self, m: &Vector3<f64>) -> f64 {
        FRAC_PI_2 - angle_between(m, &Vector3::z())
    }

    /// I3 roll: (γ \[− margin\]) − |τ| \[rad\].
    pub fn roll_slack(&self, roll: f64, bound: Bound) -> f64 {
        self.roll_limit(bound) - roll.abs()
    }

    /// I4: |p_i − p_j| − (2r + clearance) \[m\].
    pub fn collision_slack(&self, p_i: &Vector3<f64>, p_j: &Vector3<f64>) -> f64 {
        (p_i - p_j).norm() - self.min_distance
    }

    /// I5 (object centre fixed, fingertip on the object): contact tolerance
    /// − ||p| − (R + r)| \[m\] for a grasping fingertip centre `p`.
    pub fn contact_slack(&self, p: &Vector3<f64>) -> f64 {
        self.config.model.contact_tolerance - (p.norm() - self.contact_radius).abs()
    }

    /// I1 for two soft contacts: Fact 3 with the angle margin δ,
    /// angle(n_i, n_j) − (π − 2θ + δ) \[rad\]; force-closure iff > 0.
    pub fn pair_fc_slack(&self, n_i: &Vector3<f64>, n_j: &Vector3<f64>) -> f64 {
        fact3_slack(n_i, n_j, self.theta, self.fc_margin)
    }

    /// Fact 4 slack at the margin friction angle θ − δ/2 \[rad\]; the three
    /// hard contacts are force-closure with margin if it is > 0.
    pub fn fact4_slack(&self, n: &[Vector3<f64>; 3]) -> f64 {
        fact4_slack(&n[0], &n[1], &n[2], self.theta - 0.5 * self.fc_margin)
    }

    /// The grasping fingers' contacts: soft for a two-finger grasp, hard
    /// otherwise (SPEC §1.2); returns the contacts and their finger indices
    /// and count (unused entries are copies of the first).
    pub fn contacts(&self, state: &HandState) -> ([Contact; FINGERS], [usize; FINGERS], usize) {
        let (idx, n) = state.grasping();
        let soft = n == 2;
        let mut out = [Contact::hard(Vector3::x()); FINGERS];
        for (slot, &k) in out.iter_mut().zip(&idx[..n]) {
            let normal = state.fingers[k].contact_normal();
            *slot = if soft {
                Contact::soft(normal)
            } else {
                Contact::hard(normal)
            };
        }
        (out, idx, n)
    }

    /// Whether `finger` may lift (SPEC §1.3 I1): it is grasping, and the
    /// other grasping fingers are exactly two that pass Fact 3 with margin.
    /// Returns their slack \[rad\], or `None` when lifting is not possible at
    /// all (not grasping, or not exactly two would remain).
    pub fn lift_slack(&self, state: &HandState, finger: usize) -> Option<f64> {
        if state.fingers.get(finger)?.mode != FingerMode::Grasping {
            return None;
        }
        let (idx, n) = state.grasping();
        let mut rest = idx[..n].iter().filter(|&&k| k != finger);
        let (a, b) = (rest.next()?, rest.next()?);
        if rest.next().is_some() {
            return None;
        }
        Some(self.pair_fc_slack(
            &state.fingers[*a].contact_normal(),
            &state.fingers[*b].contact_normal(),
        ))
    }
}
