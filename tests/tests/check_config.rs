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
    assert!(
        shown.contains("writer_priority = 70  # unset: derived from fifo_priority\n"),
        "{shown}"
    );
}

#[test]
fn bad_key_is_named_in_the_error() {
    let dir = test_support::scratch_dir("check-config");
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
    let dir = test_support::scratch_dir("check-trace-dir");
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

/// The `[ipc]` section of `--check-config`'s output.
fn ipc_section(stdout: &[u8]) -> String {
    let text = String::from_utf8_lossy(stdout);
    let body = text
        .split("\n[ipc]\n")
        .nth(1)
        .unwrap_or_else(|| panic!("no [ipc] section in:\n{text}"));
    body.split("\n[").next().unwrap_or_default().to_owned()
}

/// `--check-config` with `env` (and no other GAITD_* location variable).
fn check_shipped_config_with(env: &[(&str, &str)]) -> Output {
    let mut cmd = gaitd();
    cmd.arg("--config")
        .arg(gaitd_tests::repo_root().join("deploy/gaitd.toml"))
        .arg("--check-config");
    for k in [
        "GAITD_PREFIX",
        "GAITD_IPC_CONFIG",
        "GAITD_IPC_ROOT",
        "GAITD_IPC_FILE_PREFIX",
    ] {
        cmd.env_remove(k);
    }
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().unwrap()
}

/// The printed configuration is the one in effect: environment overrides
/// applied and defaults resolved in `[ipc]` itself (the shipped file has
/// empty strings there), each with where it came from.
#[test]
fn the_printed_ipc_section_has_the_values_in_effect() {
    let out = check_shipped_config_with(&[
        ("GAITD_PREFIX", "xyz"),
        ("GAITD_IPC_ROOT", "/tmp/gaitd-check-env/iceoryx2/"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let ipc = ipc_section(&out.stdout);
    let line = |key: &str| {
        ipc.lines()
            .find(|l| l.starts_with(&format!("{key} = ")))
            .unwrap_or_else(|| panic!("no {key} in [ipc]:\n{ipc}"))
            .to_owned()
    };
    assert_eq!(
        line("service_prefix"),
        r#"service_prefix = "xyz"  # from $GAITD_PREFIX"#
    );
    assert_eq!(
        line("root_path"),
        r#"root_path = "/tmp/gaitd-check-env/iceoryx2/"  # from $GAITD_IPC_ROOT"#
    );
    assert_eq!(line("file_prefix"), r#"file_prefix = "gaitd_"  # default"#);
    assert!(line("iceoryx2_config").starts_with(r#"iceoryx2_config = """#));

    // The shipped iceoryx2 config named in the environment decides the
    // root path and the file prefix.
    let iox = gaitd_tests::repo_root().join("deploy/iceoryx2.toml");
    let out = check_shipped_config_with(&[("GAITD_IPC_CONFIG", iox.to_str().unwrap())]);
    assert!(out.status.success());
    let ipc = ipc_section(&out.stdout);
    for want in [
        r#"service_prefix = "gaitd"  # default"#.to_owned(),
        format!(
            r#"iceoryx2_config = "{}"  # from $GAITD_IPC_CONFIG"#,
            iox.display()
        ),
        r#"root_path = "/run/gaitd/iceoryx2/"  # from the iceoryx2 config file"#.to_owned(),
        r#"file_prefix = "gaitd_"  # from the iceoryx2 config file"#.to_owned(),
    ] {
        assert!(ipc.lines().any(|l| l == want), "{want} in:\n{ipc}");
    }
}

/// A bad value from the environment is named with its variable.
#[test]
fn a_bad_environment_value_names_its_variable() {
    let out = check_shipped_config_with(&[("GAITD_PREFIX", "has space")]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("`has space`") && err.contains("$GAITD_PREFIX"),
        "{err}"
    );
}

/// The shipped TriFingerPro folder copied to a scratch folder, its
/// daemon configuration edited by `edit`; `--check-config` on it.
fn check_trifingerpro(tag: &str, edit: impl Fn(String) -> String) -> Output {
    let dir = test_support::scratch_dir(tag);
    let shipped = gaitd_tests::repo_root().join("deploy/hands/trifingerpro");
    for f in ["hand.toml", "trifingerpro.urdf"] {
        std::fs::copy(shipped.join(f), dir.join(f)).unwrap();
    }
    let cfg = std::fs::read_to_string(shipped.join("gaitd.toml")).unwrap();
    let path = dir.join("gaitd.toml");
    std::fs::write(&path, edit(cfg)).unwrap();
    let out = check_config(&path);
    std::fs::remove_dir_all(&dir).ok();
    out
}

#[test]
fn the_shipped_trifingerpro_config_is_valid() {
    let path = gaitd_tests::repo_root().join("deploy/hands/trifingerpro/gaitd.toml");
    let out = check_config(&path);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("three finger chains"), "{err}");
    assert!(err.contains("R = 0.0335 m"), "{err}");
}

/// Every finger on the ball's top: no pair holds it, the tips collide.
#[test]
fn a_chain_start_grasp_that_cannot_be_is_named() {
    let out = check_trifingerpro("check-chain-start", |c| {
        let line = c.lines().find(|l| l.starts_with("start_normals")).unwrap();
        c.replace(
            line,
            "start_normals = [[0.0, 0.1, 1.0], [0.1, 0.0, 1.0], [-0.1, 0.0, 1.0]]",
        )
    });
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("hand.start_normals"), "{err}");
    assert!(err.contains("not valid"), "{err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
}

#[test]
fn a_chain_hand_without_its_description_is_named() {
    let missing = check_trifingerpro("check-chain-missing", |c| {
        c.replace(
            "description = \"hand.toml\"",
            "description = \"no-such.toml\"",
        )
    });
    assert!(!missing.status.success());
    let err = String::from_utf8_lossy(&missing.stderr);
    assert!(err.contains("no-such.toml"), "{err}");
    let unset = check_trifingerpro("check-chain-unset", |c| {
        c.replace("description = \"hand.toml\"", "")
    });
    assert!(!unset.status.success());
    let err = String::from_utf8_lossy(&unset.stderr);
    assert!(err.contains("hand.description"), "{err}");
    // A chain hand on an external plant (joint-level) is a configuration;
    // a gain it would be commanded with that is no gain is named.
    let shm = check_trifingerpro("check-chain-shm", |c| {
        format!("{c}\n[plant]\nkind = \"shm\"\n")
    });
    assert!(
        shm.status.success(),
        "{}",
        String::from_utf8_lossy(&shm.stderr)
    );
    let gain = check_trifingerpro("check-chain-gain", |c| {
        c.replace("[hand]\n", "[hand]\njoint_kp = [9.0, -1.0, 9.0]\n")
    });
    assert!(!gain.status.success());
    let err = String::from_utf8_lossy(&gain.stderr);
    assert!(err.contains("hand.joint_kp"), "{err}");
    // The shipped configuration sets its damping; a negative one is named.
    let damping = check_trifingerpro("check-chain-damping", |c| {
        c.replace(
            "joint_damping = [0.09, 0.09, 0.05]",
            "joint_damping = [0.09, -0.09, 0.05]",
        )
    });
    assert!(!damping.status.success());
    let err = String::from_utf8_lossy(&damping.stderr);
    assert!(err.contains("hand.joint_damping"), "{err}");
}
