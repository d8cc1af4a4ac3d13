//! daemon → client: [`Answer`] (`answers` service), one per command.

use crate::codes::{AnswerCode, CommandKind, ReasonCode, UnknownCode};
use iceoryx2::prelude::ZeroCopySend;

/// The daemon's immediate answer to one [`Command`](crate::Command): accepted,
/// or rejected with a reason. The goal's later progress is in
/// [`Status`](crate::Status) and [`Event`](crate::Event)s.
///
/// Type name `gaitd::Answer.v8`, 56 bytes, alignment 8.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("gaitd::Answer.v8")]
pub struct Answer {
    /// Echo of the command's `client_id`.
    pub client_id: u64,
    /// Echo of the command's `request_id`.
    pub request_id: u64,
    /// Echo of the command's `goal_id`.
    pub goal_id: u64,
    /// Echo of the command's `kind` (as received, even if invalid).
    pub command: u32,
    /// [`AnswerCode`] code.
    pub code: u32,
    /// [`ReasonCode`] code (0 when accepted).
    pub reason: u32,
    /// Padding, 0.
    pub reserved: u32,
    /// Daemon tick at which the command was handled.
    pub tick: u64,
    /// Daemon instance id (same as in [`Status::instance`](crate::Status::instance)).
    pub instance: u64,
}

const _: () = assert!(core::mem::size_of::<Answer>() == 56);
const _: () = assert!(core::mem::align_of::<Answer>() == 8);

impl Answer {
    /// Size of the payload in bytes.
    pub const SIZE: usize = 56;

    /// The payload that `bytes` encode (e.g. as received from a bridge).
    /// Every bit pattern is a `Answer` (integers and floats only, no implicit
    /// padding); check the codes with `check` before use.
    pub fn from_bytes(bytes: &[u8; Self::SIZE]) -> Self {
        // SAFETY: repr(C), exactly SIZE bytes of integers and floats without
        // implicit padding: any bytes are a valid value; read_unaligned
        // accepts the byte array's alignment of 1.
        unsafe { core::ptr::read_unaligned(bytes.as_ptr().cast::<Answer>()) }
    }

    /// The payload's bytes as they travel (native endianness, as in shared memory).
    pub fn to_bytes(&self) -> [u8; Self::SIZE] {
        // SAFETY: same layout facts as in `from_bytes`; no padding means no
        // uninitialised bytes are read.
        unsafe { core::mem::transmute::<Answer, [u8; Self::SIZE]>(*self) }
    }
}

/// A decoded [`Answer`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The command was accepted.
    Accepted,
    /// The command was rejected for this reason.
    Rejected(ReasonCode),
}

impl Answer {
    /// Decodes the answer's codes.
    pub fn verdict(&self) -> Result<Verdict, UnknownCode> {
        let reason = ReasonCode::try_from(self.reason)?;
        match AnswerCode::try_from(self.code)? {
            AnswerCode::Accepted => Ok(Verdict::Accepted),
            AnswerCode::Rejected => Ok(Verdict::Rejected(reason)),
        }
    }

    /// The echoed command kind, if it was a valid one.
    pub fn command_kind(&self) -> Result<CommandKind, UnknownCode> {
        CommandKind::try_from(self.command)
    }

    /// Builds an answer.
    pub fn new(cmd: &crate::Command, verdict: Verdict, tick: u64, instance: u64) -> Self {
        let (code, reason) = match verdict {
            Verdict::Accepted => (AnswerCode::Accepted, ReasonCode::None),
            Verdict::Rejected(r) => (AnswerCode::Rejected, r),
        };
        Self {
            client_id: cmd.client_id,
            request_id: cmd.request_id,
            goal_id: cmd.goal_id,
            command: cmd.kind,
            code: code.code(),
            reason: reason.code(),
            reserved: 0,
            tick,
            instance,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Command, GoalFrame};

    #[test]
    fn answers_roundtrip() {
        let c = Command::goal(3, 4, GoalFrame::Absolute, [1.0, 0.0, 0.0, 0.0]);
        let a = Answer::new(&c, Verdict::Rejected(ReasonCode::DuplicateGoalId), 10, 99);
        assert_eq!(
            a.verdict(),
            Ok(Verdict::Rejected(ReasonCode::DuplicateGoalId))
        );
        assert_eq!(a.command_kind(), Ok(CommandKind::Goal));
        assert_eq!((a.client_id, a.goal_id, a.tick, a.instance), (3, 4, 10, 99));
        let a = Answer::new(&c, Verdict::Accepted, 1, 1);
        assert_eq!(a.verdict(), Ok(Verdict::Accepted));
        let bad = Answer { code: 0, ..a };
        assert!(bad.verdict().is_err());
    }

    #[test]
    fn bytes_round_trip() {
        let c = Command::goal(3, 4, GoalFrame::Absolute, [1.0, 0.0, 0.0, 0.0]);
        let a = Answer::new(&c, Verdict::Rejected(ReasonCode::DuplicateGoalId), 10, 99);
        let b = a.to_bytes();
        assert_eq!(Answer::from_bytes(&b), a);
        // Offsets as LAYOUT.md documents them (little-endian hosts).
        assert_eq!(u64::from_ne_bytes(b[16..24].try_into().unwrap()), 4);
        assert_eq!(u32::from_ne_bytes(b[32..36].try_into().unwrap()), 12);
    }
}
