//! `gaitctl plot TRACE -o FILE.svg|.png` (TRACE: JSON lines or MCAP): the
//! contact paths on the sphere in the style of the paper's Fig. 3/4 (hand
//! frame from above and from the side, and on the object itself), and over
//! time the object's rotation angle, the force-closure margin and each
//! finger's state. A chain hand's trace (its header names the description)
//! shows the hand itself in place of the view from above ([`hand`]).

mod hand;

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use nalgebra::{UnitQuaternion, Vector3};

use trace_mcap::file::{self as tracefile, Trace};

/// Arguments of `gaitctl plot`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The trace (gait-trajectory/1): JSON lines, or their MCAP recording
    /// (`gaitctl trace mcap`), told apart by the file's first bytes.
    trace: PathBuf,
    /// Output picture: .svg or .png.
    #[arg(long, short = 'o', value_name = "FILE")]
    out: PathBuf,
}

const COLORS: [&str; 3] = ["#d62728", "#1f77b4", "#2ca02c"];
const W: f64 = 1200.0;
const H: f64 = 860.0;

/// An orthographic camera looking at the sphere.
struct View {
    right: Vector3<f64>,
    up: Vector3<f64>,
    toward: Vector3<f64>,
    cx: f64,
    cy: f64,
    scale: f64,
}

impl View {
    fn new(toward: Vector3<f64>, up_hint: Vector3<f64>, cx: f64, cy: f64, scale: f64) -> Self {
        let toward = toward.normalize();
        let right = up_hint.cross(&toward).normalize();
        let up = toward.cross(&right);
        Self {
            right,
            up,
            toward,
            cx,
            cy,
            scale,
        }
    }
    /// Screen point and whether it faces the camera.
    fn project(&self, p: &Vector3<f64>) -> (f64, f64, bool) {
        (
            self.cx + self.scale * p.dot(&self.right),
            self.cy - self.scale * p.dot(&self.up),
            p.dot(&self.toward) >= 0.0,
        )
    }
}

/// Polyline segments of a path of unit vectors, split where visibility
/// changes; front segments solid, back ones faint.
fn sphere_path(
    svg: &mut String,
    v: &View,
    pts: &[Vector3<f64>],
    color: &str,
    width: f64,
    dash: &str,
) {
    let mut cur: Vec<(f64, f64)> = Vec::new();
    let mut front = true;
    let flush = |svg: &mut String, cur: &mut Vec<(f64, f64)>, front: bool| {
        if cur.len() >= 2 {
            let d: String = cur
                .iter()
                .enumerate()
                .map(|(i, (x, y))| format!("{}{x:.1},{y:.1}", if i == 0 { "M" } else { "L" }))
                .collect();
            let _ = write!(
                svg,
                r#"<path d="{d}" fill="none" stroke="{color}" stroke-width="{width}" stroke-opacity="{}" stroke-dasharray="{dash}"/>"#,
                if front { 1.0 } else { 0.25 }
            );
        }
        cur.clear();
    };
    for p in pts {
        let (x, y, f) = v.project(p);
        if f != front && !cur.is_empty() {
            cur.push((x, y));
            flush(svg, &mut cur, front);
        }
        front = f;
        cur.push((x, y));
    }
    flush(svg, &mut cur, front);
}

/// A circle on the unit sphere: axis `a`, angular radius `r`.
fn circle(a: &Vector3<f64>, r: f64) -> Vec<Vector3<f64>> {
    let e = if a.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let b = a.cross(&e).normalize();
    let start = UnitQuaternion::from_scaled_axis(b * r) * a;
    (0..=96)
        .map(|i| {
            UnitQuaternion::from_scaled_axis(a * (i as f64 / 96.0 * std::f64::consts::TAU)) * start
        })
        .collect()
}

fn sphere_panel(svg: &mut String, t: &Trace, v: &View, title: &str, object_frame: bool) {
    let r = v.scale;
    let _ = write!(
        svg,
        r##"<circle cx="{}" cy="{}" r="{r}" fill="#f7f7f7" stroke="#555" stroke-width="1"/>"##,
        v.cx, v.cy
    );
    let _ = write!(
        svg,
        r#"<text x="{}" y="{}" font-size="15" text-anchor="middle" font-family="sans-serif">{title}</text>"#,
        v.cx,
        v.cy - r - 14.0
    );
    // Grid: equator and meridians every 30°, latitude circles every 30°.
    for lat in [-60.0f64, -30.0, 0.0, 30.0, 60.0] {
        sphere_path(
            svg,
            v,
            &circle(&Vector3::z(), (90.0 - lat).to_radians()),
            "#bbb",
            0.6,
            "",
        );
    }
    for lon in (0..6).map(|i| i as f64 * 30.0) {
        let a = UnitQuaternion::from_scaled_axis(Vector3::z() * lon.to_radians()) * Vector3::y();
        sphere_path(
            svg,
            v,
            &circle(&a, std::f64::consts::FRAC_PI_2),
            "#bbb",
            0.6,
            "",
        );
    }
    if !object_frame {
        // Workspace cones W_k (paper §4 (a)).
        for (k, az) in t.finger_azimuth_deg.iter().enumerate() {
            let a = az.to_radians();
            let d = Vector3::new(a.cos(), a.sin(), 0.0);
            sphere_path(
                svg,
                v,
                &circle(&d, t.workspace_half_angle_deg.to_radians()),
                COLORS[k],
                1.0,
                "5,4",
            );
        }
    }
    // Contact paths while touching (hand frame, or on the object).
    let step = (t.samples.len() / 4000).max(1);
    for (k, color) in COLORS.iter().enumerate() {
        let mut seg: Vec<Vector3<f64>> = Vec::new();
        let mut touches: Vec<Vector3<f64>> = Vec::new();
        let mut was = false;
        for (i, s) in t.samples.iter().enumerate() {
            let f = &s.fingers[k];
            let n = f.p.normalize();
            let n = if object_frame {
                s.object.inverse() * n
            } else {
                n
            };
            if f.contact {
                if !was {
                    touches.push(n);
                }
                if i % step == 0 || !was {
                    seg.push(n);
                }
            } else if was {
                sphere_path(svg, v, &seg, color, 2.4, "");
                seg.clear();
            }
            was = f.contact;
        }
        sphere_path(svg, v, &seg, color, 2.4, "");
        for n in touches {
            let (x, y, front) = v.project(&n);
            let _ = write!(
                svg,
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="3.5" fill="{}" fill-opacity="{}"/>"#,
                color,
                if front { 1.0 } else { 0.3 }
            );
        }
    }
}

/// A time-series panel with its own y range.
#[allow(clippy::too_many_arguments)]
fn series(
    svg: &mut String,
    x0: f64,
    y0: f64,
    w: f64,
    h: f64,
    t_end: f64,
    title: &str,
    lines: &[(&str, Vec<(f64, f64)>)],
) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, pts) in lines {
        for &(_, y) in pts {
            if y.is_finite() {
                lo = lo.min(y);
                hi = hi.max(y);
            }
        }
    }
    if !lo.is_finite() {
        lo = 0.0;
        hi = 1.0;
    }
    if hi - lo < 1e-9 {
        hi = lo + 1.0;
    }
    let _ = write!(
        svg,
        r##"<rect x="{x0}" y="{y0}" width="{w}" height="{h}" fill="none" stroke="#999"/><text x="{}" y="{}" font-size="13" font-family="sans-serif">{title}  [{lo:.3} … {hi:.3}]</text>"##,
        x0 + 4.0,
        y0 + 15.0
    );
    for (color, pts) in lines {
        let mut d = String::new();
        for (i, &(t, y)) in pts.iter().enumerate() {
            if !y.is_finite() {
                continue;
            }
            let px = x0 + w * t / t_end.max(1e-9);
            let py = y0 + h - 4.0 - (h - 24.0) * (y - lo) / (hi - lo);
            let _ = write!(
                d,
                "{}{px:.1},{py:.1}",
                if i == 0 || d.is_empty() { "M" } else { "L" }
            );
        }
        let _ = write!(
            svg,
            r#"<path d="{d}" fill="none" stroke="{color}" stroke-width="1.4"/>"#
        );
    }
}

/// Renders the trace as SVG text (a chain hand's links drawn with
/// `hand`).
pub fn render(t: &Trace, hand: Option<&hand::HandDrawing>) -> String {
    let mut svg = String::with_capacity(1 << 20);
    let _ = write!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}"><rect width="{W}" height="{H}" fill="white"/>"#
    );
    let r = 150.0;
    let oblique = Vector3::new(0.9, -0.6, 0.55);
    match hand {
        // About 0.4 m across the panel: the fingers' bases and the ball.
        Some(h) => h.panel(&mut svg, t, oblique, (200.0, 210.0), 800.0),
        None => sphere_panel(
            &mut svg,
            t,
            &View::new(Vector3::z(), Vector3::y(), 200.0, 210.0, r),
            "contacts, hand frame, from above",
            false,
        ),
    }
    sphere_panel(
        &mut svg,
        t,
        &View::new(oblique, Vector3::z(), 600.0, 210.0, r),
        "contacts, hand frame, oblique",
        false,
    );
    sphere_panel(
        &mut svg,
        t,
        &View::new(oblique, Vector3::z(), 1000.0, 210.0, r),
        "contacts on the object (object frame)",
        true,
    );
    let t0 = t.samples[0].t;
    let t_end = t.samples[t.samples.len() - 1].t - t0;
    let step = (t.samples.len() / 3000).max(1);
    let q0 = t.samples[0].object;
    // Rotation angle from the start, unwrapped along the way.
    let mut angle = Vec::new();
    let mut total = 0.0;
    let mut prev = q0;
    for (i, s) in t.samples.iter().enumerate() {
        total += prev.angle_to(&s.object);
        prev = s.object;
        if i % step == 0 {
            angle.push((s.t - t0, total.to_degrees()));
        }
    }
    let margin: Vec<(f64, f64)> = t
        .samples
        .iter()
        .step_by(step)
        .map(|s| (s.t - t0, s.fc_margin.unwrap_or(f64::NAN)))
        .collect();
    let (x0, w) = (60.0, 1100.0);
    series(
        &mut svg,
        x0,
        400.0,
        w,
        130.0,
        t_end,
        "object rotation travelled [deg]",
        &[("#333", angle)],
    );
    series(
        &mut svg,
        x0,
        545.0,
        w,
        110.0,
        t_end,
        "force-closure margin",
        &[("#9467bd", margin)],
    );
    // Finger states: a band per finger, coloured while touching.
    let y = 670.0;
    let _ = write!(
        svg,
        r#"<text x="{}" y="{}" font-size="13" font-family="sans-serif">finger states (filled: touching the object)</text>"#,
        x0 + 4.0,
        y + 2.0
    );
    for (k, color) in COLORS.iter().enumerate() {
        let yk = y + 12.0 + k as f64 * 26.0;
        let _ = write!(
            svg,
            r#"<text x="{}" y="{}" font-size="12" font-family="sans-serif">f{}</text>"#,
            x0 - 30.0,
            yk + 15.0,
            k + 1
        );
        let mut start: Option<f64> = None;
        let close = |svg: &mut String, a: f64, b: f64| {
            let _ = write!(
                svg,
                r#"<rect x="{:.1}" y="{yk}" width="{:.1}" height="20" fill="{}"/>"#,
                x0 + w * a / t_end.max(1e-9),
                (w * (b - a) / t_end.max(1e-9)).max(0.5),
                color
            );
        };
        for s in &t.samples {
            let touching = s.fingers[k].contact;
            match (touching, start) {
                (true, None) => start = Some(s.t - t0),
                (false, Some(a)) => {
                    close(&mut svg, a, s.t - t0);
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(a) = start {
            close(&mut svg, a, t_end);
        }
        let _ = write!(
            svg,
            r##"<rect x="{x0}" y="{yk}" width="{w}" height="20" fill="none" stroke="#999"/>"##
        );
    }
    let _ = write!(
        svg,
        r#"<text x="{}" y="{}" font-size="12" font-family="sans-serif" text-anchor="end">R = {} m, r = {} m; t = {t_end:.2} s</text></svg>"#,
        x0 + w,
        H - 14.0,
        t.object_radius,
        t.fingertip_radius
    );
    svg
}

/// Runs `gaitctl plot`.
pub fn run(a: &Args) -> Result<ExitCode, String> {
    let t = tracefile::read(&a.trace)?;
    let hand = match hand::HandDrawing::of(&t) {
        Some(Ok(h)) => Some(h),
        Some(Err(e)) => {
            eprintln!("gaitctl plot: the trace's hand description: {e}: drawn without its links");
            None
        }
        None => None,
    };
    let svg = render(&t, hand.as_ref());
    let ext = a
        .out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("svg") => {
            std::fs::write(&a.out, svg).map_err(|e| format!("{}: {e}", a.out.display()))?
        }
        Some("png") => {
            let mut opt = resvg::usvg::Options::default();
            let db = opt.fontdb_mut();
            db.load_system_fonts();
            // "sans-serif" maps to Arial by default; use a font that is there.
            let family = db
                .faces()
                .find(|f| f.families.iter().any(|(n, _)| n == "DejaVu Sans"))
                .or_else(|| db.faces().next())
                .and_then(|f| f.families.first().map(|(n, _)| n.clone()));
            match family {
                Some(name) => db.set_sans_serif_family(name),
                None => {
                    eprintln!("gaitctl plot: no fonts found: the PNG has no text (try the .svg)")
                }
            }
            let tree = resvg::usvg::Tree::from_str(&svg, &opt).map_err(|e| e.to_string())?;
            let size = tree.size().to_int_size();
            let mut pixmap = resvg::tiny_skia::Pixmap::new(size.width(), size.height())
                .ok_or("cannot allocate the picture")?;
            resvg::render(
                &tree,
                resvg::tiny_skia::Transform::default(),
                &mut pixmap.as_mut(),
            );
            pixmap
                .save_png(&a.out)
                .map_err(|e| format!("{}: {e}", a.out.display()))?;
        }
        _ => {
            return Err(format!(
                "{}: the picture must end in .svg or .png",
                a.out.display()
            ));
        }
    }
    println!(
        "{} samples, {:.2} s → {}",
        t.samples.len(),
        t.samples[t.samples.len() - 1].t - t.samples[0].t,
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
