//! The planner thread and its lock-free link to the loop (SPEC §7.2).
//!
//! Planning allocates and takes milliseconds, so it runs on its own thread.
//! The loop and the planner share three pre-allocated [`handoff`] rings:
//!
//! ```text
//!  loop ── requests (Copy data) ──▶ planner      plans are built here
//!  loop ◀── replies (Box<Plan>) ─── planner
//!  loop ── retired (Box<Plan>) ───▶ planner      and dropped here
//! ```
//!
//! The loop only moves boxes: nothing is allocated or freed on it. A
//! controller that plans owns a [`PlannerLink`]; the daemon starts the
//! thread with [`spawn`].
//!
//! A request the loop no longer wants (its goal was canceled or preempted)
//! is stopped while it is planned: the loop publishes, with one atomic
//! store, which request it still waits for ([`PlannerLink::want`]); the
//! planner polls it through [`Wanted`] between search expansions.
//!
//! Waking the planner is a futex syscall (plus an inter-processor interrupt
//! on a VM, several µs). By default the link makes it at once; the daemon
//! instead gives it a [`Doorbell`] that the loop only flags and the writer
//! thread, which runs right after every tick anyway, rings — so a flood of
//! goals costs the loop no syscalls, and planning starts a few µs later.

use crate::sys::doorbell::Doorbell;
use crate::sys::handoff::{self, Consumer, Producer};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::Thread;
use std::time::Duration;

/// Computes plans off the real-time thread.
pub trait BackgroundPlanner: Send + 'static {
    /// What the loop asks for (plain data, e.g. start state + goal).
    type Request: Send + 'static;
    /// The plan handed to the loop (may own heap memory).
    type Plan: Send + 'static;
    /// Why there is no plan (plain data: it crosses to the loop as is).
    type Error: Send + 'static;
    /// Plans one request, or says why not; should stop soon once
    /// `wanted` says the loop no longer waits for it.
    fn plan(&mut self, request: &Self::Request, wanted: &Wanted)
    -> Result<Self::Plan, Self::Error>;
    /// Runs once on the planner thread before it takes any request: work
    /// every plan would begin with (default: none). A request that comes
    /// meanwhile waits for it.
    fn prepare(&mut self) {}
    /// Runs on the planner thread whenever it has no request, at least
    /// every 100 ms (default: nothing).
    fn idle(&mut self) {}
}

/// No request is wanted (the loop waits for no plan).
const NONE_WANTED: u64 = u64::MAX;

/// Whether the loop still waits for the request being planned.
#[derive(Debug)]
pub struct Wanted {
    seq: u64,
    wanted: Arc<AtomicU64>,
}

impl Wanted {
    /// Whether the loop still waits for this request (one atomic load).
    pub fn still(&self) -> bool {
        self.wanted.load(Ordering::Acquire) == self.seq
    }
}

/// A planner's answer to request number `seq`.
#[derive(Debug)]
pub struct Reply<P, E> {
    /// Sequence number returned by [`PlannerLink::submit`].
    pub seq: u64,
    /// The plan, or why there is none.
    pub result: Result<Box<P>, E>,
}

/// The loop's end of the planner link. Every method is wait-free and
/// allocation-free.
pub struct PlannerLink<Req, P, E> {
    requests: Producer<(u64, Req)>,
    wanted: Arc<AtomicU64>,
    replies: Consumer<Reply<P, E>>,
    retired: Producer<Box<P>>,
    planner: Thread,
    doorbell: Option<Arc<Doorbell>>,
    next_seq: u64,
}

impl<Req, P, E> std::fmt::Debug for PlannerLink<Req, P, E> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlannerLink")
            .field("next_seq", &self.next_seq)
            .finish()
    }
}

impl<Req: Send, P: Send, E: Send> PlannerLink<Req, P, E> {
    /// From now on the planner is woken through `doorbell` (flagged here,
    /// delivered by whoever calls [`Doorbell::deliver`]) instead of at once.
    pub fn wake_through(&mut self, doorbell: Arc<Doorbell>) {
        doorbell.attach(self.planner.clone());
        self.doorbell = Some(doorbell);
    }

    fn wake(&self) {
        match &self.doorbell {
            Some(d) => d.press(),
            None => self.planner.unpark(),
        }
    }

    /// Queues a request and wakes the planner; returns its sequence number,
    /// or the request back when the queue is full. It is the wanted one
    /// from now on ([`PlannerLink::want`]).
    pub fn submit(&mut self, request: Req) -> Result<u64, Req> {
        let seq = self.next_seq;
        self.wanted.store(seq, Ordering::Release);
        if let Err((_, r)) = self.requests.push((seq, request)) {
            return Err(r);
        }
        self.next_seq += 1;
        self.wake();
        Ok(seq)
    }

    /// Says which request the loop still waits for (`None`: none); a
    /// request being planned that is not it stops (one atomic store).
    pub fn want(&self, seq: Option<u64>) {
        self.wanted
            .store(seq.unwrap_or(NONE_WANTED), Ordering::Release);
    }

    /// Whether a reply waits to be polled (wait-free).
    pub fn reply_ready(&self) -> bool {
        !self.replies.is_empty()
    }

    /// The next finished reply, if any.
    pub fn poll(&mut self) -> Option<Reply<P, E>> {
        self.replies.pop()
    }

    /// Hands a plan the loop no longer needs back to the planner thread,
    /// which drops it. Returns it if the ring is full (keep it, retry next
    /// tick: never drop it on the loop thread).
    pub fn retire(&mut self, plan: Box<P>) -> Result<(), Box<P>> {
        self.retired.push(plan)?;
        self.wake();
        Ok(())
    }
}

/// Handle of the planner thread: `join` (or drop) stops it and waits.
pub type PlannerThread = crate::sys::worker::StoppableThread;

/// What [`spawn`] returns: the loop's link and the thread's handle.
pub type Spawned<Pl> = (
    PlannerLink<
        <Pl as BackgroundPlanner>::Request,
        <Pl as BackgroundPlanner>::Plan,
        <Pl as BackgroundPlanner>::Error,
    >,
    PlannerThread,
);

/// Starts `planner` on a thread named `gaitd-planner`; `queue` bounds the
/// requests (and replies) in flight. `on_start` runs first on the new
/// thread (CPU affinity).
pub fn spawn<Pl: BackgroundPlanner>(
    mut planner: Pl,
    queue: usize,
    on_start: impl FnOnce() + Send + 'static,
) -> std::io::Result<Spawned<Pl>> {
    let (req_tx, mut req_rx) = handoff::channel::<(u64, Pl::Request)>(queue);
    let (mut rep_tx, rep_rx) = handoff::channel::<Reply<Pl::Plan, Pl::Error>>(queue);
    // Room for every plan that can be alive on the loop side at once.
    let (ret_tx, mut ret_rx) = handoff::channel::<Box<Pl::Plan>>(queue + 2);
    let stop = Arc::new(AtomicBool::new(false));
    let stop2 = stop.clone();
    let wanted = Arc::new(AtomicU64::new(NONE_WANTED));
    let wanted2 = wanted.clone();
    let handle = std::thread::Builder::new()
        .name("gaitd-planner".into())
        .spawn(move || {
            on_start();
            planner.prepare();
            while !stop2.load(Ordering::Acquire) {
                while let Some(old) = ret_rx.pop() {
                    drop(old);
                }
                if let Some((seq, req)) = req_rx.pop() {
                    let wanted = Wanted {
                        seq,
                        wanted: wanted2.clone(),
                    };
                    let result = planner.plan(&req, &wanted).map(Box::new);
                    let mut reply = Reply { seq, result };
                    // The loop drains replies every tick; wait for room.
                    loop {
                        match rep_tx.push(reply) {
                            Ok(()) => break,
                            Err(r) if stop2.load(Ordering::Acquire) => {
                                drop(r);
                                return;
                            }
                            Err(r) => {
                                reply = r;
                                std::thread::park_timeout(Duration::from_millis(1));
                            }
                        }
                    }
                    continue;
                }
                planner.idle();
                std::thread::park_timeout(Duration::from_millis(100));
            }
        })?;
    let link = PlannerLink {
        requests: req_tx,
        wanted,
        replies: rep_rx,
        retired: ret_tx,
        planner: handle.thread().clone(),
        doorbell: None,
        next_seq: 1,
    };
    Ok((link, PlannerThread::new(stop, handle)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_schema::ReasonCode;
    use std::sync::atomic::AtomicUsize;

    /// Builds a heap-owning "plan" and counts drops, to check where plans die.
    struct Squares(Arc<AtomicUsize>);
    #[derive(Debug)]
    struct Plan {
        values: Vec<u64>,
        dropped_on: Arc<AtomicUsize>,
    }
    impl Drop for Plan {
        fn drop(&mut self) {
            if std::thread::current().name() == Some("gaitd-planner") {
                self.dropped_on.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
    /// Answers each request with whether it was prepared first.
    struct Prepared(bool);
    impl BackgroundPlanner for Prepared {
        type Request = ();
        type Plan = bool;
        type Error = ReasonCode;
        fn plan(&mut self, _: &(), _: &Wanted) -> Result<bool, ReasonCode> {
            Ok(self.0)
        }
        fn prepare(&mut self) {
            self.0 = std::thread::current().name() == Some("gaitd-planner");
        }
    }

    #[test]
    fn the_planner_thread_prepares_before_its_first_request() {
        let (mut link, _thread) = spawn(Prepared(false), 2, || {}).unwrap();
        link.submit(()).unwrap();
        let reply = loop {
            if let Some(r) = link.poll() {
                break r;
            }
            std::thread::sleep(Duration::from_millis(1));
        };
        assert_eq!(reply.result.map(|b| *b), Ok(true));
    }

    impl BackgroundPlanner for Squares {
        type Request = u64;
        type Plan = Plan;
        type Error = ReasonCode;
        fn plan(&mut self, n: &u64, _: &Wanted) -> Result<Plan, ReasonCode> {
            if *n == 0 {
                return Err(ReasonCode::NoPlan);
            }
            Ok(Plan {
                values: (0..*n).map(|i| i * i).collect(),
                dropped_on: self.0.clone(),
            })
        }
    }

    #[test]
    fn plans_travel_to_the_loop_and_die_on_the_planner_thread() {
        let dropped = Arc::new(AtomicUsize::new(0));
        let (mut link, thread) = spawn(Squares(dropped.clone()), 4, || {}).unwrap();
        let mut got = 0;
        let mut held: Option<Box<Plan>> = None;
        for n in 0..20u64 {
            let seq = link.submit(n).unwrap();
            let reply = loop {
                if let Some(r) = link.poll() {
                    break r;
                }
                std::thread::yield_now();
            };
            assert_eq!(reply.seq, seq);
            match reply.result {
                Ok(plan) => {
                    assert_eq!(plan.values.len() as u64, n);
                    if let Some(old) = held.replace(plan) {
                        link.retire(old).unwrap();
                    }
                    got += 1;
                }
                Err(r) => assert_eq!((n, r), (0, ReasonCode::NoPlan)),
            }
        }
        link.retire(held.take().unwrap()).unwrap();
        while dropped.load(Ordering::Relaxed) < got {
            std::thread::yield_now();
        }
        thread.join();
        assert_eq!(dropped.load(Ordering::Relaxed), 19);
    }

    /// Through a doorbell, a request waits for the delivery (the planner
    /// only polls every 100 ms on its own), then is planned.
    #[test]
    fn a_doorbell_wakes_the_planner_when_delivered() {
        let dropped = Arc::new(AtomicUsize::new(0));
        let (mut link, thread) = spawn(Squares(dropped), 4, || {}).unwrap();
        let bell = Arc::new(Doorbell::default());
        link.wake_through(bell.clone());
        // Let the planner park (its first poll finds nothing).
        std::thread::sleep(Duration::from_millis(20));
        let seq = link.submit(3).unwrap();
        assert!(bell.pressed(), "flagged, not woken");
        bell.deliver();
        assert!(!bell.pressed());
        let reply = loop {
            if let Some(r) = link.poll() {
                break r;
            }
            std::thread::yield_now();
        };
        assert_eq!(reply.seq, seq);
        link.retire(reply.result.unwrap()).unwrap();
        bell.deliver();
        thread.join();
    }
}

#[cfg(test)]
mod wanted_tests {
    use super::*;

    /// Plans "forever" — until the loop no longer wants the request — and
    /// answers how often it looked.
    struct UntilUnwanted;

    impl BackgroundPlanner for UntilUnwanted {
        type Request = ();
        type Plan = u64;
        type Error = u64;
        fn plan(&mut self, _: &(), wanted: &Wanted) -> Result<u64, u64> {
            let mut polls = 0;
            while wanted.still() {
                polls += 1;
                std::thread::yield_now();
            }
            Err(polls)
        }
    }

    fn reply<P: Send, E: Send>(link: &mut PlannerLink<(), P, E>) -> Reply<P, E> {
        loop {
            if let Some(r) = link.poll() {
                return r;
            }
            std::thread::yield_now();
        }
    }

    #[test]
    fn a_request_no_longer_wanted_stops_its_planning() {
        let (mut link, thread) = spawn(UntilUnwanted, 4, || {}).unwrap();
        // A newer request supersedes the one being planned.
        let first = link.submit(()).unwrap();
        let second = link.submit(()).unwrap();
        let r = reply(&mut link);
        assert_eq!(r.seq, first);
        assert!(r.result.is_err(), "stopped by the newer request");
        // The newer one runs until the loop wants none (a cancel).
        link.want(None);
        let r = reply(&mut link);
        assert_eq!(r.seq, second);
        // Wanted again while it is queued: it runs until unwanted.
        let third = link.submit(()).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(5));
        link.want(Some(third));
        std::thread::sleep(std::time::Duration::from_millis(5));
        assert!(!link.reply_ready(), "still planned while wanted");
        link.want(None);
        assert_eq!(reply(&mut link).seq, third);
        thread.join();
    }
}
