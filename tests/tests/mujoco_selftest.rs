//! The MuJoCo oracle's own self-test (tests/oracles/mujoco/selftest.sh)
//! runs with the other tests: demo plans that must pass, and negative
//! controls that must FAIL (fingertips that slide over the object instead
//! of rolling, a grip too weak to hold the object under gravity, a grasp
//! that swings about its grasp line). An oracle that stopped failing the
//! bad plans would pass every real trace too; this test catches that.

use gaitd_tests::{oracle_python, repo_root};
use std::process::Command;

/// Verdicts selftest.sh checks today: 7 plans that must pass and 4 that
/// must fail (the sliding-fingertip control with and without gravity, the
/// weak grip, the out-of-plane swap). A case added to or removed from the
/// script must change these numbers, so none is dropped unnoticed.
const EXPECTED_VERDICTS: usize = 11;
const EXPECTED_FAILING_PLANS: usize = 4;

#[test]
fn the_mujoco_oracle_passes_the_good_plans_and_fails_the_bad_ones() {
    let out = Command::new("bash")
        .arg(repo_root().join("tests/oracles/mujoco/selftest.sh"))
        .arg(oracle_python())
        .output()
        .expect("run selftest.sh");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let all = format!("{stdout}{stderr}");
    println!("{stdout}");
    assert_eq!(
        stdout.lines().last(),
        Some(format!("{EXPECTED_VERDICTS} passed, 0 failed").as_str()),
        "the MuJoCo oracle's self-test:\n{all}"
    );
    assert!(out.status.success(), "selftest.sh exit status:\n{all}");
    // Expected verdicts that were FAIL: the negative controls, failed by
    // the oracle as they must be.
    let failed_as_expected = stdout
        .lines()
        .filter(|l| l.starts_with("ok ") && l.contains(": FAIL "))
        .count();
    assert_eq!(failed_as_expected, EXPECTED_FAILING_PLANS, "{all}");
}
