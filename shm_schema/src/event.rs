//! daemon → clients: [`Event`]s, published with history.

use crate::codes::{EventKind, FaultCode, GoalState, ReasonCode, UnknownCode};
use iceoryx2::prelude::ZeroCopySend;

/// Something that happened: goal transitions, gait events, faults, overruns
/// (SPEC §7.3). Fields a kind does not use are 0 (`finger`: `NO_FINGER`).
///
/// Type name `gaitd::Event.v8`, 88 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Event.v8")]
pub struct Event {
    /// Sequence number within this daemon instance, from 1, no gaps.
    pub seq: u64,
    /// Tick at which it happened.
    pub tick: u64,
    /// Time of that tick \[ns\], as [`Status::time_ns`](crate::Status):
    /// CLOCK_MONOTONIC, or in lockstep the plant's time.
    pub time_ns: u64,
    /// Daemon instance id.
    pub instance: u64,
    /// [`EventKind`] code.
    pub kind: u32,
    /// Finger index 0–2, or [`NO_FINGER`](crate::NO_FINGER).
    pub finger: u32,
    /// [`GoalState`] code (goal transitions; 0 otherwise).
    pub state: u32,
    /// [`ReasonCode`] code.
    pub reason: u32,
    /// Goal concerned, 0 if none.
    pub goal_id: u64,
    /// That goal's client.
    pub client_id: u64,
    /// [`FaultCode`] code (Fault: the fault; NearLimit: the invariant, as
    /// the fault it would become).
    pub fault: u32,
    /// Padding, 0.
    pub reserved: u32,
    /// Kind-specific count (Overrun: missed periods; ClientsCleaned: nodes;
    /// Drift, NearLimit: replans of the goal so far; Substitution: the
    /// finger that took over, as a bit (bit k for finger k); Rewind: the
    /// relocated fingers as bits).
    pub count: u64,
    /// Kind-specific value (GoalTransition: remaining angle \[rad\]).
    pub value: f64,
}

const _: () = assert!(core::mem::size_of::<Event>() == 88);
const _: () = assert!(core::mem::align_of::<Event>() == 8);

impl Event {
    /// Size of the payload in bytes.
    pub const SIZE: usize = 88;

    /// The payload that `bytes` encode (e.g. as received from a bridge).
    /// Every bit pattern is a `Event` (integers and floats only, no implicit
    /// padding); check the codes with `check` before use.
    pub fn from_bytes(bytes: &[u8; Self::SIZE]) -> Self {
        // SAFETY: repr(C), exactly SIZE bytes of integers and floats without
        // implicit padding: any bytes are a valid value; read_unaligned
        // accepts the byte array's alignment of 1.
        unsafe { core::ptr::read_unaligned(bytes.as_ptr().cast::<Event>()) }
    }

    /// The payload's bytes as they travel (native endianness, as in shared memory).
    pub fn to_bytes(&self) -> [u8; Self::SIZE] {
        // SAFETY: same layout facts as in `from_bytes`; no padding means no
        // uninitialised bytes are read.
        unsafe { core::mem::transmute::<Event, [u8; Self::SIZE]>(*self) }
    }
}

impl Event {
    /// An event of `kind` with every other field 0 / none.
    pub const fn new(kind: EventKind) -> Self {
        Self {
            seq: 0,
            tick: 0,
            time_ns: 0,
            instance: 0,
            kind: kind.code(),
            finger: crate::NO_FINGER,
            state: 0,
            reason: 0,
            goal_id: 0,
            client_id: 0,
            fault: 0,
            reserved: 0,
            count: 0,
            value: 0.0,
        }
    }

    /// Checks every code (a reader never trusts foreign bytes).
    pub fn check(&self) -> Result<(), UnknownCode> {
        EventKind::try_from(self.kind)?;
        GoalState::try_from(self.state)?;
        ReasonCode::try_from(self.reason)?;
        FaultCode::try_from(self.fault)?;
        if self.finger != crate::NO_FINGER && self.finger as usize >= crate::FINGERS {
            return Err(UnknownCode {
                kind: "finger",
                code: self.finger,
            });
        }
        Ok(())
    }

    /// Decoded [`EventKind`].
    pub fn kind(&self) -> Result<EventKind, UnknownCode> {
        EventKind::try_from(self.kind)
    }

    /// Decoded [`GoalState`].
    pub fn state(&self) -> Result<GoalState, UnknownCode> {
        GoalState::try_from(self.state)
    }

    /// Decoded [`ReasonCode`].
    pub fn reason(&self) -> Result<ReasonCode, UnknownCode> {
        ReasonCode::try_from(self.reason)
    }

    /// Decoded [`FaultCode`].
    pub fn fault(&self) -> Result<FaultCode, UnknownCode> {
        FaultCode::try_from(self.fault)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_event_checks() {
        let e = Event::new(EventKind::Overrun);
        assert_eq!(e.check(), Ok(()));
        assert_eq!(e.kind(), Ok(EventKind::Overrun));
        assert!(Event { finger: 3, ..e }.check().is_err());
        assert!(Event { kind: 0, ..e }.check().is_err());
        assert!(Event { state: 77, ..e }.check().is_err());
    }

    #[test]
    fn bytes_round_trip() {
        let e = Event {
            seq: 7,
            value: 1.5,
            ..Event::new(EventKind::GoalTransition)
        };
        let b = e.to_bytes();
        assert_eq!(Event::from_bytes(&b), e);
        assert_eq!(u64::from_ne_bytes(b[0..8].try_into().unwrap()), 7);
        assert_eq!(f64::from_ne_bytes(b[80..88].try_into().unwrap()), 1.5);
    }
}
