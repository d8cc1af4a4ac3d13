//! ProgressView as a terminal wants it, or as a log wants it. On a terminal
//! `demo`, `watch` and `reorient --wait` redraw their view in place
//! (carriage return, ANSI escapes); when standard output is a file, a pipe
//! or a CI job's log they print one line per change of phase or goal state
//! instead (events still get a line each), so the output reads as a log.

use crate::common::{code, deg};
use gaitd_client::Status;
use std::io::{IsTerminal, Write};

/// When to redraw in place.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Live {
    /// When standard output is a terminal.
    #[default]
    Auto,
    /// Always (ANSI escapes and carriage returns even into a file).
    Always,
    /// Never: one line per change of phase or goal state.
    Never,
}

impl Live {
    /// Whether to redraw in place.
    pub fn redraw(self) -> bool {
        match self {
            Live::Auto => std::io::stdout().is_terminal(),
            Live::Always => true,
            Live::Never => false,
        }
    }
}

/// The `--live` flag of the subcommands with a live view.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct LiveArg {
    /// Redraw the view in place: auto (when standard output is a
    /// terminal), always, or never (one line per change of phase or goal
    /// state, for logs and pipes).
    #[arg(long, value_enum, default_value_t = Live::Auto)]
    pub live: Live,
}

/// What a line-per-change view prints a line for: the goal, its state and
/// the controller's phase.
#[derive(Debug, Default)]
pub struct Changes {
    last: Option<(u64, u32, u32)>,
}

impl Changes {
    /// Whether `s` shows another goal, goal state or phase than the status
    /// passed in before.
    pub fn changed(&mut self, s: &Status) -> bool {
        let now = (s.goal.goal_id, s.goal.state, s.phase);
        self.last.replace(now) != Some(now)
    }
}

/// One line describing a status, for logs: daemon time and tick, goal and
/// its state, phase, what is left, gaits, and the fault if there is one.
pub fn change_line(s: &Status) -> String {
    let g = &s.goal;
    let mut line = format!(
        "t {:>10.3} s  tick {:<8} goal {} {:<9} phase {:<9} remaining {:7.2} deg  gaits {}/{}",
        s.time_ns as f64 / 1e9,
        s.tick,
        g.goal_id,
        code(s.goal_state(), g.state),
        code(s.phase(), s.phase),
        deg(g.remaining_angle),
        g.gaits_done,
        g.gaits_planned,
    );
    if s.fault != 0 {
        line += &format!("  fault {}", code(s.fault(), s.fault));
    }
    line
}

/// A progress line on standard output: redrawn in place on a terminal, or
/// a line per change (see [`Live`]), with other lines printed above it.
#[derive(Debug)]
pub struct ProgressView {
    redraw: bool,
    changes: Changes,
    /// A redrawn line is on screen without its newline.
    drawn: bool,
}

impl ProgressView {
    /// A progress view as `live` says.
    pub fn new(live: Live) -> Self {
        Self {
            redraw: live.redraw(),
            changes: Changes::default(),
            drawn: false,
        }
    }

    /// Whether it redraws in place.
    pub fn redraws(&self) -> bool {
        self.redraw
    }

    /// Shows status `s`: `line()` redrawn in place, or [`change_line`]
    /// when the goal, its state or the phase changed.
    pub fn status(&mut self, s: &Status, line: impl FnOnce() -> String) {
        let mut out = std::io::stdout().lock();
        if self.redraw {
            let _ = write!(out, "\r{}\x1b[K", line());
            self.drawn = true;
        } else if self.changes.changed(s) {
            let _ = writeln!(out, "{}", change_line(s));
        }
        let _ = out.flush();
    }

    /// Prints `text` as a line of its own, above the progress line.
    pub fn println(&mut self, text: &str) {
        let mut out = std::io::stdout().lock();
        if self.drawn {
            // Over the progress line, which the next status draws again.
            let _ = write!(out, "\r\x1b[K");
            self.drawn = false;
        }
        let _ = writeln!(out, "{text}");
    }

    /// Ends a redrawn progress line (it stays on screen).
    pub fn finish(&mut self) {
        if self.drawn {
            println!();
            self.drawn = false;
        }
    }
}
