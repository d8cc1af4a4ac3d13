//! Faults around the daemon (SPEC §12): clients that die, a daemon killed
//! with SIGKILL and restarted over its stale shared memory, SIGTERM.

use gaitd_client::{DaemonState, EventKind, Verdict};
use gaitd_tests::TestDaemon;
use std::time::{Duration, Instant};

const T: Duration = Duration::from_secs(5);

#[test]
fn a_client_killed_mid_session_does_not_disturb_the_daemon() {
    let d = TestDaemon::start("client-killed");
    let mut c = d.client();
    // Another client process sends a long goal and waits for it, then is
    // killed hard while the goal runs.
    let mut other = d
        .gaitctl()
        .args([
            "reorient",
            "--axis",
            "0,0,1",
            "--angle-deg",
            "200",
            "--relative",
            "--wait",
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while c.wait_status(T).unwrap().clients < 2 {
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "the other client never showed up"
        );
    }
    let t0 = Instant::now();
    while c.wait_status(T).unwrap().goal.state != shm_schema::GoalState::Executing.code() {
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "the goal never started"
        );
    }
    let before = c.wait_status(T).unwrap();
    other.kill().unwrap();
    other.wait().unwrap();
    // Housekeeping finds and cleans the dead node (about once a second)
    // and the loop reports it as an event; status never stopped.
    let t0 = Instant::now();
    let cleaned = loop {
        let e = c.next_event(Duration::from_millis(200)).unwrap();
        if let Some(e) = e
            && e.kind() == Ok(EventKind::ClientsCleaned)
        {
            break e;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "dead client never cleaned up"
        );
    };
    assert!(cleaned.count >= 1);
    let after = c.wait_status(T).unwrap();
    assert!(after.tick > before.tick);
    assert_eq!(after.instance, before.instance);
    assert_eq!(after.clients, 1, "only this client is left");
    // The dead client's goal goes on to the end.
    let t0 = Instant::now();
    loop {
        let s = c.wait_status(T).unwrap();
        if s.goal.state == shm_schema::GoalState::Succeeded.code() {
            break;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "the goal never finished"
        );
    }
    assert_eq!(c.hold(T).unwrap(), Verdict::Accepted);
}

#[test]
fn daemon_killed_and_restarted_clients_reconnect() {
    let mut d = TestDaemon::start("sigkill");
    let mut c = d.client();
    let old = c.wait_status(T).unwrap().instance;
    d.signal(libc::SIGKILL);
    d.wait(T).expect("killed");
    // The client notices that nothing is published any more.
    std::thread::sleep(Duration::from_millis(1200));
    assert!(!c.daemon_alive().unwrap());
    // The new daemon starts over the dead one's shared memory (still held
    // open by this client) and must come up cleanly.
    d.spawn();
    assert_eq!(c.hold(T).unwrap(), Verdict::Accepted, "log:\n{}", d.log());
    let s = c.wait_status(T).unwrap();
    assert_ne!(s.instance, old, "a new daemon instance");
    assert_eq!(c.reconnects(), 1, "the client reconnected once");
    // The services were still held by this client: the new daemon adopted
    // them (iceoryx2 removed the dead daemon's node and ports when the new
    // node was created).
    let log = d.log();
    assert!(
        log.contains("adopted a service left by an earlier daemon"),
        "{log}"
    );
    assert_eq!(s.daemon_state(), Ok(DaemonState::Running));
    // A fresh client connects too, and events flow from the new instance.
    let mut fresh = d.client();
    assert_eq!(fresh.wait_status(T).unwrap().instance, s.instance);
    assert_eq!(fresh.hold(T).unwrap(), Verdict::Accepted);
    assert!(d.running());
}

#[test]
fn sigterm_holds_publishes_a_final_status_and_exits_cleanly() {
    let mut d = TestDaemon::start("sigterm");
    let mut c = d.client();
    let running = c.wait_status(T).unwrap();
    d.signal(libc::SIGTERM);
    let status = d.wait(T).expect("exits after SIGTERM");
    assert!(status.success(), "exit status {status:?}\n{}", d.log());
    // The final status and the stopping event reached the client.
    let t0 = Instant::now();
    let last = loop {
        let s = c.latest_status().unwrap().unwrap();
        if s.daemon_state() == Ok(DaemonState::Stopped) {
            break s;
        }
        assert!(t0.elapsed() < T, "no final status");
        std::thread::sleep(Duration::from_millis(10));
    };
    assert_eq!(last.instance, running.instance);
    assert!(last.tick >= running.tick);
    let events: Vec<_> = c.events().unwrap().collect();
    assert!(
        events
            .iter()
            .any(|e| e.kind() == Ok(EventKind::DaemonStopping)),
        "{events:?}"
    );
    let log = d.log();
    assert!(log.contains("stopped: final status published"), "{log}");
}
