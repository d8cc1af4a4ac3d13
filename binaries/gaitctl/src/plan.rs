//! `gaitctl plan`: plan and execute offline (no daemon) on the embedded
//! kinematic hand, export a `gait-trajectory/1` trace, print a summary.

use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use gait::HandState;
use gait::executor::{GoalStage, GoalTarget};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::offline::{GoalRun, OfflineRun, load_config};
use super::trace;
use trace_mcap::file as tracefile;

/// Where the trace goes: the JSON-lines file and, for the MCAP recording,
/// a copy in memory (the recording's writer needs the header's model and
/// converts the whole trace at the end).
struct Sinks {
    file: Option<BufWriter<std::fs::File>>,
    copy: Option<Vec<u8>>,
}

impl Write for Sinks {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if let Some(f) = self.file.as_mut() {
            f.write_all(buf)?;
        }
        if let Some(c) = self.copy.as_mut() {
            c.extend_from_slice(buf);
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.file.as_mut().map_or(Ok(()), Write::flush)
    }
}

/// Built-in scenarios.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scenario {
    /// The paper's scenario: from three fingers 120° apart, roll to a
    /// two-finger grasp, then a full turn about z and a full turn about x
    /// by finger substitutions.
    Paper,
}

/// Arguments of `gaitctl plan`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Goal orientation as a quaternion W,X,Y,Z (object → hand).
    #[arg(long, value_name = "W,X,Y,Z", allow_hyphen_values = true, conflicts_with_all = ["axis", "scenario"])]
    quat: Option<String>,
    /// Goal as a rotation axis X,Y,Z (hand frame), with --angle.
    #[arg(
        long,
        value_name = "X,Y,Z",
        allow_hyphen_values = true,
        requires = "angle",
        conflicts_with = "scenario"
    )]
    axis: Option<String>,
    /// Rotation angle in degrees for --axis (any size with --relative: 360 is a full turn).
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        requires = "axis"
    )]
    angle: Option<f64>,
    /// The goal is a rotation from the start orientation, not an absolute orientation.
    #[arg(long)]
    relative: bool,
    /// Start state: `paper` (three fingers 120° apart on the equator) or a
    /// trace file (its last state).
    #[arg(long, default_value = "paper", value_name = "paper|TRACE")]
    from: String,
    /// A built-in scenario instead of a single goal.
    #[arg(long, value_enum)]
    scenario: Option<Scenario>,
    /// Write the trace (gait-trajectory/1, JSON lines) here.
    #[arg(long, short = 'o', value_name = "FILE")]
    out: Option<PathBuf>,
    /// Write the trace as an MCAP recording here too (as `gaitctl trace mcap`).
    #[arg(long, value_name = "FILE.mcap")]
    mcap: Option<PathBuf>,
    /// gaitd configuration file for the model (default: built-in defaults).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Control rate of the execution and the trace, in Hz.
    #[arg(long, default_value_t = 1000.0)]
    rate: f64,
    /// Print progress while executing.
    #[arg(long)]
    progress: bool,
}

fn parse<const N: usize>(s: &str, what: &str) -> Result<[f64; N], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("--{what} {s}: {e}"))?;
    if v.len() != N || v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "--{what} {s}: expected {N} finite numbers separated by commas"
        ));
    }
    let mut out = [0.0; N];
    out.copy_from_slice(&v);
    Ok(out)
}

/// The goals this invocation asks for, given the start orientation.
fn goals(a: &Args, start: &UnitQuaternion<f64>) -> Result<Vec<(String, GoalTarget)>, String> {
    if a.scenario == Some(Scenario::Paper) {
        let turn = std::f64::consts::TAU;
        return Ok(vec![
            (
                "360° about z".into(),
                GoalTarget::Rotation {
                    axis: Vector3::z(),
                    angle: turn,
                },
            ),
            (
                "360° about x".into(),
                GoalTarget::Rotation {
                    axis: Vector3::x(),
                    angle: turn,
                },
            ),
        ]);
    }
    if let Some(q) = &a.quat {
        let [w, x, y, z] = parse::<4>(q, "quat")?;
        let q = Quaternion::new(w, x, y, z);
        if q.norm() < 1e-9 {
            return Err("--quat: the zero quaternion is not a rotation".into());
        }
        let q = UnitQuaternion::new_normalize(q);
        let target = if a.relative { q * start } else { q };
        return Ok(vec![(
            format!("quaternion {w},{x},{y},{z}"),
            GoalTarget::Orientation(target),
        )]);
    }
    if let (Some(axis), Some(deg)) = (&a.axis, a.angle) {
        let v = Vector3::from(parse::<3>(axis, "axis")?);
        if v.norm() < 1e-9 {
            return Err("--axis: the zero vector has no direction".into());
        }
        let label = format!("{deg}° about ({axis})");
        let angle = deg.to_radians();
        return Ok(vec![(
            label,
            if a.relative {
                GoalTarget::Rotation { axis: v, angle }
            } else {
                GoalTarget::Orientation(UnitQuaternion::from_scaled_axis(v.normalize() * angle))
            },
        )]);
    }
    Err("give a goal: --quat W,X,Y,Z, or --axis X,Y,Z --angle DEG, or --scenario paper".into())
}

fn summary(label: &str, r: &GoalRun) {
    let [roll, rotate, transfer, place, lift] = r.steps;
    println!("goal {label}: {:?}", r.state);
    if let Some(p) = &r.plan {
        println!(
            "  plan: {} primitives (roll {roll}, rotate {rotate}, transfer {transfer}, place {place}, lift {lift}); {} gaits ({} substitutions, {} rewinds); planned {:.2} s; planning {:.2} ms{}",
            r.steps.iter().sum::<u32>(),
            p.gaits,
            p.substitutions,
            p.rewinds,
            p.duration,
            r.planning_ms,
            if p.escaped {
                "; a detour or regrasp where no gait could follow (Theory 1)"
            } else {
                ""
            }
        );
        let e = &p.effort;
        println!(
            "  effort: {} expansions, {} nodes, {} deferred actions evaluated, {} plans built ({} refused by the exact check), {} passes",
            e.expansions, e.generated, e.evaluated, e.built, e.refused, e.passes
        );
    }
    if let Some(route) = &r.route {
        println!("  route: {route}");
    }
    println!(
        "  executed {:.3} s; final orientation error {:.2e} rad; min force-closure margin {:.4}; max grip {:.2} N",
        r.duration, r.final_error, r.min_fc_margin, r.max_grip
    );
}

/// Runs `gaitctl plan`.
pub fn run(a: &Args) -> Result<ExitCode, String> {
    let cfg = load_config(a.config.as_deref())?;
    if !(a.rate.is_finite() && (100.0..=10_000.0).contains(&a.rate)) {
        return Err("--rate must be in [100, 10000] Hz".into());
    }
    let start = if a.from == "paper" {
        HandState::paper_start(&cfg)
    } else {
        let t = tracefile::read(std::path::Path::new(&a.from))?;
        t.samples[t.samples.len() - 1].hand_state()
    };
    let goals = goals(a, &start.object)?;
    let dt = 1.0 / a.rate;
    let mut run = OfflineRun::new(&cfg, start, dt)?;
    let file = match &a.out {
        Some(p) => {
            Some(BufWriter::new(std::fs::File::create(p).map_err(|e| {
                format!("cannot create {}: {e}", p.display())
            })?))
        }
        None => None,
    };
    let mut writer = (a.out.is_some() || a.mcap.is_some()).then(|| Sinks {
        file,
        copy: a.mcap.as_ref().map(|_| Vec::new()),
    });
    if let Some(w) = writer.as_mut() {
        let labels: Vec<String> = goals.iter().map(|(l, _)| format!("{l:?}")).collect();
        let extra = format!(
            "\"goals\":[{}],\"start\":{:?},\"generator\":\"gaitctl plan\"",
            labels.join(","),
            a.from
        );
        run.header(w, &extra).map_err(|e| e.to_string())?;
    }
    let mut ok = true;
    for (i, (label, target)) in goals.iter().enumerate() {
        let mut last = 0;
        let mut progress = |r: &gait::executor::TickReport| {
            if a.progress && r.tick - last >= 250 {
                last = r.tick;
                eprint!(
                    "\r  t {:7.2} s  {:<9}  remaining {:6.1}°  gaits {}/{}   ",
                    r.tick as f64 * dt,
                    gait::trace::phase_name(r.phase, r.step_kind),
                    r.remaining_angle.to_degrees(),
                    r.gaits.0,
                    r.gaits.1
                );
            }
        };
        let w: Option<&mut dyn Write> = writer.as_mut().map(|w| w as &mut dyn Write);
        let r = run.goal(i as u64 + 1, *target, w, &mut progress)?;
        if a.progress {
            eprintln!();
        }
        summary(label, &r);
        ok &= r.state == GoalStage::Succeeded && r.final_error <= 1e-6;
    }
    if let Some(mut w) = writer {
        w.flush().map_err(|e| e.to_string())?;
        if let Some(p) = &a.out {
            println!("trace: {}", p.display());
        }
        if let (Some(p), Some(copy)) = (&a.mcap, &w.copy) {
            trace::write_mcap(&copy[..], p)?;
            println!("MCAP recording: {}", p.display());
        }
    }
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
