//! Which placements hold the load with a grasping contact, tabulated
//! (SPEC §1.3 I1'; SPEC §4.3 "Under load": whether a pair holds
//! depends only on where its contacts are in the hand frame).
//!
//! The search asks, again and again, which candidate placements of the
//! free finger make with a grasping contact a pair that holds the load at
//! rest (paper Theory 1 under load, and the substitutions' first filter).
//! The contact moves with the object, so it is rarely on the candidate
//! grid; but the answer changes little when it moves by a degree. So each
//! cone is covered by a chart of cells about [`CELL_DEG`] wide (rings
//! about the cone's axis), and for each cell, free finger and candidate
//! two bits record, for the cell's centre, whether the candidate surely
//! makes a good pair (Fact 3 with the planning margin) that holds the load
//! at rest, or may: where the pair's angle is within a cell's radius of
//! the margin, or the slack of [`PairLoad`]'s sufficient test within
//! [`SLACK_BAND`] of zero (measured: over a cell's radius, 1.42°, the slack
//! changes by at most 0.57 N over 12 500 random pairs), or — with the
//! exact test behind it — the exact F* at most [`EXACT_BAND`] times
//! `load.max_grip`. A "may" is decided where the contact really is.
//! Cells are filled on first use (lock-free: a cell's words are written,
//! then its flag; a race fills the same bits twice) and shared by every
//! clone of the planner.

use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::Vector3;

use super::super::candidates::Candidates;
use super::super::geometry::{Geometry, any_perpendicular};
use super::super::load::PairLoad;

/// Width of a chart cell \[deg\].
pub const CELL_DEG: f64 = 2.0;

/// Slack of the sufficient test \[N\] within which a cell's verdict is
/// "may" (module docs).
pub const SLACK_BAND: f64 = 0.8;

/// F* of the exact test, over `load.max_grip`, up to which a cell's
/// verdict is "may".
pub const EXACT_BAND: f64 = 1.3;

/// One cone's chart: rings about its axis.
#[derive(Debug)]
struct Chart {
    axis: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    step: f64,
    /// First cell of each ring, and its cell count.
    rings: Vec<(usize, usize)>,
    cells: usize,
}

impl Chart {
    fn new(axis: Vector3<f64>, half_angle: f64) -> Self {
        let step = CELL_DEG.to_radians();
        let e1 = any_perpendicular(&axis);
        let e2 = axis.cross(&e1);
        let n_rings = (half_angle / step).ceil() as usize + 2;
        let mut rings = Vec::with_capacity(n_rings);
        let mut cells = 0;
        for j in 0..n_rings {
            let alpha = j as f64 * step;
            let n = ((std::f64::consts::TAU * alpha.sin() / step).round() as usize).max(1);
            rings.push((cells, n));
            cells += n;
        }
        Self {
            axis,
            e1,
            e2,
            step,
            rings,
            cells,
        }
    }

    /// The cell of unit direction `c` (`None` beyond the chart).
    fn cell(&self, c: &Vector3<f64>) -> Option<usize> {
        let (x, y, z) = (c.dot(&self.e1), c.dot(&self.e2), c.dot(&self.axis));
        let alpha = (x * x + y * y).sqrt().atan2(z);
        let j = (alpha / self.step).round() as usize;
        let &(first, n) = self.rings.get(j)?;
        let phi = y.atan2(x).rem_euclid(std::f64::consts::TAU);
        let i = (phi / (std::f64::consts::TAU / n as f64)).round() as usize % n;
        Some(first + i)
    }

    /// The centre of cell `(j, i)`.
    fn centre(&self, j: usize, i: usize) -> Vector3<f64> {
        let alpha = j as f64 * self.step;
        let n = self.rings[j].1;
        let phi = std::f64::consts::TAU * i as f64 / n as f64;
        let (sa, ca) = alpha.sin_cos();
        let (sp, cp) = phi.sin_cos();
        self.axis * ca + (self.e1 * cp + self.e2 * sp) * sa
    }

    /// The ring and index of a cell.
    fn ring_of(&self, cell: usize) -> (usize, usize) {
        let j = self.rings.partition_point(|&(first, _)| first <= cell) - 1;
        (j, cell - self.rings[j].0)
    }
}

/// The table (module docs).
#[derive(Debug)]
pub struct HoldTable {
    charts: [Chart; 3],
    /// Words per bit set (the largest candidate count over fingers).
    words: usize,
    /// Per grasping finger x, per free finger z (slot 0 and 1 of the two
    /// others), per cell: `words` words of "surely", `words` of "may", then
    /// the filled flag.
    bits: Vec<AtomicU64>,
    /// Where each x's block starts.
    base: [usize; 3],
}

/// A cell's verdicts for one free finger: the candidates that surely
/// hold, and those that may.
pub struct Holding<'a> {
    /// Surely.
    pub sure: Bits<'a>,
    /// May: decide where the contact really is.
    pub may: Bits<'a>,
}

/// Set bits of a bit set, as indices in order.
pub struct Bits<'a> {
    words: &'a [AtomicU64],
    word: usize,
    current: u64,
}

impl Iterator for Bits<'_> {
    type Item = usize;
    fn next(&mut self) -> Option<usize> {
        loop {
            if self.current != 0 {
                let b = self.current.trailing_zeros() as usize;
                self.current &= self.current - 1;
                return Some((self.word - 1) * 64 + b);
            }
            let w = self.words.get(self.word)?;
            self.current = w.load(Ordering::Relaxed);
            self.word += 1;
        }
    }
}

impl HoldTable {
    /// An empty table for the cones of `g` and the grids of `cand`.
    pub fn new(g: &Geometry, cand: &Candidates) -> Self {
        let charts = std::array::from_fn(|k| Chart::new(g.base[k], g.cone_half_angle));
        let words = (0..3)
            .map(|k| cand.points[k].len().div_ceil(64))
            .max()
            .unwrap_or(1);
        let mut base = [0; 3];
        let mut len = 0;
        for (x, chart) in charts.iter().enumerate() {
            base[x] = len;
            len += 2 * chart.cells * (2 * words + 1);
        }
        let bits = (0..len).map(|_| AtomicU64::new(0)).collect();
        Self {
            charts,
            words,
            bits,
            base,
        }
    }

    /// The candidates of free finger `z` that make with finger `x`'s
    /// contact `cx` a good pair holding the load at rest, as the table has
    /// them (`None`: `cx` is off the chart; ask directly).
    pub fn holding(
        &self,
        g: &Geometry,
        load: &PairLoad,
        cand: &Candidates,
        x: usize,
        cx: &Vector3<f64>,
        z: usize,
    ) -> Option<Holding<'_>> {
        let cell = self.charts[x].cell(cx)?;
        let block = self.block(x, z, cell);
        let w = self.words;
        if block[2 * w].load(Ordering::Acquire) == 0 {
            self.fill(g, load, cand, x, z, cell);
        }
        Some(Holding {
            sure: Bits {
                words: &block[..w],
                word: 0,
                current: 0,
            },
            may: Bits {
                words: &block[w..2 * w],
                word: 0,
                current: 0,
            },
        })
    }

    /// The words of grasping finger `x`'s cell `cell` for free finger `z`.
    fn block(&self, x: usize, z: usize, cell: usize) -> &[AtomicU64] {
        // The two fingers other than x, in order: slot 0 and 1.
        let first_other = usize::from(x == 0);
        let slot = usize::from(z != first_other);
        let stride = 2 * self.words + 1;
        let at = self.base[x] + (slot * self.charts[x].cells + cell) * stride;
        &self.bits[at..at + stride]
    }

    /// Decides a cell at its centre (module docs) and sets its flag.
    fn fill(
        &self,
        g: &Geometry,
        load: &PairLoad,
        cand: &Candidates,
        x: usize,
        z: usize,
        cell: usize,
    ) {
        let chart = &self.charts[x];
        let block = self.block(x, z, cell);
        let w = self.words;
        let (j, i) = chart.ring_of(cell);
        let centre = chart.centre(j, i);
        let radius = 0.75 * CELL_DEG.to_radians();
        for (n, c) in cand.points[z].iter().enumerate() {
            let angle = c.angle(&centre);
            let margin = angle - g.cos_fc_plan.acos();
            if margin < -radius {
                continue;
            }
            let slack = load.slack(&centre, c, None);
            let sure = margin > radius && slack > SLACK_BAND;
            // The exact F* (the costly part) only where the slack leaves
            // it open.
            let may = !sure
                && (slack > -SLACK_BAND
                    || load
                        .exact_peak(&centre, c)
                        .is_some_and(|f| f <= EXACT_BAND * load.max_grip()));
            let bit = 1 << (n % 64);
            if sure {
                block[n / 64].fetch_or(bit, Ordering::Relaxed);
            } else if may {
                block[w + n / 64].fetch_or(bit, Ordering::Relaxed);
            }
        }
        block[2 * w].store(1, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;

    #[test]
    fn cells_are_found_where_their_centres_are() {
        let g = Geometry::new(&HandConfig::default());
        let chart = Chart::new(g.base[1], g.cone_half_angle);
        for cell in 0..chart.cells {
            let (j, i) = chart.ring_of(cell);
            assert_eq!(chart.cell(&chart.centre(j, i)), Some(cell), "cell {cell}");
        }
        // A direction is never more than a cell's diagonal from its centre.
        let mut worst: f64 = 0.0;
        for k in 0..2000 {
            let a = k as f64 * 0.7;
            let c = (g.base[1] + 0.8 * Vector3::new(a.sin(), a.cos(), (1.3 * a).sin())).normalize();
            if c.dot(&g.base[1]) < g.cos_cone {
                continue;
            }
            let cell = chart.cell(&c).unwrap();
            let (j, i) = chart.ring_of(cell);
            worst = worst.max(c.angle(&chart.centre(j, i)));
        }
        assert!(worst.to_degrees() < CELL_DEG, "{}", worst.to_degrees());
    }
}

#[cfg(test)]
mod agree {
    use super::*;
    use crate::HandConfig;

    #[test]
    fn bits_agree_with_the_test_mostly() {
        let cfg = HandConfig::default();
        let g = Geometry::new(&cfg);
        let cand = Candidates::new(&g, 6.0);
        let load = PairLoad::new(&cfg);
        let t = HoldTable::new(&g, &cand);
        let (mut same, mut table_only, mut direct_only) = (0, 0, 0);
        for k in 0..3000 {
            let a = k as f64 * 0.37;
            let x = k % 3;
            let cx =
                (g.base[x] + 0.9 * Vector3::new(a.sin(), a.cos(), (1.7 * a).sin())).normalize();
            if cx.dot(&g.base[x]) < g.cos_cone {
                continue;
            }
            let z = (x + 1 + k % 2) % 3;
            let h = t.holding(&g, &load, &cand, x, &cx, z).unwrap();
            let sure: Vec<usize> = h.sure.collect();
            let may: Vec<usize> = h.may.collect();
            for (i, c) in cand.points[z].iter().enumerate() {
                let direct = g.is_good_pair(c, &cx) && load.holds(&cx, c, None);
                let said = sure.contains(&i)
                    || (may.contains(&i) && g.is_good_pair(c, &cx) && load.holds(&cx, c, None));
                match (said, direct) {
                    (true, true) => same += 1,
                    (true, false) => table_only += 1,
                    (false, true) => direct_only += 1,
                    _ => {}
                }
            }
        }
        println!("agree {same}, table only {table_only}, direct only {direct_only}");
        assert_eq!((table_only, direct_only), (0, 0));
    }
}
