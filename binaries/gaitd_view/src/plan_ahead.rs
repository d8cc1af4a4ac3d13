//! The live view's path ahead: from the daemon's latest plan path (the
//! `plan` service), the part the hand has still to go in the next
//! [`AHEAD`] seconds, while the status says that plan's goal is executing.
//! How far along it the hand is comes from the status: the plan's
//! duration minus the goal's ETA.

use crate::replay::AHEAD;
use crate::scene::rotation_columns;
use gaitd_client::{GoalState, PlanPath, Status};

/// Fingertip centres and the object's body axes' tips along the path
/// ahead (hand frame), per finger and per axis.
pub type Ahead = ([Vec<[f64; 3]>; 3], [Vec<[f64; 3]>; 3]);

/// The path ahead of `status` on `path` (axes' tips `axis_length` from the
/// centre), or None when the status is not executing that plan's goal.
pub fn ahead(path: &PlanPath, status: &Status, axis_length: f64) -> Option<Ahead> {
    let g = &status.goal;
    let same_goal = path.instance == status.instance
        && path.goal_id == g.goal_id
        && path.client_id == g.client_id;
    if !same_goal || g.state != GoalState::Executing.code() || g.eta < 0.0 {
        return None;
    }
    let points = path.checked().ok()?;
    let now = (path.duration - g.eta).max(0.0);
    let window: Vec<_> = points
        .iter()
        .filter(|p| p.t >= now && p.t <= now + AHEAD)
        .collect();
    let tips = core::array::from_fn(|k| window.iter().map(|p| p.tip_position[k]).collect());
    let axes = core::array::from_fn(|a| {
        window
            .iter()
            .map(|p| rotation_columns(&p.object_q)[a].map(|x| x * axis_length))
            .collect()
    });
    Some((tips, axes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 10 s path of 101 points, one every 0.1 s, fingertip 0 at x = t.
    fn path() -> PlanPath {
        let mut p = PlanPath {
            instance: 9,
            goal_id: 4,
            client_id: 7,
            sequence: 1,
            duration: 10.0,
            count: 101,
            ..PlanPath::default()
        };
        for i in 0..101 {
            let t = i as f64 * 0.1;
            p.points[i].t = t;
            p.points[i].object_q = [1.0, 0.0, 0.0, 0.0];
            p.points[i].tip_position[0] = [t, 0.0, 0.0];
        }
        p
    }

    fn status(eta: f64) -> Status {
        let mut s = Status {
            instance: 9,
            ..Status::default()
        };
        s.goal.goal_id = 4;
        s.goal.client_id = 7;
        s.goal.state = GoalState::Executing.code();
        s.goal.eta = eta;
        s
    }

    #[test]
    fn the_path_ahead_starts_where_the_eta_says_the_hand_is() {
        // 6.5 s left of 10: the hand is 3.5 s along; 3 s ahead of it.
        let (tips, axes) = ahead(&path(), &status(6.5), 2.0).expect("executing");
        let xs: Vec<f64> = tips[0].iter().map(|p| p[0]).collect();
        assert!((xs[0] - 3.5).abs() < 1e-9, "{xs:?}");
        assert!((xs[xs.len() - 1] - 6.5).abs() < 1e-9, "{xs:?}");
        assert_eq!(xs.len(), 31);
        assert_eq!(axes[0][0], [2.0, 0.0, 0.0], "the x axis' tip");
        // Near the end only what is left.
        let (tips, _) = ahead(&path(), &status(1.0), 2.0).unwrap();
        assert_eq!(tips[0].len(), 11);
    }

    #[test]
    fn no_path_ahead_for_another_goal_or_when_not_executing() {
        let p = path();
        let mut s = status(5.0);
        s.goal.goal_id = 5;
        assert!(ahead(&p, &s, 1.0).is_none(), "another goal");
        let mut s = status(5.0);
        s.instance = 10;
        assert!(ahead(&p, &s, 1.0).is_none(), "another daemon");
        let mut s = status(5.0);
        s.goal.state = GoalState::Planning.code();
        assert!(ahead(&p, &s, 1.0).is_none(), "planning");
        let mut p = path();
        p.count = 0;
        assert!(ahead(&p, &status(5.0), 1.0).is_none(), "a bad path");
    }
}
