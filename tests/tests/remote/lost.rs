//! An operator that dies while its goal runs: the bridge applies
//! `on_client_lost` (cancel, the default) once its session is gone (link
//! closed or lease expired) and the grace period has passed; the goal ends
//! smoothly, as the daemon reports.

use crate::support::{Pki, T, TestBridge};
use gaitd_client::remote::protocol::client_id_for;
use gaitd_client::{GoalState, ReasonCode};
use gaitd_tests::TestDaemon;
use std::process::Stdio;
use std::time::{Duration, Instant};

#[test]
fn a_killed_operators_running_goal_is_canceled_by_the_bridge() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("lost");
    let d = TestDaemon::start("remote-lost");
    let mut local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let op = client_id_for("op");
    // A long turn, so that it still runs when the operator dies.
    let mut gaitctl = b
        .gaitctl(&pki, "op")
        .args([
            "reorient",
            "--axis",
            "0,0,1",
            "--angle-deg",
            "170",
            "--relative",
            "--wait",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    let goal = loop {
        let s = local.wait_status(T).unwrap();
        if s.goal.client_id == op && s.goal.state == GoalState::Executing.code() {
            break s.goal.goal_id;
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "never executed");
    };
    // SIGKILL: no goodbye. Here the kernel closes its socket at once; on
    // another host a lost network would let the client's lease run out.
    gaitctl.kill().unwrap();
    let _ = gaitctl.wait();
    // The daemon's status says how op's goal ended (this local client is
    // not op: its own wait_outcome would not look at op's goal).
    let t1 = Instant::now();
    let ended = loop {
        let s = local.wait_status(T).unwrap();
        let state = s.goal_state().unwrap();
        if s.goal.goal_id == goal && state.is_terminal() {
            break (state, s.goal_reason().unwrap());
        }
        assert!(t1.elapsed() < Duration::from_secs(60), "never ended");
    };
    // (The bridge's log is printed on failure.)
    assert_eq!(ended, (GoalState::Canceled, ReasonCode::CanceledByClient));
    let log = b.log();
    assert!(log.contains("remote client lost"), "{log}");
    assert!(log.contains("client-lost policy applied"), "{log}");
}
