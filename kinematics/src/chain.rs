//! A finger chain in fixed-size form (SPEC §14.1 "Model").
//!
//! Finger k is a serial chain of N revolute joints from a base fixed in the
//! hand frame. Joint i's frame at $q_i$ is its parent's frame composed with
//! its origin (at $q = 0$) and a rotation by $q_i$ about its axis
//! (right-handed: positive $q_i$ turns counter-clockwise looking down the
//! axis). The tip frame hangs fixed below joint N; the tip is a sphere of
//! radius r centred at the tip frame's origin.
//!
//! Limits: a joint position is admissible when it lies in
//! $\[q_{min} + m, q_{max} - m\]$, m the description's joint-limit margin.
//!
//! Everything here is `Copy` and fixed-size: a chain is built once from a
//! [`FingerDescription`] and then used per tick without allocation.

use nalgebra::{SVector, Unit, Vector3};

use crate::capsule::{Capsule, LinkCapsule};
use crate::description::{Body, FingerDescription, JointLimits};
use crate::error::DescriptionError;
use crate::frame::Frame;
use crate::patch::TipPatch;

/// Collision capsules a chain holds at most.
pub const MAX_CAPSULES: usize = 12;

/// A finger chain of N revolute joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chain<const N: usize> {
    /// The base frame in the hand frame.
    pub base: Frame,
    /// Joint i's frame at q = 0 in joint i−1's frame (the base for i = 0).
    pub origins: [Frame; N],
    /// Joint i's unit axis in its own frame.
    pub axes: [Unit<Vector3<f64>>; N],
    /// Joint limits as described.
    pub limits: [JointLimits; N],
    /// Margin kept inside the position limits \[rad\].
    pub margin: f64,
    /// The tip frame in joint N's frame.
    pub tip: Frame,
    /// Tip radius r \[m\].
    pub tip_radius: f64,
    /// The contactable patch of the tip (§14.1 "Tip patch").
    pub patch: TipPatch,
    /// Per joint i, the mass and centre of mass of the link it moves.
    pub bodies: [Body; N],
    capsules: [LinkCapsule; MAX_CAPSULES],
    capsule_count: usize,
}

impl<const N: usize> Chain<N> {
    /// The fixed-size chain of a described finger; `margin` from
    /// [`crate::HandDescription::joint_limit_margin`].
    pub fn from_description(f: &FingerDescription, margin: f64) -> Result<Self, DescriptionError> {
        if f.joints.len() != N {
            return Err(DescriptionError::JointCount {
                finger: f.name.clone(),
                expected: N,
                found: f.joints.len(),
            });
        }
        if f.capsules.len() > MAX_CAPSULES {
            return Err(DescriptionError::TooManyCapsules {
                finger: f.name.clone(),
                count: f.capsules.len(),
                max: MAX_CAPSULES,
            });
        }
        let mut capsules = [LinkCapsule {
            segment: 0,
            capsule: Capsule::POINT,
        }; MAX_CAPSULES];
        capsules[..f.capsules.len()].copy_from_slice(&f.capsules);
        Ok(Chain {
            base: f.base,
            origins: std::array::from_fn(|i| f.joints[i].origin),
            axes: std::array::from_fn(|i| f.joints[i].axis),
            limits: std::array::from_fn(|i| f.joints[i].limits),
            margin,
            tip: f.tip,
            tip_radius: f.tip_radius,
            patch: TipPatch {
                pole: f.tip_pole,
                alpha: f.tip_patch,
            },
            bodies: std::array::from_fn(|i| f.bodies[i]),
            capsules,
            capsule_count: f.capsules.len(),
        })
    }

    /// Lower position limits with the margin, $q_{min} + m$.
    pub fn lower(&self) -> SVector<f64, N> {
        SVector::from_fn(|i, _| self.limits[i].lower + self.margin)
    }

    /// Upper position limits with the margin, $q_{max} - m$.
    pub fn upper(&self) -> SVector<f64, N> {
        SVector::from_fn(|i, _| self.limits[i].upper - self.margin)
    }

    /// The middle of each joint's range.
    pub fn mid_range(&self) -> SVector<f64, N> {
        SVector::from_fn(|i, _| 0.5 * (self.limits[i].lower + self.limits[i].upper))
    }

    /// Torque limits τ_max \[N·m\].
    pub fn effort(&self) -> SVector<f64, N> {
        SVector::from_fn(|i, _| self.limits[i].effort)
    }

    /// Velocity limits \[rad/s\].
    pub fn velocity(&self) -> SVector<f64, N> {
        SVector::from_fn(|i, _| self.limits[i].velocity)
    }

    /// The tightest joint-limit margin at `q` \[rad\]: the smallest distance
    /// of a joint to its nearer limit, minus the configured margin. Non-negative
    /// exactly when every joint is admissible.
    pub fn limit_margin(&self, q: &SVector<f64, N>) -> f64 {
        (0..N)
            .map(|i| (q[i] - self.limits[i].lower).min(self.limits[i].upper - q[i]))
            .fold(f64::INFINITY, f64::min)
            - self.margin
    }

    /// The collision capsules, each on its segment (in that segment's frame).
    pub fn link_capsules(&self) -> &[LinkCapsule] {
        &self.capsules[..self.capsule_count]
    }

    /// Forward kinematics: every joint frame and the tip frame at `q`.
    pub fn forward(&self, q: &SVector<f64, N>) -> ChainState<N> {
        let mut frames = [Frame::IDENTITY; N];
        let mut axes = [Vector3::zeros(); N];
        let mut f = self.base;
        for i in 0..N {
            f = f.compose(&self.origins[i]);
            f.rotation *= Frame::rotation_about(&self.axes[i], q[i]);
            axes[i] = f.rotation * self.axes[i].as_ref();
            frames[i] = f;
        }
        ChainState {
            joints: frames,
            axes,
            tip: f.compose(&self.tip),
        }
    }

    /// The capsules in the hand frame at the state `s`.
    pub fn capsules(&self, s: &ChainState<N>) -> CapsuleSet {
        let mut out = CapsuleSet {
            items: [Capsule::POINT; MAX_CAPSULES],
            len: self.capsule_count,
        };
        for (o, lc) in out.items.iter_mut().zip(self.link_capsules()) {
            let f = if lc.segment == 0 {
                &self.base
            } else {
                &s.joints[lc.segment - 1]
            };
            *o = Capsule {
                a: f.point(&lc.capsule.a),
                b: f.point(&lc.capsule.b),
                radius: lc.capsule.radius,
            };
        }
        out
    }
}

/// A chain's frames at one configuration (output of [`Chain::forward`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainState<const N: usize> {
    /// Joint i's frame in the hand frame (its origin $p_i$ on its axis).
    pub joints: [Frame; N],
    /// Joint i's unit axis $w_i$ in the hand frame.
    pub axes: [Vector3<f64>; N],
    /// The tip frame: rotation $R_k(q)$ and centre $c_k(q)$.
    pub tip: Frame,
}

impl<const N: usize> ChainState<N> {
    /// The tip centre $c_k(q)$.
    pub fn tip_centre(&self) -> Vector3<f64> {
        self.tip.translation
    }

    /// The linear Jacobian of the tip centre, $\dot c = J_v \dot q$:
    /// column i is $w_i \times (c - p_i)$.
    pub fn jacobian_v(&self) -> nalgebra::SMatrix<f64, 3, N> {
        self.point_jacobian(&self.tip.translation, N)
    }

    /// The angular Jacobian of the tip, $\omega_f = J_\omega \dot q$:
    /// column i is $w_i$.
    pub fn jacobian_w(&self) -> nalgebra::SMatrix<f64, 3, N> {
        nalgebra::SMatrix::from_fn(|r, c| self.axes[c][r])
    }

    /// The Jacobian of a point rigidly attached to the link moved by joint
    /// `moved_by` (1-based; columns of later joints are zero).
    pub fn point_jacobian(
        &self,
        x: &Vector3<f64>,
        moved_by: usize,
    ) -> nalgebra::SMatrix<f64, 3, N> {
        let mut j = nalgebra::SMatrix::<f64, 3, N>::zeros();
        for i in 0..moved_by.min(N) {
            j.set_column(i, &self.axes[i].cross(&(x - self.joints[i].translation)));
        }
        j
    }
}

/// Capsules in the hand frame (fixed capacity, no allocation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CapsuleSet {
    items: [Capsule; MAX_CAPSULES],
    len: usize,
}

impl CapsuleSet {
    /// The capsules.
    pub fn as_slice(&self) -> &[Capsule] {
        &self.items[..self.len]
    }
}
