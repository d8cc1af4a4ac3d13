//! `gaitctl view`: the live 3D view in the browser — starts `gaitd-view`
//! (its own binary, so that gaitctl does not build the viewer) for the
//! daemon these flags name, local or remote (`--remote`), and waits for it.

use crate::common::ConnArgs;
use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, ExitCode, Stdio};

/// The web viewer's HTTP port, unless told otherwise.
const WEB_PORT: u16 = 9090;
/// The viewer's data stream port, unless told otherwise.
const GRPC_PORT: u16 = 9876;
/// Frames per second, unless told otherwise.
const RATE: f64 = 30.0;

/// Options.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// HTTP port of the web viewer.
    #[arg(long, default_value_t = WEB_PORT)]
    pub web_port: u16,
    /// Port of the viewer's data stream.
    #[arg(long, default_value_t = GRPC_PORT)]
    pub grpc_port: u16,
    /// Address the viewer listens on (0.0.0.0 to be seen from other hosts).
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: String,
    /// Frames per second sent to the viewer.
    #[arg(long, default_value_t = RATE)]
    pub rate: f64,
    /// gaitd-view binary (default: next to gaitctl).
    #[arg(long, value_name = "PATH")]
    pub gaitd_view: Option<PathBuf>,
}

impl Default for Args {
    fn default() -> Self {
        Self {
            web_port: WEB_PORT,
            grpc_port: GRPC_PORT,
            bind: "127.0.0.1".into(),
            rate: RATE,
            gaitd_view: None,
        }
    }
}

/// A running gaitd-view, stopped when dropped.
pub struct Running(pub Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Runs the view until it ends (Ctrl-C).
pub fn run(conn: &ConnArgs, a: &Args) -> Result<ExitCode, String> {
    let mut child = start(conn, a, Stdio::inherit())?;
    let status = child.wait().map_err(|e| e.to_string())?;
    Ok(if status.success() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// Starts gaitd-view for the daemon of `conn`; with piped output, returns
/// once it printed its address (and prints it).
pub fn start(conn: &ConnArgs, a: &Args, stdout: Stdio) -> Result<Child, String> {
    let bin = a.gaitd_view.clone().unwrap_or_else(|| {
        std::env::current_exe()
            .ok()
            .and_then(|p| p.parent().map(|d| d.join("gaitd-view")))
            .unwrap_or_else(|| PathBuf::from("gaitd-view"))
    });
    if a.gaitd_view.is_none() && !bin.exists() {
        return Err(format!(
            "{} is not built: cargo build --release -p gaitd-view (the Rerun viewer's SDK, \
             a few minutes)",
            bin.display()
        ));
    }
    let mut cmd = Command::new(&bin);
    cmd.args(view_args(conn, a)).stdout(stdout);
    // The view ends with this gaitctl, however it ends (a demo stopped by a
    // signal must not leave it holding the ports).
    // SAFETY: prctl is async-signal-safe; nothing else runs between fork
    // and exec.
    unsafe {
        use std::os::unix::process::CommandExt;
        cmd.pre_exec(|| {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    let mut child = cmd
        .spawn()
        .map_err(|e| format!("cannot start {}: {e}", bin.display()))?;
    if let Some(out) = child.stdout.take() {
        // Its first line is the address; the rest (frame counts) is dropped.
        let mut lines = BufReader::new(out).lines();
        match lines.next() {
            Some(Ok(line)) => println!("{line}"),
            _ => {
                let status = child.wait().map_err(|e| e.to_string())?;
                return Err(format!(
                    "gaitd-view ended ({status}) before it served the view"
                ));
            }
        }
        std::thread::spawn(move || lines.for_each(drop));
    }
    Ok(child)
}

/// gaitd-view's arguments for the daemon of `conn` (local or remote: the
/// same connection flags) and the view options `a`.
fn view_args(conn: &ConnArgs, a: &Args) -> Vec<std::ffi::OsString> {
    use std::ffi::OsStr;
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    let text = |v: &Option<String>| v.as_deref().map(OsStr::new).map(OsStr::to_owned);
    let path = |v: &Option<PathBuf>| v.as_deref().map(|p| p.as_os_str().to_owned());
    let flags = [
        ("--prefix", text(&conn.prefix)),
        ("--ipc-config", text(&conn.ipc_config)),
        ("--ipc-root", text(&conn.ipc_root)),
        ("--ipc-file-prefix", text(&conn.ipc_file_prefix)),
        ("--remote", text(&conn.remote)),
        ("--identity", text(&conn.identity)),
        ("--pki", path(&conn.pki)),
        ("--ca", path(&conn.ca)),
        ("--cert", path(&conn.cert)),
        ("--key", path(&conn.key)),
    ];
    for (flag, value) in flags {
        if let Some(v) = value {
            out.extend([flag.into(), v]);
        }
    }
    for (flag, value) in [
        ("--web-port", a.web_port.to_string()),
        ("--grpc-port", a.grpc_port.to_string()),
        ("--bind", a.bind.clone()),
        ("--rate", a.rate.to_string()),
        ("--timeout", conn.timeout.to_string()),
    ] {
        out.extend([flag.into(), value.into()]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        conn: ConnArgs,
    }

    fn args_for(line: &[&str]) -> Vec<String> {
        let cli = Cli::parse_from(std::iter::once("gaitctl").chain(line.iter().copied()));
        view_args(&cli.conn, &Args::default())
            .into_iter()
            .map(|a| a.to_string_lossy().into_owned())
            .collect()
    }

    #[test]
    fn the_view_gets_the_same_connection_local_or_remote() {
        let local = args_for(&["--prefix", "lab", "--ipc-root", "/run/gaitd/"]);
        assert_eq!(
            local[..4],
            ["--prefix", "lab", "--ipc-root", "/run/gaitd/"].map(String::from)
        );
        assert!(!local.contains(&"--remote".to_owned()));
        let remote = args_for(&[
            "--remote",
            "quic/robot:7460",
            "--pki",
            "pki",
            "--identity",
            "wallboard",
            "--timeout",
            "5",
        ]);
        let after = |flag: &str| {
            let i = remote
                .iter()
                .position(|a| a == flag)
                .unwrap_or_else(|| panic!("no {flag}: {remote:?}"));
            remote[i + 1].clone()
        };
        assert_eq!(after("--remote"), "quic/robot:7460");
        assert_eq!(after("--pki"), "pki");
        assert_eq!(after("--identity"), "wallboard");
        assert_eq!(after("--timeout"), "5");
        assert_eq!(after("--web-port"), "9090");
    }
}
