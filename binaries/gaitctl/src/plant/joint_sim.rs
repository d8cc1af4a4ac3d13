//! A chain hand (TriFingerPro) as an out-of-process plant, kinematic and
//! joint-level: each command's joint setpoints (`command_flags::JOINTS`)
//! are where the joints are the next period, the object turns as
//! commanded, and a finger touches the object where the setpoint puts its
//! tip on it. It measures what a joint-level hand measures — joint
//! positions, velocities and the torques it applies (the feed-forward,
//! clipped at each motor's limit: no tracking error, so the PD terms add
//! nothing), the object's orientation, the contacts — and no tip poses:
//! the daemon makes them from the joints.

use super::sim::{Lie, STOP, take_lie};
use gait::planner::chains::ChainHand;
use gaitd_client::plant::PlantModel;
use gaitd_client::shm_schema::{
    PlantCommand, PlantFingerMode, PlantMeasurement, command_flags, measurement_valid, plant_state,
};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::sync::atomic::Ordering;

use super::config::ChainSetup;

/// Joints per finger.
const JOINTS: usize = 3;

/// The joint-level kinematic plant; stops the run after `seconds`
/// simulated, if given.
pub struct JointKinematicPlant {
    hand: ChainHand,
    q: [Vector3<f64>; 3],
    qd: [Vector3<f64>; 3],
    tau: [Vector3<f64>; 3],
    object: UnitQuaternion<f64>,
    contact: [bool; 3],
    until_ns: Option<u64>,
    time_ns: u64,
    period_ns: u64,
    /// Commands without joints seen (said once).
    tip_commands: u64,
    lie: Option<Lie>,
}

fn joints3(a: &[f64; 4]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

impl JointKinematicPlant {
    /// At `setup`'s start grasp, each finger on the branch the daemon
    /// picks for it; `None` if a finger cannot reach its start.
    pub fn new(setup: &ChainSetup, period_ns: u64, seconds: Option<f64>) -> Option<Self> {
        let mut q = [Vector3::zeros(); 3];
        for (k, f) in setup.start.fingers.iter().enumerate() {
            q[k] = setup.hand.joints(k, &f.center, None)?;
        }
        Some(Self {
            hand: setup.hand.clone(),
            q,
            qd: [Vector3::zeros(); 3],
            tau: [Vector3::zeros(); 3],
            object: setup.start.object,
            contact: [true; 3],
            until_ns: seconds.map(|s| (s * 1e9) as u64),
            time_ns: 0,
            period_ns,
            tip_commands: 0,
            lie: None,
        })
    }

    /// Tells `lie` once for every SIGUSR1 received.
    pub fn with_lie(mut self, lie: Option<Lie>) -> Self {
        self.lie = lie;
        self
    }

    /// Finger `k`'s tip centre distance from the object's surface shell
    /// (R + r from its centre) \[m\].
    fn off_surface(&self, k: usize) -> f64 {
        let o = self.hand.object();
        let tip = self.hand.chain(k).forward(&self.q[k]).tip_centre();
        (tip - o.centre).norm() - (o.radius + self.hand.chain(k).tip_radius)
    }
}

impl PlantModel for JointKinematicPlant {
    fn apply(&mut self, c: &PlantCommand) {
        if c.flags & command_flags::JOINTS == 0 {
            if self.tip_commands == 0 {
                eprintln!(
                    "joint plant: the daemon commands fingertips, not joints: run it with the \
                     same [hand] (kind = \"chains\") as this plant"
                );
            }
            self.tip_commands += 1;
            return;
        }
        self.object = UnitQuaternion::new_normalize(Quaternion::new(
            c.object_q[0],
            c.object_q[1],
            c.object_q[2],
            c.object_q[3],
        ));
        for (k, f) in c.fingers.iter().enumerate() {
            if f.joint_count as usize != JOINTS {
                continue;
            }
            self.q[k] = joints3(&f.joint_position);
            self.qd[k] = joints3(&f.joint_velocity);
            let limit = self.hand.chain(k).effort();
            self.tau[k] = joints3(&f.joint_torque).zip_map(&limit, |t, l| t.clamp(-l, l));
            // Grasping presses; a placing or lifting tip the setpoint puts
            // on the surface touches too (PLANT-GUIDE: the grip ramps in,
            // or out, while it does).
            let mode = f.mode;
            self.contact[k] = mode == PlantFingerMode::Grasping.code()
                || ((mode == PlantFingerMode::Placing.code()
                    || mode == PlantFingerMode::Lifting.code())
                    && self.off_surface(k).abs() < 1e-9);
        }
    }

    fn step(&mut self, _dt: f64) {
        self.time_ns += self.period_ns;
        if self.until_ns.is_some_and(|t| self.time_ns >= t) {
            STOP.store(true, Ordering::Release);
        }
    }

    fn measure(&mut self, m: &mut PlantMeasurement) {
        m.valid = measurement_valid::REQUIRED_JOINTS
            | measurement_valid::JOINT_VELOCITY
            | measurement_valid::JOINT_TORQUE;
        m.state = plant_state::SIMULATED;
        m.object_q = [self.object.w, self.object.i, self.object.j, self.object.k];
        for (k, w) in m.fingers.iter_mut().enumerate() {
            w.joint_count = JOINTS as u32;
            for i in 0..JOINTS {
                w.joint_position[i] = self.q[k][i];
                w.joint_velocity[i] = self.qd[k][i];
                w.joint_torque[i] = self.tau[k][i];
            }
            w.contact = u32::from(self.contact[k]);
        }
        take_lie(self.lie, m, "joint plant");
    }
}
