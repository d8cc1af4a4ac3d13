//! The view of a running daemon: its status sampled at the view's rate,
//! every event, and the path ahead from the daemon's plan paths
//! ([`crate::plan_ahead`]), until `--frames` or the end of the process.

use crate::Args;
use crate::frame::Frame;
use crate::plan_ahead;
use crate::scene::{Scene, log_ahead};
use gaitd_client::{Client, PlanPaths};
use rerun::RecordingStream;
use std::time::{Duration, Instant};

/// Connects to the daemon, waiting up to `--timeout`.
pub fn connect(a: &Args) -> Result<Client, String> {
    a.conn
        .connect("gaitd-view")
        .map_err(|e| format!("no gaitd to view: {e}"))
}

/// The daemon's plan paths, if it publishes them (if not — a daemon of
/// another build — said once, and the view goes on without).
fn plan_paths(client: &Client) -> Option<PlanPaths> {
    client
        .plan_paths()
        .map_err(|e| println!("gaitd-view: no path ahead: {e}"))
        .ok()
}

/// Frames from `client` into `rec`.
pub fn run(rec: &RecordingStream, mut client: Client, a: &Args) -> Result<(), String> {
    let mut scene = Scene::new(a.friction_deg.to_radians());
    let mut paths = plan_paths(&client);
    let (mut reconnects, mut drawn) = (client.reconnects(), false);
    let period = Duration::from_secs_f64(1.0 / a.rate);
    let (mut frames, mut last_tick) = (0u64, None);
    let mut next = Instant::now();
    let mut report = Instant::now();
    let mut quiet_since = Instant::now();
    loop {
        // A daemon that went away reads as silence: the view keeps what it
        // showed and waits for it to come back.
        let events: Vec<_> = client.events().map(Iterator::collect).unwrap_or_default();
        for e in &events {
            scene.event(rec, e);
        }
        match client.latest_status().unwrap_or(None) {
            Some(s) if Some(s.tick) != last_tick => {
                last_tick = Some(s.tick);
                let frame = Frame::from_status(&s);
                scene.frame(rec, &frame);
                if client.reconnects() != reconnects {
                    // A restarted daemon: its plan service is a new one.
                    reconnects = client.reconnects();
                    paths = plan_paths(&client);
                }
                // (The object's radius, where a fingertip touches it.)
                let big_r = frame.radii().map_or(0.0, |(big_r, _)| big_r);
                let path = paths.as_mut().and_then(|p| p.latest().ok().flatten());
                match path.and_then(|p| plan_ahead::ahead(p, &s, 1.4 * big_r)) {
                    Some((tips, axes)) => {
                        log_ahead(rec, &tips, &axes, big_r);
                        drawn = true;
                    }
                    None if drawn => {
                        log_ahead(rec, &Default::default(), &Default::default(), big_r);
                        drawn = false;
                    }
                    None => {}
                }
                frames += 1;
                quiet_since = Instant::now();
            }
            // The daemon went away (or restarted): keep the view and wait
            // for it.
            _ if quiet_since.elapsed() > Duration::from_secs(2)
                && client.ensure_connected(period).unwrap_or(false) =>
            {
                quiet_since = Instant::now();
            }
            _ => {}
        }
        if a.report_every > 0.0 && report.elapsed().as_secs_f64() >= a.report_every {
            println!("gaitd-view: {frames} frames");
            report = Instant::now();
        }
        if a.frames > 0 && frames >= a.frames {
            println!("gaitd-view: {frames} frames");
            return Ok(());
        }
        next += period;
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        } else {
            next = now;
        }
    }
}
