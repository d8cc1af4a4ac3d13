//! daemon → clients: [`Status`], published every tick (latest value).

use crate::codes::{
    DaemonState, FaultCode, FingerPhase, GoalState, GraspState, Phase, ReasonCode, UnknownCode,
};
use iceoryx2::prelude::ZeroCopySend;

/// Number of fingers.
pub const FINGERS: usize = 3;

/// Number of buckets of the coarse wake-up jitter histogram.
pub const JITTER_BUCKETS: usize = 16;

/// Upper edge of jitter bucket `i` in ns: bucket 0 counts jitter < 1 µs,
/// bucket i (1 ≤ i < 15) counts [2^(i−1), 2^i) µs, bucket 15 counts ≥ 16.384 ms.
pub const fn jitter_bucket_upper_ns(i: usize) -> u64 {
    1000 << i
}

/// The bucket of a wake-up jitter value \[ns\].
pub const fn jitter_bucket(jitter_ns: u64) -> usize {
    let us = jitter_ns / 1000;
    if us == 0 {
        return 0;
    }
    let b = (64 - us.leading_zeros()) as usize;
    if b >= JITTER_BUCKETS {
        JITTER_BUCKETS - 1
    } else {
        b
    }
}

/// Marker for "no finger" in finger-index fields.
pub const NO_FINGER: u32 = u32::MAX;

/// The active goal and its progress.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::GoalStatus.v8")]
pub struct GoalStatus {
    /// Id of the current (or last) goal, 0 if none.
    pub goal_id: u64,
    /// Its client's id.
    pub client_id: u64,
    /// [`GoalState`] code.
    pub state: u32,
    /// [`ReasonCode`] code (set in terminal states).
    pub reason: u32,
    /// Angle still to rotate to the target \[rad\].
    pub remaining_angle: f64,
    /// Estimated time to completion \[s\]; −1 when unknown.
    pub eta: f64,
    /// Gaits completed for this goal.
    pub gaits_done: u32,
    /// Gaits in the current plan.
    pub gaits_planned: u32,
    /// Finger moved by the current primitive, or [`NO_FINGER`].
    pub active_finger: u32,
    /// Padding, 0.
    pub reserved: u32,
}

/// Bits of [`Status::measured_mask`]: which measured fields hold a
/// measurement (a plant reports what it senses; the rest stay 0).
pub mod measured {
    /// `measured_object_q` and `object_error`.
    pub const OBJECT: u32 = 1 << 0;
    /// Every finger's `measured_tip_position`, `measured_tip_orientation`
    /// and `tip_error`.
    pub const TIPS: u32 = 1 << 1;
    /// Every finger's `measured_contact`.
    pub const CONTACTS: u32 = 1 << 2;
    /// Every finger's `measured_normal_force`.
    pub const FORCES: u32 = 1 << 3;
    /// Every finger's `measured_joints` (a chain hand whose plant measures
    /// its joints).
    pub const JOINTS: u32 = 1 << 4;
    /// Every bit defined.
    pub const ALL: u32 = OBJECT | TIPS | CONTACTS | FORCES | JOINTS;
}

/// One finger (SPEC §7.3): the commanded state (`commanded_*` and the
/// contact geometry derived from it) beside what the plant measured
/// (`measured_*`, valid per [`Status::measured_mask`]). Contact fields are
/// meaningful while the finger touches (Grasping, Rolling); they are 0
/// otherwise.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::FingerStatus.v8")]
pub struct FingerStatus {
    /// [`FingerPhase`] code.
    pub state: u32,
    /// Measured contact: 1 touching, 0 not (valid with `measured::CONTACTS`).
    pub measured_contact: u32,
    /// Commanded contact point on the object surface, hand frame \[m\].
    pub contact_hand: [f64; 3],
    /// Commanded contact point on the object surface, object frame \[m\].
    pub contact_object: [f64; 3],
    /// Commanded fingertip sphere centre p, hand frame \[m\].
    pub commanded_tip_position: [f64; 3],
    /// Commanded fingertip orientation Q_f [w, x, y, z] (fingertip → hand frame).
    pub commanded_tip_orientation: [f64; 4],
    /// Commanded contact point on the fingertip, fingertip frame, unit vector m.
    pub tip_contact: [f64; 3],
    /// Commanded roll τ about the fingertip pole axis \[rad\].
    pub roll: f64,
    /// Angle from the commanded contact (or lifted tip direction) to its
    /// workspace cone boundary, positive inside \[rad\].
    pub workspace_margin: f64,
    /// Normal force the controller intends at the contact \[N\]; 0 when not
    /// in contact or not computed.
    pub commanded_normal_force: f64,
    /// Measured fingertip centre, hand frame \[m\] (valid with `measured::TIPS`).
    pub measured_tip_position: [f64; 3],
    /// Measured fingertip orientation [w, x, y, z] (valid with `measured::TIPS`).
    pub measured_tip_orientation: [f64; 4],
    /// Measured normal force \[N\] (valid with `measured::FORCES`).
    pub measured_normal_force: f64,
    /// Tracking error: distance from the measured fingertip centre to the
    /// one commanded by the setpoint the measurement answers (see
    /// `Status::measured_age`) \[m\] (valid with `measured::TIPS`).
    pub tip_error: f64,
    /// A chain hand's commanded joint positions, base to tip: the joints
    /// that put the tip where the setpoint commands it \[rad\]; 0 on
    /// free fingertips (`Status::hand`).
    pub commanded_joints: [f64; 3],
    /// Margin of the commanded contact on the fingertip, positive inside
    /// \[rad\]: to the tip patch's edge less its margin on a chain hand, to
    /// the hemisphere's edge on free fingertips; 0 when not touching.
    pub tip_margin: f64,
    /// A chain hand's links off the object beyond the configured
    /// clearance, the closest link \[m\]; 0 on free fingertips.
    pub link_clearance: f64,
    /// A chain hand's measured joint positions, base to tip \[rad\]
    /// (valid with `measured::JOINTS`); the measured tip is where they put
    /// it.
    pub measured_joints: [f64; 3],
}

/// Loop timing (SPEC §7.2, §11). Percentiles are refreshed every
/// [`TIMING_REFRESH_TICKS`] ticks; last and max every tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Timing.v8")]
pub struct Timing {
    /// Loop period \[ns\].
    pub period_ns: u64,
    /// Compute time of the previous tick (wake-up to end of work) \[ns\].
    pub compute_last_ns: u64,
    /// Compute time median since start \[ns\].
    pub compute_p50_ns: u64,
    /// Compute time 99th percentile since start \[ns\].
    pub compute_p99_ns: u64,
    /// Compute time maximum since start \[ns\].
    pub compute_max_ns: u64,
    /// Wake-up jitter (wake time − deadline) of this tick \[ns\].
    pub jitter_last_ns: u64,
    /// Wake-up jitter 99th percentile since start \[ns\].
    pub jitter_p99_ns: u64,
    /// Wake-up jitter maximum since start \[ns\].
    pub jitter_max_ns: u64,
    /// Missed periods since start (skipped, never made up in a burst).
    pub overruns: u64,
    /// Coarse wake-up jitter histogram since start (see [`jitter_bucket`]).
    pub jitter_hist: [u64; JITTER_BUCKETS],
    /// External plant: ticks whose command went out after the tick's
    /// deadline (too late for the plant's next step) since start.
    pub plant_commands_late: u64,
    /// External plant: plant steps that applied the same command as the
    /// step before although a newer one had been sent (the plant held the
    /// last command) since start.
    pub plant_commands_repeated: u64,
    /// External plant: ticks that found no new measurement (the last one
    /// held) since start.
    pub plant_measurements_late: u64,
    /// External plant: measurements received again with a sequence number
    /// already taken since start.
    pub plant_measurements_repeated: u64,
    /// External plant: ticks in a row, up to this one, that missed the
    /// timing contract (any of the four above); at `plant.max_misses_in_row`
    /// the plant is faulted (`PlantTiming`).
    pub plant_misses_in_row: u64,
    /// External plant: the longest such run since start \[ticks\].
    pub plant_misses_in_row_max: u64,
}

/// How often the timing percentiles are recomputed \[ticks\].
pub const TIMING_REFRESH_TICKS: u64 = 100;

/// The daemon's state, published every tick with latest-value semantics
/// (SPEC §7.3): the commanded state beside the measured one, named so that
/// neither is mistaken for the other.
///
/// Type name `gaitd::Status.v8`, 1400 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Status.v8")]
pub struct Status {
    /// Tick counter since daemon start.
    pub tick: u64,
    /// Time of this tick \[ns\]: CLOCK_MONOTONIC at its wake-up; in
    /// lockstep the plant's time of the measurement it ran on (one clock
    /// per run: 0 before the plant's first measurement, the last plant time
    /// while it is gone).
    pub time_ns: u64,
    /// CLOCK_MONOTONIC time just before publishing \[ns\] (for latency measurements).
    pub publish_time_ns: u64,
    /// Random id of this daemon run; changes when the daemon restarts.
    pub instance: u64,
    /// [`DaemonState`] code.
    pub daemon_state: u32,
    /// [`Phase`] code.
    pub phase: u32,
    /// [`FaultCode`] code.
    pub fault: u32,
    /// [`GraspState`] code (force closure of the grasping fingers).
    pub grasp: u32,
    /// Force-closure margin \[rad\] (angle margin of SPEC §3); 0 when unknown.
    pub grasp_margin: f64,
    /// The largest normal force the commanded grasp needs to hold the load
    /// (weight, acceleration torque and any disturbance of the configured
    /// size; F* of SPEC §1.3 I1') \[N\]; +∞ when no grip holds it, 0 with
    /// gravity off and no disturbance.
    pub load_grip: f64,
    /// Load margin `load.max_grip` − `load_grip` \[N\]: ≥ 0 while the
    /// grasp holds the load within the fingertips' force limit, negative
    /// (or −∞) when it cannot. On a chain hand the limit is the strongest
    /// normal push every grasping finger's motors give where it is (with
    /// the links' weight held), if lower than `load.max_grip`.
    pub load_margin: f64,
    /// Commanded object orientation q_o [w, x, y, z] (object → hand frame):
    /// the controller's setpoint, not a measurement.
    pub commanded_object_q: [f64; 4],
    /// Commanded object angular velocity, hand frame [rad/s].
    pub commanded_object_omega: [f64; 3],
    /// Measured object orientation [w, x, y, z] (valid with `measured::OBJECT`).
    pub measured_object_q: [f64; 4],
    /// Angle between the measured object orientation and the one
    /// commanded by the setpoint the measurement answers (see
    /// `measured_age`) \[rad\] (valid with `measured::OBJECT`).
    pub object_error: f64,
    /// Tick at which the measurement reported here was read; 0 = none yet.
    pub measured_tick: u64,
    /// Which measured fields are valid ([`measured`] bits).
    pub measured_mask: u32,
    /// Commands sent after the one the measurement answers (0: it answers
    /// the command of tick `measured_tick` − 1): `object_error` and
    /// `tip_error` compare it with the setpoint of tick `measured_tick` −
    /// 1 − `measured_age`, not with this tick's.
    pub measured_age: u32,
    /// Active goal and progress.
    pub goal: GoalStatus,
    /// Fingers f1, f2, f3.
    pub fingers: [FingerStatus; FINGERS],
    /// Loop timing.
    pub timing: Timing,
    /// Commands received since start.
    pub commands: u64,
    /// Commands rejected since start.
    pub rejected: u64,
    /// Client nodes alive (seen by housekeeping, once per housekeeping
    /// period, about a second).
    pub clients: u32,
    /// The hand model ([`hand`] codes): free fingertips, or finger chains
    /// (whose fingers report their joints).
    pub hand: u32,
}

/// Values of [`Status::hand`].
pub mod hand {
    /// The paper's free fingertips.
    pub const FINGERTIPS: u32 = 0;
    /// Finger joint chains (a URDF hand, e.g. TriFingerPro).
    pub const CHAINS: u32 = 1;
}

const _: () = assert!(core::mem::size_of::<GoalStatus>() == 56);
const _: () = assert!(core::mem::size_of::<FingerStatus>() == 296);
const _: () = assert!(core::mem::size_of::<Timing>() == 248);
const _: () = assert!(core::mem::size_of::<Status>() == 1400);
const _: () = assert!(core::mem::align_of::<Status>() == 8);

impl Status {
    /// Size of the payload in bytes.
    pub const SIZE: usize = 1400;

    /// The payload that `bytes` encode (e.g. as received from a bridge).
    /// Every bit pattern is a `Status` (integers and floats only, no implicit
    /// padding); check the codes with `check` before use.
    pub fn from_bytes(bytes: &[u8; Self::SIZE]) -> Self {
        // SAFETY: repr(C), exactly SIZE bytes of integers and floats without
        // implicit padding: any bytes are a valid value; read_unaligned
        // accepts the byte array's alignment of 1.
        unsafe { core::ptr::read_unaligned(bytes.as_ptr().cast::<Status>()) }
    }

    /// The payload's bytes as they travel (native endianness, as in shared memory).
    pub fn to_bytes(&self) -> [u8; Self::SIZE] {
        // SAFETY: same layout facts as in `from_bytes`; no padding means no
        // uninitialised bytes are read.
        unsafe { core::mem::transmute::<Status, [u8; Self::SIZE]>(*self) }
    }
}

impl Status {
    /// Checks every code in the status (a reader never trusts foreign bytes).
    pub fn check(&self) -> Result<(), UnknownCode> {
        DaemonState::try_from(self.daemon_state)?;
        Phase::try_from(self.phase)?;
        FaultCode::try_from(self.fault)?;
        GraspState::try_from(self.grasp)?;
        GoalState::try_from(self.goal.state)?;
        ReasonCode::try_from(self.goal.reason)?;
        for f in &self.fingers {
            FingerPhase::try_from(f.state)?;
            if f.measured_contact > 1 {
                return Err(UnknownCode {
                    kind: "measured_contact",
                    code: f.measured_contact,
                });
            }
        }
        if self.hand > hand::CHAINS {
            return Err(UnknownCode {
                kind: "hand",
                code: self.hand,
            });
        }
        if self.measured_mask & !measured::ALL != 0 {
            return Err(UnknownCode {
                kind: "measured_mask",
                code: self.measured_mask,
            });
        }
        Ok(())
    }

    /// Decoded [`DaemonState`].
    pub fn daemon_state(&self) -> Result<DaemonState, UnknownCode> {
        DaemonState::try_from(self.daemon_state)
    }

    /// Decoded [`Phase`].
    pub fn phase(&self) -> Result<Phase, UnknownCode> {
        Phase::try_from(self.phase)
    }

    /// Decoded [`FaultCode`].
    pub fn fault(&self) -> Result<FaultCode, UnknownCode> {
        FaultCode::try_from(self.fault)
    }

    /// Decoded [`GraspState`].
    pub fn grasp(&self) -> Result<GraspState, UnknownCode> {
        GraspState::try_from(self.grasp)
    }

    /// Decoded [`GoalState`] of the current goal.
    pub fn goal_state(&self) -> Result<GoalState, UnknownCode> {
        GoalState::try_from(self.goal.state)
    }

    /// Decoded [`ReasonCode`] of the current goal.
    pub fn goal_reason(&self) -> Result<ReasonCode, UnknownCode> {
        ReasonCode::try_from(self.goal.reason)
    }
}

impl FingerStatus {
    /// Decoded [`FingerPhase`].
    pub fn phase(&self) -> Result<FingerPhase, UnknownCode> {
        FingerPhase::try_from(self.state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_buckets_are_powers_of_two_microseconds() {
        assert_eq!(jitter_bucket(0), 0);
        assert_eq!(jitter_bucket(999), 0);
        assert_eq!(jitter_bucket(1000), 1);
        assert_eq!(jitter_bucket(1999), 1);
        assert_eq!(jitter_bucket(2000), 2);
        assert_eq!(jitter_bucket(16_383_999), 14);
        assert_eq!(jitter_bucket(16_384_000), 15);
        assert_eq!(jitter_bucket(u64::MAX), 15);
        for i in 0..JITTER_BUCKETS - 1 {
            assert_eq!(jitter_bucket(jitter_bucket_upper_ns(i) - 1), i);
            assert_eq!(jitter_bucket(jitter_bucket_upper_ns(i)), i + 1);
        }
    }

    #[test]
    fn bytes_round_trip() {
        let mut s = Status {
            tick: 42,
            commands: 9,
            ..Status::default()
        };
        s.fingers[2].tip_error = 0.25;
        let b = s.to_bytes();
        assert_eq!(Status::from_bytes(&b), s);
        assert_eq!(u64::from_ne_bytes(b[0..8].try_into().unwrap()), 42);
        assert_eq!(u64::from_ne_bytes(b[1376..1384].try_into().unwrap()), 9);
    }

    #[test]
    fn a_hand_code_no_daemon_sends_is_refused() {
        let mut s = Status {
            daemon_state: DaemonState::Running.code(),
            phase: Phase::Hold.code(),
            fault: FaultCode::None.code(),
            grasp: GraspState::Unknown.code(),
            ..Status::default()
        };
        s.goal.state = GoalState::None.code();
        s.goal.reason = ReasonCode::None.code();
        for f in &mut s.fingers {
            f.state = FingerPhase::Free.code();
        }
        assert_eq!(s.check(), Ok(()));
        s.hand = hand::CHAINS;
        assert_eq!(s.check(), Ok(()));
        s.hand = 2;
        assert_eq!(s.check().map_err(|e| e.kind), Err("hand"));
    }

    #[test]
    fn zeroed_status_is_refused() {
        assert!(Status::default().check().is_err());
    }
}
