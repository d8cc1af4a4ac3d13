//! `gaitctl bench --soak SECONDS`: bounded memory and numerical health over
//! a long run (SPEC §11 "daemon memory: bounded", §12 "long runs do not
//! drift").
//!
//! Streams goals at the running daemon for the given time — absolute
//! (Haar-random), relative, full turns, preemptions, cancels, holds and
//! malformed or duplicate commands — and samples the daemon's resident
//! memory (`VmRSS`, `VmHWM` from `/proc/<pid>/status`) every few seconds
//! together with its tick and missed-period counters. The report (a table
//! and JSON) gives the growth after the warm-up: iceoryx2 maps its shared
//! memory lazily and the planner's caches fill during the first goals, so
//! only growth after that counts as a leak. Nothing is asserted: it is a
//! measurement, like the rest of `bench`.

use crate::common::code;
use gaitd_client::{Client, Command, GoalFrame, GoalSpec, Verdict};
use serde_json::json;
use std::collections::BTreeMap;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// What one RSS sample saw.
#[derive(Debug, Clone, Copy)]
struct Sample {
    t_s: f64,
    tick: u64,
    rss_kb: u64,
    hwm_kb: u64,
    overruns: u64,
    goals: u64,
}

/// Reads `VmRSS` and `VmHWM` \[kB\] of `pid`.
pub fn rss_kb(pid: i32) -> Option<(u64, u64)> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let field = |name: &str| {
        text.lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|v| v.parse().ok())
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// A small deterministic generator (splitmix64): the client has no `rand`.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A Haar-random unit quaternion (Shoemake).
    fn quaternion(&mut self) -> [f64; 4] {
        let (u1, u2, u3) = (self.unit(), self.unit(), self.unit());
        let tau = std::f64::consts::TAU;
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        [
            a * (tau * u2).sin(),
            a * (tau * u2).cos(),
            b * (tau * u3).sin(),
            b * (tau * u3).cos(),
        ]
    }

    /// A random unit axis.
    fn axis(&mut self) -> [f64; 3] {
        let q = self.quaternion();
        let n = (q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt().max(1e-9);
        [q[1] / n, q[2] / n, q[3] / n]
    }
}

struct Soak<'a> {
    c: &'a mut Client,
    pid: i32,
    start: Instant,
    every: Duration,
    next_sample: Instant,
    samples: Vec<Sample>,
    goals: u64,
    outcomes: BTreeMap<String, u64>,
    verdicts: BTreeMap<String, u64>,
    min_norm: f64,
    max_norm: f64,
    quiet: bool,
}

impl Soak<'_> {
    /// Takes a sample when one is due; also checks the status's quaternion.
    fn tick(&mut self) -> gaitd_client::Result<()> {
        if let Some(s) = self.c.latest_status()? {
            let norm = |q: &[f64; 4]| q.iter().map(|x| x * x).sum::<f64>().sqrt();
            let (c, m) = (norm(&s.commanded_object_q), norm(&s.measured_object_q));
            // The farther from 1 of the two (NaN wins).
            let n = if (c - 1.0).abs() >= (m - 1.0).abs() || c.is_nan() {
                c
            } else {
                m
            };
            // NaN must show: min/max with NaN would hide it.
            if !n.is_finite() {
                self.min_norm = f64::NAN;
            } else if !self.min_norm.is_nan() {
                self.min_norm = self.min_norm.min(n);
                self.max_norm = self.max_norm.max(n);
            }
        }
        if Instant::now() < self.next_sample {
            return Ok(());
        }
        self.next_sample += self.every;
        let st = self.c.latest_status()?;
        let (rss_kb, hwm_kb) = rss_kb(self.pid).unwrap_or((0, 0));
        let s = Sample {
            t_s: self.start.elapsed().as_secs_f64(),
            tick: st.map_or(0, |s| s.tick),
            rss_kb,
            hwm_kb,
            overruns: st.map_or(0, |s| s.timing.overruns),
            goals: self.goals,
        };
        if !self.quiet {
            eprintln!(
                "soak {:>7.0} s  tick {:>9}  rss {:>7} kB  peak {:>7} kB  missed {:>6}  goals {:>5}",
                s.t_s, s.tick, s.rss_kb, s.hwm_kb, s.overruns, s.goals
            );
        }
        self.samples.push(s);
        Ok(())
    }

    /// Sends a goal and records its verdict; returns its id if accepted.
    fn goal(&mut self, g: &GoalSpec) -> gaitd_client::Result<Option<u64>> {
        let t = self.c.reorient(g, Duration::from_secs(5))?;
        self.goals += 1;
        let key = match t.verdict {
            Verdict::Accepted => "accepted".to_string(),
            Verdict::Rejected(r) => format!("rejected {r}"),
        };
        *self.verdicts.entry(key).or_default() += 1;
        Ok((t.verdict == Verdict::Accepted).then_some(t.goal_id))
    }

    /// Waits (sampling meanwhile) for the goal's outcome or `limit`.
    fn outcome(&mut self, id: u64, limit: Duration) -> gaitd_client::Result<()> {
        let deadline = Instant::now() + limit;
        let state = loop {
            self.tick()?;
            match self.c.wait_outcome(id, Duration::from_millis(250)) {
                Ok(o) => break code(Ok::<_, ()>(o.state), 0),
                Err(gaitd_client::Error::Timeout { .. }) if Instant::now() < deadline => {}
                Err(gaitd_client::Error::Timeout { .. }) => break "no outcome in time".into(),
                Err(e) => return Err(e),
            }
        };
        *self.outcomes.entry(state).or_default() += 1;
        Ok(())
    }

    /// Lets `d` pass, sampling meanwhile.
    fn pause(&mut self, d: Duration) -> gaitd_client::Result<()> {
        let end = Instant::now() + d;
        while Instant::now() < end {
            self.tick()?;
            let _ = self.c.wait_status(Duration::from_millis(50));
        }
        Ok(())
    }

    /// One round of the goal mix (`k` picks the kind).
    fn round(&mut self, k: u64, rng: &mut Rng) -> gaitd_client::Result<()> {
        let wait = Duration::from_secs(30);
        let abs = |rng: &mut Rng| GoalSpec::absolute(rng.quaternion());
        match k % 8 {
            0 => {
                if let Some(id) = self.goal(&abs(rng))? {
                    self.outcome(id, wait)?;
                }
            }
            1 => {
                let g = GoalSpec::axis_angle(
                    rng.axis(),
                    std::f64::consts::PI * rng.unit(),
                    GoalFrame::Relative,
                )?;
                if let Some(id) = self.goal(&g)? {
                    self.outcome(id, wait)?;
                }
            }
            2 => {
                let g = GoalSpec::turn(rng.axis(), std::f64::consts::TAU)?;
                if let Some(id) = self.goal(&g)? {
                    self.outcome(id, Duration::from_secs(60))?;
                }
            }
            3 => {
                // Preemption mid-motion by a newer goal.
                let first = self.goal(&abs(rng))?;
                self.pause(Duration::from_millis(200 + rng.next() % 1500))?;
                if let Some(id) = self.goal(&abs(rng))? {
                    self.outcome(id, wait)?;
                }
                if let Some(id) = first {
                    self.outcome(id, Duration::from_secs(1))?;
                }
            }
            4 | 5 => {
                let id = self.goal(&abs(rng))?;
                self.pause(Duration::from_millis(100 + rng.next() % 2000))?;
                if k % 8 == 4 {
                    self.c.cancel(None, Duration::from_secs(5))?;
                } else {
                    self.c.hold(Duration::from_secs(5))?;
                }
                if let Some(id) = id {
                    self.outcome(id, wait)?;
                }
            }
            6 => {
                // Garbage and duplicates: answered, never executed.
                let me = self.c.client_id();
                for cmd in [
                    Command::goal(me, 1, GoalFrame::Absolute, [f64::NAN, 0.0, 0.0, 0.0]),
                    Command::goal(me, 1, GoalFrame::Absolute, [1.0, 0.0, 0.0, 0.0]),
                    Command {
                        kind: 99,
                        ..Command::hold(me)
                    },
                ] {
                    let req = self.c.send_command(cmd)?;
                    let a = self.c.wait_answer(req, Duration::from_secs(5))?;
                    let key = match a.verdict() {
                        Ok(Verdict::Accepted) => "accepted".to_string(),
                        Ok(Verdict::Rejected(r)) => format!("rejected {r}"),
                        Err(_) => "undecodable answer".into(),
                    };
                    *self.verdicts.entry(key).or_default() += 1;
                }
            }
            _ => {
                let g = GoalSpec::turn([0.0, 0.0, 1.0], -std::f64::consts::FRAC_PI_2)?;
                if let Some(id) = self.goal(&g)? {
                    self.outcome(id, wait)?;
                }
            }
        }
        Ok(())
    }
}

/// Least-squares slope of `y` over `x`.
fn slope(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len() as f64;
    if x.len() < 3 {
        return None;
    }
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Runs the soak for `seconds` (sampling every `every`, growth counted
/// after `warmup`) and prints the report.
pub fn run(
    c: &mut Client,
    seconds: f64,
    every: Duration,
    warmup: Duration,
    json_only: bool,
) -> gaitd_client::Result<ExitCode> {
    let pid = c.daemon_pid().ok_or(gaitd_client::Error::Invalid(
        "no daemon process found in this namespace (RSS cannot be sampled)",
    ))?;
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(seconds.max(0.0));
    let first = c.wait_status(Duration::from_secs(5))?;
    let mut s = Soak {
        c,
        pid,
        start,
        every,
        next_sample: start,
        samples: Vec::new(),
        goals: 0,
        outcomes: BTreeMap::new(),
        verdicts: BTreeMap::new(),
        min_norm: f64::INFINITY,
        max_norm: 0.0,
        quiet: json_only,
    };
    let mut rng = Rng(0x5eed_50a4 ^ first.instance);
    let mut k = 0;
    while Instant::now() < end {
        s.round(k, &mut rng)?;
        k += 1;
    }
    // A final sample at the end.
    s.next_sample = Instant::now();
    s.tick()?;
    let last = s.c.latest_status()?.unwrap_or(first);
    let bad = s.c.bad_samples();
    let warm: Vec<&Sample> = s
        .samples
        .iter()
        .filter(|x| x.t_s >= warmup.as_secs_f64())
        .collect();
    let growth = match (warm.first(), warm.last()) {
        (Some(a), Some(b)) => Some(b.rss_kb as i64 - a.rss_kb as i64),
        _ => None,
    };
    let max_after = warm.iter().map(|x| x.rss_kb).max();
    let xs: Vec<f64> = warm.iter().map(|x| x.t_s / 3600.0).collect();
    let ys: Vec<f64> = warm.iter().map(|x| x.rss_kb as f64).collect();
    let table: Vec<_> = s
        .samples
        .iter()
        .map(|x| {
            json!({"t_s": x.t_s, "tick": x.tick, "rss_kb": x.rss_kb, "hwm_kb": x.hwm_kb,
                   "missed_periods": x.overruns, "goals_sent": x.goals})
        })
        .collect();
    let ticks = last.tick.saturating_sub(first.tick);
    let report = json!({
        "soak_s": start.elapsed().as_secs_f64(),
        "daemon_pid": pid,
        "ticks": ticks,
        "missed_periods": last.timing.overruns - first.timing.overruns,
        "goals_sent": s.goals,
        "goal_verdicts": s.verdicts,
        "goal_outcomes": s.outcomes,
        "object_q_norm_min": s.min_norm,
        "object_q_norm_max": s.max_norm,
        "undecodable_samples": bad,
        "tick_compute_ns": {"p50": last.timing.compute_p50_ns, "p99": last.timing.compute_p99_ns,
                            "max": last.timing.compute_max_ns, "since": "daemon start"},
        "warmup_s": warmup.as_secs_f64(),
        "rss_after_warmup_kb": warm.first().map(|x| x.rss_kb),
        "rss_final_kb": warm.last().map(|x| x.rss_kb),
        "rss_max_after_warmup_kb": max_after,
        "rss_growth_after_warmup_kb": growth,
        "rss_slope_after_warmup_kb_per_h": slope(&xs, &ys),
        "rss_peak_kb": s.samples.last().map(|x| x.hwm_kb),
        "samples": table,
    });
    if !json_only {
        println!(
            "gaitctl bench --soak: {:.0} s, {ticks} ticks, {} goals, daemon pid {pid}",
            report["soak_s"].as_f64().unwrap_or(0.0),
            s.goals
        );
        println!(
            "{:>8} {:>10} {:>10} {:>10} {:>8} {:>7}",
            "t [s]", "tick", "RSS [kB]", "peak [kB]", "missed", "goals"
        );
        for x in &s.samples {
            println!(
                "{:>8.0} {:>10} {:>10} {:>10} {:>8} {:>7}",
                x.t_s, x.tick, x.rss_kb, x.hwm_kb, x.overruns, x.goals
            );
        }
        println!("goal verdicts: {}", report["goal_verdicts"]);
        println!("goal outcomes: {}", report["goal_outcomes"]);
        println!(
            "object quaternion norm over sampled statuses: [{:.15}, {:.15}]; undecodable samples: {bad}",
            s.min_norm, s.max_norm
        );
        println!(
            "RSS after {:.0} s warm-up: {} kB -> final {} kB (growth {} kB, max {} kB, slope {} kB/h)",
            warmup.as_secs_f64(),
            report["rss_after_warmup_kb"],
            report["rss_final_kb"],
            report["rss_growth_after_warmup_kb"],
            report["rss_max_after_warmup_kb"],
            report["rss_slope_after_warmup_kb_per_h"]
                .as_f64()
                .map_or("-".into(), |v| format!("{v:.1}")),
        );
        println!();
    }
    println!("{report}");
    Ok(ExitCode::SUCCESS)
}
