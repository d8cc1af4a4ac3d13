//! A misbehaving plant for the end-to-end tests (as dora's
//! fault-tolerance fixtures): an exact kinematic hand in lockstep that, after `--after N`
//! good steps, lies, stalls or faults in the way `--lie` says — or starts
//! in a state that breaks an invariant. It numbers its own measurements
//! (`PlantHost::send_raw`) so that it can lie about them.
//!
//! `plant_fixture --prefix P --root R --file-prefix F --lie KIND [--after N]`
//! KIND: none, nan, non-unit, backwards, session, contact, fault, stall,
//! exit, start-invalid, deaf (for 5 steps it steps on each answer without
//! applying it: the plant repeats its last command), stuck (finger 2 is
//! reported 1 mm out along its contact normal: off its setpoint by twice
//! `feedback.finger_tolerance`, yet not slipping over the object),
//! nan-omega (a NaN `object_omega`, flagged valid), inf-tip-velocity (an
//! infinite `angular_velocity` of finger 2, flagged valid).

use gaitd_client::ConnectOptions;
use gaitd_client::plant::PlantHost;
use gaitd_client::shm_schema::{
    PlantCommand, PlantFault, PlantFingerMode, PlantMeasurement, measurement_valid, plant_state,
};
use std::time::Duration;

/// The paper's start grasp for the default model (R = 0.5, r = 0.1,
/// fingers at 0°, 120°, 240° on the equator, touching with their poles,
/// pole axis −d_k, fingertip x axis = hand z): stated here, not imported.
fn paper_start() -> PlantMeasurement {
    let mut m = PlantMeasurement {
        valid: measurement_valid::REQUIRED,
        state: plant_state::SIMULATED,
        object_q: [1.0, 0.0, 0.0, 0.0],
        ..PlantMeasurement::default()
    };
    for (k, f) in m.fingers.iter_mut().enumerate() {
        let phi = (120.0 * k as f64).to_radians();
        f.position = [0.6 * phi.cos(), 0.6 * phi.sin(), 0.0];
        // Columns x = (0,0,1), y = z × x, z = −d: the rotation about the
        // axis taking e_z to −d; as a quaternion, built from the matrix.
        let (x, z) = ([0.0, 0.0, 1.0], [-phi.cos(), -phi.sin(), 0.0]);
        let y = [
            z[1] * x[2] - z[2] * x[1],
            z[2] * x[0] - z[0] * x[2],
            z[0] * x[1] - z[1] * x[0],
        ];
        f.orientation = quat_from_columns(x, y, z);
        f.contact = 1;
    }
    m
}

/// A unit quaternion [w, x, y, z] from a rotation matrix's columns.
fn quat_from_columns(x: [f64; 3], y: [f64; 3], z: [f64; 3]) -> [f64; 4] {
    let (m00, m11, m22) = (x[0], y[1], z[2]);
    let t = m00 + m11 + m22;
    let q = if t > 0.0 {
        let s = (t + 1.0).sqrt() * 2.0;
        [
            0.25 * s,
            (y[2] - z[1]) / s,
            (z[0] - x[2]) / s,
            (x[1] - y[0]) / s,
        ]
    } else if m00 > m11 && m00 > m22 {
        let s = (1.0 + m00 - m11 - m22).sqrt() * 2.0;
        [
            (y[2] - z[1]) / s,
            0.25 * s,
            (y[0] + x[1]) / s,
            (z[0] + x[2]) / s,
        ]
    } else if m11 > m22 {
        let s = (1.0 + m11 - m00 - m22).sqrt() * 2.0;
        [
            (z[0] - x[2]) / s,
            (y[0] + x[1]) / s,
            0.25 * s,
            (z[1] + y[2]) / s,
        ]
    } else {
        let s = (1.0 + m22 - m00 - m11).sqrt() * 2.0;
        [
            (x[1] - y[0]) / s,
            (z[0] + x[2]) / s,
            (z[1] + y[2]) / s,
            0.25 * s,
        ]
    };
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / n)
}

/// The command applied exactly.
fn follow(m: &mut PlantMeasurement, c: &PlantCommand) {
    m.object_q = c.object_q;
    for (f, cf) in m.fingers.iter_mut().zip(&c.fingers) {
        f.position = cf.position;
        f.orientation = cf.orientation;
        f.roll = cf.roll;
        f.contact = u32::from(cf.mode == PlantFingerMode::Grasping.code());
    }
}

fn arg(args: &[String], flag: &str) -> Option<String> {
    args.iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1).cloned())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let need = |f: &str| arg(&args, f).unwrap_or_else(|| panic!("{f} is required"));
    let lie = arg(&args, "--lie").unwrap_or_else(|| "none".into());
    let after: u64 = arg(&args, "--after").map_or(200, |v| v.parse().expect("--after N"));
    let opts = ConnectOptions::new()
        .prefix(need("--prefix"))
        .root_path(need("--root"))
        .file_prefix(need("--file-prefix"))
        .timeout(Duration::from_secs(10));
    let mut host = PlantHost::open(&opts).expect("open the plant services");
    let mut m = paper_start();
    if lie == "start-invalid" {
        // Two contacts 120° apart: not force-closure (SPEC §3.1 Fact 3).
        m.fingers[0].contact = 0;
        m.fingers[0].position = [0.65, 0.0, 0.0];
    }
    let period = 1_000_000u64;
    let (mut seq, mut step) = (1u64, 0u64);
    m.seq = seq;
    host.send_raw(&m).expect("publish");
    loop {
        let Some(c) = host
            .next_command(Duration::from_millis(100))
            .expect("receive")
        else {
            // Lockstep: republish (a daemon may be starting).
            host.send_raw(&m).expect("publish");
            continue;
        };
        if c.answers != seq {
            continue;
        }
        let deaf = lie == "deaf" && (after..after + 5).contains(&step);
        if !deaf {
            if c.flags & gaitd_client::shm_schema::command_flags::ENABLE != 0 {
                follow(&mut m, &c);
            }
            m.session = c.session;
            m.applied = c.seq;
        }
        step += 1;
        seq += 1;
        m.seq = seq;
        m.time_ns = step * period;
        let mut out = m;
        if step >= after {
            match lie.as_str() {
                "nan" => out.fingers[1].position[0] = f64::NAN,
                "non-unit" => out.object_q = [0.5, 0.0, 0.0, 0.0],
                "stuck" => {
                    out.fingers[2].position = out.fingers[2].position.map(|x| x * 0.601 / 0.6)
                }
                "nan-omega" => {
                    out.valid |= measurement_valid::OBJECT_VELOCITY;
                    out.object_omega[1] = f64::NAN;
                }
                "inf-tip-velocity" => {
                    out.valid |= measurement_valid::TIP_VELOCITY;
                    out.fingers[2].angular_velocity[0] = f64::INFINITY;
                }
                "backwards" => out.seq = seq.saturating_sub(50).max(1),
                "session" => out.session ^= 0xbad,
                // A grasping finger reports no contact (it slipped off).
                "contact" => out.fingers[0].contact = 0,
                "fault" => {
                    out.state |= plant_state::FAULT;
                    out.fault = PlantFault::EmergencyStop.code();
                }
                "stall" => loop {
                    std::thread::sleep(Duration::from_secs(3600));
                },
                "exit" => std::process::exit(3),
                _ => {}
            }
        }
        host.send_raw(&out).expect("publish");
    }
}
