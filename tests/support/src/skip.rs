//! Skipped checks, made visible.
//!
//! A test that cannot run a check on this machine (SCHED_FIFO refused, a
//! file installed that changes the case, …) calls [`skip`] and runs what it
//! still can. `cargo test --quiet` hides a test's stderr, so the line also
//! goes to the file named by [`SKIP_LOG_ENV`]: `.ci/test` points it at a
//! fresh file and prints every skipped check, with the count, at the end of
//! the run.

use std::io::Write;

/// The environment variable naming the skip log (one line per skipped
/// check, appended; unset: stderr only).
pub const SKIP_LOG_ENV: &str = "GAITD_SKIP_LOG";

/// Records that `check` was not run here because of `reason`: prints
/// `SKIPPED <check>: <reason>` to stderr and appends it to the skip log.
///
/// Panics if the log is set but cannot be written: a skip must never pass
/// unseen.
pub fn skip(check: &str, reason: &str) {
    record(std::env::var_os(SKIP_LOG_ENV).as_deref(), check, reason);
}

fn record(log: Option<&std::ffi::OsStr>, check: &str, reason: &str) {
    let line = format!("SKIPPED {}: {}\n", one_line(check), one_line(reason));
    eprint!("{line}");
    if let Some(path) = log {
        // One write of one short line with O_APPEND: lines of tests running
        // in parallel, in several processes, do not interleave.
        let written = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .and_then(|mut f| f.write_all(line.as_bytes()));
        if let Err(e) = written {
            panic!(
                "cannot append to the skip log {} ({SKIP_LOG_ENV}): {e}; line: {line}",
                std::path::Path::new(&path).display()
            );
        }
    }
}

/// The text on one line (a skip is one line of the log).
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_skip_appends_one_line_to_the_log() {
        let path = std::env::temp_dir().join(format!("gaitd-skip-log-{}", std::process::id()));
        let _ = std::fs::remove_file(&path);
        record(Some(path.as_os_str()), "first check", "reason one");
        record(Some(path.as_os_str()), "second", "a reason\non two lines");
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(
            text,
            "SKIPPED first check: reason one\nSKIPPED second: a reason on two lines\n"
        );
    }

    #[test]
    #[should_panic(expected = "cannot append to the skip log")]
    fn an_unwritable_log_fails_the_test() {
        record(
            Some(std::ffi::OsStr::new("/nonexistent-dir/skips.log")),
            "c",
            "r",
        );
    }
}
