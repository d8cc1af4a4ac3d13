//! Fuzz of the daemon's command decoder (SPEC §12 "Fuzz the decoder"):
//! untrusted bytes from another process → `Command::from_bytes` (what the
//! subscriber sees) → the daemon's own [`Intake`] (validation, shutdown,
//! duplicate ids, limit overrides, conversion) → a probing controller,
//! exactly the loop's preprocess path, with the intake's state carried
//! from one input to the next.
//!
//! 10⁶ inputs on stable Rust: random bytes, random bytes with valid codes,
//! and valid commands with 1–3 structured mutations (bit flips, boundary
//! floats — NaN payloads, ±Inf, subnormals, ±0, huge, values a few ulps
//! either side of every threshold —, every enum code ±1, zero and extreme
//! ids, reserved bytes, limit masks and zero/negative/too-high limits).
//! Each answer is checked against an independent model
//! (`support/intake_oracle.rs`): nothing panics, every rejection carries a
//! reason that applies, every well-formed command is accepted, and what
//! reaches the controller is finite and exactly what was sent. The run
//! also checks its own coverage: every reason the intake can give was
//! produced. A proptest over the same model shrinks any failure to a
//! minimal command. The libFuzzer target in `daemon/fuzz/` (nightly) runs
//! the same check coverage-guided.

#[path = "support/intake_oracle.rs"]
mod oracle;

use oracle::{MAX_ANGLE, MIN_OVERRIDE_FRACTION, NORM_TOLERANCE, Rig, configured_values};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shm_schema::{Command, CommandKind, GoalFrame, ReasonCode};

/// Floats at and around every boundary the decoder knows.
fn special_f64(rng: &mut ChaCha8Rng, cfg: &[f64; 9]) -> f64 {
    let tol = NORM_TOLERANCE;
    let ulp = |x: f64, k: i64| f64::from_bits((x.to_bits() as i64 + k) as u64);
    let k = rng.random_range(-2..=2);
    match rng.random_range(0..25) {
        0 => f64::NAN,
        1 => -f64::NAN,
        2 => f64::from_bits(0x7ff0_0000_0000_0001), // signalling NaN
        3 => f64::from_bits(0xfff8_dead_beef_0001), // NaN with a payload
        4 => f64::INFINITY,
        5 => f64::NEG_INFINITY,
        6 => 0.0,
        7 => -0.0,
        8 => f64::from_bits(1),        // smallest subnormal
        9 => -f64::MIN_POSITIVE / 3.0, // negative subnormal
        10 => f64::MIN_POSITIVE,
        11 => f64::MAX,
        12 => -f64::MAX,
        13 => 1e300,
        14 => -1e-300,
        15 => ulp(1.0 + tol, k),
        16 => ulp(1.0 - tol, k),
        17 => ulp(2.0, k),
        18 => ulp(1e-6, k),
        19 => ulp(MAX_ANGLE, k),
        20 => ulp(cfg[rng.random_range(0..9)], k),
        21 => -cfg[rng.random_range(0..9)],
        22 => ulp(1e6, k),
        23 => ulp(MIN_OVERRIDE_FRACTION * cfg[rng.random_range(0..9)], k),
        _ => 1.0,
    }
}

/// A random unit quaternion (Haar-random), in the wire's (w, x, y, z)
/// order.
fn unit_quaternion(rng: &mut ChaCha8Rng) -> [f64; 4] {
    let q = test_support::random::haar(rng);
    [q.w, q.i, q.j, q.k]
}

/// A well-formed command: any kind, ids from small pools (so duplicates
/// happen and the id memory wraps), overrides at or below the limits.
fn valid(rng: &mut ChaCha8Rng, cfg: &[f64; 9]) -> Command {
    let client = rng.random_range(1..=4);
    match rng.random_range(0..8) {
        0 => Command::cancel(client, rng.random_range(0..4)),
        1 => Command::hold(client),
        2 => Command::reset(client),
        _ => {
            let goal = rng.random_range(1..=3000);
            let mut c = match rng.random_range(0..3) {
                0 => Command::goal(client, goal, GoalFrame::Absolute, unit_quaternion(rng)),
                1 => Command::goal(client, goal, GoalFrame::Relative, unit_quaternion(rng)),
                _ => {
                    let q = unit_quaternion(rng);
                    let angle = rng.random_range(-MAX_ANGLE..=MAX_ANGLE);
                    Command::goal(
                        client,
                        goal,
                        GoalFrame::AxisAngle,
                        [angle, q[1], q[2], q[3]],
                    )
                }
            };
            // Slightly off unit, within tolerance: the daemon renormalises.
            if c.frame != GoalFrame::AxisAngle.code() && rng.random_bool(0.3) {
                let s = 1.0 + rng.random_range(-0.9..0.9) * NORM_TOLERANCE;
                c.target = c.target.map(|x| x * s);
            }
            c.request_id = rng.random();
            for (bit, limit) in cfg.iter().enumerate() {
                if rng.random_bool(0.15) {
                    c.limit_mask |= 1 << bit;
                    let v = limit * rng.random_range(1e-3..=1.0);
                    set_f64(&mut c, 4 + bit, v);
                }
            }
            c
        }
    }
}

/// The 13 floats of a command: target 0–3, overrides 4–12 (mask-bit order).
fn set_f64(c: &mut Command, i: usize, v: f64) {
    let slot = match i {
        0..4 => &mut c.target[i],
        4 => &mut c.object_limits.velocity,
        5 => &mut c.object_limits.acceleration,
        6 => &mut c.object_limits.jerk,
        7 => &mut c.fingertip_limits.velocity,
        8 => &mut c.fingertip_limits.acceleration,
        9 => &mut c.fingertip_limits.jerk,
        10 => &mut c.rolling_limits.velocity,
        11 => &mut c.rolling_limits.acceleration,
        _ => &mut c.rolling_limits.jerk,
    };
    *slot = v;
}

/// Codes around every valid one, and extremes.
fn code_near(rng: &mut ChaCha8Rng, valid_max: u32) -> u32 {
    match rng.random_range(0..4) {
        0 => rng.random_range(0..=valid_max + 1),
        1 => u32::MAX - rng.random_range(0..2),
        2 => 1 << rng.random_range(0..32),
        _ => rng.random(),
    }
}

/// One structured mutation.
fn mutate(c: &mut Command, rng: &mut ChaCha8Rng, cfg: &[f64; 9]) {
    match rng.random_range(0..11) {
        0 => {
            let mut b = c.to_bytes();
            let bit = rng.random_range(0..Command::SIZE * 8);
            b[bit / 8] ^= 1 << (bit % 8);
            *c = Command::from_bytes(&b);
        }
        1 => {
            let mut b = c.to_bytes();
            b[rng.random_range(0..Command::SIZE)] = rng.random();
            *c = Command::from_bytes(&b);
        }
        2 => set_f64(c, rng.random_range(0..13), special_f64(rng, cfg)),
        3 => set_f64(c, rng.random_range(0..13), f64::from_bits(rng.random())),
        4 => c.kind = code_near(rng, CommandKind::Reset.code()),
        5 => c.frame = code_near(rng, GoalFrame::AxisAngle.code()),
        6 => {
            c.limit_mask = match rng.random_range(0..3) {
                0 => c.limit_mask | 1 << rng.random_range(0..32),
                1 => c.limit_mask & !(1 << rng.random_range(0..9)),
                _ => rng.random(),
            }
        }
        7 => {
            let v = [0, 1, u64::MAX, rng.random()][rng.random_range(0..4)];
            match rng.random_range(0..3) {
                0 => c.client_id = v,
                1 => c.goal_id = v,
                _ => c.request_id = v,
            }
        }
        8 => c.reserved = rng.random_range(1..=u32::MAX),
        9 => {
            // The quaternion scaled to a boundary norm, or to zero/huge.
            let s = match rng.random_range(0..6) {
                0 => 1.0 + NORM_TOLERANCE * (1.0 + rng.random_range(-1e-9..1e-9)),
                1 => 1.0 - NORM_TOLERANCE * (1.0 + rng.random_range(-1e-9..1e-9)),
                2 => 0.0,
                3 => 1e-7,
                4 => 1e200,
                _ => rng.random_range(0.5..1.5),
            };
            c.target = c.target.map(|x| x * s);
        }
        _ => {
            // A limit override set to something bad or too high.
            let bit = rng.random_range(0..9);
            c.limit_mask |= 1 << bit;
            let v = match rng.random_range(0..4) {
                0 => 0.0,
                1 => -cfg[bit],
                2 => f64::from_bits(cfg[bit].to_bits() + 1),
                _ => special_f64(rng, cfg),
            };
            set_f64(c, 4 + bit, v);
        }
    }
}

const INPUTS: u64 = 1_000_000;

#[test]
fn a_million_hostile_commands_are_classified_and_none_reaches_the_controller_unclean() {
    let mut rig = Rig::new();
    let cfg = configured_values(&rig.oracle.limits);
    let mut rng = ChaCha8Rng::seed_from_u64(0xf022_de70);
    for i in 0..INPUTS {
        // The last 2 % arrive while the daemon shuts down.
        if i == INPUTS * 98 / 100 {
            rig.shutdown();
        }
        let bytes = match i % 16 {
            0 => {
                let mut b = [0u8; Command::SIZE];
                rng.fill(&mut b[..]);
                b
            }
            1 => {
                // Random bytes that get past the kind and frame checks.
                let mut b = [0u8; Command::SIZE];
                rng.fill(&mut b[..]);
                let mut c = Command::from_bytes(&b);
                c.kind = rng.random_range(1..=4);
                c.frame = rng.random_range(1..=3);
                c.to_bytes()
            }
            _ => {
                let mut c = valid(&mut rng, &cfg);
                for _ in 0..rng.random_range(0..=3) {
                    mutate(&mut c, &mut rng, &cfg);
                }
                c.to_bytes()
            }
        };
        rig.feed(&bytes);
    }
    let seen = |r: ReasonCode| rig.seen[r.code() as usize];
    let mut report: Vec<_> = ReasonCode::ALL
        .iter()
        .filter(|r| seen(**r) > 0)
        .map(|r| format!("{r:?} {}", seen(*r)))
        .collect();
    report.push(format!("accepted {}", rig.accepted));
    println!("{INPUTS} inputs: {}", report.join(", "));
    // Coverage: every reason the intake itself can give was produced.
    for r in [
        ReasonCode::UnknownCommandKind,
        ReasonCode::UnknownGoalFrame,
        ReasonCode::ZeroGoalId,
        ReasonCode::ZeroClientId,
        ReasonCode::NonFiniteQuaternion,
        ReasonCode::ZeroQuaternion,
        ReasonCode::NonUnitQuaternion,
        ReasonCode::BadLimitMask,
        ReasonCode::NonFiniteLimit,
        ReasonCode::NonPositiveLimit,
        ReasonCode::NonZeroReserved,
        ReasonCode::DuplicateGoalId,
        ReasonCode::LimitAboveConfigured,
        ReasonCode::LimitBelowMinimum,
        ReasonCode::ShuttingDown,
        ReasonCode::BadAxisAngle,
    ] {
        assert!(seen(r) >= 50, "{r:?} produced only {} times", seen(r));
    }
    assert!(rig.accepted > INPUTS / 10, "accepting path exercised");
    assert_eq!(
        (rig.intake.received(), rig.intake.rejected()),
        (INPUTS, INPUTS - rig.accepted)
    );
}

/// Every float at a boundary, in every float slot of every goal frame,
/// with and without its override bit: the exhaustive corner product the
/// random run may miss.
#[test]
fn every_boundary_float_in_every_slot() {
    let mut rig = Rig::new();
    let cfg = configured_values(&rig.oracle.limits);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut goal_id = 1;
    for frame in [
        GoalFrame::Absolute,
        GoalFrame::Relative,
        GoalFrame::AxisAngle,
    ] {
        for slot in 0..13 {
            for _ in 0..400 {
                let v = special_f64(&mut rng, &cfg);
                for with_bit in [false, true] {
                    goal_id += 1;
                    let mut c = Command::goal(1, goal_id, frame, [0.0, 0.0, 0.0, 1.0]);
                    if frame == GoalFrame::AxisAngle {
                        c.target = [1.0, 0.0, 0.0, 1.0];
                    }
                    set_f64(&mut c, slot, v);
                    if with_bit && slot >= 4 {
                        c.limit_mask |= 1 << (slot - 4);
                    }
                    rig.feed(&c.to_bytes());
                }
            }
        }
    }
}

fn arb_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(0.0),
        Just(-0.0),
        Just(f64::from_bits(1)),
        Just(1e300),
        -2.0..2.0f64,
        any::<f64>(),
    ]
}

fn arb_command() -> impl Strategy<Value = Command> {
    (
        0u32..6,
        0u32..5,
        prop_oneof![Just(0u64), 1u64..4, any::<u64>()],
        prop_oneof![Just(0u64), 1u64..64],
        prop::array::uniform4(arb_f64()),
        prop_oneof![Just(0u32), 0u32..512, any::<u32>()],
        prop_oneof![Just(0u32), any::<u32>()],
        prop::array::uniform9(prop_oneof![Just(0.0), arb_f64()]),
    )
        .prop_map(|(kind, frame, client, goal, target, mask, reserved, lim)| {
            let mut c = Command::ZERO;
            c.kind = kind;
            c.frame = frame;
            c.client_id = client;
            c.goal_id = goal;
            c.target = target;
            c.limit_mask = mask;
            c.reserved = reserved;
            for (i, v) in lim.into_iter().enumerate() {
                set_f64(&mut c, 4 + i, v);
            }
            c
        })
}

proptest! {
    // No regression files: the seeded runs above are the regression suite.
    #![proptest_config(ProptestConfig {
        cases: 4096,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Sequences of structured commands through one intake (state carried):
    /// a failure shrinks to a minimal sequence.
    #[test]
    fn sequences_of_structured_commands_agree_with_the_model(
        cmds in prop::collection::vec(arb_command(), 1..16)
    ) {
        let mut rig = Rig::new();
        for c in &cmds {
            rig.feed(&c.to_bytes());
        }
    }
}
