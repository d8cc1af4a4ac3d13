//! `gaitd` command line.

use anyhow::Result;
use clap::Parser;
use gaitd::config::{DEFAULT_CONFIG_PATH, DaemonConfig};

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
}

fn main() -> Result<()> {
    let args = Args::parse();
    let cfg = DaemonConfig::load(&args.config)?;
    if args.check_config {
        println!("{}", toml::to_string_pretty(&cfg)?);
        eprintln!("config OK: {}", args.config);
        return Ok(());
    }
    anyhow::bail!("the control loop is not built yet (issue 5); only --check-config works")
}
