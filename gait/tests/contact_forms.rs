//! Contact kinematics (SPEC §2.2–2.3): Montana's chart form and the vector
//! form integrated side by side along seeded random motions — with spin,
//! with slip, through chart switches — agree to 1e-9 over 10⁴ steps; both
//! contact points travel equal arc lengths when rolling; Theory 2 and
//! eq. (4) hold; the state conversions round-trip.

mod common;

use gait::contact::{
    BodyRates, ChartContact, ChartIntegrator, ContactGeometry, ContactState, ContactTwist,
    VectorIntegrator, body_rates_from_twist, contact_rates, montana, rolling_finger_rates,
    rolling_object_rates, twist_from_body_rates,
};
use gait::sphere::chart::wrap_angle;
use gait::sphere::{ChartId, ChartPoint, best_chart};
use gait::{HandConfig, HandState};
use nalgebra::{UnitQuaternion, Vector2, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

fn geom() -> ContactGeometry {
    ContactGeometry::from_config(&HandConfig::default())
}

/// A random contact state in the hand frame.
fn random_state(rng: &mut ChaCha8Rng) -> ContactState {
    let object = common::rotation(rng);
    let n_o = common::unit(rng);
    let m = common::hemisphere_point(rng);
    let rel = common::touching(rng, &n_o, &m);
    ContactState {
        object,
        fingertip: object * rel,
        normal: object * n_o,
        roll: rng.random_range(-1.0..1.0),
    }
}

/// Smooth random signal: a sum of three sinusoids per component.
#[derive(Clone, Copy)]
struct Signal {
    amp: [[f64; 3]; 3],
    freq: [[f64; 3]; 3],
    phase: [[f64; 3]; 3],
    bias: [f64; 3],
}

impl Signal {
    fn new(rng: &mut ChaCha8Rng, scale: f64) -> Self {
        let mut s = Signal {
            amp: [[0.0; 3]; 3],
            freq: [[0.0; 3]; 3],
            phase: [[0.0; 3]; 3],
            bias: [0.0; 3],
        };
        for c in 0..3 {
            s.bias[c] = rng.random_range(-0.5..0.5) * scale;
            for j in 0..3 {
                s.amp[c][j] = rng.random_range(-1.0..1.0) * scale;
                s.freq[c][j] = rng.random_range(0.2..3.0);
                s.phase[c][j] = rng.random_range(0.0..6.3);
            }
        }
        s
    }

    fn at(&self, t: f64) -> Vector3<f64> {
        Vector3::from_fn(|c, _| {
            self.bias[c]
                + (0..3)
                    .map(|j| self.amp[c][j] * (self.freq[c][j] * t + self.phase[c][j]).sin())
                    .sum::<f64>()
        })
    }
}

struct Run {
    max_contact_err: f64,
    max_psi_err: f64,
    arc_err: f64,
    arc_gap_chart: f64,
    arc_gap_vector: f64,
    switches: u32,
    arc: f64,
}

/// Integrates both forms with the same relative motion (given in the
/// fingertip contact frame) and compares them every step.
fn run(seed: u64, spin: bool, slip: bool, steps: usize, h: f64) -> Run {
    let g = geom();
    let mut rng = common::rng(seed);
    let s0 = random_state(&mut rng);
    let fc = best_chart(&s0.fingertip_contact());
    let oc = best_chart(&s0.object_contact());
    let mut chart = ChartIntegrator::new(g, s0.chart_contact(fc, oc));
    let mut vector = VectorIntegrator::new(g, s0);
    let omega = Signal::new(&mut rng, 2.5);
    let slip_sig = Signal::new(&mut rng, 0.08);
    let object_sig = Signal::new(&mut rng, 1.0);
    let twist = move |t: f64| {
        let mut w = omega.at(t);
        if !spin {
            w.z = 0.0;
        }
        let mut v = if slip {
            slip_sig.at(t)
        } else {
            Vector3::zeros()
        };
        v.z = 0.0;
        ContactTwist {
            linear: v,
            angular: w,
        }
    };
    let mut out = Run {
        max_contact_err: 0.0,
        max_psi_err: 0.0,
        arc_err: 0.0,
        arc_gap_chart: 0.0,
        arc_gap_vector: 0.0,
        switches: 0,
        arc: 0.0,
    };
    for i in 0..steps {
        let t = i as f64 * h;
        let finger_chart = chart.state.finger.chart;
        vector.step(t, h, |tt, s| {
            body_rates_from_twist(s, finger_chart, &object_sig.at(tt), &twist(tt))
        });
        chart.step(t, h, twist);
        let c = &chart.state;
        let s = &vector.state;
        let e_o = (c.object.unit() - s.object_contact()).norm();
        let e_f = (c.finger.unit() - s.fingertip_contact()).norm();
        let psi = s.chart_contact(c.finger.chart, c.object.chart).psi;
        out.max_contact_err = out.max_contact_err.max(e_o).max(e_f);
        out.max_psi_err = out.max_psi_err.max(wrap_angle(psi - c.psi).abs());
    }
    out.arc_err = (chart.arc_object - vector.arc_object)
        .abs()
        .max((chart.arc_fingertip - vector.arc_fingertip).abs());
    out.arc_gap_chart = (chart.arc_object - chart.arc_fingertip).abs();
    out.arc_gap_vector = (vector.arc_object - vector.arc_fingertip).abs();
    out.switches = chart.switches;
    out.arc = vector.arc_object;
    out
}

#[test]
fn chart_and_vector_forms_agree_over_ten_thousand_steps() {
    let mut switches = 0;
    // (spin, slip): pure rolling, rolling with spin, general motion with slip.
    for (seed, spin, slip) in [
        (10, false, false),
        (11, false, false),
        (12, true, false),
        (13, true, false),
        (14, true, true),
        (15, true, true),
    ] {
        let r = run(seed, spin, slip, 10_000, 1e-3);
        eprintln!(
            "seed {seed} spin {spin} slip {slip}: contact {:.1e}, psi {:.1e}, arc {:.1e}, \
             switches {}, arc length {:.2} m",
            r.max_contact_err, r.max_psi_err, r.arc_err, r.switches, r.arc
        );
        assert!(
            r.max_contact_err <= 1e-9,
            "contact error {}",
            r.max_contact_err
        );
        assert!(r.max_psi_err <= 1e-9, "psi error {}", r.max_psi_err);
        assert!(r.arc_err <= 1e-9, "arc length error {}", r.arc_err);
        assert!(r.arc > 0.5, "the contact must travel");
        if !slip {
            // Rolling (with or without spin): equal arc lengths on both bodies.
            assert!(r.arc_gap_chart <= 1e-9, "{}", r.arc_gap_chart);
            assert!(r.arc_gap_vector <= 1e-12, "{}", r.arc_gap_vector);
        } else {
            assert!(r.arc_gap_vector > 1e-3, "slip must separate the arcs");
        }
        switches += r.switches;
    }
    assert!(switches >= 6, "runs must cross chart switches ({switches})");
}

#[test]
fn vector_form_keeps_material_points_together_when_rolling() {
    // Rolling without slip: the velocities of the two material points at
    // the contact are equal; with slip they differ by exactly the slip.
    let g = geom();
    let mut rng = common::rng(20);
    for _ in 0..5000 {
        let s = random_state(&mut rng);
        let slip = if rng.random_bool(0.5) {
            let v = common::unit(&mut rng) * 0.1;
            v - s.normal * s.normal.dot(&v)
        } else {
            Vector3::zeros()
        };
        let b = BodyRates {
            object: common::unit(&mut rng) * rng.random_range(0.0..3.0),
            fingertip: common::unit(&mut rng) * rng.random_range(0.0..3.0),
            slip,
        };
        let r = contact_rates(&g, &s, &b);
        let n = s.normal;
        let v_fp = r.center + b.fingertip.cross(&(-n * g.fingertip_radius));
        let v_op = b.object.cross(&(n * g.object_radius));
        assert!((v_fp - v_op - slip).norm() < 1e-14);
        // The contact point itself: R ṅ = R ω_o × n + R Q_o ṅ_o (object side)
        // and R ṅ = r-side: −r d(Q_f m)/dt ... both give the same ṅ.
        let from_object = b.object.cross(&n) + s.object * r.object_contact;
        let from_finger = -(b.fingertip.cross(&(-n)) + s.fingertip * r.fingertip_contact);
        assert!((from_object - r.normal).norm() < 1e-14);
        assert!((from_finger - r.normal).norm() < 1e-14);
        assert!((r.spin - (b.fingertip - b.object).dot(&n)).abs() < 1e-15);
        // Twist round trip through Montana's contact frame.
        let fc = best_chart(&s.fingertip_contact());
        let tw = twist_from_body_rates(&s, fc, &b);
        let back = body_rates_from_twist(&s, fc, &b.object, &tw);
        assert!((back.fingertip - b.fingertip).norm() < 1e-14);
        assert!((back.slip - slip).norm() < 1e-14);
        // Montana's coordinate rates equal the vector form's, mapped through
        // the chart differential.
        let oc = best_chart(&s.object_contact());
        let c = s.chart_contact(fc, oc);
        let mr = montana(&g, &c, &tw);
        let (fo, ff) = (c.object.frame(), c.finger.frame());
        let om = gait::sphere::metric(1.0, c.object.u);
        let fm = gait::sphere::metric(1.0, c.finger.u);
        let dn_o =
            fo.column(0) * (om[(0, 0)] * mr.object.x) + fo.column(1) * (om[(1, 1)] * mr.object.y);
        let dm =
            ff.column(0) * (fm[(0, 0)] * mr.finger.x) + ff.column(1) * (fm[(1, 1)] * mr.finger.y);
        assert!((dn_o - r.object_contact).norm() < 1e-12);
        assert!((dm - r.fingertip_contact).norm() < 1e-12);
    }
}

#[test]
fn theory_2_great_circle_iff_great_circle() {
    let g = geom();
    let mut rng = common::rng(30);
    for trial in 0..200 {
        let s0 = random_state(&mut rng);
        let rel = s0.relative();
        let (n0, m0) = (rel.contact, rel.fingertip_contact());
        // Either pick the object great circle (normal k ⊥ n0) or the
        // fingertip great circle (normal g ⊥ m0 in the fingertip frame,
        // k = Q g): rolling about a fixed k traces both.
        let k_obj = if trial % 2 == 0 {
            let k = common::unit(&mut rng);
            (k - n0 * n0.dot(&k)).normalize()
        } else {
            let gf = common::unit(&mut rng);
            rel.fingertip * (gf - m0 * m0.dot(&gf)).normalize()
        };
        let object = s0.object;
        let b = BodyRates {
            object: Vector3::zeros(),
            fingertip: object * k_obj * rng.random_range(0.5..3.0),
            slip: Vector3::zeros(),
        };
        let mut vi = VectorIntegrator::new(g, s0);
        let plane_o = k_obj;
        let plane_f = rel.fingertip.inverse() * k_obj;
        for _ in 0..400 {
            vi.step(0.0, 2e-3, |_, _| b);
            let r = vi.state.relative();
            assert!(r.contact.dot(&plane_o).abs() < 1e-12);
            assert!(r.fingertip_contact().dot(&plane_f).abs() < 1e-12);
        }
        // Equal arcs: the fingertip contact angle is R/r times the object's.
        let r = vi.state.relative();
        let a_o = common::angle(&n0, &r.contact);
        let a_f = common::angle(&m0, &r.fingertip_contact());
        let expect = (a_o * g.object_radius / g.fingertip_radius).min(std::f64::consts::PI);
        if expect < 3.0 {
            assert!((a_f - expect).abs() < 1e-9, "{a_f} vs {expect}");
        }
    }
}

#[test]
fn theory_2_example_from_the_origin() {
    // From (u_f, v_f, u_o, v_o, ψ) = (0, 0, 0, 0, 0), moving the fingertip
    // contact to (0, Δv) by eq. (4) moves the object contact to
    // (0, −(r/R) Δv); ψ stays 0.
    let g = geom();
    let mut rng = common::rng(40);
    for _ in 0..100 {
        let dv = rng.random_range(-1.5..1.5);
        let mut c = ChartContact {
            finger: ChartPoint::new(ChartId::Primary, 0.0, 0.0),
            object: ChartPoint::new(ChartId::Primary, 0.0, 0.0),
            psi: 0.0,
        };
        let n = 1000;
        let rate = Vector2::new(0.0, dv);
        for _ in 0..n {
            let ao = rolling_object_rates(&g, &c, &rate);
            let psi = gait::contact::rolling_psi_rate(&g, &c, &rate, &ao);
            c.finger.v += dv / n as f64;
            c.object.u += ao.x / n as f64;
            c.object.v += ao.y / n as f64;
            c.psi += psi / n as f64;
        }
        assert!(c.object.u.abs() < 1e-15);
        assert!((c.object.v + g.fingertip_radius / g.object_radius * dv).abs() < 1e-12);
        assert!(c.psi.abs() < 1e-15);
    }
}

#[test]
fn theory_2_example_by_montanas_general_form() {
    // The same example driven through eq. (3) (ChartIntegrator, pure
    // rolling about the contact frame's x axis): u stays 0 on both bodies
    // and v_o = −(r/R) v_f throughout.
    let g = geom();
    let start = ChartContact {
        finger: ChartPoint::new(ChartId::Primary, 0.0, 0.0),
        object: ChartPoint::new(ChartId::Primary, 0.0, 0.0),
        psi: 0.0,
    };
    for wx in [-2.0, -0.3, 0.7, 2.5] {
        let mut ci = ChartIntegrator::new(g, start);
        for i in 0..1000 {
            ci.step(i as f64 * 1e-3, 1e-3, |_| ContactTwist {
                linear: Vector3::zeros(),
                angular: Vector3::new(wx, 0.0, 0.0),
            });
            let c = &ci.state;
            assert!(c.finger.u.abs() < 1e-15 && c.object.u.abs() < 1e-15);
            let ratio = g.fingertip_radius / g.object_radius;
            assert!((c.object.v + ratio * c.finger.v).abs() < 1e-13);
            assert!(c.psi.abs() < 1e-15);
        }
        assert!(ci.state.finger.v.abs() > 0.1);
    }
}

#[test]
fn eq_4_follows_from_eq_3() {
    let g = geom();
    let mut rng = common::rng(50);
    for _ in 0..20_000 {
        let s = random_state(&mut rng);
        let c = s.chart_contact(
            best_chart(&s.fingertip_contact()),
            best_chart(&s.object_contact()),
        );
        let tw = ContactTwist {
            linear: Vector3::zeros(),
            angular: Vector3::new(
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
                0.0,
            ),
        };
        let r = montana(&g, &c, &tw);
        let af = rolling_finger_rates(&g, &c, &r.object);
        assert!((af - r.finger).norm() < 1e-12 * (1.0 + r.finger.norm()));
        let ao = rolling_object_rates(&g, &c, &r.finger);
        assert!((ao - r.object).norm() < 1e-12 * (1.0 + r.object.norm()));
    }
}

#[test]
fn conversions_round_trip() {
    let g = geom();
    let mut rng = common::rng(60);
    for _ in 0..5000 {
        let s = random_state(&mut rng);
        let f = s.to_finger(&g);
        let back = ContactState::from_finger(&f, s.object, &g).unwrap();
        assert!((back.normal - s.normal).norm() < 1e-15);
        for fc in [ChartId::Primary, ChartId::Secondary] {
            for oc in [ChartId::Primary, ChartId::Secondary] {
                let c = s.chart_contact(fc, oc);
                let r = ContactState::from_chart_contact(&c, s.object, s.roll);
                assert!((r.normal - s.normal).norm() < 1e-13);
                assert!(r.fingertip.angle_to(&s.fingertip) < 1e-13);
            }
        }
        let rel = s.relative();
        let again = ContactState::from_relative(&rel, s.object);
        assert!(again.fingertip.angle_to(&s.fingertip) < 1e-14);
        assert!((rel.fingertip_contact() - s.fingertip_contact()).norm() < 1e-14);
    }
    // The paper's start converts; free or detached fingers do not.
    let cfg = HandConfig::default();
    let hs = HandState::paper_start(&cfg);
    for f in &hs.fingers {
        let c = ContactState::from_finger(f, hs.object, &g).unwrap();
        assert!((c.fingertip_contact() - Vector3::z()).norm() < 1e-12);
        assert!((c.hemisphere_margin() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
    let mut lifted = hs.fingers[0];
    lifted.center *= 1.01;
    assert_eq!(
        ContactState::from_finger(&lifted, hs.object, &g),
        Err(gait::contact::ContactError::NotTouching)
    );
    lifted.mode = gait::FingerMode::Free;
    assert_eq!(
        ContactState::from_finger(&lifted, hs.object, &g),
        Err(gait::contact::ContactError::NotGrasping)
    );
    let mut bad = hs.fingers[0];
    bad.roll = f64::NAN;
    assert_eq!(
        ContactState::from_finger(&bad, UnitQuaternion::identity(), &g),
        Err(gait::contact::ContactError::NonFinite)
    );
}

#[test]
fn exact_constant_rate_step_matches_rkmk4() {
    let g = geom();
    let mut rng = common::rng(70);
    for _ in 0..50 {
        let s = random_state(&mut rng);
        let b = BodyRates {
            object: common::unit(&mut rng) * rng.random_range(0.0..2.0),
            fingertip: common::unit(&mut rng) * rng.random_range(0.0..4.0),
            slip: Vector3::zeros(),
        };
        let mut exact = VectorIntegrator::new(g, s);
        let mut rk = VectorIntegrator::new(g, s);
        exact.advance_constant(&b, 1.0);
        for _ in 0..1000 {
            rk.step(0.0, 1e-3, |_, _| b);
        }
        assert!((exact.state.normal - rk.state.normal).norm() < 1e-11);
        assert!(exact.state.fingertip.angle_to(&rk.state.fingertip) < 1e-11);
        assert!(exact.state.object.angle_to(&rk.state.object) < 1e-11);
        assert!((exact.state.roll - rk.state.roll).abs() < 1e-11);
    }
}
