//! `gaitctl --remote` beyond goals: `watch` and `reset` through the bridge,
//! a monitor's `reset` refused, and the mistakes a user makes with the TLS
//! flags, each a one-line message and exit code 2 (never a backtrace).

use crate::support::{Pki, TestBridge, run};
use gaitd_tests::{TestDaemon, workspace_bin};
use std::process::Command;

#[test]
fn gaitctl_remote_watch_and_reset_and_the_tls_flags_mistakes() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("cli-more");
    let d = TestDaemon::start("remote-cli-more");
    let _local = d.client();
    let b = TestBridge::start(&d, &pki, "");

    // watch without a terminal: the daemon's line, then stops after 3 frames.
    let (rc, out, err) = run(b.gaitctl(&pki, "dash").args(["watch", "--frames", "3"]));
    assert_eq!(rc, Some(0), "{out}{err}");
    let first = out.lines().next().unwrap_or_default();
    assert!(
        first.starts_with("gaitd ") && first.contains("Running"),
        "{out}"
    );

    // reset: the daemon's own answer (it is not faulted).
    let (rc, out, err) = run(b.gaitctl(&pki, "op").arg("reset"));
    assert_eq!(
        (rc, out.trim()),
        (Some(1), "reset: rejected (NotFaulted)"),
        "{err}"
    );
    // A monitor's reset never reaches the daemon: an error, not a verdict.
    let (rc, out, err) = run(b.gaitctl_waiting(&pki, "dash", 2).arg("reset"));
    assert_eq!(rc, Some(2), "{out}{err}");
    assert!(out.is_empty(), "{out}");
    assert!(
        err.starts_with("gaitctl: ") && err.lines().count() == 1,
        "{err}"
    );

    let gaitctl = || {
        let mut c = Command::new(workspace_bin("gaitctl"));
        c.args(["--remote", &b.endpoint, "--timeout", "2"]);
        c
    };
    let one_line = |rc: Option<i32>, err: &str, needle: &str| {
        assert_eq!(rc, Some(2), "{err}");
        assert!(err.lines().count() == 1 && err.contains(needle), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    };
    // No certificates at all.
    let (rc, _, err) = run(gaitctl().arg("status"));
    one_line(
        rc,
        &err,
        "--remote needs --pki DIR --identity NAME, or --ca, --cert and --key",
    );
    // --pki without --identity.
    let (rc, _, err) = run(gaitctl().arg("--pki").arg(&pki.dir).arg("status"));
    one_line(rc, &err, "--remote needs --pki DIR --identity NAME");
    // An identity whose files do not exist: the missing file is named.
    let (rc, _, err) =
        run(gaitctl()
            .arg("--pki")
            .arg(&pki.dir)
            .args(["--identity", "nobody", "status"]));
    one_line(
        rc,
        &err,
        &format!("{}", pki.dir.join("nobody.pem").display()),
    );
    // A key that is not PEM.
    let junk = pki.dir.join("junk.key");
    std::fs::write(&junk, "not a key").unwrap();
    let (rc, _, err) = run(gaitctl()
        .arg("--pki")
        .arg(&pki.dir)
        .args(["--identity", "op", "--key"])
        .arg(&junk)
        .arg("status"));
    one_line(rc, &err, "not a PEM file");
    // A protocol the bridge does not speak.
    let (rc, _, err) = run(Command::new(workspace_bin("gaitctl"))
        .args(["--remote", "tcp/127.0.0.1:7447", "--pki"])
        .arg(&pki.dir)
        .args(["--identity", "op", "status"]));
    one_line(rc, &err, "only accepts quic/ or tls/");
    // A QUIC endpoint where no bridge listens: both causes are named.
    let (rc, _, err) = run(Command::new(workspace_bin("gaitctl"))
        .arg("--remote")
        .arg(format!(
            "quic/127.0.0.1:{}",
            crate::support::free_udp_port()
        ))
        .arg("--pki")
        .arg(&pki.dir)
        .args(["--identity", "op", "--timeout", "1", "status"]));
    one_line(rc, &err, "is gaitd-bridge running there");
}
