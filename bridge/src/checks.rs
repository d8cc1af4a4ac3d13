//! What the bridge checks in a remote command before anything reaches the
//! daemon (pure: bytes in, a verdict out).
//!
//! In order: the key names a known identity that is an operator and a known
//! command; the encoding is `application/octet-stream;gaitd::Command.v5`
//! (the schema version); the payload is exactly 144 bytes; the command's
//! kind is the one the key names; the bytes pass
//! [`Command::validate`](shm_schema::Command::validate). The `client_id` is
//! then replaced by the identity's ([`proto::client_id_for`]): whatever the
//! payload says is ignored.

use crate::config::{Config, Role};
use gaitd_client::remote::protocol::{self as proto, Refusal, RefusalCode};
use shm_schema::{Answer, Command, CommandKind, Verdict};

/// A command that may go to the daemon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Checked {
    /// The identity (from the key, authenticated by access control).
    pub identity_id: u64,
    /// The command with the identity's `client_id`.
    pub command: Command,
    /// The request id the remote client chose (echoed in its answer).
    pub request_id: u64,
}

/// The verdict on one query.
#[derive(Debug, Clone, PartialEq)]
pub enum Check {
    /// Forward to the daemon.
    Forward(Checked),
    /// Answer `Rejected` with the daemon's reason, without the daemon.
    Reject(Answer),
    /// Refuse with a bridge refusal.
    Refuse(Refusal),
}

/// Checks one query: its key, encoding (as a string) and payload.
pub fn check(cfg: &Config, key: &str, encoding: Option<&str>, payload: &[u8]) -> Check {
    let refuse = |code, msg: String| Check::Refuse(Refusal::new(code, msg));
    let prefix = &cfg.zenoh.key_prefix;
    let Some((identity, name)) = proto::parse_command_key(prefix, key) else {
        return refuse(
            RefusalCode::WrongKey,
            format!("`{key}` is not a command key"),
        );
    };
    match cfg.role(identity) {
        Some(Role::Operator) => {}
        Some(Role::Monitor) | None => {
            return refuse(
                RefusalCode::NotOperator,
                format!("identity `{identity}` may not send commands"),
            );
        }
    }
    let Some(kind) = proto::command_from_name(name) else {
        return refuse(
            RefusalCode::WrongKey,
            format!("no command `{name}` (reorient, cancel, hold, reset)"),
        );
    };
    let want = proto::encoding_of(proto::COMMAND_SCHEMA);
    if encoding != Some(want.as_str()) {
        return refuse(
            RefusalCode::WrongSchema,
            format!(
                "encoding `{}`, expected `{want}` (a client of another schema version?)",
                encoding.unwrap_or("none")
            ),
        );
    }
    let Ok(bytes) = <&[u8; Command::SIZE]>::try_from(payload) else {
        return refuse(
            RefusalCode::WrongSize,
            format!(
                "{} bytes, a Command is {} (see LAYOUT.md)",
                payload.len(),
                Command::SIZE
            ),
        );
    };
    let mut cmd = Command::from_bytes(bytes);
    let request_id = cmd.request_id;
    let identity_id = proto::client_id_for(identity);
    cmd.client_id = identity_id;
    if let Ok(k) = CommandKind::try_from(cmd.kind)
        && k != kind
    {
        return refuse(
            RefusalCode::WrongKey,
            format!("a {k:?} command sent to `{name}`"),
        );
    }
    if let Err(reason) = cmd.validate() {
        return Check::Reject(Answer::new(&cmd, Verdict::Rejected(reason), 0, 0));
    }
    Check::Forward(Checked {
        identity_id,
        command: cmd,
        request_id,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_schema::{GoalFrame, ReasonCode};
    use std::path::Path;

    fn cfg() -> Config {
        Config::parse(
            "[[identity]]\nname = \"op\"\nrole = \"operator\"\n\
             [[identity]]\nname = \"dash\"\nrole = \"monitor\"\n",
            Path::new("t.toml"),
        )
        .unwrap()
    }

    fn enc() -> String {
        proto::encoding_of(proto::COMMAND_SCHEMA)
    }

    fn refusal(c: Check) -> RefusalCode {
        match c {
            Check::Refuse(r) => r.code,
            other => panic!("{other:?}"),
        }
    }

    const ID: [f64; 4] = [1.0, 0.0, 0.0, 0.0];

    #[test]
    fn a_good_goal_is_forwarded_with_the_identitys_client_id() {
        let mut c = Command::goal(0xbad, 7, GoalFrame::Absolute, ID);
        c.request_id = 42;
        let got = check(&cfg(), "gaitd/cmd/op/reorient", Some(&enc()), &c.to_bytes());
        let Check::Forward(f) = got else {
            panic!("{got:?}")
        };
        assert_eq!(f.command.client_id, proto::client_id_for("op"));
        assert_eq!(f.identity_id, proto::client_id_for("op"));
        assert_eq!(f.request_id, 42);
        assert_eq!(f.command.goal_id, 7);
    }

    #[test]
    fn bad_bytes_get_their_reason() {
        let cfg = cfg();
        let hold = Command::hold(1).to_bytes();
        let e = enc();
        let k = "gaitd/cmd/op/hold";
        assert_eq!(
            refusal(check(&cfg, k, Some(&e), &hold[..100])),
            RefusalCode::WrongSize
        );
        let mut long = hold.to_vec();
        long.push(0);
        assert_eq!(
            refusal(check(&cfg, k, Some(&e), &long)),
            RefusalCode::WrongSize
        );
        let v1 = "application/octet-stream;gaitd::Command.v1";
        assert_eq!(
            refusal(check(&cfg, k, Some(v1), &hold)),
            RefusalCode::WrongSchema
        );
        assert_eq!(
            refusal(check(&cfg, k, None, &hold)),
            RefusalCode::WrongSchema
        );
        assert_eq!(
            refusal(check(&cfg, "gaitd/cmd/op/cancel", Some(&e), &hold)),
            RefusalCode::WrongKey
        );
        assert_eq!(
            refusal(check(&cfg, "gaitd/cmd/op/launch", Some(&e), &hold)),
            RefusalCode::WrongKey
        );
        assert_eq!(
            refusal(check(&cfg, "gaitd/cmd/dash/hold", Some(&e), &hold)),
            RefusalCode::NotOperator
        );
        assert_eq!(
            refusal(check(&cfg, "gaitd/cmd/nobody/hold", Some(&e), &hold)),
            RefusalCode::NotOperator
        );
        // Bytes that decode but do not validate: the daemon's reason.
        let nan = Command::goal(1, 1, GoalFrame::Absolute, [f64::NAN, 0.0, 0.0, 0.0]);
        match check(&cfg, "gaitd/cmd/op/reorient", Some(&e), &nan.to_bytes()) {
            Check::Reject(a) => {
                assert_eq!(
                    a.verdict(),
                    Ok(Verdict::Rejected(ReasonCode::NonFiniteQuaternion))
                );
                assert_eq!(a.client_id, proto::client_id_for("op"));
                assert_eq!(a.tick, 0);
            }
            other => panic!("{other:?}"),
        }
        let unknown = Command {
            kind: 99,
            ..Command::hold(1)
        };
        match check(&cfg, "gaitd/cmd/op/reorient", Some(&e), &unknown.to_bytes()) {
            Check::Reject(a) => assert_eq!(
                a.verdict(),
                Ok(Verdict::Rejected(ReasonCode::UnknownCommandKind))
            ),
            other => panic!("{other:?}"),
        }
    }

    /// A zero client id in the payload is not an error: the bridge fills it.
    #[test]
    fn the_payloads_client_id_is_never_used() {
        let c = Command::hold(0);
        assert!(matches!(
            check(&cfg(), "gaitd/cmd/op/hold", Some(&enc()), &c.to_bytes()),
            Check::Forward(_)
        ));
    }
}
