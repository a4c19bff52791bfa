//! [`Planner::connect`]: a path between two configurations, the query MotionBenchMaker and
//! MoveIt ask.

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::Planner;
use super::search::LazySearch;

use crate::PlanError;
use crate::pose_goal::PoseGoal;
use crate::query::{Goal, PlanOptions, Planned};
use crate::rrt::{GOAL_COLLIDES, Growth, RrtOptions, RrtPath, rrt_connect_in, shortcut};
use crate::simplify::{prove_path, recheck, simplified_finer};

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
    /// Configurations checked for collision by this query (RRT-Connect's and the graph's).
    pub checks: u64,
    /// RRT-Connect's samples.
    pub iterations: usize,
    /// Wall time, s.
    pub seconds: f64,
    /// Of [`Connection::seconds`], the time spent simplifying the path found (shortcutting it
    /// and checking the result again; proving it, with certified paths), s: the rest is
    /// planning.
    pub simplify_seconds: f64,
    /// Whether the path is proved free in continuous motion ([`RrtOptions::certified`]).
    pub proved: bool,
}

impl Planner {
    /// A collision-free path from `start` to `goal` (active values), found with `options`'
    /// resolution, seed and budget:
    /// - without maps or kept paths, by RRT-Connect ([`crate::rrt::rrt_connect`]: the straight
    ///   segment first, the path shortcut and checked again at half the resolution);
    /// - with them, so that they can only help: a kept path repeating the query is retrieved
    ///   (when it is still free); else RRT-Connect and the graph take turns. RRT-Connect
    ///   first, for [`HEAD_START_SAMPLES`] samples (the queries it answers that fast get the
    ///   path and checks they get without a graph); then the graph's lazy A* for
    ///   [`Planner::graph_turn_searches`] searches; then RRT-Connect again with the
    ///   same trees, up to [`ROUND_GROWTH`] times its samples so far, and the graph as many
    ///   searches more, and so on until the graph has had its searches or has no path left;
    ///   then
    ///   RRT-Connect alone within the rest of the budget. The graph's path is shortcut
    ///   greedily and checked at half the resolution as RRT-Connect's paths are. The graph's
    ///   share of a query's effort shrinks as the query lasts, and as its turns in recent
    ///   queries fail ([`Planner::graph_share`]): a map blocked in the scene costs a query a
    ///   search or two, and less in the queries after; a map that joins the two answers a
    ///   hard query early.
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
        let before = self.checker.checks;
        let mut found = self.find(start, goal, options, began, before)?;
        if options.certified && !found.proved {
            let proving = Instant::now();
            prove_path(&mut self.checker, &self.bounds, &mut found.path, options)?;
            found.proved = true;
            found.simplify_seconds += proving.elapsed().as_secs_f64();
            found.checks = self.checker.checks - before;
            found.seconds = began.elapsed().as_secs_f64();
        }
        Ok(found)
    }

    /// [`Planner::connect`]'s path, before any proof.
    fn find(
        &mut self,
        start: &[f64],
        goal: &[f64],
        options: &RrtOptions,
        began: Instant,
        before: u64,
    ) -> Result<Connection, PlanError> {
        if self.nodes.is_empty() {
            return self.sample(start, goal, options, began, before);
        }
        // a query repeating a kept path: that path, when it is still free
        if !self.kept.is_empty()
            && let Some(found) = self.retrieved(start, goal, options)?
        {
            return Ok(Connection {
                checks: self.checker.checks - before,
                seconds: began.elapsed().as_secs_f64(),
                ..found
            });
        }
        let mut growth = match Growth::new(&mut self.checker, start, goal, options) {
            Ok(growth) => growth,
            Err(e) => return Err(self.name_collisions(e, start, goal)),
        };
        // RRT-Connect and the graph take turns: RRT-Connect's samples grow fourfold a round;
        // after a round, the graph gets a turn (a quarter of its searches) when its work so far
        // would stay within its share of RRT-Connect's checks, and the rest of its searches
        // when RRT-Connect's budget is spent
        let (most, step, mut lazy) = (self.graph_searches(), self.graph_turn_searches(), None);
        // a turn's work in graph elements visited: its searches, plus a graph's worth for its
        // set-up (the query's graph built on the first turn, A*'s filters on every one)
        let turn_work = (self.graph_elements() * (step + 1)) as f64;
        let (mut samples, mut searches, mut work) = (HEAD_START_SAMPLES, step, 0.0);
        loop {
            let round = options.max_iterations.min(samples);
            if growth.grow(&mut self.checker, &self.bounds, options, round, began) {
                break;
            }
            let spent = growth.iterations() < samples;
            let checks = (self.checker.checks - before) as f64;
            if spent {
                searches = most;
            } else if work + turn_work > self.graph_share() * ELEMENTS_PER_CHECK * checks {
                samples = samples.saturating_mul(ROUND_GROWTH);
                continue;
            }
            work += turn_work;
            if let Some(found) = self.through_graph(start, goal, options, &mut lazy, searches)? {
                self.graph_record.paid();
                return Ok(Connection {
                    checks: self.checker.checks - before,
                    iterations: growth.iterations(),
                    seconds: began.elapsed().as_secs_f64(),
                    ..found
                });
            }
            if spent || searches >= most || lazy.as_ref().is_none_or(LazySearch::exhausted) {
                break;
            }
            samples = samples.saturating_mul(ROUND_GROWTH);
            searches = (searches + step).min(most);
        }
        // the trees met, or the graph did not answer: RRT-Connect goes on
        if work > 0.0 {
            self.graph_record.unpaid();
        }
        match growth.finish(&mut self.checker, &self.bounds, options, began) {
            Ok(found) => Ok(self.sampled(found, began, before)),
            Err(e) => Err(self.name_collisions(e, start, goal)),
        }
    }

    /// A collision-free configuration (active values) that meets the task-space `goal`:
    /// damped least-squares IK from `start`, then from configurations drawn from `seed`,
    /// [`GOAL_ATTEMPTS`] starts in all ([`PoseGoal::solve`]); `None` when none is found. A
    /// constraint given in a frame other than the robot's root is refused.
    pub fn solve_pose(
        &mut self,
        start: &[f64],
        goal: &PoseGoal,
        seed: u64,
    ) -> Result<Option<Vec<f64>>, PlanError> {
        let robot = self.active.model();
        let root = &robot.tree().links[0].name;
        if let Some(frame) = goal.foreign_frame(root) {
            return Err(PlanError::InvalidGoal {
                problem: format!("a goal constraint is given in frame `{frame}`"),
                fix: format!("give it in the robot's root frame `{root}`"),
            });
        }
        if goal.is_empty() {
            return Err(PlanError::InvalidGoal {
                problem: "a task-space goal without a constraint".into(),
                fix: "give position or orientation constraints".into(),
            });
        }
        let active = self.active.clone();
        Ok(goal.solve(&active, start, seed, GOAL_ATTEMPTS, |q| self.is_free(q))?)
    }

    /// A collision-free path from `start` to a configuration that meets the task-space `goal`
    /// ([`Planner::solve_pose`] with `options.seed`, then [`Planner::connect`]); the time and
    /// checks of the IK are counted in the connection's.
    pub fn connect_to_pose(
        &mut self,
        start: &[f64],
        goal: &PoseGoal,
        options: &RrtOptions,
    ) -> Result<Connection, PlanError> {
        options.check()?;
        let began = Instant::now();
        let before = self.checker.checks;
        let Some(q) = self.solve_pose(start, goal, options.seed)? else {
            return Err(PlanError::Unreachable {
                reason: format!(
                    "no collision-free configuration meets the task-space goal ({GOAL_ATTEMPTS} IK starts)"
                ),
                closest_node: None,
                closest_distance: f64::INFINITY,
            });
        };
        let rest = RrtOptions {
            max_seconds: options
                .max_seconds
                .map(|s| (s - began.elapsed().as_secs_f64()).max(f64::MIN_POSITIVE)),
            ..options.clone()
        };
        let found = self.connect(start, &q, &rest)?;
        Ok(Connection {
            checks: self.checker.checks - before,
            seconds: began.elapsed().as_secs_f64(),
            ..found
        })
    }

    /// A kept path repeating the query from `start` to `goal` ([`Planner::connect`]'s first
    /// try), shortcut and checked at half the resolution; `None` where none repeats it or it is
    /// blocked.
    fn retrieved(
        &mut self,
        start: &[f64],
        goal: &[f64],
        options: &RrtOptions,
    ) -> Result<Option<Connection>, PlanError> {
        let d = self.active.len();
        let well_formed = |q: &[f64]| q.len() == d && q.iter().all(|v| v.is_finite());
        if !well_formed(start) || !well_formed(goal) {
            // RRT-Connect names what is wrong
            return Ok(None);
        }
        // looked up without the query's own checks of its start (the kept path's joining edges
        // check it; RRT-Connect does otherwise)
        self.time_paths = false;
        let planned = self.retrieve(start, goal, &graph_options(options, 0), Instant::now());
        self.time_paths = true;
        match planned {
            Ok(Some(planned)) => Ok(self.graph_connection(planned, options)),
            Ok(None) | Err(PlanError::Unreachable { .. }) => Ok(None),
            Err(e) => Err(self.name_collisions(e, start, goal)),
        }
    }

    /// The graph's path from `start` to `goal` ([`Planner::connect`]'s turns between
    /// RRT-Connect's rounds: `lazy`'s search, made on the first turn, given up to `searches` A*
    /// searches in all), shortcut and checked at half the resolution; `None` where the graph
    /// does not join them within those searches or its path grazes an obstacle.
    fn through_graph(
        &mut self,
        start: &[f64],
        goal: &[f64],
        options: &RrtOptions,
        lazy: &mut Option<LazySearch>,
        searches: usize,
    ) -> Result<Option<Connection>, PlanError> {
        let plan_options = graph_options(options, searches);
        let began = Instant::now();
        let lazy = match lazy {
            Some(lazy) => lazy,
            None => {
                let to = Goal::Configuration(goal.to_vec());
                let made = self
                    .check_query(start, &to, &plan_options)
                    .and_then(|()| self.lazy_search(start, &to, &plan_options));
                match made {
                    // RRT-Connect checked the straight segment before the graph's first turn
                    Ok(mut made) => {
                        made.straight_blocked();
                        lazy.insert(made)
                    }
                    Err(PlanError::Unreachable { .. }) => return Ok(None),
                    Err(e) => return Err(self.name_collisions(e, start, goal)),
                }
            }
        };
        // the waypoints only: their trajectory would be thrown away
        self.time_paths = false;
        let planned = self.search_lazily(lazy, &plan_options, Some(searches), began);
        self.time_paths = true;
        match planned {
            Ok(planned) => Ok(self.graph_connection(planned, options)),
            Err(PlanError::Unreachable { .. }) => Ok(None),
            Err(e) => Err(self.name_collisions(e, start, goal)),
        }
    }

    /// The connection a path `planned` through the graph makes: shortcut greedily and checked
    /// at half the resolution as RRT-Connect's paths are; `None` where it grazes an obstacle.
    fn graph_connection(&mut self, planned: Planned, options: &RrtOptions) -> Option<Connection> {
        let mut path = planned.waypoints;
        let simplifying = Instant::now();
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        let retrieved = planned.stats.retrieved;
        // a kept path repeating the query was simplified when it was planned: the greedy pass
        // only
        let greedy = RrtOptions {
            shortcuts: 0,
            smoothing: if retrieved { 0 } else { options.smoothing },
            ..options.clone()
        };
        let raw = path.clone();
        let edges = shortcut(&mut path, &greedy, &mut self.checker, &mut rng);
        let source = if retrieved {
            Source::Retrieved
        } else if planned.nodes.is_empty() {
            Source::Straight
        } else {
            Source::Graph
        };
        // at half the resolution: the edges the shortcut found free and the graph's own
        // (checked at the same points, `WorldChecker::segment_free`) need only their midpoints
        let r = options.resolution;
        let mut free = recheck(&mut self.checker, &path, &edges, r, r);
        if !free && let Some(again) = simplified_finer(&mut self.checker, &raw, &greedy, r) {
            path = again;
            free = true;
        }
        free.then_some(Connection {
            path,
            source,
            checks: 0,
            iterations: 0,
            seconds: 0.0,
            simplify_seconds: simplifying.elapsed().as_secs_f64(),
            proved: false,
        })
    }

    /// RRT-Connect from `start` to `goal` with the planner's checker, the query's checks
    /// counted from `before`.
    fn sample(
        &mut self,
        start: &[f64],
        goal: &[f64],
        options: &RrtOptions,
        began: Instant,
        before: u64,
    ) -> Result<Connection, PlanError> {
        match rrt_connect_in(&mut self.checker, &self.bounds, start, goal, options) {
            Ok(found) => Ok(self.sampled(found, began, before)),
            Err(e) => Err(self.name_collisions(e, start, goal)),
        }
    }

    /// The connection RRT-Connect's `found` makes.
    fn sampled(&self, found: RrtPath, began: Instant, before: u64) -> Connection {
        Connection {
            source: if found.iterations == 0 {
                Source::Straight
            } else {
                Source::Sampled
            },
            path: found.path,
            checks: self.checker.checks - before,
            iterations: found.iterations,
            seconds: began.elapsed().as_secs_f64(),
            simplify_seconds: found.simplify_seconds,
            proved: found.proved,
        }
    }
}

/// IK starts [`Planner::solve_pose`] tries for a task-space goal (the start, then seeded random
/// configurations).
pub const GOAL_ATTEMPTS: usize = 500;

/// RRT-Connect's samples before [`Planner::connect`] tries the graph: queries RRT-Connect
/// answers within them are answered as without a graph.
pub const HEAD_START_SAMPLES: usize = 64;

/// Of the last queries in which [`Planner::connect`]'s graph took a turn, how many it answered:
/// the graph's share of a query's effort follows it ([`Planner::graph_share`]).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct GraphRecord {
    paid: f64,
    unpaid: f64,
}

/// The queries [`GraphRecord`] remembers, about: past this, both counts are halved, so that a
/// graph that starts answering (a world where it is free again) gets its share back within a
/// few queries.
pub const GRAPH_MEMORY: f64 = 16.0;

impl GraphRecord {
    fn paid(&mut self) {
        self.paid += 1.0;
        self.forget_old();
    }

    fn unpaid(&mut self) {
        self.unpaid += 1.0;
        self.forget_old();
    }

    fn forget_old(&mut self) {
        if self.paid + self.unpaid > GRAPH_MEMORY {
            self.paid /= 2.0;
            self.unpaid /= 2.0;
        }
    }

    /// The share of the turns that answered, counting one answered beforehand (1 with no
    /// record).
    fn rate(&self) -> f64 {
        (self.paid + 1.0) / (self.paid + self.unpaid + 1.0)
    }
}

/// How many times more samples RRT-Connect draws in each of [`Planner::connect`]'s rounds
/// than in all rounds before, while the graph's turns stay the same size: the longer a query
/// has run, the smaller the graph's share of its effort.
pub const ROUND_GROWTH: usize = 4;

/// The most [`Planner::connect`]'s turns through the graph may visit, in graph elements, for
/// every element's worth of RRT-Connect's collision checks so far (see
/// [`ELEMENTS_PER_CHECK`]): a graph whose searches cost more than this share of a query's
/// sampling waits for a later round. Scaled by how the graph's recent turns fared
/// ([`Planner::graph_share`]).
pub const GRAPH_SHARE: f64 = 0.25;

/// Graph elements (nodes and edges) a lazy A* search visits in the time of one collision
/// check of a configuration, roughly: measured on the Panda's 302-point reach map (1 734
/// elements, 12 µs a search) against its sphere model's checks (about 60 ns each, planner
/// overhead included). A robot whose checks cost more gives the graph a larger share.
pub const ELEMENTS_PER_CHECK: f64 = 8.0;

/// Into how many turns [`Planner::connect`] splits the graph's work
/// ([`GRAPH_SEARCH_WORK`]) between RRT-Connect's rounds.
pub const GRAPH_TURNS: usize = 4;

/// [`Planner::plan`]'s options for [`Planner::connect`]'s turns through the graph: `options`'
/// resolution and seed, no shortcutting (the turn shortcuts as RRT-Connect does), at most
/// `searches` searches.
fn graph_options(options: &RrtOptions, searches: usize) -> PlanOptions {
    PlanOptions {
        resolution: options.resolution,
        shortcuts: 0,
        seed: options.seed,
        exact_goal: false,
        sampling: None,
        max_searches: Some(searches),
        ..Default::default()
    }
}

/// Nodes and edges [`Planner::connect`]'s lazy searches through the graph may visit in all
/// (each search visits the whole graph at worst): on a map of 300 nodes and 1 400 edges, 4
/// searches; on a few kept paths, [`MAX_GRAPH_SEARCHES`].
pub const GRAPH_SEARCH_WORK: usize = 8192;

/// The most searches [`Planner::connect`] gives the graph, however small.
pub const MAX_GRAPH_SEARCHES: usize = 32;

impl Planner {
    /// The A* searches [`Planner::connect`] gives the lazy search through the graph (each
    /// followed by the checks of the path it found) before it returns to RRT-Connect:
    /// [`GRAPH_SEARCH_WORK`] over the graph's nodes and edges, at least 2 and at most
    /// [`MAX_GRAPH_SEARCHES`].
    pub fn graph_searches(&self) -> usize {
        (GRAPH_SEARCH_WORK / self.graph_elements()).clamp(2, MAX_GRAPH_SEARCHES)
    }

    /// The searches each of [`Planner::connect`]'s turns through the graph adds:
    /// [`GRAPH_SEARCH_WORK`] / [`GRAPH_TURNS`] over the graph's nodes and edges, at least 1,
    /// at most [`Planner::graph_searches`] (a small graph, as a few kept paths make, gets all
    /// its searches in its first turn).
    pub fn graph_turn_searches(&self) -> usize {
        (GRAPH_SEARCH_WORK / GRAPH_TURNS / self.graph_elements()).clamp(1, self.graph_searches())
    }

    /// The most of a query's effort [`Planner::connect`] gives the graph: [`GRAPH_SHARE`] times
    /// the share of its recent turns that answered (one answered counted beforehand, the last
    /// [`GRAPH_MEMORY`] queries or so): a graph that keeps failing (kept paths of other scenes,
    /// a map blocked here) costs less and less, one that answers keeps its share.
    pub fn graph_share(&self) -> f64 {
        GRAPH_SHARE * self.graph_record.rate()
    }

    /// The graph's nodes and edges (at least 1).
    fn graph_elements(&self) -> usize {
        (self.nodes.len() + self.edges.len()).max(1)
    }
}

impl Planner {
    /// What makes `q` (active values) collide in the current world, one line per colliding
    /// pair of links (or link and object; a held object counts as a part of its own) at its
    /// deepest contact, deepest first: the robot's links, held objects and the world's objects
    /// by name, and for
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
        // a body is part of a link, or of an object the robot holds
        let held = |body: usize| {
            let body = &collision.bodies()[body].name;
            collision.attached().iter().position(|o| o.holds(body))
        };
        let part = |body: usize| match held(body) {
            Some(k) => robot.num_links() + k,
            None => link(body),
        };
        let who = |body: usize| match held(body) {
            Some(k) => {
                let o = &collision.attached()[k];
                format!("held object `{}` (on `{}`)", o.name, o.link)
            }
            None => format!("link `{}`", name(link(body))),
        };
        // one line per pair of parts (or part and object), its deepest contact, deepest first
        let mut pairs = collision.colliding_pairs(&placed, self.checker.world());
        let key = |p: &trm_collision::CollidingPair| match p.other {
            trm_collision::Other::Body(_) => (part(p.body_index), part(p.other_index), false),
            trm_collision::Other::Object(_) => (part(p.body_index), p.other_index, true),
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
                        format!("{} and object `{object}`, {depth}", who(p.body_index))
                    }
                    trm_collision::Other::Body(_) => {
                        let (a, b) = (link(p.body_index), link(p.other_index));
                        let why = if held(p.body_index).is_some() || held(p.other_index).is_some() {
                            "a held object is checked against every link but its touch links"
                                .to_string()
                        } else {
                            match self.own_acm.reason(a, b) {
                                Some(reason) => format!(
                                    "checked by the matrix set on the planner (a scene's); the model's own disables it ({})",
                                    reason.as_str()
                                ),
                                None => "checked by the model's own matrix".into(),
                            }
                        };
                        let (x, y) = (p.body_index, p.other_index);
                        if held(x).is_none() && held(y).is_none() {
                            format!("links `{}` and `{}`, {depth}: {why}", name(a), name(b))
                        } else {
                            format!("{} and {}, {depth}: {why}", who(x), who(y))
                        }
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
            } if reason.starts_with(GOAL_COLLIDES) => PlanError::Unreachable {
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

#[cfg(test)]
mod tests {
    use super::{GRAPH_MEMORY, GraphRecord};

    /// Turns that fail shrink the graph's share to about 1 / GRAPH_MEMORY and no further; a
    /// turn that answers lifts it at once.
    #[test]
    fn the_graphs_share_follows_its_recent_turns() {
        let mut record = GraphRecord::default();
        assert_eq!(record.rate(), 1.0);
        for _ in 0..3 {
            record.unpaid();
        }
        assert_eq!(record.rate(), 0.25);
        // past the memory the counts are halved: the share stays between about 1/GRAPH_MEMORY
        // and twice that
        for _ in 0..100 {
            record.unpaid();
            let rate = record.rate();
            assert!(rate > 1.0 / (GRAPH_MEMORY + 2.0) && rate < 0.25, "{rate}");
        }
        assert!(record.rate() < 2.5 / GRAPH_MEMORY, "{}", record.rate());
        let before = record.rate();
        record.paid();
        assert!(
            record.rate() > 1.5 * before,
            "{} after {before}",
            record.rate()
        );
        for _ in 0..10 {
            record.paid();
        }
        assert!(record.rate() > 0.5, "{}", record.rate());
    }
}
