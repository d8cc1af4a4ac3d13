//! Fixed-step integrators for the two forms of the contact kinematics.
//!
//! - [`VectorIntegrator`]: the vector form (SPEC §2.3) on
//!   SO(3) × SO(3) × S² × ℝ by the Runge–Kutta–Munthe-Kaas method with the
//!   classical RK4 tableau and the exact inverse differential of exp
//!   (order 4; every update is an exponential, never a sum of quaternion
//!   components). For rates constant over a step without slip,
//!   [`VectorIntegrator::advance_constant`] is exact: both bodies and the
//!   normal turn about fixed axes.
//! - [`ChartIntegrator`]: Montana's equations (SPEC §2.2) in chart
//!   coordinates by classical RK4, with longitudes wrapped and charts
//!   switched between steps by the atlas hysteresis; ψ follows the frame
//!   change. It is the independent oracle for the vector form.
//!
//! Both accumulate the contact arc length travelled on each body
//! (quadrature of the speeds with the same RK4 stages). Neither allocates.

use super::montana::{ChartContact, ContactTwist, montana};
use super::state::{ContactGeometry, ContactState};
use super::vector::{BodyRates, contact_rates};
use crate::sphere::chart::wrap_angle;
use crate::sphere::rotation::{dexp_inv, exp, rotate};
use crate::sphere::{ChartPoint, hysteresis};
use nalgebra::{SVector, UnitQuaternion, Vector3};

/// Integrates the vector form of the contact kinematics (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VectorIntegrator {
    /// Radii.
    pub geom: ContactGeometry,
    /// Current contact state.
    pub state: ContactState,
    /// Arc length travelled by the contact point on the object \[m\].
    pub arc_object: f64,
    /// Arc length travelled by the contact point on the fingertip \[m\].
    pub arc_fingertip: f64,
}

/// Lie-algebra velocity of the three group components plus scalar rates.
#[derive(Clone, Copy)]
struct Tangent {
    object: Vector3<f64>,
    fingertip: Vector3<f64>,
    normal: Vector3<f64>,
    /// τ̇, object-contact speed, fingertip-contact speed.
    scalars: Vector3<f64>,
}

impl VectorIntegrator {
    /// Starts at `state` with zero arc lengths.
    pub fn new(geom: ContactGeometry, state: ContactState) -> Self {
        Self {
            geom,
            state,
            arc_object: 0.0,
            arc_fingertip: 0.0,
        }
    }

    fn tangent(&self, s: &ContactState, b: &BodyRates) -> Tangent {
        let g = &self.geom;
        let d = g.center_distance();
        let n = &s.normal;
        let vs = b.slip - n * n.dot(&b.slip);
        let cr = contact_rates(g, s, b);
        Tangent {
            object: b.object,
            fingertip: b.fingertip,
            // ṅ = w × n with w = (R ω_o + r ω_f + n × v_s)/(R + r).
            normal: (b.object * g.object_radius + b.fingertip * g.fingertip_radius + n.cross(&vs))
                / d,
            scalars: Vector3::new(
                cr.roll,
                cr.object_contact.norm() * g.object_radius,
                cr.fingertip_contact.norm() * g.fingertip_radius,
            ),
        }
    }

    fn stage(s0: &ContactState, u: &Tangent) -> ContactState {
        ContactState {
            object: exp(&u.object) * s0.object,
            fingertip: exp(&u.fingertip) * s0.fingertip,
            normal: exp(&u.normal) * s0.normal,
            roll: s0.roll + u.scalars.x,
        }
    }

    /// One RKMK4 step of size `h` from time `t`; `rates(t, state)` gives
    /// the body rates at a stage (it may depend on the state, e.g. for
    /// inputs expressed in the contact frame).
    pub fn step<F>(&mut self, t: f64, h: f64, mut rates: F)
    where
        F: FnMut(f64, &ContactState) -> BodyRates,
    {
        let s0 = self.state;
        let scale = |x: &Tangent, k: f64| Tangent {
            object: x.object * k,
            fingertip: x.fingertip * k,
            normal: x.normal * k,
            scalars: x.scalars * k,
        };
        // k_i = h dexp⁻¹_{u_i}(f(exp(u_i) y₀)), componentwise on the product group.
        let mut eval = |tt: f64, u: &Tangent| -> Tangent {
            let s = Self::stage(&s0, u);
            let f = self.tangent(&s, &rates(tt, &s));
            Tangent {
                object: dexp_inv(&u.object, &f.object) * h,
                fingertip: dexp_inv(&u.fingertip, &f.fingertip) * h,
                normal: dexp_inv(&u.normal, &f.normal) * h,
                scalars: f.scalars * h,
            }
        };
        let zero = Tangent {
            object: Vector3::zeros(),
            fingertip: Vector3::zeros(),
            normal: Vector3::zeros(),
            scalars: Vector3::zeros(),
        };
        let k1 = eval(t, &zero);
        let k2 = eval(t + 0.5 * h, &scale(&k1, 0.5));
        let k3 = eval(t + 0.5 * h, &scale(&k2, 0.5));
        let k4 = eval(t + h, &k3);
        let comb =
            |f: fn(&Tangent) -> Vector3<f64>| (f(&k1) + f(&k2) * 2.0 + f(&k3) * 2.0 + f(&k4)) / 6.0;
        let u = Tangent {
            object: comb(|k| k.object),
            fingertip: comb(|k| k.fingertip),
            normal: comb(|k| k.normal),
            scalars: comb(|k| k.scalars),
        };
        let s1 = Self::stage(&s0, &u);
        self.state = ContactState {
            object: UnitQuaternion::new_normalize(s1.object.into_inner()),
            fingertip: UnitQuaternion::new_normalize(s1.fingertip.into_inner()),
            normal: s1.normal.normalize(),
            roll: s1.roll,
        };
        self.arc_object += u.scalars.y;
        self.arc_fingertip += u.scalars.z;
    }

    /// Exact step for body rates constant over `dt` without slip (the slip
    /// field is ignored): Q_o ← exp(ω_o dt) Q_o, Q_f ← exp(ω_f dt) Q_f,
    /// n ← exp(w dt) n with w = (R ω_o + r ω_f)/(R + r), τ ← τ + dt ω_f·a_f
    /// (a_f turns about ω_f, so ω_f·a_f is constant). Arc lengths by
    /// Simpson's rule on the exact motion.
    pub fn advance_constant(&mut self, rates: &BodyRates, dt: f64) {
        let g = self.geom;
        let b = BodyRates {
            slip: Vector3::zeros(),
            ..*rates
        };
        let w =
            (b.object * g.object_radius + b.fingertip * g.fingertip_radius) / g.center_distance();
        let s0 = self.state;
        let at = |x: f64| ContactState {
            object: exp(&(b.object * x)) * s0.object,
            fingertip: exp(&(b.fingertip * x)) * s0.fingertip,
            normal: rotate_scaled(&w, x, &s0.normal),
            roll: s0.roll + x * b.fingertip.dot(&s0.pole_axis()),
        };
        let speeds = |s: &ContactState| {
            let cr = contact_rates(&g, s, &b);
            (
                cr.object_contact.norm() * g.object_radius,
                cr.fingertip_contact.norm() * g.fingertip_radius,
            )
        };
        let (a0, f0) = speeds(&s0);
        let (am, fm) = speeds(&at(0.5 * dt));
        let s1 = at(dt);
        let (a1, f1) = speeds(&s1);
        self.arc_object += dt * (a0 + 4.0 * am + a1) / 6.0;
        self.arc_fingertip += dt * (f0 + 4.0 * fm + f1) / 6.0;
        self.state = ContactState {
            object: UnitQuaternion::new_normalize(s1.object.into_inner()),
            fingertip: UnitQuaternion::new_normalize(s1.fingertip.into_inner()),
            normal: s1.normal.normalize(),
            roll: s1.roll,
        };
    }
}

/// exp([w x]×) v for a non-unit w (rotation by |w| x about w/|w|).
fn rotate_scaled(w: &Vector3<f64>, x: f64, v: &Vector3<f64>) -> Vector3<f64> {
    let norm = w.norm();
    if norm == 0.0 {
        *v
    } else {
        rotate(&(w / norm), norm * x, v)
    }
}

/// Integrates Montana's equations in chart coordinates (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartIntegrator {
    /// Radii.
    pub geom: ContactGeometry,
    /// Current contact coordinates.
    pub state: ChartContact,
    /// Arc length travelled by the contact point on the object \[m\].
    pub arc_object: f64,
    /// Arc length travelled by the contact point on the fingertip \[m\].
    pub arc_fingertip: f64,
    /// Number of chart switches so far (both bodies).
    pub switches: u32,
}

type Y = SVector<f64, 7>;

impl ChartIntegrator {
    /// Starts at `state` with zero arc lengths.
    pub fn new(geom: ContactGeometry, state: ChartContact) -> Self {
        Self {
            geom,
            state,
            arc_object: 0.0,
            arc_fingertip: 0.0,
            switches: 0,
        }
    }

    fn rhs(&self, y: &Y, twist: &ContactTwist) -> Y {
        let c = ChartContact {
            finger: ChartPoint {
                chart: self.state.finger.chart,
                u: y[0],
                v: y[1],
            },
            object: ChartPoint {
                chart: self.state.object.chart,
                u: y[2],
                v: y[3],
            },
            psi: y[4],
        };
        let r = montana(&self.geom, &c, twist);
        let g = &self.geom;
        // Speeds |M α̇| = ρ sqrt(u̇² + cos²u v̇²).
        let so = g.object_radius * r.object.x.hypot(y[2].cos() * r.object.y);
        let sf = g.fingertip_radius * r.finger.x.hypot(y[0].cos() * r.finger.y);
        Y::from([
            r.finger.x, r.finger.y, r.object.x, r.object.y, r.psi, so, sf,
        ])
    }

    /// One RK4 step of size `h` from time `t`; `twist(t)` is the relative
    /// motion in the current fingertip contact frame. After the step the
    /// longitudes and ψ are wrapped and each contact point changes chart if
    /// the hysteresis says so (ψ += χ).
    pub fn step<F>(&mut self, t: f64, h: f64, mut twist: F)
    where
        F: FnMut(f64) -> ContactTwist,
    {
        let s = &self.state;
        let y0 = Y::from([
            s.finger.u, s.finger.v, s.object.u, s.object.v, s.psi, 0.0, 0.0,
        ]);
        let k1 = self.rhs(&y0, &twist(t));
        let k2 = self.rhs(&(y0 + k1 * (0.5 * h)), &twist(t + 0.5 * h));
        let k3 = self.rhs(&(y0 + k2 * (0.5 * h)), &twist(t + 0.5 * h));
        let k4 = self.rhs(&(y0 + k3 * h), &twist(t + h));
        let y1 = y0 + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        let mut next = ChartContact {
            finger: ChartPoint::new(s.finger.chart, y1[0], y1[1]),
            object: ChartPoint::new(s.object.chart, y1[2], y1[3]),
            psi: y1[4],
        };
        if let Some(sw) = hysteresis(&next.finger) {
            next.finger = sw.point;
            next.psi += sw.frame_angle;
            self.switches += 1;
        }
        if let Some(sw) = hysteresis(&next.object) {
            next.object = sw.point;
            next.psi += sw.frame_angle;
            self.switches += 1;
        }
        next.psi = wrap_angle(next.psi);
        self.state = next;
        self.arc_object += y1[5];
        self.arc_fingertip += y1[6];
    }
}
