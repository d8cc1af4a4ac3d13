//! The loop side of an external plant (shm_schema `PLANT-GUIDE.md`): each
//! tick it takes the newest measurement the loop received and decides
//! whether it is fresh, held, or a fault, and it numbers the commands.
//!
//! A measurement is taken only if it continues the plant's sequence (seq
//! one or more above the last, time later), echoes this daemon's session
//! once the plant has applied one of its commands, echoes no command that
//! was never sent, and converts ([`super::wire::measurement`]). The age it
//! reflects is the number of commands sent after the one it applied, so
//! the executor compares it with the setpoint it really answers (one tick
//! of delay is not a tracking error).
//!
//! Without a fresh measurement the last one is held (its age grows) for
//! up to `plant.max_missed` ticks — in real time also at most
//! `plant.stale_after_ms` after it arrived — then the plant is lost. After
//! a fault a measurement that does not continue the old sequence is the
//! start of a new plant run (a restarted plant), taken as fresh.

use super::PlantSample;
use super::joints::{FingerSetpoint, JointLink};
use super::wire::{self, finger_commands, object_command};
use crate::config::PlantSection;
use crate::sys::clock::Nanos;
use gait::executor::FaultKind;
use gait::planner::Setpoint;
use gait::sim::Measurement;
use nalgebra::Vector3;
use shm_schema::{
    PlantCommand, PlantFault, PlantFingerMode, PlantMeasurement, command_flags, plant_state,
};

/// What a tick gets from the plant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Read {
    /// The measurement to use (fresh or held), if any.
    pub measurement: Option<Measurement>,
    /// Whether it arrived this tick.
    pub fresh: bool,
    /// A fault to report.
    pub fault: Option<LinkFault>,
    /// A chain hand's measured joints, with the measurement.
    pub joints: Option<[Vector3<f64>; 3]>,
}

/// A fault of the plant link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinkFault {
    /// What.
    pub kind: FaultKind,
    /// The plant's own fault code (with `PlantFault`; else `None`).
    pub code: PlantFault,
    /// The finger whose measured field is invalid (with `PlantInvalid`,
    /// when the bad field is one fingertip's).
    pub finger: Option<u8>,
}

impl LinkFault {
    /// A fault of `kind` with no plant code, about no finger.
    pub fn of(kind: FaultKind) -> Self {
        Self {
            kind,
            code: PlantFault::None,
            finger: None,
        }
    }
}

/// The external plant's link state (module docs).
#[derive(Debug, Clone)]
pub struct ExternalPlant {
    session: u64,
    period_ns: u64,
    lockstep: bool,
    max_missed: u32,
    stale_after_ns: u64,
    /// Sequence number and plant time of the last measurement taken (0: none
    /// in this plant run).
    last_seq: u64,
    last_time: u64,
    /// When it was received (wall clock).
    last_arrival: Nanos,
    /// The last measurement taken, with its age brought up to date.
    held: Option<Measurement>,
    /// Ticks in a row without a fresh measurement.
    missed: u32,
    /// The plant has echoed this session: from now on any other is a lie.
    echoed: bool,
    /// A fault was reported since the last fresh measurement.
    faulted: bool,
    /// `PlantLost` reported (once per loss).
    lost: bool,
    /// Commands sent; the last one's sequence number.
    sent: u64,
    /// Fingertip velocities of the last command (acceleration feed-forward).
    prev_velocity: [Vector3<f64>; 3],
    /// A chain hand's joints: read, and commanded.
    joints: Option<Box<Joints>>,
}

/// A joint-level plant's side of the link.
#[derive(Debug, Clone)]
struct Joints {
    link: JointLink,
    /// The joints of the measurement held.
    held: Option<[Vector3<f64>; 3]>,
    /// The joints last commanded (where a setpoint has none).
    last: [Vector3<f64>; 3],
}

impl ExternalPlant {
    /// The link of daemon session `session` (its instance id), ticking
    /// every `period_ns`, with the `[plant]` settings.
    pub fn new(session: u64, period_ns: u64, settings: &PlantSection) -> Self {
        Self {
            session,
            period_ns,
            lockstep: settings.lockstep(),
            max_missed: settings.max_missed,
            stale_after_ns: u64::from(settings.stale_after_ms) * 1_000_000,
            last_seq: 0,
            last_time: 0,
            last_arrival: 0,
            held: None,
            missed: 0,
            echoed: false,
            faulted: false,
            lost: false,
            sent: 0,
            prev_velocity: [Vector3::zeros(); 3],
            joints: None,
        }
    }

    /// A joint-level plant of a chain hand: measured and commanded by
    /// its joints through `link` (shm_schema plant docs).
    pub fn with_joints(mut self, link: JointLink) -> Self {
        self.joints = Some(Box::new(Joints {
            link,
            held: None,
            last: [Vector3::zeros(); 3],
        }));
        self
    }

    /// Whether the loop is paced by the plant.
    pub fn lockstep(&self) -> bool {
        self.lockstep
    }

    /// Sequence number of the last measurement taken (0: none yet).
    pub fn last_seq(&self) -> u64 {
        self.last_seq
    }

    /// Plant time of the last measurement taken \[ns\].
    pub fn last_time(&self) -> u64 {
        self.last_time
    }

    /// This tick's measurement from `sample`, received (wall clock) by
    /// `now`: fresh, held, or a fault (module docs).
    pub fn read(&mut self, sample: &PlantSample, now: Nanos) -> Read {
        let mut fault = None;
        let mut fresh = false;
        if let Some(raw) = &sample.newest {
            match self.take(raw, sample.received_at) {
                Ok(true) => fresh = true,
                Ok(false) => {}
                Err(f) => fault = Some(f),
            }
        }
        if fresh {
            self.missed = 0;
            self.lost = false;
            self.faulted = false;
        } else {
            self.missed = self.missed.saturating_add(1);
            if let Some(m) = self.held.as_mut() {
                m.age = m.age.saturating_add(1);
            }
            let stale =
                !self.lockstep && now.saturating_sub(self.last_arrival) > self.stale_after_ns;
            let gone =
                self.held.is_some() && (self.missed > self.max_missed || stale || sample.timed_out);
            if gone {
                self.held = None;
                if let Some(j) = self.joints.as_mut() {
                    j.held = None;
                }
                if !self.lost && fault.is_none() {
                    self.lost = true;
                    fault = Some(LinkFault::of(FaultKind::PlantLost));
                }
            }
        }
        if sample.contract_broken && fault.is_none() {
            fault = Some(LinkFault::of(FaultKind::PlantTiming));
        }
        if fault.is_some() {
            self.faulted = true;
        }
        Read {
            measurement: self.held,
            fresh,
            fault,
            joints: self.held.and(self.joints.as_ref().and_then(|j| j.held)),
        }
    }

    /// Takes `raw` if it is a new, valid measurement: `Ok(true)` when taken,
    /// `Ok(false)` when it repeats the last one, the fault otherwise.
    fn take(&mut self, raw: &PlantMeasurement, at: Nanos) -> Result<bool, LinkFault> {
        let lie = |k| Err(LinkFault::of(k));
        if raw.seq == 0 {
            return lie(FaultKind::PlantSequence);
        }
        // A new plant run after a fault (a restarted plant) starts afresh.
        let continues = self.last_seq == 0 || raw.seq > self.last_seq;
        if raw.seq == self.last_seq {
            return Ok(false);
        }
        if !continues && !self.faulted {
            return lie(FaultKind::PlantSequence);
        }
        let new_run = !continues;
        if !new_run && self.last_seq != 0 && raw.time_ns <= self.last_time {
            return lie(FaultKind::PlantSequence);
        }
        let ours = raw.session == self.session;
        if (self.echoed && !ours && !new_run) || (ours && raw.applied > self.sent) {
            return lie(FaultKind::PlantSequence);
        }
        // In sequence: the next command answers it, whatever it holds (a
        // lockstep plant waits for that answer; one that never came would
        // stall the exchange after a single bad measurement). Its content
        // is taken only if it is valid.
        self.last_seq = raw.seq;
        self.last_time = raw.time_ns;
        self.last_arrival = at;
        if raw.state & plant_state::FAULT != 0 {
            let code = raw.fault().unwrap_or(PlantFault::Other);
            return Err(LinkFault {
                code,
                ..LinkFault::of(FaultKind::PlantFault)
            });
        }
        let age = if ours {
            u32::try_from(self.sent - raw.applied).unwrap_or(u32::MAX)
        } else {
            0
        };
        let (m, joints) = match &self.joints {
            Some(j) => wire::joint_measurement(raw, age, &j.link).map(|(m, q)| (m, Some(q))),
            None => wire::measurement(raw, age).map(|m| (m, None)),
        }
        .map_err(|e| LinkFault {
            finger: e.finger(),
            ..LinkFault::of(FaultKind::PlantInvalid)
        })?;
        let m = Measurement {
            object_age: wire::object_age_ticks(raw.object_age_us, self.period_ns),
            ..m
        };
        if age > self.max_missed {
            // It reflects a command older than the tolerance: the plant
            // lags too far behind to be controlled.
            return lie(FaultKind::PlantLost);
        }
        self.echoed = ours;
        self.held = Some(m);
        if let Some(j) = self.joints.as_mut() {
            j.held = joints;
        }
        Ok(true)
    }

    /// The next command: the setpoint `sp`, each finger's mode and intended
    /// grip (its normal force, and its whole contact force `force` on the
    /// object), and the `flags` (ENABLE, HOLD, LOCKSTEP bits); on a chain
    /// hand also its joint fields from the commanded `joints` (a finger
    /// without keeps the joints it was last commanded) and the JOINTS bit.
    pub fn command(
        &mut self,
        sp: &Setpoint,
        modes: &[PlantFingerMode; 3],
        (grip, force): (&[f64; 3], &[Vector3<f64>; 3]),
        joints: &[Option<Vector3<f64>>; 3],
        flags: u32,
    ) -> PlantCommand {
        self.sent += 1;
        let dt = self.period_ns as f64 * 1e-9;
        let accel = std::array::from_fn(|k| (sp.finger_velocity[k] - self.prev_velocity[k]) / dt);
        self.prev_velocity = sp.finger_velocity;
        let mut c = PlantCommand {
            session: self.session,
            seq: self.sent,
            answers: self.last_seq,
            target_time_ns: if self.last_seq == 0 {
                0
            } else {
                self.last_time + self.period_ns
            },
            period_ns: self.period_ns,
            flags,
            reserved: 0,
            fingers: finger_commands(sp, &accel, modes, grip),
            ..PlantCommand::default()
        };
        object_command(sp, &mut c);
        if let Some(j) = self.joints.as_mut() {
            c.flags |= command_flags::JOINTS;
            for (k, f) in c.fingers.iter_mut().enumerate() {
                if let Some(q) = joints[k] {
                    j.last[k] = q;
                }
                let setpoint = FingerSetpoint {
                    joints: j.last[k],
                    center: sp.state.fingers[k].center,
                    velocity: sp.finger_velocity[k],
                    force: if f.grip_force > 0.0 {
                        force[k]
                    } else {
                        Vector3::zeros()
                    },
                };
                j.link.command(k, &setpoint, f);
            }
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gait::HandConfig;
    use gait::HandState;
    use shm_schema::measurement_valid;

    const SESSION: u64 = 0x5e55;

    fn raw(seq: u64, applied: u64, session: u64) -> PlantMeasurement {
        let s = HandState::paper_start(&HandConfig::default());
        let mut m = PlantMeasurement {
            session,
            seq,
            applied,
            time_ns: seq * 1_000_000,
            valid: measurement_valid::REQUIRED,
            object_q: [1.0, 0.0, 0.0, 0.0],
            ..PlantMeasurement::default()
        };
        for (w, f) in m.fingers.iter_mut().zip(&s.fingers) {
            w.position = f.center.into();
            let q = f.orientation;
            w.orientation = [q.w, q.i, q.j, q.k];
            w.contact = 1;
        }
        m
    }

    fn sample(m: PlantMeasurement, at: Nanos) -> PlantSample {
        PlantSample {
            newest: Some(m),
            received: 1,
            received_at: at,
            ..PlantSample::default()
        }
    }

    fn link(max_missed: u32) -> ExternalPlant {
        let settings = PlantSection {
            max_missed,
            ..PlantSection::default()
        };
        ExternalPlant::new(SESSION, 1_000_000, &settings)
    }

    fn send(l: &mut ExternalPlant) -> PlantCommand {
        let sp = Setpoint {
            state: HandState::paper_start(&HandConfig::default()),
            object_rate: Vector3::zeros(),
            finger_velocity: [Vector3::zeros(); 3],
            finger_rate: [Vector3::zeros(); 3],
            estimate_epoch: 0,
        };
        l.command(
            &sp,
            &[PlantFingerMode::Grasping; 3],
            (&[1.0; 3], &[Vector3::zeros(); 3]),
            &[None; 3],
            1,
        )
    }

    #[test]
    fn fresh_held_then_lost() {
        let mut l = link(3);
        let r = l.read(&sample(raw(1, 0, 0), 10), 10);
        assert!(r.fresh && r.fault.is_none() && r.measurement.unwrap().age == 0);
        let c = send(&mut l);
        assert_eq!((c.seq, c.answers, c.target_time_ns), (1, 1, 2_000_000));
        send(&mut l);
        // The plant applied command 1 while 2 was already sent: age 1.
        let r = l.read(&sample(raw(2, 1, SESSION), 20), 20);
        assert_eq!(r.measurement.unwrap().age, 1);
        // Three ticks held (age grows), the fourth is a loss, reported once.
        for k in 1..=3 {
            let r = l.read(&PlantSample::default(), 20 + k);
            assert!(!r.fresh && r.fault.is_none());
            assert_eq!(r.measurement.unwrap().age, 1 + k as u32);
        }
        let r = l.read(&PlantSample::default(), 30);
        assert_eq!(r.fault, Some(LinkFault::of(FaultKind::PlantLost)));
        assert!(r.measurement.is_none());
        assert_eq!(l.read(&PlantSample::default(), 31).fault, None);
        // It comes back: fresh again.
        let r = l.read(&sample(raw(3, 2, SESSION), 40), 40);
        assert!(r.fresh && r.fault.is_none());
    }

    #[test]
    fn a_repeated_sample_is_not_fresh_and_lies_are_faults() {
        let mut l = link(10);
        l.read(&sample(raw(5, 0, 0), 1), 1);
        send(&mut l);
        assert!(!l.read(&sample(raw(5, 0, 0), 2), 2).fresh);
        let lie = |l: &mut ExternalPlant, m: PlantMeasurement| l.read(&sample(m, 3), 3).fault;
        // Backwards.
        assert_eq!(
            lie(&mut l.clone(), raw(4, 1, SESSION)).map(|f| f.kind),
            Some(FaultKind::PlantSequence)
        );
        // Echoes a command never sent.
        assert_eq!(
            lie(&mut l.clone(), raw(6, 9, SESSION)).map(|f| f.kind),
            Some(FaultKind::PlantSequence)
        );
        // Time not moving on.
        let mut m = raw(6, 1, SESSION);
        m.time_ns = 1;
        assert_eq!(
            lie(&mut l.clone(), m).map(|f| f.kind),
            Some(FaultKind::PlantSequence)
        );
        // Non-finite, in finger 2's field or the object's.
        let mut m = raw(6, 1, SESSION);
        m.fingers[2].position[0] = f64::NAN;
        assert_eq!(
            lie(&mut l.clone(), m).map(|f| (f.kind, f.finger)),
            Some((FaultKind::PlantInvalid, Some(2)))
        );
        let mut m = raw(6, 1, SESSION);
        m.object_q[0] = f64::NAN;
        assert_eq!(
            lie(&mut l.clone(), m).map(|f| (f.kind, f.finger)),
            Some((FaultKind::PlantInvalid, None))
        );
        // Its own fault.
        let mut m = raw(6, 1, SESSION);
        m.state = plant_state::FAULT;
        m.fault = PlantFault::EmergencyStop.code();
        assert_eq!(
            lie(&mut l.clone(), m),
            Some(LinkFault {
                code: PlantFault::EmergencyStop,
                ..LinkFault::of(FaultKind::PlantFault)
            })
        );
        // Once our session was echoed, another one is a lie.
        l.read(&sample(raw(6, 1, SESSION), 4), 4);
        assert_eq!(
            lie(&mut l.clone(), raw(7, 1, 0xbad)).map(|f| f.kind),
            Some(FaultKind::PlantSequence)
        );
    }

    /// A measurement in sequence that cannot be used (non-unit, the
    /// plant's own fault) is still answered: a lockstep plant waits for
    /// exactly that answer. Its content is not taken.
    #[test]
    fn an_unusable_measurement_in_sequence_is_answered() {
        let mut l = link(10);
        l.read(&sample(raw(5, 0, 0), 1), 1);
        assert_eq!(send(&mut l).answers, 5);
        let mut bad = raw(6, 1, SESSION);
        bad.object_q = [0.9, 0.0, 0.0, 0.0];
        let r = l.read(&sample(bad, 2), 2);
        assert_eq!(r.fault.map(|f| f.kind), Some(FaultKind::PlantInvalid));
        assert!(!r.fresh);
        assert_eq!(
            r.measurement.unwrap().object.w,
            1.0,
            "the last good one held"
        );
        assert_eq!(send(&mut l).answers, 6);
        // The plant goes on: taken.
        let r = l.read(&sample(raw(7, 2, SESSION), 3), 3);
        assert!(r.fresh && r.fault.is_none(), "{r:?}");
        // A lie about the sequence is not answered.
        let mut l2 = l.clone();
        l2.read(&sample(raw(3, 2, SESSION), 4), 4);
        assert_eq!(send(&mut l2).answers, 7);
    }

    #[test]
    fn after_a_fault_a_restarted_plant_starts_a_new_run() {
        let mut l = link(10);
        l.read(&sample(raw(100, 0, 0), 1), 1);
        send(&mut l);
        l.read(&sample(raw(101, 1, SESSION), 2), 2);
        // Killed: lost after the tolerance.
        for t in 0..11 {
            l.read(&PlantSample::default(), 3 + t);
        }
        // Restarted: seq from 1, no command applied yet.
        let r = l.read(&sample(raw(1, 0, 0), 20), 20);
        assert!(r.fresh && r.fault.is_none(), "{r:?}");
        let r = l.read(&sample(raw(2, 0, 0), 21), 21);
        assert!(r.fresh);
    }

    #[test]
    fn stale_in_real_time() {
        let mut l = link(1000);
        l.read(&sample(raw(1, 0, 0), 0), 0);
        // 20 ms default staleness bound.
        assert!(l.read(&PlantSample::default(), 19_000_000).fault.is_none());
        assert_eq!(
            l.read(&PlantSample::default(), 21_000_000)
                .fault
                .map(|f| f.kind),
            Some(FaultKind::PlantLost)
        );
    }
}
