//! The state of one fingertip–object contact (SPEC §2.2–2.3) and its
//! conversions.

use crate::hand_state::{FingerMode, FingerState};
use crate::sphere::{ChartId, ChartPoint, rotation::angle_between};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Radii of the two spheres (SPEC §1.1): object R, fingertip r.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// Object radius R \[m\].
    pub object_radius: f64,
    /// Fingertip radius r \[m\].
    pub fingertip_radius: f64,
}

/// Why a contact state could not be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ContactError {
    /// A radius is not a positive finite number.
    #[error("sphere radii must be positive and finite")]
    InvalidGeometry,
    /// An input holds NaN or an infinity.
    #[error("contact input is not finite")]
    NonFinite,
    /// The finger is not in contact (mode Free).
    #[error("finger is not grasping")]
    NotGrasping,
    /// The fingertip centre is not at distance R + r from the object centre.
    #[error("fingertip centre is not at distance R + r")]
    NotTouching,
}

impl ContactGeometry {
    /// Radii R, r, both positive and finite.
    pub fn new(object_radius: f64, fingertip_radius: f64) -> Result<Self, ContactError> {
        let ok = |x: f64| x.is_finite() && x > 0.0;
        if ok(object_radius) && ok(fingertip_radius) {
            Ok(Self {
                object_radius,
                fingertip_radius,
            })
        } else {
            Err(ContactError::InvalidGeometry)
        }
    }

    /// The radii of a (validated) configuration.
    pub fn from_config(config: &crate::HandConfig) -> Self {
        Self {
            object_radius: config.model.object_radius,
            fingertip_radius: config.model.fingertip_radius,
        }
    }

    /// Distance R + r from the object centre to a touching fingertip centre.
    pub fn center_distance(&self) -> f64 {
        self.object_radius + self.fingertip_radius
    }

    /// r/(R + r): object-contact angle per radian of fingertip rotation
    /// relative to the object, when rolling (SPEC §2.3: ṅ_o).
    pub fn object_ratio(&self) -> f64 {
        self.fingertip_radius / self.center_distance()
    }

    /// R/(R + r): fingertip-contact angle per radian of relative rotation.
    pub fn fingertip_ratio(&self) -> f64 {
        self.object_radius / self.center_distance()
    }

    /// rR/(R + r): contact arc length (equal on both bodies) per radian of
    /// relative rotation \[m\].
    pub fn arc_ratio(&self) -> f64 {
        self.object_radius * self.fingertip_radius / self.center_distance()
    }
}

/// One contact, hand frame (SPEC §2.3). Only independent quantities are
/// stored; the contact points, frames and ψ are derived.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactState {
    /// Object orientation Q_o (object frame → hand frame).
    pub object: UnitQuaternion<f64>,
    /// Fingertip orientation Q_f (fingertip frame → hand frame).
    pub fingertip: UnitQuaternion<f64>,
    /// Outward object normal n at the contact, hand frame (unit). The
    /// fingertip centre is (R + r) n.
    pub normal: Vector3<f64>,
    /// Fingertip roll τ about its pole axis, τ̇ = ω_f · (Q_f e_z) \[rad\].
    pub roll: f64,
}

/// A contact seen from the object (object frame): what rolling paths need
/// while the object is still (SPEC §4.2 Roll). Hand-frame quantities are
/// Q_o times these.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativeContact {
    /// Contact point on the object, n_o = Q_oᵀ n (unit, object frame).
    pub contact: Vector3<f64>,
    /// Fingertip orientation relative to the object, Q_oᵀ Q_f
    /// (fingertip frame → object frame).
    pub fingertip: UnitQuaternion<f64>,
    /// Fingertip roll τ \[rad\].
    pub roll: f64,
}

/// Angle of the fingertip contact m from the fingertip equator (positive
/// inside the contactable hemisphere, SPEC §1.1): π/2 − angle(m, e_z).
fn hemisphere_margin_of(m: &Vector3<f64>) -> f64 {
    core::f64::consts::FRAC_PI_2 - angle_between(m, &Vector3::z())
}

impl RelativeContact {
    /// Contact point on the fingertip, m = Q_relᵀ(−n_o) (fingertip frame).
    pub fn fingertip_contact(&self) -> Vector3<f64> {
        self.fingertip.inverse() * (-self.contact)
    }

    /// The fingertip pole axis Q_rel e_z, object frame.
    pub fn pole_axis(&self) -> Vector3<f64> {
        self.fingertip * Vector3::z()
    }

    /// π/2 − angle(m, e_z): ≥ 0 inside the fingertip hemisphere \[rad\].
    pub fn hemisphere_margin(&self) -> f64 {
        hemisphere_margin_of(&self.fingertip_contact())
    }

    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        self.contact.iter().all(|x| x.is_finite())
            && self.fingertip.coords.iter().all(|x| x.is_finite())
            && self.roll.is_finite()
    }
}

impl ContactState {
    /// The contact of a grasping finger (SPEC §2.3: n = p_f/|p_f|). The
    /// centre must be at R + r within 1e-9 relative.
    pub fn from_finger(
        finger: &FingerState,
        object: UnitQuaternion<f64>,
        geom: &ContactGeometry,
    ) -> Result<Self, ContactError> {
        let finite = finger.center.iter().all(|x| x.is_finite())
            && finger.orientation.coords.iter().all(|x| x.is_finite())
            && object.coords.iter().all(|x| x.is_finite())
            && finger.roll.is_finite();
        if !finite {
            return Err(ContactError::NonFinite);
        }
        if finger.mode != FingerMode::Grasping {
            return Err(ContactError::NotGrasping);
        }
        let d = geom.center_distance();
        let norm = finger.center.norm();
        if (norm - d).abs() > 1e-9 * d {
            return Err(ContactError::NotTouching);
        }
        Ok(Self {
            object,
            fingertip: finger.orientation,
            normal: finger.center / norm,
            roll: finger.roll,
        })
    }

    /// The finger state of this contact (mode Grasping).
    pub fn to_finger(&self, geom: &ContactGeometry) -> FingerState {
        FingerState {
            mode: FingerMode::Grasping,
            center: self.center(geom),
            orientation: self.fingertip,
            roll: self.roll,
        }
    }

    /// Fingertip centre p_f = (R + r) n, hand frame.
    pub fn center(&self, geom: &ContactGeometry) -> Vector3<f64> {
        self.normal * geom.center_distance()
    }

    /// Contact point on the object, n_o = Q_oᵀ n (unit, object frame).
    pub fn object_contact(&self) -> Vector3<f64> {
        self.object.inverse() * self.normal
    }

    /// Contact point on the fingertip, m = Q_fᵀ(−n) (unit, fingertip frame).
    pub fn fingertip_contact(&self) -> Vector3<f64> {
        self.fingertip.inverse() * (-self.normal)
    }

    /// Fingertip pole axis a_f = Q_f e_z, hand frame.
    pub fn pole_axis(&self) -> Vector3<f64> {
        self.fingertip * Vector3::z()
    }

    /// π/2 − angle(m, e_z): ≥ 0 inside the fingertip hemisphere \[rad\].
    pub fn hemisphere_margin(&self) -> f64 {
        hemisphere_margin_of(&self.fingertip_contact())
    }

    /// The object-frame view of this contact.
    pub fn relative(&self) -> RelativeContact {
        RelativeContact {
            contact: self.object_contact(),
            fingertip: self.object.inverse() * self.fingertip,
            roll: self.roll,
        }
    }

    /// The contact of `rel` with the object at orientation `object`.
    pub fn from_relative(rel: &RelativeContact, object: UnitQuaternion<f64>) -> Self {
        Self {
            object,
            fingertip: object * rel.fingertip,
            normal: object * rel.contact,
            roll: rel.roll,
        }
    }

    /// Fingertip contact frame C_f (hand frame): the Gauss frame of the
    /// fingertip chart `chart` at m, mapped by Q_f (its z is −n).
    pub fn fingertip_frame(&self, chart: ChartId) -> Matrix3<f64> {
        let pf = ChartPoint::from_unit(chart, &self.fingertip_contact());
        self.fingertip.to_rotation_matrix().matrix() * pf.frame()
    }

    /// Object contact frame C_o (hand frame): the Gauss frame of the object
    /// chart `chart` at n_o, mapped by Q_o (its z is n).
    pub fn object_frame(&self, chart: ChartId) -> Matrix3<f64> {
        let po = ChartPoint::from_unit(chart, &self.object_contact());
        self.object.to_rotation_matrix().matrix() * po.frame()
    }

    /// Contact frames (C_f, C_o), hand frame, from the fingertip chart
    /// `finger` and the object chart `object` (module docs).
    pub fn contact_frames(&self, finger: ChartId, object: ChartId) -> (Matrix3<f64>, Matrix3<f64>) {
        (self.fingertip_frame(finger), self.object_frame(object))
    }

    /// Chart coordinates of the contact (SPEC §2.2): α_f in the fingertip
    /// chart `finger`, α_o in the object chart `object`, and ψ.
    pub fn chart_contact(&self, finger: ChartId, object: ChartId) -> super::ChartContact {
        let pf = ChartPoint::from_unit(finger, &self.fingertip_contact());
        let po = ChartPoint::from_unit(object, &self.object_contact());
        let (cf, co) = self.contact_frames(finger, object);
        let xo = co.column(0);
        // x_o = cos ψ x_f − sin ψ y_f.
        let psi = (-xo.dot(&cf.column(1))).atan2(xo.dot(&cf.column(0)));
        super::ChartContact {
            finger: pf,
            object: po,
            psi,
        }
    }

    /// The contact with chart coordinates `c`, object orientation `object`
    /// and roll `roll` (the inverse of [`ContactState::chart_contact`]).
    pub fn from_chart_contact(
        c: &super::ChartContact,
        object: UnitQuaternion<f64>,
        roll: f64,
    ) -> Self {
        let co = object.to_rotation_matrix().matrix() * c.object.frame();
        let (s, k) = c.psi.sin_cos();
        let (xo, yo) = (co.column(0), co.column(1));
        // R_ψ is an involution: x_f = cos ψ x_o − sin ψ y_o, y_f = −sin ψ x_o − cos ψ y_o.
        let xf = xo * k - yo * s;
        let yf = -xo * s - yo * k;
        let zf = -co.column(2);
        let cf = Matrix3::from_columns(&[xf, yf, zf]);
        let qf = cf * c.finger.frame().transpose();
        Self {
            object,
            fingertip: UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(qf)),
            normal: co.column(2).into(),
            roll,
        }
    }
}
