//! Running the `gaitd` Python package (`client/python`) and its test
//! scripts (`tests/python`) from cargo tests.
//!
//! Python comes from `GAITD_ORACLE_PYTHON` or `<repo>/.venv-oracles`
//! (`gaitd_tests::oracle_python`, made by `.ci/install`). `PYTHONPATH`
//! points at this checkout's `client/python`, so the package under test is
//! the one beside the test, whatever the venv has installed.

#![allow(dead_code)] // each test binary uses a part

use gaitd_tests::{remove_shm, repo_root};
use std::path::PathBuf;
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// The oracle Python with this checkout's package on `PYTHONPATH`.
pub use gaitd_tests::client_python as python;

/// `python <tests/python/script>` with the package on the path.
pub fn script(name: &str) -> Command {
    let mut c = python();
    c.arg(repo_root().join("tests/python").join(name));
    c
}

/// The one JSON object a script printed last, after checking it succeeded.
pub fn json_output(out: &Output, what: &str) -> serde_json::Value {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or("");
    serde_json::from_str(line)
        .unwrap_or_else(|e| panic!("{what}: no JSON ({e}):\n{stdout}\n{stderr}"))
}

static NEXT: AtomicU32 = AtomicU32::new(0);

/// An iceoryx2 namespace of its own (service prefix, root path, file
/// prefix) and a scratch directory; removed on drop.
pub struct Namespace {
    /// Service-name prefix.
    pub prefix: String,
    /// iceoryx2 root path (ends with `/`).
    pub root: String,
    /// iceoryx2 file prefix.
    pub file_prefix: String,
    /// Scratch directory.
    pub dir: PathBuf,
}

impl Namespace {
    /// A fresh namespace tagged `tag`.
    pub fn new(tag: &str) -> Self {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let pid = std::process::id();
        let dir = std::env::temp_dir().join(format!("gaitd-py-{pid}-{n}-{tag}"));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch dir");
        Self {
            prefix: format!("py-{pid}-{n}"),
            root: format!("{}/iceoryx2/", dir.display()),
            file_prefix: format!("gp{pid}x{n}_"),
            dir,
        }
    }

    /// `--dir --prefix --root --file-prefix` for a script.
    pub fn args(&self) -> Vec<String> {
        vec![
            "--dir".into(),
            self.dir.display().to_string(),
            "--prefix".into(),
            self.prefix.clone(),
            "--root".into(),
            self.root.clone(),
            "--file-prefix".into(),
            self.file_prefix.clone(),
        ]
    }
}

impl Drop for Namespace {
    fn drop(&mut self) {
        remove_shm(&self.file_prefix);
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A plant process (Python); SIGTERM, then kill, on drop.
pub struct PlantProcess {
    child: Option<Child>,
    /// Where its stderr goes.
    pub log: PathBuf,
}

impl PlantProcess {
    /// Starts `cmd` with stderr to `log`.
    pub fn spawn(mut cmd: Command, log: PathBuf) -> Self {
        let file = std::fs::File::create(&log).expect("plant log");
        let child = cmd
            .stdout(Stdio::null())
            .stderr(file)
            .spawn()
            .expect("spawn plant");
        Self {
            child: Some(child),
            log,
        }
    }

    /// Its stderr so far.
    pub fn log(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    /// SIGTERM and wait (at most `timeout`, then kill); its exit status.
    pub fn stop(&mut self, timeout: Duration) -> Option<std::process::ExitStatus> {
        let mut child = self.child.take()?;
        // SAFETY: plain syscall on our own child.
        unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
        let t0 = Instant::now();
        loop {
            if let Some(s) = child.try_wait().expect("try_wait") {
                return Some(s);
            }
            if t0.elapsed() > timeout {
                let _ = child.kill();
                return child.wait().ok();
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for PlantProcess {
    fn drop(&mut self) {
        self.stop(Duration::from_secs(5));
    }
}

/// Connects to `d` once it ticks with `plant` (in lockstep it ticks only
/// with the plant) and its first measured state is in: no fault, and the
/// status's `measured_mask` has every bit of `mask`. Panics with both logs
/// after 90 s.
pub fn connect_when_measured(
    d: &mut gaitd_tests::TestDaemon,
    plant: &PlantProcess,
    mask: u32,
) -> gaitd_client::Client {
    let t0 = Instant::now();
    let mut c = loop {
        assert!(d.running(), "gaitd exited:\n{}", d.log());
        match gaitd_client::Client::connect(d.options()) {
            Ok(c) => break c,
            Err(_) if t0.elapsed() < Duration::from_secs(90) => {
                std::thread::sleep(Duration::from_millis(200));
            }
            Err(e) => panic!(
                "connect: {e}\n--- gaitd log ---\n{}\n--- plant log ---\n{}",
                d.log(),
                plant.log()
            ),
        }
    };
    loop {
        let s = c.wait_status(Duration::from_secs(10)).expect("status");
        if s.fault == 0 && s.measured_tick > 0 && s.measured_mask & mask == mask {
            println!(
                "daemon ready with the plant after {:.1} s",
                t0.elapsed().as_secs_f64()
            );
            return c;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(90),
            "no measured state without fault (fault {}):\n{}\n{}",
            s.fault,
            d.log(),
            plant.log()
        );
    }
}
