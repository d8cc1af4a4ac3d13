//! Placing a fingertip on the object where it is measured (SPEC §6.3).
//!
//! The model puts the object centre at the origin. A real grasp under load
//! lets the object creep a little in it (soft contacts, measured in MuJoCo:
//! up to 1.2 mm over 16 goals at 0.1 kg), so a fingertip placed on the
//! modelled surface lands short of (or into) the real one: the placing
//! finger then finds no contact until its grip has pushed it across the
//! gap, or never (fault ContactLost). A plant that measures the object
//! centre c lets the executor place relative to the object instead: finger
//! k is commanded at
//!
//! $$ p_k' = p_k + w(g_k)\, o_k, \qquad g_k = |p_k| - (R + r), \qquad
//!    w(g) = 1 - S(g/L),\; S(x) = 3x^2 - 2x^3 \text{ on } [0, 1] $$
//!
//! (p_k the plan, g_k its distance from the modelled surface, L the blend
//! distance). The offset o_k is the measured centre (at most
//! `feedback.max_place_offset` long), taken while the fingertip is farther
//! than L from the surface (w = 0) and held while it is within L: it
//! blends in over the last L of an approach, so the fingertip lands on the
//! real surface and touches at once.
//!
//! Once the finger grasps, its offset is released over `RELEASE` seconds
//! (o_k · (1 − S(t/T)), t the time it has grasped): the mount returns to
//! the model's position and the fingertip's press takes up the gap, as it
//! does for every other grasping finger. That keeps what centres the
//! object in a compliant grasp: a press extended further pushes less, so
//! the object is pushed back to where the model has it. (Held for good,
//! the offsets would hold the object wherever it crept: measured in
//! MuJoCo, the object centre then drifted 1.9 mm over 17 goals, against
//! 1.25 mm with no offset.) Lifted before the release ends, the rest blends
//! out over the first L of the lift. The offset changes only where it is
//! applied with weight 0, and w and S are C¹: the commanded fingertip never
//! jumps. The start grasp and a plant that does not measure the centre
//! (the kinematic hand) have o = 0: the plan is commanded exactly.

use nalgebra::Vector3;

use crate::hand_state::{FingerMode, HandState};
use crate::planner::Setpoint;

/// Distance from the modelled surface over which a placement offset blends
/// in or out \[m\]: a few times the offsets seen (≤ 1.2 mm), so the
/// approach speed changes by at most a few tens of percent.
pub const BLEND: f64 = 0.005;

/// How long a placed finger's offset takes to release once it grasps
/// \[s\]: long against the grip's ramp in (tens of ms), so the press has
/// the force to follow the mount back (a gap g needs F ≳ k g, 6 N for
/// 1.2 mm at the MuJoCo press's k = 5000 N/m), short against a grasp
/// (seconds).
pub const RELEASE: f64 = 1.0;

/// The smoothstep S(x) = 3x² − 2x³ on [0, 1] and its derivative.
fn smoothstep(x: f64) -> (f64, f64) {
    if x <= 0.0 {
        (0.0, 0.0)
    } else if x >= 1.0 {
        (1.0, 0.0)
    } else {
        (x * x * (3.0 - 2.0 * x), 6.0 * x * (1.0 - x))
    }
}

/// The per-finger placement offsets (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    offsets: [Vector3<f64>; 3],
    /// How long each finger has grasped since its offset was taken \[s\].
    held: [f64; 3],
    max: f64,
    contact_radius: f64,
}

impl Placement {
    /// No offsets yet; each at most `max` \[m\] (0: off); `contact_radius`
    /// is R + r.
    pub fn new(max: f64, contact_radius: f64) -> Self {
        Self {
            offsets: [Vector3::zeros(); 3],
            held: [0.0; 3],
            max,
            contact_radius,
        }
    }

    /// The offsets held now (hand frame \[m\]).
    pub fn offsets(&self) -> [Vector3<f64>; 3] {
        self.offsets
    }

    /// Forgets them (a re-based estimate: the plan starts where the
    /// fingertips were measured, offsets included).
    pub fn clear(&mut self) {
        self.offsets = [Vector3::zeros(); 3];
        self.held = [0.0; 3];
    }

    /// The blend weight w and its derivative dw/dg at plan position `p`.
    fn weight(&self, p: &Vector3<f64>) -> (f64, f64) {
        let (s, ds) = smoothstep((p.norm() - self.contact_radius) / BLEND);
        (1.0 - s, -ds / BLEND)
    }

    /// The share of finger `k`'s offset not yet released, and its rate
    /// \[1/s\] while it grasps.
    fn kept(&self, k: usize, grasping: bool) -> (f64, f64) {
        let (s, ds) = smoothstep(self.held[k] / RELEASE);
        (1.0 - s, if grasping { -ds / RELEASE } else { 0.0 })
    }

    /// One period `dt` \[s\] on: takes the measured object centre
    /// `center` (hand frame \[m\]) for every fingertip of `plan` beyond
    /// the blend distance, and releases the offsets of grasping ones.
    pub fn update(&mut self, plan: &HandState, center: Option<&Vector3<f64>>, dt: f64) {
        let o = center.map(|c| {
            let n = c.norm();
            if n > self.max && n > 0.0 {
                c * (self.max / n)
            } else {
                *c
            }
        });
        for (k, f) in plan.fingers.iter().enumerate() {
            if self.weight(&f.center).0 == 0.0 {
                if let Some(o) = o {
                    self.offsets[k] = o;
                    self.held[k] = 0.0;
                }
            } else if f.mode == FingerMode::Grasping {
                self.held[k] = (self.held[k] + dt).min(RELEASE);
            }
        }
    }

    /// `sp` with the offsets applied to its fingertip positions and
    /// velocities (exactly `sp` when every offset is zero).
    pub fn apply(&self, sp: &Setpoint) -> Setpoint {
        let mut out = *sp;
        for k in 0..3 {
            let o = self.offsets[k];
            if o == Vector3::zeros() {
                continue;
            }
            let f = &sp.state.fingers[k];
            let (w, dw) = self.weight(&f.center);
            let (a, da) = self.kept(k, f.mode == FingerMode::Grasping);
            out.state.fingers[k].center += o * (w * a);
            // d/dt (w(g) a(t) o) = (w'(g) (n̂ · ṗ) a + w ȧ) o, n̂ = p/|p|.
            let gap_rate = if dw != 0.0 {
                f.center.normalize().dot(&out.finger_velocity[k])
            } else {
                0.0
            };
            let rate = dw * gap_rate * a + w * da;
            if rate != 0.0 {
                out.finger_velocity[k] += o * rate;
            }
        }
        out
    }

    /// The offsets `state` (the plan) gets, per finger \[m\].
    pub fn shifts(&self, state: &HandState) -> [Vector3<f64>; 3] {
        std::array::from_fn(|k| {
            let f = &state.fingers[k];
            let kept = self.kept(k, f.mode == FingerMode::Grasping).0;
            self.offsets[k] * (self.weight(&f.center).0 * kept)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;
    use crate::executor::rest;

    /// The paper start, R + r and a placement of at most 2 mm.
    fn fixture() -> (HandState, f64, Placement) {
        let cfg = HandConfig::default();
        let rc = cfg.model.object_radius + cfg.model.fingertip_radius;
        (HandState::paper_start(&cfg), rc, Placement::new(0.002, rc))
    }

    #[test]
    fn an_offset_blends_in_over_the_last_blend_distance_and_never_jumps() {
        let (start, rc, mut pl) = fixture();
        // A plant that measures nothing: the plan exactly.
        pl.update(&start, None, 1e-3);
        assert_eq!(pl.apply(&rest(start)), rest(start));
        // The start grasp touches (w = 1): a measured centre is not taken.
        let c = Vector3::new(0.0003, -0.0001, -0.0012);
        pl.update(&start, Some(&c), 1e-3);
        assert_eq!(pl.apply(&rest(start)), rest(start));
        // Finger 0 lifted 3 blend distances out: it takes the centre.
        let n = start.fingers[0].center.normalize();
        let mut s = start;
        s.fingers[0].mode = FingerMode::Free;
        s.fingers[0].center = n * (rc + 3.0 * BLEND);
        pl.update(&s, Some(&c), 1e-3);
        assert_eq!(pl.offsets()[0], c);
        assert_eq!(pl.apply(&rest(s)), rest(s), "w = 0 beyond the blend");
        // Approach: the commanded tip moves continuously onto the surface
        // shifted by the held centre; a centre measured within the blend
        // distance is not taken.
        s.fingers[0].center = n * (rc + 0.999 * BLEND);
        let mut last = pl.apply(&rest(s)).state.fingers[0].center;
        let (steps, from) = (3000, 0.999 * BLEND);
        for i in 0..=steps {
            s.fingers[0].center = n * (rc + from * (1.0 - i as f64 / steps as f64));
            pl.update(&s, Some(&(c * 2.0)), 1e-3);
            let now = pl.apply(&rest(s)).state.fingers[0].center;
            let planned_step = from / steps as f64;
            assert!((now - last).norm() < 1.5 * planned_step, "a jump at {i}");
            last = now;
        }
        assert_eq!(pl.offsets()[0], c);
        assert!((last - (s.fingers[0].center + c)).norm() < 1e-15);
        // Grasping: released smoothly over RELEASE, back onto the plan.
        s.fingers[0].mode = FingerMode::Grasping;
        let dt = 1e-3;
        let ticks = (RELEASE / dt).round() as usize;
        let largest_step = c.norm() * 1.5 / RELEASE * dt;
        for i in 0..ticks + 10 {
            let sp = pl.apply(&rest(s));
            let now = sp.state.fingers[0].center;
            assert!((now - last).norm() <= largest_step, "a jump at {i}");
            pl.update(&s, Some(&c), dt);
            // The feed-forward is the offset's rate.
            let next = pl.apply(&rest(s)).state.fingers[0].center;
            assert!((sp.finger_velocity[0] * dt - (next - now)).norm() < 1e-8);
            last = now;
        }
        assert_eq!(pl.apply(&rest(s)), rest(s), "released");
        // Bounded: a centre beyond max is clamped.
        s.fingers[0].center = n * (rc + 2.0 * BLEND);
        pl.update(&s, Some(&Vector3::new(0.0, 0.0, 0.01)), 1e-3);
        assert!((pl.offsets()[0].norm() - 0.002).abs() < 1e-15);
    }

    #[test]
    fn the_velocity_feed_forward_is_the_derivative_of_the_offset() {
        let (start, rc, mut pl) = fixture();
        let n = start.fingers[1].center.normalize();
        let mut s = start;
        s.fingers[1].center = n * (rc + 2.0 * BLEND);
        pl.update(&s, Some(&Vector3::new(0.001, 0.0005, -0.001)), 1e-3);
        // Moving in at 0.1 m/s, halfway through the blend.
        let v = -n * 0.1;
        let at = |g: f64| {
            let mut st = s;
            st.fingers[1].center = n * (rc + g);
            let mut sp = rest(st);
            sp.finger_velocity[1] = v;
            pl.apply(&sp)
        };
        let (g, h) = (0.5 * BLEND, 1e-7);
        let ff = at(g).finger_velocity[1];
        let numeric = (at(g - 0.1 * h).state.fingers[1].center - at(g).state.fingers[1].center) / h;
        assert!((ff - numeric).norm() < 1e-6, "{ff} vs {numeric}");
    }
}
