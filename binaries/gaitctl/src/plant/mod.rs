//! `gaitctl plant sim|mujoco --config FILE`: run a plant out of process
//! against a daemon started with `[plant] kind = "shm"` (shm_schema
//! `PLANT-GUIDE.md`). `sim` is the kinematic hand (the embedded one, over
//! the plant interface: every setpoint executed exactly) — free
//! fingertips, or, where the file's `[hand]` is a chain hand, that hand
//! at the joint level ([`joint_sim`]); `mujoco` starts the MuJoCo physics
//! hand of the Python package (`client/python`): the free fingertips, or
//! a chain hand's description in physics at the joint level
//! (`gaitd.plants.trifinger_plant`: torque-limited joints under robot_fingers'
//! action law, gravity, the ball's pose through a tracker model).

mod config;
pub mod joint_sim;
pub mod sim;

use crate::common::ConnArgs;
use config::PlantView;
use gaitd_client::plant::{Pacing, PlantHost};
use std::process::ExitCode;

/// Which plant.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The kinematic hand: executes every setpoint exactly.
    Sim,
    /// The MuJoCo physics hand (Python package `gaitd`, `client/python`).
    Mujoco,
}

/// Pacing.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingArg {
    /// The plant's measurement drives each daemon tick.
    Lockstep,
    /// Both on the wall clock.
    Realtime,
}

/// `gaitctl plant` arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Which plant.
    #[arg(value_enum)]
    pub kind: Kind,
    /// The daemon's configuration file: the model, the load, the control
    /// rate, `[plant] timing` and `[ipc]` come from it.
    #[arg(long)]
    pub config: String,
    /// Override `[plant] timing`.
    #[arg(long, value_enum)]
    pub timing: Option<TimingArg>,
    /// Stop after this many simulated seconds (default: until Ctrl-C).
    #[arg(long)]
    pub seconds: Option<f64>,
    /// Python interpreter for `mujoco` [env: GAITD_PYTHON; default python3].
    #[arg(long)]
    pub python: Option<String>,
    /// `sim` only, to test fault handling: each SIGUSR1 makes the next
    /// measurement tell this lie once (`kill -USR1 <pid>`).
    #[arg(long, value_enum)]
    pub lie_on_usr1: Option<sim::Lie>,
    /// `mujoco` only: write the plant's report here at exit (JSON: its
    /// counters and real-time factor, the object's final pose as
    /// simulated, its largest drift; on a chain hand the applied torques'
    /// peaks and the action law's clip counts too).
    #[arg(long, value_name = "FILE")]
    pub report: Option<String>,
    /// `mujoco` on a chain hand: the simulator's true object pose every
    /// step instead of the default tracker model (30 Hz, 10 ms late, 1 mm
    /// and 1° RMS noise).
    #[arg(long)]
    pub exact_tracker: bool,
}

/// Runs the plant.
pub fn run(conn: &ConnArgs, a: &Args) -> Result<(), String> {
    let view = PlantView::load(&a.config)?;
    let timing = match a.timing {
        Some(TimingArg::Lockstep) => Pacing::Lockstep,
        Some(TimingArg::Realtime) => Pacing::Realtime,
        None => view.timing,
    };
    if a.kind == Kind::Sim && (a.report.is_some() || a.exact_tracker) {
        return Err("--report and --exact-tracker are for `gaitctl plant mujoco`".into());
    }
    match a.kind {
        Kind::Sim => {
            let opts = view.connect_options(conn);
            let mut host = PlantHost::open(&opts).map_err(|e| e.to_string())?;
            let stop = &sim::STOP;
            crate::common::stop_on_signal(stop);
            if a.lie_on_usr1.is_some() {
                sim::lie_on_usr1();
            }
            let r = match &view.chains {
                Some(setup) => {
                    let mut model =
                        joint_sim::JointKinematicPlant::new(setup, view.period_ns(), a.seconds)
                            .ok_or("hand.start_normals: a finger cannot reach its start grasp")?
                            .with_lie(a.lie_on_usr1);
                    eprintln!(
                        "kinematic joint-level chain hand: {timing:?}, {} Hz, the configured \
                         start grasp",
                        view.tick_hz
                    );
                    host.run(&mut model, timing, view.period_ns(), stop)
                }
                None => {
                    let mut model =
                        sim::KinematicPlant::new(&view.hand, view.period_ns(), a.seconds)
                            .with_lie(a.lie_on_usr1);
                    eprintln!(
                        "kinematic plant: {timing:?}, {} Hz, paper start grasp",
                        view.tick_hz
                    );
                    host.run(&mut model, timing, view.period_ns(), stop)
                }
            }
            .map_err(|e| e.to_string())?;
            eprintln!(
                "{} steps ({:.2} s simulated in {:.2} s: real-time factor {:.1}), {} commands applied, {} refused",
                r.steps,
                r.sim_seconds,
                r.wall_seconds,
                r.sim_seconds / r.wall_seconds.max(1e-9),
                r.applied,
                r.refused
            );
            Ok(())
        }
        Kind::Mujoco if a.exact_tracker && view.chains.is_none() => Err(
            "--exact-tracker is for a chain hand ([hand] kind = \"chains\"): the fingertip MuJoCo \
             plant always reports the simulated object"
                .into(),
        ),
        Kind::Mujoco => mujoco(conn, a, timing),
    }
}

/// Runs the Python MuJoCo plant (`python -m gaitd.plants.mujoco`).
fn mujoco(conn: &ConnArgs, a: &Args, timing: Pacing) -> Result<(), String> {
    if a.lie_on_usr1.is_some() {
        return Err("--lie-on-usr1 is for `gaitctl plant sim` only".into());
    }
    let python = a
        .python
        .clone()
        .or_else(|| std::env::var("GAITD_PYTHON").ok())
        .unwrap_or_else(|| "python3".into());
    let mut cmd = std::process::Command::new(&python);
    cmd.args(["-m", "gaitd.plants.mujoco", "--config", &a.config])
        .arg("--timing")
        .arg(match timing {
            Pacing::Lockstep => "lockstep",
            Pacing::Realtime => "realtime",
        });
    if let Some(r) = &a.report {
        cmd.arg("--report").arg(r);
    }
    if a.exact_tracker {
        cmd.arg("--exact-tracker");
    }
    if let Some(s) = a.seconds {
        let view = PlantView::load(&a.config)?;
        cmd.arg("--max-steps")
            .arg(((s * view.tick_hz).round() as u64).to_string());
    }
    // The command line's connection settings reach it as the variables
    // every client honours (the config file's [ipc] keys come first).
    for (var, v) in [
        ("GAITD_PREFIX", &conn.prefix),
        ("GAITD_IPC_ROOT", &conn.ipc_root),
        ("GAITD_IPC_FILE_PREFIX", &conn.ipc_file_prefix),
        ("GAITD_IPC_CONFIG", &conn.ipc_config),
    ] {
        if let Some(v) = v {
            cmd.env(var, v);
        }
    }
    // Becomes the plant (exec): a SIGTERM or SIGINT to this process (from
    // `gaitctl demo`, a shell, systemd) reaches the plant itself, which
    // prints its summary and exits. A child instead would be left running,
    // waiting for a daemon that is gone.
    use std::os::unix::process::CommandExt;
    let e = cmd.exec();
    Err(format!(
        "cannot run {python} (the MuJoCo plant needs the Python package: \
         `pip install -e client/python[mujoco]`; GAITD_PYTHON or --python names the \
         interpreter): {e}"
    ))
}

/// `main`'s entry: errors are the user's (a message, exit 1).
pub fn main(conn: &ConnArgs, a: &Args) -> ExitCode {
    match run(conn, a) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gaitctl plant: {e}");
            ExitCode::FAILURE
        }
    }
}
