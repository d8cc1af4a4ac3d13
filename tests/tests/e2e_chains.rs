//! The daemon on a chain hand (SPEC §14): `gaitd` with the shipped
//! TriFingerPro configuration, its embedded kinematic hand, driven by a
//! client in another process. Graded on the hand's measured state in the
//! status: the ball at the goal, every grasping tip on the ball, no fault
//! on any status read.
//!
//! The status reports each finger's commanded joints: the test puts them
//! through the description's forward kinematics and finds the commanded
//! tip there, the joints inside TriFingerPro's soft limits.
//!
//! And on a joint-level plant out of process (`gaitctl plant sim` on the
//! same configuration): the daemon commands joints, the plant measures
//! them; the status's measured tips are where the test's own forward
//! kinematics of the measured joints puts them, and the ball ends at the
//! goal as the plant reports it.
//!
//! The numbers the test holds it to are the tennis ball's and the tips'
//! (deploy/hands/trifingerpro/hand.toml: R = 33.5 mm, r = 10 mm, the ball's
//! centre 80 mm above the arena) and the URDF's soft joint limits
//! (`robot_properties_fingers`) less the description's 0.05 rad.

use gaitd_client::{Client, GoalSpec, GoalState, GoalTicket, ReasonCode, Verdict};
use gaitd_tests::{TestDaemon, TestPlant};
use std::time::{Duration, Instant};
use test_support::quat::angle;

const T: Duration = Duration::from_secs(5);
/// The ball's and the tip's radii \[m\].
const BALL: f64 = 0.0335;
const TIP: f64 = 0.010;
/// The ball's centre in the hand frame \[m\].
const CENTRE: [f64; 3] = [0.0, 0.0, 0.08];
/// Soft joint limits \[rad\] of every finger (upper, middle, lower
/// joint) and the margin kept inside them.
const LOWER: [f64; 3] = [-0.33, 0.0, -2.7];
const UPPER: [f64; 3] = [1.0, 1.57, 0.0];
const MARGIN: f64 = 0.05;

/// The shipped description's chains (forward kinematics only).
fn chains() -> Vec<kinematics::Chain<3>> {
    let dir = gaitd_tests::repo_root().join("deploy/hands/trifingerpro");
    let urdf = std::fs::read_to_string(dir.join("trifingerpro.urdf")).unwrap();
    let section = std::fs::read_to_string(dir.join("hand.toml")).unwrap();
    let d = kinematics::HandDescription::parse(&urdf, &section).unwrap();
    d.fingers
        .iter()
        .map(|f| kinematics::Chain::<3>::from_description(f, 0.0).unwrap())
        .collect()
}

/// The shipped configuration, its description read from the source tree.
fn trifingerpro() -> String {
    let dir = gaitd_tests::repo_root().join("deploy/hands/trifingerpro");
    let cfg = std::fs::read_to_string(dir.join("gaitd.toml")).unwrap();
    cfg.replace(
        "description = \"hand.toml\"",
        &format!("description = \"{}\"", dir.join("hand.toml").display()),
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

/// Asks for a quarter turn about −x (a few gaits from the configured
/// grasp) from the orientation `start`: the goal and the ticket.
fn quarter_turn(c: &mut Client, d: &TestDaemon, start: [f64; 4]) -> ([f64; 4], GoalTicket) {
    let (h, q) = (
        std::f64::consts::FRAC_PI_4.sin(),
        std::f64::consts::FRAC_PI_4.cos(),
    );
    let t = c
        .reorient(
            &GoalSpec::turn([-1.0, 0.0, 0.0], std::f64::consts::FRAC_PI_2).unwrap(),
            T,
        )
        .unwrap();
    assert_eq!(t.verdict, Verdict::Accepted, "{}", d.log());
    (mul([q, -h, 0.0, 0.0], start), t)
}

/// The goal of `t` ended reached.
fn assert_reached(c: &mut Client, t: &GoalTicket, d: &TestDaemon) {
    let o = c.wait_outcome(t.goal_id, T).unwrap();
    assert_eq!(
        (o.state, o.reason),
        (GoalState::Succeeded, ReasonCode::Reached),
        "{}",
        d.log()
    );
}

#[test]
fn a_chain_hand_turns_the_ball_to_its_goal() {
    let mut d = TestDaemon::new("chains", &trifingerpro());
    // Its goal's trace, too.
    let traces = d.record_traces();
    d.spawn();
    let mut c = d.client();
    let s0 = c.wait_status(T).unwrap();
    // gaitctl shows the joints: in its JSON, and in `watch` beside the
    // margins.
    let out = d.gaitctl().args(["status", "--json"]).output().unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["hand"], "chains");
    for (k, f) in v["fingers"].as_array().unwrap().iter().enumerate() {
        let q: Vec<f64> = f["commanded_joints"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert_eq!(q, s0.fingers[k].commanded_joints.to_vec());
    }
    let out = d
        .gaitctl()
        .args(["watch", "--frames", "1", "--live", "always"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("joints [deg]"), "{text}");
    let (goal, t) = quarter_turn(&mut c, &d, s0.measured_object_q);
    let t0 = Instant::now();
    let mut reads = 0;
    let mut least_grasping = usize::MAX;
    let chains = chains();
    let mut tightest = f64::INFINITY;
    loop {
        let s = c.wait_status(T).unwrap();
        reads += 1;
        assert_eq!(s.fault, 0, "a fault while turning: {s:?}\n{}", d.log());
        assert_eq!(s.hand, shm_schema::status::hand::CHAINS);
        for (k, f) in s.fingers.iter().enumerate() {
            let q = nalgebra::Vector3::from(f.commanded_joints);
            let tip = chains[k].forward(&q).tip_centre();
            let want =
                nalgebra::Vector3::from(f.commanded_tip_position) + nalgebra::Vector3::from(CENTRE);
            assert!(
                (tip - want).norm() < 1e-9,
                "finger {k}: its joints {q:?} put the tip {:.2e} m off",
                (tip - want).norm()
            );
            for j in 0..3 {
                let m = (q[j] - LOWER[j]).min(UPPER[j] - q[j]) - MARGIN;
                tightest = tightest.min(m);
                assert!(m >= 0.0, "finger {k} joint {j} at {} rad", q[j]);
            }
            assert!(
                f.link_clearance >= 0.0,
                "finger {k}: links {}",
                f.link_clearance
            );
        }
        // Every grasping tip (contact measured) is on the ball's surface.
        let mut grasping = 0;
        for (k, f) in s.fingers.iter().enumerate() {
            if f.measured_contact == 1 {
                grasping += 1;
                let r = f
                    .measured_tip_position
                    .iter()
                    .map(|x| x * x)
                    .sum::<f64>()
                    .sqrt();
                assert!(
                    (r - (BALL + TIP)).abs() < 1e-6,
                    "finger {k}'s tip is {r} m from the ball's centre"
                );
            }
        }
        least_grasping = least_grasping.min(grasping);

        if GoalState::try_from(s.goal.state).is_ok_and(|g| g.is_terminal()) {
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(120), "no outcome");
    }
    assert_reached(&mut c, &t, &d);
    let end = c.wait_status(T).unwrap();
    let err = angle(end.measured_object_q, goal);
    assert!(err < 1e-6, "the ball is {err} rad from the goal");
    assert!(
        least_grasping >= 2,
        "the ball was held by {least_grasping} tips"
    );
    assert!(reads > 100, "{reads} status reads");
    eprintln!("{reads} status reads; tightest joint margin {tightest:.3} rad");
    // The trace's every tick has each finger's joints, and they put its
    // tip where the line says.
    let lines = gaitd_tests::trace_lines(&traces);
    assert!(lines.len() > 1000, "{} trace lines", lines.len());
    for l in &lines {
        let v: serde_json::Value = serde_json::from_str(l).unwrap();
        assert!(v["joint_margin"].as_f64().unwrap() >= 0.0, "{l}");
        for (k, f) in v["fingers"].as_array().unwrap().iter().enumerate() {
            let get = |key: &str| {
                let a: Vec<f64> = f[key]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect();
                nalgebra::Vector3::new(a[0], a[1], a[2])
            };
            let tip = chains[k].forward(&get("joints")).tip_centre();
            let want = get("p") + nalgebra::Vector3::from(CENTRE);
            assert!((tip - want).norm() < 1e-9, "finger {k}: {l}");
        }
    }
    assert_eq!(c.bad_samples(), 0);
    // The trace's header names the description, and `gaitctl plot` draws
    // the hand from it: every link capsule and tip of the three fingers at
    // the start and at the end.
    let trace = std::fs::read_dir(&traces)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|x| x == "jsonl"))
        .unwrap();
    let header = std::fs::read_to_string(&trace).unwrap();
    let header: serde_json::Value = serde_json::from_str(header.lines().next().unwrap()).unwrap();
    assert_eq!(header["hand"], "chains");
    assert!(
        header["hand_description"]
            .as_str()
            .is_some_and(|p| p.ends_with("deploy/hands/trifingerpro/hand.toml")),
        "{header}"
    );
    let svg = d.dir.join("chains.svg");
    let out = d
        .gaitctl()
        .args(["plot", trace.to_str().unwrap(), "-o", svg.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let svg = std::fs::read_to_string(&svg).unwrap();
    let capsules: usize = chains.iter().map(|c| c.link_capsules().len()).sum();
    assert!(capsules >= 3, "{capsules} link capsules");
    assert_eq!(svg.matches(r#"class="link""#).count(), 2 * capsules);
    assert_eq!(svg.matches(r#"class="tip""#).count(), 6);
}

/// A quarter turn about −x on a joint-level kinematic TriFingerPro in
/// its own process, in lockstep (module docs).
#[test]
fn a_joint_level_plant_is_commanded_and_read_by_its_joints() {
    let cfg = format!(
        "{}\n[plant]\nkind = \"shm\"\ntiming = \"lockstep\"\n",
        trifingerpro()
    );
    let mut d = TestDaemon::new("chains-plant", &cfg);
    d.spawn();
    let plant = TestPlant::sim(&d);
    let mut c = d.client();
    let s0 = gaitd_tests::wait_plant_started(&mut c, &d, &plant);
    let (goal, t) = quarter_turn(&mut c, &d, s0.measured_object_q);
    let chains = chains();
    let (t0, mut with_joints) = (Instant::now(), 0);
    let end = loop {
        let s = c.wait_status(T).unwrap();
        assert_eq!(s.fault, 0, "a fault: {s:?}\n{}\n{}", d.log(), plant.log());
        if s.measured_mask & shm_schema::measured::JOINTS != 0 {
            with_joints += 1;
            for (k, f) in s.fingers.iter().enumerate() {
                let q = nalgebra::Vector3::from(f.measured_joints);
                let tip = chains[k].forward(&q).tip_centre() - nalgebra::Vector3::from(CENTRE);
                let read = nalgebra::Vector3::from(f.measured_tip_position);
                assert!((tip - read).norm() < 1e-12, "finger {k}: {tip} vs {read}");
                for j in 0..3 {
                    assert!(
                        (q[j] - LOWER[j]).min(UPPER[j] - q[j]) >= MARGIN - 1e-9,
                        "finger {k} joint {j} measured at {} rad",
                        q[j]
                    );
                }
            }
        }
        if GoalState::try_from(s.goal.state).is_ok_and(|g| g.is_terminal())
            && s.phase == shm_schema::Phase::Hold.code()
        {
            break s;
        }
        assert!(t0.elapsed() < Duration::from_secs(180), "no outcome");
    };
    assert_reached(&mut c, &t, &d);
    let err = angle(end.measured_object_q, goal);
    assert!(err < 1e-6, "the plant has the ball {err} rad from the goal");
    // At rest the plant's joints are the ones commanded.
    let s = c.wait_status(T).unwrap();
    for f in &s.fingers {
        let gap = nalgebra::Vector3::from(f.measured_joints)
            - nalgebra::Vector3::from(f.commanded_joints);
        assert!(
            gap.norm() < 1e-12,
            "measured {:?} commanded {:?}",
            f.measured_joints,
            f.commanded_joints
        );
    }
    assert!(
        with_joints > 100,
        "{with_joints} statuses with measured joints"
    );
    drop(plant);
}
