//! Remote clients in the end-to-end tests: a private CA made with
//! `deploy/gaitd-certs.sh`, a `gaitd-bridge` process beside a
//! [`TestDaemon`], client options and `gaitctl --remote` for an identity.
//!
//! Every bridge listens on loopback only, on a port picked free for it,
//! under a key prefix of its own (so parallel tests never hear each
//! other), and is killed when dropped.

use gaitd_client::{Client, ConnectOptions, TlsFiles};
use gaitd_tests::{TestDaemon, repo_root, workspace_bin};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// One remote test at a time: each runs a daemon, a bridge and several
/// Zenoh clients, and in parallel on two cores (debug builds) they starve
/// each other until queries time out. Held for the whole test.
pub fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(report_panics_at_once);
    // A failed test poisons the lock; the next one may still run.
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// Also writes each panic's place and message straight to stderr, past
/// the test harness's capture. This binary once died with SIGILL (an
/// abort, most likely a second panic while unwinding the first), and an
/// abort throws away the captured output with the first panic's message;
/// now that message is in the log whatever follows. The usual report
/// follows as before.
fn report_panics_at_once() {
    let previous = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        use std::io::Write;
        let thread = std::thread::current();
        let line = format!(
            "[remote tests] thread '{}' panicked: {info}\n",
            thread.name().unwrap_or("?")
        );
        let _ = std::io::stderr().write_all(line.as_bytes());
        previous(info);
    }));
}

/// A daemon holding a weightless object, for the tests whose goals run to
/// their end: the bridge is what they check, and a weightless object's
/// turns take 2–6 s where the default 0.1 kg one's take longer (its pair
/// first rolls apart to carry the weight).
pub fn weightless_daemon(tag: &str) -> TestDaemon {
    let mut d = TestDaemon::new(tag, "[load]\ngravity = [0.0, 0.0, 0.0]\n");
    d.spawn();
    d
}

/// Connect and command timeout of the test clients.
pub const T: Duration = Duration::from_secs(10);

static NEXT: AtomicU32 = AtomicU32::new(0);

/// A private CA and certificates: `op` (operator), `dash` (monitor),
/// `stranger` (signed by the CA, not configured), and `rogue/op.pem`
/// (named `op`, signed by another CA).
pub struct Pki {
    /// The directory (removed on drop).
    pub dir: PathBuf,
}

fn certs(dir: &Path, args: &[&str]) {
    let out = Command::new("bash")
        .arg(repo_root().join("deploy/gaitd-certs.sh"))
        .arg("--dir")
        .arg(dir)
        .args(args)
        .output()
        .expect("run deploy/gaitd-certs.sh (needs openssl)");
    assert!(
        out.status.success(),
        "gaitd-certs.sh {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

impl Pki {
    /// Makes the CA and the certificates.
    pub fn new(tag: &str) -> Self {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("gaitd-pki-{}-{n}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        certs(&dir, &["ca"]);
        certs(&dir, &["bridge"]);
        for name in ["op", "dash", "stranger"] {
            certs(&dir, &["client", name]);
        }
        let rogue = dir.join("rogue");
        certs(&rogue, &["ca"]);
        certs(&rogue, &["client", "op"]);
        Self { dir }
    }

    /// The files of identity `name` (ca.pem, NAME.pem, NAME.key).
    pub fn files(&self, name: &str) -> TlsFiles {
        TlsFiles::in_dir(&self.dir, name)
    }

    /// `op`'s certificate from another CA, with our CA to trust the bridge.
    pub fn rogue(&self) -> TlsFiles {
        let r = self.dir.join("rogue");
        TlsFiles::new(self.dir.join("ca.pem"), r.join("op.pem"), r.join("op.key"))
    }
}

impl Drop for Pki {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Logs the in-process clients' Zenoh session to stderr with the filter in
/// `GAITD_TEST_CLIENT_LOG` (e.g. `zenoh_transport=debug`), if set: with
/// the bridge's (`GAITD_TEST_BRIDGE_LOG`) it shows which side closed a link.
pub fn client_log() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        if let Ok(filter) = std::env::var("GAITD_TEST_CLIENT_LOG") {
            let _ = tracing_subscriber::fmt()
                .with_env_filter(tracing_subscriber::EnvFilter::new(filter))
                .with_writer(std::io::stderr)
                .with_ansi(false)
                .try_init();
        }
    });
}

/// Runs `c` to completion: its exit code, stdout and stderr.
pub fn run(c: &mut Command) -> (Option<i32>, String, String) {
    let out = c.output().unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A TCP port nobody listens on right now (the OS's pick).
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port")
}

/// A UDP port free at the time of asking (for a `quic/` endpoint).
pub fn free_udp_port() -> u16 {
    std::net::UdpSocket::bind("127.0.0.1:0")
        .and_then(|s| s.local_addr())
        .map(|a| a.port())
        .expect("a free UDP port")
}

/// A gaitd-bridge process for a [`TestDaemon`]'s namespace.
pub struct TestBridge {
    /// The process (None when stopped).
    pub child: Option<Child>,
    /// `quic/127.0.0.1:PORT` (the default link).
    pub endpoint: String,
    /// `tls/127.0.0.1:PORT` (the bridge listens on both; the cut-link
    /// tests put a TCP forwarder in front of this one).
    pub tls_endpoint: String,
    /// Its key prefix.
    pub prefix: String,
    /// Its config file.
    pub config: PathBuf,
    log: PathBuf,
}

impl TestBridge {
    /// Writes the config (identities `op` operator and `dash` monitor, then
    /// `extra` TOML appended to `[bridge]`) and starts the bridge; waits
    /// until it listens.
    pub fn start(d: &TestDaemon, pki: &Pki, extra: &str) -> Self {
        let mut b = Self::configure(d, pki, extra);
        b.spawn();
        b
    }

    /// Writes the config without starting the bridge.
    pub fn configure(d: &TestDaemon, pki: &Pki, extra: &str) -> Self {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let (port, tls_port) = (free_udp_port(), free_port());
        let prefix = format!("rt{}x{n}", std::process::id());
        let config = d.dir.join(format!("bridge-{n}.toml"));
        let text = format!(
            "[gaitd]\nservice_prefix = \"{}\"\nroot_path = \"{}/\"\nfile_prefix = \"{}\"\n\
             [zenoh]\nlisten = [\"quic/127.0.0.1:{port}\", \"tls/127.0.0.1:{tls_port}\"]\nkey_prefix = \"{prefix}\"\n\
             ca = \"{dir}/ca.pem\"\ncert = \"{dir}/bridge.pem\"\nkey = \"{dir}/bridge.key\"\n\
             [[identity]]\nname = \"op\"\nrole = \"operator\"\n\
             [[identity]]\nname = \"dash\"\nrole = \"monitor\"\n\
             [bridge]\n{extra}\n",
            d.prefix,
            d.root.display(),
            d.file_prefix,
            dir = pki.dir.display(),
        );
        std::fs::write(&config, text).expect("write the bridge config");
        Self {
            child: None,
            endpoint: format!("quic/127.0.0.1:{port}"),
            tls_endpoint: format!("tls/127.0.0.1:{tls_port}"),
            prefix,
            log: d.dir.join(format!("bridge-{n}.log")),
            config,
        }
    }

    /// Starts (or restarts) the process and waits until it listens.
    pub fn spawn(&mut self) {
        let log = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&self.log)
            .expect("bridge log");
        let before = self.log().matches("gaitd-bridge: ready").count();
        let child = Command::new(workspace_bin("gaitd-bridge"))
            .arg("--config")
            .arg(&self.config)
            // GAITD_TEST_BRIDGE_LOG: another filter to diagnose with
            // (e.g. `info,zenoh_transport=debug` for why a session closed).
            .env(
                "RUST_LOG",
                std::env::var("GAITD_TEST_BRIDGE_LOG").unwrap_or_else(|_| "info,zenoh=warn".into()),
            )
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()
            .expect("spawn gaitd-bridge");
        self.child = Some(child);
        let t0 = Instant::now();
        while self.log().matches("gaitd-bridge: ready").count() == before {
            assert!(
                t0.elapsed() < Duration::from_secs(30),
                "gaitd-bridge not ready:\n{}",
                self.log()
            );
            assert!(self.running(), "gaitd-bridge exited:\n{}", self.log());
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Whether the process runs.
    pub fn running(&mut self) -> bool {
        self.child
            .as_mut()
            .is_some_and(|c| c.try_wait().expect("try_wait").is_none())
    }

    /// Kills the process at once (SIGKILL).
    pub fn kill(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }

    /// What the bridge logged.
    pub fn log(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    /// Client options for identity `name` with `pki`'s files.
    pub fn options(&self, pki: &Pki, name: &str) -> ConnectOptions {
        self.options_with(pki.files(name))
    }

    /// Client options with the given TLS files.
    pub fn options_with(&self, tls: TlsFiles) -> ConnectOptions {
        ConnectOptions::remote(&self.endpoint, tls)
            .prefix(&self.prefix)
            .timeout(T)
    }

    /// A connected remote client (panics with the bridge's log if not).
    pub fn client(&self, pki: &Pki, name: &str) -> Client {
        client_log();
        match Client::connect(self.options(pki, name)) {
            Ok(c) => c,
            Err(e) => panic!(
                "remote connect as {name}: {e}\n--- bridge log ---\n{}",
                self.log()
            ),
        }
    }

    /// `gaitctl --remote … --identity NAME` for this bridge (10 s timeout).
    pub fn gaitctl(&self, pki: &Pki, name: &str) -> Command {
        self.gaitctl_waiting(pki, name, 10)
    }

    /// [`TestBridge::gaitctl`] with a `--timeout` of `secs`.
    pub fn gaitctl_waiting(&self, pki: &Pki, name: &str, secs: u32) -> Command {
        let mut c = Command::new(workspace_bin("gaitctl"));
        c.arg("--remote")
            .arg(&self.endpoint)
            .arg("--pki")
            .arg(&pki.dir)
            .arg("--identity")
            .arg(name)
            .arg("--prefix")
            .arg(&self.prefix)
            .arg("--timeout")
            .arg(secs.to_string());
        c
    }
}

impl Drop for TestBridge {
    fn drop(&mut self) {
        self.kill();
        // A failing test shows what the bridge saw, whatever failed (and
        // every test does when diagnosing with GAITD_TEST_BRIDGE_LOG).
        if std::thread::panicking() || std::env::var_os("GAITD_TEST_BRIDGE_LOG").is_some() {
            use std::io::Write;
            let text = format!(
                "--- bridge log ({}) ---\n{}",
                self.log.display(),
                self.log()
            );
            let _ = std::io::stderr().write_all(text.as_bytes());
        }
    }
}
