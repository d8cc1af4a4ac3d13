//! The hand in 3D, from one [`Frame`] (hand frame, metres; entity paths
//! under `world/`):
//!
//! - `world/object`: the object's orientation as the plant measures it
//!   (the commanded one until the plant reports it); under it the ball
//!   (orange), three great circles and its body axes (x red, y green, z
//!   blue), so that its rotation is visible, and each finger's contact path
//!   on it (object frame: the paths turn with the ball);
//! - `world/commanded_axes`: the commanded orientation's axes, thin;
//! - `world/tips/commanded` (solid) and `world/tips/measured` (wireframe):
//!   the fingertip spheres, one colour per finger;
//! - `world/contacts`: the contact points of the fingers that touch, with
//!   `world/cones`, their friction cones (outside the object, around the
//!   normal), and `world/forces/commanded`, `world/forces/measured`: the
//!   normal forces, pressing into the object (10 N as long as R).
//!
//! - `world/ahead/tips`, `world/ahead/axes` (replays only: a trace knows
//!   what comes next): the fingertips' paths and the paths of the object's
//!   axes' tips over the next seconds, thin.
//!
//! The ball's and fingertips' radii are read off the frame (the contact
//! lies on the object's surface, the tip centre r outside it), so the view
//! needs no configuration but the friction angle. Measured things are
//! drawn only where the frame has them (a trace has none).

use crate::frame::Frame;
use crate::series;
use gaitd_client::Event;
use gaitd_client::describe::event_line;
use rerun::{Color, RecordingStream};

/// One colour per finger (f1, f2, f3).
pub const FINGER_COLOURS: [[u8; 3]; 3] = [[66, 133, 244], [52, 168, 83], [171, 71, 188]];

/// The ball's colour.
pub const BALL_COLOUR: [u8; 3] = [255, 140, 0];

/// Points kept per contact path (the oldest are dropped).
const PATH_POINTS: usize = 2000;

/// A contact path gets a point where the contact has moved this far from
/// the last one, in object radii.
const PATH_STEP: f64 = 0.005;

/// The contact paths are sent every this many frames (a browser on a slow
/// machine falls behind if the whole paths come 30 times a second).
const PATH_EVERY: u64 = 15;

/// Sides of a friction cone's rim.
const CONE_SIDES: usize = 24;

/// The view's state between frames.
pub struct Scene {
    /// tan of the friction angle.
    mu: f64,
    /// Object and fingertip radii once seen \[m\].
    radii: Option<(f64, f64)>,
    /// Per finger, its contact path on the object (object frame).
    paths: [Vec<[f32; 3]>; 3],
    /// Frames drawn so far.
    frames: u64,
}

impl Scene {
    /// A view drawing friction cones of half-angle `friction` \[rad\].
    pub fn new(friction: f64) -> Self {
        Self {
            mu: friction.tan(),
            radii: None,
            paths: Default::default(),
            frames: 0,
        }
    }

    /// One event, as a line of the `events` log.
    pub fn event(&mut self, rec: &RecordingStream, e: &Event) {
        let level = match e.kind() {
            Ok(gaitd_client::EventKind::Fault) => "ERROR",
            Ok(gaitd_client::EventKind::Overrun | gaitd_client::EventKind::NearLimit) => "WARN",
            _ => "INFO",
        };
        note(rec, e.time_ns as f64 * 1e-9, &event_line(e), level);
    }

    /// One frame: the 3D scene and the time series.
    pub fn frame(&mut self, rec: &RecordingStream, s: &Frame) {
        rec.set_duration_secs(TIME, s.time);
        if let Some(tick) = s.tick {
            rec.set_time_sequence("tick", i64::try_from(tick).unwrap_or(i64::MAX));
        }
        if self.radii.is_none() {
            self.radii = s.radii();
            if let Some((big_r, _)) = self.radii {
                log_object_body(rec, big_r);
            }
        }
        let _ = rec.log(
            "world/object",
            &rerun::Transform3D::from_rotation(quaternion(&s.shown_object())),
        );
        let (big_r, r) = self.radii.unwrap_or((0.5, 0.1));
        let _ = rec.log(
            "world/commanded_axes",
            &axes(&s.object, 1.25 * big_r, 0.004 * big_r),
        );
        self.tips(rec, s, r);
        self.contacts(rec, s, big_r);
        if self.frames.is_multiple_of(PATH_EVERY) {
            self.log_paths(rec, big_r);
        }
        self.frames += 1;
        series::log(rec, s);
    }

    fn tips(&self, rec: &RecordingStream, s: &Frame, r: f64) {
        let colours: [Color; 3] = core::array::from_fn(finger_colour);
        let commanded = s.fingers.iter().map(|f| v32(&f.tip));
        let _ = rec.log(
            "world/tips/commanded",
            &rerun::Ellipsoids3D::from_centers_and_radii(commanded, [r as f32; 3])
                .with_colors(colours)
                .with_fill_mode(rerun::FillMode::Solid),
        );
        let measured: Option<Vec<[f32; 3]>> = s
            .fingers
            .iter()
            .map(|f| f.measured_tip.as_ref().map(v32))
            .collect();
        if let Some(at) = measured {
            let _ = rec.log(
                "world/tips/measured",
                &rerun::Ellipsoids3D::from_centers_and_radii(at, [1.02 * r as f32; 3])
                    .with_colors(colours)
                    .with_fill_mode(rerun::FillMode::MajorWireframe),
            );
        }
    }

    fn contacts(&mut self, rec: &RecordingStream, s: &Frame, big_r: f64) {
        // 10 N of normal force as long as the object's radius.
        let scale = 0.1 * big_r;
        let (mut points, mut colours, mut cones, mut cone_colours) =
            (vec![], vec![], vec![], vec![]);
        let (mut origins, mut pushes, mut measured_pushes) = (vec![], vec![], vec![]);
        for (k, f) in s.fingers.iter().enumerate() {
            if !f.touching {
                continue;
            }
            let c = f.contact_hand;
            let norm = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            if norm <= 0.0 {
                continue;
            }
            let n = [c[0] / norm, c[1] / norm, c[2] / norm];
            let colour = finger_colour(k);
            points.push(v32(&c));
            colours.push(colour);
            for strip in cone(&c, &n, 0.6 * big_r, self.mu) {
                cones.push(strip);
                cone_colours.push(colour);
            }
            origins.push(v32(&c));
            let push = |force: f64| v32(&n.map(|x| -x * force * scale));
            pushes.push(push(f.force));
            if let Some(m) = f.measured_force {
                measured_pushes.push(push(m));
            }
            let path = &mut self.paths[k];
            if path.len() >= PATH_POINTS {
                path.drain(..PATH_POINTS / 4);
            }
            let at = v32(&f.contact_object);
            let moved = path.last().is_none_or(|p| {
                let d: f32 = (0..3).map(|i| (p[i] - at[i]).powi(2)).sum();
                f64::from(d.sqrt()) > PATH_STEP * big_r
            });
            if moved {
                path.push(at);
            }
        }
        let _ = rec.log(
            "world/contacts",
            &rerun::Points3D::new(points)
                .with_colors(colours)
                .with_radii([0.02 * big_r as f32]),
        );
        let _ = rec.log(
            "world/cones",
            &rerun::LineStrips3D::new(cones)
                .with_colors(cone_colours)
                .with_radii([0.002 * big_r as f32]),
        );
        let _ = rec.log(
            "world/forces/commanded",
            &rerun::Arrows3D::from_vectors(pushes)
                .with_origins(origins.clone())
                .with_colors([Color::from_rgb(230, 30, 30)]),
        );
        // Forces are measured for every finger or for none (the status's
        // mask); logged whenever measured, so that none left clears them.
        if s.fingers.iter().any(|f| f.measured_force.is_some()) {
            let _ = rec.log(
                "world/forces/measured",
                &rerun::Arrows3D::from_vectors(measured_pushes)
                    .with_origins(origins)
                    .with_colors([Color::from_rgb(250, 220, 40)]),
            );
        }
    }

    /// Each finger's contact path on the object (object frame).
    fn log_paths(&self, rec: &RecordingStream, big_r: f64) {
        let strips: Vec<Vec<[f32; 3]>> =
            self.paths.iter().filter(|p| p.len() > 1).cloned().collect();
        let path_colours: Vec<Color> = (0..3)
            .filter(|&k| self.paths[k].len() > 1)
            .map(finger_colour)
            .collect();
        let _ = rec.log(
            "world/object/contact_paths",
            &rerun::LineStrips3D::new(strips)
                .with_colors(path_colours)
                .with_radii([0.004 * big_r as f32]),
        );
    }
}

/// The path ahead: each fingertip's centre and each of the object's body
/// axes' tips at the coming frames (hand frame), thin, in the finger's and
/// the axis' colours.
pub fn log_ahead(
    rec: &RecordingStream,
    tips: &[Vec<[f64; 3]>; 3],
    axes: &[Vec<[f64; 3]>; 3],
    big_r: f64,
) {
    let strips = |paths: &[Vec<[f64; 3]>; 3]| {
        paths
            .iter()
            .map(|p| p.iter().map(v32).collect::<Vec<_>>())
            .collect::<Vec<_>>()
    };
    let _ = rec.log(
        "world/ahead/tips",
        &rerun::LineStrips3D::new(strips(tips))
            .with_colors(core::array::from_fn::<_, 3, _>(finger_colour))
            .with_radii([0.003 * big_r as f32]),
    );
    let _ = rec.log(
        "world/ahead/axes",
        &rerun::LineStrips3D::new(strips(axes))
            .with_colors(AXIS_COLOURS.map(|[r, g, b]| Color::from_rgb(r, g, b)))
            .with_radii([0.003 * big_r as f32]),
    );
}

/// Finger `k`'s colour.
fn finger_colour(k: usize) -> Color {
    let [r, g, b] = FINGER_COLOURS[k];
    Color::from_rgb(r, g, b)
}

/// The timeline every frame and note is logged on: the daemon's clock, or
/// a trace's time.
pub const TIME: &str = "daemon_time";

/// A line of the `events` log at `time` \[s\].
pub fn note(rec: &RecordingStream, time: f64, text: &str, level: &str) {
    rec.set_duration_secs(TIME, time);
    let _ = rec.log("events", &rerun::TextLog::new(text).with_level(level));
}

/// The ball, its great circles and its axes (static, object frame).
fn log_object_body(rec: &RecordingStream, big_r: f64) {
    let ball = BALL_COLOUR;
    let _ = rec.log_static(
        "world/object/ball",
        &rerun::Ellipsoids3D::from_radii([big_r as f32])
            .with_colors([Color::from_rgb(ball[0], ball[1], ball[2])])
            .with_fill_mode(rerun::FillMode::Solid),
    );
    let _ = rec.log_static(
        "world/object/circles",
        &rerun::LineStrips3D::new((0..3).map(|axis| great_circle(axis, 1.01 * big_r, 72)))
            .with_colors([Color::from_rgb(60, 30, 0)])
            .with_radii([0.006 * big_r as f32]),
    );
    let _ = rec.log_static(
        "world/object/axes",
        &axes(&[1.0, 0.0, 0.0, 0.0], 1.4 * big_r, 0.012 * big_r),
    );
}

/// The circle of radius `radius` about the origin perpendicular to the
/// coordinate axis `axis` (0, 1, 2), closed, `sides` segments.
pub fn great_circle(axis: usize, radius: f64, sides: usize) -> Vec<[f32; 3]> {
    (0..=sides)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / sides as f64;
            let (s, c) = a.sin_cos();
            let mut p = [0.0; 3];
            p[(axis + 1) % 3] = radius * c;
            p[(axis + 2) % 3] = radius * s;
            v32(&p)
        })
        .collect()
}

/// A friction cone at contact `c` (unit outward normal `n`): its rim at
/// `height` along the normal, radius μ·height, and four generators.
pub fn cone(c: &[f64; 3], n: &[f64; 3], height: f64, mu: f64) -> Vec<Vec<[f32; 3]>> {
    let (u, w) = perpendiculars(n);
    let rim_at = |a: f64| {
        let (s, co) = a.sin_cos();
        let rho = mu * height;
        core::array::from_fn::<f64, 3, _>(|i| c[i] + height * n[i] + rho * (co * u[i] + s * w[i]))
    };
    let rim: Vec<[f32; 3]> = (0..=CONE_SIDES)
        .map(|i| {
            v32(&rim_at(
                std::f64::consts::TAU * i as f64 / CONE_SIDES as f64,
            ))
        })
        .collect();
    let mut strips = vec![rim];
    for i in 0..4 {
        let a = std::f64::consts::FRAC_PI_2 * i as f64;
        strips.push(vec![v32(c), v32(&rim_at(a))]);
    }
    strips
}

/// Two unit vectors completing unit `n` to an orthonormal frame.
fn perpendiculars(n: &[f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let d = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    let u = [a[0] - d * n[0], a[1] - d * n[1], a[2] - d * n[2]];
    let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let u = u.map(|x| x / l);
    let w = [
        n[1] * u[2] - n[2] * u[1],
        n[2] * u[0] - n[0] * u[2],
        n[0] * u[1] - n[1] * u[0],
    ];
    (u, w)
}

/// Body axes of orientation `q` [w, x, y, z]: x red, y green, z blue.
fn axes(q: &[f64; 4], length: f64, radius: f64) -> rerun::Arrows3D {
    let columns = rotation_columns(q);
    rerun::Arrows3D::from_vectors(columns.map(|c| v32(&c.map(|x| x * length))))
        .with_colors(AXIS_COLOURS.map(|[r, g, b]| Color::from_rgb(r, g, b)))
        .with_radii([radius as f32])
}

/// The body axes' colours: x red, y green, z blue.
const AXIS_COLOURS: [[u8; 3]; 3] = [[220, 40, 40], [40, 180, 40], [40, 90, 230]];

/// The columns of the rotation matrix of unit quaternion `q` [w, x, y, z].
pub fn rotation_columns(q: &[f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = *q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y + w * z),
            2.0 * (x * z - w * y),
        ],
        [
            2.0 * (x * y - w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z + w * x),
        ],
        [
            2.0 * (x * z + w * y),
            2.0 * (y * z - w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// Rerun's quaternion (x, y, z, w) from [w, x, y, z].
fn quaternion(q: &[f64; 4]) -> rerun::Quaternion {
    rerun::Quaternion::from_xyzw([q[1] as f32, q[2] as f32, q[3] as f32, q[0] as f32])
}

fn v32(p: &[f64; 3]) -> [f32; 3] {
    p.map(|x| x as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    #[test]
    fn a_quarter_turn_about_z_takes_x_to_y() {
        let h = std::f64::consts::FRAC_PI_4;
        let c = rotation_columns(&[h.cos(), 0.0, 0.0, h.sin()]);
        for (got, want) in c
            .iter()
            .zip([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
        {
            for i in 0..3 {
                assert!((got[i] - want[i]).abs() < 1e-12, "{c:?}");
            }
        }
    }

    #[test]
    fn a_cone_opens_by_the_friction_angle_around_the_normal() {
        let n = [0.0, 0.6, 0.8];
        let c = n.map(|x| 0.5 * x);
        let mu = 20f64.to_radians().tan();
        let strips = cone(&c, &n, 0.3, mu);
        assert_eq!(strips.len(), 5);
        for p in &strips[0] {
            let d = [p[0] as f64 - c[0], p[1] as f64 - c[1], p[2] as f64 - c[2]];
            let along = dot(&d, &n);
            let across = (dot(&d, &d) - along * along).sqrt();
            assert!((along - 0.3).abs() < 1e-6, "{along}");
            assert!((across.atan2(along) - 20f64.to_radians()).abs() < 1e-5);
        }
    }

    #[test]
    fn great_circles_lie_on_the_sphere_across_their_axis() {
        for axis in 0..3 {
            for p in great_circle(axis, 0.5, 36) {
                let r = (p.iter().map(|x| (*x as f64).powi(2)).sum::<f64>()).sqrt();
                assert!((r - 0.5).abs() < 1e-6);
                assert_eq!(p[axis], 0.0);
            }
        }
    }
}
