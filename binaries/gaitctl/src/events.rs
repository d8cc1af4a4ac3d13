//! `gaitctl events`: the daemon's event history, then (with `--follow`)
//! new events as they come.

use crate::common::{ConnArgs, event_json, event_line};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Options.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Keep printing new events.
    #[arg(long, short)]
    follow: bool,
    /// With --follow: stop after this many seconds.
    #[arg(long)]
    duration: Option<f64>,
    /// One JSON object per line (every field; codes as names).
    #[arg(long)]
    json: bool,
}

fn print(e: &shm_schema::Event, json: bool) {
    if json {
        println!("{}", event_json(e));
    } else {
        println!("{}", event_line(e));
    }
}

/// Runs the subcommand.
pub fn run(conn: &ConnArgs, a: &Args) -> gaitd_client::Result<ExitCode> {
    let mut c = conn.connect("gaitctl")?;
    if c.is_remote() {
        // The bridge's history answers a query: print until it is quiet.
        while let Some(e) = c.next_event(Duration::from_millis(300))? {
            print(&e, a.json);
        }
    } else {
        // History arrives with the connection; give it a moment to land.
        std::thread::sleep(Duration::from_millis(20));
    }
    for e in c.events()? {
        print(&e, a.json);
    }
    if a.follow {
        // On stderr, so that piped events stay one JSON object per line.
        eprintln!("(following events; Ctrl-C to stop)");
        let end = a
            .duration
            .map(|d| Instant::now() + Duration::from_secs_f64(d));
        let mut holes = Vec::new();
        loop {
            if end.is_some_and(|t| Instant::now() >= t) {
                break;
            }
            // Remote: events that never arrived (a bridge restart), said.
            let now = c.event_holes();
            if now != holes {
                for (instance, first, last) in now.iter().filter(|h| !holes.contains(h)) {
                    eprintln!(
                        "(missed events {first}..={last} of daemon instance {instance:016x})"
                    );
                }
                holes = now;
            }
            if let Some(e) = c.next_event(Duration::from_millis(200))? {
                print(&e, a.json);
            } else if !c.daemon_alive()? {
                c.ensure_connected(conn.timeout())?;
                eprintln!(
                    "(reconnected to daemon instance {:016x})",
                    c.daemon_instance()
                );
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
