//! `gaitd-view`: a live 3D view of a running gaitd in the browser.
//!
//! A process of its own — the control loop never feels it: it reads the
//! status and the events over iceoryx2 like any client, decimated to the
//! view's rate, and streams them to Rerun's web viewer, which this process
//! serves (the viewer's files over HTTP, the data over Rerun's gRPC proxy).
//! Open the address it prints; `gaitctl view` and `gaitctl demo --view`
//! start it.
//!
//! What it shows is listed in [`scene`] and [`series`].

mod scene;
mod series;

use clap::Parser;
use gaitd_client::{Client, ConnectOptions};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Live 3D view of a running gaitd in the browser (Rerun's web viewer).
#[derive(Parser, Debug)]
#[command(version)]
struct Args {
    /// Service-name prefix of the daemon [env: GAITD_PREFIX; default gaitd].
    #[arg(long)]
    prefix: Option<String>,
    /// iceoryx2 config file [env: GAITD_IPC_CONFIG].
    #[arg(long)]
    ipc_config: Option<String>,
    /// iceoryx2 root path [env: GAITD_IPC_ROOT].
    #[arg(long)]
    ipc_root: Option<String>,
    /// iceoryx2 file prefix [env: GAITD_IPC_FILE_PREFIX].
    #[arg(long)]
    ipc_file_prefix: Option<String>,
    /// Address the viewer's servers listen on (0.0.0.0 to be seen from
    /// other hosts).
    #[arg(long, default_value = "127.0.0.1")]
    bind: String,
    /// HTTP port of the web viewer.
    #[arg(long, default_value_t = 9090)]
    web_port: u16,
    /// Port of the data stream (Rerun's gRPC proxy) the viewer reads.
    #[arg(long, default_value_t = 9876)]
    grpc_port: u16,
    /// Frames per second sent to the viewer (the status is sampled at this
    /// rate; events are all sent).
    #[arg(long, default_value_t = 30.0)]
    rate: f64,
    /// Friction angle of the cones drawn at the contacts, in degrees (the
    /// daemon's `model.friction_angle_deg`).
    #[arg(long, default_value_t = 20.0)]
    friction_deg: f64,
    /// How long to wait for the daemon, in seconds.
    #[arg(long, default_value_t = 10.0)]
    timeout: f64,
    /// Stop after this many frames (0: run until interrupted).
    #[arg(long, default_value_t = 0)]
    frames: u64,
    /// Print the frames sent so far every this many seconds (0: never).
    #[arg(long, default_value_t = 5.0)]
    report_every: f64,
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
    let mut client = connect(a)?;
    let rec = rerun::RecordingStreamBuilder::new("gaitd")
        .with_blueprint(layout())
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
    let mut scene = scene::Scene::new(a.friction_deg.to_radians());
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
            scene.event(&rec, e);
        }
        match client.latest_status().unwrap_or(None) {
            Some(s) if Some(s.tick) != last_tick => {
                last_tick = Some(s.tick);
                scene.frame(&rec, &s);
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
            let _ = rec.flush_with_timeout(Duration::from_secs(2));
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

/// Connects to the daemon, waiting up to `--timeout`.
fn connect(a: &Args) -> Result<Client, String> {
    let mut o = ConnectOptions::new()
        .timeout(Duration::from_secs_f64(a.timeout.max(0.0)))
        .node_name("gaitd-view");
    o.ipc.service_prefix = a.prefix.clone();
    o.ipc.iceoryx2_config = a.ipc_config.clone();
    o.ipc.root_path = a.ipc_root.clone();
    o.ipc.file_prefix = a.ipc_file_prefix.clone();
    Client::connect(o).map_err(|e| format!("no gaitd to view: {e}"))
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
