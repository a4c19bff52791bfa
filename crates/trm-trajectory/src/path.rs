//! A joint path through waypoints whose corners are cut by circular blends of bounded
//! deviation (the path Kunz and Stilman time, "Time-optimal trajectory generation for path
//! following with bounded acceleration and velocity", RSS 2012): straight lines joined by arcs
//! tangent to both lines, so the path has a continuous tangent wherever a corner is blended.
//!
//! A corner keeps its point (no arc) when its deviation is 0, when the path runs straight on
//! through it, or when it turns back on itself; the motion must then stop there
//! ([`BlendedPath::stops`]).
//!
//! ```
//! use trm_trajectory::BlendedPath;
//! let path = BlendedPath::new(&[vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 1.0]], 0.1)?;
//! assert!(path.length() < 2.0); // the corner at (1, 0) is cut
//! assert_eq!(path.position(0.0), vec![0.0, 0.0]);
//! assert_eq!(path.position(path.length()), vec![1.0, 1.0]);
//! # Ok::<(), trm_trajectory::TrajectoryError>(())
//! ```

use std::ops::Range;

use crate::{TrajectoryError, invalid};

/// Turns smaller than this (rad) are a straight run: no arc.
const STRAIGHT: f64 = 1e-9;
/// Turns closer than this to a full reversal (rad) cannot be blended: the motion stops.
const REVERSAL: f64 = 1e-6;

/// One piece of a [`BlendedPath`], parametrised by arc length from its start.
#[derive(Debug, Clone, PartialEq)]
enum Piece {
    /// `from + s · direction`, `s ∈ [0, length]`.
    Line {
        from: Vec<f64>,
        direction: Vec<f64>,
        length: f64,
    },
    /// `center + radius · (cos φ · x + sin φ · y)`, `φ = s / radius ∈ [0, angle]`.
    Arc {
        center: Vec<f64>,
        x: Vec<f64>,
        y: Vec<f64>,
        radius: f64,
        angle: f64,
        /// Index of the waypoint whose corner this arc cuts.
        corner: usize,
    },
}

impl Piece {
    fn length(&self) -> f64 {
        match self {
            Piece::Line { length, .. } => *length,
            Piece::Arc { radius, angle, .. } => radius * angle,
        }
    }
}

/// A path through waypoints with its corners blended by arcs (see the module's text),
/// parametrised by arc length `s ∈ [0, length]`.
#[derive(Debug, Clone, PartialEq)]
pub struct BlendedPath {
    pieces: Vec<Piece>,
    /// Arc length at the start of each piece.
    starts: Vec<f64>,
    length: f64,
    dim: usize,
    /// Arc lengths where the motion must stop: the ends and unblended corners.
    stops: Vec<f64>,
    /// Deviation allowed at each waypoint (ends unused).
    deviations: Vec<f64>,
    /// The first waypoint (the whole path when it has no length).
    first: Vec<f64>,
}

impl BlendedPath {
    /// The path through `waypoints` with every corner cut by an arc that stays within
    /// `max_deviation` of the waypoint (and uses at most half of each adjacent segment).
    /// Repeated consecutive waypoints are dropped. Errors: fewer than one waypoint, waypoints
    /// of different lengths, a non-finite value, a negative or non-finite deviation.
    pub fn new(waypoints: &[Vec<f64>], max_deviation: f64) -> Result<Self, TrajectoryError> {
        Self::with_deviations(waypoints, &vec![max_deviation; waypoints.len()])
    }

    /// As [`BlendedPath::new`], with a deviation per waypoint (`deviations[i]` for the corner
    /// at `waypoints[i]`; the ends' are unused): set one to 0 to keep that corner's point.
    pub fn with_deviations(
        waypoints: &[Vec<f64>],
        deviations: &[f64],
    ) -> Result<Self, TrajectoryError> {
        let Some(first) = waypoints.first() else {
            return Err(invalid("waypoints", "none given: give at least one"));
        };
        let dim = first.len();
        if deviations.len() != waypoints.len() {
            return Err(invalid(
                "deviations",
                format!(
                    "{} for {} waypoints: give one per waypoint",
                    deviations.len(),
                    waypoints.len()
                ),
            ));
        }
        for (i, (w, d)) in waypoints.iter().zip(deviations).enumerate() {
            if w.len() != dim {
                return Err(invalid(
                    "waypoints",
                    format!("waypoint {i} has {} values, waypoint 0 has {dim}", w.len()),
                ));
            }
            if let Some(j) = w.iter().position(|v| !v.is_finite()) {
                return Err(invalid(
                    "waypoints",
                    format!("waypoint {i}, value {j} is {}: give finite values", w[j]),
                ));
            }
            if !(d.is_finite() && *d >= 0.0) {
                return Err(invalid(
                    "deviation",
                    format!("{d} at waypoint {i}: give a finite deviation ≥ 0"),
                ));
            }
        }
        // drop repeated points, keeping each kept point's deviation
        let mut points: Vec<(&[f64], f64, usize)> = Vec::with_capacity(waypoints.len());
        for (i, (w, &d)) in waypoints.iter().zip(deviations).enumerate() {
            if points.last().is_none_or(|(p, _, _)| distance(p, w) > 0.0) {
                points.push((w, d, i));
            }
        }
        let directions: Vec<(Vec<f64>, f64)> = points
            .windows(2)
            .map(|w| {
                let length = distance(w[0].0, w[1].0);
                let d = w[1].0.iter().zip(w[0].0).map(|(b, a)| (b - a) / length);
                (d.collect(), length)
            })
            .collect();
        // the length each corner's arc takes from its two segments
        let mut cut = vec![0.0; points.len()];
        let mut arcs = vec![None; points.len()];
        for k in 1..points.len().saturating_sub(1) {
            let (d1, l1) = &directions[k - 1];
            let (d2, l2) = &directions[k];
            let turn = dot(d1, d2).clamp(-1.0, 1.0).acos();
            let deviation = points[k].1;
            if !(STRAIGHT..=std::f64::consts::PI - REVERSAL).contains(&turn) || deviation == 0.0 {
                continue;
            }
            let half = turn / 2.0;
            let reach = deviation * half.sin() / (1.0 - half.cos());
            let l = reach.min(l1 / 2.0).min(l2 / 2.0);
            let radius = l / half.tan();
            if !(radius > 0.0 && radius.is_finite()) {
                continue;
            }
            cut[k] = l;
            // the arc's normal at its start: d2's part perpendicular to d1
            let along = dot(d1, d2);
            let inward: Vec<f64> = d2.iter().zip(d1).map(|(b, a)| b - along * a).collect();
            let norm = dot(&inward, &inward).sqrt();
            let start: Vec<f64> = points[k].0.iter().zip(d1).map(|(w, d)| w - l * d).collect();
            let center: Vec<f64> = start
                .iter()
                .zip(&inward)
                .map(|(p, n)| p + radius * n / norm)
                .collect();
            let x: Vec<f64> = inward.iter().map(|n| -n / norm).collect();
            arcs[k] = Some(Piece::Arc {
                center,
                x,
                y: d1.clone(),
                radius,
                angle: turn,
                corner: points[k].2,
            });
        }
        let mut pieces = Vec::new();
        let mut stops = vec![0.0];
        let mut s = 0.0;
        for k in 0..points.len().saturating_sub(1) {
            let (direction, length) = &directions[k];
            let line = length - cut[k] - cut[k + 1];
            if line > 0.0 {
                let from = points[k].0.iter().zip(direction);
                pieces.push(Piece::Line {
                    from: from.map(|(w, d)| w + cut[k] * d).collect(),
                    direction: direction.clone(),
                    length: line,
                });
                s += line;
            }
            match arcs[k + 1].take() {
                Some(arc) => {
                    s += arc.length();
                    pieces.push(arc);
                }
                None => stops.push(s),
            }
        }
        if points.len() == 1 {
            stops.push(0.0);
        }
        let mut starts = Vec::with_capacity(pieces.len());
        let mut at = 0.0;
        for p in &pieces {
            starts.push(at);
            at += p.length();
        }
        if let Some(last) = stops.last_mut() {
            *last = at;
        }
        stops.dedup();
        Ok(BlendedPath {
            pieces,
            starts,
            length: at,
            dim,
            stops,
            deviations: deviations.to_vec(),
            first: first.clone(),
        })
    }

    /// The same waypoints with the corner at waypoint `corner` kept (its deviation halved, or
    /// set to 0 once below `floor`): how a blend that collides is tightened. `waypoints` must
    /// be the ones this path was made from.
    pub fn tightened(
        &self,
        waypoints: &[Vec<f64>],
        corner: usize,
        floor: f64,
    ) -> Result<Self, TrajectoryError> {
        let mut deviations = self.deviations.clone();
        if let Some(d) = deviations.get_mut(corner) {
            *d = if *d / 2.0 < floor { 0.0 } else { *d / 2.0 };
        }
        Self::with_deviations(waypoints, &deviations)
    }

    /// Path length (joint-space arc length).
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Number of joints.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Arc lengths where the motion must come to rest: 0, the length, and every corner kept
    /// as a point (increasing).
    pub fn stops(&self) -> &[f64] {
        &self.stops
    }

    /// Arc lengths where a piece starts, then the length: a timing grid must hold them.
    pub fn breaks(&self) -> Vec<f64> {
        let mut b = self.starts.clone();
        b.push(self.length);
        b.dedup();
        b
    }

    /// The arcs: for each, the waypoint index whose corner it cuts and its arc-length range
    /// (what a collision check of the blends walks).
    pub fn blends(&self) -> Vec<(usize, Range<f64>)> {
        self.pieces
            .iter()
            .zip(&self.starts)
            .filter_map(|(p, &s)| match p {
                Piece::Arc { corner, .. } => Some((*corner, s..s + p.length())),
                Piece::Line { .. } => None,
            })
            .collect()
    }

    /// Index of the piece holding arc length `s` (clamped to the path) and `s` within it.
    fn locate(&self, s: f64) -> Option<(&Piece, f64)> {
        let i = self.starts.partition_point(|&a| a <= s).checked_sub(1)?;
        let local = (s - self.starts[i]).clamp(0.0, self.pieces[i].length());
        Some((&self.pieces[i], local))
    }

    /// Position at arc length `s` (clamped to `[0, length]`).
    pub fn position(&self, s: f64) -> Vec<f64> {
        let mut q = vec![0.0; self.dim];
        self.evaluate(s, &mut q, &mut [], &mut []);
        q
    }

    /// Position, first and second derivatives with respect to arc length at `s` (clamped),
    /// into caller-owned buffers (a buffer left empty is not filled). At a corner kept as a
    /// point the piece after it is used.
    pub fn evaluate(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]) {
        let s = s.clamp(0.0, self.length);
        let Some((piece, local)) = self.locate(s) else {
            // a path of one point
            for j in 0..self.dim {
                fill(q, j, self.first[j]);
                fill(dq, j, 0.0);
                fill(ddq, j, 0.0);
            }
            return;
        };
        match piece {
            Piece::Line {
                from, direction, ..
            } => {
                for j in 0..self.dim {
                    fill(q, j, from[j] + local * direction[j]);
                    fill(dq, j, direction[j]);
                    fill(ddq, j, 0.0);
                }
            }
            Piece::Arc {
                center,
                x,
                y,
                radius,
                ..
            } => {
                let (sin, cos) = (local / radius).sin_cos();
                for j in 0..self.dim {
                    let out = cos * x[j] + sin * y[j];
                    fill(q, j, center[j] + radius * out);
                    fill(dq, j, -sin * x[j] + cos * y[j]);
                    fill(ddq, j, -out / radius);
                }
            }
        }
    }

    /// Angle (rad) the tangent turns through over `[s0, s1]` within one piece (0 on lines).
    pub(crate) fn turn(&self, s0: f64, s1: f64) -> f64 {
        match self.locate((s0 + s1) / 2.0) {
            Some((Piece::Arc { radius, .. }, _)) => (s1 - s0) / radius,
            _ => 0.0,
        }
    }

    /// Bounds of each joint's first and second derivative over `[s0, s1]` (within one piece):
    /// `(first_min, first_max, second_min, second_max)` per joint, into `out`.
    pub(crate) fn derivative_bounds(&self, s0: f64, s1: f64, out: &mut Vec<[f64; 4]>) {
        out.clear();
        let Some((piece, a)) = self.locate((s0 + s1) / 2.0) else {
            out.resize(self.dim, [0.0; 4]);
            return;
        };
        let half = (s1 - s0) / 2.0;
        match piece {
            Piece::Line { direction, .. } => {
                out.extend(direction.iter().map(|&d| [d, d, 0.0, 0.0]));
            }
            Piece::Arc { x, y, radius, .. } => {
                // q' = −sin φ x + cos φ y and q'' = −(cos φ x + sin φ y) / r: each one's
                // derivative in φ is the other's (times ∓r), so q' peaks (±A, A = |(x, y)|)
                // inside the interval only where q'' changes sign, and q'' (±A/r) only where q'
                // does
                let (s0, c0) = ((a - half) / radius).sin_cos();
                let (s1, c1) = ((a + half) / radius).sin_cos();
                for j in 0..self.dim {
                    let first = [-s0 * x[j] + c0 * y[j], -s1 * x[j] + c1 * y[j]];
                    let second = [
                        -(c0 * x[j] + s0 * y[j]) / radius,
                        -(c1 * x[j] + s1 * y[j]) / radius,
                    ];
                    let amplitude = x[j].hypot(y[j]);
                    let mut b = [
                        first[0].min(first[1]),
                        first[0].max(first[1]),
                        second[0].min(second[1]),
                        second[0].max(second[1]),
                    ];
                    // q' rises while q'' > 0 (dq'/dφ = r q''): a sign change + → − is a peak
                    if second[0] > 0.0 && second[1] < 0.0 {
                        b[1] = amplitude;
                    } else if second[0] < 0.0 && second[1] > 0.0 {
                        b[0] = -amplitude;
                    }
                    // dq''/dφ = −q'/r: q'' peaks where q' goes − → +
                    if first[0] < 0.0 && first[1] > 0.0 {
                        b[3] = amplitude / radius;
                    } else if first[0] > 0.0 && first[1] < 0.0 {
                        b[2] = -amplitude / radius;
                    }
                    out.push(b);
                }
            }
        }
    }
}

fn fill(buffer: &mut [f64], j: usize, value: f64) {
    if let Some(b) = buffer.get_mut(j) {
        *b = value;
    }
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(crate) fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The derivative bounds of every grid interval hold the derivatives sampled densely.
    #[test]
    fn derivative_bounds_hold_the_sampled_derivatives() {
        let waypoints = vec![
            vec![0.0, 0.0, 0.0],
            vec![1.0, 0.3, -0.2],
            vec![1.2, 1.0, 0.4],
            vec![0.2, 1.1, 0.9],
            vec![0.3, 0.0, 0.0],
        ];
        let path = BlendedPath::new(&waypoints, 0.3).unwrap();
        let mut bounds = Vec::new();
        let (mut q, mut dq, mut ddq) = (vec![0.0; 3], vec![0.0; 3], vec![0.0; 3]);
        for (_, range) in path.blends() {
            let n = 7;
            for k in 0..n {
                let s0 = range.start + (range.end - range.start) * k as f64 / n as f64;
                let s1 = range.start + (range.end - range.start) * (k + 1) as f64 / n as f64;
                path.derivative_bounds(s0, s1, &mut bounds);
                for m in 0..=100 {
                    // within the piece: its end point belongs to the next one
                    let s = s0 + (s1 - s0) * (m as f64 / 100.0).min(1.0 - 1e-9);
                    path.evaluate(s, &mut q, &mut dq, &mut ddq);
                    for j in 0..3 {
                        let b = bounds[j];
                        assert!(
                            dq[j] >= b[0] - 1e-9 && dq[j] <= b[1] + 1e-9,
                            "q' {j}: {} not in {b:?}",
                            dq[j]
                        );
                        assert!(
                            ddq[j] >= b[2] - 1e-9 && ddq[j] <= b[3] + 1e-9,
                            "q'' {j}: {} not in {b:?}",
                            ddq[j]
                        );
                    }
                }
            }
        }
    }
}
