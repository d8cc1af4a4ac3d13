//! Closed-form geometry the planner searches with (SPEC §1.1, §4.2).
//!
//! Everything here is about rotations of points on spheres about axes through
//! the object centre O. A point c rotated about the unit axis k by t has, with
//! a fixed unit vector d,
//!
//! d · c(t) = A + M cos(t − t0),  A = (k·c)(k·d),  c⊥ = c − (k·c)k,
//! B = d·c⊥,  C = d·(k × c⊥),  M = |(B, C)|,  t0 = atan2(C, B),
//!
//! so the angle at which a contact leaves a cone, or comes within a distance
//! of another fingertip, is a closed form.

use nalgebra::{Unit, UnitQuaternion, Vector3};

use crate::HandConfig;

/// Derived constants of the hand model used by the planner and executor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// Object radius R.
    pub object_radius: f64,
    /// Fingertip radius r.
    pub fingertip_radius: f64,
    /// Radius of fingertip centres in contact, R + r.
    pub contact_radius: f64,
    /// Radius of fingertip centres while hovering/travelling, R + r + h.
    pub transfer_radius: f64,
    /// Hover/travel height h above contact.
    pub transfer_height: f64,
    /// Finger base directions d_k.
    pub base: [Vector3<f64>; 3],
    /// Friction angle θ (μ = tan θ).
    pub friction_angle: f64,
    /// Workspace cone half angle with margin, β − margin.
    pub cone_half_angle: f64,
    /// cos(β − margin).
    pub cos_cone: f64,
    /// Roll limit with margin, γ − margin.
    pub roll_limit: f64,
    /// Smallest pair angle that is force-closure with margin: π − 2θ + margin
    /// (Fact 3, SPEC §3.1).
    pub fc_min_angle: f64,
    /// cos of `fc_min_angle`.
    pub cos_fc: f64,
    /// cos of the least angle of the pairs the planner makes:
    /// `fc_min_angle` + `planner.pair_margin_deg` (a wider pair needs far
    /// less grip force to hold the load).
    pub cos_fc_plan: f64,
    /// Minimum distance between fingertip centres, 2r + clearance.
    pub min_center_distance: f64,
    /// cos of the smallest angle between two contacts (both at R + r) that
    /// keeps their fingertips apart.
    pub cos_sep_contact: f64,
    /// cos of the smallest angle between a hovering fingertip (R + r + h) and
    /// a contact (R + r).
    pub cos_sep_hover: f64,
}

/// Tiny angle by which the planner stays inside every boundary it computes,
/// so floating-point rounding never puts a planned state on the wrong side.
pub const BOUNDARY_EPS: f64 = 1e-9;

impl Geometry {
    /// Derives the constants from a (validated) configuration.
    pub fn new(config: &HandConfig) -> Self {
        let m = &config.model;
        let r_obj = m.object_radius;
        let r_tip = m.fingertip_radius;
        let rho_c = r_obj + r_tip;
        let h = config.planner.transfer_height;
        let rho_t = rho_c + h;
        let dmin = 2.0 * r_tip + m.fingertip_clearance;
        let cone = (m.workspace_half_angle_deg - m.workspace_margin_deg).to_radians();
        let fc_min = std::f64::consts::PI - 2.0 * m.friction_angle_deg.to_radians()
            + m.fc_margin_deg.to_radians();
        // Law of cosines: |p_i − p_j|² = ρ_i² + ρ_j² − 2 ρ_i ρ_j cos α ≥ dmin².
        let cos_sep = |rho_a: f64, rho_b: f64| {
            ((rho_a * rho_a + rho_b * rho_b - dmin * dmin) / (2.0 * rho_a * rho_b)).min(1.0)
        };
        Self {
            object_radius: r_obj,
            fingertip_radius: r_tip,
            contact_radius: rho_c,
            transfer_radius: rho_t,
            transfer_height: h,
            base: m.finger_azimuth_deg.map(|a| {
                let a = a.to_radians();
                Vector3::new(a.cos(), a.sin(), 0.0)
            }),
            friction_angle: m.friction_angle_deg.to_radians(),
            cone_half_angle: cone,
            cos_cone: cone.cos(),
            roll_limit: (m.roll_limit_deg - m.roll_margin_deg).to_radians(),
            fc_min_angle: fc_min,
            cos_fc: fc_min.cos(),
            cos_fc_plan: (fc_min + config.planner.pair_margin_deg.to_radians())
                .min(std::f64::consts::PI)
                .cos(),
            min_center_distance: dmin,
            cos_sep_contact: cos_sep(rho_c, rho_c),
            cos_sep_hover: cos_sep(rho_c, rho_t),
        }
    }

    /// Whether two contact normals form a force-closure pair with margin
    /// (Fact 3: angle ≥ π − 2θ + margin).
    pub fn is_fc_pair(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
        a.dot(b) <= self.cos_fc - BOUNDARY_EPS
    }

    /// Whether two contact normals are a pair the planner may make: Fact 3
    /// with the force-closure margin plus the planner's pair margin.
    pub fn is_good_pair(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
        a.dot(b) <= self.cos_fc_plan - BOUNDARY_EPS
    }

    /// Whether a contact normal lies in finger `k`'s workspace cone (with margin).
    pub fn in_cone(&self, k: usize, c: &Vector3<f64>) -> bool {
        self.base[k].dot(c) >= self.cos_cone - BOUNDARY_EPS
    }
}

/// The sinusoid d·c(t) = A + M cos(t − t0) = A + B cos t + C sin t for c
/// rotated about `k`. Kept as (A, B, C): the phase t0 = atan2(C, B) costs
/// an `atan2` and is only needed when a crossing has to be located, which
/// the planner's range queries mostly decide without it.
#[derive(Debug, Clone, Copy)]
pub struct Sinusoid {
    /// Offset A.
    pub a: f64,
    /// Cosine coefficient B = M cos t0.
    pub b: f64,
    /// Sine coefficient C = M sin t0.
    pub c: f64,
}

impl Sinusoid {
    /// d·(Rot(k, t) c) as a sinusoid in t.
    pub fn new(k: &Vector3<f64>, c: &Vector3<f64>, d: &Vector3<f64>) -> Self {
        let kc = k.dot(c);
        let c_perp = c - k * kc;
        Self {
            a: kc * k.dot(d),
            b: d.dot(&c_perp),
            c: d.dot(&k.cross(&c_perp)),
        }
    }

    /// Amplitude M ≥ 0.
    pub fn m(&self) -> f64 {
        (self.b * self.b + self.c * self.c).sqrt()
    }

    /// Phase t0 (the first peak).
    pub fn t0(&self) -> f64 {
        self.c.atan2(self.b)
    }

    /// Value at t.
    pub fn at(&self, t: f64) -> f64 {
        let (sin, cos) = t.sin_cos();
        self.a + self.b * cos + self.c * sin
    }

    /// First t ≥ 0 at which the value falls below `level`, given it is
    /// ≥ `level` at t = 0; `f64::INFINITY` if it never does. Returns 0 if
    /// it is already below.
    pub fn first_below(&self, level: f64) -> f64 {
        let m = self.m();
        if self.a - m >= level {
            return f64::INFINITY;
        }
        // Value at t = 0 is A + B.
        if self.a + self.b < level {
            return 0.0;
        }
        // m > 0 here. cos(u) ≥ ρ on u ∈ [−acos ρ, acos ρ], u = t − t0.
        let rho = ((level - self.a) / m).clamp(-1.0, 1.0);
        let half = rho.acos();
        let u0 = wrap_pi(-self.t0());
        (half - u0).max(0.0)
    }

    /// First t ≥ 0 at which the value rises above `level`, given it is
    /// ≤ `level` at t = 0; `f64::INFINITY` if it never does.
    pub fn first_above(&self, level: f64) -> f64 {
        Sinusoid {
            a: -self.a,
            b: -self.b,
            c: -self.c,
        }
        .first_below(-level)
    }

    /// Maximum over t ∈ [0, t_end].
    pub fn max_on(&self, t_end: f64) -> f64 {
        let mut best = (self.a + self.b).max(self.at(t_end));
        // Peaks at t = t0 + 2πn.
        let tau = std::f64::consts::TAU;
        let t0 = self.t0();
        let n = ((0.0 - t0) / tau).ceil();
        let peak = t0 + n * tau;
        if peak <= t_end {
            best = best.max(self.a + self.m());
        }
        best
    }
}

/// Wraps an angle into (−π, π].
pub fn wrap_pi(x: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let mut y = x.rem_euclid(tau);
    if y > std::f64::consts::PI {
        y -= tau;
    }
    y
}

/// Angle between two unit vectors, robust near 0 and π.
pub fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// How far (rad) the contact `c` of finger `k` can rotate about `axis`
/// before leaving its cone.
pub fn cone_exit(g: &Geometry, k: usize, axis: &Vector3<f64>, c: &Vector3<f64>) -> f64 {
    Sinusoid::new(axis, c, &g.base[k]).first_below(g.cos_cone)
}

/// How far (rad) a fingertip with pole axis `pole` and roll `tau` can rotate
/// rigidly about `axis` before its roll τ (τ̇ = ω·a, SPEC §1.1) reaches ±γ
/// (with margin). The pole axis turns with the rotation, so k·a is constant.
pub fn roll_exit(g: &Geometry, axis: &Vector3<f64>, pole: &Vector3<f64>, tau: f64) -> f64 {
    let rate = axis.dot(pole);
    if rate > 1e-12 {
        ((g.roll_limit - tau) / rate).max(0.0)
    } else if rate < -1e-12 {
        ((-g.roll_limit - tau) / rate).max(0.0)
    } else {
        f64::INFINITY
    }
}

/// Roll preset and rotation range of a fresh contact at `c` touched with the
/// fingertip pole (pole axis −c), rotating about `axis`: the preset puts τ at
/// the limit against the motion, so the whole 2γ is usable.
pub fn fresh_range(g: &Geometry, k: usize, axis: &Vector3<f64>, c: &Vector3<f64>) -> (f64, f64) {
    let rate = -axis.dot(c);
    let (tau, roll) = if rate > 1e-12 {
        (-g.roll_limit, 2.0 * g.roll_limit / rate)
    } else if rate < -1e-12 {
        (g.roll_limit, -2.0 * g.roll_limit / rate)
    } else {
        (0.0, f64::INFINITY)
    };
    (tau, roll.min(cone_exit(g, k, axis, c)))
}

/// First rotation angle about `axis` at which a contact `c` (at R + r) comes
/// too close to a fixed hovering fingertip in direction `u` (at R + r + h).
pub fn hover_collision(
    g: &Geometry,
    axis: &Vector3<f64>,
    c: &Vector3<f64>,
    u: &Vector3<f64>,
) -> f64 {
    Sinusoid::new(axis, c, u).first_above(g.cos_sep_hover)
}

/// Rotation about a unit axis by an angle.
pub fn rotation(axis: &Vector3<f64>, angle: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Unit::new_unchecked(*axis), angle)
}

/// A unit vector perpendicular to `v` (deterministic).
pub fn any_perpendicular(v: &Vector3<f64>) -> Vector3<f64> {
    let helper = if v.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    v.cross(&helper).normalize()
}

/// Minimal rotation taking unit vector `from` to unit vector `to` (the
/// "swing": its axis is perpendicular to both, so it leaves a fingertip's
/// roll τ unchanged, SPEC §1.1).
pub fn swing(from: &Vector3<f64>, to: &Vector3<f64>) -> UnitQuaternion<f64> {
    let axis = from.cross(to);
    let s = axis.norm();
    let c = from.dot(to);
    if s < 1e-12 {
        if c > 0.0 {
            return UnitQuaternion::identity();
        }
        return rotation(&any_perpendicular(from), std::f64::consts::PI);
    }
    rotation(&(axis / s), s.atan2(c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use test_support::random::unit;

    #[test]
    fn sinusoid_matches_rotation() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..1000 {
            let (k, c, d) = (unit(&mut rng), unit(&mut rng), unit(&mut rng));
            let s = Sinusoid::new(&k, &c, &d);
            let t: f64 = rng.random_range(-7.0..7.0);
            let direct = d.dot(&(rotation(&k, t) * c));
            assert!((s.at(t) - direct).abs() < 1e-12);
        }
    }

    #[test]
    fn first_below_is_the_first_crossing() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for _ in 0..2000 {
            let (k, c, d) = (unit(&mut rng), unit(&mut rng), unit(&mut rng));
            let s = Sinusoid::new(&k, &c, &d);
            let level = s.at(0.0) - rng.random_range(0.0..0.5);
            let t = s.first_below(level);
            if t.is_infinite() {
                for i in 0..=720 {
                    assert!(s.at(i as f64 * 0.00873) >= level - 1e-12);
                }
                continue;
            }
            assert!((s.at(t) - level).abs() < 1e-9, "crossing value");
            for i in 0..200 {
                let ti = t * i as f64 / 200.0;
                assert!(s.at(ti) >= level - 1e-9, "no earlier crossing");
            }
        }
    }

    #[test]
    fn max_on_interval() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..1000 {
            let (k, c, d) = (unit(&mut rng), unit(&mut rng), unit(&mut rng));
            let s = Sinusoid::new(&k, &c, &d);
            let end: f64 = rng.random_range(0.0..7.0);
            let sampled = (0..=2000)
                .map(|i| s.at(end * i as f64 / 2000.0))
                .fold(f64::MIN, f64::max);
            let m = s.max_on(end);
            assert!(m >= sampled - 1e-12 && m <= sampled + 1e-5);
        }
    }

    #[test]
    fn swing_keeps_roll() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..100 {
            let (a, b) = (unit(&mut rng), unit(&mut rng));
            let q = swing(&a, &b);
            assert!((q * a - b).norm() < 1e-12);
            // Its axis is perpendicular to a: τ̇ = ω·a = 0 along the swing.
            if let Some(axis) = q.axis() {
                assert!(axis.dot(&a).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn contact_separation_is_19_67_degrees() {
        let g = Geometry::new(&HandConfig::default());
        // At the default radii two contacts need ≥ 19.67° of separation.
        let sep = g.cos_sep_contact.acos().to_degrees();
        assert!((sep - 19.67).abs() < 0.01, "{sep}");
        assert!((g.fc_min_angle.to_degrees() - 142.0).abs() < 1e-9);
    }
}
