//! A burst of commands from one operator (PROTOCOL.md, "Commands"): every
//! query gets a reply, those beyond the identity's token bucket are refused
//! `RateLimited` — never `DaemonBusy`, which is for a full queue of
//! commands within their rate limits — and the daemon gets only the
//! allowed ones. A raw Zenoh session with the operator's certificate fires
//! the queries all at once (the client library sends one at a time).

use crate::support::{Pki, T, TestBridge, one_at_a_time};
use gaitd_client::remote::protocol::{self as proto, Refusal, RefusalCode};
use gaitd_client::remote::tls;
use gaitd_client::{Command, RemoteOptions};
use gaitd_tests::TestDaemon;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::Wait;
use zenoh::bytes::Encoding;

const BURST: usize = 150;

#[test]
fn a_burst_beyond_the_rate_limit_is_refused_rate_limited_not_busy() {
    let _one = one_at_a_time();
    let pki = Pki::new("burst");
    let d = TestDaemon::start("remote-burst");
    let mut local = d.client();
    // A slow bucket: 1 command/s after a burst of 10.
    let b = TestBridge::start(
        &d,
        &pki,
        "[rate_limit]\ncommands_per_second = 1.0\nburst = 10\n",
    );
    let before = local.wait_status(T).unwrap().commands;
    let ep = tls::parse_endpoint(&b.endpoint).unwrap();
    let opts = RemoteOptions::new(&b.endpoint, pki.files("op"));
    let session = zenoh::open(tls::client_config(&ep, &opts, T).unwrap())
        .wait()
        .unwrap();
    let key = proto::command_key(&b.prefix, "op", gaitd_client::shm_schema::CommandKind::Hold);
    let encoding = Encoding::from(proto::encoding_of(proto::COMMAND_SCHEMA));
    let replies: Arc<Mutex<Vec<Result<(), RefusalCode>>>> = Arc::default();
    let t0 = Instant::now();
    let mut pending = Vec::new();
    for i in 0..BURST {
        let mut cmd = Command::hold(1);
        cmd.request_id = i as u64 + 1;
        let r = replies.clone();
        let get = session
            .get(&key)
            .payload(cmd.to_bytes().to_vec())
            .encoding(encoding.clone())
            .timeout(T)
            .callback(move |reply| {
                let out = match reply.result() {
                    Ok(_) => Ok(()),
                    Err(e) => Err(Refusal::from_bytes(&e.payload().to_bytes())
                        .map_or(RefusalCode::WrongSize, |r| r.code)),
                };
                r.lock().unwrap().push(out);
            })
            .wait();
        pending.push(get);
    }
    while replies.lock().unwrap().len() < BURST && t0.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let elapsed = t0.elapsed();
    let replies = replies.lock().unwrap().clone();
    let answered = replies.iter().filter(|r| r.is_ok()).count();
    let count = |c: RefusalCode| replies.iter().filter(|r| **r == Err(c)).count();
    let (limited, busy) = (
        count(RefusalCode::RateLimited),
        count(RefusalCode::DaemonBusy),
    );
    println!(
        "{BURST} queries in {elapsed:?}: {} replies, {answered} answered, {limited} RateLimited, \
         {busy} DaemonBusy",
        replies.len()
    );
    assert_eq!(
        replies.len(),
        BURST,
        "every query gets a reply: {replies:?}"
    );
    assert_eq!(busy, 0, "a burst of one identity is rate limited, not busy");
    assert_eq!(answered + limited, BURST, "{replies:?}");
    // The bucket: 10 at once, then 1/s while the burst lasts.
    let allowed = 10 + elapsed.as_secs_f64().ceil() as usize;
    assert!(answered >= 10 && answered <= allowed, "{answered} answered");
    std::thread::sleep(Duration::from_millis(300));
    let after = local.wait_status(T).unwrap().commands;
    assert_eq!(
        after - before,
        answered as u64,
        "the daemon got the answered ones only"
    );
    drop(pending);
}
