//! Placing on the object where it is measured (SPEC §6.3,
//! `executor::placement`): a grasp under load lets the object creep in it,
//! so the object centre is off the model's origin by a millimetre or so
//! (MuJoCo, 0.1 kg: up to 1.2 mm). A fingertip placed on the modelled
//! surface then lands short of the real one.
//!
//! The plant here is a compliant hand on a displaced object: the object
//! centre sits at a fixed `SAG` from the origin, the object turns exactly
//! as commanded, and the fingertip mounts go exactly where commanded. A
//! grasping fingertip stays on the object (the object rests against it;
//! its press takes up the rest), but a fingertip commanded to grasp after
//! a placement first has to reach the real surface: a force-controlled
//! fingertip in free air extends until its spring balances the grip, F / k
//! (k = `PRESS_STIFFNESS`, the MuJoCo plant's press spring), so it touches
//! once its gap is within that. Graded on that plant's truth: the gaps
//! placed fingertips really had, and whether the goal succeeded.

use gait::executor::{Executor, ExecutorCommand, ExecutorEvent, GoalStage, GoalTarget, Mode};
use gait::planner::{Planner, StepKind};
use gait::sim::{MeasuredFinger, Measurement};
use gait::{FingerMode, HandConfig, HandState};
use nalgebra::{UnitQuaternion, Vector3};

/// Where the real object centre is \[m\]: about what MuJoCo measured
/// after 16 goals at 0.1 kg.
const SAG: Vector3<f64> = Vector3::new(0.0003, -0.0001, -0.0012);
/// The press spring of a fingertip \[N/m\] (mujoco_scene.py's
/// `grip_stiffness`).
const PRESS_STIFFNESS: f64 = 5000.0;
/// A gap this small is a touch (rounding) \[m\].
const TOUCH: f64 = 1e-6;
/// The gap the test's goal must open under a fingertip placed on the
/// modelled surface \[m\]: twice what the runs without placement must
/// show, so that the goal found is clearly one the sag matters to.
const PLACE_GAP: f64 = 4e-4;
/// The seed of the goals searched, and how many are tried.
const SEED: u64 = 0x91ACE;
const TRIES: usize = 64;

/// What one run did, measured on the plant.
struct Run {
    outcome: Option<GoalStage>,
    fault: Option<String>,
    /// Placements: fingertips commanded to grasp after being free.
    placements: usize,
    /// Largest gap between a placed fingertip and the real surface when it
    /// was first commanded to grasp \[m\].
    worst_gap: f64,
    /// Most ticks a placed fingertip took to touch.
    slowest_touch: u32,
}

/// The plant's measurement of the hand commanded `written` with grips
/// `grip`; `touching` says which fingertips are on the object (updated);
/// `reports_centre` whether it measures the object centre. Returns it and
/// each fingertip's gap to the real surface \[m\].
fn measure(
    written: &HandState,
    grip: &[f64; 3],
    touching: &mut [bool; 3],
    rc: f64,
    reports_centre: bool,
) -> (Measurement, [f64; 3]) {
    let mut gaps = [0.0; 3];
    let fingers = std::array::from_fn(|k| {
        let f = &written.fingers[k];
        let gap = (f.center - SAG).norm() - rc;
        gaps[k] = gap;
        touching[k] = match f.mode {
            FingerMode::Grasping => {
                touching[k] || gap <= grip[k].max(0.0) / PRESS_STIFFNESS + TOUCH
            }
            FingerMode::Free => gap <= TOUCH,
        };
        MeasuredFinger {
            center: f.center,
            orientation: f.orientation,
            contact: touching[k],
            normal_force: None,
            roll: Some(f.roll),
        }
    });
    let m = Measurement {
        object: written.object,
        fingers,
        center: reports_centre.then_some(SAG),
        age: 0,
        object_age: 0,
    };
    (m, gaps)
}

/// The configuration of every run: placing up to `max_place_offset`.
fn config(max_place_offset: f64) -> HandConfig {
    let mut cfg = HandConfig::default();
    // The fingertips are commanded off the modelled sphere by the offsets
    // and the object is off the model: a physics plant's tolerances
    // (gaitctl demo --plant mujoco).
    cfg.feedback.finger_tolerance = 0.005;
    cfg.feedback.contact_tolerance = 0.004;
    cfg.feedback.object_tolerance_deg = 2.0;
    cfg.feedback.max_place_offset = max_place_offset;
    cfg
}

/// How far short of the real surface a fingertip placed on the modelled
/// one at `center` stays \[m\] (positive: a gap).
fn sag_gap(center: &Vector3<f64>, rc: f64) -> f64 {
    (center - SAG).norm() - rc
}

/// The largest gap the sag opens under the fingertips `goal`'s plan
/// places, from the paper's start (`None`: no plan, or no placement).
fn planned_gap(planner: &Planner, cfg: &HandConfig, goal: &UnitQuaternion<f64>) -> Option<f64> {
    let rc = cfg.model.object_radius + cfg.model.fingertip_radius;
    let plan = planner.plan(&HandState::paper_start(cfg), goal).ok()?;
    plan.steps
        .iter()
        .filter(|st| st.kind == StepKind::Place)
        .filter_map(|st| {
            let placed = st.eval(&st.dofs().length, &[0.0; 3]).state;
            Some(sag_gap(&placed.fingers[st.finger()?].center, rc))
        })
        .reduce(f64::max)
}

/// The first of a seeded stream of Haar-random goals whose plan places a
/// fingertip where the sag opens a gap of `PLACE_GAP` or more (above the
/// equator: the sag is mostly downwards), with that gap. Found, not
/// written down: which goals place where changes with the planner.
fn goal_placing_over_the_sag() -> (UnitQuaternion<f64>, f64) {
    let cfg = config(0.0);
    let planner = Planner::new(&cfg).unwrap();
    let mut rng = test_support::random::rng(SEED);
    for _ in 0..TRIES {
        let goal = test_support::random::haar(&mut rng);
        if let Some(gap) = planned_gap(&planner, &cfg, &goal)
            && gap >= PLACE_GAP
        {
            return (goal, gap);
        }
    }
    panic!("none of {TRIES} random goals places a fingertip {PLACE_GAP} m short");
}

fn run(max_place_offset: f64, reports_centre: bool, goal: UnitQuaternion<f64>) -> Run {
    let cfg = config(max_place_offset);
    let rc = cfg.model.object_radius + cfg.model.fingertip_radius;
    let start = HandState::paper_start(&cfg);
    let planner = Planner::new(&cfg).unwrap();
    let mut exec = Executor::new(&cfg, 1e-3, start).unwrap();
    exec.command(ExecutorCommand::Goal {
        id: 1,
        target: GoalTarget::Orientation(goal),
        limits: None,
    });
    // Before the first command the plant holds the start grasp.
    let (mut written, mut grip, mut touching) = (start, [5.0; 3], [true; 3]);
    let mut r = Run {
        outcome: None,
        fault: None,
        placements: 0,
        worst_gap: 0.0,
        slowest_touch: 0,
    };
    // Ticks each placed fingertip has been commanded to grasp untouched.
    let mut waiting: [Option<u32>; 3] = [None; 3];
    let mut modes = start.fingers.map(|f| f.mode);
    for _ in 0..400_000 {
        let was = modes;
        let (m, gaps) = measure(&written, &grip, &mut touching, rc, reports_centre);
        for k in 0..3 {
            let grasping = written.fingers[k].mode == FingerMode::Grasping;
            if grasping && was[k] == FingerMode::Free {
                r.placements += 1;
                r.worst_gap = r.worst_gap.max(gaps[k]);
                waiting[k] = Some(0);
            }
            if let Some(n) = waiting[k].as_mut() {
                *n += 1;
                r.slowest_touch = r.slowest_touch.max(*n);
                if touching[k] || !grasping {
                    waiting[k] = None;
                }
            }
        }
        modes = written.fingers.map(|f| f.mode);
        let rep = *exec.tick(Some(&m));
        written = rep.setpoint.state;
        grip = rep.grip;
        if let Some(req) = exec.take_plan_request() {
            drop(exec.deliver_plan(req.goal, req.plan(&planner).map(Box::new)));
        }
        while let Some(e) = exec.pop_event() {
            match e {
                ExecutorEvent::Goal { state, .. } if state.is_terminal() => r.outcome = Some(state),
                ExecutorEvent::Fault { kind, finger } => {
                    r.fault.get_or_insert(format!("{kind:?} (finger {finger})"));
                }
                _ => {}
            }
        }
        if r.outcome.is_some() && exec.phase() == Mode::Holding {
            break;
        }
    }
    r
}

#[test]
fn fingertips_placed_where_the_object_is_measured_touch_it() {
    // A goal whose plan places a fingertip above the equator, where a sag
    // of 1.2 mm opens a gap: searched for, so that a planner placing
    // elsewhere changes the goal, not the test.
    let (goal, gap) = goal_placing_over_the_sag();
    println!(
        "goal {:?}: its plan places a fingertip {:.3} mm short of the real surface",
        goal.coords.as_slice(),
        gap * 1e3
    );
    let on = run(HandConfig::default().feedback.max_place_offset, true, goal);
    let off = run(0.0, true, goal);
    let blind = run(HandConfig::default().feedback.max_place_offset, false, goal);
    for (what, r) in [
        ("placed where measured", &on),
        ("off", &off),
        ("no centre measured", &blind),
    ] {
        println!(
            "{what}: outcome {:?}, fault {:?}, {} placements, largest gap at placement {:.3} mm, \
             slowest to touch {} ticks",
            r.outcome,
            r.fault,
            r.placements,
            r.worst_gap * 1e3,
            r.slowest_touch
        );
    }
    assert_eq!(
        on.outcome,
        Some(GoalStage::Succeeded),
        "fault {:?}",
        on.fault
    );
    assert!(on.fault.is_none(), "{:?}", on.fault);
    assert!(on.placements > 0, "the goal places no fingertip");
    assert!(
        on.slowest_touch <= 2,
        "placed where measured: a fingertip took {} ticks to touch",
        on.slowest_touch
    );
    assert!(
        on.worst_gap < 1e-5,
        "placed where measured: a fingertip placed {:.3} mm off the real surface",
        on.worst_gap * 1e3
    );
    // Without it (or without a measured centre) the same plant sees the
    // fingertips land short.
    for r in [&off, &blind] {
        assert!(
            r.worst_gap > 2e-4,
            "without placement the largest gap is only {:.3} mm",
            r.worst_gap * 1e3
        );
        assert!(
            (r.worst_gap - gap).abs() < TOUCH,
            "without placement the gap is {:.3} mm, the plan's {:.3} mm",
            r.worst_gap * 1e3,
            gap * 1e3
        );
    }
}
