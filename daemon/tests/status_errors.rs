//! The status's tracking errors compare a measurement with the setpoint it
//! answers (LAYOUT.md, `Status.measured_age`), not with the one written in
//! the same tick: the daemon's real loop (`Runtime`, the gait controller,
//! iceoryx2 ports, the writer thread) on the mock clock, with the embedded
//! hand, which executes every setpoint exactly and measures it one tick
//! later. While the hand moves, `object_error` and every `tip_error` are
//! then zero (to rounding), although consecutive setpoints differ by the
//! distance moved in a period.

#[path = "support/ipc_rig.rs"]
mod ipc_rig;

use ipc_rig::{Namespace, gait_loop};
use shm_schema::{Command, GoalFrame, Phase, Status, measured};

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

#[test]
fn errors_compare_the_measurement_with_the_setpoint_it_answers() {
    let ns = Namespace::new("er");
    let mut g = gait_loop(&ns, 47, |_| {});
    g.client.send(Command::goal(
        5,
        1,
        GoalFrame::Relative,
        [0.9238795325112867, 0.0, 0.3826834323650898, 0.0],
    ));
    let mut prev: Option<Status> = None;
    let (mut moving, mut step_max, mut tip_max, mut object_max) = (0u32, 0.0f64, 0.0f64, 0.0f64);
    let mut ticks = 0;
    while ticks < 4000 {
        for s in g.tick().0 {
            let expected = measured::OBJECT | measured::TIPS;
            assert_eq!(s.measured_mask & expected, expected, "tick {}", s.tick);
            // The embedded hand answers the previous tick's setpoint.
            assert_eq!(s.measured_age, 0, "tick {}", s.tick);
            assert_eq!(s.measured_tick, s.tick, "read in the status's tick");
            if s.phase != Phase::Hold.code() {
                moving += 1;
                for f in &s.fingers {
                    tip_max = tip_max.max(f.tip_error);
                }
                object_max = object_max.max(s.object_error);
                // How far the commanded fingertips moved in one period:
                // what a comparison with this tick's setpoint would report.
                if let Some(p) = prev.filter(|p| p.tick + 1 == s.tick) {
                    let step = (0..3)
                        .map(|k| {
                            dist(
                                s.fingers[k].commanded_tip_position,
                                p.fingers[k].commanded_tip_position,
                            )
                        })
                        .fold(0.0, f64::max);
                    step_max = step_max.max(step);
                }
            }
            prev = Some(s);
        }
        if !g.yield_to_planner() {
            ticks += 1;
        }
    }
    println!(
        "{moving} statuses in motion checked: fingertips moved up to {step_max:.2e} m per tick, \
         tip_error at most {tip_max:.1e} m, object_error at most {object_max:.1e} rad"
    );
    assert!(moving > 50, "the hand moved: {moving} statuses");
    assert!(step_max > 1e-4, "{step_max}");
    assert!(tip_max <= 1e-12, "tip_error {tip_max:e} m while moving");
    // (An angle from acos: good to ~1e-8 rad.)
    assert!(
        object_max <= 1e-7,
        "object_error {object_max:e} rad while moving"
    );
    g.finish();
}
