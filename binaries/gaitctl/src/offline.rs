//! Offline execution for `plan` (and `demo`): the planner, the executor and
//! the embedded kinematic hand in this process, ticking at the control rate,
//! exactly as gaitd runs them — no daemon, no clock: the trace's time is
//! tick × dt.

use std::io::Write;
use std::path::Path;

use gait::executor::{
    Executor, ExecutorCommand, ExecutorEvent, GoalStage, GoalTarget, Mode, Reason,
};
use gait::planner::{PlanSummary, Planner, Route, StepKind};
use gait::sim::{KinematicHand, Plant};
use gait::{HandConfig, HandState};

/// Loads the model sections (`[model]`, `[load]`, `[limits]`, `[planner]`,
/// `[feedback]`) of a gaitd configuration file; other sections are ignored.
pub fn load_config(path: Option<&Path>) -> Result<HandConfig, String> {
    let Some(path) = path else {
        return Ok(HandConfig::default());
    };
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read config file {}: {e}", path.display()))?;
    let mut table: toml::Table = text
        .parse()
        .map_err(|e| format!("config file {}: {e}", path.display()))?;
    const MODEL: [&str; 5] = ["model", "load", "limits", "planner", "feedback"];
    table.retain(|k, _| MODEL.contains(&k));
    let cfg: HandConfig = table
        .try_into()
        .map_err(|e| format!("config file {}: {e}", path.display()))?;
    cfg.validate()
        .map_err(|e| format!("config file {}: {e}", path.display()))?;
    Ok(cfg)
}

/// What one goal did.
#[derive(Debug, Clone)]
pub struct GoalRun {
    /// How it ended.
    pub state: GoalStage,
    /// Why.
    pub reason: Reason,
    /// The plan's statistics (if one was made).
    pub plan: Option<PlanSummary>,
    /// The plan's route: its actions and the pass that found them.
    pub route: Option<Route>,
    /// Steps of the plan by kind: roll, rotate, transfer, place, lift.
    pub steps: [u32; 5],
    /// Execution time \[s\].
    pub duration: f64,
    /// Angle between the final and the goal orientation \[rad\].
    pub final_error: f64,
    /// Smallest force-closure slack seen while executing.
    pub min_fc_margin: f64,
    /// Largest commanded normal force \[N\].
    pub max_grip: f64,
    /// Planning wall time \[ms\].
    pub planning_ms: f64,
}

/// Runs goals one after the other from `start`, writing the trace (header
/// first) to `trace` if given; calls `progress` every `every` ticks.
pub struct OfflineRun {
    cfg: HandConfig,
    dt: f64,
    exec: Executor,
    plant: KinematicHand,
    planner: Planner,
    tick: u64,
    line: String,
}

impl OfflineRun {
    /// Sets up the hand at `start` with control period `dt`.
    pub fn new(cfg: &HandConfig, start: HandState, dt: f64) -> Result<Self, String> {
        Ok(Self {
            cfg: *cfg,
            dt,
            exec: Executor::new(cfg, dt, start).map_err(|e| e.to_string())?,
            plant: KinematicHand::new(start, dt),
            planner: Planner::new(cfg).map_err(|e| e.to_string())?,
            tick: 0,
            line: String::with_capacity(1024),
        })
    }

    /// Writes the trace header.
    pub fn header(&mut self, out: &mut dyn Write, extra: &str) -> std::io::Result<()> {
        self.line.clear();
        gait::trace::header(&mut self.line, &self.cfg, self.dt, extra);
        out.write_all(self.line.as_bytes())
    }

    /// The hand's current (commanded) state.
    pub fn state(&self) -> HandState {
        self.exec.setpoint().state
    }

    /// Executes one goal to its end.
    pub fn goal(
        &mut self,
        id: u64,
        target: GoalTarget,
        mut trace: Option<&mut dyn Write>,
        progress: &mut dyn FnMut(&gait::executor::TickReport),
    ) -> Result<GoalRun, String> {
        let answer = self.exec.command(ExecutorCommand::Goal {
            id,
            target,
            limits: None,
        });
        if answer != gait::executor::ExecutorAnswer::Accepted {
            return Err(format!("goal refused: {answer:?}"));
        }
        let mut run = GoalRun {
            state: GoalStage::Accepted,
            reason: Reason::None,
            plan: None,
            steps: [0; 5],
            duration: 0.0,
            final_error: 0.0,
            min_fc_margin: f64::INFINITY,
            max_grip: 0.0,
            planning_ms: 0.0,
            route: None,
        };
        let end = target.resolve(&self.state().object);
        let t0 = self.tick;
        loop {
            let m = self.plant.read();
            let rep = *self.exec.tick(m.as_ref());
            self.plant.write(&rep.setpoint);
            self.tick += 1;
            if let Some(req) = self.exec.take_plan_request() {
                let clock = std::time::Instant::now();
                let plan = req.plan(&self.planner);
                run.planning_ms = clock.elapsed().as_secs_f64() * 1e3;
                if let Ok(p) = &plan {
                    run.plan = Some(p.summary);
                    run.route = Some(p.route.clone());
                    for s in &p.steps {
                        let i = match s.kind {
                            StepKind::Roll => 0,
                            StepKind::Rotate => 1,
                            StepKind::Transfer => 2,
                            StepKind::Place => 3,
                            StepKind::Lift => 4,
                        };
                        run.steps[i] += 1;
                    }
                }
                drop(self.exec.deliver_plan(req.goal, plan.map(Box::new)));
            }
            if rep.phase == Mode::Moving {
                run.min_fc_margin = run.min_fc_margin.min(rep.force_closure.1);
            }
            run.max_grip = run
                .max_grip
                .max(rep.grip.iter().cloned().fold(0.0, f64::max));
            if let Some(out) = trace.as_deref_mut() {
                self.line.clear();
                gait::trace::line(&mut self.line, self.tick as f64 * self.dt, &rep);
                out.write_all(self.line.as_bytes())
                    .map_err(|e| format!("writing the trace: {e}"))?;
            }
            progress(&rep);
            while let Some(e) = self.exec.pop_event() {
                if let ExecutorEvent::Goal {
                    id: gid,
                    state,
                    reason,
                } = e
                    && gid == id
                    && state.is_terminal()
                {
                    run.state = state;
                    run.reason = reason;
                }
            }
            if run.state.is_terminal() && matches!(rep.phase, Mode::Holding | Mode::SafeHold) {
                break;
            }
            if self.tick - t0 > 10_000_000 {
                return Err("goal did not finish within 10^7 ticks".into());
            }
        }
        run.duration = (self.tick - t0) as f64 * self.dt;
        run.final_error = end.angle_to(&self.state().object);
        Ok(run)
    }
}
