//! Lockstep with a slow planner: while a plan is being made, the loop holds
//! the plant's measurement and keeps beating (status heartbeats, watchdog)
//! between ticks instead of waiting inside one; the plan then arrives at
//! the tick right after its request, and no plant timeout is reported for
//! a wait that was the planner's.
//!
//! The planner here is the real one behind a gate the test opens: as long
//! as the gate is shut, no tick may run.

#[path = "support/ipc_rig.rs"]
mod ipc_rig;

use gait::executor::Mode;
use gait::planner::{Plan, PlanError};
use gaitd::control::gait_controller::GaitPlanner;
use gaitd::control::gait_controller::GoalPlanRequest;
use gaitd::control::plan_thread::{BackgroundPlanner, Wanted};
use ipc_rig::Namespace;
use shm_schema::{Command, GoalFrame};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// The real planner, entered at once but finishing only when `open`.
struct Gated {
    inner: GaitPlanner,
    open: Arc<AtomicBool>,
    entered: Arc<AtomicU64>,
}

impl BackgroundPlanner for Gated {
    type Request = GoalPlanRequest;
    type Plan = Plan;
    type Error = PlanError;
    fn plan(&mut self, r: &GoalPlanRequest, wanted: &Wanted) -> Result<Plan, PlanError> {
        self.entered.fetch_add(1, Ordering::AcqRel);
        while !self.open.load(Ordering::Acquire) {
            std::thread::sleep(Duration::from_millis(1));
        }
        self.inner.plan(r, wanted)
    }
}

/// Stops the plant and opens the gate when dropped.
struct Release<'a>(&'a AtomicBool, &'a AtomicBool);

impl Drop for Release<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
        self.1.store(true, Ordering::Release);
    }
}

#[test]
fn a_plan_in_flight_holds_the_lockstep_tick_and_the_loop_beats_meanwhile() {
    let mut ns = Namespace::new("xgate");
    ns.cfg.plant.kind = gaitd::config::PlantKind::Shm;
    ns.cfg.plant.timing = gaitd::config::PlantTiming::Lockstep;
    let (open, entered) = (
        Arc::new(AtomicBool::new(false)),
        Arc::new(AtomicU64::new(0)),
    );
    let planner = Gated {
        inner: GaitPlanner::new(gait::planner::Planner::new(&ns.cfg.hand()).unwrap(), None),
        open: open.clone(),
        entered: entered.clone(),
    };
    let mut g = ipc_rig::gait_loop_with(&ns, 49, planner, |_| {});
    let (stop, steps) = (AtomicBool::new(false), AtomicU64::new(0));
    std::thread::scope(|s| {
        // A failing assertion must not leave the plant and the planner
        // waiting forever (the scope joins them before it fails).
        let _release = Release(&stop, &open);
        let (ns, stop, steps) = (&ns, &stop, &steps);
        s.spawn(move || {
            let mut plant = ipc_rig::RigPlant::open(ns);
            while !stop.load(Ordering::Acquire) {
                plant.publish();
                // One measurement, answered or not: no re-sending.
                while !plant.follow(Duration::from_millis(20)) {
                    if stop.load(Ordering::Acquire) {
                        return;
                    }
                }
                steps.fetch_add(1, Ordering::AcqRel);
            }
        });
        let bounded = |what: &str, k: u64| assert!(k < 200_000, "{what}: never");
        // Warm-up: the plant's first state is taken, ticks follow it.
        let mut k = 0;
        while steps.load(Ordering::Acquire) < 200 {
            g.rt.lockstep_once();
            k += 1;
            bounded("warm-up", k);
        }
        g.client.send(Command::goal(
            7,
            1,
            GoalFrame::AxisAngle,
            [0.0, 0.0, 1.0, 0.5],
        ));
        k = 0;
        while entered.load(Ordering::Acquire) == 0 {
            g.rt.lockstep_once();
            g.clock.advance(1_000_000);
            k += 1;
            bounded("plan request", k);
        }
        // The gate is shut: the plant's next measurement is held, no tick
        // runs, the plant gets no command, and status heartbeats go on.
        let answered = steps.load(Ordering::Acquire);
        let _ = g.client.drain();
        let mut beats = 0;
        for pass in 0..300 {
            assert!(
                !g.rt.lockstep_once(),
                "a tick ran at pass {pass} with the plan in flight"
            );
            g.clock.advance(1_000_000);
            beats += g.client.drain().0.len();
        }
        assert!(
            steps.load(Ordering::Acquire) <= answered + 1,
            "the plant was answered"
        );
        assert!(beats > 0, "no status while the loop waited for the plan");
        assert!(g.rt.controller().phase() == Mode::Planning);
        // The gate opens: the held tick runs with the plan.
        open.store(true, Ordering::Release);
        k = 0;
        while !g.rt.lockstep_once() {
            g.clock.advance(1_000_000);
            k += 1;
            bounded("the held tick", k);
        }
        assert!(
            g.rt.controller().phase() != Mode::Planning,
            "the plan did not arrive at the held tick"
        );
        assert_eq!(g.rt.stats().plan_waits(), 1);
        // The goal runs on; the wait for the plan was no plant timeout.
        let before = steps.load(Ordering::Acquire);
        k = 0;
        while steps.load(Ordering::Acquire) < before + 200 {
            g.rt.lockstep_once();
            k += 1;
            bounded("after the plan", k);
        }
        assert!(!g.rt.controller().awaiting_plant());
        let (statuses, _) = g.client.drain();
        let last = statuses.last().expect("statuses after the plan");
        assert_eq!(last.fault, 0, "fault {}", last.fault);
        stop.store(true, Ordering::Release);
    });
    g.finish();
}
