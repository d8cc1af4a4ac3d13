//! `gaitd --check-config` on the shipped example and on broken files.

use std::path::Path;
use std::process::{Command, Output};

fn gaitd() -> Command {
    Command::new(gaitd_tests::workspace_bin("gaitd"))
}

/// `gaitd --config path --check-config`.
fn check_config(path: &Path) -> Output {
    gaitd()
        .arg("--config")
        .arg(path)
        .arg("--check-config")
        .output()
        .unwrap()
}

#[test]
fn shipped_example_config_is_valid() {
    let path = gaitd_tests::repo_root().join("deploy/gaitd.toml");
    let out = check_config(&path);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The effective values are printed, derived defaults included.
    let shown = String::from_utf8_lossy(&out.stdout);
    assert!(shown.contains("fifo_priority = 80\n"), "{shown}");
    assert!(shown.contains("writer_priority = 70\n"), "{shown}");
}

#[test]
fn bad_key_is_named_in_the_error() {
    let dir = std::env::temp_dir().join(format!("gaitd-check-config-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(&path, "[model]\nroll_limit_deg = -5\n").unwrap();
    let out = check_config(&path);
    std::fs::remove_dir_all(&dir).ok();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("model.roll_limit_deg"), "{err}");
}

#[test]
fn a_missing_trace_dir_is_named_in_the_error() {
    let dir = std::env::temp_dir().join(format!("gaitd-check-trace-dir-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.toml");
    std::fs::write(
        &path,
        format!(
            "[daemon]\ntrace_dir = \"{}\"\n",
            dir.join("no-such-dir").display()
        ),
    )
    .unwrap();
    let out = check_config(&path);
    std::fs::remove_dir_all(&dir).ok();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("daemon.trace_dir") && err.contains("does not exist"),
        "{err}"
    );
}

#[test]
fn missing_file_is_a_clear_error() {
    let out = check_config(Path::new("/nonexistent/gaitd.toml"));
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cannot read config file /nonexistent/gaitd.toml"),
        "{err}"
    );
}

/// A new user starting `gaitd` without arguments on a machine where the
/// service is not installed is told what to pass.
#[test]
fn no_config_anywhere_says_what_to_pass() {
    if std::path::Path::new("/etc/gaitd/gaitd.toml").exists() {
        test_support::skip(
            "check_config: the no-config message",
            "/etc/gaitd/gaitd.toml is installed here (the default path is valid)",
        );
        return;
    }
    let out = gaitd().arg("--check-config").output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no configuration at /etc/gaitd/gaitd.toml") && err.contains("--config"),
        "{err}"
    );
}

#[test]
fn shipped_iceoryx2_config_puts_resources_under_run_gaitd() {
    let out = gaitd()
        .arg("--config")
        .arg(gaitd_tests::repo_root().join("deploy/gaitd.toml"))
        .arg("--check-config")
        .env(
            "GAITD_IPC_CONFIG",
            gaitd_tests::repo_root().join("deploy/iceoryx2.toml"),
        )
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("iceoryx2 root /run/gaitd/iceoryx2/, file prefix gaitd_"),
        "{err}"
    );
}

#[test]
fn a_missing_iceoryx2_config_is_refused() {
    let out = gaitd()
        .arg("--config")
        .arg(gaitd_tests::repo_root().join("deploy/gaitd.toml"))
        .arg("--check-config")
        .env("GAITD_IPC_CONFIG", "/nonexistent/iceoryx2.toml")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/iceoryx2.toml"), "{err}");
}
