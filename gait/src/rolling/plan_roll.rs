//! Single-finger rolling planner (SPEC §2.4, §4.2 Roll).
//!
//! Given a finger's current contact (object contact, fingertip contact
//! anywhere in its hemisphere, roll τ) and a target contact point on the
//! still object, [`plan_roll`] returns a [`RollingPath`] ending with the
//! object contact exactly at the target, keeping the fingertip contact in
//! its closed hemisphere and the roll within the limit, or a typed reason.
//!
//! Strategy (deterministic):
//! 1. the direct great-circle roll, if it keeps the hemisphere and roll
//!    limits;
//! 2. otherwise: roll the fingertip contact back to its pole along a
//!    fingertip longitude (no roll change); repeat Fig. 2 paths along the
//!    great circle towards the target (paper Fig. 3), each as long as the
//!    roll budget allows and each turning to the side that unwinds the
//!    roll (turn right when τ > 0): the roll is unwound for free, without
//!    spin, so every path after the first may change the roll by up to
//!    2(γ − margin); finish with a longitude roll from the pole that reaches
//!    the target (at most (π/2)(r/R) away). The fewest paths are used, and
//!    they and the closing roll all use the same fraction of their reach,
//!    so the slack is shared between the roll margin and the fingertip
//!    hemisphere margin (the closing roll ends on the fingertip equator
//!    only when the target needs every bit of reach).
//!
//! Spin is used only when a final roll is requested ([`RollGoal::final_roll`]),
//! at the last pole visit (the closing longitude roll does not change the
//! roll), and only if [`RollLimits::allow_spin`] (three-finger hard-contact
//! grasp, SPEC §1.2).
//!
//! Roll rule: every segment end keeps |τ| ≤ max(γ − margin, |τ₀|), so a
//! start inside the margin band is never made worse; τ is linear on each
//! segment, so this bounds |τ| everywhere.
//!
//! Not checked here (the planner above does it): the other fingers,
//! force closure (I1), the workspace cone (I2; see
//! [`RollingPath::max_angle_from`]) and fingertip collisions (I4).

use super::fig2::{Turn, fig2_leg_angle, fig2_reach, fig2_roll_for};
use super::path::{MAX_SEGMENTS, PathError, RollingPath};
use crate::contact::{ContactGeometry, RelativeContact};
use crate::sphere::rotation::{angle_between, any_perpendicular, rotate, tangent_towards};
use nalgebra::Vector3;

/// Roll limits for one rolling finger.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollLimits {
    /// γ: roll limit |τ| ≤ γ \[rad\] (SPEC §1.1).
    pub roll_limit: f64,
    /// Margin kept inside γ at the end of every segment \[rad\].
    pub roll_margin: f64,
    /// Whether spin segments are allowed (three-finger hard-contact grasp).
    pub allow_spin: bool,
}

impl RollLimits {
    /// γ and the roll margin from a validated configuration.
    pub fn from_config(config: &crate::HandConfig, allow_spin: bool) -> Self {
        Self {
            roll_limit: config.model.roll_limit_deg.to_radians(),
            roll_margin: config.model.roll_margin_deg.to_radians(),
            allow_spin,
        }
    }

    /// γ − margin.
    pub fn usable(&self) -> f64 {
        self.roll_limit - self.roll_margin
    }
}

/// Where the rolling finger should go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollGoal {
    /// Target contact point on the object (unit, object frame).
    pub target: Vector3<f64>,
    /// Roll τ wanted at the end \[rad\], or None (free, within the limits).
    pub final_roll: Option<f64>,
}

/// Why no rolling path was returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum RollPlanError {
    /// The start contact is not finite or its contact point is not a unit vector.
    #[error("invalid start contact")]
    InvalidStart,
    /// The target is not finite or not a unit vector.
    #[error("invalid target contact")]
    InvalidTarget,
    /// The roll limits are not finite or leave no roll range.
    #[error("invalid roll limits")]
    InvalidLimits,
    /// The start fingertip contact is outside the fingertip hemisphere.
    #[error("start fingertip contact outside its hemisphere")]
    StartOutsideHemisphere,
    /// The start roll exceeds γ.
    #[error("start roll beyond the roll limit")]
    StartRollOutsideLimit,
    /// The requested final roll exceeds γ − margin.
    #[error("requested final roll beyond the roll limit")]
    FinalRollOutsideLimit,
    /// A final roll was requested but spin is not allowed (two-finger grasp).
    #[error("final roll needs a spin, which this grasp does not allow")]
    SpinNotAllowed,
    /// More segments than a path holds would be needed.
    #[error("rolling path needs more than the path capacity")]
    CapacityExceeded,
    /// Internal check failed (numerical breakdown); no path is returned.
    #[error("rolling path failed its own limit check")]
    CheckFailed,
}

impl From<PathError> for RollPlanError {
    fn from(e: PathError) -> Self {
        match e {
            PathError::Full => RollPlanError::CapacityExceeded,
            _ => RollPlanError::CheckFailed,
        }
    }
}

/// Tolerances of the limit checks.
const HEMISPHERE_TOL: f64 = 1e-9;
const ROLL_TOL: f64 = 1e-12;

fn unit_ok(v: &Vector3<f64>, tol: f64) -> bool {
    v.iter().all(|x| x.is_finite()) && (v.norm() - 1.0).abs() <= tol
}

/// Whether `path` keeps the hemisphere and every segment end within `bound`.
fn within_limits(path: &RollingPath, bound: f64) -> bool {
    let m = path.margins();
    m.min_hemisphere >= -HEMISPHERE_TOL && m.max_abs_roll <= bound + ROLL_TOL
}

/// Object-contact distance covered by `count` Fig. 2 paths, each using the
/// fraction `scale` of its largest step (turning against τ, so the budget
/// is usable + |τ|), plus the closing longitude roll scaled alike.
fn covered(geom: &ContactGeometry, mut tau: f64, usable: f64, count: usize, scale: f64) -> f64 {
    let mut total = scale * fig2_leg_angle(geom);
    for _ in 0..count {
        let step = scale * fig2_reach(geom, usable + tau.abs());
        total += step;
        let change = fig2_roll_for(geom, step).unwrap_or(0.0);
        tau -= if tau > 0.0 { change } else { -change };
    }
    total
}

/// The fewest Fig. 2 paths that reach `distance`, within `room` segments.
fn fig2_count(
    geom: &ContactGeometry,
    tau: f64,
    usable: f64,
    distance: f64,
    room: usize,
) -> Result<usize, RollPlanError> {
    (1..=room / 3)
        .find(|&n| covered(geom, tau, usable, n, 1.0) * (1.0 - 1e-12) >= distance)
        .ok_or(RollPlanError::CapacityExceeded)
}

/// The common fraction of their reach used by the Fig. 2 paths and the
/// closing roll to cover exactly `distance`: the slack is shared between
/// the roll margin and the fingertip-hemisphere margin instead of ending
/// on the fingertip equator. Bisection (covered() is continuous in the
/// fraction, 0 at 0 and ≥ distance at 1).
fn share(geom: &ContactGeometry, tau: f64, usable: f64, distance: f64, count: usize) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0 - 1e-12);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if covered(geom, tau, usable, count, mid) < distance {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Plans a rolling path from `start` to `goal` (module docs).
pub fn plan_roll(
    geom: &ContactGeometry,
    start: &RelativeContact,
    goal: &RollGoal,
    limits: &RollLimits,
) -> Result<RollingPath, RollPlanError> {
    if !(start.is_finite() && unit_ok(&start.contact, 1e-9)) {
        return Err(RollPlanError::InvalidStart);
    }
    if !unit_ok(&goal.target, 1e-6) || goal.final_roll.is_some_and(|r| !r.is_finite()) {
        return Err(RollPlanError::InvalidTarget);
    }
    let finite_limits = limits.roll_limit.is_finite() && limits.roll_margin.is_finite();
    if !(finite_limits && limits.roll_margin >= 0.0 && limits.usable() > 0.0) {
        return Err(RollPlanError::InvalidLimits);
    }
    if start.roll.abs() > limits.roll_limit + ROLL_TOL {
        return Err(RollPlanError::StartRollOutsideLimit);
    }
    if start.hemisphere_margin() < -HEMISPHERE_TOL {
        return Err(RollPlanError::StartOutsideHemisphere);
    }
    let usable = limits.usable();
    if goal.final_roll.is_some_and(|r| r.abs() > usable + ROLL_TOL) {
        return Err(RollPlanError::FinalRollOutsideLimit);
    }
    let target = goal.target.normalize();
    let bound = usable.max(start.roll.abs());

    if goal.final_roll.is_none() {
        let mut direct = RollingPath::new(*geom, *start);
        direct.push_roll_to(&target)?;
        if within_limits(&direct, bound) {
            return Ok(direct);
        }
    }

    let mut path = RollingPath::new(*geom, *start);
    // 1. Back to the pole along a fingertip longitude.
    let m = start.fingertip_contact();
    let off_pole = angle_between(&m, &Vector3::z());
    if off_pole > 1e-12 {
        let dir = start.fingertip * tangent_towards(&m, &Vector3::z());
        path.push_roll(&dir, off_pole * geom.fingertip_radius / geom.object_radius)?;
    }
    // 2. Fig. 2 paths along the great circle from the pole contact P.
    let p = path.end().contact;
    let leg = fig2_leg_angle(geom);
    let distance = angle_between(&p, &target);
    let cross = p.cross(&target);
    let gc_axis = if cross.norm() > 1e-12 {
        cross.normalize()
    } else {
        any_perpendicular(&p)
    };
    let tail = 1 + usize::from(goal.final_roll.is_some());
    if distance > leg {
        let tau = path.end().roll;
        let count = fig2_count(
            geom,
            tau,
            usable,
            distance,
            MAX_SEGMENTS - path.len() - tail,
        )?;
        let scale = share(geom, tau, usable, distance, count);
        let mut covered = 0.0;
        for _ in 0..count {
            let tau = path.end().roll;
            covered += scale * fig2_reach(geom, usable + tau.abs());
            let turn = if tau > 0.0 { Turn::Right } else { Turn::Left };
            path.push_fig2_to(&rotate(&gc_axis, covered, &p), turn)?;
        }
    }
    // 3. Requested roll by a spin at the pole, then the closing longitude.
    if let Some(wanted) = goal.final_roll {
        let change = wanted - path.end().roll;
        if change.abs() > ROLL_TOL {
            if !limits.allow_spin {
                return Err(RollPlanError::SpinNotAllowed);
            }
            path.push_spin_roll(change)?;
        }
    }
    path.push_roll_to(&target)?;
    if within_limits(&path, bound) {
        Ok(path)
    } else {
        Err(RollPlanError::CheckFailed)
    }
}
