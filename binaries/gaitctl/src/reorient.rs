//! `gaitctl reorient`: send a goal, optionally wait for its outcome.

use crate::common::{ConnArgs, code};
use crate::progress::{LiveArg, ProgressView};
use gaitd_client::{Client, GoalFrame, GoalSpec, GoalState, LimitKind, LimitOrder, Verdict};
use std::process::ExitCode;
use std::time::Duration;

/// Options.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Target quaternion w,x,y,z.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, conflicts_with_all = ["axis", "angle_deg"])]
    quat: Option<Vec<f64>>,
    /// Rotation axis x,y,z (with --angle-deg).
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        requires = "angle_deg"
    )]
    axis: Option<Vec<f64>>,
    /// Rotation angle in degrees (with --axis).
    #[arg(long, allow_hyphen_values = true, requires = "axis")]
    angle_deg: Option<f64>,
    /// Rotate relative to the current orientation (default: absolute target);
    /// with --axis/--angle-deg any angle is turned in full (360 = one turn).
    #[arg(long)]
    relative: bool,
    /// Lower a motion limit, e.g. `object.velocity=0.5` (repeatable).
    #[arg(long = "limit", value_parser = parse_limit)]
    limits: Vec<(LimitKind, LimitOrder, f64)>,
    /// Wait for the goal's outcome and print progress. Remote: also keeps
    /// the operator's session open, so the bridge's `on_client_lost` policy
    /// does not stop the goal when gaitctl exits.
    #[arg(long)]
    wait: bool,
    /// With --wait: give up after this many seconds.
    #[arg(long, default_value_t = 120.0)]
    wait_timeout: f64,
    #[command(flatten)]
    live: LiveArg,
}

fn parse_limit(s: &str) -> Result<(LimitKind, LimitOrder, f64), String> {
    let (key, value) = s.split_once('=').ok_or("expected kind.order=value")?;
    let (kind, order) = key.split_once('.').ok_or("expected kind.order=value")?;
    let kind = match kind {
        "object" => LimitKind::Object,
        "fingertip" => LimitKind::Fingertip,
        "rolling" => LimitKind::Rolling,
        _ => {
            return Err(format!(
                "unknown motion kind `{kind}` (object, fingertip, rolling)"
            ));
        }
    };
    let order = match order {
        "velocity" => LimitOrder::Velocity,
        "acceleration" => LimitOrder::Acceleration,
        "jerk" => LimitOrder::Jerk,
        _ => {
            return Err(format!(
                "unknown limit `{order}` (velocity, acceleration, jerk)"
            ));
        }
    };
    let v: f64 = value.parse().map_err(|e| format!("{value}: {e}"))?;
    Ok((kind, order, v))
}

/// Runs the subcommand.
pub fn run(conn: &ConnArgs, a: &Args) -> gaitd_client::Result<ExitCode> {
    let frame = if a.relative {
        GoalFrame::Relative
    } else {
        GoalFrame::Absolute
    };
    let mut goal = match (&a.quat, &a.axis, a.angle_deg) {
        (Some(q), _, _) if q.len() != 4 => {
            return Err(gaitd_client::Error::Invalid(
                "--quat takes four numbers w,x,y,z",
            ));
        }
        (_, Some(ax), _) if ax.len() != 3 => {
            return Err(gaitd_client::Error::Invalid(
                "--axis takes three numbers x,y,z",
            ));
        }
        (Some(q), _, _) => GoalSpec {
            target: [q[0], q[1], q[2], q[3]],
            frame,
            limits: Vec::new(),
        },
        // Relative axis-angle: a turn of that many degrees (360 is a full
        // turn, not a no-op).
        (None, Some(ax), Some(deg)) if a.relative => {
            GoalSpec::turn([ax[0], ax[1], ax[2]], deg.to_radians())?
        }
        (None, Some(ax), Some(deg)) => {
            GoalSpec::axis_angle([ax[0], ax[1], ax[2]], deg.to_radians(), frame)?
        }
        _ => {
            return Err(gaitd_client::Error::Invalid(
                "give --quat w,x,y,z or --axis x,y,z --angle-deg A",
            ));
        }
    };
    goal.limits.clone_from(&a.limits);
    let mut c = conn.connect("gaitctl")?;
    let t = c.reorient(&goal, conn.timeout())?;
    match t.verdict {
        Verdict::Rejected(r) => {
            println!("goal {}: rejected ({r})", t.goal_id);
            return Ok(ExitCode::from(1));
        }
        Verdict::Accepted => println!("goal {}: accepted", t.goal_id),
    }
    if !a.wait {
        if c.is_remote() {
            // The bridge's dead-man policy (`on_client_lost`, cancel by
            // default) sees this exit as the operator vanishing.
            eprintln!("{REMOTE_NO_WAIT}");
        }
        return Ok(ExitCode::SUCCESS);
    }
    wait(&mut c, t.goal_id, a)
}

/// Printed when a remote goal is sent without `--wait`.
const REMOTE_NO_WAIT: &str = "note: gaitctl exits now; once this identity has no remote session left \
for the bridge's client_lost_grace_ms (1 s by default), the bridge applies its on_client_lost \
policy to the goal (cancel by default): keep a session open with --wait, or with \
`gaitctl --remote ... watch` under the same identity";

/// `--wait`: progress until goal `goal_id` ends; exit 0 if it succeeded.
fn wait(c: &mut Client, goal_id: u64, a: &Args) -> gaitd_client::Result<ExitCode> {
    let deadline = std::time::Instant::now() + Duration::from_secs_f64(a.wait_timeout);
    let mut view = ProgressView::new(a.live.live);
    loop {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        if left.is_zero() {
            view.finish();
            return Err(gaitd_client::Error::Timeout {
                what: "the goal's outcome",
                waited: Duration::from_secs_f64(a.wait_timeout),
            });
        }
        match c.wait_outcome(goal_id, left.min(Duration::from_millis(50))) {
            Ok(o) => {
                if let Some(s) = c.latest_status()?
                    && (s.goal.client_id, s.goal.goal_id) == (c.client_id(), goal_id)
                {
                    view.status(&s, || progress_line(&s));
                }
                view.finish();
                println!("goal {}: {} ({})", o.goal_id, o.state, o.reason);
                return Ok(if o.state == GoalState::Succeeded {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::from(1)
                });
            }
            Err(gaitd_client::Error::Timeout { .. }) => {
                if let Some(s) = c.latest_status()?
                    && (s.goal.client_id, s.goal.goal_id) == (c.client_id(), goal_id)
                {
                    view.status(&s, || progress_line(&s));
                }
            }
            Err(e) => {
                view.finish();
                return Err(e);
            }
        }
    }
}

/// The redrawn progress line of `--wait`.
fn progress_line(s: &gaitd_client::Status) -> String {
    format!(
        "{} remaining {:7.2} deg  gaits {}/{}  phase {}",
        code(s.goal_state(), s.goal.state),
        s.goal.remaining_angle.to_degrees(),
        s.goal.gaits_done,
        s.goal.gaits_planned,
        code(s.phase(), s.phase)
    )
}
