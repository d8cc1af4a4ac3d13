//! The remote protocol of `gaitd-bridge`: Zenoh keys, payload encodings,
//! the bridge's refusals and how an identity becomes a `client_id`.
//!
//! Shared by the bridge and every remote client (the Python package mirrors
//! it in `gaitd/remote.py`); `bridge/PROTOCOL.md` describes it for other
//! languages. Pure: no Zenoh types here.
//!
//! Keys, under a prefix (default `gaitd`, the bridge's `[zenoh] prefix`):
//!
//! | key | what |
//! |---|---|
//! | `P/status` | [`Status`](shm_schema::Status) bytes, downsampled, latest value (dropped, never queued, under congestion) |
//! | `P/events` | [`Event`](shm_schema::Event) bytes, advanced publisher: history for late joiners, miss detection |
//! | `P/cmd/<identity>/<command>` | queryable: [`Command`](shm_schema::Command) bytes in the query, the [`Answer`](shm_schema::Answer) in the reply, a [`Refusal`] as an error reply |
//! | `P/alive/bridge` | liveliness token of the bridge |
//! | `P/alive/daemon` | liveliness token, present while the bridge sees a running gaitd |
//! | `P/clients/<identity>/<zid>` | liveliness token of each remote client session |
//!
//! `<identity>` is the common name of the client's certificate. The bridge's
//! access control lets a session query only its own identity's command keys
//! and declare only its own client token, so the key names an
//! authenticated identity; the bridge derives the `client_id` from it
//! ([`client_id_for`]) and ignores the one in the payload.

use shm_schema::CommandKind;

/// Default key prefix.
pub const DEFAULT_KEY_PREFIX: &str = "gaitd";

/// Zenoh encoding of every payload: `application/octet-stream` with the
/// payload's versioned type name as its schema, e.g.
/// `application/octet-stream;gaitd::Command.v8`.
pub const ENCODING_PREFIX: &str = "application/octet-stream";

/// Schema of a [`Command`](shm_schema::Command) (its iceoryx2 type name).
pub const COMMAND_SCHEMA: &str = "gaitd::Command.v8";
/// Schema of an [`Answer`](shm_schema::Answer).
pub const ANSWER_SCHEMA: &str = "gaitd::Answer.v8";
/// Schema of a [`Status`](shm_schema::Status).
pub const STATUS_SCHEMA: &str = "gaitd::Status.v8";
/// Schema of an [`Event`](shm_schema::Event).
pub const EVENT_SCHEMA: &str = "gaitd::Event.v8";
/// Schema of a [`PlanPath`](shm_schema::PlanPath).
pub const PLAN_SCHEMA: &str = "gaitd::PlanPath.v8";
/// Schema of a [`Refusal`] (an error reply from the bridge).
pub const REFUSAL_SCHEMA: &str = "gaitd-bridge::Refusal.v1";

/// Longest identity (certificate common name) the bridge accepts.
pub const MAX_IDENTITY_LEN: usize = 64;

/// `P/status`.
pub fn status_key(prefix: &str) -> String {
    format!("{prefix}/status")
}

/// `P/events`.
pub fn events_key(prefix: &str) -> String {
    format!("{prefix}/events")
}

/// `P/plan`: each plan's path (the bridge caches the latest).
pub fn plan_key(prefix: &str) -> String {
    format!("{prefix}/plan")
}

/// `P/alive/bridge`.
pub fn bridge_token_key(prefix: &str) -> String {
    format!("{prefix}/alive/bridge")
}

/// `P/alive/daemon`.
pub fn daemon_token_key(prefix: &str) -> String {
    format!("{prefix}/alive/daemon")
}

/// `P/alive/*` (both tokens above).
pub fn alive_keys(prefix: &str) -> String {
    format!("{prefix}/alive/*")
}

/// `P/clients/<identity>/<session>`: a remote client's liveliness token.
pub fn client_token_key(prefix: &str, identity: &str, session: &str) -> String {
    format!("{prefix}/clients/{identity}/{session}")
}

/// How often a client beats: a put on its own token's key
/// ([`client_token_key`]); the bridge counts a session that has been silent
/// for its `client_beat_timeout_ms` (1500 ms by default) as gone
/// (PROTOCOL.md, "Lost clients") \[ms\].
pub const CLIENT_BEAT_MS: u64 = 500;

/// `P/clients/**`: every client token (the bridge watches these).
pub fn client_tokens(prefix: &str) -> String {
    format!("{prefix}/clients/**")
}

/// `P/cmd/<identity>/*`: the command queryable of one identity.
pub fn command_keys(prefix: &str, identity: &str) -> String {
    format!("{prefix}/cmd/{identity}/*")
}

/// The last key chunk of a command: `reorient`, `cancel`, `hold`, `reset`.
pub fn command_name(kind: CommandKind) -> &'static str {
    match kind {
        CommandKind::Goal => "reorient",
        CommandKind::Cancel => "cancel",
        CommandKind::Hold => "hold",
        CommandKind::Reset => "reset",
    }
}

/// The command kind a key chunk names.
pub fn command_from_name(name: &str) -> Option<CommandKind> {
    CommandKind::ALL
        .iter()
        .copied()
        .find(|k| command_name(*k) == name)
}

/// `P/cmd/<identity>/<command>`.
pub fn command_key(prefix: &str, identity: &str, kind: CommandKind) -> String {
    format!("{prefix}/cmd/{identity}/{}", command_name(kind))
}

/// Splits `P/cmd/<identity>/<command>` into its identity and command name.
pub fn parse_command_key<'k>(prefix: &str, key: &'k str) -> Option<(&'k str, &'k str)> {
    let rest = key.strip_prefix(prefix)?.strip_prefix("/cmd/")?;
    let (identity, name) = rest.split_once('/')?;
    (!identity.is_empty() && !name.contains('/')).then_some((identity, name))
}

/// Splits `P/clients/<identity>/<session>` into identity and session.
pub fn parse_client_token<'k>(prefix: &str, key: &'k str) -> Option<(&'k str, &'k str)> {
    let rest = key.strip_prefix(prefix)?.strip_prefix("/clients/")?;
    let (identity, session) = rest.split_once('/')?;
    (!identity.is_empty() && !session.is_empty()).then_some((identity, session))
}

/// Whether `name` can be an identity: 1–64 characters of `[A-Za-z0-9._-]`,
/// not starting with `.` or `-` (it becomes one key chunk and an ACL
/// subject).
pub fn identity_valid(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= MAX_IDENTITY_LEN
        && !name.starts_with(['.', '-'])
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"._-".contains(&b))
}

/// Whether `prefix` can be a key prefix: non-empty chunks of
/// `[A-Za-z0-9._-]` separated by `/`.
pub fn prefix_valid(prefix: &str) -> bool {
    !prefix.is_empty()
        && prefix.len() <= 200
        && prefix.split('/').all(|c| {
            !c.is_empty()
                && c.bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b"._-".contains(&b))
        })
}

/// The `client_id` the bridge gives an identity: FNV-1a (64 bit) of
/// `gaitd-remote/<identity>` with the top bit set (never 0; a local
/// client's random id may have any bits, so the top bit is only a hint).
/// Every session of one identity shares it; goal ids are per client, so a
/// remote client starts its goal ids at a random value.
pub fn client_id_for(identity: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in b"gaitd-remote/".iter().chain(identity.as_bytes()) {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h | 1 << 63
}

/// Why the bridge refused a command: it never reached the daemon, except
/// with [`RefusalCode::DaemonTimeout`], which may have. (Bytes that decode
/// but fail [`Command::validate`](shm_schema::Command::validate) are not
/// refused: they are answered `Rejected` with the daemon's reason code,
/// in an [`Answer`](shm_schema::Answer) with `tick` 0 made by the bridge.)
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum RefusalCode {
    /// The payload is not exactly the size of a `Command` (144 bytes).
    WrongSize = 1,
    /// The payload's encoding is not `application/octet-stream;gaitd::Command.v8` (another schema version).
    WrongSchema = 2,
    /// The command's kind is not the one the key names (e.g. a goal sent to `cancel`), or the key names no command.
    WrongKey = 3,
    /// This identity sent commands faster than the bridge's rate limit.
    RateLimited = 4,
    /// The bridge has no running gaitd behind it.
    NoDaemon = 5,
    /// The daemon's command queue for the bridge is full.
    DaemonBusy = 6,
    /// The daemon did not answer within the bridge's command timeout.
    DaemonTimeout = 7,
    /// This identity may not send commands (a monitor); normally access control drops the query before.
    NotOperator = 8,
}

impl RefusalCode {
    /// Every code.
    pub const ALL: [RefusalCode; 8] = [
        RefusalCode::WrongSize,
        RefusalCode::WrongSchema,
        RefusalCode::WrongKey,
        RefusalCode::RateLimited,
        RefusalCode::NoDaemon,
        RefusalCode::DaemonBusy,
        RefusalCode::DaemonTimeout,
        RefusalCode::NotOperator,
    ];

    /// The code on the wire.
    pub const fn code(self) -> u32 {
        self as u32
    }

    /// The name.
    pub const fn name(self) -> &'static str {
        match self {
            RefusalCode::WrongSize => "WrongSize",
            RefusalCode::WrongSchema => "WrongSchema",
            RefusalCode::WrongKey => "WrongKey",
            RefusalCode::RateLimited => "RateLimited",
            RefusalCode::NoDaemon => "NoDaemon",
            RefusalCode::DaemonBusy => "DaemonBusy",
            RefusalCode::DaemonTimeout => "DaemonTimeout",
            RefusalCode::NotOperator => "NotOperator",
        }
    }
}

impl TryFrom<u32> for RefusalCode {
    type Error = u32;
    fn try_from(v: u32) -> Result<Self, u32> {
        RefusalCode::ALL
            .iter()
            .copied()
            .find(|c| c.code() == v)
            .ok_or(v)
    }
}

impl core::fmt::Display for RefusalCode {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// An error reply of the bridge: a code and a sentence for people.
///
/// Wire form (schema [`REFUSAL_SCHEMA`]): `code: u32` little-endian, then
/// the message as UTF-8.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal {
    /// What went wrong.
    pub code: RefusalCode,
    /// Explanation.
    pub message: String,
}

impl Refusal {
    /// A refusal with a message.
    pub fn new(code: RefusalCode, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }

    /// The bytes of the error reply.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut v = Vec::with_capacity(4 + self.message.len());
        v.extend_from_slice(&self.code.code().to_le_bytes());
        v.extend_from_slice(self.message.as_bytes());
        v
    }

    /// Decodes an error reply; `None` if it is not a refusal.
    pub fn from_bytes(b: &[u8]) -> Option<Self> {
        let code = u32::from_le_bytes(b.get(0..4)?.try_into().ok()?);
        Some(Self {
            code: RefusalCode::try_from(code).ok()?,
            message: String::from_utf8_lossy(&b[4..]).into_owned(),
        })
    }
}

impl core::fmt::Display for Refusal {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} ({})", self.message, self.code)
    }
}

/// The full encoding string of a schema (`application/octet-stream;<schema>`).
pub fn encoding_of(schema: &str) -> String {
    format!("{ENCODING_PREFIX};{schema}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use iceoryx2::prelude::ZeroCopySend;
    use shm_schema::{Answer, Command, Event, Status};

    fn type_name<T: ZeroCopySend>() -> &'static str {
        // SAFETY: the derive returns a compile-time constant.
        unsafe { <T as ZeroCopySend>::type_name() }
    }

    #[test]
    fn schemas_are_the_iceoryx2_type_names() {
        assert_eq!(COMMAND_SCHEMA, type_name::<Command>());
        assert_eq!(ANSWER_SCHEMA, type_name::<Answer>());
        assert_eq!(STATUS_SCHEMA, type_name::<Status>());
        assert_eq!(EVENT_SCHEMA, type_name::<Event>());
        assert_eq!(
            encoding_of(COMMAND_SCHEMA),
            "application/octet-stream;gaitd::Command.v8"
        );
    }

    #[test]
    fn keys_parse_back() {
        let k = command_key("gaitd", "op-1", CommandKind::Goal);
        assert_eq!(k, "gaitd/cmd/op-1/reorient");
        assert_eq!(parse_command_key("gaitd", &k), Some(("op-1", "reorient")));
        assert_eq!(parse_command_key("gaitd", "gaitd/cmd/op-1"), None);
        assert_eq!(parse_command_key("gaitd", "other/cmd/a/b"), None);
        for k in CommandKind::ALL {
            assert_eq!(command_from_name(command_name(*k)), Some(*k));
        }
        assert_eq!(command_from_name("launch"), None);
        let t = client_token_key("a/b", "mon", "zid1");
        assert_eq!(parse_client_token("a/b", &t), Some(("mon", "zid1")));
    }

    #[test]
    fn identities_and_prefixes_are_checked() {
        assert!(identity_valid("operator-1"));
        assert!(identity_valid("dash.board_2"));
        for bad in ["", "a/b", "a*", "$x", "@admin", ".hidden", "-x", "a b", "é"] {
            assert!(!identity_valid(bad), "{bad}");
        }
        assert!(!identity_valid(&"a".repeat(MAX_IDENTITY_LEN + 1)));
        assert!(prefix_valid("gaitd"));
        assert!(prefix_valid("lab/hand-2"));
        for bad in ["", "/x", "x/", "a//b", "a/*", "a/**", "a$"] {
            assert!(!prefix_valid(bad), "{bad}");
        }
    }

    #[test]
    fn client_ids_are_stable_distinct_and_non_zero() {
        let a = client_id_for("operator-1");
        assert_eq!(a, client_id_for("operator-1"));
        assert_ne!(a, client_id_for("operator-2"));
        assert_ne!(a, 0);
        assert_eq!(a >> 63, 1);
        // The documented function (bridge/PROTOCOL.md, gaitd/remote.py).
        assert_eq!(client_id_for(""), 0xffd3_3721_a611_5632);
    }

    #[test]
    fn refusals_round_trip() {
        for code in RefusalCode::ALL {
            let r = Refusal::new(code, "why");
            assert_eq!(Refusal::from_bytes(&r.to_bytes()), Some(r));
        }
        let b = Refusal::new(RefusalCode::RateLimited, "slow down").to_bytes();
        assert_eq!(&b[0..4], &[4, 0, 0, 0]);
        assert_eq!(&b[4..], b"slow down");
        assert_eq!(Refusal::from_bytes(&[1, 0, 0]), None);
        assert_eq!(Refusal::from_bytes(&[99, 0, 0, 0]), None);
    }
}
