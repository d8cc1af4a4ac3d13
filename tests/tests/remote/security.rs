//! Who may do what: a certificate from another CA, or none, is refused at
//! the TLS session, an identity the bridge does not know sees nothing, a monitor
//! cannot command (and the daemon never sees the attempt), and bad bytes
//! from an operator are rejected with a reason before the daemon.

use crate::support::{Pki, T, TestBridge};
use gaitd_client::remote::protocol::{COMMAND_SCHEMA, RefusalCode, client_id_for};
use gaitd_client::remote::{RawReply, RemoteError};
use gaitd_client::{Client, Error, GoalSpec, ReasonCode, Verdict};
use gaitd_tests::TestDaemon;
use shm_schema::{Command, Status};
use std::time::{Duration, Instant};

/// The daemon's own view: its command counters (read over iceoryx2, not
/// through the bridge) and whether any event names `client_id`.
fn daemon_counts(local: &mut Client) -> (u64, u64) {
    let s: Status = local.wait_status(T).expect("local status");
    (s.commands, s.rejected)
}

fn saw_client(local: &mut Client, client_id: u64) -> bool {
    let mut seen = false;
    while let Some(e) = local.next_event(Duration::from_millis(100)).unwrap() {
        seen |= e.client_id == client_id;
    }
    seen
}

#[test]
fn certificates_of_another_ca_and_unknown_identities_are_refused() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("certs");
    let d = TestDaemon::start("remote-certs");
    let b = TestBridge::start(&d, &pki, "");
    let short = Duration::from_secs(3);

    // `op` by name, but signed by another CA: no session at all.
    let e = Client::connect(b.options_with(pki.rogue()).timeout(short))
        .expect_err("a certificate of another CA was accepted");
    let text = e.to_string();
    assert!(
        matches!(
            e,
            Error::Remote(
                RemoteError::Handshake { .. }
                    | RemoteError::NoSession { .. }
                    | RemoteError::NoBridge { .. }
            )
        ),
        "{text}"
    );
    assert!(!text.contains("panicked"), "{text}");

    // Signed by our CA but without an [[identity]] entry: default deny,
    // it sees no bridge (not even its liveliness token).
    let e = Client::connect(b.options(&pki, "stranger").timeout(short))
        .expect_err("an unknown identity was let in");
    assert!(
        matches!(e, Error::Remote(RemoteError::NoBridge { .. })),
        "{e}"
    );
    assert!(e.to_string().contains("[[identity]]"), "{e}");

    // No client certificate at all (a bare Zenoh session that trusts our
    // CA but presents nothing): the bridge's TLS listener demands one, so
    // no session opens.
    let json = serde_json::json!({
        "mode": "client",
        "connect": { "endpoints": [&b.endpoint], "timeout_ms": 3000, "exit_on_failure": true },
        "listen": { "endpoints": [] },
        "scouting": { "multicast": { "enabled": false }, "gossip": { "enabled": false } },
        "transport": { "link": { "protocols": ["quic"], "tls": {
            "root_ca_certificate": pki.dir.join("ca.pem").display().to_string(),
            "verify_name_on_connect": true,
        } } },
    });
    let config = zenoh::Config::from_json5(&json.to_string()).unwrap();
    assert!(
        zenoh::Wait::wait(zenoh::open(config)).is_err(),
        "a session without a client certificate was opened"
    );

    // The bridge is unharmed: its operator still connects.
    let mut op = b.client(&pki, "op");
    assert_eq!(op.hold(T).unwrap(), Verdict::Accepted);
}

#[test]
fn a_monitor_cannot_command_and_the_daemon_never_sees_it() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("monitor");
    let d = TestDaemon::start("remote-monitor");
    let mut local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let mut dash = b.client(&pki, "dash");
    // A monitor reads the status.
    let s = dash.wait_status(T).unwrap();
    assert!(s.tick > 0);
    saw_client(&mut local, 0);
    let before = daemon_counts(&mut local);

    // Access control drops a monitor's commands: nothing answers, so each
    // attempt waits out its (short) timeout.
    let nope = Duration::from_secs(2);
    let goal = GoalSpec::turn([0.0, 0.0, 1.0], 1.0).unwrap();
    let e = dash
        .reorient(&goal, nope)
        .expect_err("a monitor's goal got through");
    assert!(
        matches!(
            e,
            Error::Remote(RemoteError::NoAnswer { .. } | RemoteError::Refused(_))
        ),
        "{e}"
    );
    assert!(dash.hold(nope).is_err());
    assert!(dash.cancel(None, nope).is_err());
    // Raw bytes on the command key, with a forged client id: dropped too.
    let mut cmd = Command::from_bytes(&[0; Command::SIZE]);
    cmd.kind = 3;
    cmd.client_id = client_id_for("op");
    let r = dash
        .send_raw("hold", &cmd.to_bytes(), COMMAND_SCHEMA, nope)
        .unwrap();
    assert!(
        matches!(r, RawReply::NoReply)
            || matches!(&r, RawReply::Refused(x) if x.code == RefusalCode::NotOperator),
        "{r:?}"
    );

    // The daemon's own counters and events: nothing arrived.
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        daemon_counts(&mut local),
        before,
        "the daemon saw a command"
    );
    assert!(!saw_client(&mut local, client_id_for("dash")));
    assert!(!saw_client(&mut local, client_id_for("op")));
}

/// A Hold command's bytes (kind 3 at offset 0).
fn hold_bytes() -> [u8; Command::SIZE] {
    let mut cmd = Command::from_bytes(&[0; Command::SIZE]);
    cmd.kind = 3;
    cmd.to_bytes()
}

fn refused(r: RawReply, code: RefusalCode) -> String {
    match r {
        RawReply::Refused(x) if x.code == code => x.message,
        other => panic!("expected a {code:?} refusal, got {other:?}"),
    }
}

#[test]
fn bad_bytes_are_rejected_with_a_reason_and_the_daemon_is_unaffected() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("bytes");
    let d = TestDaemon::start("remote-bytes");
    let mut local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let mut op = b.client(&pki, "op");
    let before = daemon_counts(&mut local);
    let instance = local.daemon_instance();

    // Too short, too long.
    let m = refused(
        op.send_raw("hold", &[1, 2, 3], COMMAND_SCHEMA, T).unwrap(),
        RefusalCode::WrongSize,
    );
    assert!(m.contains("3 bytes") && m.contains("144"), "{m}");
    let long = [0u8; Command::SIZE + 8];
    refused(
        op.send_raw("hold", &long, COMMAND_SCHEMA, T).unwrap(),
        RefusalCode::WrongSize,
    );
    // Another schema version.
    let m = refused(
        op.send_raw("hold", &hold_bytes(), "gaitd::Command.v1", T)
            .unwrap(),
        RefusalCode::WrongSchema,
    );
    assert!(m.contains("gaitd::Command.v1"), "{m}");
    // A hold sent to the reorient key; a key that names no command.
    refused(
        op.send_raw("reorient", &hold_bytes(), COMMAND_SCHEMA, T)
            .unwrap(),
        RefusalCode::WrongKey,
    );
    refused(
        op.send_raw("selfdestruct", &hold_bytes(), COMMAND_SCHEMA, T)
            .unwrap(),
        RefusalCode::WrongKey,
    );
    // The right size and key, but a reserved field set: the daemon's own
    // reason, answered by the bridge.
    let mut bad = hold_bytes();
    bad[68] = 1;
    match op.send_raw("hold", &bad, COMMAND_SCHEMA, T).unwrap() {
        RawReply::Answer(a) => assert_eq!(
            a.verdict().unwrap(),
            Verdict::Rejected(ReasonCode::NonZeroReserved)
        ),
        other => panic!("{other:?}"),
    }

    // None of it reached the daemon, which runs on as before.
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        daemon_counts(&mut local),
        before,
        "bad bytes reached the daemon"
    );
    assert!(!saw_client(&mut local, client_id_for("op")));
    assert_eq!(local.daemon_instance(), instance);
    let t0 = Instant::now();
    let s = local.wait_status(T).unwrap();
    assert_eq!(s.fault, 0, "the daemon faulted");
    assert!(t0.elapsed() < T);
    // And good bytes after the bad ones work.
    match op
        .send_raw("hold", &hold_bytes(), COMMAND_SCHEMA, T)
        .unwrap()
    {
        RawReply::Answer(a) => assert_eq!(a.verdict().unwrap(), Verdict::Accepted),
        other => panic!("{other:?}"),
    }
    assert_eq!(daemon_counts(&mut local).0, before.0 + 1);
}

#[test]
fn a_request_sent_again_gets_the_same_answer_and_reaches_the_daemon_once() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("again");
    let d = TestDaemon::start("remote-again");
    let mut local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let mut op = b.client(&pki, "op");
    let (before, _) = daemon_counts(&mut local);
    // As a client sends it again after a dropped link: same request id.
    let mut send = |request_id: u64| {
        let mut cmd = Command::from_bytes(&hold_bytes());
        cmd.request_id = request_id;
        match op
            .send_raw("hold", &cmd.to_bytes(), COMMAND_SCHEMA, T)
            .unwrap()
        {
            RawReply::Answer(a) => a,
            other => panic!("{other:?}"),
        }
    };
    let (first, again) = (send(77), send(77));
    assert_eq!(first.verdict().unwrap(), Verdict::Accepted);
    assert_eq!(first.request_id, 77);
    assert_eq!(again, first);
    // Another request id is another command.
    assert_eq!(send(78).request_id, 78);
    std::thread::sleep(Duration::from_millis(300));
    let (after, _) = daemon_counts(&mut local);
    assert_eq!(after, before + 2, "the daemon got the repeated request");
    assert!(b.log().contains("request sent again"), "{}", b.log());
}
