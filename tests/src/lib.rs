//! End-to-end tests live in `tests/`; this library holds shared fixtures.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The repository root (parent of this crate).
///
/// Taken from `CARGO_MANIFEST_DIR` at run time (cargo sets it for test
/// binaries) before the compile-time value: when several checkouts share
/// one target directory, this library's artifact may have been compiled in
/// another checkout.
pub fn repo_root() -> PathBuf {
    std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")))
        .parent()
        .expect("tests/ has a parent")
        .to_path_buf()
}

/// Path of a workspace binary (`gaitd`, `gaitctl`), built once per test
/// process with the same profile as the running test.
///
/// Test binaries live in `target/<profile>/deps/`; the workspace binaries
/// one level up.
///
/// `GAITD_TEST_BUILD_FLAGS` (whitespace-separated) is appended to that
/// `cargo build`: `.ci/test` sets it to the flags of its own `cargo test`
/// (`--all-features --tests`), so that the build resolves the same features
/// as the test build (dev-dependencies included), finds everything fresh
/// and compiles nothing a second time (Zenoh and the other dependencies
/// whose features dev-dependencies widen).
pub fn workspace_bin(name: &str) -> PathBuf {
    static BUILT: OnceLock<()> = OnceLock::new();
    let exe = std::env::current_exe().expect("test executable path");
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>/deps/<test>")
        .to_path_buf();
    BUILT.get_or_init(|| {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut cmd = Command::new(cargo);
        cmd.current_dir(repo_root())
            .args(["build", "--quiet", "--workspace", "--bins"]);
        // Not the variables cargo set for this test: build scripts that
        // watch one (ring's watches CARGO_MANIFEST_DIR) would count as
        // changed and rebuild, with everything above them (TLS, Zenoh),
        // here and again in the next outer `cargo test`.
        for (k, _) in std::env::vars_os() {
            let k = k.to_string_lossy();
            if k.starts_with("CARGO_PKG_")
                || k.starts_with("CARGO_BIN_EXE_")
                || matches!(
                    k.as_ref(),
                    "CARGO_MANIFEST_DIR"
                        | "CARGO_MANIFEST_PATH"
                        | "CARGO_CRATE_NAME"
                        | "CARGO_PRIMARY_PACKAGE"
                        | "CARGO_TARGET_TMPDIR"
                        | "CARGO_RUSTC_CURRENT_DIR"
                )
            {
                cmd.env_remove(k.as_ref());
            }
        }
        if let Ok(flags) = std::env::var("GAITD_TEST_BUILD_FLAGS") {
            cmd.args(flags.split_whitespace());
        }
        if profile_dir.file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        if let Some(target) = profile_dir.parent() {
            cmd.env("CARGO_TARGET_DIR", target);
        }
        let status = cmd.status().expect("run cargo build");
        assert!(status.success(), "cargo build --workspace --bins failed");
    });
    profile_dir.join(name)
}

/// A gaitd process in its own iceoryx2 namespace (service prefix, root
/// path, file prefix), so tests run in parallel without colliding. Dropping
/// it kills the process and removes the namespace's files.
pub struct TestDaemon {
    /// The process (None after it was waited for).
    pub child: Option<std::process::Child>,
    /// Service-name prefix.
    pub prefix: String,
    /// iceoryx2 root path.
    pub root: PathBuf,
    /// iceoryx2 file prefix (names in /dev/shm).
    pub file_prefix: String,
    /// Directory with the config and the log.
    pub dir: PathBuf,
    extra_env: Vec<(String, String)>,
}

static NEXT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);

impl TestDaemon {
    /// A namespace and config, not started yet. `extra_config` is appended
    /// to the config file. No real-time setup (see [`TestDaemon::with_rt`]).
    pub fn new(tag: &str, extra_config: &str) -> Self {
        Self::with_rt(tag, "lock_memory = false\nfifo_priority = 0", extra_config)
    }

    /// As [`TestDaemon::new`], with `rt` as the body of the `[rt]` section.
    pub fn with_rt(tag: &str, rt: &str, extra_config: &str) -> Self {
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let pid = std::process::id();
        let dir = std::env::temp_dir().join(format!("gaitd-e2e-{pid}-{n}-{tag}"));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("test dir");
        let root = dir.join("iceoryx2");
        let d = Self {
            child: None,
            prefix: format!("e2e-{pid}-{n}"),
            file_prefix: format!("ge{pid}x{n}_"),
            root,
            dir,
            extra_env: Vec::new(),
        };
        let extra_config = with_test_budget(extra_config);
        let cfg = format!(
            "[ipc]\nservice_prefix = \"{}\"\nroot_path = \"{}/\"\nfile_prefix = \"{}\"\n\
             [rt]\n{rt}\n{extra_config}\n",
            d.prefix,
            d.root.display(),
            d.file_prefix
        );
        std::fs::write(d.config_path(), cfg).expect("write config");
        d
    }

    /// Starts a daemon with the default test config.
    pub fn start(tag: &str) -> Self {
        let mut d = Self::new(tag, "");
        d.spawn();
        d
    }

    /// Path of the config file.
    pub fn config_path(&self) -> PathBuf {
        self.dir.join("gaitd.toml")
    }

    /// Before it starts: record every goal's trace into `<its dir>/traces`
    /// (removed with it), which is returned. The config must have no
    /// `[daemon]` section of its own.
    pub fn record_traces(&self) -> PathBuf {
        let traces = self.dir.join("traces");
        std::fs::create_dir_all(&traces).expect("trace dir");
        let mut cfg = std::fs::read_to_string(self.config_path()).expect("config");
        cfg.push_str(&format!("[daemon]\ntrace_dir = \"{}\"\n", traces.display()));
        std::fs::write(self.config_path(), cfg).expect("config");
        traces
    }

    /// Path of the daemon's log (stderr, appended across restarts).
    pub fn log_path(&self) -> PathBuf {
        self.dir.join("gaitd.log")
    }

    /// The daemon's log so far.
    pub fn log(&self) -> String {
        std::fs::read_to_string(self.log_path()).unwrap_or_default()
    }

    /// Sets an environment variable for the next spawn.
    pub fn env(&mut self, k: &str, v: &str) {
        self.extra_env.push((k.into(), v.into()));
    }

    /// Starts (or restarts) the process.
    pub fn spawn(&mut self) {
        let log = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(self.log_path())
            .expect("log file");
        let mut cmd = Command::new(workspace_bin("gaitd"));
        cmd.arg("--config")
            .arg(self.config_path())
            .env_remove("NOTIFY_SOCKET")
            .env_remove("WATCHDOG_USEC")
            .env_remove("WATCHDOG_PID")
            .env("RUST_LOG", "info")
            .stdout(std::process::Stdio::null())
            .stderr(log);
        for (k, v) in &self.extra_env {
            cmd.env(k, v);
        }
        self.child = Some(cmd.spawn().expect("spawn gaitd"));
    }

    /// Waits until the daemon logged that it is ready (its services exist).
    pub fn wait_ready(&self, timeout: std::time::Duration) {
        let t0 = std::time::Instant::now();
        while !self.log().contains("gaitd: ready") {
            assert!(t0.elapsed() < timeout, "gaitd not ready:\n{}", self.log());
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }

    /// The process id.
    pub fn pid(&self) -> i32 {
        self.child.as_ref().expect("running").id() as i32
    }

    /// Sends `signal` to the process.
    pub fn signal(&self, signal: i32) {
        // SAFETY: plain syscall on our own child.
        unsafe { libc::kill(self.pid(), signal) };
    }

    /// Waits for the process to exit (at most `timeout`), returning its status.
    pub fn wait(&mut self, timeout: std::time::Duration) -> Option<std::process::ExitStatus> {
        let t0 = std::time::Instant::now();
        let child = self.child.as_mut()?;
        loop {
            if let Some(s) = child.try_wait().expect("try_wait") {
                self.child = None;
                return Some(s);
            }
            if t0.elapsed() > timeout {
                return None;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }

    /// Whether the process is still running.
    pub fn running(&mut self) -> bool {
        self.child
            .as_mut()
            .is_some_and(|c| c.try_wait().expect("try_wait").is_none())
    }

    /// Client options for this daemon's namespace.
    pub fn options(&self) -> gaitd_client::ConnectOptions {
        gaitd_client::ConnectOptions::new()
            .prefix(&self.prefix)
            .root_path(format!("{}/", self.root.display()))
            .file_prefix(&self.file_prefix)
            .timeout(std::time::Duration::from_secs(10))
    }

    /// A connected client (panics with the daemon's log and its process's
    /// state if it cannot connect). A daemon that is alive but slow to
    /// create its services (a machine loaded by parallel tests) gets up to
    /// 30 s; one that has exited fails at once.
    pub fn client(&self) -> gaitd_client::Client {
        let t0 = std::time::Instant::now();
        loop {
            match gaitd_client::Client::connect(self.options()) {
                Ok(c) => return c,
                Err(e) if t0.elapsed().as_secs() >= 30 || !self.alive() => panic!(
                    "connect: {e}\n--- gaitd process: {} ---\n--- gaitd log ---\n{}",
                    self.process_state(),
                    self.log()
                ),
                Err(_) => {}
            }
        }
    }

    /// Whether the daemon's process exists and is not a zombie.
    fn alive(&self) -> bool {
        let s = self.process_state();
        !(s.starts_with("gone") || s.contains("zombie"))
    }

    /// The daemon process's state as the kernel reports it (`State:` and
    /// the kernel function it waits in), for failure messages.
    fn process_state(&self) -> String {
        let Some(pid) = self.child.as_ref().map(|c| c.id()) else {
            return "gone (waited for)".into();
        };
        let status = std::fs::read_to_string(format!("/proc/{pid}/status"));
        let Ok(status) = status else {
            return format!("gone (pid {pid})");
        };
        let state = status
            .lines()
            .find(|l| l.starts_with("State:"))
            .unwrap_or("State: ?")
            .to_owned();
        let wchan = std::fs::read_to_string(format!("/proc/{pid}/wchan")).unwrap_or_default();
        format!("pid {pid}, {state}, waiting in {wchan:?}")
    }

    /// `gaitctl` with this daemon's namespace flags.
    pub fn gaitctl(&self) -> Command {
        let mut c = Command::new(workspace_bin("gaitctl"));
        c.arg("--prefix")
            .arg(&self.prefix)
            .arg("--ipc-root")
            .arg(format!("{}/", self.root.display()))
            .arg("--ipc-file-prefix")
            .arg(&self.file_prefix)
            .arg("--timeout")
            .arg("10");
        c
    }
}

/// Waits (up to 20 s) until the status says the controller holds a valid
/// start state: the plant's first measurement was taken. Panics with both
/// logs otherwise.
pub fn wait_plant_started(
    c: &mut gaitd_client::Client,
    d: &TestDaemon,
    plant: &TestPlant,
) -> gaitd_client::Status {
    let t0 = std::time::Instant::now();
    loop {
        let s = c.wait_status(std::time::Duration::from_secs(5)).unwrap();
        if s.fault == shm_schema::FaultCode::None.code()
            && s.phase == shm_schema::Phase::Hold.code()
        {
            return s;
        }
        assert!(
            t0.elapsed() < std::time::Duration::from_secs(20),
            "never started: fault {} phase {}\n--- gaitd ---\n{}\n--- plant ---\n{}",
            s.fault,
            s.phase,
            d.log(),
            plant.log()
        );
    }
}

/// Removes /dev/shm files whose names start with `file_prefix`.
pub fn remove_shm(file_prefix: &str) {
    if let Ok(dir) = std::fs::read_dir("/dev/shm") {
        for e in dir.flatten() {
            if e.file_name().to_string_lossy().starts_with(file_prefix) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// A plant process attached to a [`TestDaemon`] started with
/// `[plant] kind = "shm"`: `gaitctl plant sim` (the kinematic hand) or the
/// misbehaving `plant_fixture`. Dropping it kills the process.
pub struct TestPlant {
    /// The process (None once killed).
    pub child: Option<std::process::Child>,
    log: PathBuf,
}

impl TestPlant {
    /// `gaitctl plant sim --config <the daemon's config>` (its `[ipc]` and
    /// `[plant]` settings).
    pub fn sim(d: &TestDaemon) -> Self {
        Self::sim_with(d, &[])
    }

    /// As [`TestPlant::sim`], with more `gaitctl plant sim` arguments
    /// (e.g. `--timing realtime`, `--lie-on-usr1 non-unit`).
    pub fn sim_with(d: &TestDaemon, args: &[&str]) -> Self {
        let log = d.dir.join(format!(
            "plant-{}.log",
            NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
        ));
        let mut cmd = d.gaitctl();
        cmd.arg("plant")
            .arg("sim")
            .arg("--config")
            .arg(d.config_path())
            .args(args);
        Self::spawn(cmd, log)
    }

    /// Sends `signal` to the plant process (e.g. `libc::SIGUSR1`).
    pub fn signal(&self, signal: i32) {
        if let Some(c) = &self.child {
            // SAFETY: plain syscall on our own child.
            unsafe { libc::kill(c.id() as i32, signal) };
        }
    }

    /// The misbehaving fixture: `lie` after `after` good steps (see
    /// `src/bin/plant_fixture.rs`).
    pub fn fixture(d: &TestDaemon, lie: &str, after: u64) -> Self {
        let log = d.dir.join(format!("fixture-{lie}.log"));
        let mut cmd = Command::new(workspace_bin("plant_fixture"));
        cmd.arg("--prefix")
            .arg(&d.prefix)
            .arg("--root")
            .arg(format!("{}/", d.root.display()))
            .arg("--file-prefix")
            .arg(&d.file_prefix)
            .arg("--lie")
            .arg(lie)
            .arg("--after")
            .arg(after.to_string());
        Self::spawn(cmd, log)
    }

    fn spawn(mut cmd: Command, log: PathBuf) -> Self {
        let file = std::fs::File::create(&log).expect("plant log");
        cmd.stdout(std::process::Stdio::null()).stderr(file);
        Self {
            child: Some(cmd.spawn().expect("spawn the plant")),
            log,
        }
    }

    /// Kills the plant at once (SIGKILL: no goodbye).
    pub fn kill(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }

    /// What the plant printed.
    pub fn log(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }
}

impl Drop for TestPlant {
    fn drop(&mut self) {
        self.kill();
    }
}

impl Drop for TestDaemon {
    fn drop(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
        remove_shm(&self.file_prefix);
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The planner's wall-clock budget of a test daemon, unless its config
/// sets one: the suite runs many daemons and test binaries at once, so a
/// plan's wall time says little about its work, and a test is graded on
/// what the plan does, not on how fast a loaded machine found it (the
/// budget itself is tested with budgets small enough to bite).
const TEST_BUDGET_MS: &str = "budget_ms = 60000.0\n";

/// `extra_config` with [`TEST_BUDGET_MS`] in its `[planner]` section
/// (one is added when it has none).
fn with_test_budget(extra_config: &str) -> String {
    if extra_config.contains("budget_ms") {
        extra_config.to_owned()
    } else if extra_config.contains("[planner]\n") {
        extra_config.replacen("[planner]\n", &format!("[planner]\n{TEST_BUDGET_MS}"), 1)
    } else {
        format!("{extra_config}\n[planner]\n{TEST_BUDGET_MS}")
    }
}

/// The Python of the test oracles: `GAITD_ORACLE_PYTHON`, else
/// `<repo>/.venv-oracles/bin/python` (made by `.ci/install`). Panics with
/// instructions if neither exists: the oracle tests must not pass silently.
pub fn oracle_python() -> PathBuf {
    test_support::repo::oracle_python(&repo_root())
}

/// The oracle Python with this checkout's `client/python` (the `gaitd`
/// package) first on `PYTHONPATH`.
pub fn client_python() -> Command {
    let mut c = Command::new(oracle_python());
    c.env("PYTHONPATH", repo_root().join("client/python"));
    c
}

/// Runs `cmd` to completion like [`Command::output`], but at most `limit`:
/// a child still running then is killed and the test fails with what it had
/// printed, so a hung client cannot hang the test run.
pub fn output_within(cmd: &mut Command, limit: std::time::Duration) -> std::process::Output {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {cmd:?}: {e}"));
    // Drained on their own threads: a child blocked on a full pipe would
    // otherwise never exit.
    let drain = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut b = Vec::new();
            let _ = r.read_to_end(&mut b);
            b
        })
    };
    let out = drain(Box::new(child.stdout.take().expect("piped stdout")));
    let err = drain(Box::new(child.stderr.take().expect("piped stderr")));
    let t0 = std::time::Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("try_wait") {
            break Some(s);
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let stdout = out.join().unwrap_or_default();
    let stderr = err.join().unwrap_or_default();
    let Some(status) = status else {
        panic!(
            "{cmd:?} still running after {limit:?}, killed\n--- stdout ---\n{}\n--- stderr ---\n{}",
            String::from_utf8_lossy(&stdout),
            String::from_utf8_lossy(&stderr)
        );
    };
    std::process::Output {
        status,
        stdout,
        stderr,
    }
}

/// Replays the `gait-trajectory/1` trace `trace` of a 0.1 kg object in
/// MuJoCo (`tests/oracles/mujoco/replay.py -q`); its output and exit status
/// say whether the object followed the trace.
pub fn mujoco_replay(trace: &Path) -> std::process::Output {
    Command::new(oracle_python())
        .arg(repo_root().join("tests/oracles/mujoco/replay.py"))
        .arg(trace)
        .args(["--mass", "0.1", "-q"])
        .output()
        .unwrap()
}

/// The (state, tick) of every goal transition of `goal_id` the client has
/// received so far.
pub fn goal_transition_ticks(c: &mut gaitd_client::Client, goal_id: u64) -> Vec<(u32, u64)> {
    c.events()
        .expect("events")
        .filter(|e| e.kind() == Ok(gaitd_client::EventKind::GoalTransition) && e.goal_id == goal_id)
        .map(|e| (e.state, e.tick))
        .collect()
}

/// The lines after the header of the first trace (`*.jsonl`) written to
/// `dir`, waiting up to 10 s for the daemon's trace thread to write it.
pub fn trace_lines(dir: &Path) -> Vec<String> {
    let t0 = std::time::Instant::now();
    let file = loop {
        let found = std::fs::read_dir(dir)
            .expect("trace dir")
            .flatten()
            .find(|e| e.file_name().to_string_lossy().ends_with(".jsonl"));
        if let Some(f) = found {
            break f.path();
        }
        assert!(
            t0.elapsed() < std::time::Duration::from_secs(10),
            "no trace written to {}",
            dir.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let text = std::fs::read_to_string(file).expect("read trace");
    text.lines().skip(1).map(str::to_owned).collect()
}
