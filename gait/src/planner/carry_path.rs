//! A grasp of finger chains carried by the object's turn, as a step can
//! hold it (SPEC §14.2): the contacts' path, fitted once when the plan is
//! built, evaluated at any angle without state.
//!
//! A free fingertip is carried rigidly ([`super::plan::Motion::Rotate`]):
//! its contact is a material point of the object. A chain finger's tip
//! orientation follows from its joints, so its contact rolls: while the
//! object turns about a fixed unit axis k, each contact normal n obeys
//! the rolling law, $\dot n = \dot c/(R + r)$ with $\dot c$ from
//! [`kinematics::rolling_rates`] at $\omega_o = k$ — an ordinary
//! differential equation in the turned angle θ with no closed form.
//!
//! [`CarryPath::fit`] integrates it ([`kinematics::carry()`], RK4) and keeps,
//! at evenly spaced knots, every carried contact's normal and its
//! derivative $dn/d\theta$ from the law itself; [`CarryPath::at`]
//! interpolates between two knots by cubic Hermite and projects onto the
//! unit sphere. The executor, the preview and the plan's check all
//! evaluate a step at arbitrary angles, in any order, so the step cannot
//! integrate as it goes; the fit is bounded work per evaluation and needs
//! no allocation. Its error is measured where cubic Hermite errs most, at
//! each interval's midpoint, against the integration: a fit that misses
//! the tolerance with [`CARRY_KNOTS`] knots is refused
//! ([`FitError::TooLong`]) and the caller carries in shorter steps.

use kinematics::{Chain, Object, carry, rolling_rates};
use nalgebra::Vector3;

/// Most knots a carry's path holds (ends included).
pub const CARRY_KNOTS: usize = 16;

/// Fewest knots a fit starts from: its knots are no further apart than
/// [`FIRST_SPACING`] \[rad\] (more are added until the fit is close).
const FIRST_SPACING: f64 = 0.1;

/// The integration's longest step \[rad\]: RK4's error at this step is far
/// below any tolerance a fit is asked for (`kinematics` measures a 1° step
/// at 4e-11 rad over 60°; halving it divides that by 16).
const LAW_STEP: f64 = 0.5 * std::f64::consts::PI / 180.0;

/// The contact normals of up to three grasping chain fingers along a turn
/// of the object about a fixed axis (module docs). Fixed size, `Copy`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarryPath {
    /// Knots used (2..=[`CARRY_KNOTS`]).
    knots: usize,
    /// Which fingers are carried (bit k: finger k).
    carried: u8,
    /// Turned angle between two knots \[rad\].
    spacing: f64,
    /// Tip-centre distance from the object's centre, R + r, per finger \[m\].
    radius: [f64; 3],
    /// Unit contact normal of each finger at each knot (hand frame).
    normal: [[Vector3<f64>; 3]; CARRY_KNOTS],
    /// dn/dθ of each finger at each knot \[1/rad\].
    slope: [[Vector3<f64>; 3]; CARRY_KNOTS],
}

/// A carried finger as the fit takes it: its index in the hand, its chain
/// and its joints at the start.
pub type CarriedFinger<'a> = (usize, &'a Chain<3>, Vector3<f64>);

/// Why a carry could not be fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum FitError {
    /// The rolling law is singular somewhere on the way (a finger at a
    /// singular posture cannot follow the object).
    #[error("finger {finger} cannot follow the object (singular posture)")]
    Singular {
        /// The finger (hand index).
        finger: usize,
    },
    /// [`CARRY_KNOTS`] knots do not reach the tolerance: carry in shorter
    /// steps.
    #[error("the turn is too long to fit in one step")]
    TooLong,
    /// No finger, more than three, a finger named twice, or an angle or
    /// tolerance that is not finite and positive (angle ≥ 0).
    #[error("a carry needs one to three distinct fingers and a finite angle")]
    BadInput,
}

/// How a fit met its tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitReport {
    /// Knots used.
    pub knots: usize,
    /// Largest distance between a fitted unit normal and the integrated
    /// one at the intervals' midpoints (the chord, ≈ the angle \[rad\]).
    pub error: f64,
    /// The fingers' joints at the end of the turn, as integrated, in the
    /// order they were given (where the next carry starts from).
    pub end: [Vector3<f64>; 3],
}

/// A contact's normal and its derivative along the turn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactAt {
    /// Unit outward contact normal (hand frame).
    pub normal: Vector3<f64>,
    /// dn/dθ \[1/rad\].
    pub slope: Vector3<f64>,
    /// Tip-centre position relative to the object's centre, (R + r)·n \[m\].
    pub centre: Vector3<f64>,
    /// d centre/dθ \[m/rad\].
    pub centre_slope: Vector3<f64>,
}

impl CarryPath {
    /// Fits the carry of `fingers` about the unit `axis` by `angle`
    /// (module docs), the fitted normals within `tolerance` \[rad\] of the
    /// rolling law at every interval's midpoint.
    pub fn fit(
        fingers: &[CarriedFinger<'_>],
        object: &Object,
        axis: &Vector3<f64>,
        angle: f64,
        tolerance: f64,
    ) -> Result<(Self, FitReport), FitError> {
        let m = fingers.len();
        let mut carried = 0u8;
        for (k, _, _) in fingers {
            if *k >= 3 || carried & (1 << k) != 0 {
                return Err(FitError::BadInput);
            }
            carried |= 1 << k;
        }
        if m == 0
            || !(0.0..f64::INFINITY).contains(&angle)
            || !(tolerance.is_finite() && tolerance > 0.0)
        {
            return Err(FitError::BadInput);
        }
        let mut knots = ((angle / FIRST_SPACING).ceil() as usize + 1).clamp(2, CARRY_KNOTS);
        loop {
            let (path, error, end) = Self::try_knots(fingers, carried, object, axis, angle, knots)?;
            if error <= tolerance {
                return Ok((path, FitReport { knots, error, end }));
            }
            if knots == CARRY_KNOTS {
                break;
            }
            // Cubic Hermite errs as the spacing's fourth power: aim at the
            // tolerance with a tenth to spare.
            let wanted = 1.0 + (knots - 1) as f64 * (1.1 * error / tolerance).powf(0.25);
            knots = (wanted.ceil() as usize).clamp(knots + 1, CARRY_KNOTS);
        }
        Err(FitError::TooLong)
    }

    /// The fit with `knots` knots and its largest midpoint error.
    fn try_knots(
        fingers: &[CarriedFinger<'_>],
        carried: u8,
        object: &Object,
        axis: &Vector3<f64>,
        angle: f64,
        knots: usize,
    ) -> Result<(Self, f64, [Vector3<f64>; 3]), FitError> {
        let m = fingers.len();
        let chains: [&Chain<3>; 3] = std::array::from_fn(|i| fingers[i.min(m - 1)].1);
        let chains = &chains[..m];
        let mut q = [Vector3::zeros(); 3];
        for (i, f) in fingers.iter().enumerate() {
            q[i] = f.2;
        }
        let mut path = Self {
            knots,
            carried,
            spacing: angle / (knots - 1) as f64,
            radius: [0.0; 3],
            normal: [[Vector3::zeros(); 3]; CARRY_KNOTS],
            slope: [[Vector3::zeros(); 3]; CARRY_KNOTS],
        };
        for (k, chain, _) in fingers {
            path.radius[*k] = object.radius + chain.tip_radius;
        }
        // (The law's only failure is a singular finger.)
        let singular = |b: kinematics::Bound| match b {
            kinematics::Bound::Singular { finger } => FitError::Singular {
                finger: fingers[finger].0,
            },
            _ => FitError::BadInput,
        };
        let mut error: f64 = 0.0;
        let half = 0.5 * path.spacing;
        path.record(0, fingers, &q[..m], object, axis)?;
        for j in 0..knots - 1 {
            carry(chains, &mut q[..m], object, axis, half, LAW_STEP).map_err(singular)?;
            let (theta_mid, mid) = (j as f64 * path.spacing + half, q);
            carry(chains, &mut q[..m], object, axis, half, LAW_STEP).map_err(singular)?;
            // The midpoint is compared once both of its knots are known.
            path.record(j + 1, fingers, &q[..m], object, axis)?;
            for (i, (k, chain, _)) in fingers.iter().enumerate() {
                let truth = (chain.forward(&mid[i]).tip_centre() - object.centre).normalize();
                let fitted = path.at(*k, theta_mid).normal;
                // (The chord, not `angle`: acos cannot resolve below 1e-8 rad.)
                error = error.max((fitted - truth).norm());
            }
        }
        Ok((path, error, q))
    }

    /// Stores knot `j`'s normals and slopes from the fingers' joints `q`.
    fn record(
        &mut self,
        j: usize,
        fingers: &[CarriedFinger<'_>],
        q: &[Vector3<f64>],
        object: &Object,
        axis: &Vector3<f64>,
    ) -> Result<(), FitError> {
        for ((k, chain, _), q) in fingers.iter().zip(q) {
            let s = chain.forward(q);
            let n = (s.tip_centre() - object.centre).normalize();
            let r = rolling_rates(&s, axis, &n, object.radius, chain.tip_radius)
                .ok_or(FitError::Singular { finger: *k })?;
            self.normal[j][*k] = n;
            self.slope[j][*k] = r.c_dot / (object.radius + chain.tip_radius);
        }
        Ok(())
    }

    /// Whether finger `k` is carried.
    pub fn carries(&self, k: usize) -> bool {
        k < 3 && self.carried & (1 << k) != 0
    }

    /// The turned angle the path covers \[rad\].
    pub fn angle(&self) -> f64 {
        self.spacing * (self.knots - 1) as f64
    }

    /// Knots used.
    pub fn knots(&self) -> usize {
        self.knots
    }

    /// Finger `k`'s contact at turned angle `theta` (clamped to the
    /// path). Meaningless for a finger the path does not carry.
    pub fn at(&self, k: usize, theta: f64) -> ContactAt {
        let k = k.min(2);
        let last = self.knots - 1;
        let h = self.spacing;
        let x = if h > 0.0 {
            (theta / h).clamp(0.0, last as f64)
        } else {
            0.0
        };
        let i = (x.floor() as usize).min(last.saturating_sub(1));
        let j = (i + 1).min(last);
        let t = x - i as f64;
        let (t2, t3) = (t * t, t * t * t);
        // Cubic Hermite basis and its derivative in t.
        let (h00, h10, h01, h11) = (
            2.0 * t3 - 3.0 * t2 + 1.0,
            t3 - 2.0 * t2 + t,
            -2.0 * t3 + 3.0 * t2,
            t3 - t2,
        );
        let (d00, d10, d01, d11) = (
            6.0 * t2 - 6.0 * t,
            3.0 * t2 - 4.0 * t + 1.0,
            -6.0 * t2 + 6.0 * t,
            3.0 * t2 - 2.0 * t,
        );
        let (n0, n1) = (self.normal[i][k], self.normal[j][k]);
        let (m0, m1) = (self.slope[i][k] * h, self.slope[j][k] * h);
        let p = n0 * h00 + m0 * h10 + n1 * h01 + m1 * h11;
        let dp = if h > 0.0 {
            (n0 * d00 + m0 * d10 + n1 * d01 + m1 * d11) / h
        } else {
            self.slope[i][k]
        };
        // Onto the unit sphere: n = p/|p|, dn = (dp − n (n·dp))/|p|.
        let len = p.norm();
        let normal = p / len;
        let slope = (dp - normal * normal.dot(&dp)) / len;
        let radius = self.radius[k];
        ContactAt {
            normal,
            slope,
            centre: normal * radius,
            centre_slope: slope * radius,
        }
    }
}
