//! Contacts on the object sphere, their frames, the friction model and the
//! grasp map G (SPEC.md §1.2, §3.2).
//!
//! A contact is a point R·n on the object sphere (centre O at the origin of
//! the hand frame), n the unit outward normal. The contact force on the
//! object is
//!
//! F = f_n (−n) + f_1 t_1 + f_2 t_2,
//!
//! with (t_1, t_2) the tangent frame of [`ContactFrame`]. A soft contact adds
//! a torsional moment τ_n about the inward normal −n.
//!
//! The grasp map used here is *normalised*: torque rows are divided by R, so
//! every entry is dimensionless and the rank test does not depend on the
//! object's size; and the torsion column acts on the scaled torsion
//! s = τ_n · μ/μ_t, the variable that enters the elliptic soft-finger cone
//! ‖(f_1, f_2, s)‖ ≤ μ f_n (SPEC §3.2) on equal footing with the tangential
//! forces. With p = R n, the normal force passes through O and contributes no
//! torque; the tangential columns are (t_1; n × t_1) = (t_1; t_2) and
//! (t_2; n × t_2) = (t_2; −t_1); the torsion column is (0; −κ n) with
//! κ = μ_t / (μ R).

use nalgebra::{Matrix6, SymmetricEigen, Vector3, Vector6};

use crate::HandConfig;

/// Contact model of one grasping finger (SPEC §1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ContactKind {
    /// Point contact with friction: normal force plus two tangential forces.
    Hard,
    /// Soft finger: hard contact plus torsional friction about the normal.
    Soft,
}

impl ContactKind {
    /// Number of force components (3 hard, 4 soft).
    pub const fn dim(self) -> usize {
        match self {
            Self::Hard => 3,
            Self::Soft => 4,
        }
    }
}

/// One contact: unit outward normal n (hand frame) and its model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Unit outward object normal at the contact, hand frame.
    pub normal: Vector3<f64>,
    /// Hard or soft.
    pub kind: ContactKind,
}

impl Contact {
    /// A hard contact at unit normal `normal`.
    pub const fn hard(normal: Vector3<f64>) -> Self {
        Self {
            normal,
            kind: ContactKind::Hard,
        }
    }

    /// A soft contact at unit normal `normal`.
    pub const fn soft(normal: Vector3<f64>) -> Self {
        Self {
            normal,
            kind: ContactKind::Soft,
        }
    }
}

/// Friction data of the grasp-analysis problems (SPEC §1.1, §1.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Friction {
    /// Coulomb coefficient μ = tan θ (> 0).
    pub mu: f64,
    /// Torsional coefficient μ_t \[m\] (> 0; SPEC default 0.1 · r · μ).
    pub mu_torsion: f64,
    /// Object radius R \[m\], used to normalise torques.
    pub object_radius: f64,
}

impl Friction {
    /// The configuration's friction: μ = tan θ, μ_t = ratio · r · μ, R.
    pub fn from_config(config: &HandConfig) -> Self {
        Self {
            mu: config.mu(),
            mu_torsion: config.mu_torsion(),
            object_radius: config.model.object_radius,
        }
    }

    /// The same friction with the friction angle reduced by `delta` \[rad\]:
    /// μ' = tan(θ − δ), μ_t scaled by μ'/μ (the SPEC ratio μ_t ∝ μ is kept).
    /// Force closure at θ − δ/2 is force closure "with angle margin δ" in
    /// the sense of Fact 3 (SPEC §1.3 I1): the separation bound π − 2θ grows
    /// by exactly δ.
    pub fn reduced(&self, delta: f64) -> Self {
        let theta = self.mu.atan();
        let mu = (theta - delta).max(1e-6).tan();
        Self {
            mu,
            mu_torsion: self.mu_torsion * mu / self.mu,
            object_radius: self.object_radius,
        }
    }

    /// Torsion lever κ = μ_t / (μ R) of the normalised torsion column.
    pub fn torsion_lever(&self) -> f64 {
        self.mu_torsion / (self.mu * self.object_radius)
    }

    /// True when every field is finite and positive.
    pub fn is_valid(&self) -> bool {
        [self.mu, self.mu_torsion, self.object_radius]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
    }
}

/// Deterministic tangent frame (t_1, t_2, n) of a contact: right-handed,
/// t_2 = n × t_1, t_1 the projection onto the tangent plane of the coordinate
/// axis least aligned with n (lowest index on ties). Discontinuous where that
/// axis switches, which does not matter to anything rotationally symmetric
/// about n (cones, margins, normal forces).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    /// First tangent.
    pub t1: Vector3<f64>,
    /// Second tangent, n × t_1.
    pub t2: Vector3<f64>,
    /// Unit outward normal n.
    pub n: Vector3<f64>,
}

impl ContactFrame {
    /// The frame at unit normal `n` (normalised here; `n` must be non-zero
    /// and finite).
    pub fn new(n: &Vector3<f64>) -> Self {
        let n = n.normalize();
        let a = n.abs();
        let axis = if a.x <= a.y && a.x <= a.z {
            Vector3::x()
        } else if a.y <= a.z {
            Vector3::y()
        } else {
            Vector3::z()
        };
        let t1 = (axis - n * n.dot(&axis)).normalize();
        let t2 = n.cross(&t1);
        Self { t1, t2, n }
    }
}

/// Relative tolerance on singular values of the normalised grasp map for
/// the numerical rank (σ_i > 1e-6 σ_max; eigenvalues of G Gᵀ above 1e-12
/// of the largest).
pub const RANK_TOLERANCE: f64 = 1e-6;

/// Columns of the normalised grasp map for one contact, in variable order
/// (f_n, f_1, f_2 \[, s\]). Unused trailing columns are zero.
pub fn grasp_columns(contact: &Contact, friction: &Friction) -> [Vector6<f64>; 4] {
    let fr = ContactFrame::new(&contact.normal);
    let col = |f: Vector3<f64>, m: Vector3<f64>| Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z);
    let z = Vector3::zeros();
    let torsion = match contact.kind {
        ContactKind::Hard => Vector6::zeros(),
        ContactKind::Soft => col(z, -fr.n * friction.torsion_lever()),
    };
    [
        col(-fr.n, z),
        col(fr.t1, fr.t2),
        col(fr.t2, -fr.t1),
        torsion,
    ]
}

/// G Gᵀ (6×6) of the normalised grasp map: its eigenvalues are the squared
/// singular values of G. Accumulated per contact, so any number of contacts
/// works without allocation.
pub fn grasp_gram(contacts: &[Contact], friction: &Friction) -> Matrix6<f64> {
    let mut m = Matrix6::zeros();
    for c in contacts {
        let cols = grasp_columns(c, friction);
        for col in &cols[..c.kind.dim()] {
            m += col * col.transpose();
        }
    }
    m
}

/// Numerical rank of the normalised grasp map (0..=6), with relative
/// tolerance [`RANK_TOLERANCE`] on singular values. Force closure needs 6.
pub fn grasp_rank(contacts: &[Contact], friction: &Friction) -> u8 {
    let gram = grasp_gram(contacts, friction);
    if !gram.iter().all(|v| v.is_finite()) {
        return 0;
    }
    let eig = SymmetricEigen::new(gram).eigenvalues;
    let max = eig.max();
    if max <= 0.0 {
        return 0;
    }
    let threshold = max * RANK_TOLERANCE * RANK_TOLERANCE;
    eig.iter().filter(|&&l| l > threshold).count() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    fn friction() -> Friction {
        Friction::from_config(&HandConfig::default())
    }

    #[test]
    fn frames_are_orthonormal_right_handed() {
        for n in [
            Vector3::x(),
            -Vector3::y(),
            Vector3::new(1.0, 2.0, -3.0).normalize(),
            Vector3::new(1.0, 1.0, 1.0).normalize(),
        ] {
            let f = ContactFrame::new(&n);
            assert!((f.t1.norm() - 1.0).abs() < 1e-14);
            assert!(f.t1.dot(&n).abs() < 1e-14);
            assert!((f.t1.cross(&f.t2) - n).norm() < 1e-14);
        }
    }

    #[test]
    fn two_hard_contacts_never_span_wrenches() {
        let c = [Contact::hard(Vector3::x()), Contact::hard(-Vector3::x())];
        assert_eq!(grasp_rank(&c, &friction()), 5);
        let c = [Contact::soft(Vector3::x()), Contact::soft(-Vector3::x())];
        assert_eq!(grasp_rank(&c, &friction()), 6);
        let c = [Contact::soft(Vector3::x()), Contact::soft(Vector3::x())];
        assert_eq!(grasp_rank(&c, &friction()), 4);
    }

    #[test]
    fn reduced_friction_keeps_torsion_ratio() {
        let f = friction();
        let g = f.reduced(1f64.to_radians());
        assert!((g.mu.atan() - (20f64 - 1.0).to_radians()).abs() < 1e-12);
        assert!((g.mu_torsion / g.mu - f.mu_torsion / f.mu).abs() < 1e-15);
    }
}
