//! The kinematic hand as an out-of-process plant: the embedded hand
//! (`gait::sim::KinematicHand`, every setpoint executed exactly) behind
//! the plant interface, so the interface is tested without physics.

use gait::planner::Setpoint;
use gait::sim::{KinematicHand, Plant};
use gait::{FingerMode, HandConfig, HandState};
use gaitd_client::plant::PlantModel;
use gaitd_client::shm_schema::{
    PlantCommand, PlantFingerMode, PlantMeasurement, measurement_valid, plant_state,
};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::sync::atomic::{AtomicBool, Ordering};

/// A lie the plant tells once, on SIGUSR1 (`gaitctl plant sim
/// --lie-on-usr1 KIND`): to see how a daemon (and its clients) handle a
/// plant that misbehaves for one measurement.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lie {
    /// The next measurement's object quaternion is (0.9, 0, 0, 0): not of
    /// unit norm.
    NonUnit,
}

/// Set by SIGUSR1; the next measurement lies (then it is cleared).
static LIE_NOW: AtomicBool = AtomicBool::new(false);

extern "C" fn on_usr1(_: libc::c_int) {
    LIE_NOW.store(true, Ordering::Release);
}

/// Makes SIGUSR1 arm a one-time lie.
pub fn lie_on_usr1() {
    // SAFETY: the handler only stores to an atomic (async-signal-safe).
    unsafe {
        libc::signal(libc::SIGUSR1, on_usr1 as *const () as libc::sighandler_t);
    }
}

/// The kinematic plant; stops the run after `seconds` simulated, if given.
pub struct KinematicPlant {
    hand: KinematicHand,
    until_ns: Option<u64>,
    time_ns: u64,
    period_ns: u64,
    /// |centre| of a fingertip touching the object, R + r \[m\].
    contact_radius: f64,
    /// The lie told on SIGUSR1, if any.
    lie: Option<Lie>,
}

fn quat(q: [f64; 4]) -> UnitQuaternion<f64> {
    UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3]))
}

fn q4(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// Set once the simulated time is up (and on Ctrl-C, see `common`).
pub static STOP: AtomicBool = AtomicBool::new(false);

impl KinematicPlant {
    /// At the paper's start grasp of `config`.
    pub fn new(config: &HandConfig, period_ns: u64, seconds: Option<f64>) -> Self {
        let start = HandState::paper_start(config);
        Self {
            hand: KinematicHand::new(start, period_ns as f64 * 1e-9),
            until_ns: seconds.map(|s| (s * 1e9) as u64),
            time_ns: 0,
            period_ns,
            contact_radius: config.model.object_radius + config.model.fingertip_radius,
            lie: None,
        }
    }

    /// Tells `lie` once for every SIGUSR1 received ([`lie_on_usr1`]).
    pub fn with_lie(mut self, lie: Option<Lie>) -> Self {
        self.lie = lie;
        self
    }
}

impl PlantModel for KinematicPlant {
    fn apply(&mut self, c: &PlantCommand) {
        let mut state = *self.hand.state();
        state.object = quat(c.object_q);
        for (f, cf) in state.fingers.iter_mut().zip(&c.fingers) {
            f.center = Vector3::from(cf.position);
            f.orientation = quat(cf.orientation);
            f.roll = cf.roll;
            // Grasping presses; a placing or lifting fingertip that the
            // setpoint puts on the surface touches too (PLANT-GUIDE: the
            // grip ramps in, or out, while it does).
            let on_surface = (f.center.norm() - self.contact_radius).abs() < 1e-9;
            let touching = cf.mode == PlantFingerMode::Grasping.code()
                || ((cf.mode == PlantFingerMode::Placing.code()
                    || cf.mode == PlantFingerMode::Lifting.code())
                    && on_surface);
            f.mode = if touching {
                FingerMode::Grasping
            } else {
                FingerMode::Free
            };
        }
        let sp = Setpoint {
            state,
            object_rate: Vector3::from(c.object_omega),
            finger_velocity: c.fingers.map(|f| Vector3::from(f.velocity)),
            finger_rate: c.fingers.map(|f| Vector3::from(f.angular_velocity)),
            estimate_epoch: 0,
        };
        self.hand.write(&sp);
    }

    fn step(&mut self, _dt: f64) {
        self.time_ns += self.period_ns;
        if self.until_ns.is_some_and(|t| self.time_ns >= t) {
            STOP.store(true, Ordering::Release);
        }
    }

    fn measure(&mut self, m: &mut PlantMeasurement) {
        let s = self.hand.state();
        m.valid = measurement_valid::REQUIRED;
        m.state = plant_state::SIMULATED;
        m.object_q = q4(&s.object);
        for (w, f) in m.fingers.iter_mut().zip(&s.fingers) {
            w.position = f.center.into();
            w.orientation = q4(&f.orientation);
            w.contact = u32::from(f.mode == FingerMode::Grasping);
            w.roll = f.roll;
        }
        take_lie(self.lie, m, "kinematic plant");
    }
}

/// Tells `lie` in `m` if SIGUSR1 armed it (then disarms it); `who` says
/// so on stderr.
pub fn take_lie(lie: Option<Lie>, m: &mut PlantMeasurement, who: &str) {
    if let Some(lie) = lie
        && LIE_NOW.swap(false, Ordering::AcqRel)
    {
        match lie {
            Lie::NonUnit => m.object_q = [0.9, 0.0, 0.0, 0.0],
        }
        eprintln!("{who}: lied once ({lie:?})");
    }
}
