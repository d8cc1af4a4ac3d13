//! Shared by the `otg-oracle` binary and the oracle tests: parsing of
//! `ruckig-oracle/1` cases (tests/oracles/ruckig_oracle.py) and solving
//! them with this crate for any DoF count up to [`MAX_DOFS`].

use otg::{
    ControlInterface, DurationDiscretization, Input, Otg, OtgError, Profile, Synchronization,
    Trajectory,
};
use serde_json::Value;

/// Largest DoF count the dynamic dispatch supports.
pub const MAX_DOFS: usize = 18;
/// Sample fractions of the oracle format (then 1.0).
pub const FRACTIONS: [f64; 6] = [0.1, 0.3, 0.5, 0.7, 0.9, 1.0];

/// One oracle case with Ruckig's result.
#[derive(Clone, Debug)]
pub struct Case {
    pub id: u64,
    pub category: String,
    pub kind: ControlInterface,
    pub dofs: usize,
    pub delta_time: f64,
    pub synchronization: Synchronization,
    pub discretization: DurationDiscretization,
    pub minimum_duration: Option<f64>,
    pub p0: Vec<f64>,
    pub v0: Vec<f64>,
    pub a0: Vec<f64>,
    pub pf: Vec<f64>,
    pub vf: Vec<f64>,
    pub af: Vec<f64>,
    pub v_max: Vec<f64>,
    pub a_max: Vec<f64>,
    pub j_max: Vec<f64>,
    pub v_min: Option<Vec<f64>>,
    pub a_min: Option<Vec<f64>>,
    pub current_within_limits: bool,
    pub ruckig: Option<RuckigResult>,
    pub raw: Value,
}

/// What Ruckig returned.
#[derive(Clone, Debug)]
pub struct RuckigResult {
    pub status: String,
    pub duration: Option<f64>,
    pub independent_min_durations: Option<Vec<f64>>,
    pub limiting_dofs: Option<Vec<usize>>,
}

fn floats(v: &Value) -> Option<Vec<f64>> {
    v.as_array()?.iter().map(Value::as_f64).collect()
}

/// Parses one JSON line; `Err` with a message on malformed input.
pub fn parse(line: &str) -> Result<Case, String> {
    let raw: Value = serde_json::from_str(line).map_err(|e| e.to_string())?;
    let inp = &raw["input"];
    let arr = |k: &str| floats(&inp[k]).ok_or_else(|| format!("missing input.{k}"));
    let kind = match raw["kind"].as_str() {
        Some("velocity") => ControlInterface::Velocity,
        _ => ControlInterface::Position,
    };
    let synchronization = match raw["synchronization"].as_str() {
        Some("phase") => Synchronization::Phase,
        Some("none") => Synchronization::None,
        _ => Synchronization::Time,
    };
    let discretization = match raw["duration_discretization"].as_str() {
        Some("discrete") => DurationDiscretization::Discrete,
        _ => DurationDiscretization::Continuous,
    };
    let res = &raw["result"];
    let ruckig = res["status"].as_str().map(|s| RuckigResult {
        status: s.to_string(),
        duration: res["duration"].as_f64(),
        independent_min_durations: floats(&res["independent_min_durations"]),
        limiting_dofs: res["limiting_dofs"].as_array().map(|a| {
            a.iter()
                .filter_map(Value::as_u64)
                .map(|x| x as usize)
                .collect()
        }),
    });
    let case = Case {
        id: raw["id"].as_u64().unwrap_or(0),
        category: raw["category"].as_str().unwrap_or("").to_string(),
        kind,
        dofs: raw["dofs"].as_u64().ok_or("missing dofs")? as usize,
        delta_time: raw["delta_time"].as_f64().unwrap_or(0.001),
        synchronization,
        discretization,
        minimum_duration: raw["minimum_duration"].as_f64(),
        p0: arr("current_position")?,
        v0: arr("current_velocity")?,
        a0: arr("current_acceleration")?,
        pf: arr("target_position")?,
        vf: arr("target_velocity")?,
        af: arr("target_acceleration")?,
        v_max: arr("max_velocity")?,
        a_max: arr("max_acceleration")?,
        j_max: arr("max_jerk")?,
        v_min: floats(&inp["min_velocity"]),
        a_min: floats(&inp["min_acceleration"]),
        current_within_limits: raw["current_within_limits"].as_bool().unwrap_or(false),
        ruckig,
        raw,
    };
    if case.dofs == 0 || case.dofs > MAX_DOFS {
        return Err(format!("dofs {} not in 1..={MAX_DOFS}", case.dofs));
    }
    Ok(case)
}

/// A DoF-count-erased trajectory.
#[derive(Clone, Debug)]
pub struct Solved {
    pub profiles: Vec<Profile>,
    pub duration: f64,
    pub independent_min_durations: Vec<f64>,
    pub limiting_dof: Option<usize>,
}

impl Solved {
    /// `(p, v, a)` of every DoF at `t`.
    pub fn at(&self, t: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = self.profiles.len();
        let mut out = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for p in &self.profiles {
            let (x, v, a, _) = p.state_in(t.max(0.0), self.duration);
            out.0.push(x);
            out.1.push(v);
            out.2.push(a);
        }
        out
    }
}

fn fixed<const N: usize>(v: &[f64]) -> [f64; N] {
    let mut a = [0.0; N];
    a.copy_from_slice(&v[..N]);
    a
}

/// The case as an input of this crate.
pub fn input<const N: usize>(c: &Case) -> Input<N> {
    let mut i = Input::<N>::new(fixed(&c.v_max), fixed(&c.a_max), fixed(&c.j_max));
    i.control_interface = c.kind;
    i.synchronization = c.synchronization;
    i.duration_discretization = c.discretization;
    i.minimum_duration = c.minimum_duration;
    i.current_position = fixed(&c.p0);
    i.current_velocity = fixed(&c.v0);
    i.current_acceleration = fixed(&c.a0);
    i.target_position = fixed(&c.pf);
    i.target_velocity = fixed(&c.vf);
    i.target_acceleration = fixed(&c.af);
    i.min_velocity = c.v_min.as_deref().map(fixed);
    i.min_acceleration = c.a_min.as_deref().map(fixed);
    i
}

fn solve_n<const N: usize>(
    c: &Case,
    start: Option<(&[f64], &[f64], &[f64])>,
) -> Result<Solved, OtgError> {
    let mut inp = input::<N>(c);
    if let Some((p, v, a)) = start {
        inp.current_position = fixed(p);
        inp.current_velocity = fixed(v);
        inp.current_acceleration = fixed(a);
    }
    let mut otg = Otg::<N>::new(c.delta_time)?;
    let mut traj = Trajectory::<N>::default();
    otg.calculate(&inp, &mut traj)?;
    Ok(Solved {
        profiles: traj.profiles.to_vec(),
        duration: traj.duration,
        independent_min_durations: traj.independent_min_durations.to_vec(),
        limiting_dof: traj.limiting_dof,
    })
}

/// Solves the case (optionally from another current state).
pub fn solve(c: &Case, start: Option<(&[f64], &[f64], &[f64])>) -> Result<Solved, OtgError> {
    macro_rules! dispatch {
        ($($n:literal)*) => {
            match c.dofs {
                $($n => solve_n::<$n>(c, start),)*
                _ => unreachable!("checked in parse"),
            }
        };
    }
    dispatch!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18)
}

/// Ruckig's name for an error.
pub fn status_name(r: &Result<Solved, OtgError>) -> &'static str {
    match r {
        Ok(_) => "Working",
        Err(OtgError::InvalidInput { .. }) => "ErrorInvalidInput",
        Err(OtgError::TrajectoryDuration) => "ErrorTrajectoryDuration",
        Err(OtgError::ExecutionTimeCalculation { .. }) => "ErrorExecutionTimeCalculation",
        Err(OtgError::SynchronizationCalculation { .. }) => "ErrorSynchronizationCalculation",
    }
}

/// Whether all DoFs share the phase durations (1e-12 relative).
pub fn phase_synced(s: &Solved) -> bool {
    let t0 = s.profiles[0].t;
    s.profiles[1..].iter().all(|p| {
        p.t.iter()
            .zip(t0)
            .all(|(a, b)| (a - b).abs() <= 1e-12 * a.abs().max(1.0))
    })
}
