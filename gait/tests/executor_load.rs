//! The controller under load (SPEC §1.3 I1', §3.3; issue "Holding against
//! gravity"): Haar-random goals from the paper start executed tick by tick
//! on the kinematic hand with gravity on (0.1 kg, the default force limit).
//! Every tick the commanded grip stays within `load.max_grip`, the load
//! margin the executor reports is not negative, no finger's commanded
//! force jumps (placements ramp in, lifts ramp out: `load.handover_time`),
//! and — checked independently every 10th tick by the test's own SOCP —
//! the commanded normal forces (within 0.01 N), with tangential forces and
//! torsion inside the coupled cones, hold the weight and the torque that
//! accelerates the object.
//!
//! CI runs `GAIT_LOAD_EXEC_GOALS` goals (default 10).

mod planning;

use gait::executor::{ExecutorCommand, GoalStage, GoalTarget, Mode};
use gait::planner::fingertips::{Fingertips, StillAction};
use gait::planner::hand_model::{Action, HandModel, RegraspFor};
use gait::planner::{StepKind, Unbounded};
use gait::{FingerMode, HandConfig, HandState};
use nalgebra::{UnitQuaternion, Vector3};
use planning::load::{Kind, LoadCheck};
use planning::run::Rig;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Largest change of one finger's commanded normal force in one tick [N]:
/// the handover ramp (C², 0.15 s) moves at most 1.875 × 20 N × 1 ms /
/// 0.15 s = 0.25 N a tick; a jump at a gait would be several newtons.
const MAX_STEP_N: f64 = 0.35;

/// How far the delivered normal forces may differ from the commanded ones
/// in the independent check [N]: along a pair's chord only the normals
/// balance the load, so the torque the test estimates from consecutive
/// object rates (a finite difference, not the controller's exact I α) is
/// absorbed there, as a compliant fingertip absorbs it.
const NORMAL_TOL: f64 = 0.01;

/// Goal 1 of `rig` succeeded without a fault or a broken invariant, and
/// the plant's object is at `goal` (its own state, not the command).
fn assert_reached(rig: &Rig, goal: &UnitQuaternion<f64>, i: usize) {
    assert_eq!(
        rig.stats.goals.last(),
        Some(&(1, GoalStage::Succeeded)),
        "goal {i}"
    );
    let err = rig.plant.state().object.angle_to(goal);
    assert!(err < 1e-6, "goal {i}: final error {err}");
    assert!(
        rig.stats.violations.is_empty(),
        "goal {i}: {:?}",
        &rig.stats.violations[..1]
    );
    assert_eq!(rig.stats.faults, 0, "goal {i}: fault");
}

#[test]
fn grips_hold_the_load_every_tick_and_never_jump() {
    let n = std::env::var("GAIT_LOAD_EXEC_GOALS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10);
    let cfg = HandConfig::default();
    let check = LoadCheck::new(&cfg);
    let inertia = 0.4 * cfg.load.object_mass * cfg.model.object_radius.powi(2);
    let mut rng = ChaCha8Rng::seed_from_u64(19);
    let (mut ticks, mut checked, mut max_step, mut min_margin, mut max_grip) =
        (0u64, 0u64, 0.0f64, f64::INFINITY, 0.0f64);
    for i in 0..n {
        let goal = planning::haar(&mut rng);
        let mut rig = Rig::new(cfg, HandState::paper_start(&cfg), 1e-3);
        rig.command(ExecutorCommand::Goal {
            id: 1,
            target: GoalTarget::Orientation(goal),
            limits: None,
        });
        let mut prev: Option<([f64; 3], Vector3<f64>)> = None;
        for t in 0..200_000u64 {
            let rep = rig.tick();
            ticks += 1;
            for k in 0..3 {
                assert!(
                    rep.grip[k] <= cfg.load.max_grip + 1e-9,
                    "goal {i} tick {t}: grip {}",
                    rep.grip[k]
                );
                max_grip = max_grip.max(rep.grip[k]);
            }
            if rep.phase == Mode::Moving {
                assert!(
                    rep.load_margin >= -1e-9,
                    "goal {i} tick {t}: load margin {} (peak {})",
                    rep.load_margin,
                    rep.grip_peak
                );
                min_margin = min_margin.min(rep.load_margin);
            }
            let rate = rep.setpoint.object_rate;
            if let Some((g0, r0)) = prev {
                for (k, (now, before)) in rep.grip.iter().zip(g0).enumerate() {
                    let step = (now - before).abs();
                    max_step = max_step.max(step);
                    assert!(
                        step <= MAX_STEP_N,
                        "goal {i} tick {t}: finger {k} grip jumps by {step} N"
                    );
                }
                if t % 10 == 0 {
                    let s = &rep.setpoint.state;
                    let idx: Vec<usize> = (0..3)
                        .filter(|&k| s.fingers[k].mode == FingerMode::Grasping)
                        .collect();
                    let normals: Vec<Vector3<f64>> = idx
                        .iter()
                        .map(|&k| s.fingers[k].center.normalize())
                        .collect();
                    let f_n: Vec<f64> = idx.iter().map(|&k| rep.grip[k]).collect();
                    let torque = (rate - r0) / 1e-3 * inertia;
                    assert!(
                        check.commanded_holds_weight(
                            &normals,
                            &f_n,
                            Kind::Soft,
                            &torque,
                            NORMAL_TOL
                        ),
                        "goal {i} tick {t}: the commanded grip {f_n:?} does not hold the weight"
                    );
                    checked += 1;
                }
            }
            prev = Some((rep.grip, rate));
            if (rep.phase == Mode::Holding || rep.phase == Mode::SafeHold) && t > 1 {
                break;
            }
        }
        assert_reached(&rig, &goal, i);
    }
    println!(
        "{n} goals, {ticks} ticks: largest commanded grip {max_grip:.2} N, least load margin while moving {min_margin:.2} N, largest per-tick grip change {max_step:.3} N; {checked} ticks' commanded grips checked by the independent SOCP"
    );
}

#[test]
fn a_fingertip_spinning_under_load_pushes_along_its_normal_only() {
    // Plans that unwind a fingertip's roll by spinning it in a
    // three-finger grasp under load (SPEC §1.3 I1'): the fingertips' last
    // resort, which the planner makes only when nothing else plans — so
    // the test makes them itself, from random two-finger states, with the
    // fingertips' own regrasp, and has the executor run them. Every tick
    // of every spin the commanded normal forces — the spinner's with no
    // tangential force and no torsion (its cone is used up by the spin),
    // the other two's inside their coupled cones — must hold the weight,
    // by the test's own SOCP; and the spinner is told to press (it stays
    // in contact) within max_grip.
    let cfg = HandConfig::default();
    let check = LoadCheck::new(&cfg);
    let hand = Fingertips::new(&cfg).for_pass(true, true);
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let mut scripted: Vec<(HandState, gait::planner::Plan)> = Vec::new();
    while scripted.len() < 2 {
        let start = planning::random_two_finger_state(&mut rng, &cfg);
        let mut never = Unbounded;
        let offers = hand.regrasps(&start, RegraspFor::Unstick, &mut never);
        let Some(o) = offers.into_iter().find(|o| {
            o.regrasp
                .actions
                .iter()
                .any(|a| matches!(a, StillAction::Spin(..)))
        }) else {
            continue;
        };
        let actions = [Action::Regrasp {
            regrasp: o.regrasp,
            why: RegraspFor::Unstick,
        }];
        let steps = hand.build(&start, &actions).expect("built");
        hand.check(&start, &steps).expect("held at every sample");
        let gaits = steps
            .iter()
            .filter(|s| matches!(s.kind, StepKind::Place | StepKind::Lift))
            .count() as u32;
        let plan = gait::planner::Plan {
            start,
            goal: start.object,
            summary: gait::planner::PlanSummary {
                gaits,
                duration: steps.iter().map(|s| s.duration).sum(),
                ..Default::default()
            },
            steps,
            route: Default::default(),
            profiles: Vec::new(),
        };
        assert!(planning::spins_in_a_triple(&plan));
        scripted.push((start, plan));
    }
    let goals: Vec<UnitQuaternion<f64>> = scripted.iter().map(|(s, _)| s.object).collect();
    let mut spin_ticks = 0;
    for (i, (goal, (start, plan))) in goals.iter().zip(scripted).enumerate() {
        let mut rig = Rig::new(cfg, start, 1e-3);
        rig.script(plan);
        rig.command(ExecutorCommand::Goal {
            id: 1,
            target: GoalTarget::Orientation(*goal),
            limits: None,
        });
        let mut prev: Option<HandState> = None;
        for t in 0..200_000u64 {
            let rep = rig.tick();
            let s = rep.setpoint.state;
            if let Some(p) = prev
                && s.fingers.iter().all(|f| f.mode == FingerMode::Grasping)
                && s.object.angle_to(&p.object) == 0.0
            {
                // A finger whose orientation turns while its centre stays
                // spins on the still object.
                let spinner = (0..3).find(|&k| {
                    s.fingers[k].orientation.angle_to(&p.fingers[k].orientation) > 1e-9
                        && (s.fingers[k].center - p.fingers[k].center).norm() < 1e-12
                });
                if let Some(k) = spinner {
                    let normals: Vec<Vector3<f64>> =
                        s.fingers.iter().map(|f| f.center.normalize()).collect();
                    assert!(
                        check.commanded_holds_weight_with(
                            &normals,
                            &rep.grip,
                            Kind::Soft,
                            &Vector3::zeros(),
                            NORMAL_TOL,
                            1 << k
                        ),
                        "goal {i} tick {t}: finger {k} spins, the commanded grip {:?} does not hold the weight",
                        rep.grip
                    );
                    assert!(rep.grip.iter().all(|&g| g <= cfg.load.max_grip + 1e-9));
                    spin_ticks += 1;
                }
            }
            prev = Some(s);
            if (rep.phase == Mode::Holding || rep.phase == Mode::SafeHold) && t > 1 {
                break;
            }
        }
        assert_reached(&rig, goal, i);
    }
    assert!(spin_ticks > 0, "no tick spun a fingertip");
    println!(
        "{} goals that spin under load: {spin_ticks} spinning ticks, each one's commanded grip checked by the independent SOCP (spinner frictionless)",
        goals.len()
    );
}
