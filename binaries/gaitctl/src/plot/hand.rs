//! A chain hand's trace drawn in the hand frame (the description's):
//! the ball at its centre, each finger's links — their capsules, as wide
//! as they are — where the trace starts (faint) and where it ends, and
//! each tip's path between. The links come from the trace's joints through
//! the description's forward kinematics.

use std::fmt::Write as _;
use std::path::Path;

use kinematics::{Chain, HandDescription};
use nalgebra::Vector3;
use trace_mcap::file::{Trace, TraceSample};

use super::{COLORS, View};

/// The hand a trace names, ready to draw.
pub struct HandDrawing {
    chains: Vec<Chain<3>>,
    /// The object's centre O in the hand frame \[m\].
    centre: Vector3<f64>,
    radius: f64,
}

impl HandDrawing {
    /// The chain hand `t`'s header names (`hand_description`), if it names
    /// one: the drawing, or why its description cannot be read.
    pub fn of(t: &Trace) -> Option<Result<Self, String>> {
        let path = t.hand_description.as_deref()?;
        let load = || -> Result<Self, String> {
            let d = HandDescription::load(Path::new(path), |p| std::fs::read_to_string(p))
                .map_err(|e| e.to_string())?;
            let chains = d
                .fingers
                .iter()
                .map(|f| Chain::<3>::from_description(f, d.joint_limit_margin))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| format!("{path}: {e}"))?;
            if chains.len() != 3 {
                return Err(format!("{path}: {} fingers, a trace has 3", chains.len()));
            }
            Ok(Self {
                chains,
                centre: d.object.centre,
                radius: d.object.radius,
            })
        };
        Some(load())
    }

    /// The panel: a view of the hand frame from `toward` centred at
    /// (`cx`, `cy`), `scale` pixels per metre.
    pub fn panel(
        &self,
        svg: &mut String,
        t: &Trace,
        toward: Vector3<f64>,
        (cx, cy): (f64, f64),
        scale: f64,
    ) {
        // Centred a little above the ball, below the fingers' bases.
        let look_at = self.centre + Vector3::z() * 0.05;
        let v = View::new(toward, Vector3::z(), cx, cy, scale);
        let at = |p: &Vector3<f64>| {
            let (x, y, _) = v.project(&(p - look_at));
            (x, y)
        };
        let (ox, oy) = at(&self.centre);
        let _ = write!(
            svg,
            r##"<circle cx="{ox:.1}" cy="{oy:.1}" r="{:.1}" fill="#f0e68c" fill-opacity="0.6" stroke="#555" stroke-width="1"/>"##,
            self.radius * scale
        );
        let _ = write!(
            svg,
            r#"<text x="{cx}" y="{}" font-size="15" text-anchor="middle" font-family="sans-serif">the hand: links at the start (faint) and the end</text>"#,
            cy - 178.0
        );
        let first = &t.samples[0];
        let last = &t.samples[t.samples.len() - 1];
        self.links(svg, first, &at, scale, 0.2);
        let step = (t.samples.len() / 2000).max(1);
        for (k, color) in COLORS.iter().enumerate() {
            let d: String = t
                .samples
                .iter()
                .step_by(step)
                .enumerate()
                .map(|(i, s)| {
                    let (x, y) = at(&(s.fingers[k].p + self.centre));
                    format!("{}{x:.1},{y:.1}", if i == 0 { "M" } else { "L" })
                })
                .collect();
            let _ = write!(
                svg,
                r#"<path d="{d}" fill="none" stroke="{color}" stroke-width="1" stroke-opacity="0.7"/>"#
            );
        }
        self.links(svg, last, &at, scale, 0.75);
    }

    /// Every finger's link capsules and tip at sample `s`'s joints.
    fn links(
        &self,
        svg: &mut String,
        s: &TraceSample,
        at: &impl Fn(&Vector3<f64>) -> (f64, f64),
        scale: f64,
        opacity: f64,
    ) {
        for (k, (chain, color)) in self.chains.iter().zip(COLORS).enumerate() {
            let Some(q) = s.fingers[k].joints else {
                continue;
            };
            let state = chain.forward(&Vector3::from(q));
            for c in chain.capsules(&state).as_slice() {
                let ((x1, y1), (x2, y2)) = (at(&c.a), at(&c.b));
                let _ = write!(
                    svg,
                    r#"<line class="link" x1="{x1:.1}" y1="{y1:.1}" x2="{x2:.1}" y2="{y2:.1}" stroke="{color}" stroke-width="{:.1}" stroke-linecap="round" stroke-opacity="{opacity}"/>"#,
                    // Thinner than the capsule: the ball stays visible.
                    (c.radius * scale).max(1.0)
                );
            }
            let (x, y) = at(&state.tip_centre());
            let _ = write!(
                svg,
                r#"<circle class="tip" cx="{x:.1}" cy="{y:.1}" r="{:.1}" fill="{color}" fill-opacity="{opacity}"/>"#,
                chain.tip_radius * scale
            );
        }
    }
}
