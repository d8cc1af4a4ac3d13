//! A user's mistake — a bad config key or section, a missing file, a bad
//! setting, no daemon, a bad argument — gives its message and a non-zero
//! exit, never a backtrace, also with `RUST_BACKTRACE=1` (backtraces are
//! for bugs, which panic).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `bin` with `args`, RUST_BACKTRACE=1 and no GAITD_* locations.
fn run(bin: &str, args: &[&str]) -> Output {
    let mut cmd = Command::new(gaitd_tests::workspace_bin(bin));
    cmd.args(args)
        .env("RUST_BACKTRACE", "1")
        .env_remove("NOTIFY_SOCKET");
    for k in [
        "GAITD_PREFIX",
        "GAITD_IPC_CONFIG",
        "GAITD_IPC_ROOT",
        "GAITD_IPC_FILE_PREFIX",
    ] {
        cmd.env_remove(k);
    }
    cmd.output().unwrap()
}

/// Failed, with every one of `names` in its message and no backtrace.
fn assert_user_error(what: &str, out: &Output, names: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{what}: exit status 0\n{err}");
    for n in names {
        assert!(err.contains(n), "{what}: `{n}` not named in:\n{err}");
    }
    let lower = err.to_lowercase();
    assert!(
        !lower.contains("backtrace") && !lower.contains("panicked"),
        "{what}: a backtrace or panic:\n{err}"
    );
    // Frame lines of a backtrace: `  12: name` and `at src/x.rs:1:2`.
    for line in err.lines().map(str::trim_start) {
        let frame = line
            .split_once(": ")
            .is_some_and(|(n, _)| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
        let at = line.starts_with("at ") && line.contains(".rs:");
        assert!(!frame && !at, "{what}: backtrace frame `{line}` in:\n{err}");
    }
}

/// A scratch directory removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Self {
        Self(test_support::scratch_dir(&format!("cli-errors-{tag}")))
    }

    fn file(&self, name: &str, text: &str) -> String {
        let p = self.0.join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn gaitd_config_mistakes_give_a_message_not_a_backtrace() {
    let dir = Scratch::new("gaitd");
    let section = dir.file("section.toml", "[bogus]\nx = 1\n");
    let key = dir.file("key.toml", "[model]\nroll_limt_deg = 45\n");
    let value = dir.file("value.toml", "[model]\nroll_limit_deg = -5\n");
    let missing = dir.0.join("missing.toml").display().to_string();
    let cases: [(&str, &[&str], &[&str]); 5] = [
        (
            "unknown section",
            &["--config", &section, "--check-config"],
            &["bogus", &section],
        ),
        (
            "unknown key",
            &["--config", &key, "--check-config"],
            &["roll_limt_deg"],
        ),
        (
            "bad value",
            &["--config", &value, "--check-config"],
            &["model.roll_limit_deg"],
        ),
        (
            "missing file",
            &["--config", &missing, "--check-config"],
            &["cannot read config file", &missing],
        ),
        ("bad argument", &["--bogus"], &["--bogus"]),
    ];
    for (what, args, names) in cases {
        assert_user_error(what, &run("gaitd", args), names);
    }
    // The same mistake without --check-config, and one found only when
    // the daemon starts (logging is up by then).
    assert_user_error(
        "unknown section, starting",
        &run("gaitd", &["--config", &section]),
        &["bogus"],
    );
    let root = dir.file(
        "root.toml",
        "[ipc]\nservice_prefix = \"cli-errors\"\nroot_path = \"/proc/gaitd-no-such-dir/iceoryx2/\"\n\
         [rt]\nlock_memory = false\nfifo_priority = 0\n",
    );
    assert_user_error(
        "root path not creatable",
        &run("gaitd", &["--config", &root]),
        &["/proc/gaitd-no-such-dir/iceoryx2/"],
    );
}

#[test]
fn gaitctl_mistakes_give_a_message_not_a_backtrace() {
    // A namespace nobody serves.
    let d = gaitd_tests::TestDaemon::new("cli-errors", "");
    let root = format!("{}/", d.root.display());
    let ns = [
        "--prefix",
        d.prefix.as_str(),
        "--ipc-root",
        root.as_str(),
        "--ipc-file-prefix",
        d.file_prefix.as_str(),
        "--timeout",
        "0.3",
    ];
    fn with_ns<'a>(ns: &[&'a str], args: &[&'a str]) -> Vec<&'a str> {
        [ns, args].concat()
    }
    assert_user_error(
        "no daemon",
        &run("gaitctl", &with_ns(&ns, &["status"])),
        &["no gaitd running", &d.prefix],
    );
    assert_user_error(
        "bad axis",
        &run(
            "gaitctl",
            &with_ns(&ns, &["reorient", "--axis", "0,0", "--angle-deg", "10"]),
        ),
        &["--axis takes three numbers"],
    );
    assert_user_error(
        "missing iceoryx2 config",
        &run(
            "gaitctl",
            &["--ipc-config", "/nonexistent/iceoryx2.toml", "status"],
        ),
        &["/nonexistent/iceoryx2.toml"],
    );
    assert_user_error(
        "bad argument",
        &run("gaitctl", &["reorient", "--limit", "object.speed=1"]),
        &["speed"],
    );
    let fingertips = gaitd_tests::repo_root().join("deploy/gaitd.toml");
    assert_user_error(
        "the tracker model on the fingertip MuJoCo plant",
        &run(
            "gaitctl",
            &[
                "plant",
                "mujoco",
                "--config",
                fingertips.to_str().unwrap(),
                "--exact-tracker",
            ],
        ),
        &["--exact-tracker", "chain hand"],
    );
    let missing = Path::new("/nonexistent/trace.jsonl");
    assert_user_error(
        "missing trace",
        &run(
            "gaitctl",
            &["plot", missing.to_str().unwrap(), "-o", "/tmp/x.svg"],
        ),
        &["/nonexistent/trace.jsonl"],
    );
}
