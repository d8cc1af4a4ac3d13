//! TriFingerPro in MuJoCo driven by the daemon in closed loop: `gaitd`
//! with the shipped chain-hand configuration and an external plant in
//! lockstep, the plant being the Python package's joint-level MuJoCo
//! TriFingerPro (`python -m gaitd.plants.mujoco` on a `[hand] kind =
//! "chains"` file: torque motors under robot_fingers' action law, gravity,
//! soft tips, the ball's pose through a tracker model).
//!
//! - The link: the plant starts where the daemon commands it (its start
//!   joints on the daemon's branch), the daemon reads its
//!   measured joints, no command is refused, and as simulated the ball
//!   stays in the hand (centre within 5 mm, no link on it) while the
//!   daemon holds it, with no fault; the ball's pose through the default
//!   tracker (30 Hz, 10 ms late, 1 mm / 1° RMS noise).
//! - A quarter turn of the ball about −x from the configured grasp (a few
//!   gaits), the ball seen through the default tracker, graded on the
//!   plant's report, the simulator's truth, never the daemon's status:
//!   reached within 1° as simulated (the goal is the turn applied to the
//!   ball's true start), never dropped (its centre within 5 mm of where
//!   the description puts it at every step), no link on it, the motors'
//!   limits and the soft joint limits respected as applied. The daemon's
//!   `[feedback]` as for a tracked object (`TRACKER_FEEDBACK`); with each
//!   sample taken as it is the daemon stops the turn on a `Slip` it reads
//!   into the noise (docs/design/14-finger-chains.md §14.5, "In closed
//!   loop").
//!
//! Skipped, with the reason, where the Python environment has no MuJoCo.
//! Wall-clock figures are printed, never asserted.

mod python_support;

use gaitd_client::{Client, GoalSpec, GoalState, ReasonCode, Verdict};
use gaitd_tests::{TestDaemon, repo_root};
use python_support::{PlantProcess, connect_when_measured};
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};
use test_support::quat::angle;

const T: Duration = Duration::from_secs(10);
/// Longest wait for the goal (planning and the plant's pace).
const GOAL: Duration = Duration::from_secs(400);
/// `[feedback]` for a physics plant, as `gaitctl demo --plant mujoco`
/// uses it (`binaries/gaitctl/src/demo.rs`, `PHYSICS_FEEDBACK`).
const PHYSICS_FEEDBACK: &str = "[feedback]\nobject_tolerance_deg = 2.0\nfinger_tolerance = 0.005\n\
     contact_tolerance = 0.004\nlimit_guard = 0.0\nstall_ratio = 0.0\n";
/// `[feedback]` keys for the ball's pose through a camera tracker, as
/// `gaitctl demo --hand trifingerpro --plant mujoco` adds them
/// (`TRACKER_FEEDBACK` there).
const TRACKER_FEEDBACK: &str = "tracker_gain = 0.25\norientation_gain = 2.0\n";

/// The Python with MuJoCo and numpy, or why there is none.
fn mujoco_python() -> Result<PathBuf, String> {
    let python = std::env::var_os("GAITD_ORACLE_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| repo_root().join(".venv-oracles/bin/python"));
    if !python.exists() {
        return Err(format!(
            "no Python at {} (bash .ci/install makes it; or set GAITD_ORACLE_PYTHON)",
            python.display()
        ));
    }
    let out = Command::new(&python)
        .args(["-c", "import mujoco, numpy"])
        .output()
        .map_err(|e| format!("{}: {e}", python.display()))?;
    if !out.status.success() {
        return Err(format!(
            "{} has no MuJoCo: {}",
            python.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    Ok(python)
}

/// The shipped TriFingerPro configuration, its description read from the
/// source tree, with a lockstep plant over shared memory.
fn config() -> String {
    let dir = repo_root().join("deploy/hands/trifingerpro");
    let cfg = std::fs::read_to_string(dir.join("gaitd.toml")).unwrap();
    let cfg = cfg.replace(
        "description = \"hand.toml\"",
        &format!("description = \"{}\"", dir.join("hand.toml").display()),
    );
    format!(
        "{cfg}\n[plant]\nkind = \"shm\"\ntiming = \"lockstep\"\n{PHYSICS_FEEDBACK}{TRACKER_FEEDBACK}"
    )
}

/// Hamilton product of [w, x, y, z] quaternions.
fn mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

fn q4(v: &serde_json::Value) -> [f64; 4] {
    let a: Vec<f64> = v.as_array().unwrap().iter().map(f).collect();
    [a[0], a[1], a[2], a[3]]
}

/// The daemon and the MuJoCo plant in lockstep (the plant's tracker
/// options `tracker`), connected once the daemon took the plant's first
/// state; `None` (skipped, with the reason) without MuJoCo.
fn start(tag: &str, tracker: &[&str]) -> Option<(TestDaemon, PlantProcess, Client, PathBuf)> {
    let python = match mujoco_python() {
        Ok(p) => p,
        Err(why) => {
            test_support::skip(&format!("TriFingerPro in MuJoCo ({tag})"), &why);
            return None;
        }
    };
    let mut d = TestDaemon::new(tag, &config());
    d.spawn();
    let report = d.dir.join("plant-report.json");
    let mut cmd = Command::new(&python);
    cmd.env("PYTHONPATH", repo_root().join("client/python"))
        .args(["-m", "gaitd.plants.mujoco", "--config"])
        .arg(d.config_path())
        .args(["--timing", "lockstep"])
        .args(tracker)
        .arg("--report")
        .arg(&report);
    let plant = PlantProcess::spawn(cmd, d.dir.join("plant.log"));
    let c = connect_when_measured(&mut d, &plant, shm_schema::status::measured::JOINTS);
    Some((d, plant, c, report))
}

/// Stops the plant and reads its report.
fn finish(plant: &mut PlantProcess, report: &std::path::Path, d: &TestDaemon) -> serde_json::Value {
    let status = plant.stop(Duration::from_secs(10));
    let text = std::fs::read_to_string(report).unwrap_or_else(|e| {
        panic!(
            "no plant report ({e}): {status:?}\n{}\n{}",
            plant.log(),
            d.log()
        )
    });
    serde_json::from_str(&text).unwrap()
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(f).collect()
}

fn counts(v: &serde_json::Value) -> u64 {
    v.as_array()
        .unwrap()
        .iter()
        .filter_map(|x| x.as_u64())
        .sum()
}

#[test]
fn the_plant_starts_where_the_daemon_commands_and_keeps_the_ball() {
    let Some((d, mut plant, mut c, report)) = start("trifinger-link", &[]) else {
        return;
    };
    let s0 = c.wait_status(T).unwrap();
    assert_ne!(
        s0.measured_mask & shm_schema::status::measured::JOINTS,
        0,
        "no measured joints in the status"
    );
    // A second of the daemon holding the ball.
    let mut last = s0;
    for _ in 0..1000 {
        last = c.wait_status(T).unwrap();
    }
    let fault = shm_schema::FaultCode::try_from(last.fault).map_or("?", |f| f.name());
    let r = finish(&mut plant, &report, &d);
    let start = floats(&r["start_joints"]);
    let mut branch_gap: f64 = 0.0;
    let mut settled_gap: f64 = 0.0;
    for (k, f) in s0.fingers.iter().enumerate() {
        for j in 0..3 {
            branch_gap = branch_gap.max((f.commanded_joints[j] - start[3 * k + j]).abs());
            settled_gap = settled_gap.max((f.measured_joints[j] - start[3 * k + j]).abs());
        }
    }
    println!(
        "TriFingerPro in MuJoCo, held by the daemon for 1 s: start joints {:.2e} rad from the \
         daemon's, measured {settled_gap:.2e} rad off them after settling; drift max {:.3} mm; \
         peak |tau| {:.3} N·m; clip {} joint-steps; daemon fault now {fault}; real-time factor {:.2}",
        branch_gap,
        1e3 * f(&r["max_object_drift_m"]),
        floats(&r["peak_torque_Nm"]).into_iter().fold(0.0, f64::max),
        counts(&r["clip_count"]),
        f(&r["real_time_factor"]),
    );
    // The daemon commands the joints of the tips it measured (settled a
    // little off the configured grasp); another branch is tenths of a
    // radian away.
    assert!(
        branch_gap < 1e-3,
        "the plant started on another branch: {branch_gap} rad"
    );
    assert!(
        settled_gap < 2e-3,
        "measured {settled_gap} rad off the start joints"
    );
    assert_eq!(r["rejected"], 0, "{}", r["last_rejection"]);
    assert_eq!(r["lockstep_timeouts"], 0);
    assert!(r["diverged"].is_null(), "diverged: {}", r["diverged"]);
    assert!(
        f(&r["max_object_drift_m"]) < 0.005,
        "the ball left the tips: {} m",
        r["max_object_drift_m"]
    );
    assert_eq!(r["link_contact_steps"], 0, "a link touched the ball");
    assert_eq!(r["floor_contact_steps"], 0, "the ball fell");
    // Every grasping finger keeps pressing: the daemon never saw a
    // contact lost, a slip or a tracking fault while it held the ball.
    assert_eq!(fault, "None", "the daemon faulted while holding the ball");
}

#[test]
fn the_daemon_turns_the_ball_in_trifingerpros_hand_in_mujoco() {
    let t0 = Instant::now();
    let Some((d, mut plant, mut c, report)) = start("trifinger-turn", &[]) else {
        return;
    };
    let ready = t0.elapsed().as_secs_f64();

    let (h, w) = (
        std::f64::consts::FRAC_PI_4.sin(),
        std::f64::consts::FRAC_PI_4.cos(),
    );
    let turn = [w, -h, 0.0, 0.0];
    let ticket = c
        .reorient(
            &GoalSpec::turn([-1.0, 0.0, 0.0], std::f64::consts::FRAC_PI_2).unwrap(),
            T,
        )
        .unwrap();
    assert_eq!(ticket.verdict, Verdict::Accepted, "{}", d.log());
    let o = c
        .wait_outcome(ticket.goal_id, GOAL)
        .unwrap_or_else(|e| panic!("{e}\n{}\n{}", d.log(), plant.log()));
    let s = c.wait_status(T).unwrap();
    let reached = (o.state, o.reason) == (GoalState::Succeeded, ReasonCode::Reached);
    let fault = shm_schema::FaultCode::try_from(s.fault).map_or("?", |f| f.name());
    // Let the ball settle in the hand, then stop the plant: it writes its report.
    for _ in 0..200 {
        c.wait_status(T).unwrap();
    }
    let wall = t0.elapsed().as_secs_f64();
    let log = plant.log();
    let r = finish(&mut plant, &report, &d);
    let start = q4(&r["start_object_q"]);
    let end = q4(&r["final_object_q"]);
    let err = angle(end, mul(turn, start)).to_degrees();
    let peaks = floats(&r["peak_torque_Nm"]);
    let sum = |key: &str| counts(&r[key]);
    println!(
        "TriFingerPro in MuJoCo, a quarter turn about -x: {:?} ({:?}), fault {fault}; as simulated \
         {err:.3}° from the goal, centre drift max {:.2} mm; peak |tau| {:.3} N·m (limit 0.396), \
         clip acted {} joint-steps, soft limits {}, feed-forward at the limit {} joint-commands, \
         link contacts {} steps; {:.1} s simulated, real-time factor {:.2}; {wall:.0} s wall \
         ({ready:.1} s to start)",
        o.state,
        o.reason,
        1e3 * f(&r["max_object_drift_m"]),
        peaks.iter().copied().fold(0.0, f64::max),
        sum("clip_count"),
        sum("limit_count"),
        sum("feedforward_at_limit"),
        r["link_contact_steps"],
        f(&r["simulated_s"]),
        f(&r["real_time_factor"]),
    );
    assert!(r["diverged"].is_null(), "diverged: {}", r["diverged"]);
    assert_eq!(r["rejected"], 0, "{}", r["last_rejection"]);
    assert!(
        reached,
        "goal {:?} ({:?}), fault {fault}\n--- gaitd ---\n{}\n--- plant ---\n{log}",
        o.state,
        o.reason,
        d.log()
    );
    assert!(
        f(&r["max_object_drift_m"]) < 0.005,
        "the ball left the tips: centre {} m off",
        r["max_object_drift_m"]
    );
    assert!(
        err < 1.0,
        "as simulated the ball is {err:.3}° from the goal"
    );
    assert_eq!(r["link_contact_steps"], 0, "a link touched the ball");
    assert_eq!(r["floor_contact_steps"], 0, "the ball touched the floor");
    assert!(peaks.iter().all(|&t| t <= 0.396 + 1e-12), "{peaks:?}");
    assert_eq!(sum("limit_count"), 0, "a joint crossed its soft limit");
}
