//! Cross-check against Ruckig (the `ruckig` Python package) through
//! tests/oracles/ruckig_oracle.py: 5000 cases per configuration (1, 3, 7, 18
//! DoF; position and velocity kinds; `core` and `all` categories).
//!
//! Checks: same status where Ruckig succeeds; duration within
//! 1e-9·max(1, T); final state within 1e-8 (p, v) and 1e-10 (a); limits
//! never exceeded at 1 ms sampling (1e-12 relative); phase-synchronised
//! cases are straight lines; re-planning from states on the trajectory is
//! never shorter than the remaining time and never more than 1e-6 longer.
//!
//! Where both fail, they must fail for the same reason (an invalid input,
//! or a duration beyond the maximum); and every run must have at least
//! [`MIN_AGREEING`] cases that Ruckig solved and we matched, so the checks
//! above cannot pass by having nothing to compare.
//!
//! Needs the oracle venv: `bash .ci/install` creates `<repo>/.venv-oracles`
//! (or set GAITD_ORACLE_PYTHON) with exactly [`RUCKIG_VERSION`]. A missing
//! oracle, or another version, fails the test.

#[path = "../oracle/case.rs"]
#[allow(dead_code)]
mod case;

use std::path::PathBuf;
use std::process::Command;
use test_support::repo::oracle_python;

use case::{Case, Solved};
use otg::{ControlInterface, OtgError, Synchronization};

const N_CASES: usize = 5000;

/// The `ruckig` package the numbers below were measured with: `.ci/install`
/// installs exactly this version.
const RUCKIG_VERSION: &str = "0.19.4";

/// Cases of one run (5000 seeded cases) that Ruckig must solve and we must
/// match. The generator builds every case inside Ruckig's domain, and with
/// the pinned Ruckig and fixed seeds a run is deterministic: with ruckig
/// 0.19.4 every case of every run is solved and matched (5000 of 5000). So
/// the floor is all of them: a case Ruckig stops solving (a new version, a
/// generator change, a broken status mapping) would otherwise move silently
/// to the weaker "ours only" or "both fail" checks.
const MIN_AGREEING: usize = 5000;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn generate(seed: u64, dofs: usize, kind: &str, categories: &str) -> Vec<Case> {
    let script = repo().join("tests/oracles/ruckig_oracle.py");
    let out = Command::new(oracle_python(&repo()))
        .arg(&script)
        .args([
            "gen",
            "--seed",
            &seed.to_string(),
            "--n",
            &N_CASES.to_string(),
        ])
        .args([
            "--dofs",
            &dofs.to_string(),
            "--kind",
            kind,
            "--categories",
            categories,
        ])
        .output()
        .expect("run ruckig_oracle.py (run `bash .ci/install`)");
    assert!(
        out.status.success(),
        "ruckig_oracle.py failed (run `bash .ci/install`): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let cases: Vec<Case> = text
        .lines()
        .map(|l| case::parse(l).expect("oracle line"))
        .collect();
    assert_eq!(cases.len(), N_CASES);
    cases
}

#[derive(Default, Debug)]
struct Report {
    cases: usize,
    ruckig_ok: usize,
    /// Ruckig solved it and ours matched it (no failure recorded).
    agreed: usize,
    /// Both failed, for the same reason.
    both_refused: usize,
    ours_ok_where_ruckig_fails: usize,
    max_dur_err: f64,
    max_final: [f64; 3],
    max_excess: [f64; 3],
    samples: usize,
    replans: usize,
    max_replan_longer: f64,
    min_replan_rel: f64,
    failures: Vec<String>,
    n_failures: usize,
    by_category: std::collections::BTreeMap<String, usize>,
}

impl Report {
    fn fail(&mut self, msg: String) {
        self.n_failures += 1;
        if let (Some(a), Some(b)) = (msg.find('('), msg.find(')')) {
            *self
                .by_category
                .entry(msg[a + 1..b].to_string())
                .or_default() += 1;
        }
        if self.failures.len() < 20 {
            self.failures.push(msg);
        } else if self.failures.len() == 20 {
            self.failures.push("…".into());
        }
    }
}

fn limits(c: &Case, i: usize) -> (f64, f64, f64, f64, f64) {
    let vmin = c.v_min.as_ref().map_or(-c.v_max[i], |v| v[i]);
    let amin = c.a_min.as_ref().map_or(-c.a_max[i], |v| v[i]);
    (c.v_max[i], vmin, c.a_max[i], amin, c.j_max[i])
}

/// Final state, limits and straight-line checks of one solution.
fn check_solution(c: &Case, s: &Solved, r: &mut Report) {
    let position = c.kind == ControlInterface::Position;
    let t_end = s.duration;
    let (p, v, a) = s.at(t_end);
    for i in 0..c.dofs {
        let e = [
            if position {
                (p[i] - c.pf[i]).abs()
            } else {
                0.0
            },
            (v[i] - c.vf[i]).abs(),
            (a[i] - c.af[i]).abs(),
        ];
        for (m, x) in r.max_final.iter_mut().zip(e) {
            *m = m.max(x);
        }
        if e[0] > 1e-8 || e[1] > 1e-8 || e[2] > 1e-10 {
            r.fail(format!(
                "case {} ({}) DoF {i}: final error {e:?}",
                c.id, c.category
            ));
        }
        if !(p[i].is_finite() && v[i].is_finite() && a[i].is_finite()) {
            r.fail(format!("case {}: non-finite final state", c.id));
        }
    }

    if c.current_within_limits {
        let steps = (t_end / c.delta_time).ceil() as usize;
        for k in 0..=steps {
            let t = (k as f64 * c.delta_time).min(t_end);
            r.samples += 1;
            // Per DoF, without collecting the state (10⁷–10⁸ DoF samples per run).
            for (i, prof) in s.profiles.iter().enumerate() {
                let (_, v, a, _) = prof.state_in(t, t_end);
                let (vmax, vmin, amax, amin, _) = limits(c, i);
                let xv = if position {
                    (v - vmax * (1.0 + 1e-12)).max(vmin * (1.0 + 1e-12) - v)
                } else {
                    f64::NEG_INFINITY
                };
                let xa = (a - amax * (1.0 + 1e-12)).max(amin * (1.0 + 1e-12) - a);
                r.max_excess[0] = r.max_excess[0].max(xv);
                r.max_excess[1] = r.max_excess[1].max(xa);
                if xv > 0.0 || xa > 0.0 {
                    r.fail(format!(
                        "case {} ({}) DoF {i} t={t}: limit excess v {xv:e} a {xa:e}",
                        c.id, c.category
                    ));
                }
            }
        }
        for (i, prof) in s.profiles.iter().enumerate() {
            let jmax = c.j_max[i];
            for &j in prof.j.iter().chain(prof.brake.j.iter()) {
                let x = j.abs() - jmax * (1.0 + 1e-12);
                r.max_excess[2] = r.max_excess[2].max(x);
                if x > 0.0 {
                    r.fail(format!("case {} DoF {i}: jerk {j} > {jmax}", c.id));
                }
            }
        }
    }

    if c.synchronization == Synchronization::Phase
        && c.ruckig
            .as_ref()
            .and_then(|x| x.limiting_dofs.as_ref())
            .is_some()
    {
        let ruckig_phase = c.raw["result"]["phase_synced"].as_bool() == Some(true);
        if ruckig_phase && !case::phase_synced(s) {
            r.fail(format!(
                "case {}: Ruckig is phase synchronised, we are not",
                c.id
            ));
        }
        if case::phase_synced(s) {
            check_straight(c, s, r);
        }
    }
}

/// The path (position kind) or velocity (velocity kind) stays on one line.
fn check_straight(c: &Case, s: &Solved, r: &mut Report) {
    let position = c.kind == ControlInterface::Position;
    let (p0, _, _) = s.at(0.0);
    let base: Vec<f64> = if position {
        p0.clone()
    } else {
        vec![0.0; c.dofs]
    };
    for k in 1..=20 {
        let t = s.duration * k as f64 / 20.0;
        let (p, v, _) = s.at(t);
        let x: Vec<f64> = if position { p } else { v };
        let d: Vec<f64> = x.iter().zip(&base).map(|(a, b)| a - b).collect();
        let dir = direction(c);
        let norm2: f64 = dir.iter().map(|x| x * x).sum();
        if norm2 == 0.0 {
            continue;
        }
        let s_t = d.iter().zip(&dir).map(|(a, b)| a * b).sum::<f64>() / norm2;
        let off = d
            .iter()
            .zip(&dir)
            .map(|(a, b)| (a - s_t * b).abs())
            .fold(0.0, f64::max);
        if off > 1e-9 {
            r.fail(format!(
                "case {}: phase-synchronised motion leaves the line by {off:e}",
                c.id
            ));
        }
    }
}

/// The common direction of the collinear boundary vectors.
fn direction(c: &Case) -> Vec<f64> {
    let pd: Vec<f64> = (0..c.dofs).map(|i| c.pf[i] - c.p0[i]).collect();
    let position = c.kind == ControlInterface::Position;
    let candidates = [
        if position { pd } else { vec![0.0; c.dofs] },
        c.v0.clone(),
        c.a0.clone(),
        c.vf.clone(),
        c.af.clone(),
    ];
    candidates
        .into_iter()
        .find(|v| v.iter().any(|x| *x != 0.0))
        .unwrap_or_else(|| vec![0.0; c.dofs])
}

/// Bellman consistency: re-plan from states on the trajectory.
fn check_replan(c: &Case, s: &Solved, r: &mut Report) {
    let t_total = s.duration;
    if t_total <= 0.0 {
        return;
    }
    let discrete = c.discretization == otg::DurationDiscretization::Discrete;
    for f in [0.25, 0.5, 0.75] {
        // A discrete trajectory is re-planned on a control cycle, and a
        // minimum duration counts from the original start.
        let t = if discrete {
            (f * t_total / c.delta_time).floor() * c.delta_time
        } else {
            f * t_total
        };
        let mut c = c.clone();
        c.minimum_duration = c.minimum_duration.map(|m| (m - t).max(0.0));
        let c = &c;
        let (p, v, a) = s.at(t);
        let remaining = t_total - t;
        match case::solve(c, Some((&p, &v, &a))) {
            Ok(s2) => {
                r.replans += 1;
                let rel = (s2.duration - remaining) / t_total.max(1.0);
                r.max_replan_longer = r.max_replan_longer.max(rel);
                r.min_replan_rel = r.min_replan_rel.min(rel);
                if !(-1e-9..=1e-6).contains(&rel) {
                    r.fail(format!(
                        "case {} ({}) replan at f={f}: remaining {remaining}, new {} (rel {rel:e})",
                        c.id, c.category, s2.duration
                    ));
                }
            }
            Err(e) => r.fail(format!(
                "case {} ({}) replan at f={f} failed: {e}",
                c.id, c.category
            )),
        }
    }
}

/// Whether a failure of both is expected: both refuse an invalid input, or
/// both find the duration beyond the maximum. Anything else (our Step 1 or
/// Step 2 failing, or a different refusal) is a bug on one side.
fn same_refusal(ours: &OtgError, ruckig_status: &str) -> bool {
    match ours {
        OtgError::InvalidInput { .. } => matches!(
            ruckig_status,
            "RuckigError" | "ErrorInvalidInput" | "ErrorPositionalLimits" | "ErrorZeroLimits"
        ),
        OtgError::TrajectoryDuration => ruckig_status == "ErrorTrajectoryDuration",
        OtgError::ExecutionTimeCalculation { .. } | OtgError::SynchronizationCalculation { .. } => {
            false
        }
    }
}

fn run(seed: u64, dofs: usize, kind: &str, categories: &str) -> Option<String> {
    let cases = generate(seed, dofs, kind, categories);
    let mut r = Report::default();
    for c in &cases {
        r.cases += 1;
        let ours = case::solve(c, None);
        let ruckig = c.ruckig.as_ref().expect("oracle result");
        if ruckig.status == "Working" {
            r.ruckig_ok += 1;
            let Ok(s) = &ours else {
                r.fail(format!(
                    "case {} ({}): Ruckig Working, ours {}",
                    c.id,
                    c.category,
                    case::status_name(&ours)
                ));
                continue;
            };
            let t = ruckig.duration.expect("duration");
            let err = (s.duration - t).abs() / t.max(1.0);
            r.max_dur_err = r.max_dur_err.max(err);
            if err > 1e-9 {
                r.fail(format!(
                    "case {} ({}): duration {} vs Ruckig {t}",
                    c.id, c.category, s.duration
                ));
            }
            let failures = r.n_failures;
            check_solution(c, s, &mut r);
            check_replan(c, s, &mut r);
            if r.n_failures == failures {
                r.agreed += 1;
            }
        } else if let Ok(s) = &ours {
            // Where Ruckig fails we may succeed, but then correctly.
            r.ours_ok_where_ruckig_fails += 1;
            check_solution(c, s, &mut r);
        } else if let Err(e) = &ours
            && same_refusal(e, &ruckig.status)
        {
            r.both_refused += 1;
        } else {
            r.fail(format!(
                "case {} ({}): both fail, for different reasons: Ruckig {}, ours {ours:?}",
                c.id, c.category, ruckig.status
            ));
        }
    }
    if r.agreed < MIN_AGREEING {
        r.fail(format!(
            "only {} of {} cases solved by Ruckig and matched: floor {MIN_AGREEING}, Ruckig ok {}",
            r.agreed, r.cases, r.ruckig_ok
        ));
    }
    eprintln!(
        "oracle {dofs} DoF {kind} {categories}: {} failures {:?}, {} cases, Ruckig ok {}, agreed {}, ours-only ok {}, both refused {}, max duration err {:e}, \
         max final err {:?}, max limit excess (v,a,j) {:?} over {} samples, replans {} (rel range [{:e}, {:e}])",
        r.n_failures,
        r.by_category,
        r.cases,
        r.ruckig_ok,
        r.agreed,
        r.ours_ok_where_ruckig_fails,
        r.both_refused,
        r.max_dur_err,
        r.max_final,
        r.max_excess,
        r.samples,
        r.replans,
        r.min_replan_rel,
        r.max_replan_longer
    );
    if r.failures.is_empty() {
        None
    } else {
        Some(format!(
            "{dofs} DoF {kind} {categories}:\n{}",
            r.failures.join("\n")
        ))
    }
}

/// The installed oracle is the Ruckig these tests were calibrated against.
#[test]
fn the_oracle_is_the_pinned_ruckig() {
    let out = Command::new(oracle_python(&repo()))
        .args([
            "-c",
            "import importlib.metadata as m; print(m.version('ruckig'))",
        ])
        .output()
        .expect("run the oracle Python");
    assert!(
        out.status.success(),
        "ruckig is not installed (run `bash .ci/install`): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let installed = String::from_utf8_lossy(&out.stdout).trim().to_string();
    assert_eq!(
        installed, RUCKIG_VERSION,
        "the oracle's ruckig is {installed}, the tests expect {RUCKIG_VERSION} (run `bash .ci/install`)"
    );
}

macro_rules! oracle_test {
    ($name:ident, $seed:expr, $dofs:expr, $kind:expr) => {
        #[test]
        fn $name() {
            let errors: Vec<String> = [
                run($seed, $dofs, $kind, "core"),
                run($seed + 100, $dofs, $kind, "all"),
            ]
            .into_iter()
            .flatten()
            .collect();
            assert!(errors.is_empty(), "{}", errors.join("\n"));
        }
    };
}

oracle_test!(position_1dof, 11, 1, "position");
oracle_test!(position_3dof, 13, 3, "position");
oracle_test!(position_7dof, 17, 7, "position");
oracle_test!(position_18dof, 28, 18, "position");
oracle_test!(velocity_1dof, 31, 1, "velocity");
oracle_test!(velocity_3dof, 33, 3, "velocity");
oracle_test!(velocity_7dof, 37, 7, "velocity");
oracle_test!(velocity_18dof, 48, 18, "velocity");
