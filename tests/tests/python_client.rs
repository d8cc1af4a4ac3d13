//! The `gaitd` Python package's client (`client/python/gaitd/client.py`,
//! PyPI `iceoryx2` at the daemon's version) sends commands to a real
//! daemon and reads its status and events. The script
//! (`tests/python/client_smoke.py`) first checks the package's ctypes
//! mirror against `shm_schema/LAYOUT.md`.
//!
//! Python comes from `GAITD_ORACLE_PYTHON` or `<repo>/.venv-oracles/bin/python`
//! (made by `.ci/install`); the test fails with instructions if neither exists.

mod python_support;

use gaitd_tests::{TestDaemon, repo_root};
use python_support::{json_output, script};

#[test]
fn python_client_sends_commands_and_reads_status() {
    let d = TestDaemon::start("python");
    let _wait_until_up = d.client();
    let t0 = std::time::Instant::now();
    let out = script("client_smoke.py")
        .arg("--layout")
        .arg(repo_root().join("shm_schema/LAYOUT.md"))
        .args(["--prefix", &d.prefix])
        .arg("--root")
        .arg(format!("{}/", d.root.display()))
        .args(["--file-prefix", &d.file_prefix])
        .output()
        .expect("run python");
    println!("client_smoke.py ran {:.1} s", t0.elapsed().as_secs_f64());
    let v = json_output(&out, "python client");
    assert_eq!(v["iceoryx2"], shm_schema::ICEORYX2_VERSION);
    assert_eq!(v["status"]["daemon_state"], 1, "Running");
    assert_eq!(v["status"]["phase"], 1, "Hold");
    for r in v["status"]["contact_radii"].as_array().unwrap() {
        assert!((r.as_f64().unwrap() - 0.5).abs() < 1e-12);
    }
    assert_eq!(v["hold"]["code"], "Accepted");
    assert_eq!(v["goal"]["code"], "Accepted");
    assert_eq!(v["goal"]["goal_id"], 1);
    assert_eq!(v["nan_goal"]["code"], "Rejected");
    assert_eq!(v["nan_goal"]["reason"], "NonFiniteQuaternion");
    assert_eq!(v["goal_outcome"]["state"], "Succeeded");
    assert_eq!(v["goal_outcome"]["reason"], "Reached");
    assert_eq!(
        v["goal_transitions"],
        serde_json::json!(["Accepted", "Planning", "Executing", "Succeeded"])
    );
    assert_eq!(v["status_after"]["commands"], 3);
    assert_eq!(v["status_after"]["rejected"], 1);
    assert_eq!(v["bad_samples"], 0);
}
