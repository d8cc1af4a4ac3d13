//! The chain hand behind the search's boundary ([`HandModel`], SPEC §4.2,
//! §14): what the one search asks a hand, answered for finger chains.
//!
//! - **Where a finger can touch**: the workspace (§14.1) on a Fibonacci
//!   grid of normals — the closed-form branch with the most joint-limit
//!   margin, inside the tip patch and with the links clear of the object
//!   by the hand's margins ([`kinematics::reach`]).
//! - **Which pairs**: force-closure with the planner's margin (paper Fact
//!   3), the two fingers' links and tips apart by the hand's gap.
//! - **Turning the object**: three fingers, whose contacts follow the
//!   rolling law (§14.2); how far is [`kinematics::carry_range`]. A pair
//!   of 3-joint fingers turned about a fixed axis spins at its contacts,
//!   and a pair holds only through torsion (§1.2): a pair does not turn
//!   (its range is 0); the object is turned by three fingers, and gaits
//!   lift and place one at a time.
//! - **The load**: the torque box (§14.1) at the fingers' joints, two
//!   fingers as soft contacts at rest, three as hard ones, turning with
//!   the torque of the largest angular acceleration.
//! - **Regrasps on the still object**: none — a chain finger's tip
//!   orientation follows its position, so it cannot roll on the still
//!   object (§14.2 with ω_o = 0 leaves ċ = 0).
//! - **Steps and their check**: [`super::steps`], [`super::certify`].
//!
//! A fresh placement's range is the finger's own: its contact follows
//! the object by its own chain alone (the rolling law is per finger), so
//! a grasp turns as far as the least of its fingers' ranges, unless two
//! fingers come too close first.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use nalgebra::Vector3;

use super::ChainHand;
use super::carry_load::CarryLoads;
use super::certify::{ChainViolation, CheckParams, check, check_way, grasp_share};
use super::quick_hold::closed_form_share;
use super::steps::{ChainBuilder, carried};
use crate::HandConfig;
use crate::hand_state::{FINGERS, FingerMode, HandState};
use crate::planner::budget::Stop;
use crate::planner::fingertips::open::fact4;
use crate::planner::geometry::{Geometry, rotation};
use crate::planner::hand_model::{Action, At, HandModel, Offer, RegraspFor};
use crate::planner::plan::Step;
use crate::planner::timing::DurationModel;

/// Normals of the workspace grid on the whole sphere (each finger keeps
/// the third or so it reaches).
pub const GRID: usize = 600;

/// The longest turn a carry range is scanned for \[rad\] (half a turn).
const RANGE_LIMIT: f64 = std::f64::consts::PI;

/// The longest turn a fresh placement's own range is scanned for \[rad\]
/// (90°): a table of every candidate is made for every axis the search
/// turns about, and a grasp that turns further is rare (the links' and
/// the tip patch's limits come sooner).
const TOUCH_LIMIT: f64 = std::f64::consts::FRAC_PI_2;

/// A fresh placement's scan step \[rad\] (8°, the failing step bisected):
/// it ranks placements; the grasp's own range is scanned finer.
const TOUCH_STEP: f64 = 8.0 * std::f64::consts::PI / 180.0;

/// Halvings of a fresh placement's first failing step: its range is
/// found to 8°/64 = 0.125°, enough to rank placements (a table of every
/// candidate is made per axis, and the halvings are most of its cost).
const TOUCH_BISECTIONS: u32 = 6;

/// The range scan's step \[rad\] (4°; the first failing step is bisected).
/// The search's ranges steer it; the plan's check samples every degree.
const RANGE_STEP: f64 = 4.0 * std::f64::consts::PI / 180.0;

/// Samples of a turn's load test \[rad\] (3°, as the free fingertips').
const LOAD_STEP: f64 = 3.0 * std::f64::consts::PI / 180.0;

/// Most resting-pair verdicts kept (about 10 MB).
const RESTING_MEMO: usize = 200_000;

/// A resting pair asked: grasping finger, its contact's bits, free
/// finger, its candidate.
type RestingKey = (usize, [u64; 3], usize, usize);

/// A chain hand offers no regrasp on the still object (module docs).
#[derive(Debug, Clone, PartialEq)]
pub enum NoRegrasp {}

/// The workspace grids and the pairs among them.
#[derive(Debug)]
struct Grids {
    points: [Vec<Vector3<f64>>; FINGERS],
    partners: [[Vec<Vec<u16>>; FINGERS]; FINGERS],
}

/// The chain hand as the search sees it (module docs). Clones share the
/// grids and the memo of resting pairs.
#[derive(Debug, Clone)]
pub struct ChainModel {
    hand: ChainHand,
    config: HandConfig,
    geom: Geometry,
    timing: DurationModel,
    params: CheckParams,
    grids: Arc<Grids>,
    /// Resting-pair verdicts by (x, contact's bits, z, candidate).
    resting: Arc<Mutex<HashMap<RestingKey, bool>>>,
    /// The load tests along carries so far.
    carries: Arc<CarryLoads>,
    /// `apart` verdicts by (fingers, contacts' bits), at most
    /// [`APART_MEMO`].
    apart_memo: Arc<Mutex<HashMap<ApartKey, bool>>>,
}

/// Two fingers and their contacts' bits.
type ApartKey = (usize, usize, [u64; 3], [u64; 3]);

/// Most `apart` verdicts kept (about 10 MB); the memo starts afresh past it.
const APART_MEMO: usize = 1 << 17;

impl ChainModel {
    /// The model of `hand` with the planner's settings from `config`: its
    /// motion limits, `planner.transfer_height` (the free fingers' hover
    /// height), `planner.pair_margin_deg`, `model.fc_margin_deg`,
    /// `load.handover_time` and `load.min_grip`; the object, friction and
    /// gravity are the hand's own (they replace `config`'s).
    pub fn new(hand: ChainHand, config: &HandConfig) -> Self {
        let mut config = *config;
        let o = hand.object();
        config.model.object_radius = o.radius;
        config.model.fingertip_radius = hand.chain(0).tip_radius;
        config.model.friction_angle_deg = hand.friction_mu().atan().to_degrees();
        config.load.object_mass = o.mass;
        config.load.gravity = (*hand.gravity()).into();
        // The free fingertips' shell is no limit of a chain (reach and
        // clearance bound its free tip); its greatest valid height keeps
        // the configuration valid for the executor's checks.
        config.model.free_space_height = o.radius;
        let geom = Geometry::new(&config);
        let params = CheckParams {
            carry_step: std::f64::consts::PI / 180.0,
            free_step: 0.001,
            branch_jump: 0.25,
            max_acceleration: config.limits.object.acceleration,
            min_grip: config.load.min_grip,
        };
        let grids = Arc::new(Grids::new(&hand, &geom));
        Self {
            timing: DurationModel::new(&config),
            hand,
            config,
            geom,
            params,
            grids,
            resting: Arc::default(),
            carries: Arc::default(),
            apart_memo: Arc::default(),
        }
    }

    /// The same model timing and costing plans under `limits` (a goal's
    /// motion-limit overrides): the grids and the verdicts at rest are
    /// shared; the load tests along carries, which depend on the ball's
    /// acceleration, start afresh.
    pub fn with_limits(&self, limits: &crate::config::LimitsConfig) -> Self {
        let config = HandConfig {
            limits: *limits,
            ..self.config
        };
        Self {
            timing: DurationModel::new(&config),
            params: CheckParams {
                max_acceleration: limits.object.acceleration,
                ..self.params
            },
            carries: Arc::default(),
            config,
            ..self.clone()
        }
    }

    /// The hand.
    pub fn hand(&self) -> &ChainHand {
        &self.hand
    }

    /// The check's sampling and load settings.
    pub fn check_params(&self) -> &CheckParams {
        &self.params
    }

    /// The settings it plans with.
    pub fn config(&self) -> &HandConfig {
        &self.config
    }

    fn joints_at(&self, k: usize, n: &Vector3<f64>) -> Option<Vector3<f64>> {
        self.hand.joints(k, &(n * self.contact_radius(k)), None)
    }

    fn contact_radius(&self, k: usize) -> f64 {
        self.hand.object().radius + self.hand.chain(k).tip_radius
    }

    /// Whether fingers `a` and `b` at those contacts keep the finger gap
    /// ([`HandModel::apart`], computed).
    fn apart_now(&self, (a, na): At<'_>, (b, nb): At<'_>) -> bool {
        let (Some(qa), Some(qb)) = (self.joints_at(a, na), self.joints_at(b, nb)) else {
            return false;
        };
        let (sa, sb) = (
            self.hand.chain(a).forward(&qa),
            self.hand.chain(b).forward(&qb),
        );
        let gap = if a < b {
            self.hand
                .gap(a, b)
                .gap((self.hand.chain(a), &sa), (self.hand.chain(b), &sb))
        } else {
            self.hand
                .gap(b, a)
                .gap((self.hand.chain(b), &sb), (self.hand.chain(a), &sa))
        };
        gap >= self.hand.limits().finger_gap
    }

    /// The torque box's verdict on a state's grasp (turning about `axis`).
    fn holds(&self, state: &HandState, axis: Option<&Vector3<f64>>) -> bool {
        let joints = std::array::from_fn(|k| {
            self.hand
                .joints(k, &state.fingers[k].center, None)
                .filter(|_| state.fingers[k].mode == FingerMode::Grasping)
        });
        closed_form_share(&self.hand, state, &joints, axis, &self.params).is_some_and(|s| s <= 1.0)
            || grasp_share(&self.hand, state, &joints, axis, &self.params) <= 1.0
    }

    /// A state with finger `a` at `na` and `b` at `nb` grasping, the third
    /// free.
    fn pair_state(&self, (a, na): At<'_>, (b, nb): At<'_>) -> HandState {
        let mut s = HandState::paper_start(&self.config);
        for f in &mut s.fingers {
            f.mode = FingerMode::Free;
        }
        for (k, n) in [(a, na), (b, nb)] {
            s.fingers[k].mode = FingerMode::Grasping;
            s.fingers[k].center = n * self.contact_radius(k);
        }
        s
    }
}

impl Grids {
    fn new(hand: &ChainHand, geom: &Geometry) -> Self {
        let grid = kinematics::sphere_grid(GRID);
        let mut points: [Vec<Vector3<f64>>; FINGERS] = Default::default();
        let mut joints: [Vec<Vector3<f64>>; FINGERS] = Default::default();
        for k in 0..FINGERS {
            for n in &grid {
                if let Some(r) = hand.reach(k, n) {
                    points[k].push(*n);
                    joints[k].push(r.q);
                }
            }
        }
        let mut partners: [[Vec<Vec<u16>>; FINGERS]; FINGERS] = Default::default();
        for a in 0..FINGERS {
            for b in 0..FINGERS {
                if a == b {
                    continue;
                }
                partners[a][b] = points[a]
                    .iter()
                    .zip(&joints[a])
                    .map(|(na, qa)| {
                        let sa = hand.chain(a).forward(qa);
                        (0..points[b].len())
                            .filter(|&j| {
                                let sb = hand.chain(b).forward(&joints[b][j]);
                                let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                                let (slo, shi) = if a < b { (&sa, &sb) } else { (&sb, &sa) };
                                geom.is_good_pair(na, &points[b][j])
                                    && hand
                                        .gap(lo, hi)
                                        .gap((hand.chain(lo), slo), (hand.chain(hi), shi))
                                        >= hand.limits().finger_gap
                            })
                            .map(|j| j as u16)
                            .collect()
                    })
                    .collect();
            }
        }
        Self { points, partners }
    }
}

impl HandModel for ChainModel {
    type Touch = ();
    type Regrasp = NoRegrasp;
    type Violation = ChainViolation;

    fn timing(&self) -> &DurationModel {
        &self.timing
    }

    fn candidates(&self, k: usize) -> &[Vector3<f64>] {
        &self.grids.points[k]
    }

    fn partners(&self, a: usize, b: usize, i: usize) -> &[u16] {
        &self.grids.partners[a][b][i]
    }

    fn good_pair(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
        self.geom.is_good_pair(a, b)
    }

    fn apart(&self, (a, na): At<'_>, (b, nb): At<'_>) -> bool {
        if a == b {
            return false;
        }
        let bits = |n: &Vector3<f64>| [n.x.to_bits(), n.y.to_bits(), n.z.to_bits()];
        let key = (a, b, bits(na), bits(nb));
        if let Some(&v) = self.apart_memo.lock().expect("not poisoned").get(&key) {
            return v;
        }
        let v = self.apart_now((a, na), (b, nb));
        let mut memo = self.apart_memo.lock().expect("not poisoned");
        // Bounded: carried contacts are continuous, so a long-lived planner
        // would otherwise keep every pair it was ever asked about.
        if memo.len() >= APART_MEMO {
            memo.clear();
        }
        memo.insert(key, v);
        v
    }

    fn fc_triple(&self, c: &[Vector3<f64>; 3]) -> bool {
        fact4(&self.geom, &c[0], &c[1], &c[2])
    }

    fn pairs_turn(&self) -> bool {
        false
    }

    fn offers_regrasps(&self) -> bool {
        false
    }

    fn carry_range(
        &self,
        hand: &HandState,
        fingers: &[usize],
        axis: &Vector3<f64>,
        limit: f64,
    ) -> f64 {
        if fingers.len() != FINGERS {
            return 0.0;
        }
        let mut q = [Vector3::zeros(); FINGERS];
        for (slot, &k) in q.iter_mut().zip(fingers) {
            match self.hand.joints(k, &hand.fingers[k].center, None) {
                Some(j) => *slot = j,
                None => return 0.0,
            }
        }
        let chains = [
            self.hand.chain(fingers[0]),
            self.hand.chain(fingers[1]),
            self.hand.chain(fingers[2]),
        ];
        let limits = self.hand.limits();
        let r = kinematics::carry_range(
            &chains,
            &q,
            self.hand.object(),
            axis,
            limit.min(RANGE_LIMIT),
            limits,
            RANGE_STEP,
        );
        r.angle
    }

    fn carry(&self, hand: &mut HandState, axis: &Vector3<f64>, angle: f64) {
        match carried(&self.hand, hand, axis, angle) {
            Some(s) => *hand = s,
            // A finger that cannot follow: the object turns, the contacts
            // stay (the range the search asked first rules this out).
            None => hand.object = rotation(axis, angle) * hand.object,
        }
    }

    // A finger's contact follows the object by its own chain alone (the
    // rolling law is per finger): its range on its own limits bounds every
    // grasp it is part of (the gaps between fingers aside).
    fn touch_for(&self, k: usize, contact: &Vector3<f64>, axis: &Vector3<f64>) -> ((), f64) {
        let Some(q) = self.joints_at(k, contact) else {
            return ((), 0.0);
        };
        let r = kinematics::carry_range_with(
            &[self.hand.chain(k)],
            &[q],
            self.hand.object(),
            axis,
            TOUCH_LIMIT,
            self.hand.limits(),
            kinematics::Scan {
                step: TOUCH_STEP,
                bisections: TOUCH_BISECTIONS,
            },
        );
        ((), r.angle)
    }

    fn place(&self, hand: &mut HandState, k: usize, contact: &Vector3<f64>, _touch: ()) {
        let f = &mut hand.fingers[k];
        f.mode = FingerMode::Grasping;
        f.center = contact * self.contact_radius(k);
    }

    fn lift(&self, hand: &mut HandState, k: usize) {
        let rho = self.contact_radius(k) + self.config.planner.transfer_height;
        let f = &mut hand.fingers[k];
        f.mode = FingerMode::Free;
        f.center = f.center.normalize() * rho;
    }

    // The lift checked as the plan's check samples it (its links can
    // sweep into a neighbour's as it rises).
    fn can_lift(&self, hand: &HandState, k: usize) -> bool {
        let mut b = ChainBuilder::new(
            &self.hand,
            self.config.limits,
            0.0,
            self.config.planner.transfer_height,
            self.params,
            *hand,
        );
        let mut joints = b.joints();
        b.lift(k).is_ok() && check_way(&self.hand, &b.steps, &mut joints, &self.params).is_ok()
    }

    fn hover_dir(&self, hand: &HandState, k: usize) -> Vector3<f64> {
        hand.fingers[k].center.normalize()
    }

    // A chain finger's state beyond its contact is its joints, which its
    // tip centre decides.
    fn key(&self, _hand: &HandState, _k: usize, _axis: &Vector3<f64>) -> [i64; 2] {
        [0, 0]
    }

    fn load_active(&self) -> bool {
        self.hand.object().mass * self.hand.gravity().norm() > 0.0
    }

    fn weight_direction(&self) -> Vector3<f64> {
        self.hand
            .gravity()
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
        let bits = [cx.x.to_bits(), cx.y.to_bits(), cx.z.to_bits()];
        for (i, c) in self.grids.points[z].iter().enumerate() {
            if !self.geom.is_good_pair(c, cx) {
                continue;
            }
            let key = (x, bits, z, i);
            let known = self
                .resting
                .lock()
                .map(|m| m.get(&key).copied())
                .ok()
                .flatten();
            let held = known.unwrap_or_else(|| {
                let h = self.pair_holds((x, cx), (z, c), None);
                if let Ok(mut m) = self.resting.lock() {
                    // Bounded: kept across searches, forgotten when full.
                    if m.len() >= RESTING_MEMO {
                        m.clear();
                    }
                    m.insert(key, h);
                }
                h
            });
            if held && !f(i, true) {
                return;
            }
        }
    }

    fn pair_holds(&self, a: At<'_>, b: At<'_>, axis: Option<&Vector3<f64>>) -> bool {
        // A pair does not turn (module docs).
        axis.is_none() && self.holds(&self.pair_state(a, b), None)
    }

    fn pair_hold_range(&self, _a: At<'_>, _b: At<'_>, _axis: &Vector3<f64>, _limit: f64) -> f64 {
        0.0
    }

    fn holds_at_rest(&self, hand: &HandState) -> bool {
        !self.load_active() || self.holds(hand, None)
    }

    fn holds_along(&self, hand: &HandState, axis: &Vector3<f64>, angle: f64) -> bool {
        self.carries
            .holds_along(&self.hand, hand, axis, angle, LOAD_STEP, &mut |s| {
                self.holds(s, Some(axis))
            })
    }

    fn regrasps(
        &self,
        _hand: &HandState,
        _why: RegraspFor,
        _stop: &mut dyn Stop,
    ) -> Vec<Offer<NoRegrasp>> {
        Vec::new()
    }

    fn regrasp_name(&self, r: &NoRegrasp) -> &'static str {
        match *r {}
    }

    // (Never asked: the hand offers no regrasp.)
    fn regrasp_bound(&self, _hand: &HandState, _why: RegraspFor) -> f64 {
        0.0
    }

    fn build(&self, start: &HandState, actions: &[Action<Self>]) -> Result<Vec<Step>, usize> {
        let mut b = ChainBuilder::new(
            &self.hand,
            self.config.limits,
            self.config.load.handover_time,
            self.config.planner.transfer_height,
            self.params,
            *start,
        );
        for a in actions {
            match a {
                Action::Rotate { axis, angle, .. } => b.rotate(axis, *angle)?,
                Action::Place {
                    finger, contact, ..
                } => b.place(*finger, contact)?,
                Action::Lift { finger } => b.lift(*finger)?,
                Action::Regrasp { regrasp, .. } => match *regrasp {},
            }
        }
        Ok(b.steps)
    }

    fn check(&self, start: &HandState, steps: &[Step]) -> Result<(), ChainViolation> {
        check(&self.hand, start, steps, &self.params).map(|_| ())
    }
}
