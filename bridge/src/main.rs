//! `gaitd-bridge`: gaitd's services for remote clients over Zenoh (mutual
//! TLS, access control). See the library docs and `bridge/PROTOCOL.md`.

use anyhow::Context;
use clap::Parser;
use gaitd_bridge::commands::Commands;
use gaitd_bridge::config::Config;
use gaitd_bridge::{forward, session};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use zenoh::Wait;

/// Bridge gaitd to remote clients over Zenoh (mutual TLS, access control).
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Configuration file (TOML; see deploy/gaitd-bridge.toml).
    #[arg(long, default_value = "/etc/gaitd/gaitd-bridge.toml")]
    config: PathBuf,
    /// Check the configuration and the certificate files, print the access
    /// control in effect, and exit.
    #[arg(long)]
    check_config: bool,
    /// Log as JSON lines.
    #[arg(long)]
    log_json: bool,
}

static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    STOP.store(true, Ordering::Release);
}

/// `READY=1` / `STOPPING=1` to systemd when started by it.
fn sd_notify(state: &str) {
    let Some(path) = std::env::var_os("NOTIFY_SOCKET") else {
        return;
    };
    use std::os::unix::net::UnixDatagram;
    let Ok(sock) = UnixDatagram::unbound() else {
        return;
    };
    let bytes = path.as_encoded_bytes();
    let res = if let Some(name) = bytes.strip_prefix(b"@") {
        use std::os::linux::net::SocketAddrExt;
        std::os::unix::net::SocketAddr::from_abstract_name(name)
            .and_then(|a| sock.send_to_addr(state.as_bytes(), &a))
    } else {
        sock.send_to(state.as_bytes(), &path)
    };
    if let Err(e) = res {
        tracing::warn!("sd_notify: {e}");
    }
}

fn run(args: &Args) -> anyhow::Result<()> {
    let cfg = Config::load(&args.config)?;
    cfg.check_files()?;
    if args.check_config {
        println!(
            "{}",
            serde_json::to_string_pretty(&session::access_control(&cfg))?
        );
        return Ok(());
    }
    if cfg.identities.is_empty() {
        tracing::warn!("no [[identity]] configured: every remote client is denied");
    }
    if cfg.listens_beyond_loopback() {
        tracing::info!(listen = ?cfg.zenoh.listen, "listening beyond loopback (mutual TLS, access control)");
    }
    // SAFETY: the handler only stores to an atomic (async-signal-safe).
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
    let z = session::open(&cfg)?;
    let prefix = &cfg.zenoh.key_prefix;
    // Everything a client uses is declared before the token that tells
    // clients the bridge is there.
    let declared = Commands::declare(&z, &cfg)?;
    let publishers = forward::Publishers::declare(&cfg, &z)?;
    let _alive = z
        .liveliness()
        .declare_token(gaitd_client::remote::protocol::bridge_token_key(prefix))
        .wait()
        .map_err(|e| anyhow::anyhow!(gaitd_client::remote::zenoh_text(e)))
        .context("declaring the bridge's liveliness token")?;
    tracing::info!(listen = ?cfg.zenoh.listen, prefix, identities = cfg.identities.len(), "gaitd-bridge: ready");
    sd_notify("READY=1");
    let result = std::thread::scope(|s| {
        let commands = std::thread::Builder::new()
            .name("commands".into())
            .spawn_scoped(s, || Commands::new(&cfg).run(declared, &STOP))
            .context("spawning the command thread")?;
        let forwarded = forward::run(&cfg, publishers, &STOP);
        STOP.store(true, Ordering::Release);
        let commanded = commands
            .join()
            .unwrap_or_else(|_| Err(anyhow::anyhow!("the command thread panicked")));
        forwarded.and(commanded)
    });
    sd_notify("STOPPING=1");
    drop(_alive);
    let _ = z.close().wait();
    tracing::info!("gaitd-bridge: stopped");
    result
}

fn main() -> ExitCode {
    let args = Args::parse();
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info,zenoh=warn,zenoh_ext=warn"));
    let sub = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr);
    if args.log_json {
        sub.json().init();
    } else {
        sub.init();
    }
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // A user's mistake (config, certificates, port in use): one
            // line with its causes, no backtrace.
            eprintln!("gaitd-bridge: {e:#}");
            ExitCode::from(2)
        }
    }
}
