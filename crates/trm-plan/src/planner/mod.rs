//! The lazy roadmap planner.

use std::time::Instant;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_collision::edge::distance;
use trm_collision::{World, WorldChecker};
use trm_kinematics::ActiveSet;
use trm_roadmap::Roadmap;
use trm_tasks::Objective;

use crate::PlanError;
use crate::query::{EXACT_WEIGHT, ExactGoal, Goal, PlanOptions, PlanStats, Planned};
use crate::rrt::{Budget, GOAL_COLLIDES, RrtOptions};

mod connect;
mod experience;
mod held;
mod search;
mod timed;
pub use connect::{
    Connection, GOAL_ATTEMPTS, GRAPH_MEMORY, GRAPH_SEARCH_WORK, GRAPH_TURNS, HEAD_START_SAMPLES,
    MAX_GRAPH_SEARCHES, ROUND_GROWTH, Source,
};
pub use experience::{EXPERIENCE_FORMAT, EXPERIENCE_VERSION};

#[derive(Debug, Clone, Copy, PartialEq)]
enum State {
    Unknown,
    Valid,
    Invalid,
}

/// A kept path's or a query's key for [`Planner::retrieve`]'s look-up: the sum of the values of
/// its two ends (the same either way round).
fn ends_key(a: &[f64], b: &[f64]) -> f64 {
    a.iter().chain(b).sum()
}

/// How near, in steps of the planning resolution, both ends of a query must lie to a kept path's
/// ends for [`Planner::plan`] to try that path before searching: a query that repeats one
/// planned before.
pub const RETRIEVE_STEPS: f64 = 2.0;

/// A planner for one robot, compiled once: its collision checks in a current world (set and
/// replaced without recompiling the robot), an optional graph of maps and kept paths
/// (experience) whose nodes and edges are checked lazily in that world, and RRT-Connect for
/// what the graph does not answer.
///
/// Two kinds of query: [`Planner::connect`] joins two configurations (the graph when it has
/// nodes, else or where it fails RRT-Connect; the query MotionBenchMaker and MoveIt ask), and
/// [`Planner::plan`] reaches task-space goals through the maps (and configuration goals, with
/// a timed trajectory).
///
/// ```
/// use trm_collision::{CollisionModel, Shape, World};
/// use trm_kinematics::nalgebra::Isometry3;
/// use trm_plan::Planner;
/// use trm_plan::rrt::RrtOptions;
///
/// let robot = trm_models::icub_upper_body();
/// let home = robot.posture("home")?.to_vec();
/// let active = robot.active_set(&["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"], &home)?;
/// let mut world = World::new();
/// world.add("pole", Shape::Box { size: [0.04, 0.04, 2.0] }, Isometry3::translation(-0.25, 0.3, 0.0))?;
/// let objective = trm_tasks::Objective::new(active, CollisionModel::new(&robot)?, world);
/// let mut planner = Planner::new(&objective, &[])?;
/// let start = objective.active().from_motors(&home);
/// let goal = vec![start[0] - 1.2, start[1] + 0.6, start[2] + 0.5];
/// let motion = planner.connect(&start, &goal, &RrtOptions::default())?;
/// assert_eq!(motion.path.first(), Some(&start));
/// assert_eq!(motion.path.last(), Some(&goal));
/// // the world moves: the robot is not compiled again
/// planner.set_world(World::new());
/// assert!(planner.is_free(&goal));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Planner {
    objective: Objective,
    active: ActiveSet,
    /// The active motors' lower and upper limits (RRT-Connect's sampling box).
    bounds: (Vec<f64>, Vec<f64>),
    /// The allowed-collision matrix the planner was made with (before [`Planner::set_acm`]).
    own_acm: trm_collision::AllowedCollisionMatrix,
    nodes: Vec<(Vec<f64>, Vec<f64>)>,
    node_state: Vec<State>,
    /// Per node: whether a map brought it (else a kept path did).
    map_node: Vec<bool>,
    /// The nodes (and two for a query's start and goal) and edges as the graph a query
    /// searches, built on first use and dropped when nodes or edges change
    /// ([`Planner::graph_changed`]).
    query_base: Option<petgraph::graph::UnGraph<(), usize>>,
    /// How [`Planner::connect`]'s recent turns through the graph fared.
    graph_record: connect::GraphRecord,
    edges: Vec<(usize, usize, f64)>,
    edge_state: Vec<State>,
    scratch: trm_tasks::Scratch,
    /// Checks in the current world.
    checker: WorldChecker,
    /// The paths kept by [`Planner::add_path`]: their nodes and edges, in order.
    kept: Vec<(Vec<usize>, Vec<usize>)>,
    /// The kept paths' first and last waypoints, twice the active motors' values per path, in
    /// [`Planner::kept`]'s order: what a retrieval's scan reads, in one sweep.
    kept_ends: Vec<f64>,
    /// Each kept path's key ([`ends_key`]: the sum of its ends' values) and its index in
    /// [`Planner::kept`], sorted by key: a retrieval reads only the paths whose keys lie near
    /// the query's.
    kept_keys: Vec<(f64, usize)>,
    /// Per kept path: the graph's nodes, edges and maps before it was kept (what
    /// [`Planner::forget_last_path`] goes back to).
    kept_from: Vec<(usize, usize, usize)>,
    /// [`Planner::rrt_options`], worked out on first use (the robot's bodies and active motors
    /// do not change; an allowed-collision matrix does not move a body).
    rrt: std::sync::OnceLock<RrtOptions>,
    /// Maps attached so far.
    maps: usize,
    /// Whether [`Planner::plan`] times its path (a search that wants only the waypoints, as
    /// [`Planner::connect`]'s through the graph, turns it off while it runs).
    time_paths: bool,
}

impl Planner {
    /// A planner over `maps` (built for the same active motors as `objective`), in the world the
    /// objective was built with. Map nodes and edges are trusted until the world changes; maps
    /// are joined by edges from each node to its nearest nodes of every other map (checked when
    /// A* first wants them).
    pub fn new(objective: &Objective, maps: &[&Roadmap]) -> Result<Self, PlanError> {
        let mut planner = Planner {
            checker: objective.world_checker(objective.world())?,
            time_paths: true,
            objective: objective.clone(),
            active: objective.active().clone(),
            bounds: objective.active().bounds(),
            own_acm: objective.collision().acm().clone(),
            node_state: Vec::new(),
            nodes: Vec::new(),
            map_node: Vec::new(),
            query_base: None,
            graph_record: Default::default(),
            edges: Vec::new(),
            edge_state: Vec::new(),
            scratch: objective.scratch(),
            kept: Vec::new(),
            kept_ends: Vec::new(),
            kept_keys: Vec::new(),
            kept_from: Vec::new(),
            rrt: std::sync::OnceLock::new(),
            maps: 0,
        };
        let mut starts = Vec::with_capacity(maps.len() + 1);
        for map in maps {
            starts.push(planner.nodes.len());
            planner.push_map(map, State::Valid)?;
        }
        starts.push(planner.nodes.len());
        // between maps: each node to its 3 nearest nodes of every later map
        for (ma, mb) in (0..maps.len()).flat_map(|a| (a + 1..maps.len()).map(move |b| (a, b))) {
            for i in starts[ma]..starts[ma + 1] {
                let near = k_nearest(
                    &planner.nodes[i].0,
                    &planner.nodes,
                    starts[mb]..starts[mb + 1],
                    3,
                );
                for (l, j) in near {
                    planner.edges.push((i, j, l));
                    planner.edge_state.push(State::Unknown);
                }
            }
        }
        Ok(planner)
    }

    /// Attaches `map` (built for the same active motors, in any world and with any model of the
    /// robot) to the planner's graph: its nodes and edges are checked in the current world when a
    /// search first wants them, and each node is joined to its 3 nearest nodes of the graph
    /// already there (maps and kept paths). Returns the number of nodes added.
    pub fn add_map(&mut self, map: &Roadmap) -> Result<usize, PlanError> {
        self.graph_changed();
        let base = self.nodes.len();
        self.push_map(map, State::Unknown)?;
        for i in base..self.nodes.len() {
            for (l, j) in k_nearest(&self.nodes[i].0, &self.nodes, 0..base, 3) {
                self.edges.push((i, j, l));
                self.edge_state.push(State::Unknown);
            }
        }
        Ok(self.nodes.len() - base)
    }

    /// Adds the next map's nodes and own edges in `state` (an error when its active motors are
    /// not the planner's).
    fn push_map(&mut self, map: &Roadmap, state: State) -> Result<(), PlanError> {
        self.graph_changed();
        if map
            .active
            .iter()
            .map(String::as_str)
            .ne(self.active.names())
        {
            let ours: Vec<&str> = self.active.names().collect();
            return Err(PlanError::IncompatibleMap {
                map: self.maps,
                problem: format!(
                    "its active motors ({}) differ from the planner's ({})",
                    map.active.join(", "),
                    ours.join(", ")
                ),
            });
        }
        let base = self.nodes.len();
        self.nodes
            .extend(map.points.iter().map(|p| (p.q.clone(), p.t.clone())));
        self.node_state.resize(self.nodes.len(), state);
        self.map_node.resize(self.nodes.len(), true);
        for &(a, b, l) in &map.edges {
            self.edges.push((base + a, base + b, l));
            self.edge_state.push(state);
        }
        self.maps += 1;
        Ok(())
    }

    /// Drops the query graph kept for the nodes and edges: they are about to change.
    fn graph_changed(&mut self) {
        self.query_base = None;
    }

    /// The current world.
    pub fn world(&self) -> &World {
        self.checker.world()
    }

    /// Replaces the world. What the nodes' and edges' checks found so far is kept where the
    /// change cannot alter it: when objects were only removed, what was found free stays free
    /// (what was blocked will be checked again when a search wants it); when objects were only
    /// added, what was found blocked stays blocked; otherwise (an object moved or changed)
    /// everything will be checked again. Objects are compared by name, shape and pose.
    pub fn set_world(&mut self, world: World) {
        let (old, new) = (self.checker.world(), &world);
        let within = |a: &World, b: &World| {
            a.objects().iter().all(|o| {
                b.object(o.name())
                    .is_ok_and(|p| p.shape() == o.shape() && p.pose() == o.pose())
            })
        };
        // the states a check could now answer differently
        let stale: &[State] = match (within(new, old), within(old, new)) {
            (true, true) => &[],
            (true, false) => &[State::Invalid],
            (false, true) => &[State::Valid],
            (false, false) => &[State::Valid, State::Invalid],
        };
        for state in self.node_state.iter_mut().chain(&mut self.edge_state) {
            if stale.contains(state) {
                *state = State::Unknown;
            }
        }
        self.checker.set_world(world);
    }

    /// Replaces the allowed-collision matrix (a planning scene's, applied over the robot's own:
    /// see `trm_moveit::load_scene`): when it differs from the current one, the checks are made
    /// again for it and every node and edge will be checked again. Whether it differed.
    pub fn set_acm(
        &mut self,
        acm: trm_collision::AllowedCollisionMatrix,
    ) -> Result<bool, PlanError> {
        if *self.objective.collision().acm() == acm {
            return Ok(false);
        }
        let collision = self.objective.collision().with_acm(acm)?;
        self.set_collision(&collision)
    }

    /// Replaces the collision model by the same robot's with another allowed-collision matrix
    /// or other held objects (a problem's, prepared once: its compiled screen is shared, not
    /// compiled again), as [`Planner::set_acm`] does. Whether the model differed.
    pub fn set_collision(
        &mut self,
        collision: &trm_collision::CollisionModel,
    ) -> Result<bool, PlanError> {
        let current = self.objective.collision();
        if current.acm() == collision.acm() && current.attached() == collision.attached() {
            return Ok(false);
        }
        if current.attached() != collision.attached() {
            // a held object changes the lever arms RRT-Connect's settings are sized by
            self.rrt = Default::default();
        }
        self.objective.set_collision(collision.clone())?;
        let world = self.checker.world().clone();
        let checks = self.checker.checks;
        self.checker = self.objective.world_checker(&world)?;
        self.checker.checks = checks;
        self.node_state.fill(State::Unknown);
        self.edge_state.fill(State::Unknown);
        Ok(true)
    }

    /// RRT-Connect's settings for this robot and these active motors
    /// ([`RrtOptions::for_robot`]: the model description's, else sized by the bodies' lever
    /// arms). Callers override what their user set.
    pub fn rrt_options(&self) -> Result<RrtOptions, PlanError> {
        if let Some(options) = self.rrt.get() {
            return Ok(options.clone());
        }
        let options = RrtOptions::for_robot(self.objective.collision(), &self.active)?;
        Ok(self.rrt.get_or_init(|| options).clone())
    }

    /// RRT-Connect's settings for one query: [`Planner::rrt_options`] with what `budget` sets.
    pub fn rrt_options_within(&self, budget: &Budget) -> Result<RrtOptions, PlanError> {
        let sized = self.rrt_options()?;
        Ok(RrtOptions {
            seed: budget.seed,
            max_seconds: budget.max_seconds,
            max_iterations: budget.max_samples,
            resolution: budget.resolution.unwrap_or(sized.resolution),
            range: budget.range.unwrap_or(sized.range),
            certified: budget.certified,
            smoothing: budget.smoothing,
            ..sized
        })
    }

    /// The active motors the planner moves (its configurations' coordinates).
    pub fn active(&self) -> &ActiveSet {
        &self.active
    }

    /// The objective the planner was made with (its robot, collision model and maps' costs).
    pub fn objective(&self) -> &Objective {
        &self.objective
    }

    /// Keeps a path (active values, free in the current world, e.g. one RRT-Connect found) as
    /// experience: its waypoints join the graph as nodes (a waypoint within 1e-9 rad of a node
    /// is that node), its segments as edges known free in the current world, and each new node
    /// is joined to its 3 nearest older nodes by edges checked when a search first wants them.
    /// Later queries, in this world or another (after [`Planner::set_world`]), search through
    /// it; a query that repeats the path's ends tries the path itself first
    /// ([`Planner::plan`]). Returns the number of nodes added; an error for a path without
    /// waypoints or a waypoint that is not one finite value per active motor.
    pub fn add_path(&mut self, path: &[Vec<f64>]) -> Result<usize, PlanError> {
        let d = self.active.len();
        if path.is_empty() {
            return Err(PlanError::InvalidOptions {
                what: "experience path".into(),
                problem: "the path has no waypoints".into(),
            });
        }
        if let Some(bad) = path
            .iter()
            .find(|q| q.len() != d || q.iter().any(|v| !v.is_finite()))
        {
            return Err(PlanError::InvalidOptions {
                what: "experience path".into(),
                problem: format!("a waypoint has {} values, not {d} finite ones", bad.len()),
            });
        }
        self.graph_changed();
        let old = self.nodes.len();
        self.kept_from.push((old, self.edges.len(), self.maps));
        let mut ids = Vec::with_capacity(path.len());
        for q in path {
            let same = (0..self.nodes.len()).find(|&i| distance(&self.nodes[i].0, q) <= 1e-9);
            let id = match same {
                Some(i) => i,
                None => {
                    let t = self.task_of(q);
                    self.nodes.push((q.clone(), t));
                    self.node_state.push(State::Valid);
                    self.map_node.push(false);
                    let me = self.nodes.len() - 1;
                    for (l, j) in k_nearest(q, &self.nodes, 0..old, 3) {
                        self.edges.push((me, j, l));
                        self.edge_state.push(State::Unknown);
                    }
                    me
                }
            };
            ids.push(id);
        }
        ids.dedup();
        let mut edges = Vec::with_capacity(ids.len());
        for w in ids.windows(2) {
            let l = distance(&self.nodes[w[0]].0, &self.nodes[w[1]].0);
            edges.push(self.edges.len());
            self.edges.push((w[0], w[1], l));
            self.edge_state.push(State::Valid);
        }
        for end in [ids[0], ids[ids.len() - 1]] {
            self.kept_ends.extend_from_slice(&self.nodes[end].0);
        }
        let key = ends_key(&self.nodes[ids[0]].0, &self.nodes[ids[ids.len() - 1]].0);
        let at = self.kept_keys.partition_point(|&(k, _)| k <= key);
        self.kept_keys.insert(at, (key, self.kept.len()));
        self.kept.push((ids, edges));
        Ok(self.nodes.len() - old)
    }

    /// Number of nodes over all maps.
    pub fn num_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Number of edges (map and inter-map).
    pub fn num_edges(&self) -> usize {
        self.edges.len()
    }

    /// Whether `q` is collision-free in the current world.
    ///
    /// # Panics
    /// If `q` does not hold one value per active motor.
    pub fn is_free(&mut self, q: &[f64]) -> bool {
        self.checker.free(q)
    }

    /// Whether the straight segment a → b is free, both ends included, at points no more than
    /// `resolution` apart (Euclidean, the rule of RRT-Connect's edges:
    /// [`trm_collision::edge::edge_steps`]), visited raked ([`WorldChecker::segment_free`]).
    pub fn segment_free(&mut self, a: &[f64], b: &[f64], resolution: f64) -> bool {
        self.checker.segment_free(a, b, resolution)
    }

    fn task_of(&mut self, q: &[f64]) -> Vec<f64> {
        self.objective.task_value(q, &mut self.scratch)
    }

    /// Plans from `start` (active values, need not be a map node) to `goal`. A task-point goal
    /// with the exact finish on and no reachable node within its tolerance, but one within
    /// twice it, goes through that node and lets NGIK cover the rest; it is unreachable only
    /// when that fails too.
    pub fn plan(
        &mut self,
        start: &[f64],
        goal: &Goal,
        options: &PlanOptions,
    ) -> Result<Planned, PlanError> {
        let planned = self.plan_once(start, goal, options);
        // a configuration goal the maps do not reach: the sampling planner finishes the query
        if let (Err(PlanError::Unreachable { .. }), Goal::Configuration(q), Some(rrt)) =
            (&planned, goal, &options.sampling)
        {
            let began = Instant::now();
            let found = crate::rrt::rrt_connect_in(&mut self.checker, &self.bounds, start, q, rrt)?;
            let mut stats = PlanStats {
                sampled: Some((found.iterations, found.checks)),
                length: crate::rrt::path_length(&found.path),
                ..Default::default()
            };
            let trajectory = self.trajectory(&found.path, &options.timing)?;
            stats.seconds = began.elapsed().as_secs_f64();
            return Ok(Planned {
                trajectory,
                nodes: Vec::new(),
                waypoints: found.path,
                stats,
            });
        }
        // a task point with no reachable node within the tolerance but one within twice it:
        // through that node, and NGIK the rest of the way
        if let (
            Err(PlanError::Unreachable {
                closest_node: Some(_),
                closest_distance,
                ..
            }),
            Goal::TaskPoint { t, tolerance },
            true,
        ) = (&planned, goal, options.exact_goal)
            && *closest_distance > *tolerance
            && *closest_distance <= 2.0 * tolerance
        {
            let wider = Goal::TaskPoint {
                t: t.clone(),
                tolerance: closest_distance * (1.0 + 1e-9) + 1e-12,
            };
            if let Ok(p) = self.plan_once(start, &wider, options)
                && matches!(p.stats.exact, ExactGoal::Reached { .. })
            {
                return Ok(p);
            }
        }
        planned
    }

    /// [`Planner::plan`] with the goal as given.
    fn plan_once(
        &mut self,
        start: &[f64],
        goal: &Goal,
        options: &PlanOptions,
    ) -> Result<Planned, PlanError> {
        let began = Instant::now();
        self.check_query(start, goal, options)?;
        // a kept path repeating the query first: before the start and goal are joined to the
        // graph, which a query answered so (or allowed no search) does not need
        if let Goal::Configuration(q) = goal {
            if let Some(planned) = self.retrieve(start, q, options, began)? {
                return Ok(planned);
            }
            if options.max_searches == Some(0) {
                return Err(PlanError::Unreachable {
                    reason: "no kept path repeats the query, and no search is allowed".into(),
                    closest_node: None,
                    closest_distance: f64::INFINITY,
                });
            }
        }
        let mut lazy = self.lazy_search(start, goal, options)?;
        self.search_lazily(&mut lazy, options, options.max_searches, began)
    }

    /// Checks a query's options, start and goal: an error says what is wrong.
    fn check_query(
        &mut self,
        start: &[f64],
        goal: &Goal,
        options: &PlanOptions,
    ) -> Result<(), PlanError> {
        options.check()?;
        if start.len() != self.active.len() {
            return Err(PlanError::InvalidStart(format!(
                "{} values for {} active motors",
                start.len(),
                self.active.len()
            )));
        }
        if let Some(k) = start.iter().position(|v| !v.is_finite()) {
            return Err(PlanError::InvalidStart(format!(
                "start[{k}] is {}",
                start[k]
            )));
        }
        let task_dim = self.objective.task().map_or(0, |t| t.dim());
        goal.check(self.active.len(), task_dim)?;
        if !self.is_free(start) {
            return Err(PlanError::InvalidStart(
                "it collides in the current world".into(),
            ));
        }
        Ok(())
    }

    /// The query's own edges: the start (node n) and a configuration goal (node n + 1) joined
    /// to their nearest map nodes and to each other; and the goal configuration, if any.
    fn query_edges(
        &mut self,
        start: &[f64],
        goal: &Goal,
        options: &PlanOptions,
    ) -> Result<(Vec<Edge>, Option<Vec<f64>>), PlanError> {
        let n = self.nodes.len();
        let mut extra: Vec<Edge> = Vec::new();
        let attach = |q: &[f64], me: usize, extra: &mut Vec<Edge>| {
            for (l, j) in k_nearest(q, &self.nodes, 0..n, options.attach_neighbours) {
                extra.push((me, j, l));
            }
        };
        attach(start, n, &mut extra);
        let Goal::Configuration(q) = goal else {
            return Ok((extra, None));
        };
        attach(q, n + 1, &mut extra);
        extra.push((n, n + 1, distance(start, q)));
        if !self.is_free(q) {
            return Err(PlanError::Unreachable {
                reason: format!("{GOAL_COLLIDES} in the current world"),
                closest_node: None,
                closest_distance: f64::INFINITY,
            });
        }
        Ok((extra, Some(q.clone())))
    }

    /// The map node of `candidates` nearest to the task point `t` (the first of equally near
    /// ones).
    fn closest_to(&self, candidates: impl Iterator<Item = usize>, t: &[f64]) -> Option<usize> {
        candidates.min_by(|&a, &b| {
            distance(&self.nodes[a].1, t).total_cmp(&distance(&self.nodes[b].1, t))
        })
    }

    /// The query is unreachable, for `reason`; `closest` is the reachable node nearest to the
    /// goal's task point `t`.
    fn unreachable(&self, reason: &str, closest: Option<usize>, t: &[f64]) -> PlanError {
        PlanError::Unreachable {
            reason: match closest {
                Some(_) => reason.into(),
                None => format!("{reason}; no map node is reachable"),
            },
            closest_node: closest,
            closest_distance: closest.map_or(f64::INFINITY, |c| distance(&self.nodes[c].1, t)),
        }
    }

    /// Checks lazily the nodes, then the edges, of a path [`Planner::search`] found, recording
    /// what it learns; whether the path is free.
    fn path_valid(
        &mut self,
        path: &[(usize, usize)],
        extra: &[(usize, usize, f64)],
        extra_state: &mut [State],
        stats: &mut PlanStats,
        options: &PlanOptions,
        config: impl Fn(usize, &Self) -> Vec<f64>,
    ) -> bool {
        let n = self.nodes.len();
        let mut blocked = false;
        for &(i, _) in path {
            if i < n && self.node_state[i] == State::Unknown && !self.node_free(i) {
                stats.nodes_invalid += 1;
                blocked = true;
            }
        }
        if blocked {
            return false;
        }
        debug_assert!(extra_state.len() == extra.len());
        for w in path.windows(2) {
            let ((a, _), (b, k)) = (w[0], w[1]);
            let state = if k < self.edges.len() {
                self.edge_state[k]
            } else {
                extra_state[k - self.edges.len()]
            };
            if state != State::Unknown {
                continue;
            }
            let (qa, qb) = (config(a, self), config(b, self));
            stats.edges_checked += 1;
            let ok = self.segment_free(&qa, &qb, options.resolution);
            let new = if ok { State::Valid } else { State::Invalid };
            if k < self.edges.len() {
                self.edge_state[k] = new;
            } else {
                extra_state[k - self.edges.len()] = new;
            }
            if !ok {
                stats.edges_invalid += 1;
                return false;
            }
        }
        true
    }

    /// A free path's waypoints shortcut, finished onto a task point when asked, timed.
    fn finish(
        &mut self,
        mut waypoints: Vec<Vec<f64>>,
        nodes: Vec<usize>,
        goal: &Goal,
        options: &PlanOptions,
        mut stats: PlanStats,
        began: Instant,
    ) -> Result<Planned, PlanError> {
        self.shortcut(&mut waypoints, options);
        if let Goal::TaskPoint { t, .. } = goal {
            if options.exact_goal {
                stats.exact = self.finish_exactly(&mut waypoints, t, options);
            }
            let end = waypoints.last().cloned().unwrap_or_default();
            stats.goal_error = Some(distance(&self.task_of(&end), t));
        }
        stats.length = waypoints.windows(2).map(|w| distance(&w[0], &w[1])).sum();
        let trajectory = self.timed_if_asked(&waypoints, &options.timing)?;
        stats.seconds = began.elapsed().as_secs_f64();
        Ok(Planned {
            trajectory,
            nodes,
            waypoints,
            stats,
        })
    }

    /// The kept path whose ends lie nearest to `start` and `goal` (either way round), when both
    /// lie within [`RETRIEVE_STEPS`] steps of `options.resolution` of them and the path with
    /// its two joining edges is free in the current world (its nodes and edges checked as a
    /// search checks them, states kept): experience retrieved as Lightning retrieves it
    /// (Berenson, Abbeel and Goldberg, ICRA 2012), for queries that repeat one planned before.
    pub(crate) fn retrieve(
        &mut self,
        start: &[f64],
        goal: &[f64],
        options: &PlanOptions,
        began: Instant,
    ) -> Result<Option<Planned>, PlanError> {
        let near = RETRIEVE_STEPS * options.resolution;
        let d = self.active.len();
        // only the paths whose keys lie near the query's: ends within `near` of the query's
        // (either way round) move the sum of the 2d values by at most 2·√d·near (a hair
        // more for rounding)
        let key = ends_key(start, goal);
        let reach = 2.0 * (d as f64).sqrt() * near * (1.0 + 1e-6) + 1e-9 * (1.0 + key.abs());
        let from = self.kept_keys.partition_point(|&(k, _)| k < key - reach);
        // a cheap test first: most candidates end far away in their first coordinates (the
        // bound is a hair wider than `near`, so that the distances alone decide)
        let wide = near * near * (1.0 + 1e-9) + f64::MIN_POSITIVE;
        let close = |a: &[f64], b: &[f64]| {
            let mut sum = 0.0;
            a.iter().zip(b).all(|(x, y)| {
                sum += (x - y) * (x - y);
                sum <= wide
            })
        };
        let Some((k, reversed)) = self.kept_keys[from..]
            .iter()
            .take_while(|&&(k, _)| k <= key + reach)
            .filter_map(|&(_, k)| {
                let (first, last) = self.kept_ends[2 * d * k..2 * d * (k + 1)].split_at(d);
                let forward = close(start, first) && close(goal, last);
                let backward = close(start, last) && close(goal, first);
                if !forward && !backward {
                    return None;
                }
                let forward = distance(start, first).max(distance(goal, last));
                let backward = distance(start, last).max(distance(goal, first));
                let (d, reversed) = (forward.min(backward), backward < forward);
                (d <= near).then_some((k, d, reversed))
            })
            // the nearest, the first kept among equals
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
            .map(|(k, _, reversed)| (k, reversed))
        else {
            return Ok(None);
        };
        let (mut ids, mut edges) = self.kept[k].clone();
        if reversed {
            ids.reverse();
            edges.reverse();
        }
        let mut stats = PlanStats::default();
        if !ids.iter().all(|&i| self.node_free(i)) {
            return Ok(None);
        }
        for (&e, w) in edges.iter().zip(ids.windows(2)) {
            if self.edge_state[e] == State::Unknown {
                let (a, b) = (self.nodes[w[0]].0.clone(), self.nodes[w[1]].0.clone());
                stats.edges_checked += 1;
                self.edge_state[e] = if self.segment_free(&a, &b, options.resolution) {
                    State::Valid
                } else {
                    State::Invalid
                };
            }
            if self.edge_state[e] == State::Invalid {
                return Ok(None);
            }
        }
        let mut waypoints: Vec<Vec<f64>> = ids.iter().map(|&i| self.nodes[i].0.clone()).collect();
        // the joining edges (none where an end is the node itself)
        for (end, at_start) in [(start, true), (goal, false)] {
            let node = if at_start {
                &waypoints[0]
            } else {
                &waypoints[waypoints.len() - 1]
            };
            if distance(end, node) > 1e-9 {
                let node = node.clone();
                stats.edges_checked += 1;
                if !self.segment_free(end, &node, options.resolution) {
                    return Ok(None);
                }
                if at_start {
                    waypoints.insert(0, end.to_vec());
                } else {
                    waypoints.push(end.to_vec());
                }
            }
        }
        stats.path_nodes = ids.len();
        stats.retrieved = true;
        self.shortcut(&mut waypoints, options);
        stats.length = waypoints.windows(2).map(|w| distance(&w[0], &w[1])).sum();
        let trajectory = self.timed_if_asked(&waypoints, &options.timing)?;
        stats.seconds = began.elapsed().as_secs_f64();
        Ok(Some(Planned {
            trajectory,
            nodes: ids,
            waypoints,
            stats,
        }))
    }

    /// Whether map node `i` is free in the current world: checked the first time it is asked,
    /// its state kept.
    fn node_free(&mut self, i: usize) -> bool {
        if self.node_state[i] == State::Unknown {
            let q = self.nodes[i].0.clone();
            self.node_state[i] = if self.is_free(&q) {
                State::Valid
            } else {
                State::Invalid
            };
        }
        self.node_state[i] == State::Valid
    }

    /// Appends a posture at the task point `t` reached by NGIK from the last waypoint, when it
    /// is within the tolerance and collision-free, joined by a free straight segment or, when
    /// that is blocked, by a short plan through the map to it.
    fn finish_exactly(
        &mut self,
        waypoints: &mut Vec<Vec<f64>>,
        t: &[f64],
        options: &PlanOptions,
    ) -> ExactGoal {
        let fallback = |reason: String| ExactGoal::Fallback { reason };
        let Some(last) = waypoints.last().cloned() else {
            return fallback("the path is empty".into());
        };
        let objective = match self.objective.with_task_target(t, EXACT_WEIGHT) {
            Ok(o) => o.with_world(self.checker.world().clone()),
            Err(e) => return fallback(e.to_string()),
        };
        let solver = trm_tasks::spec::SolverSpec {
            sigma: 0.02,
            population: Some(30),
            max_evaluations: options.exact_evaluations,
            no_improvement: Some(5_000.min(options.exact_evaluations)),
            seed: options.seed,
            ..Default::default()
        };
        let solution = match trm_tasks::solve(&objective, &last, &solver) {
            Ok(s) => s,
            Err(e) => return fallback(format!("NGIK failed: {e}")),
        };
        let error = distance(&solution.task, t);
        if error.is_nan() || error > options.exact_tolerance {
            return fallback(format!(
                "NGIK came within {error:.3e} of the goal, not {:.0e} (unreachable, or blocked in the current world)",
                options.exact_tolerance
            ));
        }
        if !self.is_free(&solution.q) {
            return fallback("the posture at the goal collides in the current world".into());
        }
        let mut detour = Vec::new();
        if !self.segment_free(&last, &solution.q, options.resolution) {
            // a short plan through the map to the goal posture (attached like a configuration
            // goal), instead of the blocked straight segment
            let local = PlanOptions {
                exact_goal: false,
                ..options.clone()
            };
            match self.plan(&last, &Goal::Configuration(solution.q.clone()), &local) {
                Ok(p) => {
                    detour = p
                        .trajectory
                        .positions
                        .iter()
                        .skip(1)
                        .map(|m| self.active.from_motors(m))
                        .collect();
                    detour.pop(); // the goal posture itself, pushed below
                }
                Err(_) => {
                    return fallback(
                        "the straight segment from the last map node to the goal posture collides, and no path through the map reaches that posture".into(),
                    );
                }
            }
        }
        let detour_len = detour.len();
        waypoints.extend(detour);
        waypoints.push(solution.q);
        ExactGoal::Reached {
            error,
            evaluations: solution.evaluations,
            detour: detour_len,
        }
    }

    /// Random shortcuts: replace the path between two waypoints by a straight segment when it is
    /// collision-free.
    fn shortcut(&mut self, waypoints: &mut Vec<Vec<f64>>, options: &PlanOptions) {
        let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
        for _ in 0..options.shortcuts {
            if waypoints.len() < 3 {
                break;
            }
            let i = rng.random_range(0..waypoints.len() - 2);
            let j = rng.random_range(i + 2..waypoints.len());
            let (a, b) = (waypoints[i].clone(), waypoints[j].clone());
            if self.segment_free(&a, &b, options.resolution) {
                waypoints.drain(i + 1..j);
            }
        }
    }
}

/// An edge of the planner's graph: its two nodes and its length.
type Edge = (usize, usize, f64);

/// Which nodes a query ends at: the goal configuration's node (n + 1), or the map nodes
/// within a task point's tolerance or a task region.
struct Target<'g> {
    goal: &'g Goal,
    /// Number of map nodes.
    n: usize,
}

impl Target<'_> {
    /// Whether node `i` is a goal node.
    fn holds(&self, i: usize, nodes: &[(Vec<f64>, Vec<f64>)]) -> bool {
        match self.goal {
            Goal::Configuration(_) => i == self.n + 1,
            Goal::TaskPoint { t, tolerance } => {
                i < self.n && distance(&nodes[i].1, t) <= *tolerance
            }
            Goal::TaskRegion { min, max } => {
                i < self.n
                    && nodes[i]
                        .1
                        .iter()
                        .enumerate()
                        .all(|(k, v)| *v >= min[k] && *v <= max[k])
            }
        }
    }
}

/// The `k` nodes of `candidates` nearest to `q` in configuration space, as (distance, index),
/// nearest first and ties by index (the order of a stable sort): a selection, then a sort of
/// `k` — not a sort of every node (experience graphs hold thousands).
fn k_nearest(
    q: &[f64],
    nodes: &[(Vec<f64>, Vec<f64>)],
    candidates: std::ops::Range<usize>,
    k: usize,
) -> Vec<(f64, usize)> {
    let order = |x: &(f64, usize), y: &(f64, usize)| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1));
    let mut near: Vec<(f64, usize)> = candidates.map(|j| (distance(q, &nodes[j].0), j)).collect();
    let k = k.min(near.len());
    if k > 0 && k < near.len() {
        near.select_nth_unstable_by(k - 1, order);
    }
    near.truncate(k);
    near.sort_unstable_by(order);
    near
}
