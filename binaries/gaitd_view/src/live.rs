//! The view of a running daemon: its status sampled at the view's rate,
//! every event, until `--frames` or the end of the process.

use crate::Args;
use crate::frame::Frame;
use crate::scene::Scene;
use gaitd_client::Client;
use rerun::RecordingStream;
use std::time::{Duration, Instant};

/// Connects to the daemon, waiting up to `--timeout`.
pub fn connect(a: &Args) -> Result<Client, String> {
    a.conn
        .connect("gaitd-view")
        .map_err(|e| format!("no gaitd to view: {e}"))
}

/// Frames from `client` into `rec`.
pub fn run(rec: &RecordingStream, mut client: Client, a: &Args) -> Result<(), String> {
    let mut scene = Scene::new(a.friction_deg.to_radians());
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
                scene.frame(rec, &Frame::from_status(&s));
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
