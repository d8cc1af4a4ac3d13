//! Orientations as the daemon's interfaces carry them: unit quaternions as
//! four numbers (`[w, x, y, z]` or `[x, y, z, w]`, the same order for both
//! arguments).

/// The angle of the rotation between orientations `a` and `b` \[rad\], in
/// `[0, π]`: `q` and `−q` are the same orientation, so the dot product's
/// sign does not count.
pub fn angle(a: [f64; 4], b: [f64; 4]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    2.0 * d.abs().min(1.0).acos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quarter_turn_either_sign() {
        let id = [1.0, 0.0, 0.0, 0.0];
        let h = std::f64::consts::FRAC_PI_4;
        let quarter = [h.cos(), 0.0, 0.0, h.sin()];
        let neg = quarter.map(|c| -c);
        for q in [quarter, neg] {
            assert!((angle(id, q) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        }
        assert_eq!(angle(quarter, neg), 0.0);
        // Rounding past |dot| = 1 is not NaN.
        assert_eq!(angle(id, [1.0 + 1e-16, 0.0, 0.0, 0.0]), 0.0);
    }
}
