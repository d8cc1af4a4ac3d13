//! Live views without a terminal: `gaitctl demo`, `reorient --wait` and
//! `watch` with standard output piped (a log file, a CI job) print one
//! line per change of phase or goal state — no carriage returns, no ANSI
//! escapes — so `gaitctl demo > log` is a readable log.

use gaitd_tests::TestDaemon;
use std::process::Output;

/// Standard output, after checking that the command succeeded and that
/// neither stream redraws anything.
fn log_text(what: &str, out: &Output) -> String {
    let (text, err) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{what} failed:\n{text}\n{err}");
    for (stream, s) in [("stdout", text.as_str()), ("stderr", &err)] {
        assert!(
            !s.contains('\r'),
            "{what}: carriage return on {stream}:\n{s:?}"
        );
        assert!(
            !s.contains('\x1b'),
            "{what}: ANSI escape on {stream}:\n{s:?}"
        );
    }
    text
}

/// A weightless object and every motion limit scaled as time halved.
const FAST_WEIGHTLESS: &str = "[load]\ngravity = [0.0, 0.0, 0.0]\n\
    [limits.object]\nvelocity = 2.0\nacceleration = 16.0\njerk = 320.0\n\
    [limits.fingertip]\nvelocity = 1.0\nacceleration = 16.0\njerk = 320.0\n\
    [limits.rolling]\nvelocity = 4.0\nacceleration = 32.0\njerk = 640.0\n";

/// Lines showing `goal` in `state` and the phases that appear for it.
fn phase_lines<'a>(text: &'a str, goal: &str, state: &str) -> Vec<&'a str> {
    text.lines()
        .filter(|l| l.contains(&format!("goal {goal} {state}")) && l.contains(" phase "))
        .collect()
}

#[test]
fn reorient_wait_prints_a_line_per_change_when_piped() {
    let d = TestDaemon::start("progress-reorient");
    let out = d
        .gaitctl()
        .args([
            "reorient",
            "--axis",
            "0,0,1",
            "--angle-deg",
            "90",
            "--relative",
            "--wait",
        ])
        .output()
        .unwrap();
    let text = log_text("reorient --wait", &out);
    let executing = phase_lines(&text, "1", "Executing");
    // Rolling to a pair, then rotations with gaits between them.
    for phase in ["Roll", "Rotate", "Place", "Lift"] {
        assert!(
            executing
                .iter()
                .any(|l| l.contains(&format!("phase {phase} "))),
            "no line for phase {phase}:\n{text}"
        );
    }
    // One line per change, not per poll.
    for pair in executing.windows(2) {
        let phase = |l: &str| {
            l.split(" phase ")
                .nth(1)
                .and_then(|p| p.split_whitespace().next())
                .map(str::to_owned)
        };
        assert_ne!(
            phase(pair[0]),
            phase(pair[1]),
            "a line without a change:\n{text}"
        );
    }
    assert!(!phase_lines(&text, "1", "Succeeded").is_empty(), "{text}");
    assert_eq!(
        text.lines().last(),
        Some("goal 1: Succeeded (Reached)"),
        "{text}"
    );
}

#[test]
fn watch_prints_lines_when_piped() {
    let d = TestDaemon::start("progress-watch");
    let out = d
        .gaitctl()
        .args(["watch", "--frames", "3"])
        .output()
        .unwrap();
    let text = log_text("watch", &out);
    let first = text.lines().next().unwrap_or_default();
    assert!(
        first.starts_with("gaitd ") && first.contains("Running"),
        "{text}"
    );
    assert_eq!(
        text.lines().filter(|l| l.contains(" phase Hold")).count(),
        1,
        "a line per change, and nothing changed:\n{text}"
    );
    assert!(
        text.contains("DaemonStarted"),
        "the event history as lines:\n{text}"
    );
}

/// The README's headline command against a running daemon, into a log.
#[test]
fn demo_into_a_log_is_readable() {
    // A weightless object, as the demo starts its own daemon without
    // `--gravity`. The motion limits scaled as time halved
    // (velocity ×2, acceleration ×4, jerk ×8): this test reads what the
    // demo prints, and the scenario takes 21 s instead of 43 s.
    let mut d = TestDaemon::new("progress-demo", FAST_WEIGHTLESS);
    d.spawn();
    let out = d.gaitctl().arg("demo").output().unwrap();
    let text = log_text("demo", &out);
    assert!(text.contains("using the running gaitd"), "{text}");
    for (goal, label) in [
        ("1", "== a full turn about z"),
        ("2", "== a full turn about x"),
    ] {
        assert!(text.contains(label), "{text}");
        let executing = phase_lines(&text, goal, "Executing");
        assert!(
            executing.iter().any(|l| l.contains("phase Rotate ")) && executing.len() >= 4,
            "goal {goal}: its phases as lines:\n{text}"
        );
        assert!(!phase_lines(&text, goal, "Succeeded").is_empty(), "{text}");
    }
    assert!(
        text.contains("   substitution: "),
        "gait events as lines:\n{text}"
    );
    assert!(text.contains("summary: succeeded"), "{text}");
}

/// The hand time (s) of a status line `t   12.345 s  tick …`.
fn line_time(line: &str) -> f64 {
    line.split_whitespace()
        .nth(1)
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no time in {line:?}"))
}

/// The first number after `key` in `line` ("after 23.50 s …" → 23.50).
fn number_after(line: &str, key: &str) -> f64 {
    line.split(key)
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no number after {key:?} in {line:?}"))
}

/// `gaitctl demo --plant sim`: the kinematic hand out of process, in
/// lockstep, runs many times faster than real time. The time each goal
/// took, and the summary's, are the hand's (the daemon's clock, which the
/// plant drives): bracketed by the hand times of the status lines printed
/// around the goal — not the wall time, a tenth of it here.
#[test]
fn demo_on_a_lockstep_plant_reports_the_hands_time() {
    let out = gaitd_tests::output_within(
        std::process::Command::new(gaitd_tests::workspace_bin("gaitctl"))
            .args(["demo", "--plant", "sim"]),
        std::time::Duration::from_secs(300),
    );
    let text = log_text("demo --plant sim", &out);
    let ends: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("   Succeeded (Reached) after "))
        .collect();
    assert_eq!(ends.len(), 2, "{text}");
    // The plant's clock starts at 0; goal 2 is sent after goal 1's last
    // line.
    let mut before = 0.0;
    let mut sum = 0.0;
    for (goal, end) in ["1", "2"].into_iter().zip(ends) {
        let lines: Vec<f64> = text
            .lines()
            .filter(|l| l.starts_with("t ") && l.contains(&format!(" goal {goal} ")))
            .map(line_time)
            .collect();
        assert!(lines.len() >= 3, "goal {goal}:\n{text}");
        let (first, running, last) = (lines[0], lines[lines.len() - 2], lines[lines.len() - 1]);
        let took = number_after(end, "after ");
        // It ran at least from its first line to its last one before
        // the end, and at most from the line before it to its end line.
        assert!(
            took >= running - first - 0.01 && took <= last - before + 0.01,
            "goal {goal}: {took} s, not within [{:.3}, {:.3}] s of the hand's clock:\n{text}",
            running - first,
            last - before
        );
        before = last;
        sum += took;
    }
    let summary = text
        .lines()
        .find(|l| l.starts_with("summary: succeeded"))
        .unwrap_or_else(|| panic!("{text}"));
    let total = number_after(summary, "2 full turns in ");
    assert!(
        (total - sum).abs() < 0.02,
        "{summary}: the goals took {sum} s"
    );
}
