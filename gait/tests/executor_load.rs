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
use gait::{FingerMode, HandConfig, HandState};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
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
    // Goals whose plans unwind a fingertip's roll by spinning it in a
    // three-finger grasp under load (SPEC §1.3 I1'). Every tick of every
    // spin the commanded normal forces — the spinner's with no tangential
    // force and no torsion (its cone is used up by the spin), the other
    // two's inside their coupled cones — must hold the weight, by the
    // test's own SOCP; and the spinner is told to press (it stays in
    // contact) within max_grip.
    // Without the waypoint fallback, which the planner tries before it
    // spins (so with it such plans are rarer still).
    let mut cfg = HandConfig::default();
    cfg.planner.waypoint_axes = 0;
    let planner = gait::planner::Planner::new(&cfg).unwrap();
    let check = LoadCheck::new(&cfg);
    // From where the paper's full turns about z, then x, leave the hand:
    // from the paper start itself no goal of seed 23 spins any more (its
    // start rolls apart with zigzag legs, gait/LOAD-FIGURES.md §12).
    let mut start = HandState::paper_start(&cfg);
    for axis in [Vector3::z(), Vector3::x()] {
        start = planner
            .plan_rotation(&start, &axis, std::f64::consts::TAU)
            .expect("the paper's turn")
            .end_state();
    }
    // Goal 868 of Haar seed 23 from there: the only one of the first 1500
    // whose plan spins (found by planning that sequence; the planner spins
    // under load only when nothing else plans, so such goals are rare).
    let goals: Vec<UnitQuaternion<f64>> = [[-0.266667, 0.750135, 0.487421, -0.358618]]
        .iter()
        .map(|q| UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3])))
        .collect();
    for (i, g) in goals.iter().enumerate() {
        let plan = planner.plan(&start, g).expect("planned");
        assert!(
            planning::spins_in_a_triple(&plan),
            "goal {i} no longer spins under load: pick new goals (the first that do of seed 23 from there)"
        );
    }
    let mut spin_ticks = 0;
    for (i, goal) in goals.iter().enumerate() {
        let mut rig = Rig::new(cfg, start, 1e-3);
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
