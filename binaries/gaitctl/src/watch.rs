//! `gaitctl watch`: a live view refreshed in place with ANSI escapes (no
//! TUI library): phase, fingers, force-closure margin, goal progress bar,
//! tick timing, and the latest events (gaits, goal transitions, faults).
//! When standard output is not a terminal (`--live`): one line per change
//! of goal, goal state or phase, and one per event.

use crate::common::{ConnArgs, code, deg, event_line, us};
use crate::progress::{Changes, LiveArg, change_line};
use gaitd_client::Client;
use gaitd_client::Status;
use shm_schema::EventKind;
use std::collections::VecDeque;
use std::fmt::Write as _;
use std::io::Write as _;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Options.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Refresh rate in Hz.
    #[arg(long, default_value_t = 20.0)]
    rate: f64,
    /// Stop after this many frames (default: until Ctrl-C).
    #[arg(long)]
    frames: Option<u64>,
    /// Latest events shown under the view (0: none; without redrawing:
    /// 0 prints no event lines).
    #[arg(long, default_value_t = 6)]
    events: usize,
    #[command(flatten)]
    live: LiveArg,
}

fn bar(fraction: f64, width: usize) -> String {
    let f = fraction.clamp(0.0, 1.0);
    let full = (f * width as f64).round() as usize;
    format!(
        "[{}{}] {:5.1} %",
        "#".repeat(full),
        "-".repeat(width - full),
        100.0 * f
    )
}

/// The view of one status. `progress` is the goal's completed fraction if
/// known; `rate` the loop rate measured by the viewer \[Hz\], if it has
/// seen enough statuses to tell.
pub fn render(s: &Status, progress: Option<f64>, rate: Option<f64>) -> String {
    let mut o = String::new();
    let t = &s.timing;
    let rate = rate.map_or_else(String::new, |r| format!("  loop {r:.0} Hz"));
    let _ = writeln!(
        o,
        "gaitd {:016x}  {}  tick {}  t {:.3} s  clients {}{rate}",
        s.instance,
        code(s.daemon_state(), s.daemon_state),
        s.tick,
        s.time_ns as f64 / 1e9,
        s.clients,
    );
    let _ = writeln!(
        o,
        "phase {:<9} fault {:<18} grasp {} margin {:.2} deg  load: grip {:.2} N margin {:+.2} N",
        code(s.phase(), s.phase),
        code(s.fault(), s.fault),
        code(s.grasp(), s.grasp),
        deg(s.grasp_margin),
        s.load_grip,
        s.load_margin,
    );
    let q = s.commanded_object_q;
    let w = s.commanded_object_omega;
    let _ = writeln!(
        o,
        "object commanded q [{:+.4} {:+.4} {:+.4} {:+.4}]  omega [{:+.3} {:+.3} {:+.3}] rad/s",
        q[0], q[1], q[2], q[3], w[0], w[1], w[2]
    );
    if s.measured_mask & shm_schema::measured::OBJECT != 0 {
        let m = s.measured_object_q;
        let _ = writeln!(
            o,
            "object measured  q [{:+.4} {:+.4} {:+.4} {:+.4}]  error {:.4} deg  (tick {})",
            m[0],
            m[1],
            m[2],
            m[3],
            deg(s.object_error),
            s.measured_tick
        );
    } else {
        let _ = writeln!(o, "object measured  -");
    }
    let g = &s.goal;
    let eta = if g.eta >= 0.0 {
        format!("{:.1} s", g.eta)
    } else {
        "?".into()
    };
    let _ = writeln!(
        o,
        "goal {} ({:x})  {} {}  remaining {:.2} deg  gaits {}/{}  eta {}",
        g.goal_id,
        g.client_id,
        code(s.goal_state(), g.state),
        code(s.goal_reason(), g.reason),
        deg(g.remaining_angle),
        g.gaits_done,
        g.gaits_planned,
        eta
    );
    let _ = writeln!(
        o,
        "progress {}",
        progress.map_or_else(|| "-".into(), |f| bar(f, 40))
    );
    let _ = writeln!(
        o,
        "finger  state      contact (hand) [m]           roll [deg]  ws margin [deg]  force cmd/meas [N]  tip err [mm]"
    );
    for (k, f) in s.fingers.iter().enumerate() {
        let c = f.contact_hand;
        let _ = writeln!(
            o,
            "f{}      {:<10} [{:+.3} {:+.3} {:+.3}]   {:+8.2}    {:8.2}         {:7.3} / {}  {}",
            k + 1,
            code(f.phase(), f.state),
            c[0],
            c[1],
            c[2],
            deg(f.roll),
            deg(f.workspace_margin),
            f.commanded_normal_force,
            if s.measured_mask & shm_schema::measured::FORCES != 0 {
                format!("{:7.3}", f.measured_normal_force)
            } else {
                "    -  ".into()
            },
            if s.measured_mask & shm_schema::measured::TIPS != 0 {
                format!("{:7.3}", f.tip_error * 1e3)
            } else {
                "-".into()
            }
        );
    }
    if s.hand == shm_schema::status::hand::CHAINS {
        let _ = writeln!(
            o,
            "finger  joints [deg]                joint margin [deg]  tip margin [deg]  links off [mm]"
        );
        for (k, f) in s.fingers.iter().enumerate() {
            let q = f.commanded_joints;
            let _ = writeln!(
                o,
                "f{}      [{:+7.2} {:+7.2} {:+7.2}]   {:8.2}            {:8.2}          {:7.2}",
                k + 1,
                deg(q[0]),
                deg(q[1]),
                deg(q[2]),
                deg(f.workspace_margin),
                deg(f.tip_margin),
                f.link_clearance * 1e3
            );
        }
    }
    let _ = writeln!(
        o,
        "tick compute last {:.1} p50 {:.1} p99 {:.1} max {:.1} us | jitter p99 {:.1} max {:.1} us | missed {}",
        us(t.compute_last_ns),
        us(t.compute_p50_ns),
        us(t.compute_p99_ns),
        us(t.compute_max_ns),
        us(t.jitter_p99_ns),
        us(t.jitter_max_ns),
        t.overruns
    );
    if let Some(line) = plant_timing_line(t) {
        let _ = writeln!(o, "{line}");
    }
    let _ = writeln!(o, "commands {}  rejected {}", s.commands, s.rejected);
    o
}

/// The timing contract with an external plant (PLANT-GUIDE.md), once it
/// was missed at all.
pub fn plant_timing_line(t: &shm_schema::Timing) -> Option<String> {
    let counts = [
        t.plant_commands_late,
        t.plant_commands_repeated,
        t.plant_measurements_late,
        t.plant_measurements_repeated,
    ];
    counts.iter().any(|n| *n > 0).then(|| {
        format!(
            "plant timing: commands late {} repeated {} | measurements late {} repeated {} | \
             misses in a row {} (max {})",
            t.plant_commands_late,
            t.plant_commands_repeated,
            t.plant_measurements_late,
            t.plant_measurements_repeated,
            t.plant_misses_in_row,
            t.plant_misses_in_row_max
        )
    })
}

/// Runs the subcommand.
pub fn run(conn: &ConnArgs, a: &Args) -> gaitd_client::Result<ExitCode> {
    let mut c = conn.connect("gaitctl")?;
    if a.live.live.redraw() {
        redraw(&mut c, conn, a)
    } else {
        lines(&mut c, conn, a)
    }
}

fn period(a: &Args) -> Duration {
    Duration::from_secs_f64(1.0 / a.rate.clamp(0.5, 100.0))
}

/// For logs and pipes: the daemon's line when it (re)appears, then a line
/// per change of goal, goal state or phase and one per event (missed
/// periods are not listed: they count in the status).
fn lines(c: &mut Client, conn: &ConnArgs, a: &Args) -> gaitd_client::Result<ExitCode> {
    let (mut changes, mut instance, mut frames) = (Changes::default(), 0, 0u64);
    let mut worst_run = 0;
    loop {
        let start = Instant::now();
        let s = match c.wait_status(conn.timeout()) {
            Ok(s) => s,
            Err(gaitd_client::Error::Timeout { .. }) => {
                println!("daemon not answering; reconnecting...");
                c.ensure_connected(conn.timeout())?;
                continue;
            }
            Err(e) => return Err(e),
        };
        if s.instance != instance {
            instance = s.instance;
            println!(
                "{}",
                render(&s, None, None).lines().next().unwrap_or_default()
            );
        }
        if changes.changed(&s) {
            println!("{}", change_line(&s));
        }
        // The plant's timing, when its longest run of misses grows.
        if s.timing.plant_misses_in_row_max > worst_run {
            worst_run = s.timing.plant_misses_in_row_max;
            if let Some(line) = plant_timing_line(&s.timing) {
                println!("{line}");
            }
        }
        for e in c.events()? {
            if a.events > 0 && e.kind() != Ok(EventKind::Overrun) {
                println!("{}", event_line(&e));
            }
        }
        frames += 1;
        if a.frames.is_some_and(|n| frames >= n) {
            return Ok(ExitCode::SUCCESS);
        }
        std::thread::sleep(period(a).saturating_sub(start.elapsed()));
    }
}

/// On a terminal: the whole view, redrawn in place.
fn redraw(c: &mut Client, conn: &ConnArgs, a: &Args) -> gaitd_client::Result<ExitCode> {
    let period = period(a);
    let mut out = std::io::stdout();
    let _ = write!(out, "\x1b[2J");
    let (mut goal, mut initial) = (0u64, 0f64);
    let mut frames = 0u64;
    let mut last_tick = None::<(u64, Instant)>;
    let mut rate = 0.0;
    let mut recent = VecDeque::with_capacity(a.events + 1);
    loop {
        let start = Instant::now();
        let s = match c.wait_status(conn.timeout()) {
            Ok(s) => s,
            Err(gaitd_client::Error::Timeout { .. }) => {
                let _ = write!(
                    out,
                    "\x1b[H\x1b[Kdaemon not answering; reconnecting...\x1b[J"
                );
                let _ = out.flush();
                c.ensure_connected(conn.timeout())?;
                continue;
            }
            Err(e) => return Err(e),
        };
        // Loop rate seen from here: ticks per wall-clock second.
        if let Some((t0, i0)) = last_tick {
            let dt = i0.elapsed().as_secs_f64();
            if dt > 0.0 && s.tick >= t0 {
                rate = (s.tick - t0) as f64 / dt;
            }
        }
        last_tick = Some((s.tick, Instant::now()));
        if s.goal.goal_id != goal {
            goal = s.goal.goal_id;
            initial = 0.0;
        }
        initial = initial.max(s.goal.remaining_angle);
        let progress = (goal != 0 && initial > 0.0).then(|| 1.0 - s.goal.remaining_angle / initial);
        // Missed periods are counted in the timing line; listing each
        // overrun would push everything else out.
        for e in c.events()? {
            if a.events > 0 && e.kind() != Ok(EventKind::Overrun) {
                if recent.len() == a.events {
                    recent.pop_front();
                }
                recent.push_back(event_line(&e));
            }
        }
        let mut view = render(&s, progress, (rate > 0.0).then_some(rate));
        if a.events > 0 {
            view.push_str("latest events\n");
            for l in &recent {
                view.push_str(l);
                view.push('\n');
            }
        }
        let view = view.replace('\n', "\x1b[K\n");
        let _ = write!(out, "\x1b[H{view}\x1b[J");
        let _ = out.flush();
        frames += 1;
        if a.frames.is_some_and(|n| frames >= n) {
            return Ok(ExitCode::SUCCESS);
        }
        std::thread::sleep(period.saturating_sub(start.elapsed()));
    }
}
