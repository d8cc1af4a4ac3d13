//! From the search's actions to executable steps (SPEC §4.2 primitives).
//!
//! Each gait becomes concrete motions: a Place is an optional arc on the
//! transfer shell (routed via the cone centre when the direct arc would pass
//! too close to another fingertip) then a radial descent; a Lift is a radial
//! ascent. While the object turns, the free finger already travels to above
//! its next placement when that is clear of the sweeping fingertips
//! (this saves about a second per goal); otherwise it stays, or
//! first parks over its cone centre, which no other fingertip can reach.

use nalgebra::Vector3;

use super::super::collision::{other_centers, path_clear, sweep_clear};
use super::super::geometry::{Geometry, angle_between};
use super::super::plan::{
    FreeMove, FreePath, Handover, Motion, Reorientation, Step, StepKind, cancel_take, end_handover,
};
use super::StillAction;
use crate::hand_state::{FingerMode, HandState};

/// Why segments could not be turned into collision-free motions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Blocked {
    /// The finger that could not move safely.
    pub finger: usize,
}

/// Builds the step list, tracking the exact state after each step.
pub struct Builder<'a> {
    g: &'a Geometry,
    limits: crate::config::LimitsConfig,
    /// `load.handover_time` (0: no handovers).
    handover_time: f64,
    /// Steps so far.
    pub steps: Vec<Step>,
    /// State after the last step.
    pub hand: HandState,
}

impl<'a> Builder<'a> {
    /// Starts at `hand`; every placement and every lift gets a handover of
    /// `handover_time` seconds (none if 0).
    pub fn new(
        g: &'a Geometry,
        limits: crate::config::LimitsConfig,
        handover_time: f64,
        hand: HandState,
    ) -> Self {
        Self {
            g,
            limits,
            handover_time,
            steps: Vec::with_capacity(32),
            hand,
        }
    }

    fn push(&mut self, kind: StepKind, motion: Motion) {
        let mut step = Step {
            kind,
            start: self.hand,
            motion,
            duration: 0.0,
            handover: None,
        };
        step.duration = step.planned_duration(&self.limits);
        let d = step.dofs();
        self.hand = step.eval(&d.length, &[0.0; 3]).state;
        self.steps.push(step);
    }

    /// The last step's grip ramps `finger` out before it lifts (a handover
    /// at the end of that step; a still step of its own when the plan
    /// starts with the lift).
    fn release_before_lift(&mut self, finger: usize) {
        // (Placed and lifted at once: the unwind's relocation under load.)
        if cancel_take(&mut self.steps, finger) {
            return;
        }
        if self.handover_time > 0.0 && self.steps.is_empty() {
            self.push(
                StepKind::Rotate,
                Motion::Rotate {
                    axis: Vector3::z(),
                    angle: 0.0,
                    free: None,
                },
            );
        }
        if let Some(h) = self.end_handover() {
            h.release = Some(finger);
        }
    }

    /// The last step ends with a handover to the carrying set in which
    /// `spin` (if any) spins next, pushing along its normal only; the
    /// handover passes the grip from the set before.
    fn mark_spin(&mut self, spin: Option<usize>) {
        if let Some(h) = self.end_handover() {
            h.spin = spin;
        }
    }

    /// The handover at the end of the last step, made (passing nothing
    /// yet, `load.handover_time` long) if it has none; `None` without
    /// handovers or steps.
    fn end_handover(&mut self) -> Option<&mut Handover> {
        end_handover(&mut self.steps, self.handover_time)
    }

    /// A motion on the still object.
    pub fn still(&mut self, a: &StillAction) -> Result<(), Blocked> {
        match a {
            StillAction::Roll(rolls) => {
                let ratio = self.g.contact_radius / self.g.fingertip_radius;
                self.push(
                    StepKind::Roll,
                    Motion::Roll {
                        rolls: *rolls,
                        ratio,
                    },
                );
                Ok(())
            }
            StillAction::Lift(f) => {
                self.lift(*f);
                Ok(())
            }
            StillAction::Place {
                finger,
                contact,
                roll,
            } => self.place(*finger, contact, *roll),
            StillAction::Path(finger, path) => {
                self.roll_path(*finger, path);
                Ok(())
            }
            StillAction::Spin(finger, path) => {
                self.mark_spin(Some(*finger));
                self.roll_path(*finger, path);
                self.mark_spin(None);
                Ok(())
            }
        }
    }

    /// A rolling path of one finger, one step per segment (the rates jump
    /// at segment ends, so the executor comes to rest there).
    pub fn roll_path(&mut self, finger: usize, path: &crate::rolling::RollingPath) {
        for (seg, from) in path.segments().iter().zip(path.waypoints()) {
            self.push(
                StepKind::Roll,
                Motion::RollSegment {
                    finger,
                    segment: *seg,
                    from: *from,
                    geom: *path.geometry(),
                },
            );
        }
    }

    /// Radial ascent of a grasping finger to the transfer height, after
    /// its grip ramped out.
    pub fn lift(&mut self, finger: usize) {
        self.release_before_lift(finger);
        let dir = self.hand.fingers[finger].contact_normal();
        self.push(
            StepKind::Lift,
            Motion::Free(FreeMove {
                finger,
                path: FreePath::Radial {
                    dir,
                    from: self.g.contact_radius,
                    to: self.g.transfer_radius,
                },
                turn: Reorientation::NONE,
                contact_at_end: false,
            }),
        );
    }

    /// Brings a free finger to the transfer height if it is elsewhere in
    /// its shell. Going down can bring it closer to a neighbour: then it
    /// first travels at its height to over its cone centre.
    fn raise_to_transfer_height(&mut self, finger: usize) -> Result<(), Blocked> {
        let p = self.hand.fingers[finger].center;
        let rho = p.norm();
        if (rho - self.g.transfer_radius).abs() <= 1e-12 {
            return Ok(());
        }
        let (others, n) = other_centers(&self.hand, finger);
        let radial = |dir: Vector3<f64>| FreePath::Radial {
            dir,
            from: rho,
            to: self.g.transfer_radius,
        };
        let mut path = radial(p / rho);
        if !path_clear(self.g, &path, &others[..n]) {
            let arc = FreePath::arc(&(p / rho), &self.g.base[finger], rho);
            if !path_clear(self.g, &arc, &others[..n]) {
                return Err(Blocked { finger });
            }
            self.free_step(StepKind::Transfer, finger, arc, Reorientation::NONE, false);
            path = radial(self.g.base[finger]);
            if !path_clear(self.g, &path, &others[..n]) {
                return Err(Blocked { finger });
            }
        }
        self.free_step(StepKind::Transfer, finger, path, Reorientation::NONE, false);
        Ok(())
    }

    fn free_step(
        &mut self,
        kind: StepKind,
        finger: usize,
        path: FreePath,
        turn: Reorientation,
        contact_at_end: bool,
    ) {
        self.push(
            kind,
            Motion::Free(FreeMove {
                finger,
                path,
                turn,
                contact_at_end,
            }),
        );
    }

    /// The arcs (one, or two via the cone centre) that take a hovering
    /// finger to above `target` clear of the other fingertips.
    fn route(
        &self,
        finger: usize,
        target: &Vector3<f64>,
        rho: f64,
    ) -> Result<([Option<FreePath>; 2], bool), Blocked> {
        let from = self.hand.fingers[finger].center.normalize();
        if angle_between(&from, target) < 1e-12 {
            return Ok(([None, None], true));
        }
        let (others, n) = other_centers(&self.hand, finger);
        let direct = FreePath::arc(&from, target, rho);
        if path_clear(self.g, &direct, &others[..n]) {
            return Ok(([Some(direct), None], false));
        }
        let centre = self.g.base[finger];
        let a = FreePath::arc(&from, &centre, rho);
        let b = FreePath::arc(&centre, target, rho);
        if path_clear(self.g, &a, &others[..n]) && path_clear(self.g, &b, &others[..n]) {
            return Ok(([Some(a), Some(b)], false));
        }
        Err(Blocked { finger })
    }

    /// Place: travel above `contact`, turn to pole-down with roll `roll`,
    /// descend and touch.
    pub fn place(
        &mut self,
        finger: usize,
        contact: &Vector3<f64>,
        roll: f64,
    ) -> Result<(), Blocked> {
        // Travel at the height the finger hovers at (a start state may leave
        // it anywhere in its shell); only when that is blocked go up to the
        // transfer height first.
        let rho = self.hand.fingers[finger].center.norm();
        let arcs = match self.route(finger, contact, rho) {
            Ok((arcs, _)) => arcs,
            Err(_) => {
                self.raise_to_transfer_height(finger)?;
                self.route(finger, contact, self.g.transfer_radius)?.0
            }
        };
        let f = self.hand.fingers[finger];
        let mut turn = Reorientation::towards(&f.orientation, &(-contact), roll - f.roll);
        let n_arcs = arcs.iter().flatten().count();
        for (i, arc) in arcs.iter().flatten().enumerate() {
            // The whole turn happens on the last arc.
            let this_turn = if i + 1 == n_arcs {
                turn
            } else {
                Reorientation::NONE
            };
            if i + 1 == n_arcs {
                turn = Reorientation::NONE;
            }
            self.push(
                StepKind::Transfer,
                Motion::Free(FreeMove {
                    finger,
                    path: *arc,
                    turn: this_turn,
                    contact_at_end: false,
                }),
            );
        }
        // Correct any residual turn (none after an arc) on the way down.
        let f = self.hand.fingers[finger];
        if n_arcs == 0 {
            turn = Reorientation::towards(&f.orientation, &(-contact), roll - f.roll);
        }
        self.push(
            StepKind::Place,
            Motion::Free(FreeMove {
                finger,
                path: FreePath::Radial {
                    dir: *contact,
                    from: self.hand.fingers[finger].center.norm(),
                    to: self.g.contact_radius,
                },
                turn,
                contact_at_end: true,
            }),
        );
        if let Some(h) = self.end_handover() {
            h.take = Some(finger);
        }
        Ok(())
    }

    /// Rotates the object by the grasping fingers; the free finger (if any)
    /// travels towards `next` (its next placement) meanwhile when safe.
    pub fn rotate(
        &mut self,
        axis: &Vector3<f64>,
        angle: f64,
        next: Option<(usize, Vector3<f64>, f64)>,
    ) -> Result<(), Blocked> {
        let free = (0..3).find(|&k| self.hand.fingers[k].mode == FingerMode::Free);
        let Some(z) = free else {
            self.push(
                StepKind::Rotate,
                Motion::Rotate {
                    axis: *axis,
                    angle,
                    free: None,
                },
            );
            return Ok(());
        };
        if let Some((finger, target, roll)) = next
            && finger == z
        {
            let f = self.hand.fingers[z];
            let rho = f.center.norm();
            let from = f.center / rho;
            if angle_between(&from, &target) > 1e-12 {
                // At the height it hovers at: the placement descends from there.
                let path = FreePath::arc(&from, &target, rho);
                if sweep_clear(self.g, &self.hand, z, axis, angle, Some(&path)) {
                    let turn = Reorientation::towards(&f.orientation, &(-target), roll - f.roll);
                    self.push(
                        StepKind::Rotate,
                        Motion::Rotate {
                            axis: *axis,
                            angle,
                            free: Some(FreeMove {
                                finger: z,
                                path,
                                turn,
                                contact_at_end: false,
                            }),
                        },
                    );
                    return Ok(());
                }
            }
        }
        if !sweep_clear(self.g, &self.hand, z, axis, angle, None) {
            // Park over the cone centre first: no other fingertip can reach it.
            self.raise_to_transfer_height(z)?;
            let from = self.hand.fingers[z].center.normalize();
            let path = FreePath::arc(&from, &self.g.base[z], self.g.transfer_radius);
            let (others, n) = other_centers(&self.hand, z);
            if !path_clear(self.g, &path, &others[..n]) {
                return Err(Blocked { finger: z });
            }
            self.push(
                StepKind::Transfer,
                Motion::Free(FreeMove {
                    finger: z,
                    path,
                    turn: Reorientation::NONE,
                    contact_at_end: false,
                }),
            );
            if !sweep_clear(self.g, &self.hand, z, axis, angle, None) {
                return Err(Blocked { finger: z });
            }
        }
        self.push(
            StepKind::Rotate,
            Motion::Rotate {
                axis: *axis,
                angle,
                free: None,
            },
        );
        Ok(())
    }
}
