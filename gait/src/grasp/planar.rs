//! A fast exact-in-practice force-closure certificate for three hard
//! contacts on a sphere (used by the invariant check before the conic test).
//!
//! # Why it works
//! Three point contacts p_1, p_2, p_3 (unit sphere, pairwise distinct) give
//! a grasp map of rank 6, so (SPEC §3.2) they are force-closure iff some
//! internal force system has every force strictly inside its friction cone.
//! Any internal system of three forces lies in the plane P of the contacts
//! (the moment about the line p_j p_k involves f_i only, so f_i meets that
//! line) and its three lines of action meet in one point c ∈ P (or are
//! parallel, the limit c → ∞). Given c the forces are, up to one common
//! scale λ, f_i = λ O_i(c) (c − p_i) with O_i(c) = det(p_j − c, p_k − c)
//! ((i, j, k) cyclic), from the identity
//! Σ det(v_j, v_k) v_i = 0 for plane vectors v_i = c − p_i.
//!
//! In P, the friction cone at p_i (axis −p_i, half angle θ) leaves the
//! wedge of directions within φ of the in-plane inward radial direction,
//! cos φ = cos θ / ρ, with ρ = √(1 − h²) the radius of the circle P ∩
//! sphere and h the distance from O to P (no wedge if h ≥ sin θ — so Fact
//! 4's plane condition is necessary). Writing σ_i = ±1 for "f_i points
//! towards / away from c" and ε = sign λ, force closure is the existence of
//! (σ, ε) and c with c ∈ p_i + σ_i W_i and ε σ_i O_i(c) > 0 for all i: nine
//! open half-planes. The 16 patterns are checked by clipping a large box
//! (half width [`BOX`]) with the half-planes; the centroid of a non-empty
//! clip gives an explicit internal force system, whose angular margin
//! θ − max_i angle(f_i, −p_i) is returned as the certificate.
//!
//! A returned margin is therefore never a false positive (the forces are
//! verified directly). `None` means no system was found: the grasp is not
//! force-closure, or it is only within a sliver (FC margin at the level of
//! rounding) or only through nearly parallel forces meeting beyond the box
//! — cases with a vanishing margin. The tests compare it with the conic
//! test on random triples.

use nalgebra::{Vector2, Vector3};

use super::facts::angle_between;

/// Half width of the clipping box in the contact plane (unit sphere).
pub const BOX: f64 = 1e4;

const MAX_VERTICES: usize = 16;

#[derive(Clone, Copy)]
struct Polygon {
    v: [Vector2<f64>; MAX_VERTICES],
    len: usize,
}

impl Polygon {
    fn square(half: f64) -> Self {
        let mut v = [Vector2::zeros(); MAX_VERTICES];
        v[0] = Vector2::new(-half, -half);
        v[1] = Vector2::new(half, -half);
        v[2] = Vector2::new(half, half);
        v[3] = Vector2::new(-half, half);
        Self { v, len: 4 }
    }

    /// Keeps the part where g·c + k ≥ 0 (Sutherland–Hodgman, one edge).
    fn clip(&mut self, g: Vector2<f64>, k: f64) {
        let mut out = [Vector2::zeros(); MAX_VERTICES];
        let mut n = 0;
        for i in 0..self.len {
            let a = self.v[i];
            let b = self.v[(i + 1) % self.len];
            let (da, db) = (g.dot(&a) + k, g.dot(&b) + k);
            if da >= 0.0 && n < MAX_VERTICES {
                out[n] = a;
                n += 1;
            }
            if (da >= 0.0) != (db >= 0.0) && n < MAX_VERTICES {
                out[n] = a + (b - a) * (da / (da - db));
                n += 1;
            }
        }
        self.v = out;
        self.len = n;
    }

    fn centroid(&self) -> Option<Vector2<f64>> {
        if self.len < 3 {
            return None;
        }
        let (mut area, mut c) = (0.0, Vector2::zeros());
        for i in 0..self.len {
            let (a, b) = (self.v[i], self.v[(i + 1) % self.len]);
            let cr = a.perp(&b);
            area += cr;
            c += (a + b) * cr;
        }
        (area.abs() > 1e-300).then(|| c / (3.0 * area))
    }
}

/// A half-plane g·c + k > 0 in plane coordinates.
#[derive(Clone, Copy)]
struct Half {
    g: Vector2<f64>,
    k: f64,
}

/// cross(a, c − q) > 0 as a half-plane in c.
fn left_of(a: Vector2<f64>, q: Vector2<f64>) -> Half {
    Half {
        g: Vector2::new(-a.y, a.x),
        k: a.y * q.x - a.x * q.y,
    }
}

fn scaled(h: Half, s: f64) -> Half {
    Half {
        g: h.g * s,
        k: h.k * s,
    }
}

fn rotate(v: Vector2<f64>, cos: f64, sin: f64) -> Vector2<f64> {
    Vector2::new(cos * v.x - sin * v.y, sin * v.x + cos * v.y)
}

/// The certificate (see the module docs): `Some(margin)` with margin > 0
/// \[rad\] when an internal force system strictly inside all three friction
/// cones (friction angle `theta`) was found, `None` otherwise. Inputs are
/// contact normals (any non-zero length).
pub fn three_hard_certificate(p: &[Vector3<f64>; 3], theta: f64) -> Option<f64> {
    let p = p.map(|v| v.normalize());
    let normal = (p[1] - p[0]).cross(&(p[2] - p[0]));
    let area2 = normal.norm();
    if area2.partial_cmp(&1e-12) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let mut m = normal / area2;
    let mut h = m.dot(&p[0]);
    if h < 0.0 {
        m = -m;
        h = -h;
    }
    if h >= theta.sin() {
        return None;
    }
    let rho = (1.0 - h * h).sqrt();
    let e1 = (p[0] - m * h) / rho;
    let e2 = m.cross(&e1);
    let q = p.map(|v| Vector2::new(v.dot(&e1), v.dot(&e2)));
    let cos_phi = (theta.cos() / rho).min(1.0);
    let sin_phi = (1.0 - cos_phi * cos_phi).sqrt();
    // Wedge boundary half-planes at each contact, for σ = +1.
    let wedge: [[Half; 2]; 3] = core::array::from_fn(|i| {
        let inward = -q[i] / rho;
        let lo = rotate(inward, cos_phi, -sin_phi);
        let hi = rotate(inward, cos_phi, sin_phi);
        [left_of(lo, q[i]), scaled(left_of(hi, q[i]), -1.0)]
    });
    // O_i(c) = det(q_j, q_k) + det(q_k − q_j, c) as a half-plane.
    let orient: [Half; 3] = core::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let a = q[k] - q[j];
        Half {
            g: Vector2::new(-a.y, a.x),
            k: q[j].perp(&q[k]),
        }
    });
    let lift = |v: Vector2<f64>| e1 * v.x + e2 * v.y;
    let mut best: Option<f64> = None;
    for pattern in 0..16u8 {
        let sigma = [0, 1, 2].map(|i| if pattern & (1 << i) == 0 { 1.0 } else { -1.0 });
        let eps = if pattern & 8 == 0 { 1.0 } else { -1.0 };
        let mut poly = Polygon::square(BOX);
        for i in 0..3 {
            for w in wedge[i] {
                let hp = scaled(w, sigma[i]);
                poly.clip(hp.g, hp.k);
            }
            let hp = scaled(orient[i], eps * sigma[i]);
            poly.clip(hp.g, hp.k);
            if poly.len < 3 {
                break;
            }
        }
        let Some(c) = poly.centroid() else {
            continue;
        };
        // Verify the system at c directly: signs and cone angles.
        let mut worst = f64::NEG_INFINITY;
        let mut consistent = true;
        for i in 0..3 {
            let o = orient[i].g.dot(&c) + orient[i].k;
            let d = (c - q[i]) * sigma[i];
            consistent &= eps * sigma[i] * o > 0.0 && d.norm() > 0.0;
            worst = worst.max(angle_between(&lift(d), &(-p[i])));
        }
        let margin = theta - worst;
        if consistent && margin > 0.0 && best.is_none_or(|b| margin > b) {
            best = Some(margin);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eq(deg: f64) -> Vector3<f64> {
        let a = deg.to_radians();
        Vector3::new(a.cos(), a.sin(), 0.0)
    }

    #[test]
    fn certifies_the_paper_start_and_rejects_a_cap() {
        let th = 20f64.to_radians();
        let m = three_hard_certificate(&[eq(0.0), eq(120.0), eq(240.0)], th).unwrap();
        assert!(m > 0.0 && m <= th + 1e-12);
        // Three contacts in a small cap around +z: plane far from O.
        let cap = [0.0, 120.0, 240.0].map(|d: f64| {
            let a = d.to_radians();
            Vector3::new(0.2 * a.cos(), 0.2 * a.sin(), 1.0)
        });
        assert!(three_hard_certificate(&cap, th).is_none());
    }

    #[test]
    fn certifies_an_obtuse_pinch() {
        // Fact 4 fails (the angle at 150° is 95°), yet the grasp is
        // force-closure (t* ≈ 0.057 by the conic test).
        let th = 20f64.to_radians();
        let p = [eq(0.0), eq(170.0), eq(150.0)];
        assert!(super::super::facts::fact4_slack(&p[0], &p[1], &p[2], th) < 0.0);
        assert!(three_hard_certificate(&p, th).is_some());
    }
}
