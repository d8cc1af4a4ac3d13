//! `gaitctl cancel`, `hold`, `reset`.

use crate::common::{ConnArgs, verdict_exit};
use std::process::ExitCode;

/// Options of `cancel`.
#[derive(clap::Args, Debug)]
pub struct CancelArgs {
    /// Goal id to cancel (default: whichever goal is active).
    #[arg(long)]
    goal: Option<u64>,
}

/// `cancel`.
pub fn cancel(conn: &ConnArgs, a: &CancelArgs) -> gaitd_client::Result<ExitCode> {
    let mut c = conn.connect("gaitctl")?;
    let v = c.cancel(a.goal, conn.timeout())?;
    Ok(verdict_exit("cancel", v))
}

/// `hold`.
pub fn hold(conn: &ConnArgs) -> gaitd_client::Result<ExitCode> {
    let mut c = conn.connect("gaitctl")?;
    let v = c.hold(conn.timeout())?;
    Ok(verdict_exit("hold", v))
}

/// `reset`.
pub fn reset(conn: &ConnArgs) -> gaitd_client::Result<ExitCode> {
    let mut c = conn.connect("gaitctl")?;
    let v = c.reset(conn.timeout())?;
    Ok(verdict_exit("reset", v))
}
