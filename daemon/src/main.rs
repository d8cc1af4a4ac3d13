//! `gaitd` command line: load the config, set up IPC and the process, run
//! the loop on the main thread (SPEC §7). The start-up steps and why their
//! order matters: [`gaitd::process::startup`].

use anyhow::{Context, Result};
use clap::Parser;
use gaitd::io::ipc;
use gaitd::process::config::{DEFAULT_CONFIG_PATH, DaemonConfig};
use gaitd::process::logging::{self, LogFormat};
use gaitd::process::signals;
use gaitd::process::startup::Daemon;
use iceoryx2::prelude::{LogLevel, set_log_level_from_env_or};

/// gaitd: real-time finger-gaiting controller daemon.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Configuration file (TOML).
    #[arg(long, default_value = DEFAULT_CONFIG_PATH)]
    config: String,
    /// Validate the configuration file, print the effective configuration and exit.
    #[arg(long)]
    check_config: bool,
    /// Log format.
    #[arg(long, value_enum, default_value_t = LogFormat::Human)]
    log_format: LogFormat,
    /// Log level (`RUST_LOG` overrides it).
    #[arg(long, default_value = "info")]
    log_level: String,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let cfg = load_config(&args.config)?;
    if args.check_config {
        return check_config(&cfg, &args.config);
    }
    logging::init(args.log_format, &args.log_level);
    // iceoryx2 prints its own diagnostics; keep them to real errors unless asked.
    set_log_level_from_env_or(LogLevel::Error);
    let stop = signals::install().context("installing SIGTERM/SIGINT handlers")?;
    Daemon::start(&cfg)?.run(stop);
    Ok(())
}

/// The configuration file, validated; a clear message when the service's
/// default path does not exist.
fn load_config(path: &str) -> Result<DaemonConfig> {
    if path == DEFAULT_CONFIG_PATH && !std::path::Path::new(path).exists() {
        anyhow::bail!(
            "no configuration at {path} (the service's default): pass --config FILE, \
             e.g. `gaitd --config deploy/gaitd.toml` from the source tree, or install \
             the service with deploy/install.sh"
        );
    }
    Ok(DaemonConfig::load(path)?)
}

/// `--check-config`: prints the effective configuration and where the
/// iceoryx2 resources will live.
fn check_config(cfg: &DaemonConfig, path: &str) -> Result<()> {
    // Print the effective values, derived defaults included.
    let mut shown = cfg.clone();
    shown.rt.writer_priority = Some(cfg.rt.writer_fifo_priority());
    println!("{}", toml::to_string_pretty(&shown)?);
    // Also resolve where the iceoryx2 resources will live (loads the
    // iceoryx2 config file if one is named, so a bad one fails here).
    let (_, ipc) = ipc::resolve(&cfg.ipc)?;
    eprintln!(
        "ipc: service prefix {}, iceoryx2 root {}, file prefix {}",
        ipc.service_prefix, ipc.root_path, ipc.file_prefix
    );
    eprintln!("config OK: {path}");
    Ok(())
}
