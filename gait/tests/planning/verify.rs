//! An independent checker of hand states along a plan (SPEC §1.3), written
//! from the configuration alone — it does not reuse the planner's geometry.

#![allow(dead_code)]

use gait::planner::{Plan, Step};
use gait::{FingerMode, HandConfig, HandState};
use nalgebra::Vector3;
use test_support::random::angle;

/// A violated invariant.
#[derive(Debug, Clone)]
pub struct Violation {
    pub step: usize,
    pub what: &'static str,
    pub finger: usize,
    pub value: f64,
}

pub struct Checker {
    r_obj: f64,
    r_tip: f64,
    base: [Vector3<f64>; 3],
    cone: f64,
    roll: f64,
    shell_top: f64,
    min_dist: f64,
    fc_angle: f64,
    theta: f64,
    tol: f64,
}

impl Checker {
    pub fn new(c: &HandConfig) -> Self {
        let m = &c.model;
        Self {
            r_obj: m.object_radius,
            r_tip: m.fingertip_radius,
            base: m.finger_azimuth_deg.map(|a| {
                let a = a.to_radians();
                Vector3::new(a.cos(), a.sin(), 0.0)
            }),
            cone: (m.workspace_half_angle_deg - m.workspace_margin_deg).to_radians(),
            roll: (m.roll_limit_deg - m.roll_margin_deg).to_radians(),
            shell_top: m.object_radius + m.fingertip_radius + m.free_space_height,
            min_dist: 2.0 * m.fingertip_radius + m.fingertip_clearance,
            fc_angle: (180.0 - 2.0 * m.friction_angle_deg + m.fc_margin_deg).to_radians(),
            theta: m.friction_angle_deg.to_radians(),
            tol: 1e-9,
        }
    }

    /// Every violated invariant of one state.
    pub fn check(&self, s: &HandState, step: usize, out: &mut Vec<Violation>) {
        let mut v = |what, finger, value| {
            out.push(Violation {
                step,
                what,
                finger,
                value,
            })
        };
        let rc = self.r_obj + self.r_tip;
        let mut grasp = Vec::new();
        for (k, f) in s.fingers.iter().enumerate() {
            let rho = f.center.norm();
            let dir = f.center / rho;
            let ang = angle(&dir, &self.base[k]);
            if ang > self.cone + self.tol {
                v("workspace", k, ang.to_degrees());
            }
            if f.roll.abs() > self.roll + self.tol {
                v("roll", k, f.roll.to_degrees());
            }
            match f.mode {
                FingerMode::Grasping => {
                    grasp.push(dir);
                    if (rho - rc).abs() > 1e-9 {
                        v("contact gap", k, rho - rc);
                    }
                    let m = f.orientation.inverse() * (-dir);
                    if m.z < -self.tol {
                        v("hemisphere", k, m.z);
                    }
                }
                FingerMode::Free => {
                    if rho < rc - 1e-9 || rho > self.shell_top + 1e-9 {
                        v("free shell", k, rho);
                    }
                }
            }
        }
        for i in 0..3 {
            for j in i + 1..3 {
                let d = (s.fingers[i].center - s.fingers[j].center).norm();
                if d < self.min_dist - self.tol {
                    v("collision", i, d);
                }
            }
        }
        let fc = match grasp.len() {
            2 => angle(&grasp[0], &grasp[1]) >= self.fc_angle - self.tol,
            3 => {
                let pair =
                    |a: usize, b: usize| angle(&grasp[a], &grasp[b]) >= self.fc_angle - self.tol;
                pair(0, 1) || pair(0, 2) || pair(1, 2) || self.fact4(&grasp)
            }
            _ => false,
        };
        if !fc {
            v("force closure", 0, grasp.len() as f64);
        }
        let q = s.object.quaternion();
        if !q.coords.iter().all(|x| x.is_finite()) {
            v("nan", 0, 0.0);
        }
    }

    fn fact4(&self, p: &[Vector3<f64>]) -> bool {
        let acute =
            |a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>| (b - a).dot(&(c - a)) > 0.0;
        if !(acute(&p[0], &p[1], &p[2]) && acute(&p[1], &p[2], &p[0]) && acute(&p[2], &p[0], &p[1]))
        {
            return false;
        }
        let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
        (n.dot(&p[0]).abs() / n.norm()) < self.theta.sin()
    }

    /// Checks `samples + 1` states along every step (parameters advanced in
    /// proportion) and the end state; returns the violations.
    pub fn check_plan(&self, plan: &Plan, samples: usize) -> Vec<Violation> {
        let mut out = Vec::new();
        self.check(&plan.start, usize::MAX, &mut out);
        for (i, st) in plan.steps.iter().enumerate() {
            self.check_step(st, i, samples, &mut out);
        }
        out
    }

    pub fn check_step(&self, st: &Step, i: usize, samples: usize, out: &mut Vec<Violation>) {
        let d = st.dofs();
        for k in 0..=samples {
            let lam = k as f64 / samples as f64;
            let s = d.length.map(|l| l * lam);
            let state = st.eval(&s, &[0.0; 3]).state;
            self.check(&state, i, out);
        }
    }
}
