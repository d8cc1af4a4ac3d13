//! The bridge killed (SIGKILL) and started again on the same endpoint: a
//! remote client that stays open gets status again and commands work,
//! without reconnecting by hand.

use crate::support::{Pki, T, TestBridge};
use gaitd_client::{Client, Verdict};
use gaitd_tests::TestDaemon;
use std::time::{Duration, Instant};

/// Waits until `c` has a status newer than tick `after`.
fn status_resumes(c: &mut Client, after: u64, b: &TestBridge) -> u64 {
    let t0 = Instant::now();
    loop {
        if let Ok(s) = c.wait_status(Duration::from_millis(500))
            && s.tick > after
        {
            return s.tick;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(30),
            "no status after the bridge's restart:\n{}",
            b.log()
        );
    }
}

#[test]
fn the_bridge_killed_and_restarted_the_client_reconnects_by_itself() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("restart");
    let d = TestDaemon::start("remote-restart");
    let _local = d.client();
    let mut b = TestBridge::start(&d, &pki, "");
    let mut op = b.client(&pki, "op");
    let tick = op.wait_status(T).unwrap().tick;

    b.kill();
    // Without the bridge the status goes stale and commands fail.
    std::thread::sleep(Duration::from_millis(1500));
    let last = op.latest_status().ok().flatten().map_or(tick, |s| s.tick);
    assert!(
        op.hold(Duration::from_secs(2)).is_err(),
        "a command went through without a bridge"
    );

    b.spawn();
    let t0 = Instant::now();
    let resumed = status_resumes(&mut op, last, &b);
    eprintln!(
        "status resumed {:?} after the bridge's restart (tick {last} -> {resumed})",
        t0.elapsed()
    );
    // A command through the new bridge, on the same client.
    let t0 = Instant::now();
    let verdict = loop {
        match op.hold(T) {
            Ok(v) => break v,
            Err(e) => assert!(t0.elapsed() < Duration::from_secs(20), "{e}"),
        }
    };
    assert_eq!(verdict, Verdict::Accepted);
}
