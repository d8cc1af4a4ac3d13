//! Events across a bridge restart, through real bridge processes on
//! loopback (PROTOCOL.md, "Events"): the bridge killed (SIGKILL), more
//! events published by the daemon while it is down than a restarted
//! bridge can replay (its cache, fed from the daemon's event history of 64),
//! the bridge restarted. Counted against the daemon's own sequence (a local
//! client's): the last ones reach the remote subscriber from the restarted
//! bridge's cache, and the ones before them that nothing can replay are
//! reported missing (`missed_events`, `event_holes`), never silently
//! skipped.

use crate::support::{Pki, T, TestBridge, one_at_a_time};
use gaitd_client::{Client, Event, Verdict};
use gaitd_tests::TestDaemon;
use std::collections::BTreeSet;
use std::time::{Duration, Instant};

/// How many events a restarted bridge can replay: its cache keeps the
/// last 64 it has (filled at start from the daemon's own history of 64;
/// PROTOCOL.md, "Events").
const REPLAYABLE: u64 = 64;

/// Sends `n` holds (each publishes one `Hold` event).
fn holds(local: &mut Client, n: usize) {
    for _ in 0..n {
        assert_eq!(local.hold(T).unwrap(), Verdict::Accepted);
    }
}

/// The daemon's sequence numbers so far, as a local client has them.
fn published(local: &mut Client, all: &mut BTreeSet<u64>) -> u64 {
    std::thread::sleep(Duration::from_millis(100));
    all.extend(local.events().unwrap().map(|e| e.seq));
    *all.last().unwrap()
}

fn receive(r: &mut Client, got: &mut Vec<Event>) {
    got.extend(r.events().unwrap());
}

#[test]
fn events_published_across_a_bridge_restart_all_arrive_or_are_reported() {
    let _one = one_at_a_time();
    let pki = Pki::new("gaps");
    let d = TestDaemon::start("remote-gaps");
    let mut local = d.client();
    let mut b = TestBridge::start(&d, &pki, "");
    let mut r = b.client(&pki, "dash");
    let mut all = BTreeSet::new();
    let mut got = Vec::new();
    holds(&mut local, 10);
    let before = published(&mut local, &mut all);
    let t0 = Instant::now();
    while got.last().is_none_or(|e: &Event| e.seq < before) {
        receive(&mut r, &mut got);
        assert!(t0.elapsed() < T, "live events never arrived");
        std::thread::sleep(Duration::from_millis(50));
    }
    let instance = local.daemon_instance();
    b.kill();
    // Published while no bridge forwards them: more than it can replay.
    holds(&mut local, 100);
    let last = published(&mut local, &mut all);
    b.spawn();
    let t1 = Instant::now();
    let has = |got: &[Event], s: u64| got.iter().any(|e| e.instance == instance && e.seq == s);
    while !has(&got, last) || r.missed_events() > 0 && t1.elapsed() < Duration::from_secs(5) {
        receive(&mut r, &mut got);
        if t1.elapsed() > Duration::from_secs(20) {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let first = got.first().map_or(1, |e| e.seq);
    let want: Vec<u64> = all.range(first..=last).copied().collect();
    let received: BTreeSet<u64> = got
        .iter()
        .filter(|e| e.instance == instance)
        .map(|e| e.seq)
        .collect();
    let lost: Vec<u64> = want
        .iter()
        .filter(|s| !received.contains(s))
        .copied()
        .collect();
    let dupes = got.len() - received.len();
    // The daemon's newest now: the cache the subscriber was sent held
    // nothing newer.
    let newest = published(&mut local, &mut all);
    println!(
        "published {}..={last} ({} events; {newest} by the end), received {} \
         (+{dupes} repeats), missing {:?}, reported missed {} {:?}",
        first,
        want.len(),
        received.len(),
        lost,
        r.missed_events(),
        r.event_holes()
    );
    assert_eq!(dupes, 0, "an event delivered twice");
    // Nothing lost silently: what did not arrive is reported, exactly.
    // (Counted over the events this test published: on a loaded machine
    // the daemon goes on publishing — overruns — and the bridge may drop
    // some of those too, which are reported beside.)
    let holes: u64 = r
        .event_holes()
        .iter()
        .filter(|(i, _, _)| *i == instance)
        .map(|(_, a, b)| {
            (*b).min(last).saturating_sub((*a).max(first)) + u64::from(*a <= last && *b >= first)
        })
        .sum();
    assert_eq!(holes, lost.len() as u64, "{lost:?}\n{:?}", r.event_holes());
    assert!(r.missed_events() >= lost.len() as u64, "{lost:?}");
    // The cache was replayed: the last event published while no bridge
    // ran arrived, and so did the last 40 published then when the cache
    // could still hold them all. (On a loaded machine the daemon goes on
    // publishing — overruns — and the bridge caches those too: its newest
    // is at most `newest`, and 64 back from it may pass `last` − 39.)
    assert!(received.contains(&last), "{last} not received\n{}", b.log());
    if newest <= last + REPLAYABLE - 40 {
        for s in last - 39..=last {
            assert!(received.contains(&s), "{s} not received\n{}", b.log());
        }
    }
    assert!(!lost.is_empty(), "more than the cache was published");
}
