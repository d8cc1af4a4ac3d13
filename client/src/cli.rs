//! The command-line flags that say where the daemon is — local (iceoryx2)
//! or remote (gaitd-bridge over Zenoh with mutual TLS) — as one `clap`
//! argument group, so that every gaitd command-line tool (`gaitctl`,
//! `gaitd-view`) takes the same flags (feature `cli`).
//!
//! ```no_run
//! #[derive(clap::Parser)]
//! struct Args {
//!     #[command(flatten)]
//!     conn: gaitd_client::cli::ConnArgs,
//! }
//! # fn main() -> gaitd_client::Result<()> {
//! let a = <Args as clap::Parser>::parse();
//! let mut client = a.conn.connect("my-tool")?;
//! # Ok(())
//! # }
//! ```

use crate::{Client, ConnectOptions, TlsFiles};
use std::path::PathBuf;
use std::time::Duration;

/// Where the daemon is (flags override the GAITD_* environment variables).
#[derive(clap::Args, Debug, Clone)]
pub struct ConnArgs {
    /// Service-name prefix [env: GAITD_PREFIX; default gaitd].
    #[arg(long, global = true)]
    pub prefix: Option<String>,
    /// iceoryx2 config file, e.g. /etc/gaitd/iceoryx2.toml [env: GAITD_IPC_CONFIG].
    #[arg(long, global = true)]
    pub ipc_config: Option<String>,
    /// iceoryx2 root path [env: GAITD_IPC_ROOT].
    #[arg(long, global = true)]
    pub ipc_root: Option<String>,
    /// iceoryx2 file prefix [env: GAITD_IPC_FILE_PREFIX].
    #[arg(long, global = true)]
    pub ipc_file_prefix: Option<String>,
    /// How long to wait for the daemon, in seconds.
    #[arg(long, global = true, default_value_t = 2.0)]
    pub timeout: f64,
    /// A remote gaitd: its gaitd-bridge at ENDPOINT (quic/HOST:PORT, or
    /// tls/HOST:PORT over TCP), over
    /// Zenoh with mutual TLS, instead of iceoryx2 (--prefix is then the
    /// bridge's key prefix).
    #[arg(long, global = true, value_name = "ENDPOINT")]
    pub remote: Option<String>,
    /// With --remote: the directory of deploy/gaitd-certs.sh's files
    /// (ca.pem, IDENTITY.pem, IDENTITY.key).
    #[arg(long, global = true, value_name = "DIR")]
    pub pki: Option<PathBuf>,
    /// With --remote: the identity (the certificate's common name; with
    /// --pki, the files' name).
    #[arg(long, global = true)]
    pub identity: Option<String>,
    /// With --remote: the CA certificate (PEM) [default: --pki/ca.pem].
    #[arg(long, global = true, value_name = "FILE")]
    pub ca: Option<PathBuf>,
    /// With --remote: this client's certificate (PEM) [default: --pki/IDENTITY.pem].
    #[arg(long, global = true, value_name = "FILE")]
    pub cert: Option<PathBuf>,
    /// With --remote: this client's key (PEM) [default: --pki/IDENTITY.key].
    #[arg(long, global = true, value_name = "FILE")]
    pub key: Option<PathBuf>,
}

impl ConnArgs {
    /// The timeout as a duration.
    pub fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.timeout.max(0.0))
    }

    /// The TLS files of --remote.
    pub fn tls_files(&self) -> crate::Result<TlsFiles> {
        let from_pki = |ext: &str| {
            let dir = self.pki.as_ref()?;
            let name = if ext == "ca" {
                "ca.pem".to_owned()
            } else {
                format!("{}.{ext}", self.identity.as_deref()?)
            };
            Some(dir.join(name))
        };
        let pick = |given: &Option<PathBuf>, ext| given.clone().or_else(|| from_pki(ext));
        match (
            pick(&self.ca, "ca"),
            pick(&self.cert, "pem"),
            pick(&self.key, "key"),
        ) {
            (Some(ca), Some(cert), Some(key)) => Ok(TlsFiles::new(ca, cert, key)),
            _ => Err(crate::Error::Invalid(
                "--remote needs --pki DIR --identity NAME, or --ca, --cert and --key",
            )),
        }
    }

    /// The connect options these flags give, for a client called
    /// `node_name` (in the daemon's and the bridge's logs).
    pub fn options(&self, node_name: &str) -> crate::Result<ConnectOptions> {
        let mut o = match &self.remote {
            Some(endpoint) => {
                let mut o = ConnectOptions::remote(endpoint.clone(), self.tls_files()?);
                if let Some(id) = &self.identity {
                    o = o.identity(id.clone());
                }
                o
            }
            None => ConnectOptions::new(),
        }
        .timeout(self.timeout())
        .node_name(node_name);
        o.ipc.service_prefix = self.prefix.clone();
        o.ipc.iceoryx2_config = self.ipc_config.clone();
        o.ipc.root_path = self.ipc_root.clone();
        o.ipc.file_prefix = self.ipc_file_prefix.clone();
        Ok(o)
    }

    /// Connects with these options.
    pub fn connect(&self, node_name: &str) -> crate::Result<Client> {
        Client::connect(self.options(node_name)?)
    }
}
