//! A free chain finger's way from one contact to another (SPEC §14.3):
//! lift along the contact normal, travel clear of the object and of the
//! other fingers, descend along the new normal.
//!
//! The way is a polyline in joint space ([`Transfer`]): the lift and the
//! descent are the closed-form IK of points on the normals (each solved
//! next to the one before, so the branch never jumps), the travel a
//! straight joint-space line between the two hover configurations, so
//! that a trajectory generator can time it joint by joint within the
//! joints' limits. Every sample, [`TransferLimits::resolution`] apart in
//! joint space, keeps the joints inside their limits (with the chain's
//! margin: the waypoints are, and so is every line between them), every
//! link capsule [`TransferLimits::clearance`] from the
//! object, the tip as far while travelling (on the normals it is as far as
//! it has risen), and the whole finger [`TransferLimits::finger_gap`] from
//! each other finger. Where the direct travel at the hover height is
//! blocked, the finger rises to twice, then four times that height first.
//!
//! Allocation-free (fixed-size waypoints).

use nalgebra::Vector3;

use crate::chain::{Chain, ChainState};
use crate::description::Object;
use crate::ik_closed::ClosedFormIk;
use crate::workspace::{FingerGap, object_clearance};

/// Points on each normal (lift, descent), the contact included.
const NORMAL_POINTS: usize = 5;

/// Most waypoints of a transfer: a lift, a descent and the travel's ends.
pub const MAX_WAYPOINTS: usize = 2 * NORMAL_POINTS;

/// Heights tried, in multiples of [`TransferLimits::hover`].
const RISES: [f64; 3] = [1.0, 2.0, 4.0];

/// What a transfer keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransferLimits {
    /// How far above the surface the tip travels \[m\].
    pub hover: f64,
    /// Least gap between the finger (links; the tip while travelling) and
    /// the object \[m\].
    pub clearance: f64,
    /// Least gap to every other finger \[m\].
    pub finger_gap: f64,
    /// Joint-space spacing of the checked samples \[rad\].
    pub resolution: f64,
}

/// Another finger, standing still while this one moves.
#[derive(Debug, Clone, Copy)]
pub struct Obstacle<'a> {
    /// Its chain.
    pub chain: &'a Chain<3>,
    /// Its configuration.
    pub state: ChainState<3>,
    /// The pairs compared between the moving finger and it
    /// (`FingerGap::new(moving, other)`).
    pub gap: FingerGap,
}

/// A transfer: joint-space waypoints, joined by straight lines.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Transfer {
    points: [Vector3<f64>; MAX_WAYPOINTS],
    len: usize,
    /// The height the tip travelled at, above the surface \[m\].
    pub height: f64,
}

impl Transfer {
    /// The waypoints, from the start contact to the end contact.
    pub fn waypoints(&self) -> &[Vector3<f64>] {
        &self.points[..self.len]
    }

    /// The joints at `u` ∈ [0, 1] along the polyline (by waypoint index,
    /// each segment an equal share).
    pub fn sample(&self, u: f64) -> Vector3<f64> {
        let x = u.clamp(0.0, 1.0) * (self.len - 1) as f64;
        let i = (x.floor() as usize).min(self.len - 2);
        let t = x - i as f64;
        self.points[i] * (1.0 - t) + self.points[i + 1] * t
    }
}

/// Why no transfer was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TransferError {
    /// A point on a normal has no joint solution inside the limits.
    Unreachable {
        /// The normal.
        normal: Vector3<f64>,
    },
    /// Every height tried meets the object, another finger or a limit.
    Blocked,
}

/// The way of `chain` (closed-form IK `ik`), now at joints `from` touching
/// the object, to touch it at the unit normal `to`, the `others` standing
/// still (module docs).
pub fn transfer(
    chain: &Chain<3>,
    ik: &ClosedFormIk,
    object: &Object,
    from: &Vector3<f64>,
    to: &Vector3<f64>,
    others: &[Obstacle<'_>],
    limits: &TransferLimits,
) -> Result<Transfer, TransferError> {
    let n0 = (chain.forward(from).tip_centre() - object.centre).normalize();
    let mut unreachable = None;
    for rise in RISES {
        let height = rise * limits.hover;
        let mut t = Transfer {
            points: [Vector3::zeros(); MAX_WAYPOINTS],
            len: 0,
            height,
        };
        // Lift: from the contact up the normal.
        let mut q = *from;
        t.points[0] = q;
        let mut ok = true;
        for i in 1..NORMAL_POINTS {
            let h = height * i as f64 / (NORMAL_POINTS - 1) as f64;
            match ik.solve(&on_normal(object, chain, &n0, h), &q) {
                Ok(next) => q = next,
                Err(_) => {
                    unreachable = Some(n0);
                    ok = false;
                    break;
                }
            }
            t.points[i] = q;
        }
        if !ok {
            continue;
        }
        // Descent, solved from the hover point down, each next to the one
        // above it.
        let mut down = [Vector3::zeros(); NORMAL_POINTS];
        for i in (0..NORMAL_POINTS).rev() {
            let h = height * i as f64 / (NORMAL_POINTS - 1) as f64;
            let reference = if i + 1 < NORMAL_POINTS {
                down[i + 1]
            } else {
                q
            };
            match ik.solve(&on_normal(object, chain, to, h), &reference) {
                Ok(next) => down[i] = next,
                Err(_) => {
                    unreachable = Some(*to);
                    ok = false;
                    break;
                }
            }
        }
        if !ok {
            continue;
        }
        for (i, d) in down.iter().rev().enumerate() {
            t.points[NORMAL_POINTS + i] = *d;
        }
        t.len = MAX_WAYPOINTS;
        if clear(chain, object, &t, others, limits) {
            return Ok(t);
        }
    }
    Err(match unreachable {
        Some(normal) => TransferError::Unreachable { normal },
        None => TransferError::Blocked,
    })
}

/// The tip centre `h` above the surface on the normal `n`.
fn on_normal(object: &Object, chain: &Chain<3>, n: &Vector3<f64>, h: f64) -> Vector3<f64> {
    object.centre + n * (object.radius + chain.tip_radius + h)
}

/// Whether every sample of `t` keeps the limits (module docs). On the
/// normals (the first and last `NORMAL_POINTS − 1` segments) the tip is
/// not held to the clearance: it is as far as it has risen.
fn clear(
    chain: &Chain<3>,
    object: &Object,
    t: &Transfer,
    others: &[Obstacle<'_>],
    limits: &TransferLimits,
) -> bool {
    let travel = NORMAL_POINTS - 1;
    for i in 0..t.len - 1 {
        let (a, b) = (t.points[i], t.points[i + 1]);
        let n = ((b - a).amax() / limits.resolution).ceil().max(1.0) as usize;
        // The segment's end is the next segment's start: checked once, and
        // the very last point here.
        let last = if i + 2 == t.len { n } else { n - 1 };
        for j in 0..=last {
            let q = a + (b - a) * (j as f64 / n as f64);
            if !admissible(chain, object, &q, i == travel, others, limits) {
                return false;
            }
        }
    }
    true
}

/// One sample's checks; `travelling`: the tip is held to the clearance.
fn admissible(
    chain: &Chain<3>,
    object: &Object,
    q: &Vector3<f64>,
    travelling: bool,
    others: &[Obstacle<'_>],
    limits: &TransferLimits,
) -> bool {
    // The joints need no check: every waypoint is an IK solution inside
    // the limits with margin, and a straight line between two points of
    // that box stays in it.
    let s = chain.forward(q);
    if object_clearance(chain, &s, object) < limits.clearance {
        return false;
    }
    if travelling {
        let tip = (s.tip_centre() - object.centre).norm() - object.radius - chain.tip_radius;
        if tip < limits.clearance {
            return false;
        }
    }
    others
        .iter()
        .all(|o| o.gap.gap((chain, &s), (o.chain, &o.state)) >= limits.finger_gap)
}
