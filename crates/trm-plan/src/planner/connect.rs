//! [`Planner::connect`]: a path between two configurations, the query MotionBenchMaker and
//! MoveIt ask.

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::Planner;
use crate::PlanError;
use crate::query::{Goal, PlanOptions};
use crate::rrt::{EdgeCheck, RrtOptions, rrt_connect_in, shortcut};

/// Where the path of a [`Planner::connect`] query came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Source {
    /// The straight segment from the start to the goal.
    Straight,
    /// A search through the maps and kept paths.
    Graph,
    /// A kept path whose ends repeat the query's (see [`crate::RETRIEVE_STEPS`]).
    Retrieved,
    /// RRT-Connect.
    Sampled,
}

impl Source {
    /// A short lowercase name: `straight`, `graph`, `retrieved` or `sampled`.
    pub fn name(self) -> &'static str {
        match self {
            Source::Straight => "straight",
            Source::Graph => "graph",
            Source::Retrieved => "retrieved",
            Source::Sampled => "sampled",
        }
    }
}

/// A collision-free path [`Planner::connect`] found, and what it cost.
#[derive(Debug, Clone, PartialEq)]
pub struct Connection {
    /// Waypoints (active values) from the start to the goal, shortcut.
    pub path: Vec<Vec<f64>>,
    /// Where the path came from.
    pub source: Source,
    /// Configurations checked for collision by this query (the graph's lazy checks excluded
    /// when RRT-Connect answered).
    pub checks: u64,
    /// RRT-Connect's samples (0 when the graph answered).
    pub iterations: usize,
    /// Wall time, s.
    pub seconds: f64,
}

impl Planner {
    /// A collision-free path from `start` to `goal` (active values), found with `options`'
    /// resolution, seed and budget:
    /// - without maps or kept paths, by RRT-Connect ([`crate::rrt::rrt_connect`]: the straight
    ///   segment first, the path shortcut and checked again at half the resolution);
    /// - with them, through the graph first ([`Planner::plan`] to a configuration goal: a kept
    ///   path repeating the query is retrieved, else A* with lazy checks), the path shortcut
    ///   greedily and checked at half the resolution as RRT-Connect's paths are; where the
    ///   graph does not join the two or its path grazes an obstacle, by RRT-Connect.
    ///
    /// Nothing is kept: a caller keeping experience adds the path ([`Planner::add_path`]) when
    /// [`Connection::source`] is [`Source::Sampled`].
    pub fn connect(
        &mut self,
        start: &[f64],
        goal: &[f64],
        options: &RrtOptions,
    ) -> Result<Connection, PlanError> {
        options.check()?;
        let began = Instant::now();
        if self.nodes.is_empty() {
            return self.sample(start, goal, options, began, 0);
        }
        let plan_options = PlanOptions {
            resolution: options.resolution,
            shortcuts: 0,
            seed: options.seed,
            exact_goal: false,
            sampling: Some(options.clone()),
            ..Default::default()
        };
        let planned = match self.plan(start, &Goal::Configuration(goal.to_vec()), &plan_options) {
            Ok(planned) => planned,
            Err(e) => return Err(self.name_collisions(e, start, goal)),
        };
        if let Some((iterations, checks)) = planned.stats.sampled {
            return Ok(Connection {
                path: planned.waypoints,
                source: Source::Sampled,
                checks,
                iterations,
                seconds: began.elapsed().as_secs_f64(),
            });
        }
        let before = self.checker.checks;
        let mut path = planned.waypoints;
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        let greedy = RrtOptions {
            shortcuts: 0,
            ..options.clone()
        };
        let edges = shortcut(&mut path, &greedy, &mut self.checker, &mut rng);
        let source = if planned.stats.retrieved {
            Source::Retrieved
        } else if planned.nodes.is_empty() {
            Source::Straight
        } else {
            Source::Graph
        };
        // at half the resolution: the edges the shortcut found free and the graph's own
        // (checked at the same points, `WorldChecker::segment_free`) need only their midpoints
        let r = options.resolution;
        let checker = &mut self.checker;
        let free = path.windows(2).zip(&edges).all(|(w, e)| {
            (*e != EdgeCheck::Piece || checker.edge_free(&w[0], &w[1], r))
                && checker.edge_midpoints_free(&w[0], &w[1], r)
        });
        let checks = self.checker.checks - before;
        if free {
            return Ok(Connection {
                path,
                source,
                checks,
                iterations: 0,
                seconds: began.elapsed().as_secs_f64(),
            });
        }
        self.sample(start, goal, options, began, checks)
    }

    /// RRT-Connect from `start` to `goal` with the planner's checker; `checks` already spent.
    fn sample(
        &mut self,
        start: &[f64],
        goal: &[f64],
        options: &RrtOptions,
        began: Instant,
        checks: u64,
    ) -> Result<Connection, PlanError> {
        let found = match rrt_connect_in(&mut self.checker, &self.bounds, start, goal, options) {
            Ok(found) => found,
            Err(e) => return Err(self.name_collisions(e, start, goal)),
        };
        Ok(Connection {
            source: if found.iterations == 0 {
                Source::Straight
            } else {
                Source::Sampled
            },
            path: found.path,
            checks: checks + found.checks,
            iterations: found.iterations,
            seconds: began.elapsed().as_secs_f64(),
        })
    }
}

impl Planner {
    /// What makes `q` (active values) collide in the current world, one line per colliding
    /// pair of links (or link and object) at its deepest contact, deepest first: the robot's links and the world's objects by name, and for
    /// a pair of links which allowed-collision matrix has it checked — the model's own, or a
    /// matrix set since ([`Planner::set_acm`], a planning scene's) that checks a pair the
    /// model's own disables (and why the model disables it). Empty when `q` is free.
    ///
    /// # Panics
    /// If `q` does not hold one value per active motor.
    pub fn collisions(&mut self, q: &[f64]) -> Vec<String> {
        let collision = self.objective.collision();
        let robot = collision.robot();
        let mut poses = robot.pose_buffer();
        if robot
            .forward_motors(&self.active.to_motors(q), &mut poses)
            .is_err()
        {
            return vec!["the configuration is not finite".into()];
        }
        let mut placed = collision.placed_bodies();
        collision.place(&poses, &mut placed);
        let link = |body: usize| collision.bodies()[body].link;
        let name = |l: usize| robot.tree().links[l].name.as_str();
        // one line per pair of links (or link and object), its deepest contact, deepest first
        let mut pairs = collision.colliding_pairs(&placed, self.checker.world());
        let key = |p: &trm_collision::CollidingPair| match p.other {
            trm_collision::Other::Body(_) => (link(p.body_index), link(p.other_index), false),
            trm_collision::Other::Object(_) => (link(p.body_index), p.other_index, true),
        };
        pairs.sort_by(|a, b| key(a).cmp(&key(b)).then(a.distance.total_cmp(&b.distance)));
        pairs.dedup_by(|b, a| key(a) == key(b));
        pairs.sort_by(|a, b| a.distance.total_cmp(&b.distance));
        pairs
            .iter()
            .map(|p| {
                let depth = format!("{:.1} mm deep", -1e3 * p.distance);
                match &p.other {
                    trm_collision::Other::Object(object) => {
                        format!("link `{}` and object `{object}`, {depth}", name(link(p.body_index)))
                    }
                    trm_collision::Other::Body(_) => {
                        let (a, b) = (link(p.body_index), link(p.other_index));
                        let why = match self.own_acm.reason(a, b) {
                            Some(reason) => format!(
                                "checked by the matrix set on the planner (a scene's); the model's own disables it ({})",
                                reason.as_str()
                            ),
                            None => "checked by the model's own matrix".into(),
                        };
                        format!("links `{}` and `{}`, {depth}: {why}", name(a), name(b))
                    }
                }
            })
            .collect()
    }

    /// `error` with the colliding pairs of the start or goal it is about named.
    pub(super) fn name_collisions(
        &mut self,
        error: PlanError,
        start: &[f64],
        goal: &[f64],
    ) -> PlanError {
        let named = |pairs: Vec<String>| {
            let mut text = String::new();
            for p in pairs.iter().take(MAX_NAMED) {
                text.push_str("\n  collides: ");
                text.push_str(p);
            }
            if pairs.len() > MAX_NAMED {
                text.push_str(&format!("\n  … and {} more pairs", pairs.len() - MAX_NAMED));
            }
            text
        };
        match error {
            PlanError::InvalidStart(why) => {
                PlanError::InvalidStart(format!("{why}{}", named(self.collisions(start))))
            }
            PlanError::Unreachable {
                reason,
                closest_node,
                closest_distance,
            } if reason.starts_with("the goal configuration collides") => PlanError::Unreachable {
                reason: format!("{reason}{}", named(self.collisions(goal))),
                closest_node,
                closest_distance,
            },
            other => other,
        }
    }
}

/// Colliding pairs an error names (the deepest first); the rest are counted.
const MAX_NAMED: usize = 5;
