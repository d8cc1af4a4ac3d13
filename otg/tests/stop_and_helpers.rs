//! The executor's smooth stop (velocity interface, target velocity 0) from
//! any state, and the planner's cheap duration helpers.

use otg::{
    ControlInterface, DofLimits, Input, Otg, Output, Progress, Trajectory, min_duration,
    rest_to_rest_duration,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// From states far outside the limits (velocity up to 10×, acceleration up
/// to 10× the limits), a jerk-limited stop always succeeds, runs at 1 kHz
/// to rest, and only exceeds the acceleration limits during its brake.
#[test]
fn velocity_stop_from_any_state() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for case in 0..2000 {
        let mut inp = Input::<7>::new([1.0; 7], [4.0; 7], [40.0; 7]);
        inp.control_interface = ControlInterface::Velocity;
        for i in 0..7 {
            let (v, a, j) = (
                rng.random_range(0.05..5.0),
                rng.random_range(0.5..50.0),
                rng.random_range(5.0..500.0),
            );
            inp.max_velocity[i] = v;
            inp.max_acceleration[i] = a;
            inp.max_jerk[i] = j;
            inp.current_position[i] = rng.random_range(-1.0..1.0);
            inp.current_velocity[i] = rng.random_range(-10.0..10.0) * v;
            inp.current_acceleration[i] = rng.random_range(-10.0..10.0) * a;
        }
        let mut otg = Otg::<7>::new(0.001).unwrap();
        let mut traj = Trajectory::<7>::default();
        otg.calculate(&inp, &mut traj)
            .unwrap_or_else(|e| panic!("case {case}: {e}"));
        let end = traj.at_time(traj.duration);
        for i in 0..7 {
            assert!(
                end.velocity[i].abs() < 1e-8 && end.acceleration[i].abs() < 1e-10,
                "case {case} DoF {i}: {end:?}"
            );
            let p = &traj.profiles[i];
            // After the brake, the acceleration stays inside its limits.
            for k in 0..=100 {
                let t = p.brake.duration + (traj.duration - p.brake.duration) * k as f64 / 100.0;
                let a = traj.at_time(t).acceleration[i];
                assert!(
                    a.abs() <= inp.max_acceleration[i] * (1.0 + 1e-12),
                    "case {case} DoF {i} t {t}: a {a}"
                );
            }
        }
        // The control loop reaches rest and reports Finished.
        let mut out = Output::<7>::default();
        let mut cycles = 0;
        while otg.update(&inp, &mut out).unwrap() == Progress::Working {
            out.pass_to_input(&mut inp);
            cycles += 1;
            assert!(cycles < 10_000_000, "case {case}: no end");
        }
        assert!(
            out.new_velocity.iter().all(|v| v.abs() < 1e-8),
            "case {case}"
        );
    }
}

/// The closed-form rest-to-rest duration equals the generator's.
#[test]
fn rest_to_rest_matches_generator() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut otg = Otg::<1>::new(0.001).unwrap();
    let mut traj = Trajectory::<1>::default();
    for _ in 0..20_000 {
        let (v, a, j) = (
            rng.random_range(0.01..5.0),
            rng.random_range(0.1..50.0),
            rng.random_range(1.0..1000.0),
        );
        let d = if rng.random_bool(0.5) {
            rng.random_range(-5.0..5.0)
        } else {
            rng.random_range(-1e-3..1e-3)
        };
        let mut inp = Input::<1>::new([v], [a], [j]);
        inp.target_position = [d];
        otg.calculate(&inp, &mut traj).unwrap();
        let t = rest_to_rest_duration(d, v, a, j);
        assert!(
            (t - traj.duration).abs() <= 1e-9 * traj.duration.max(1.0),
            "d {d} v {v} a {a} j {j}: {t} vs {}",
            traj.duration
        );
    }
}

/// `min_duration` equals the independent minimum duration of a full
/// calculation, including states outside the limits (brake).
#[test]
fn min_duration_matches_independent_durations() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut otg = Otg::<1>::new(0.001).unwrap();
    let mut traj = Trajectory::<1>::default();
    for _ in 0..20_000 {
        let lim = DofLimits {
            v_max: rng.random_range(0.1..3.0),
            v_min: -rng.random_range(0.1..3.0),
            a_max: rng.random_range(1.0..30.0),
            a_min: -rng.random_range(1.0..30.0),
            j_max: rng.random_range(10.0..500.0),
        };
        let mut inp = Input::<1>::new([lim.v_max], [lim.a_max], [lim.j_max]);
        inp.min_velocity = Some([lim.v_min]);
        inp.min_acceleration = Some([lim.a_min]);
        inp.current_velocity = [rng.random_range(-2.0..2.0) * lim.v_max];
        inp.current_acceleration = [rng.random_range(-2.0..2.0) * lim.a_max];
        inp.target_position = [rng.random_range(-3.0..3.0)];
        inp.target_velocity = [rng.random_range(0.0..0.5) * lim.v_max];
        let t = min_duration(
            0.0,
            inp.current_velocity[0],
            inp.current_acceleration[0],
            inp.target_position[0],
            inp.target_velocity[0],
            0.0,
            &lim,
        )
        .unwrap();
        otg.calculate(&inp, &mut traj).unwrap();
        assert_eq!(t, traj.independent_min_durations[0]);
    }
}

/// A trajectory calculated elsewhere (another thread, another generator
/// with the same cycle) and adopted is sampled as the generator would have
/// sampled its own, cycle for cycle, and the first update does not
/// recalculate.
#[test]
fn an_adopted_trajectory_is_sampled_as_a_calculated_one() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    for case in 0..200 {
        let mut inp = Input::<3>::new([1.0; 3], [4.0; 3], [40.0; 3]);
        for i in 0..3 {
            inp.max_velocity[i] = rng.random_range(0.1..3.0);
            inp.max_acceleration[i] = rng.random_range(1.0..30.0);
            inp.max_jerk[i] = rng.random_range(10.0..600.0);
            inp.target_position[i] = rng.random_range(0.0..2.0);
        }
        let mut elsewhere = Otg::<3>::new(0.001).unwrap();
        let mut traj = Trajectory::<3>::default();
        elsewhere.calculate(&inp, &mut traj).unwrap();

        let (mut own, mut adopted) = (Otg::<3>::new(0.001).unwrap(), Otg::<3>::new(0.001).unwrap());
        let (mut own_in, mut adopted_in) = (inp, inp);
        let (mut own_out, mut adopted_out) = (Output::<3>::default(), Output::<3>::default());
        adopted.adopt(&adopted_in, &traj, &mut adopted_out);
        for cycle in 0..100_000 {
            let a = own.update(&own_in, &mut own_out).unwrap();
            let b = adopted.update(&adopted_in, &mut adopted_out).unwrap();
            if cycle == 0 {
                assert!(
                    own_out.new_calculation,
                    "case {case}: the own one calculates"
                );
                assert!(!adopted_out.new_calculation, "case {case}: recalculated");
            }
            assert_eq!(
                (
                    a,
                    own_out.new_position,
                    own_out.new_velocity,
                    own_out.new_acceleration
                ),
                (
                    b,
                    adopted_out.new_position,
                    adopted_out.new_velocity,
                    adopted_out.new_acceleration
                ),
                "case {case} cycle {cycle}"
            );
            own_out.pass_to_input(&mut own_in);
            adopted_out.pass_to_input(&mut adopted_in);
            if a == Progress::Finished {
                break;
            }
        }
    }
}
