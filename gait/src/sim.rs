//! The plant interface and the embedded kinematic hand (SPEC §6.2).
//!
//! A [`Plant`] takes fingertip setpoints and reports measured fingertip
//! poses, contact states and the object orientation. The default plant,
//! [`KinematicHand`], applies the contact kinematics exactly: the plan is
//! executed as commanded. For tests it injects faults: contact slip, sensor
//! noise, a stuck finger and dropped measurements. Other plants (a physics
//! simulator, hardware) attach through the same trait.

use nalgebra::{UnitQuaternion, Vector3};

use crate::hand_state::{FingerMode, HandState};
use crate::planner::Setpoint;

/// One measured fingertip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredFinger {
    /// Fingertip centre, hand frame \[m\].
    pub center: Vector3<f64>,
    /// Fingertip orientation (fingertip → hand).
    pub orientation: UnitQuaternion<f64>,
    /// Whether the fingertip touches the object.
    pub contact: bool,
    /// Measured normal force at the contact \[N\], if the plant senses it
    /// (the kinematic hand does not).
    pub normal_force: Option<f64>,
    /// Roll τ about the pole axis \[rad\], if the plant reports it (a hand's
    /// twist joint; the kinematic hand reports its own).
    pub roll: Option<f64>,
}

/// What a plant reports each tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// Object orientation (object → hand).
    pub object: UnitQuaternion<f64>,
    /// The three fingertips.
    pub fingers: [MeasuredFinger; 3],
    /// Object centre, hand frame \[m\], if the plant measures it (the
    /// model puts it at the origin; a grasp under load sags a little, and
    /// the position correction, [`crate::executor::correction`], brings
    /// it back). The kinematic hand reports `None`: its object never moves.
    pub center: Option<Vector3<f64>>,
    /// How many setpoints older than the last one written this measurement
    /// reflects: 0 for a plant that applied the last setpoint (the
    /// kinematic hand, a lockstep plant), 1 when it applied the one before,
    /// and so on (an external plant echoes the command it applied).
    pub age: u32,
    /// How many ticks before the rest of this measurement the object's
    /// pose (`object`, `center`) was sampled: a tracking system's latency
    /// and the age of its last sample (0: with the rest).
    pub object_age: u32,
}

impl Measurement {
    /// The measurement a perfect sensor gives of `state`.
    pub fn of(state: &HandState) -> Self {
        Self {
            object: state.object,
            fingers: state.fingers.map(|f| MeasuredFinger {
                center: f.center,
                orientation: f.orientation,
                contact: f.mode == FingerMode::Grasping,
                normal_force: None,
                roll: Some(f.roll),
            }),
            center: None,
            age: 0,
            object_age: 0,
        }
    }

    /// The hand state this measurement describes: object and fingertips
    /// where measured, modes from the contact flags, rolls as measured
    /// (else `fallback`'s).
    pub fn hand_state(&self, fallback: &HandState) -> HandState {
        let mut s = *fallback;
        s.object = self.object;
        for (f, m) in s.fingers.iter_mut().zip(&self.fingers) {
            f.center = m.center;
            f.orientation = m.orientation;
            f.mode = if m.contact {
                FingerMode::Grasping
            } else {
                FingerMode::Free
            };
            if let Some(r) = m.roll {
                f.roll = r;
            }
        }
        s
    }

    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        self.object.coords.iter().all(|x| x.is_finite())
            && self.center.is_none_or(|c| c.iter().all(|x| x.is_finite()))
            && self.fingers.iter().all(|f| {
                f.center.iter().all(|x| x.is_finite())
                    && f.orientation.coords.iter().all(|x| x.is_finite())
                    && f.normal_force.is_none_or(f64::is_finite)
                    && f.roll.is_none_or(f64::is_finite)
            })
    }
}

/// The hand as the controller sees it.
pub trait Plant {
    /// Commands the next setpoint.
    fn write(&mut self, setpoint: &Setpoint);
    /// The latest measurement, or `None` if none arrived this tick.
    fn read(&mut self) -> Option<Measurement>;
}

/// A fault the kinematic hand can be told to simulate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InjectedFault {
    /// The object slips in the grasp: it turns about `axis` (hand frame) at
    /// `rate` rad/s relative to the fingers. The turn it made stays when the
    /// fault is cleared (the object does not jump back).
    Slip {
        /// Unit axis.
        axis: Vector3<f64>,
        /// Slip rate [rad/s].
        rate: f64,
    },
    /// Gaussian-like noise of standard deviation `position` \[m\] on the
    /// fingertip centres and `angle` \[rad\] on the object orientation.
    Noise {
        /// Position noise \[m\].
        position: f64,
        /// Orientation noise \[rad\].
        angle: f64,
    },
    /// A finger stops following its setpoints.
    Stuck {
        /// Which finger.
        finger: usize,
    },
    /// Measurements stop arriving.
    Missing,
    /// The sensor reports a finger's centre `offset` \[m\] (hand frame) from
    /// where it is (a calibration error); the finger itself is unaffected.
    Bias {
        /// Which finger.
        finger: usize,
        /// Measurement error.
        offset: Vector3<f64>,
    },
}

/// The embedded plant: applies setpoints exactly (SPEC §6.2).
///
/// Fingertips go where they are commanded. The object turns by the change
/// of the commanded object orientation from one setpoint to the next (the
/// grasping contacts roll it), so a slip leaves a lasting offset between the
/// true and the commanded object, as it would on a real hand, and a change
/// of [`Setpoint::estimate_epoch`] (the controller re-basing its estimate)
/// does not move it.
#[derive(Debug, Clone)]
pub struct KinematicHand {
    state: HandState,
    fault: Option<InjectedFault>,
    dt: f64,
    rng: u64,
    /// Object orientation and estimate epoch of the last setpoint.
    commanded_object: UnitQuaternion<f64>,
    epoch: u32,
}

impl KinematicHand {
    /// A hand in `state`, ticking every `dt` seconds.
    pub fn new(state: HandState, dt: f64) -> Self {
        Self {
            state,
            fault: None,
            dt,
            rng: 0x9E37_79B9_7F4A_7C15,
            commanded_object: state.object,
            epoch: 0,
        }
    }

    /// The true state.
    pub fn state(&self) -> &HandState {
        &self.state
    }

    /// Starts (or with `None`, clears) a simulated fault.
    pub fn inject(&mut self, fault: Option<InjectedFault>) {
        self.fault = fault;
    }

    /// The active simulated fault.
    pub fn fault(&self) -> Option<InjectedFault> {
        self.fault
    }

    /// Deterministic noise in [−1, 1]³ summed three times (≈ Gaussian,
    /// σ ≈ 1): xorshift, no allocation.
    fn noise(&mut self) -> f64 {
        let mut sum = 0.0;
        for _ in 0..3 {
            self.rng ^= self.rng << 13;
            self.rng ^= self.rng >> 7;
            self.rng ^= self.rng << 17;
            sum += (self.rng >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
        }
        sum
    }
}

impl Plant for KinematicHand {
    fn write(&mut self, setpoint: &Setpoint) {
        let stuck = match self.fault {
            Some(InjectedFault::Stuck { finger }) => Some(finger),
            _ => None,
        };
        for (k, f) in self.state.fingers.iter_mut().enumerate() {
            if stuck != Some(k) {
                *f = setpoint.state.fingers[k];
            }
        }
        let target = setpoint.state.object;
        // Across a change of epoch the estimate was re-based: no motion.
        if setpoint.estimate_epoch == self.epoch {
            if self.state.object == self.commanded_object {
                // No offset: exactly the commanded orientation.
                self.state.object = target;
            } else {
                let turn = target * self.commanded_object.inverse();
                self.state.object =
                    UnitQuaternion::new_normalize((turn * self.state.object).into_inner());
            }
        }
        self.commanded_object = target;
        self.epoch = setpoint.estimate_epoch;
        if let Some(InjectedFault::Slip { axis, rate }) = self.fault {
            let slip = UnitQuaternion::from_scaled_axis(axis * (rate * self.dt));
            self.state.object = slip * self.state.object;
        }
    }

    fn read(&mut self) -> Option<Measurement> {
        let mut m = Measurement::of(&self.state);
        match self.fault {
            Some(InjectedFault::Missing) => return None,
            Some(InjectedFault::Noise { position, angle }) => {
                for f in m.fingers.iter_mut() {
                    let d = Vector3::new(self.noise(), self.noise(), self.noise());
                    f.center += d * position;
                }
                let w = Vector3::new(self.noise(), self.noise(), self.noise());
                m.object = UnitQuaternion::from_scaled_axis(w * angle) * m.object;
            }
            Some(InjectedFault::Bias { finger, offset }) => {
                if let Some(f) = m.fingers.get_mut(finger) {
                    f.center += offset;
                }
            }
            _ => {}
        }
        Some(m)
    }
}
