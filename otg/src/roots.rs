//! Real roots of low-order polynomials, allocation-free.
//!
//! The time-optimal profile conditions (SPEC.md §5) reduce to polynomials of
//! degree ≤ 6 in one phase duration. Cubics and quartics are solved in closed
//! form (Cardano; Ferrari through the resolvent cubic), higher orders by a
//! safeguarded Newton iteration between bracketing points. Only non-negative
//! roots are ever of interest (they are durations), so the sets keep those.

use core::f64::consts::PI;

/// `f64::EPSILON`, the threshold Ruckig uses for "numerically zero".
pub(crate) const EPS: f64 = f64::EPSILON;

/// Tolerance of the safeguarded Newton iteration.
pub(crate) const NEWTON_TOL: f64 = 1e-14;

/// Cube root: bit-level estimate (3 % error) refined by three Halley steps
/// (cubic convergence), accurate to an ulp or two. Replaces `f64::cbrt`,
/// whose software implementation dominated the quartic solver's cost.
#[inline]
pub(crate) fn cbrt(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let a = x.abs();
    // Subnormals lose the estimate's accuracy: scale them up first.
    let (a, scale) = if a < f64::MIN_POSITIVE {
        (a * 2f64.powi(54), 2f64.powi(-18))
    } else {
        (a, 1.0)
    };
    let mut y = f64::from_bits(a.to_bits() / 3 + 0x2a9f_7893_782d_a1ce);
    for _ in 0..3 {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * a) / (2.0 * y3 + a);
    }
    (y * scale).copysign(x)
}

const COS_120: f64 = -0.5;
const SIN_120: f64 = 0.866_025_403_784_438_6;

/// A small stack set of non-negative roots, handed out in ascending order.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Roots<const M: usize> {
    data: [f64; M],
    len: usize,
}

impl<const M: usize> Roots<M> {
    fn new() -> Self {
        Self {
            data: [0.0; M],
            len: 0,
        }
    }

    /// Keeps `x` if it is a non-negative number (NaN is dropped).
    fn push(&mut self, x: f64) {
        if x >= 0.0 && self.len < M {
            self.data[self.len] = x;
            self.len += 1;
        }
    }

    /// The roots in ascending order.
    pub(crate) fn sorted(mut self) -> ([f64; M], usize) {
        let s = &mut self.data[..self.len];
        // Insertion sort: at most four elements.
        for i in 1..s.len() {
            let mut k = i;
            while k > 0 && s[k - 1] > s[k] {
                s.swap(k - 1, k);
                k -= 1;
            }
        }
        (self.data, self.len)
    }
}

/// Iterates the sorted non-negative roots of a set.
macro_rules! for_roots {
    ($set:expr, |$t:ident| $body:block) => {{
        let (vals, n) = $set.sorted();
        for &root in &vals[..n] {
            #[allow(unused_mut)]
            let mut $t = root;
            $body
        }
    }};
}
pub(crate) use for_roots;

/// Non-negative real roots of `a x³ + b x² + c x + d = 0` (Cardano, with the
/// trigonometric form for three real roots).
pub(crate) fn cubic(mut a: f64, mut b: f64, mut c: f64, mut d: f64) -> Roots<3> {
    let mut roots = Roots::new();
    if d.abs() < EPS {
        // x = 0 is a root; deflate to a quadratic.
        roots.push(0.0);
        d = c;
        c = b;
        b = a;
        a = 0.0;
    }
    if a.abs() < EPS {
        if b.abs() < EPS {
            if c.abs() > EPS {
                roots.push(-d / c);
            }
        } else {
            let disc = c * c - 4.0 * b * d;
            if disc >= 0.0 {
                let inv2b = 1.0 / (2.0 * b);
                let y = disc.sqrt();
                roots.push((-c + y) * inv2b);
                roots.push((-c - y) * inv2b);
            }
        }
        return roots;
    }

    let inva = 1.0 / a;
    let invaa = inva * inva;
    let bb = b * b;
    let shift = b * inva / 3.0;
    let p = (a * c - bb / 3.0) * invaa;
    let half_q = (2.0 * bb * b - 9.0 * a * b * c + 27.0 * a * a * d) / 54.0 * invaa * inva;
    let disc = p * p * p / 27.0 + half_q * half_q;

    if disc > EPS {
        // One real root.
        let y = disc.sqrt();
        let u = -half_q + y;
        let v = -half_q - y;
        let w = cbrt(if u.abs() > v.abs() { u } else { v });
        roots.push(w - p / (3.0 * w) - shift);
    } else if disc < -EPS {
        // Three real roots: cube root of a complex number in polar form.
        let x = -half_q;
        let y = (-disc).sqrt();
        let (theta, r) = if x.abs() > EPS {
            let th = if x > 0.0 {
                (y / x).atan()
            } else {
                (y / x).atan() + PI
            };
            (th, (x * x - disc).sqrt())
        } else {
            (PI / 2.0, y)
        };
        let theta = theta / 3.0;
        let r = 2.0 * cbrt(r);
        let ux = theta.cos() * r;
        let uyi = theta.sin() * r;
        roots.push(ux - shift);
        roots.push(ux * COS_120 - uyi * SIN_120 - shift);
        roots.push(ux * COS_120 + uyi * SIN_120 - shift);
    } else {
        // Double root.
        let w = 2.0 * cbrt(-half_q);
        roots.push(w - shift);
        roots.push(w * COS_120 - shift);
    }
    roots
}

/// Real roots of the resolvent cubic `x³ + a x² + b x + c`; returns how many
/// of `x` are meaningful (3, 2 or 1).
fn resolvent(x: &mut [f64; 3], a: f64, b: f64, c: f64) -> usize {
    let a = a / 3.0;
    let a2 = a * a;
    let mut q = a2 - b / 3.0;
    let r = (a * (2.0 * a2 - b) + c) / 2.0;
    let r2 = r * r;
    let q3 = q * q * q;

    if r2 < q3 {
        let qs = q.sqrt();
        let t = (r / (q * qs)).clamp(-1.0, 1.0);
        q = -2.0 * qs;
        let theta = t.acos() / 3.0;
        let ux = theta.cos() * q;
        let uyi = theta.sin() * q;
        x[0] = ux - a;
        x[1] = ux * COS_120 - uyi * SIN_120 - a;
        x[2] = ux * COS_120 + uyi * SIN_120 - a;
        3
    } else {
        let mut big_a = -cbrt(r.abs() + (r2 - q3).sqrt());
        if r < 0.0 {
            big_a = -big_a;
        }
        let big_b = if big_a == 0.0 { 0.0 } else { q / big_a };
        x[0] = (big_a + big_b) - a;
        x[1] = -(big_a + big_b) / 2.0 - a;
        x[2] = 3.0_f64.sqrt() * (big_a - big_b) / 2.0;
        if x[2].abs() < EPS {
            x[2] = x[1];
            2
        } else {
            1
        }
    }
}

/// Non-negative real roots of the monic quartic `x⁴ + a x³ + b x² + c x + d`
/// (Ferrari: factor into two quadratics through the resolvent cubic).
pub(crate) fn quartic_monic(a: f64, b: f64, c: f64, d: f64) -> Roots<4> {
    let mut roots = Roots::new();
    if d.abs() < EPS {
        if c.abs() < EPS {
            roots.push(0.0);
            let disc = a * a - 4.0 * b;
            if disc.abs() < EPS {
                roots.push(-a / 2.0);
            } else if disc > 0.0 {
                let s = disc.sqrt();
                roots.push((-a - s) / 2.0);
                roots.push((-a + s) / 2.0);
            }
            return roots;
        }
        if a.abs() < EPS && b.abs() < EPS {
            roots.push(0.0);
            roots.push(-cbrt(c));
            return roots;
        }
    }

    let mut x3 = [0.0; 3];
    let n = resolvent(
        &mut x3,
        -b,
        a * c - 4.0 * d,
        -a * a * d - c * c + 4.0 * b * d,
    );
    let mut y = x3[0];
    if n != 1 {
        // The resolvent root of largest magnitude is the best conditioned.
        if x3[1].abs() > y.abs() {
            y = x3[1];
        }
        if x3[2].abs() > y.abs() {
            y = x3[2];
        }
    }

    let (q1, q2, p1, p2);
    let disc = y * y - 4.0 * d;
    if disc.abs() < EPS {
        q1 = y / 2.0;
        q2 = q1;
        let disc2 = a * a - 4.0 * (b - y);
        if disc2.abs() < EPS {
            p1 = a / 2.0;
            p2 = p1;
        } else {
            let s = disc2.sqrt();
            p1 = (a + s) / 2.0;
            p2 = (a - s) / 2.0;
        }
    } else {
        let s = disc.sqrt();
        q1 = (y + s) / 2.0;
        q2 = (y - s) / 2.0;
        p1 = (a * q1 - c) / (q1 - q2);
        p2 = (c - a * q2) / (q1 - q2);
    }

    const EPS_Q: f64 = 16.0 * EPS;
    for (p, q) in [(p1, q1), (p2, q2)] {
        let disc = p * p - 4.0 * q;
        if disc.abs() < EPS_Q {
            roots.push(-p / 2.0);
        } else if disc > 0.0 {
            let s = disc.sqrt();
            roots.push((-p - s) / 2.0);
            roots.push((-p + s) / 2.0);
        }
    }
    roots
}

/// Quartic from `[a, b, c, d]` as in [`quartic_monic`].
#[inline]
pub(crate) fn quartic(c: &[f64; 4]) -> Roots<4> {
    quartic_monic(c[0], c[1], c[2], c[3])
}

/// [`quartic`] solved in units of its root scale: [`quartic_monic`]'s
/// "numerically zero" tests are absolute (as Ruckig's), so a quartic whose
/// roots are all tiny (a move of 1e-8 has phases of 1e-4 s and a constant
/// term of 1e-22) can lose its roots to them. With `x = s·u` for the power
/// of two `s` bounding the roots the coefficients are O(1); the scaling
/// itself is exact.
#[inline]
pub(crate) fn quartic_scaled(c: &[f64; 4]) -> Roots<4> {
    let s = root_pow(c[0], 1)
        .max(root_pow(c[1], 2))
        .max(root_pow(c[2], 3))
        .max(root_pow(c[3], 4));
    if !(1e-60..=1.0).contains(&s) {
        return quartic(c);
    }
    let is = 1.0 / s;
    let (is2, is3) = (is * is, is * is * is);
    let mut r = quartic_monic(c[0] * is, c[1] * is2, c[2] * is3, c[3] * is2 * is2);
    for x in &mut r.data[..r.len] {
        *x *= s;
    }
    r
}

/// [`quartic_in`] with [`quartic_scaled`].
#[inline]
pub(crate) fn quartic_in_scaled(c: &[f64; 4], lo: f64, hi: f64) -> Roots<4> {
    if lo > hi || !may_have_root_in(c, lo, hi) {
        return Roots::new();
    }
    quartic_scaled(c)
}

/// [`quartic`], skipped (no roots) when a Taylor bound around the middle
/// of `[lo, hi]` proves that the quartic has no root there: callers keep
/// only roots in that range, and most Step 1 shapes have none (the
/// closed-form solution costs several times the test). The range is
/// widened generously (far beyond the solver's own error), so no root the
/// solver would place inside is ever dropped.
#[inline]
pub(crate) fn quartic_in(c: &[f64; 4], lo: f64, hi: f64) -> Roots<4> {
    // A NaN bound filters nothing (comparisons with it are false).
    if lo > hi || !may_have_root_in(c, lo, hi) {
        return Roots::new();
    }
    quartic(c)
}

/// `false` only if the monic quartic `c` provably has no root in
/// `[lo, hi]` (widened): `|p(m)| > Σ |p⁽ᵏ⁾(m)/k!|·rᵏ` around the middle `m`
/// with half-width `r`. NaN gives `true`.
#[inline]
fn may_have_root_in(c: &[f64; 4], lo: f64, hi: f64) -> bool {
    let [a, b, cc, d] = *c;
    let m = 0.5 * (lo + hi);
    // Widened relative to the range and to the scale of all roots (the
    // Fujiwara bound max |cₖ|^(1/k), within a factor of 4): a root computed
    // inside but off by rounding is never excluded.
    let scale = root_pow(a, 1)
        .max(root_pow(b, 2))
        .max(root_pow(cc, 3))
        .max(root_pow(d, 4));
    let r = 0.5 * (hi - lo) * (1.0 + 1e-6) + 1e-6 * lo.abs().max(hi.abs()) + 1e-9 * scale;
    let b3 = 4.0 * m + a;
    let b2 = (6.0 * m + 3.0 * a) * m + b;
    let b1 = ((4.0 * m + 3.0 * a) * m + 2.0 * b) * m + cc;
    let b0 = (((m + a) * m + b) * m + cc) * m + d;
    let bound = (((r + b3.abs()) * r + b2.abs()) * r + b1.abs()) * r;
    // Rounding (and the solver's backward error): relative to the size of
    // the terms over the range.
    let am = m.abs() + r;
    let size = (((am + a.abs()) * am + b.abs()) * am + cc.abs()) * am + d.abs();
    let clear = bound * (1.0 + 1e-6) + 1e-12 * size;
    b0.abs() <= clear || b0.is_nan() || clear.is_nan()
}

/// An upper bound of `|x|^(1/k)` (at most 4 times too large) from the
/// binary exponent alone: no roots needed. `|x| < 2^(e+1)`, so
/// `|x|^(1/k) < 2^⌈(e+1)/k⌉`; NaN and infinity give infinity.
#[inline]
fn root_pow(x: f64, k: i64) -> f64 {
    let biased = ((x.to_bits() >> 52) & 0x7ff) as i64;
    if biased == 0x7ff {
        return f64::INFINITY;
    }
    // Zero and subnormals: below 2^-1022.
    let e = biased.max(1) - 1023 + 1;
    let q = e.div_euclid(k) + 1;
    if q > 1023 {
        return f64::INFINITY;
    }
    f64::from_bits(((q + 1023) as u64) << 52)
}

/// Horner evaluation of `p[0] x^(M-1) + … + p[M-1]`.
#[inline]
pub(crate) fn eval<const M: usize>(p: &[f64; M], x: f64) -> f64 {
    if x.abs() < EPS {
        return p[M - 1];
    }
    if x == 1.0 {
        return p.iter().rev().sum();
    }
    // Summed from the constant term, as Ruckig does, for identical rounding.
    let mut acc = 0.0;
    let mut xn = 1.0;
    for &c in p.iter().rev() {
        acc += c * xn;
        xn *= x;
    }
    acc
}

/// Derivative coefficients of a polynomial of `M` coefficients (`D = M - 1`).
#[inline]
pub(crate) fn derivative<const M: usize, const D: usize>(p: &[f64; M]) -> [f64; D] {
    let mut d = [0.0; D];
    for (i, di) in d.iter_mut().enumerate() {
        *di = (D - i) as f64 * p[i];
    }
    d
}

/// Derivative of a monic polynomial, scaled to be monic again.
#[inline]
pub(crate) fn monic_derivative<const M: usize, const D: usize>(p: &[f64; M]) -> [f64; D] {
    let mut d = [0.0; D];
    d[0] = 1.0;
    for i in 1..D {
        d[i] = (D - i) as f64 * p[i] / D as f64;
    }
    d
}

/// One root of `p` inside `[lo, hi]` where `p(lo)·p(hi) < 0`: Newton steps
/// guarded by bisection (never leaves the bracket).
pub(crate) fn shrink_interval<const M: usize, const D: usize>(
    p: &[f64; M],
    mut lo: f64,
    mut hi: f64,
) -> f64 {
    let f_lo = eval(p, lo);
    let f_hi = eval(p, hi);
    if f_lo == 0.0 {
        return lo;
    }
    if f_hi == 0.0 {
        return hi;
    }
    if f_lo > 0.0 {
        core::mem::swap(&mut lo, &mut hi);
    }
    let dp: [f64; D] = derivative(p);
    let mut x = (lo + hi) / 2.0;
    let mut dx_old = (hi - lo).abs();
    let mut dx = dx_old;
    let mut f = eval(p, x);
    let mut df = eval(&dp, x);
    for _ in 0..128 {
        let newton_leaves = ((x - hi) * df - f) * ((x - lo) * df - f) > 0.0;
        if newton_leaves || (2.0 * f).abs() > (dx_old * df).abs() {
            dx_old = dx;
            dx = (hi - lo) / 2.0;
            x = lo + dx;
            if lo == x {
                break;
            }
        } else {
            dx_old = dx;
            dx = f / df;
            let before = x;
            x -= dx;
            if before == x {
                break;
            }
        }
        if dx.abs() < NEWTON_TOL {
            break;
        }
        f = eval(p, x);
        df = eval(&dp, x);
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn collect<const M: usize>(r: Roots<M>) -> Vec<f64> {
        let (v, n) = r.sorted();
        v[..n].to_vec()
    }

    #[test]
    fn cbrt_matches_std() {
        let mut x = 1e-310_f64;
        while x < 1e300 {
            for v in [x, -x, x * 1.37] {
                let (a, b) = (cbrt(v), v.cbrt());
                assert!(
                    (a - b).abs() <= 4.0 * f64::EPSILON * b.abs(),
                    "{v}: {a} vs {b}"
                );
            }
            x *= 1.9;
        }
        assert_eq!(cbrt(27.0), 3.0);
        assert_eq!(cbrt(0.0), 0.0);
    }

    #[test]
    fn cubic_three_roots() {
        // (x-1)(x-2)(x-3)
        let r = collect(cubic(1.0, -6.0, 11.0, -6.0));
        assert_eq!(r.len(), 3);
        for (x, e) in r.iter().zip([1.0, 2.0, 3.0]) {
            assert!((x - e).abs() < 1e-12, "{r:?}");
        }
    }

    #[test]
    fn quartic_four_roots() {
        // (x-0.5)(x-1)(x-2)(x-4) = x^4 - 7.5x^3 + 17.5x^2 - 15x + 4
        let r = collect(quartic_monic(-7.5, 17.5, -15.0, 4.0));
        assert_eq!(r.len(), 4, "{r:?}");
        for (x, e) in r.iter().zip([0.5, 1.0, 2.0, 4.0]) {
            assert!((x - e).abs() < 1e-9, "{r:?}");
        }
    }

    #[test]
    fn scaled_quartic_keeps_tiny_roots() {
        // Step 1 NONE quartic of a 1.5e-8 move from v 7.2e-7 (j 3.9e4): the
        // absolute zero tests lose the root near 1.16e-4 s.
        let c = [
            0.0,
            7.385184240585768e-11,
            -1.5533784797893123e-12,
            -3.4088091417122748e-22,
        ];
        assert!(
            collect(quartic(&c))
                .iter()
                .all(|x| (x - 1.16e-4).abs() > 1e-5)
        );
        let r = collect(quartic_scaled(&c));
        let x = *r
            .iter()
            .find(|x| (**x - 1.16e-4).abs() < 1e-5)
            .expect("root");
        let p = (((x + c[0]) * x + c[1]) * x + c[2]) * x + c[3];
        assert!(p.abs() < 1e-28, "{r:?} {p:e}");
        // The scaling is exact: O(1) roots are unchanged.
        let q = [-7.5, 17.5, -15.0, 4.0];
        assert_eq!(collect(quartic_scaled(&q)), collect(quartic(&q)));
    }

    #[test]
    fn root_pow_bounds() {
        for x in [1e-300, 3e-9, 0.5, 1.0, 2.0, 7.0, 1e5, 1e300, -42.0] {
            for k in 1..=4 {
                let r = root_pow(x, k);
                let exact = x.abs().powf(1.0 / k as f64);
                assert!(r >= exact && r <= 4.0 * exact, "{x} {k}: {r} vs {exact}");
            }
        }
        assert_eq!(root_pow(0.0, 2), root_pow(1e-310, 2));
        assert!(root_pow(0.0, 3) < 1e-100);
        assert_eq!(root_pow(f64::NAN, 2), f64::INFINITY);
        assert_eq!(root_pow(f64::MAX, 1), f64::INFINITY);
        assert!(root_pow(f64::MAX, 2) >= f64::MAX.sqrt());
    }

    #[test]
    fn quartic_in_keeps_roots_in_range() {
        // (x-0.5)(x-1)(x-2)(x-4)
        let c = [-7.5, 17.5, -15.0, 4.0];
        assert_eq!(collect(quartic_in(&c, 0.4, 0.6)).len(), 4);
        assert_eq!(collect(quartic_in(&c, 1.0 - 1e-12, 1.0 - 1e-12)).len(), 4);
        assert_eq!(collect(quartic_in(&c, 2.5, 3.5)).len(), 0);
        assert_eq!(collect(quartic_in(&c, 5.0, 5.5)).len(), 0);
        assert_eq!(collect(quartic_in(&c, 3.0, 2.0)).len(), 0);
        // Random monic quartics with roots near the range ends.
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20000 {
            let x: [f64; 4] = core::array::from_fn(|_| 4.0 * rnd() - 1.0);
            let c = [
                -(x[0] + x[1] + x[2] + x[3]),
                x[0] * x[1] + x[0] * x[2] + x[0] * x[3] + x[1] * x[2] + x[1] * x[3] + x[2] * x[3],
                -(x[0] * x[1] * x[2]
                    + x[0] * x[1] * x[3]
                    + x[0] * x[2] * x[3]
                    + x[1] * x[2] * x[3]),
                x[0] * x[1] * x[2] * x[3],
            ];
            let lo = 3.0 * rnd() - 0.5;
            let hi = lo + rnd() * rnd();
            let all = collect(quartic(&c));
            let kept = collect(quartic_in(&c, lo, hi));
            if all.iter().any(|&t| t >= lo && t <= hi) {
                assert_eq!(all, kept, "{c:?} [{lo}, {hi}]");
            }
        }
    }

    #[test]
    fn negative_roots_are_dropped() {
        // (x+1)(x-2)
        let r = collect(cubic(0.0, 1.0, -1.0, -2.0));
        assert_eq!(r, vec![2.0]);
    }

    #[test]
    fn shrink_interval_finds_bracketed_root() {
        // x^5 - 2 on [1, 2]
        let p = [1.0, 0.0, 0.0, 0.0, 0.0, -2.0];
        let x = shrink_interval::<6, 5>(&p, 1.0, 2.0);
        assert!((x - 2f64.powf(0.2)).abs() < 1e-13);
    }
}
