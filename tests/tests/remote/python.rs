//! A remote Python client (`gaitd.remote.RemoteClient`, PyPI
//! `eclipse-zenoh`) through the bridge: it reads the status and sends a
//! goal that succeeds. Skipped, visibly, where the oracle Python lacks
//! `zenoh` (`pip install -e 'client/python[remote]'`).

use crate::support::{Pki, TestBridge};
use gaitd_tests::{TestDaemon, oracle_python, output_within, repo_root};
use std::process::Command;
use std::time::Duration;

fn python() -> Command {
    let mut c = Command::new(oracle_python());
    c.env("PYTHONPATH", repo_root().join("client/python"));
    c
}

#[test]
fn a_remote_python_client_sends_a_goal_and_reads_status() {
    let _one = crate::support::one_at_a_time();
    let check = "remote Python client (gaitd.remote)";
    match python().args(["-c", "import zenoh"]).output() {
        Ok(o) if o.status.success() => {}
        Ok(o) => {
            return test_support::skip(
                check,
                &format!(
                    "eclipse-zenoh is not installed in {} ({}): pip install -e 'client/python[remote]'",
                    oracle_python().display(),
                    String::from_utf8_lossy(&o.stderr)
                        .lines()
                        .last()
                        .unwrap_or("")
                ),
            );
        }
        Err(e) => return test_support::skip(check, &format!("no oracle Python: {e}")),
    }
    let pki = Pki::new("python");
    let d = TestDaemon::start("remote-python");
    let _local = d.client();
    let b = TestBridge::start(&d, &pki, "");
    // The script's own waits add up to about 90 s; a hang fails here.
    let out = output_within(
        python()
            .arg(repo_root().join("tests/python/remote_goal.py"))
            .args([&b.endpoint, &pki.dir.display().to_string(), "op", &b.prefix]),
        Duration::from_secs(150),
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "remote_goal.py failed:\n{stdout}\n{}\n--- bridge ---\n{}",
        String::from_utf8_lossy(&out.stderr),
        b.log()
    );
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or("");
    let v: serde_json::Value = serde_json::from_str(line).unwrap();
    println!("remote_goal.py: {v}");
    assert_eq!(v["accepted"], true, "{v}");
    assert_eq!(v["outcome"], "Succeeded", "{v}");
    assert!(v["status_ticks_advance"].as_bool().unwrap(), "{v}");
    assert_eq!(
        v["client_id"],
        format!("{:x}", gaitd_client::remote::protocol::client_id_for("op"))
    );
}
