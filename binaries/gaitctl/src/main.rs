//! `gaitctl`: command line for gaitd (SPEC §8).
//!
//! Against a running daemon, local or remote (`--remote`, through
//! gaitd-bridge): status, live view, goals, cancel/hold/reset, events and
//! benchmarks, all through the `gaitd_client` library. Without one: offline
//! planning and execution on the embedded kinematic hand (the `gait`
//! crate), trace export (JSON lines, MCAP through `trace_mcap`) and plots
//! (resvg), and plants for a daemon with
//! `[plant] kind = "shm"`. The planning and plotting dependencies are this
//! crate's alone: the client library does not carry them.
//!
//! One module per subcommand; add a new one by adding a variant to [`Cmd`]
//! and a module with a `run`.

mod bench;
mod common;
mod control;
mod demo;
mod events;
mod offline;
mod plan;
mod plant;
mod plot;
mod progress;
mod reorient;
mod status;
mod trace;
mod view;
mod watch;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Talk to a running gaitd.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Cli {
    #[command(flatten)]
    conn: common::ConnArgs,
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand, Debug)]
enum Cmd {
    /// Print the latest status once.
    Status(status::Args),
    /// Live view of the daemon's state (Ctrl-C to quit).
    Watch(watch::Args),
    /// Send a reorientation goal.
    Reorient(reorient::Args),
    /// Cancel the active goal (or a given one).
    Cancel(control::CancelArgs),
    /// Stop any motion and hold the grasp.
    Hold,
    /// Clear a fault.
    Reset,
    /// Print events (the daemon's history first).
    Events(events::Args),
    /// Latency benchmarks against the running daemon (`--load-seconds`:
    /// missed periods idle vs under client load; `--soak`: memory over a long run).
    Bench(bench::Args),
    /// The paper's scenario against gaitd (starts an embedded daemon if none
    /// is running), with live progress and a summary.
    Demo(demo::Args),
    /// Plan and execute offline (no daemon) on the embedded kinematic hand;
    /// export a gait-trajectory/1 trace.
    Plan(plan::Args),
    /// Draw a trace (JSON lines or its MCAP recording): contact paths on
    /// the sphere, rotation, force closure, finger states (SVG or PNG).
    Plot(plot::Args),
    /// Convert a trace: `trace mcap TRACE -o FILE.mcap` writes an MCAP
    /// recording (Foxglove, ROS 2 tools, Rerun).
    Trace(trace::Args),
    /// Run a plant out of process for a daemon with `[plant] kind = "shm"`:
    /// `sim` (the kinematic hand) or `mujoco` (the MuJoCo physics hand).
    Plant(plant::Args),
    /// The live 3D view in the browser (starts gaitd-view): the hand, the
    /// contacts and their paths, friction cones, forces, margins, errors
    /// and events as the daemon runs.
    View(view::Args),
    /// Internal: the echo side of the bench's iceoryx2 ping-pong.
    #[command(hide = true, name = "__pong")]
    Pong(bench::PongArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.cmd {
        Cmd::Status(a) => status::run(&cli.conn, &a),
        Cmd::Watch(a) => watch::run(&cli.conn, &a),
        Cmd::Reorient(a) => reorient::run(&cli.conn, &a),
        Cmd::Cancel(a) => control::cancel(&cli.conn, &a),
        Cmd::Hold => control::hold(&cli.conn),
        Cmd::Reset => control::reset(&cli.conn),
        Cmd::Events(a) => events::run(&cli.conn, &a),
        Cmd::Bench(a) => bench::run(&cli.conn, &a),
        Cmd::Demo(a) => return offline_exit(demo::run(&cli.conn, &a)),
        Cmd::Plan(a) => return offline_exit(plan::run(&a)),
        Cmd::Plot(a) => return offline_exit(plot::run(&a)),
        Cmd::Trace(a) => return offline_exit(trace::run(&a)),
        Cmd::Plant(a) => return plant::main(&cli.conn, &a),
        Cmd::View(a) => return offline_exit(view::run(&cli.conn, &a)),
        Cmd::Pong(a) => bench::pong(&a),
    };
    result.unwrap_or_else(|e| failed(&e))
}

/// Exit code of an offline subcommand (no daemon involved).
fn offline_exit(r: Result<ExitCode, String>) -> ExitCode {
    r.unwrap_or_else(|e| {
        eprintln!("gaitctl: {e}");
        ExitCode::from(2)
    })
}

/// Reports a user's mistake (no daemon, a bad argument, setting or file):
/// the message and its causes on one line, exit code 2. Never a backtrace:
/// those are for bugs, which panic.
fn failed(e: &dyn std::error::Error) -> ExitCode {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let c_text = c.to_string();
        // Most messages already include their cause's text.
        if !text.contains(&c_text) {
            text.push_str(": ");
            text.push_str(&c_text);
        }
        cause = c.source();
    }
    eprintln!("gaitctl: {text}");
    ExitCode::from(2)
}
