//! The paper's hand as the planner sees it: three free fingertips (SPEC
//! §1.1), each with a 6-DoF pose, contacts in a workspace cone W_k, a roll
//! limit γ on its pole axis, and grip forces up to `load.max_grip`.
//!
//! [`Fingertips`] implements [`HandModel`]: the cones' candidate grids,
//! rigid carrying (contacts fixed on object and fingertip; the roll changes
//! by the turn's component about the pole, τ̇ = ω·a), placements with the
//! roll preset against the coming turn, the pair load test of
//! [`super::load`], the exact check of every sample, and the regrasps only
//! fingertips can make on the still object: rolling a pair apart
//! ([`open`]), rolling one contact elsewhere and spinning rolls back to
//! zero ([`unstick`]). [`build`] turns actions into steps.

pub mod build;
pub mod hold_table;
pub mod open;
pub mod unstick;

use std::sync::Arc;

use nalgebra::{UnitQuaternion, Vector3};

use super::budget::Stop;
use super::candidates::Candidates;
use super::geometry::{BOUNDARY_EPS, Geometry, cone_exit, fresh_range, roll_exit, rotation};
use super::hand_model::{Action, At, HandModel, Offer, RegraspFor};
use super::load::{self, LoadViolation, PairLoad};
use super::plan::{GreatCircleRoll, Motion, Step, StepKind};
use super::timing::DurationModel;
use super::zigzag::ZigzagCache;
use crate::HandConfig;
use crate::grasp::grip::GripModel;
use crate::grasp::hold::Accel;
use crate::hand_state::{FingerMode, HandState};
use build::Builder;
use hold_table::HoldTable;

/// A motion on the still object (the steps of a regrasp).
#[derive(Debug, Clone, PartialEq)]
pub enum StillAction {
    /// Fingers roll on the still object (time-synchronised).
    Roll([Option<GreatCircleRoll>; 3]),
    /// A finger leaves the object.
    Lift(usize),
    /// A free finger touches down at a contact with a roll preset.
    Place {
        /// Finger.
        finger: usize,
        /// Unit contact normal.
        contact: Vector3<f64>,
        /// Roll τ at touchdown.
        roll: f64,
    },
    /// A finger follows a rolling path (rolls and spins) on the still object.
    Path(usize, Box<crate::rolling::RollingPath>),
    /// A finger spins (a rolling path) on the still object of a
    /// three-finger grasp under load, pushing along its normal only while
    /// the other two carry the rest (SPEC §1.3 I1'); the grip passes to
    /// that set before and back after.
    Spin(usize, Box<crate::rolling::RollingPath>),
}

/// What kind of regrasp, for the plan's route.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RegraspKind {
    /// A pair rolled apart along its great circle.
    Open,
    /// A pair rolled apart in several legs per finger.
    OpenInLegs,
    /// One grasping finger rolled to another contact.
    Roll,
    /// The free finger placed, the rolls spun back, the finger lifted.
    Unwind,
}

/// A fingertip regrasp: its kind and its motions.
#[derive(Debug, Clone, PartialEq)]
pub struct Regrasp {
    /// Kind.
    pub kind: RegraspKind,
    /// Motions, in order.
    pub actions: Vec<StillAction>,
}

/// The free-fingertip hand (module docs). Cheap to clone: the grids and
/// the zigzag cache are shared.
#[derive(Debug, Clone)]
pub struct Fingertips {
    config: HandConfig,
    geom: Geometry,
    timing: DurationModel,
    load: PairLoad,
    grip: GripModel,
    cand: Arc<Candidates>,
    zigzags: Arc<ZigzagCache>,
    /// The resting pairs tabulated, with the sufficient load test and with
    /// the exact one behind it.
    tables: Arc<[HoldTable; 2]>,
    exact: bool,
    spins: bool,
}

impl Fingertips {
    /// The hand of a validated configuration.
    pub fn new(config: &HandConfig) -> Self {
        let geom = Geometry::new(config);
        let cand = Candidates::new(&geom, config.planner.candidate_spacing_deg);
        Self {
            config: *config,
            geom,
            timing: DurationModel::new(config),
            load: PairLoad::new(config),
            grip: GripModel::new(config),
            tables: Arc::new([HoldTable::new(&geom, &cand), HoldTable::new(&geom, &cand)]),
            cand: Arc::new(cand),
            zigzags: Arc::default(),
            exact: false,
            spins: !PairLoad::new(config).active(),
        }
    }

    /// The same hand timed with other motion limits. The grids and the
    /// resting-pair tables are shared: a table cell is a verdict at rest,
    /// which the motion limits do not enter (the acceleration's torque
    /// only matters while turning).
    pub fn with_limits(&self, limits: &crate::config::LimitsConfig) -> Self {
        let config = &HandConfig {
            limits: *limits,
            ..self.config
        };
        Self {
            config: *config,
            timing: DurationModel::new(config),
            load: PairLoad::new(config),
            grip: GripModel::new(config),
            zigzags: Arc::default(),
            exact: false,
            spins: !PairLoad::new(config).active(),
            ..self.clone()
        }
    }

    /// The same hand searching with the exact pair load test behind the
    /// sufficient one, and with spinning contacts under load allowed or not.
    pub fn for_pass(&self, exact: bool, spins: bool) -> Self {
        Self {
            load: if exact {
                self.load.with_exact(&self.config)
            } else {
                PairLoad::new(&self.config)
            },
            exact,
            spins: spins || !self.load.active(),
            ..self.clone()
        }
    }

    /// Roll-apart paths searched so far (not found in the cache).
    pub fn zigzag_searches(&self) -> u64 {
        self.zigzags.searches()
    }

    /// Model constants.
    pub fn geometry(&self) -> &Geometry {
        &self.geom
    }

    /// The pair load test.
    pub fn pair_load(&self) -> &PairLoad {
        &self.load
    }

    /// The exact grip model.
    pub fn grip(&self) -> &GripModel {
        &self.grip
    }

    /// The configuration.
    pub fn config(&self) -> &HandConfig {
        &self.config
    }

    /// The time of `actions` as steps (a regrasp's cost).
    fn time_of(&self, start: &HandState, actions: &[StillAction]) -> Option<f64> {
        let mut b = self.builder(*start);
        for a in actions {
            b.still(a).ok()?;
        }
        Some(b.steps.iter().map(|s| s.duration).sum())
    }

    fn builder(&self, start: HandState) -> Builder<'_> {
        Builder::new(
            &self.geom,
            self.config.limits,
            self.config.load.handover_time,
            start,
        )
    }
}

impl HandModel for Fingertips {
    type Touch = f64;
    type Regrasp = Regrasp;
    type Violation = LoadViolation;

    fn timing(&self) -> &DurationModel {
        &self.timing
    }

    fn candidates(&self, k: usize) -> &[Vector3<f64>] {
        &self.cand.points[k]
    }

    fn partners(&self, a: usize, b: usize, i: usize) -> &[u16] {
        &self.cand.partners[a][b][i]
    }

    fn good_pair(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
        self.geom.is_good_pair(a, b)
    }

    // Free fingertips: only the spheres can meet, and they are alike.
    fn apart(&self, (_, a): At<'_>, (_, b): At<'_>) -> bool {
        a.dot(b) <= self.geom.cos_sep_contact - BOUNDARY_EPS
    }

    fn fc_triple(&self, c: &[Vector3<f64>; 3]) -> bool {
        open::fact4(&self.geom, &c[0], &c[1], &c[2])
    }

    // (Closed form: the whole range costs no more than part of it.)
    fn carry_range(
        &self,
        hand: &HandState,
        fingers: &[usize],
        axis: &Vector3<f64>,
        _limit: f64,
    ) -> f64 {
        grasp_range(&self.geom, hand, fingers, axis)
    }

    fn carry(&self, hand: &mut HandState, axis: &Vector3<f64>, angle: f64) {
        rotate_hand(hand, axis, angle);
    }

    fn touch_for(&self, k: usize, contact: &Vector3<f64>, axis: &Vector3<f64>) -> (f64, f64) {
        fresh_range(&self.geom, k, axis, contact)
    }

    fn place(&self, hand: &mut HandState, k: usize, contact: &Vector3<f64>, touch: f64) {
        place_finger_pose(&self.geom, hand, k, contact, touch);
    }

    fn lift(&self, hand: &mut HandState, k: usize) {
        lift_finger(&self.geom, hand, k);
    }

    fn hover_dir(&self, hand: &HandState, k: usize) -> Vector3<f64> {
        hand.fingers[k].center.normalize()
    }

    fn key(&self, hand: &HandState, k: usize, axis: &Vector3<f64>) -> [i64; 2] {
        let f = &hand.fingers[k];
        [
            (f.roll * 50.0).round() as i64,
            (f.pole_axis().dot(axis) * 50.0).round() as i64,
        ]
    }

    fn load_active(&self) -> bool {
        self.load.active()
    }

    fn weight_direction(&self) -> Vector3<f64> {
        Vector3::from(self.config.load.gravity)
            .try_normalize(1e-12)
            .unwrap_or(-Vector3::z())
    }

    fn resting_partners(
        &self,
        x: usize,
        cx: &Vector3<f64>,
        z: usize,
        f: &mut dyn FnMut(usize, bool) -> bool,
    ) {
        let table = &self.tables[usize::from(self.exact)];
        match table.holding(&self.geom, &self.load, &self.cand, x, cx, z) {
            Some(h) => {
                let cand = &self.cand.points[z];
                // A sure cell holds for every contact in it (module docs of
                // `hold_table`), but the cell is not the contact.
                for i in h.sure {
                    if !f(i, false) {
                        return;
                    }
                }
                for i in h.may {
                    let c = &cand[i];
                    if self.geom.is_good_pair(c, cx) && self.load.holds(cx, c, None) && !f(i, true)
                    {
                        return;
                    }
                }
            }
            None => {
                for (i, c) in self.cand.points[z].iter().enumerate() {
                    if self.geom.is_good_pair(c, cx) && self.load.holds(cx, c, None) && !f(i, true)
                    {
                        return;
                    }
                }
            }
        }
    }

    // Every fingertip pushes up to `load.max_grip` in any direction.
    fn pair_holds(&self, (_, a): At<'_>, (_, b): At<'_>, axis: Option<&Vector3<f64>>) -> bool {
        self.load.holds(a, b, axis)
    }

    fn pair_hold_range(
        &self,
        (_, a): At<'_>,
        (_, b): At<'_>,
        axis: &Vector3<f64>,
        limit: f64,
    ) -> f64 {
        self.load.exit(a, b, axis, limit)
    }

    fn holds_at_rest(&self, hand: &HandState) -> bool {
        !self.load.active() || self.grip.carried_with(hand, Accel::None, 0b111).feasible
    }

    fn holds_along(&self, hand: &HandState, axis: &Vector3<f64>, angle: f64) -> bool {
        if !self.load.active() {
            return true;
        }
        let mut step = Step {
            kind: StepKind::Rotate,
            start: *hand,
            motion: Motion::Rotate {
                axis: *axis,
                angle,
                free: None,
            },
            duration: 0.0,
            handover: None,
        };
        step.duration = step.planned_duration(&self.config.limits);
        let a = self.config.limits.object.acceleration;
        load::check_steps(&self.grip, a, hand, &[step]).is_ok()
    }

    fn regrasps(
        &self,
        hand: &HandState,
        why: RegraspFor,
        _stop: &mut dyn Stop,
    ) -> Vec<Offer<Regrasp>> {
        match why {
            RegraspFor::OpenPair { lift } => open::open(
                &self.geom,
                &self.timing,
                &self.load,
                &self.grip,
                &self.config,
                &self.zigzags,
                hand,
                lift,
                self.config.planner.pair_margin_deg.to_radians() + 1e-7,
            )
            .into_iter()
            .map(|o| Offer {
                regrasp: Regrasp {
                    kind: if o.legs {
                        RegraspKind::OpenInLegs
                    } else {
                        RegraspKind::Open
                    },
                    actions: o.actions,
                },
                end: o.hand,
                cost: o.cost,
            })
            .collect(),
            RegraspFor::Unstick => self.unstick(hand),
        }
    }

    fn regrasp_name(&self, r: &Regrasp) -> &'static str {
        match r.kind {
            RegraspKind::Open => "roll apart",
            RegraspKind::OpenInLegs => "roll apart in legs",
            RegraspKind::Roll => "roll a contact",
            RegraspKind::Unwind => "unwind",
        }
    }

    fn regrasp_bound(&self, hand: &HandState, why: RegraspFor) -> f64 {
        match why {
            RegraspFor::OpenPair { lift } => open::bound(&self.geom, &self.timing, hand, lift),
            RegraspFor::Unstick => 0.0,
        }
    }

    fn build(&self, start: &HandState, actions: &[Action<Self>]) -> Result<Vec<Step>, usize> {
        let mut b = self.builder(*start);
        for (i, a) in actions.iter().enumerate() {
            match a {
                Action::Rotate { axis, angle, .. } => {
                    // The free finger travels to its next placement meanwhile.
                    let next = match actions.get(i + 1) {
                        Some(Action::Place {
                            finger,
                            contact,
                            touch,
                        }) => Some((*finger, *contact, *touch)),
                        _ => None,
                    };
                    b.rotate(axis, *angle, next).map_err(|e| e.finger)?;
                }
                Action::Place {
                    finger,
                    contact,
                    touch,
                } => b.place(*finger, contact, *touch).map_err(|e| e.finger)?,
                Action::Lift { finger } => b.lift(*finger),
                Action::Regrasp { regrasp: r, .. } => {
                    for s in &r.actions {
                        b.still(s).map_err(|e| e.finger)?;
                    }
                }
            }
        }
        Ok(b.steps)
    }

    fn check(&self, start: &HandState, steps: &[Step]) -> Result<(), LoadViolation> {
        if !self.load.active() {
            return Ok(());
        }
        let a = self.config.limits.object.acceleration;
        load::check_steps(&self.grip, a, start, steps)
    }
}

impl Fingertips {
    /// The regrasps for a grasp no gait can leave: with two fingers, a
    /// grasping finger rolled elsewhere, or the rolls spun back with the
    /// free finger's help; with three, the rolls spun back ([`unstick`]).
    fn unstick(&self, hand: &HandState) -> Vec<Offer<Regrasp>> {
        let mut out = Vec::new();
        if hand.grasping().1 == 3 {
            // Under load a spin uses its contact's whole cone: only in the
            // pass that allows spins.
            let loaded = self.load.active();
            if (!loaded || self.spins)
                && let Some(u) =
                    unstick::unwind_triple(&self.geom, &self.grip, &self.config, hand, loaded)
                && let Some(cost) = self.time_of(hand, &u.actions)
            {
                out.push(Offer {
                    regrasp: Regrasp {
                        kind: RegraspKind::Unwind,
                        actions: u.actions,
                    },
                    end: u.hand,
                    cost,
                });
            }
            return out;
        }
        let mut offer = |kind, actions: Vec<StillAction>, end: HandState| {
            if let Some(cost) = self.time_of(hand, &actions) {
                out.push(Offer {
                    regrasp: Regrasp { kind, actions },
                    end,
                    cost,
                });
            }
        };
        let rolls =
            unstick::roll_escapes(&self.geom, &self.cand, &self.load, &self.config, hand, 2);
        for (finger, path) in rolls {
            let mut end = *hand;
            end.fingers[finger] = path
                .eval(path.length())
                .finger_state(&hand.object, path.geometry());
            offer(
                RegraspKind::Roll,
                vec![StillAction::Path(finger, Box::new(path))],
                end,
            );
        }
        // Spinning a contact under load is the last pass's (its torsion is
        // used up by the spin); without it, the free finger is only
        // relocated (no spins).
        let plain_spin = !self.load.active();
        if let Some(u) = unstick::unwind(
            &self.geom,
            &self.cand,
            &self.grip,
            &self.config,
            hand,
            plain_spin,
        ) {
            offer(RegraspKind::Unwind, u.actions, u.hand);
        }
        if self.spins
            && self.load.active()
            && let Some(u) =
                unstick::unwind_loaded(&self.geom, &self.cand, &self.grip, &self.config, hand)
        {
            offer(RegraspKind::Unwind, u.actions, u.hand);
        }
        out
    }
}

/// Puts a free finger down at `contact` with its pole, swinging and
/// twisting its orientation (SPEC §1.1: swing leaves τ alone, the twist
/// about the pole changes τ to `roll`).
pub fn place_finger(
    g: &Geometry,
    hand: &mut HandState,
    finger: usize,
    contact: &Vector3<f64>,
    roll: f64,
) {
    let f = &mut hand.fingers[finger];
    let pole = -contact;
    let turn = super::plan::Reorientation::towards(&f.orientation, &pole, roll - f.roll);
    f.orientation = turn.at(&f.orientation, 1.0);
    f.center = contact * g.contact_radius;
    f.roll = roll;
    f.mode = FingerMode::Grasping;
}

/// What the search needs of a placement: contact, pole axis −c and roll.
/// The fingertip orientation about its pole is whichever is cheapest (the
/// plan builder makes the real one with [`place_finger`]); this takes the
/// minimal rotation e_z → −c from its half-way quaternion, without trig.
pub fn place_finger_pose(
    g: &Geometry,
    hand: &mut HandState,
    finger: usize,
    contact: &Vector3<f64>,
    roll: f64,
) {
    let f = &mut hand.fingers[finger];
    let pole = -contact;
    // q = (1 + e_z·p, e_z × p) normalised rotates e_z onto p (p ≠ −e_z).
    let w = 1.0 + pole.z;
    f.orientation = if w > 1e-9 {
        UnitQuaternion::new_normalize(nalgebra::Quaternion::new(w, -pole.y, pole.x, 0.0))
    } else {
        rotation(&Vector3::x(), std::f64::consts::PI)
    };
    f.center = contact * g.contact_radius;
    f.roll = roll;
    f.mode = FingerMode::Grasping;
}

/// Lifts a grasping finger straight up to the transfer height.
pub fn lift_finger(g: &Geometry, hand: &mut HandState, finger: usize) {
    let f = &mut hand.fingers[finger];
    f.center = f.center.normalize() * g.transfer_radius;
    f.mode = FingerMode::Free;
}

/// How far the grasping `fingers` of `hand` can carry the object about
/// `axis`: each contact in its cone, each roll within its limit (less
/// [`BOUNDARY_EPS`]).
pub fn grasp_range(g: &Geometry, hand: &HandState, fingers: &[usize], axis: &Vector3<f64>) -> f64 {
    let mut range = f64::INFINITY;
    for &k in fingers {
        let f = &hand.fingers[k];
        range = range
            .min(cone_exit(g, k, axis, &f.contact_normal()))
            .min(roll_exit(g, axis, &f.pole_axis(), f.roll));
    }
    (range - BOUNDARY_EPS).max(0.0)
}

/// Rotates the object and every grasping finger about `axis` by `angle`.
pub fn rotate_hand(hand: &mut HandState, axis: &Vector3<f64>, angle: f64) {
    let q = rotation(axis, angle);
    hand.object = q * hand.object;
    for f in hand.fingers.iter_mut() {
        if f.mode == FingerMode::Grasping {
            let pole = f.pole_axis();
            f.roll += angle * axis.dot(&pole);
            f.center = q * f.center;
            f.orientation = q * f.orientation;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_placement_points_the_pole_at_the_object() {
        let cfg = crate::HandConfig::default();
        let g = Geometry::new(&cfg);
        let mut hand = HandState::paper_start(&cfg);
        for i in 0..200 {
            let a = i as f64 * 0.1;
            let c = Vector3::new(
                a.cos() * (a * 0.3).sin(),
                a.sin() * (a * 0.3).sin(),
                (a * 0.3).cos(),
            );
            place_finger_pose(&g, &mut hand, 0, &c, 0.1);
            let f = hand.fingers[0];
            assert!((f.pole_axis() + c).norm() < 1e-12, "{c:?}");
            assert!((f.fingertip_contact() - Vector3::z()).norm() < 1e-12);
        }
    }
}
