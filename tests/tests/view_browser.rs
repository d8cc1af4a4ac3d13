//! The live view in a real browser: `gaitd-view` beside a daemon that turns
//! the object, its page opened in headless Chromium (`view_browser.py`).
//! The screenshots must show the ball (its orange in the 3D view) and a
//! hand that moves between two of them (3 s apart), and the view must have
//! sent frames at its rate.

use gaitd_client::GoalSpec;
use gaitd_tests::{TestDaemon, oracle_python, output_within, repo_root, workspace_bin};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::Duration;

/// Orange pixels the ball must cover in the 3D view (it covers about 60 000
/// at 1280 × 800; a page without the scene has none).
const BALL_PIXELS: f64 = 5000.0;
/// Pixels of the 3D view that must change in 3 s of a turn (the fingertips
/// and axes move; an idle view changes none); the script looks for such a
/// pair of screenshots for up to 90 s (it stops at its own MOVED_MIN, the
/// same number).
const MOVED_PIXELS: f64 = 300.0;

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port")
}

fn has_chromium() -> bool {
    let names = [
        std::env::var("GAITD_CHROMIUM").unwrap_or_default(),
        "chromium".into(),
        "chromium-browser".into(),
        "google-chrome".into(),
    ];
    names.iter().filter(|n| !n.is_empty()).any(|n| {
        Command::new("sh")
            .args(["-c", &format!("command -v {n}")])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

#[test]
fn the_live_view_shows_the_ball_and_the_hand_moving_in_a_browser() {
    if !has_chromium() {
        test_support::skip(
            "live view in a browser (view_browser)",
            "no Chromium here (.ci/install installs Debian's chromium; or set GAITD_CHROMIUM)",
        );
        return;
    }
    let d = TestDaemon::start("view");
    let (web, grpc) = (free_port(), free_port());
    let mut view = Command::new(workspace_bin("gaitd-view"))
        .args(["--prefix", &d.prefix])
        .arg("--ipc-root")
        .arg(format!("{}/", d.root.display()))
        .args(["--ipc-file-prefix", &d.file_prefix])
        .args([
            "--web-port",
            &web.to_string(),
            "--grpc-port",
            &grpc.to_string(),
        ])
        // 15 Hz: a browser rendering in software on a loaded machine keeps
        // up with it (at 30 Hz it falls tens of seconds behind there).
        .args(["--rate", "15", "--report-every", "1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start gaitd-view");
    let mut out = BufReader::new(view.stdout.take().expect("stdout"));
    let mut first = String::new();
    out.read_line(&mut first).expect("gaitd-view's first line");
    let url = first
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .unwrap_or_else(|| panic!("no address in {first:?}"))
        .to_owned();
    // The frames it reports, read as they come.
    let frames = std::thread::spawn(move || {
        let mut last = 0u64;
        for line in out.lines().map_while(Result::ok) {
            if let Some(n) = line
                .strip_prefix("gaitd-view: ")
                .and_then(|s| s.strip_suffix(" frames"))
                .and_then(|n| n.parse().ok())
            {
                last = n;
            }
        }
        last
    });
    // Two full turns: the hand moves for the whole time the browser looks.
    let mut c = d.client();
    let goal = GoalSpec::turn([0.0, 0.0, 1.0], 4.0 * std::f64::consts::PI).expect("goal");
    c.reorient(&goal, Duration::from_secs(10))
        .expect("the turn is accepted");
    // Kept after the run (the daemon's directory is not), for a look.
    let shots = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("view-shots");
    std::fs::create_dir_all(&shots).expect("screenshot dir");
    let mut browser = Command::new(oracle_python());
    browser
        .arg(repo_root().join("tests/tests/view_browser.py"))
        .arg(&url)
        .arg(&shots)
        .arg("90");
    let o = output_within(&mut browser, Duration::from_secs(180));
    let _ = view.kill();
    let _ = view.wait();
    let sent = frames.join().expect("frame reader");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "view_browser.py failed: {stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let seen: serde_json::Value = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("view_browser.py printed {stdout:?}: {e}"));
    let num = |k: &str| seen[k].as_f64().unwrap_or(f64::NAN);
    println!(
        "view: {sent} frames sent; browser: ball {} / {} px, {} px changed in 3 s, page ready after {} s, motion seen after {} s; shots in {}",
        num("ball_a"),
        num("ball_b"),
        num("changed"),
        num("waited_s"),
        num("moved_after_s"),
        shots.display()
    );
    assert!(
        num("ball_b") >= BALL_PIXELS,
        "the ball is not drawn: {seen} (screenshots in {})",
        shots.display()
    );
    assert!(
        num("changed") >= MOVED_PIXELS,
        "the hand did not move in the view: {seen} (screenshots in {})",
        shots.display()
    );
    // At 15 Hz for the ≥ 7.5 s the browser took at least.
    assert!(sent >= 100, "gaitd-view sent {sent} frames");
}
