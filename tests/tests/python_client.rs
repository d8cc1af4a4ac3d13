//! A Python client (PyPI `iceoryx2`, the daemon's version) built only from
//! the documented layout (`shm_schema/LAYOUT.md`) sends commands and reads
//! the status of a real daemon. The script checks its ctypes mirror
//! against the document field by field before talking to the daemon.
//!
//! Python comes from `GAITD_ORACLE_PYTHON` or `<repo>/.venv-oracles/bin/python`
//! (made by `.ci/install`); the test fails with instructions if neither exists.

use gaitd_tests::{TestDaemon, oracle_python, repo_root};
use std::process::Command;

#[test]
fn python_client_sends_commands_and_reads_status() {
    let py = oracle_python();
    let d = TestDaemon::start("python");
    let _wait_until_up = d.client();
    let out = Command::new(py)
        .arg(repo_root().join("tests/python/gaitd_client.py"))
        .arg("--layout")
        .arg(repo_root().join("shm_schema/LAYOUT.md"))
        .args(["--prefix", &d.prefix])
        .arg("--root")
        .arg(format!("{}/", d.root.display()))
        .args(["--file-prefix", &d.file_prefix])
        .output()
        .expect("run python");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "python client failed:\n{stdout}\n{stderr}"
    );
    let v: serde_json::Value = serde_json::from_str(stdout.trim()).expect("one JSON object");
    assert_eq!(v["iceoryx2"], shm_schema::ICEORYX2_VERSION);
    assert_eq!(v["status"]["daemon_state"], 1, "Running");
    assert_eq!(v["status"]["phase"], 1, "Hold");
    for r in v["status"]["contact_radii"].as_array().unwrap() {
        assert!((r.as_f64().unwrap() - 0.5).abs() < 1e-12);
    }
    assert_eq!(v["hold"]["code"], "Accepted");
    assert_eq!(v["goal"]["code"], "Accepted");
    assert_eq!(v["goal"]["goal_id"], 1);
    assert_eq!(v["nan_goal"]["reason"], "NonFiniteQuaternion");
    assert_eq!(v["status_after"]["commands"], 3);
    assert_eq!(v["status_after"]["rejected"], 1);
}
