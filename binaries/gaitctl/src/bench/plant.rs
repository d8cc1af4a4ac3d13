//! `gaitctl bench --plant-steps N`: the plant interface's latency. gaitctl
//! starts its own daemon with an external plant in lockstep and is that
//! plant itself (the kinematic hand, so the goals it sends really run):
//! every step it publishes measurement k, then busy-polls for the command
//! answering k.
//!
//! Measured per step, wall clock: **measurement published → its command
//! received** — the whole daemon side of a lockstep step (the loop's
//! wake-up on the plant's event, the tick, the writer's wake-up, publish
//! and notify) and the two iceoryx2 hops. Beside it, in the same run and
//! namespace: a bare iceoryx2 ping-pong round trip (busy-polling, no
//! event, no tick) and the daemon's own tick compute time with the plant.

use super::reference;
use super::summary;
use crate::demo::Embedded;
use crate::plant::sim::KinematicPlant;
use gaitd_client::plant::{PlantHost, PlantModel};
use gaitd_client::shm_schema::PlantMeasurement;
use gaitd_client::{GoalSpec, GoalState, monotonic_ns};
use serde_json::json;
use std::time::{Duration, Instant};

fn err(e: impl std::fmt::Display) -> gaitd_client::Error {
    gaitd_client::Error::Ipc {
        what: "plant bench",
        why: e.to_string(),
    }
}

/// Runs `steps` lockstep steps and the reference; prints a table and JSON.
pub fn run(steps: usize, pings: usize, json_only: bool) -> gaitd_client::Result<()> {
    let bin = std::env::current_exe()
        .ok()
        .and_then(|p| p.parent().map(|d| d.join("gaitd")))
        .ok_or_else(|| err("cannot find gaitd next to gaitctl"))?;
    let config =
        "[plant]\nkind = \"shm\"\ntiming = \"lockstep\"\n[load]\ngravity = [0.0, 0.0, 0.0]\n";
    let daemon = Embedded::start(bin, config).map_err(err)?;
    let mut client = gaitd_client::Client::connect(daemon.opts.clone())?;
    let mut host = PlantHost::open(&daemon.opts)?;
    let hand = gait::HandConfig::default();
    let period = 1_000_000u64;
    let mut model = KinematicPlant::new(&hand, period, None);

    let (mut seq, mut applied, mut session) = (0u64, 0u64, 0u64);
    let mut waits = Vec::with_capacity(steps);
    let (mut goals, mut goal_id) = (0u32, 0u64);
    let t0 = Instant::now();
    for step in 0..steps + 200 {
        seq += 1;
        let mut m = PlantMeasurement::default();
        model.measure(&mut m);
        (m.seq, m.applied, m.session, m.time_ns) = (seq, applied, session, seq * period);
        let sent = monotonic_ns();
        host.send_raw(&m)?;
        let c = loop {
            if let Some(c) = host.try_command()?
                && c.answers == seq
            {
                break c;
            }
            if t0.elapsed() > Duration::from_secs(600) {
                return Err(err("the daemon stopped answering"));
            }
            std::hint::spin_loop();
        };
        if step >= 200 {
            waits.push((monotonic_ns() - sent) as f64 / 1e3);
        }
        (applied, session) = (c.seq, c.session);
        if c.flags & gaitd_client::shm_schema::command_flags::ENABLE != 0 {
            model.apply(&c);
        }
        model.step(period as f64 * 1e-9);
        // Keep the hand busy: a new goal whenever the last one ended.
        if step % 500 == 0
            && let Some(s) = client.latest_status()?
            && (goal_id == 0 || s.goal_state().is_ok_and(GoalState::is_terminal))
        {
            goal_id = client.send_command(
                GoalSpec::turn([0.3, -0.4, 1.0], 1.2)
                    .map_err(err)?
                    .to_command(client.client_id(), goals as u64 + 1),
            )?;
            goals += 1;
        }
    }
    let status = client.wait_status(Duration::from_secs(2))?;
    let settings = client.settings().clone();
    let bare = reference::measure(
        pings,
        0,
        1000,
        (settings.root_path.as_str(), settings.file_prefix.as_str()),
        None,
    )?;
    let t = status.timing;
    let mut rtt: Vec<f64> = bare.half_rtt.iter().map(|h| 2.0 * h).collect();
    let report = json!({
        "plant_steps": waits.len(),
        "goals_sent": goals,
        "measurement_to_command_us": summary(&mut waits),
        "bare_iceoryx2_round_trip_us": summary(&mut rtt),
        "daemon_tick_compute_us": {
            "p50": t.compute_p50_ns as f64 / 1e3,
            "p99": t.compute_p99_ns as f64 / 1e3,
            "max": t.compute_max_ns as f64 / 1e3,
        },
    });
    if !json_only {
        let row = |what: &str, v: &serde_json::Value| {
            println!(
                "{what:<48} p50 {:>8.1} µs   p99 {:>8.1} µs   max {:>9.1} µs",
                v["p50"].as_f64().unwrap_or(f64::NAN),
                v["p99"].as_f64().unwrap_or(f64::NAN),
                v["max"].as_f64().unwrap_or(f64::NAN)
            );
        };
        println!(
            "plant interface, lockstep, {} steps ({goals} goals):",
            waits.len()
        );
        row(
            "measurement published → command received",
            &report["measurement_to_command_us"],
        );
        row(
            "bare iceoryx2 ping-pong round trip",
            &report["bare_iceoryx2_round_trip_us"],
        );
        row(
            "daemon tick compute (with the plant)",
            &report["daemon_tick_compute_us"],
        );
        println!();
    }
    println!("{report}");
    drop(client);
    drop(host);
    drop(daemon);
    Ok(())
}
