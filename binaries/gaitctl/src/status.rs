//! `gaitctl status`: the latest status once.

use crate::common::{ConnArgs, status_json};
use crate::watch::render;
use std::process::ExitCode;

/// Options.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Print JSON instead of the human view.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand.
pub fn run(conn: &ConnArgs, a: &Args) -> gaitd_client::Result<ExitCode> {
    let mut c = conn.connect("gaitctl")?;
    let s = c.wait_status(conn.timeout())?;
    if a.json {
        println!("{}", status_json(&s));
    } else {
        print!("{}", render(&s, None, None));
    }
    Ok(ExitCode::SUCCESS)
}
