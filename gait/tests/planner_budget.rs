//! The planner's budget (`[planner] max_expansions`, the caller's clock and
//! cancel flag): a request over budget ends in `PlanError::Timeout`, one
//! canceled ends in `PlanError::Canceled` at the next poll — the search
//! polls before every expansion and evaluation — and with the expansion
//! count alone the same request gives the same plan, bit for bit.

mod planning;

use gait::planner::{Budget, Halt, PlanError, Planner, Stop, Target, Unbounded};
use gait::{HandConfig, HandState};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Says stop after `after` polls, and counts the polls.
struct StopAfter {
    after: u32,
    polls: u32,
    why: Halt,
}

impl Stop for StopAfter {
    fn poll(&mut self) -> Option<Halt> {
        self.polls += 1;
        (self.polls > self.after).then_some(self.why)
    }
}

/// Goals from the paper start that need some search (more than `n`
/// expansions under the default budget).
fn goals_needing(planner: &Planner, start: &HandState, n: u32) -> Vec<Target> {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let mut out = Vec::new();
    while out.len() < 3 {
        let t = Target::Orientation(planning::haar(&mut rng));
        let mut never = Unbounded;
        let mut b = Budget::new(planner.config().planner.max_expansions, &mut never);
        if let Ok(p) = planner.plan_within(start, &t, &mut b)
            && p.summary.effort.expansions > n
        {
            out.push(t);
        }
    }
    out
}

#[test]
fn a_request_over_its_budget_is_refused_as_a_timeout() {
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let start = HandState::paper_start(&cfg);
    for (i, t) in goals_needing(&planner, &start, 20).iter().enumerate() {
        // The expansion count.
        let mut never = Unbounded;
        let mut b = Budget::new(20, &mut never);
        assert_eq!(
            planner.plan_within(&start, t, &mut b),
            Err(PlanError::Timeout),
            "goal {i}"
        );
        assert_eq!(
            b.used(),
            20,
            "goal {i}: the budget is used up, not exceeded"
        );
        // The caller's clock.
        let mut clock = StopAfter {
            after: 10,
            polls: 0,
            why: Halt::OutOfBudget,
        };
        let mut b = Budget::new(u32::MAX, &mut clock);
        assert_eq!(
            planner.plan_within(&start, t, &mut b),
            Err(PlanError::Timeout),
            "goal {i}"
        );
    }
}

#[test]
fn a_canceled_request_stops_at_the_next_poll() {
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let start = HandState::paper_start(&cfg);
    for (i, t) in goals_needing(&planner, &start, 50).iter().enumerate() {
        for after in [0, 1, 17, 40] {
            let mut cancel = StopAfter {
                after,
                polls: 0,
                why: Halt::Canceled,
            };
            let mut b = Budget::new(u32::MAX, &mut cancel);
            let r = planner.plan_within(&start, t, &mut b);
            let used = b.used();
            assert_eq!(
                r,
                Err(PlanError::Canceled),
                "goal {i}, cancel after {after}"
            );
            // Not one expansion after the poll that said stop.
            assert_eq!(used, after, "goal {i}");
            assert_eq!(
                cancel.polls,
                after + 1,
                "goal {i}: polled again after stopping"
            );
        }
    }
}

#[test]
fn every_expansion_and_evaluation_takes_from_the_budget() {
    // What the search does between two polls is one expansion or one
    // deferred evaluation: each takes one unit (so a cancel is seen before
    // the next one starts).
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let start = HandState::paper_start(&cfg);
    for (i, t) in goals_needing(&planner, &start, 50).iter().enumerate() {
        let mut polls = StopAfter {
            after: u32::MAX - 1,
            polls: 0,
            why: Halt::Canceled,
        };
        let mut b = Budget::new(u32::MAX, &mut polls);
        let p = planner.plan_within(&start, t, &mut b).expect("planned");
        let e = p.summary.effort;
        let used = b.used();
        assert!(e.evaluated > 0, "goal {i}: nothing deferred");
        assert_eq!(used, e.expansions + e.evaluated, "goal {i}");
        assert_eq!(polls.polls, used, "goal {i}");
    }
}

#[test]
fn the_expansion_budget_alone_plans_bit_for_bit_the_same() {
    let cfg = HandConfig::default();
    let planner = Planner::new(&cfg).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for i in 0..6 {
        let start = if i % 2 == 0 {
            HandState::paper_start(&cfg)
        } else {
            planning::random_two_finger_state(&mut rng, &cfg)
        };
        let goal = planning::haar(&mut rng);
        let a = planner.plan(&start, &goal);
        // A fresh planner (cold tables and caches) and a clone (warm).
        let b = Planner::new(&cfg).unwrap().plan(&start, &goal);
        let c = planner.clone().plan(&start, &goal);
        assert_eq!(a, b, "goal {i}");
        assert_eq!(a, c, "goal {i}");
    }
}

#[test]
fn a_prepared_planner_plans_the_same_and_searches_far_less() {
    // The paper start under the default load: the pair must roll apart
    // beyond one great circle's reach, in legs found by search.
    let cfg = HandConfig::default();
    let start = HandState::paper_start(&cfg);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let goals: Vec<_> = (0..3).map(|_| planning::haar(&mut rng)).collect();
    let cold = Planner::new(&cfg).unwrap();
    let prepared = Planner::new(&cfg).unwrap();
    prepared.prepare(&start);
    let searched = prepared.roll_apart_searches();
    assert!(searched > 0, "prepare searched nothing");
    for (i, g) in goals.iter().enumerate() {
        assert_eq!(cold.plan(&start, g), prepared.plan(&start, g), "goal {i}");
    }
    // What prepare kept, planning did not search again.
    let (cold_n, more) = (
        cold.roll_apart_searches(),
        prepared.roll_apart_searches() - searched,
    );
    println!("roll-apart searches: prepare {searched}, then {more}; cold {cold_n}");
    assert!(more < cold_n, "prepare spared planning no search");
}
