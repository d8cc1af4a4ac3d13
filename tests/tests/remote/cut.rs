//! A dropped link with a command in flight, as Zenoh 1.10.2's TLS links do
//! now and then (bridge/PROTOCOL.md, "Known issue"): a TCP forwarder
//! between the client and the bridge, armed by the test, lets the client's
//! next query reach the bridge, throws the bridge's reply away and closes
//! the connection. The client sends the command again on the new link, the
//! bridge answers it as before, and the daemon gets it once.

use crate::support::{Pki, T, TestBridge, free_port};
use gaitd_client::{Client, ConnectOptions, Verdict};
use gaitd_tests::TestDaemon;
use std::io::{Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// Bytes from the client that are more than a keep-alive: a query.
const QUERY_BYTES: usize = 150;

/// How long the client must have sent nothing but keep-alives before the
/// cutter arms: a session still declaring its subscriptions would otherwise
/// have its declaration cut instead of the command.
const QUIET: Duration = Duration::from_millis(500);

/// The forwarder: listens on `port`, connects each client to `to` (also
/// used by the Python client's test, `python.rs`).
pub struct Cutter {
    /// Where clients connect (127.0.0.1).
    pub port: u16,
    armed: Arc<AtomicBool>,
    /// Messages from clients longer than a keep-alive, so far.
    queries: Arc<AtomicU64>,
    /// Links cut so far.
    pub cuts: Arc<AtomicU64>,
}

impl Cutter {
    /// Forwards to `to` (`HOST:PORT`) from a free port.
    pub fn start(to: String) -> Self {
        let port = free_port();
        let listener = TcpListener::bind(("127.0.0.1", port)).unwrap();
        let (armed, queries, cuts) = (
            Arc::new(AtomicBool::new(false)),
            Arc::new(AtomicU64::new(0)),
            Arc::new(AtomicU64::new(0)),
        );
        let counters = Counters {
            armed: armed.clone(),
            queries: queries.clone(),
            cuts: cuts.clone(),
        };
        std::thread::spawn(move || {
            for client in listener.incoming().map_while(Result::ok) {
                let Ok(bridge) = TcpStream::connect(&to) else {
                    continue;
                };
                link(client, bridge, counters.clone());
            }
        });
        Self {
            port,
            armed,
            queries,
            cuts,
        }
    }

    /// The next query's reply is lost with its link. Waits first until the
    /// clients have sent no query for `QUIET` (at most `T`), so that the
    /// query cut is the caller's next command.
    pub fn arm(&self) {
        let start = std::time::Instant::now();
        let mut seen = self.queries.load(Ordering::Acquire);
        let mut since = std::time::Instant::now();
        while since.elapsed() < QUIET && start.elapsed() < T {
            std::thread::sleep(Duration::from_millis(20));
            let now = self.queries.load(Ordering::Acquire);
            if now != seen {
                (seen, since) = (now, std::time::Instant::now());
            }
        }
        self.armed.store(true, Ordering::Release);
    }
}

/// What the forwarder's links share with the test.
#[derive(Clone)]
struct Counters {
    armed: Arc<AtomicBool>,
    queries: Arc<AtomicU64>,
    cuts: Arc<AtomicU64>,
}

fn link(client: TcpStream, bridge: TcpStream, counters: Counters) {
    let Counters {
        armed,
        queries,
        cuts,
    } = counters;
    let cut = Arc::new(AtomicBool::new(false));
    let (mut c_rx, mut b_tx) = (client.try_clone().unwrap(), bridge.try_clone().unwrap());
    let (mut b_rx, mut c_tx) = (bridge, client);
    let up = cut.clone();
    // Client → bridge: on a query while armed, let it through, then cut
    // once the bridge has had time to answer.
    std::thread::spawn(move || {
        let mut buf = [0u8; 16384];
        while let Ok(n) = c_rx.read(&mut buf) {
            if n == 0 || b_tx.write_all(&buf[..n]).is_err() {
                break;
            }
            if n < QUERY_BYTES {
                continue;
            }
            queries.fetch_add(1, Ordering::AcqRel);
            if armed.swap(false, Ordering::AcqRel) {
                up.store(true, Ordering::Release);
                std::thread::sleep(Duration::from_millis(300));
                cuts.fetch_add(1, Ordering::AcqRel);
                let _ = c_rx.shutdown(Shutdown::Both);
                let _ = b_tx.shutdown(Shutdown::Both);
                break;
            }
        }
    });
    // Bridge → client: nothing passes once the cut has begun.
    std::thread::spawn(move || {
        let mut buf = [0u8; 16384];
        while let Ok(n) = b_rx.read(&mut buf) {
            if n == 0 {
                break;
            }
            if !cut.load(Ordering::Acquire) && c_tx.write_all(&buf[..n]).is_err() {
                break;
            }
        }
    });
}

#[test]
fn a_command_whose_link_drops_before_the_reply_is_answered_once_on_the_next_link() {
    let _one = crate::support::one_at_a_time();
    let pki = Pki::new("cut");
    let d = TestDaemon::start("remote-cut");
    let mut local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    let to = b.tls_endpoint.trim_start_matches("tls/").to_owned();
    let cutter = Cutter::start(to);
    let mut op = Client::connect(
        ConnectOptions::remote(format!("tls/127.0.0.1:{}", cutter.port), pki.files("op"))
            .prefix(&b.prefix)
            .timeout(T),
    )
    .unwrap_or_else(|e| panic!("connect through the cutter: {e}"));
    let commands = |local: &mut Client| local.wait_status(T).unwrap().commands;
    let before = commands(&mut local);
    cutter.arm();
    let verdict = op.hold(Duration::from_secs(30));
    assert_eq!(
        cutter.cuts.load(Ordering::Acquire),
        1,
        "the link was not cut"
    );
    assert_eq!(verdict.unwrap(), Verdict::Accepted);
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        commands(&mut local),
        before + 1,
        "the daemon got the command twice (or never)"
    );
    assert!(b.log().contains("request sent again"), "{}", b.log());
}
