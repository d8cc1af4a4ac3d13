//! What a client of the daemon waits for (`gaitctl bench`):
//!
//! - goal → answer: a reorientation goal sent at a phase spread over the
//!   period, its answer received (the client blocks on the daemon's
//!   notification, as applications do);
//! - goal → first motion: ticks from the tick that accepted a goal to the
//!   first status showing the hand moving for it (planning included);
//! - status latency: `publish_time_ns` (stamped by the daemon's writer just
//!   before publishing) to reception by this process busy-polling, and
//!   separately blocking on the notification like applications.

use crate::common::us;
use gaitd_client::{Client, GoalFrame, GoalSpec, Status, Verdict, monotonic_ns};
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

/// Goal → answer latencies \[µs\] and how the goals were answered.
#[derive(Debug, Default)]
pub struct GoalAnswers {
    /// One per goal sent.
    pub latency_us: Vec<f64>,
    /// `"accepted"` or `"rejected <reason>"` → count.
    pub verdicts: BTreeMap<String, usize>,
}

/// Sends `n` small relative goals, each at another phase of the daemon's
/// period (`period_ns`), and cancels each accepted one.
///
/// Commands are read at the start of a tick, so a goal sent right after a
/// status (as a loop sending back to back does) always waits a whole
/// period; independent applications send at any phase.
pub fn goal_to_answer(
    c: &mut Client,
    n: usize,
    period_ns: u64,
    timeout: Duration,
) -> gaitd_client::Result<GoalAnswers> {
    let mut out = GoalAnswers {
        latency_us: Vec::with_capacity(n),
        verdicts: BTreeMap::new(),
    };
    for i in 0..n {
        let goal = GoalSpec::axis_angle(
            [0.0, 0.0, 1.0],
            0.01 * (i % 7) as f64 + 0.01,
            GoalFrame::Relative,
        )?;
        c.wait_status(timeout)?;
        // Golden-ratio sequence: phases evenly spread over [0, period).
        let phase = ((i as f64 * 0.618_033_988_75).fract() * period_ns as f64) as u64;
        let until = Instant::now() + Duration::from_nanos(phase);
        while Instant::now() < until {
            std::hint::spin_loop();
        }
        let t0 = Instant::now();
        let t = c.reorient(&goal, timeout)?;
        out.latency_us.push(t0.elapsed().as_secs_f64() * 1e6);
        let key = match t.verdict {
            Verdict::Accepted => "accepted".to_string(),
            Verdict::Rejected(r) => format!("rejected {r}"),
        };
        *out.verdicts.entry(key).or_default() += 1;
        if t.verdict == Verdict::Accepted {
            // Do not leave a goal running: the next one would preempt it anyway.
            let _ = c.cancel(Some(t.goal_id), timeout);
        }
    }
    Ok(out)
}

/// Goal → first motion, in ticks and in wall-clock milliseconds.
#[derive(Debug, Default)]
pub struct FirstMotion {
    /// Ticks from the accepting tick to the first moving status.
    pub ticks: Vec<f64>,
    /// The same seen from here \[ms\] (answer → first moving status).
    pub wall_ms: Vec<f64>,
}

/// Plans and starts `n` turns about z, measures when each starts moving,
/// cancels it and waits for rest.
pub fn goal_to_first_motion(
    c: &mut Client,
    n: usize,
    timeout: Duration,
) -> gaitd_client::Result<FirstMotion> {
    let mut out = FirstMotion {
        ticks: Vec::with_capacity(n),
        wall_ms: Vec::with_capacity(n),
    };
    for i in 0..n {
        let goal = GoalSpec::turn([0.0, 0.0, 1.0], 0.3 + 0.05 * i as f64)?;
        let t = c.reorient(&goal, timeout)?;
        if t.verdict != Verdict::Accepted {
            continue;
        }
        let deadline = Instant::now() + Duration::from_secs(10);
        let t_answer = Instant::now();
        while Instant::now() < deadline {
            if let Some(s) = c.latest_status()?
                && s.goal.goal_id == t.goal_id
                && s.phase != shm_schema::Phase::Hold.code()
            {
                out.ticks.push(s.tick.saturating_sub(t.tick) as f64);
                out.wall_ms.push(t_answer.elapsed().as_secs_f64() * 1e3);
                break;
            }
            std::hint::spin_loop();
        }
        let _ = c.cancel(Some(t.goal_id), timeout);
        wait_for_rest(c, timeout)?;
    }
    Ok(out)
}

/// Waits (at most 10 s) for a status in phase Hold.
fn wait_for_rest(c: &mut Client, timeout: Duration) -> gaitd_client::Result<()> {
    let deadline = Instant::now() + Duration::from_secs(10);
    while Instant::now() < deadline {
        if c.wait_status(timeout)?.phase == shm_schema::Phase::Hold.code() {
            break;
        }
    }
    Ok(())
}

/// The status latencies of one window of statuses, and its ends.
#[derive(Debug)]
pub struct StatusWindow {
    /// The newest status when the window started.
    pub start: Status,
    /// The newest status when the busy-polling part ended.
    pub end: Status,
    /// publish → receive, busy-polling \[µs\].
    pub publish_us: Vec<f64>,
    /// tick wake-up → receive, busy-polling \[µs\].
    pub tick_us: Vec<f64>,
    /// The daemon's compute time of each status seen \[µs\].
    pub compute_us: Vec<f64>,
    /// publish → receive, blocking on the notification \[µs\].
    pub blocking_us: Vec<f64>,
}

/// Busy-polls `n` statuses (at most 60 s), then receives `n / 5` more
/// blocking on the daemon's notification (`wait_status`, as applications
/// do: adds the wake-up of a sleeping thread). `fallback` stands in for
/// the window's ends if no status arrives.
pub fn status_window(
    c: &mut Client,
    n: usize,
    fallback: Status,
    timeout: Duration,
) -> gaitd_client::Result<StatusWindow> {
    let mut w = StatusWindow {
        start: fallback,
        end: fallback,
        publish_us: Vec::with_capacity(n),
        tick_us: Vec::with_capacity(n),
        compute_us: Vec::with_capacity(n),
        blocking_us: Vec::with_capacity(n / 5),
    };
    let mut last_tick = c.latest_status()?.map_or(0, |s| s.tick);
    w.start = c.latest_status()?.unwrap_or(fallback);
    let deadline = Instant::now() + Duration::from_secs(60);
    while w.publish_us.len() < n && Instant::now() < deadline {
        if let Some(s) = c.latest_status()?
            && s.tick != last_tick
        {
            let now = monotonic_ns();
            last_tick = s.tick;
            w.publish_us.push(us(now.saturating_sub(s.publish_time_ns)));
            w.tick_us.push(us(now.saturating_sub(s.time_ns)));
            w.compute_us.push(us(s.timing.compute_last_ns));
        } else {
            std::hint::spin_loop();
        }
    }
    w.end = c.latest_status()?.unwrap_or(fallback);
    for _ in 0..n / 5 {
        let s = c.wait_status(timeout)?;
        w.blocking_us
            .push(us(monotonic_ns().saturating_sub(s.publish_time_ns)));
    }
    Ok(w)
}
