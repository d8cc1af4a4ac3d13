//! `gaitd` command line: load the config, set up IPC and the process, run
//! the loop on the main thread (SPEC §7). The start-up steps and why their
//! order matters: [`gaitd::process::startup`].

use anyhow::{Context, Result};
use clap::Parser;
use gaitd::config::{DEFAULT_CONFIG_PATH, DaemonConfig};
use gaitd::io::ipc;
use gaitd::process::hand_setup::HandSetup;
use gaitd::process::logging::{self, LogFormat};
use gaitd::process::startup::Daemon;
use gaitd::process::{check, load_check, signals};
use iceoryx2::prelude::{LogLevel, set_log_level_from_env_or};
use std::process::ExitCode;

/// gaitd: real-time finger-gaiting controller daemon.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Args {
    /// Configuration file (TOML).
    #[arg(long, default_value = DEFAULT_CONFIG_PATH)]
    config: String,
    /// Validate the configuration file, print the configuration in effect
    /// (environment overrides applied, defaults resolved) and exit.
    #[arg(long)]
    check_config: bool,
    /// Log format.
    #[arg(long, value_enum, default_value_t = LogFormat::Human)]
    log_format: LogFormat,
    /// Log level (`RUST_LOG` overrides it).
    #[arg(long, default_value = "info")]
    log_level: String,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let cfg = match load_config(&args.config) {
        Ok(cfg) => cfg,
        Err(e) => return failed(&e),
    };
    if args.check_config {
        return check_config(&cfg, &args.config)
            .map_or_else(|e| failed(&e), |()| ExitCode::SUCCESS);
    }
    logging::init(args.log_format, &args.log_level);
    // iceoryx2 prints its own diagnostics; keep them to real errors unless asked.
    set_log_level_from_env_or(LogLevel::Error);
    match serve(&cfg) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Logging is up: the error goes where the logs go, in their format.
            tracing::error!("{}", chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// Starts the daemon and runs it until SIGTERM/SIGINT.
fn serve(cfg: &DaemonConfig) -> Result<()> {
    let stop = signals::install().context("installing SIGTERM/SIGINT handlers")?;
    Daemon::start(cfg)?.run(stop);
    Ok(())
}

/// Reports a user's mistake (a bad file, key, setting): its message and
/// causes, never a backtrace — those are for bugs, which panic.
fn failed(e: &anyhow::Error) -> ExitCode {
    eprintln!("gaitd: {}", chain(e));
    ExitCode::FAILURE
}

/// The error and its causes on one line, each text once (many of our
/// errors already include their cause's text in their message).
fn chain(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text.push_str(": ");
            text.push_str(&cause);
        }
    }
    text
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

/// `--check-config`: prints the configuration in effect (environment
/// overrides applied, where the iceoryx2 resources will live); loading the
/// iceoryx2 config file it names, so a bad one fails here.
fn check_config(cfg: &DaemonConfig, path: &str) -> Result<()> {
    // A chain hand's description and start grasp are read and checked
    // (its start must hold the load within the torque box).
    let setup = HandSetup::load(cfg)?;
    let ipc = ipc::resolve_explained(&cfg.ipc)?;
    println!("{}", check::effective_config(cfg, &ipc, path)?);
    let s = &ipc.settings;
    eprintln!(
        "ipc: service prefix {}, iceoryx2 root {}, file prefix {}",
        s.service_prefix, s.root_path, s.file_prefix
    );
    if let Some(m) = &setup.chains {
        let h = m.hand();
        eprintln!(
            "hand: three finger chains; ball R = {} m, {} kg, centre {:?} m; μ = {}; the start \
             grasp holds it within every limit",
            h.object().radius,
            h.object().mass,
            h.object().centre.as_slice(),
            h.friction_mu()
        );
    }
    let load = load_check::paper_start_load(cfg);
    if setup.chains.is_none() && !load.holds() {
        let which = "the paper's start grasp (the embedded hand's, and gaitctl plant sim's)";
        eprintln!(
            "gaitd: warning: {}",
            load_check::warning(which, load.peak, &cfg.load)
        );
    }
    eprintln!("config OK: {path}");
    Ok(())
}
