//! systemd notifications over a real unix datagram socket (NOTIFY_SOCKET):
//! READY=1 only once the services exist, WATCHDOG=1 while running,
//! STATUS= texts, STOPPING=1 on SIGTERM.

use gaitd_client::Status;
use gaitd_tests::TestDaemon;
use iceoryx2::prelude::*;
use std::os::unix::net::UnixDatagram;
use std::time::{Duration, Instant};

fn recv(sock: &UnixDatagram) -> Option<String> {
    let mut buf = [0u8; 512];
    match sock.recv(&mut buf) {
        Ok(n) => Some(String::from_utf8_lossy(&buf[..n]).into_owned()),
        Err(_) => None,
    }
}

#[test]
fn ready_watchdog_status_and_stopping() {
    let mut d = TestDaemon::new("sd-notify", "[daemon]\nhousekeeping_period_ms = 200\n");
    let path = d.dir.join("notify.sock");
    let sock = UnixDatagram::bind(&path).unwrap();
    sock.set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    d.env("NOTIFY_SOCKET", path.to_str().unwrap());
    d.env("WATCHDOG_USEC", "100000"); // 100 ms: fed every 50 ms
    d.spawn();

    let first = recv(&sock).expect("a message");
    assert_eq!(first, "READY=1", "READY comes first\n{}", d.log());
    // READY means the services exist: they open at once, no retry.
    let (config, _) = d.options().resolve().unwrap();
    let node = NodeBuilder::new()
        .config(&config)
        .create::<ipc::Service>()
        .unwrap();
    let status = node
        .service_builder(&ServiceName::new(&format!("{}/status", d.prefix)).unwrap())
        .publish_subscribe::<Status>()
        .open();
    assert!(status.is_ok(), "{status:?}");

    let t0 = Instant::now();
    let (mut watchdogs, mut statuses) = (0, Vec::new());
    while t0.elapsed() < Duration::from_secs(2) || watchdogs < 5 || statuses.len() < 2 {
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "too few notifications"
        );
        let m = recv(&sock).expect("notifications keep coming");
        if m == "WATCHDOG=1" {
            watchdogs += 1;
        } else if let Some(s) = m.strip_prefix("STATUS=") {
            statuses.push(s.to_owned());
        }
    }
    assert!(
        statuses
            .iter()
            .any(|s| s.contains("tick") && s.contains("compute p99")),
        "{statuses:?}"
    );

    d.signal(libc::SIGTERM);
    let mut stopping = false;
    while let Some(m) = recv(&sock) {
        if m == "STOPPING=1" {
            stopping = true;
            break;
        }
    }
    assert!(stopping, "STOPPING=1 on SIGTERM");
    assert!(d.wait(Duration::from_secs(10)).unwrap().success());
}
