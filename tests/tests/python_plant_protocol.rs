//! The `Plant` base class of the `gaitd` Python package
//! (`client/python/gaitd/plant.py`) speaks the plant protocol of
//! PLANT-GUIDE.md: measurement numbering and time stamps, echo of session
//! and applied command, the lockstep wait with its wall-clock timeout and
//! holding while the daemon is away, the real-time loop, refusal of bad
//! commands (NaN, non-unit quaternions, unknown codes and bits, padding,
//! period, timing, target time, stale and future numbers), HOLD and
//! no-ENABLE, a new daemon session, a restart over a dead predecessor's
//! publisher slot. The plant is the example `client/python/examples/kinematic_hand.py`,
//! in its own process; `tests/python/plant_protocol.py` plays the daemon's
//! side over real iceoryx2 services it creates itself (a fixture for the
//! base class, not a replacement for gaitd).

mod python_support;

use gaitd_tests::repo_root;
use python_support::{Namespace, json_output, script};

#[test]
fn the_plant_base_class_speaks_the_protocol() {
    let ns = Namespace::new("protocol");
    let t0 = std::time::Instant::now();
    let out = script("plant_protocol.py")
        .args(ns.args())
        .output()
        .unwrap();
    let v = json_output(&out, "plant_protocol.py");
    let checks = v["checks"].as_object().expect("checks");
    let mut failed = Vec::new();
    for (name, c) in checks {
        let ok = c["ok"].as_bool() == Some(true);
        println!("{} {name}", if ok { "ok  " } else { "FAIL" });
        if !ok {
            failed.push(format!("{name}: {}", c["detail"]));
        }
    }
    println!(
        "{} protocol checks in {:.1} s",
        checks.len(),
        t0.elapsed().as_secs_f64()
    );
    assert!(checks.len() >= 30, "only {} checks ran", checks.len());
    assert!(
        failed.is_empty(),
        "failed:\n{}\nlogs: {}",
        failed.join("\n"),
        v["logs"]
    );
}
#[test]
fn the_package_readme_shows_the_example_plant_as_it_is() {
    let example =
        std::fs::read_to_string(repo_root().join("client/python/examples/kinematic_hand.py"))
            .unwrap();
    let readme = std::fs::read_to_string(repo_root().join("client/python/README.md")).unwrap();
    assert!(
        example.lines().count() <= 50,
        "the example plant is {} lines",
        example.lines().count()
    );
    assert!(
        readme.contains(&example),
        "client/python/README.md does not show examples/kinematic_hand.py as it is"
    );
}
