//! `gaitd-view`: a live 3D view of a running gaitd in the browser, or of
//! a recorded trace.
//!
//! A process of its own — the control loop never feels it: it reads the
//! status and the events over iceoryx2 like any client, decimated to the
//! view's rate ([`live`]), or a trace file the daemon wrote ([`replay`]),
//! and streams them to Rerun's web viewer, which this process serves (the
//! viewer's files over HTTP, the data over Rerun's gRPC proxy), or writes
//! them to a Rerun recording (`.rrd`, `--save`) that Rerun's viewer opens.
//! Open the address it prints; `gaitctl view` and `gaitctl demo --view`
//! start it.
//!
//! What it shows is listed in [`scene`] and [`series`].

mod frame;
mod live;
mod plan_ahead;
mod replay;
mod scene;
mod series;

use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

/// Live 3D view of a running gaitd in the browser (Rerun's web viewer),
/// or of a recorded trace; or either written to a Rerun recording.
#[derive(Parser, Debug)]
#[command(version)]
pub struct Args {
    /// Where the daemon is: local (iceoryx2), or remote through its
    /// gaitd-bridge (`--remote`), as for gaitctl.
    #[command(flatten)]
    pub conn: gaitd_client::cli::ConnArgs,
    /// Address the viewer's servers listen on (0.0.0.0 to be seen from
    /// other hosts).
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: String,
    /// HTTP port of the web viewer.
    #[arg(long, default_value_t = 9090)]
    pub web_port: u16,
    /// Port of the data stream (Rerun's gRPC proxy) the viewer reads.
    #[arg(long, default_value_t = 9876)]
    pub grpc_port: u16,
    /// Frames per second sent to the viewer (the status is sampled at this
    /// rate; events are all sent).
    #[arg(long, default_value_t = 30.0)]
    pub rate: f64,
    /// Friction angle of the cones drawn at the contacts, in degrees (the
    /// daemon's `model.friction_angle_deg`).
    #[arg(long, default_value_t = 20.0)]
    pub friction_deg: f64,
    /// Stop after this many frames (0: run until interrupted).
    #[arg(long, default_value_t = 0)]
    pub frames: u64,
    /// Print the frames sent so far every this many seconds (0: never).
    #[arg(long, default_value_t = 5.0)]
    pub report_every: f64,
    /// Show this trace instead of a running daemon: JSON lines (as the
    /// daemon's `[daemon] trace_dir` or `gaitctl plan --out` write them) or
    /// their MCAP recording (`gaitctl trace mcap`).
    #[arg(long, value_name = "TRACE")]
    pub replay: Option<PathBuf>,
    /// Write the view to this Rerun recording (`.rrd`) instead of serving
    /// it: a trace's whole view, or a live one's first `--frames` frames.
    #[arg(long, value_name = "FILE.rrd")]
    pub save: Option<PathBuf>,
}

fn main() -> ExitCode {
    let a = Args::parse();
    match run(&a) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gaitd-view: {e}");
            ExitCode::from(1)
        }
    }
}

/// The servers, then frames until `--frames` or the end of the process.
fn run(a: &Args) -> Result<(), String> {
    if !(a.rate.is_finite() && a.rate > 0.0 && a.rate <= 1000.0) {
        return Err(format!("--rate must be in (0, 1000] Hz, not {}", a.rate));
    }
    if a.save.is_some() && a.replay.is_none() && a.frames == 0 {
        return Err("--save of a live view needs --frames N (the recording ends there)".into());
    }
    let builder = rerun::RecordingStreamBuilder::new("gaitd").with_blueprint(layout());
    // What to show first: a missing daemon or a bad trace leaves no file.
    let source = match &a.replay {
        Some(path) => Source::Trace(trace_mcap::file::read(path)?, path),
        None => Source::Daemon(Box::new(live::connect(a)?)),
    };
    let (rec, web) = match &a.save {
        Some(path) => {
            let rec = builder
                .save(path)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            (rec, None)
        }
        None => {
            let (rec, web) = serve(builder, a)?;
            (rec, Some(web))
        }
    };
    match source {
        Source::Daemon(client) => live::run(&rec, *client, a)?,
        Source::Trace(trace, path) => {
            let frames = replay::run(&rec, &trace, a.rate, a.friction_deg.to_radians());
            println!("gaitd-view: {frames} frames from {}", path.display());
        }
    }
    let _ = rec.flush_with_timeout(Duration::from_secs(10));
    if let Some(path) = &a.save {
        println!("gaitd-view: wrote {}", path.display());
    } else if web.is_some() && a.replay.is_some() {
        // The viewer reads the trace from this process: keep serving.
        println!("gaitd-view: serving until interrupted");
        loop {
            std::thread::park();
        }
    }
    Ok(())
}

/// What the view shows.
enum Source<'a> {
    /// A running daemon.
    Daemon(Box<gaitd_client::Client>),
    /// A recorded trace, and its file.
    Trace(trace_mcap::file::Trace, &'a std::path::Path),
}

/// Serves the data stream and the web viewer; prints the address to open.
fn serve(
    builder: rerun::RecordingStreamBuilder,
    a: &Args,
) -> Result<(rerun::RecordingStream, Box<dyn std::any::Any>), String> {
    let rec = builder
        .serve_grpc_opts(&a.bind, a.grpc_port, rerun::ServerOptions::default())
        .map_err(|e| {
            format!(
                "cannot serve the data stream on {}:{}: {e}",
                a.bind, a.grpc_port
            )
        })?;
    let proxy = format!("rerun+http://{}:{}/proxy", a.bind, a.grpc_port);
    let web = rerun::serve_web_viewer(rerun::web_viewer::WebViewerConfig {
        bind_ip: a.bind.clone(),
        web_port: a.web_port.into(),
        connect_to: vec![proxy.clone()],
        open_browser: false,
        ..Default::default()
    })
    .map_err(|e| {
        format!(
            "cannot serve the web viewer on {}:{}: {e}",
            a.bind, a.web_port
        )
    })?;
    println!(
        "gaitd-view: open {}/?url={} in a browser",
        web.server_url(),
        percent_encode(&proxy)
    );
    // The server stops when its handle is dropped.
    Ok((rec, Box::new(web)))
}

/// The viewer's layout: the hand in 3D on the left; on the right the
/// margins, the grip forces, the tracking errors with the tick time and
/// the goal, and the events.
fn layout() -> rerun::blueprint::Blueprint {
    use rerun::blueprint::components::PanelState;
    use rerun::blueprint::{
        Blueprint, BlueprintPanel, Horizontal, SelectionPanel, Spatial3DView, TextLogView,
        TimeSeriesView, Vertical,
    };
    let plots = |name: &str, origin: &str| TimeSeriesView::new(name).with_origin(origin).into();
    Blueprint::new(
        Horizontal::new([
            Spatial3DView::new("hand").with_origin("world").into(),
            Vertical::new([
                plots("force-closure and load margins", "plots/margins"),
                plots("grip forces [N]", "plots/grip"),
                plots("tracking errors", "plots/errors"),
                Horizontal::new([
                    plots("tick compute [µs]", "plots/tick"),
                    plots("goal: remaining [deg]", "plots/goal"),
                ])
                .into(),
                TextLogView::new("events").with_origin("events").into(),
            ])
            .into(),
        ])
        .with_column_shares([0.6, 0.4]),
    )
    // The views get the page; the side panels open with a click.
    .with_blueprint_panel(BlueprintPanel::from_state(PanelState::Collapsed))
    .with_selection_panel(SelectionPanel::from_state(PanelState::Collapsed))
}

/// The viewer's `url=` argument: everything but ASCII letters and digits
/// escaped.
fn percent_encode(s: &str) -> String {
    s.bytes()
        .map(|b| {
            if b.is_ascii_alphanumeric() {
                (b as char).to_string()
            } else {
                format!("%{b:02X}")
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_proxy_address_is_escaped_as_the_viewer_reads_it() {
        assert_eq!(
            super::percent_encode("rerun+http://127.0.0.1:9876/proxy"),
            "rerun%2Bhttp%3A%2F%2F127%2E0%2E0%2E1%3A9876%2Fproxy"
        );
    }
}
