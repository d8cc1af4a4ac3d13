//! From the search's actions to steps a chain hand executes (SPEC §4.2,
//! §14.2, §14.3).
//!
//! - A turn becomes carries ([`Motion::Carry`]): the grasping fingers'
//!   contacts fitted along the rolling law ([`CarryPath`]) in pieces the
//!   fit accepts (at most [`MAX_PIECE`], halved until it fits).
//! - A lift is a straight move out along the contact normal to the hover
//!   height; a placement an arc at the finger's hover radius (or higher,
//!   below) to above the new contact, then a straight descent onto it.
//! - As for the free fingertips, the grip passes between fingers at rest
//!   (`load.handover_time`): the step before a lift ends with a handover
//!   that releases the finger, a placement with one that takes it.
//!
//! A placing finger's way is checked as the exact check
//! ([`super::certify`]) samples it, without the load: where the way at the
//! hover height passes too near another finger, the finger rises higher
//! first. Everything else the exact check decides on the whole plan.

use nalgebra::Vector3;

use super::ChainHand;
use super::certify::{CheckParams, check_way};
use crate::config::LimitsConfig;
use crate::hand_state::{FINGERS, FingerMode, HandState};
use crate::planner::carry_path::{CarriedFinger, CarryPath, FitError};
use crate::planner::geometry::rotation;
use crate::planner::plan::{
    FreeMove, FreePath, Handover, Motion, Reorientation, Step, StepKind, cancel_take, end_handover,
};

/// The longest turn one carry step is fitted for \[rad\].
pub const MAX_PIECE: f64 = 1.5;

/// The fit's tolerance on the contact normals \[rad\]: 1e-7 rad is 4 nm of
/// tip centre on a tennis ball, far below any tracking a hand does.
pub const FIT_TOLERANCE: f64 = 1e-7;

/// The heights a placing finger travels at, in multiples of the hover
/// height: the first whose way is clear.
pub const RISES: [f64; 3] = [1.0, 2.0, 4.0];

/// Builds a chain plan's steps, keeping the state after the last.
pub struct ChainBuilder<'a> {
    hand: &'a ChainHand,
    limits: LimitsConfig,
    handover_time: f64,
    hover: f64,
    /// How a finger's way is sampled.
    check: CheckParams,
    /// Steps so far.
    pub steps: Vec<Step>,
    /// State after the last step.
    pub state: HandState,
    /// Each finger's joints there, on the branch it has been on.
    joints: [Option<Vector3<f64>>; FINGERS],
}

impl<'a> ChainBuilder<'a> {
    /// Starts at `state`: steps timed at `limits`, handovers of
    /// `handover_time` \[s\] (none if 0), free fingers `hover` \[m\] above
    /// the object, their ways sampled as `check` says.
    pub fn new(
        hand: &'a ChainHand,
        limits: LimitsConfig,
        handover_time: f64,
        hover: f64,
        check: CheckParams,
        state: HandState,
    ) -> Self {
        Self {
            joints: std::array::from_fn(|k| hand.joints(k, &state.fingers[k].center, None)),
            hand,
            limits,
            handover_time,
            hover,
            check,
            steps: Vec::with_capacity(32),
            state,
        }
    }

    /// Each finger's joints after the last step (on the branch it has
    /// been on).
    pub fn joints(&self) -> [Option<Vector3<f64>>; FINGERS] {
        self.joints
    }

    fn push(&mut self, kind: StepKind, motion: Motion) -> Result<(), usize> {
        let mut step = Step {
            kind,
            start: self.state,
            motion,
            duration: 0.0,
            handover: None,
        };
        step.duration = step.planned_duration(&self.limits);
        self.state = step.eval(&step.dofs().length, &[0.0; 3]).state;
        self.steps.push(step);
        // Where the step moved a finger, its joints follow on its branch.
        for k in 0..FINGERS {
            let c = self.state.fingers[k].center;
            self.joints[k] = match self.joints[k] {
                Some(before) => self.hand.nearest_branch(k, &c, &before),
                None => self.hand.joints(k, &c, None),
            };
            if self.joints[k].is_none() {
                return Err(k);
            }
        }
        Ok(())
    }

    /// The object turned about `axis` by `angle` (finite, ≥ 0) by the
    /// grasping fingers; `Err(finger)` where the fit fails (a singular
    /// finger; the first grasping finger for an angle out of range).
    pub fn rotate(&mut self, axis: &Vector3<f64>, angle: f64) -> Result<(), usize> {
        if !(0.0..f64::INFINITY).contains(&angle) {
            return Err(self.first_grasping());
        }
        let mut done = 0.0;
        loop {
            let mut piece = (angle - done).min(MAX_PIECE);
            let (path, end) = loop {
                match self.fit(axis, piece) {
                    Ok(p) => break p,
                    Err(FitError::TooLong) if piece > 1e-3 => piece *= 0.5,
                    Err(FitError::Singular { finger }) => return Err(finger),
                    Err(_) => return Err(self.first_grasping()),
                }
            };
            self.push(
                StepKind::Rotate,
                Motion::Carry {
                    axis: *axis,
                    angle: piece,
                    path,
                },
            )?;
            // The carried fingers go on from the joints the law brought
            // them to (not a branch guessed from their tips).
            let (idx, n) = self.state.grasping();
            for (i, &k) in idx[..n].iter().enumerate() {
                self.joints[k] = Some(end[i]);
            }
            done += piece;
            if angle - done <= 1e-12 {
                return Ok(());
            }
        }
    }

    fn first_grasping(&self) -> usize {
        self.state.grasping().0[0]
    }

    fn fit(
        &self,
        axis: &Vector3<f64>,
        angle: f64,
    ) -> Result<(CarryPath, [Vector3<f64>; 3]), FitError> {
        let (idx, n) = self.state.grasping();
        let mut fingers: [Option<CarriedFinger<'_>>; FINGERS] = [None; FINGERS];
        for (slot, &k) in fingers.iter_mut().zip(&idx[..n]) {
            let q = self.joints[k].ok_or(FitError::Singular { finger: k })?;
            *slot = Some((k, self.hand.chain(k), q));
        }
        let carried: Vec<CarriedFinger<'_>> = fingers.iter().flatten().copied().collect();
        CarryPath::fit(&carried, self.hand.object(), axis, angle, FIT_TOLERANCE)
            .map(|(p, r)| (p, r.end))
    }

    /// Grasping finger `k` out along its normal to the hover height, its
    /// grip released first.
    pub fn lift(&mut self, k: usize) -> Result<(), usize> {
        self.release_before_lift(k)?;
        let c = self.state.fingers[k].center;
        let rho = c.norm();
        self.free(
            StepKind::Lift,
            k,
            FreePath::Radial {
                dir: c / rho,
                from: rho,
                to: self.contact_radius(k) + self.hover,
            },
            false,
        )
    }

    /// Free finger `k` over to above `contact`, then down onto it; its
    /// grip taken after. The way goes at the finger's height if it can be
    /// made and is clear ([`check_way`]: limits, the object, the other
    /// fingers), else the finger first rises to the next of [`RISES`]
    /// where it is; where none is, the way at its height stands (the
    /// plan's check refuses it, or `Err(k)` where it cannot be made).
    pub fn place(&mut self, k: usize, contact: &Vector3<f64>) -> Result<(), usize> {
        let mark = (self.steps.len(), self.state, self.joints);
        let rho = self.state.fingers[k].center.norm();
        for rise in RISES {
            let top = rho.max(self.contact_radius(k) + rise * self.hover);
            // (A height the finger cannot reach is one more not clear.)
            let mut joints = mark.2;
            let clear = self.way(k, contact, top).is_ok()
                && check_way(self.hand, &self.steps[mark.0..], &mut joints, &self.check).is_ok();
            if clear {
                return Ok(());
            }
            self.steps.truncate(mark.0);
            (self.state, self.joints) = (mark.1, mark.2);
        }
        self.way(k, contact, rho)
    }

    /// Free finger `k` up to `top` from the centre, over to above
    /// `contact` there, and down onto it; its grip taken after.
    fn way(&mut self, k: usize, contact: &Vector3<f64>, top: f64) -> Result<(), usize> {
        let c = self.state.fingers[k].center;
        let rho = c.norm();
        let from = c / rho;
        if top > rho + 1e-12 {
            let rise = FreePath::Radial {
                dir: from,
                from: rho,
                to: top,
            };
            self.free(StepKind::Transfer, k, rise, false)?;
        }
        if (from - contact).norm() > 1e-12 {
            self.free(
                StepKind::Transfer,
                k,
                FreePath::arc(&from, contact, top),
                false,
            )?;
        }
        self.free(
            StepKind::Place,
            k,
            FreePath::Radial {
                dir: *contact,
                from: top,
                to: self.contact_radius(k),
            },
            true,
        )?;
        if let Some(h) = self.end_handover() {
            h.take = Some(k);
        }
        Ok(())
    }

    fn contact_radius(&self, k: usize) -> f64 {
        self.hand.object().radius + self.hand.chain(k).tip_radius
    }

    fn free(
        &mut self,
        kind: StepKind,
        finger: usize,
        path: FreePath,
        contact_at_end: bool,
    ) -> Result<(), usize> {
        self.push(
            kind,
            Motion::Free(FreeMove {
                finger,
                path,
                turn: Reorientation::NONE,
                contact_at_end,
            }),
        )
    }

    /// The last step's handover releases `finger` (a still step of its own
    /// when the plan starts with the lift); a finger placed and lifted at
    /// once never carried, and no grip passes.
    fn release_before_lift(&mut self, finger: usize) -> Result<(), usize> {
        if cancel_take(&mut self.steps, finger) {
            return Ok(());
        }
        if self.handover_time > 0.0 && self.steps.is_empty() {
            self.rotate(&Vector3::z(), 0.0)?;
        }
        if let Some(h) = self.end_handover() {
            h.release = Some(finger);
        }
        Ok(())
    }

    /// The handover at the end of the last step, made if it has none.
    fn end_handover(&mut self) -> Option<&mut Handover> {
        end_handover(&mut self.steps, self.handover_time)
    }
}

/// `hand` with its object turned about `axis` by `angle` and its grasping
/// fingers carried as the rolling law makes them (joints on the branch
/// [`ChainHand::joints`] picks); `None` where a finger cannot follow.
pub fn carried(
    hand: &ChainHand,
    state: &HandState,
    axis: &Vector3<f64>,
    angle: f64,
) -> Option<HandState> {
    let mut last = None;
    along_carry(hand, state, axis, angle, 1, &mut |s| {
        last = Some(*s);
        true
    })
    .then_some(())?;
    last
}

/// Calls `f` with the state at each of `samples` + 1 even angles of a
/// carry (as [`carried`]), until it returns false; whether every sample
/// was made and passed.
pub fn along_carry(
    hand: &ChainHand,
    state: &HandState,
    axis: &Vector3<f64>,
    angle: f64,
    samples: usize,
    f: &mut dyn FnMut(&HandState) -> bool,
) -> bool {
    let (idx, n) = state.grasping();
    let mut q = [Vector3::zeros(); FINGERS];
    let mut chains = [hand.chain(0); FINGERS];
    for (i, &k) in idx[..n].iter().enumerate() {
        let Some(j) = hand.joints(k, &state.fingers[k].center, None) else {
            return false;
        };
        q[i] = j;
        chains[i] = hand.chain(k);
    }
    let step = 1f64.to_radians();
    let piece = angle / samples.max(1) as f64;
    for s in 0..=samples.max(1) {
        if s > 0
            && kinematics::carry(&chains[..n], &mut q[..n], hand.object(), axis, piece, step)
                .is_err()
        {
            return false;
        }
        let mut out = *state;
        out.object = rotation(axis, piece * s as f64) * state.object;
        for (i, &k) in idx[..n].iter().enumerate() {
            let f = &mut out.fingers[k];
            debug_assert_eq!(f.mode, FingerMode::Grasping);
            f.center = hand.chain(k).forward(&q[i]).tip_centre() - hand.object().centre;
        }
        if !f(&out) {
            return false;
        }
    }
    true
}
