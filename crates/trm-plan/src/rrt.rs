//! RRT-Connect (Kuffner and LaValle, 2000) in an objective's active configuration space, for the
//! queries maps do not answer: two trees, one from the start and one from the goal, grown
//! towards random samples and towards each other until they meet; the path then shortcut.
//! Edges are checked raked, as VAMP checks them: the interpolation points of an edge spread over
//! the lanes of one batched check, so a collision anywhere on it is usually found in the first
//! batch. Seeded, so a query is reproducible; bounded by iterations and, optionally, time.

use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trm_collision::{World, WorldChecker};
use trm_tasks::Objective;

use crate::PlanError;
pub use crate::samples::{BOX_DRAWS_BEFORE_DOMAINS, Sampler};
use crate::samples::{DrawTally, Samples, domain_draw, weigh_domains};
pub use crate::simplify::{
    EdgeCheck, SMOOTHING_MIN_CHANGE, SMOOTHING_ROUNDS, path_length, shortcut,
};
use crate::simplify::{prove_path, recheck, simplified_finer};

/// RRT-Connect settings.
#[derive(Debug, Clone, PartialEq)]
pub struct RrtOptions {
    /// Seed of the sampler.
    pub seed: u64,
    /// Longest step a tree grows by, rad (Euclidean in configuration space).
    pub range: f64,
    /// Largest gap between checked points of an edge, rad.
    pub resolution: f64,
    /// Most samples extended from before giving up (samples outside the dynamic domain are not
    /// counted; see [`MAX_DRAWS_PER_SAMPLE`]).
    pub max_iterations: usize,
    /// Time budget, s (`None`: only the iteration budget; reproducible).
    pub max_seconds: Option<f64>,
    /// Random shortcut attempts on the found path after the greedy pass (0 by default: on
    /// MotionBenchMaker's Panda set 100 attempts shortened paths by 7 % but tripled the median
    /// time, and their corner-cutting edges graze obstacles between checked points).
    pub shortcuts: usize,
    /// Rounds of corner cutting after the shortcuts ([`shortcut`]): each interior waypoint
    /// `v` between `a` and `b` moved to `(a + 6v + b) / 8` where the corner's two new edges
    /// (from the midpoints of `a v` and `v b`) are free, then the greedy pass again, until a
    /// round changes nothing — VAMP's B-spline step and shortcut, alternated as its simplifier
    /// does ([`SMOOTHING_ROUNDS`] by default; 0: the greedy pass only).
    pub smoothing: usize,
    /// Dynamic domain (Jaillet, Yershova, LaValle and Siméon, IROS 2005), as VAMP grows its
    /// trees: a node whose extension hit an obstacle takes samples only within a radius of it
    /// (first `domain_radius`, shrinking by [`DOMAIN_ALPHA`] at each failure down to
    /// [`DOMAIN_MIN_RADIUS`], growing at each success); farther samples are drawn again
    /// without a collision check, from the domains themselves after
    /// [`BOX_DRAWS_BEFORE_DOMAINS`] misses (the same distribution, at a cost that does not grow
    /// as the domains shrink).
    pub dynamic_domain: bool,
    /// A dynamic domain's first radius, rad ([`DOMAIN_RADIUS`] by default, VAMP's; sized by the
    /// motor count in [`RrtOptions::sized`]).
    pub domain_radius: f64,
    /// Grow the smaller tree (the trees swap roles only while their sizes are within a factor
    /// of 2), as VAMP does; otherwise they alternate.
    pub balance: bool,
    /// Where samples come from.
    pub sampler: Sampler,
    /// Certified paths: the returned path is proved free in continuous motion
    /// ([`WorldChecker::prove`]: the robot padded on the fast checker, then exact distances and
    /// lever-arm bounds), not only free at its checked points. RRT-Connect proves each segment
    /// of its simplified path in place of checking it again at half the resolution, and
    /// replaces a segment it cannot prove by a search between its ends whose every accepted
    /// edge is proved; [`crate::Planner::connect`] proves the paths its maps give as well.
    pub certified: bool,
}

/// Searches run again at a finer resolution (each halving it) at most, where a path grazes an
/// obstacle between its checked points.
const REFINEMENTS: u32 = 2;

/// Draws per counted sample at most: samples outside every dynamic domain are drawn again
/// without a collision check and not counted in [`RrtOptions::max_iterations`], up to this
/// many times its value in all.
pub const MAX_DRAWS_PER_SAMPLE: usize = 100;

/// First radius of a node's dynamic domain after a failed extension, rad (VAMP's default, for
/// a robot of [`STEP_MOTORS`] motors; [`RrtOptions::sized`] scales it).
pub const DOMAIN_RADIUS: f64 = 4.0;
/// Relative change of a domain radius per failed (−) or successful (+) extension.
pub const DOMAIN_ALPHA: f64 = 1e-4;
/// Smallest domain radius, rad.
pub const DOMAIN_MIN_RADIUS: f64 = 1.0;

/// What a user sets for one query ([`crate::Planner::rrt_options_within`]); the rest of
/// RRT-Connect's settings are sized for the robot.
#[derive(Debug, Clone, PartialEq)]
pub struct Budget {
    /// Seed of the sampler.
    pub seed: u64,
    /// Time budget, s (`None`: only the sample budget; reproducible).
    pub max_seconds: Option<f64>,
    /// Most samples ([`RrtOptions::max_iterations`]).
    pub max_samples: usize,
    /// Largest gap between checked points of an edge, rad (`None`: sized for the robot).
    pub resolution: Option<f64>,
    /// Longest step a tree grows by, rad (`None`: sized for the robot).
    pub range: Option<f64>,
    /// Certified paths ([`RrtOptions::certified`]).
    pub certified: bool,
    /// Corner-cutting rounds ([`RrtOptions::smoothing`]).
    pub smoothing: usize,
}

impl Default for Budget {
    fn default() -> Self {
        Budget {
            seed: 0,
            max_seconds: None,
            max_samples: 1_000_000,
            resolution: None,
            range: None,
            certified: false,
            smoothing: SMOOTHING_ROUNDS,
        }
    }
}

impl Default for RrtOptions {
    fn default() -> Self {
        RrtOptions {
            seed: 0,
            range: 1.0,
            resolution: 1.0 / 32.0,
            max_iterations: 100_000,
            max_seconds: None,
            shortcuts: 0,
            smoothing: SMOOTHING_ROUNDS,
            dynamic_domain: true,
            domain_radius: DOMAIN_RADIUS,
            balance: true,
            sampler: Sampler::default(),
            certified: false,
        }
    }
}

/// The farthest one step of RRT-Connect may move a point of the robot's bodies, by the lever
/// bound ([`trm_collision::Levers::max_reach`]), for a robot of [`STEP_MOTORS`] motors, m
/// ([`RrtOptions::sized`]). 2 m gives VAMP's hand-tuned 1 rad on the Panda (largest lever
/// 2.01 m/rad).
pub const STEP_TRAVEL: f64 = 2.0;

/// The motor count [`STEP_TRAVEL`] is stated for: a robot of `n` motors steps
/// `√(STEP_MOTORS / n)` as far (fitted on VAMP's hand-tuned steps: 1 rad for the 7-motor
/// Panda, 0.5 rad for the 14-motor Baxter). A step moving more bodies at once hits something
/// sooner: on MotionBenchMaker's Baxter set (30 problems per family, 2 s) RRT-Connect solved
/// 54 % with the Panda's step, 87 % with the lever bound alone and 99 % with this factor.
pub const STEP_MOTORS: f64 = 7.0;

/// The farthest a point of the robot's bodies may move between checked points of an edge, by
/// the lever bound, m: [`RrtOptions::sized`]'s resolution is this over the robot's largest
/// lever (1/16 m gives the Panda VAMP's 1/32 rad).
pub const CHECK_TRAVEL: f64 = 1.0 / 16.0;

impl RrtOptions {
    /// RRT-Connect's settings for `collision`'s robot moving `active`'s motors: the robot's own
    /// (its model description's `planning`: `trm_kinematics::PlanningSpec`) where it gives
    /// them, else sized by its lever arms ([`RrtOptions::sized`]).
    pub fn for_robot(
        collision: &trm_collision::CollisionModel,
        active: &trm_kinematics::ActiveSet,
    ) -> Result<RrtOptions, PlanError> {
        let sized = RrtOptions::sized(&trm_collision::Levers::new(collision, active)?);
        let own = collision.robot().planning();
        Ok(RrtOptions {
            range: own.range.unwrap_or(sized.range),
            resolution: own.resolution.unwrap_or(sized.resolution),
            domain_radius: own.domain_radius.unwrap_or(sized.domain_radius),
            ..sized
        })
    }

    /// The default settings with the step, the resolution and the dynamic domains sized by the
    /// robot instead of by hand, from the largest displacement of any body point per radian of
    /// the `n` active coordinates (`levers`, a bound for every configuration): `range` =
    /// [`STEP_TRAVEL`] / reach · √([`STEP_MOTORS`] / n), `resolution` = [`CHECK_TRAVEL`] /
    /// reach and `domain_radius` = [`DOMAIN_RADIUS`] · √(n / [`STEP_MOTORS`]). A robot twice the
    /// Panda's size steps half as far and checks twice as densely; a dual-arm robot is sized by
    /// its longer arm and steps shorter for moving both; distances between configurations grow
    /// as √n, and so do the domains (with VAMP's 4 rad on a 14-motor robot, most draws fall
    /// outside every domain and are drawn again). The defaults when no coordinate moves a body.
    pub fn sized(levers: &trm_collision::Levers) -> RrtOptions {
        let defaults = RrtOptions::default();
        let (reach, motors) = (levers.max_reach(), levers.num_coordinates());
        if !(reach.is_finite() && reach > 0.0) || motors == 0 {
            return defaults;
        }
        let motors = motors as f64;
        RrtOptions {
            range: STEP_TRAVEL / reach * (STEP_MOTORS / motors).sqrt(),
            resolution: CHECK_TRAVEL / reach,
            domain_radius: DOMAIN_RADIUS * (motors / STEP_MOTORS).sqrt(),
            ..defaults
        }
    }

    /// Checks the settings' ranges.
    pub fn check(&self) -> Result<(), PlanError> {
        let bad = |what: &str, problem: String| PlanError::InvalidOptions {
            what: what.into(),
            problem,
        };
        if !(self.range.is_finite() && self.range > 0.0) {
            return Err(bad(
                "range",
                format!("{} is not a positive finite step", self.range),
            ));
        }
        if !(self.resolution.is_finite() && self.resolution >= 1e-6) {
            return Err(bad(
                "resolution",
                format!(
                    "{} is not a finite step of at least 1e-6 rad",
                    self.resolution
                ),
            ));
        }
        if !(self.domain_radius.is_finite() && self.domain_radius > 0.0) {
            return Err(bad(
                "domain_radius",
                format!("{} is not a positive finite radius", self.domain_radius),
            ));
        }
        if let Some(s) = self.max_seconds {
            if !(s.is_finite() && s > 0.0) {
                return Err(bad(
                    "max_seconds",
                    format!("{s} is not a positive finite time"),
                ));
            }
        }
        if self.max_iterations == 0 {
            return Err(bad("max_iterations", "0 draws no sample".into()));
        }
        Ok(())
    }
}

/// What a search found and what it cost.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RrtPath {
    /// Waypoints from the start to the goal (shortcut).
    pub path: Vec<Vec<f64>>,
    /// Waypoints before shortcutting.
    pub raw_waypoints: usize,
    /// Samples drawn.
    pub iterations: usize,
    /// Nodes of both trees.
    pub nodes: usize,
    /// Configurations checked for collision.
    pub checks: u64,
    /// Wall time, s.
    pub seconds: f64,
    /// Of [`RrtPath::seconds`], the time spent simplifying the path the trees made
    /// (shortcutting and checking the result again), s: the rest is planning.
    pub simplify_seconds: f64,
    /// Searches run again at a finer resolution because the path grazed an obstacle.
    pub refinements: u32,
    /// Whether the path is proved free in continuous motion ([`RrtOptions::certified`]).
    pub proved: bool,
}

/// Draws of a search between two reads of the clock for its time limit.
const CLOCK_EVERY: usize = 64;

/// Nodes per block of [`Tree::blocks`]: one 4-wide `f64` vector instruction per coordinate.
const SCAN_LANES: usize = 4;

/// A tree of configurations: node `i` at `nodes[i * dim..]`, and again in blocks of
/// [`SCAN_LANES`] nodes coordinate by coordinate (`blocks[(b * dim + k) * SCAN_LANES + l]` is
/// coordinate `k` of node `b * SCAN_LANES + l`), which the nearest-node scan reads four nodes
/// at a time.
struct Tree {
    dim: usize,
    nodes: Vec<f64>,
    blocks: Vec<f64>,
    parents: Vec<usize>,
    /// Dynamic-domain radius of each node (infinite until an extension from it fails).
    radii: Vec<f64>,
    /// Where a step goes, reused.
    to: Vec<f64>,
}

impl Tree {
    fn new(root: &[f64]) -> Self {
        let mut tree = Tree {
            dim: root.len(),
            nodes: Vec::new(),
            blocks: Vec::new(),
            parents: Vec::new(),
            radii: Vec::new(),
            to: vec![0.0; root.len()],
        };
        tree.push(root, usize::MAX);
        tree
    }

    /// Adds node `q`, a child of `parent`.
    fn push(&mut self, q: &[f64], parent: usize) {
        let (i, dim) = (self.len(), self.dim);
        if i % SCAN_LANES == 0 {
            // a new block, its unused lanes infinitely far
            self.blocks
                .resize(self.blocks.len() + dim * SCAN_LANES, f64::INFINITY);
        }
        let (block, lane) = (i / SCAN_LANES, i % SCAN_LANES);
        for (k, &v) in q.iter().enumerate() {
            self.blocks[(block * dim + k) * SCAN_LANES + lane] = v;
        }
        self.nodes.extend_from_slice(q);
        self.parents.push(parent);
        self.radii.push(f64::INFINITY);
    }

    /// Number of nodes.
    fn len(&self) -> usize {
        self.parents.len()
    }

    /// Node `i`.
    fn node(&self, i: usize) -> &[f64] {
        &self.nodes[i * self.dim..(i + 1) * self.dim]
    }

    /// The node nearest to `q` (the first of equally near ones) and its distance.
    fn nearest(&self, q: &[f64]) -> (usize, f64) {
        nearest_in_blocks(&self.blocks, q)
    }

    /// Root → node `i`.
    fn path_to(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        while i != usize::MAX {
            out.push(self.node(i).to_vec());
            i = self.parents[i];
        }
        out.reverse();
        out
    }
}

/// [`Tree::nearest`] over its `blocks`, compiled for several instruction sets with the best
/// one chosen at run time (four nodes per AVX instruction).
#[allow(unsafe_code)] // multiversion's run-time CPU-feature dispatch
#[multiversion::multiversion(targets("x86_64+avx2+fma", "x86_64+avx", "aarch64+neon"))]
fn nearest_in_blocks(blocks: &[f64], q: &[f64]) -> (usize, f64) {
    // per lane, the nearest of the nodes it holds; each distance summed coordinate by
    // coordinate as a one-node loop would (no fused multiply-add: the same sums everywhere)
    let (mut best, mut index) = ([f64::INFINITY; SCAN_LANES], [0usize; SCAN_LANES]);
    for (b, block) in blocks.chunks_exact(q.len() * SCAN_LANES).enumerate() {
        let mut d = [0.0; SCAN_LANES];
        for (column, &x) in block.chunks_exact(SCAN_LANES).zip(q) {
            for l in 0..SCAN_LANES {
                let e = column[l] - x;
                d[l] += e * e;
            }
        }
        for l in 0..SCAN_LANES {
            if d[l] < best[l] {
                best[l] = d[l];
                index[l] = b * SCAN_LANES + l;
            }
        }
    }
    let mut nearest = (index[0], best[0]);
    for l in 1..SCAN_LANES {
        if best[l] < nearest.1 || (best[l] == nearest.1 && index[l] < nearest.0) {
            nearest = (index[l], best[l]);
        }
    }
    (nearest.0, nearest.1.sqrt())
}

enum Extend {
    Reached(usize),
    Advanced(usize),
    Trapped,
    /// Outside the nearest node's dynamic domain: nothing checked.
    Outside,
}

/// One step of `tree` from its node nearest to `target` towards it (at most `range`); with
/// `domain`, the nearest node's dynamic domain bounds where it goes and learns from the step.
fn extend(
    tree: &mut Tree,
    target: &[f64],
    options: &RrtOptions,
    checker: &mut WorldChecker,
    domain: bool,
) -> Extend {
    let (near, d) = tree.nearest(target);
    extend_from(tree, (near, d), target, options, checker, domain)
}

/// [`extend`] from `tree`'s node `near`, the nearest to `target` at distance `d`.
fn extend_from(
    tree: &mut Tree,
    (near, d): (usize, f64),
    target: &[f64],
    options: &RrtOptions,
    checker: &mut WorldChecker,
    domain: bool,
) -> Extend {
    if domain && d > tree.radii[near] {
        return Extend::Outside;
    }
    let reached = d <= options.range;
    let mut to = std::mem::take(&mut tree.to);
    if reached {
        to.copy_from_slice(target);
    } else {
        let s = options.range / d;
        for ((t, a), b) in to.iter_mut().zip(tree.node(near)).zip(target) {
            *t = a + s * (b - a);
        }
    }
    let free = checker.edge_and_end_free(tree.node(near), &to, options.resolution);
    if free {
        tree.push(&to, near);
    }
    tree.to = to;
    if !free {
        if domain {
            let r = &mut tree.radii[near];
            *r = if r.is_infinite() {
                options.domain_radius
            } else {
                // never below the first radius, were that set below the floor
                (*r * (1.0 - DOMAIN_ALPHA)).max(DOMAIN_MIN_RADIUS.min(options.domain_radius))
            };
        }
        return Extend::Trapped;
    }
    if domain && tree.radii[near].is_finite() {
        tree.radii[near] *= 1.0 + DOMAIN_ALPHA;
    }
    let i = tree.len() - 1;
    if reached {
        Extend::Reached(i)
    } else {
        Extend::Advanced(i)
    }
}

/// A collision-free path from `start` to `goal` in `world` (both checked first), by RRT-Connect
/// in the box of the active motors' limits, then shortcut.
///
/// The shortcut path is checked again at half the resolution: the points halfway between those
/// its edges were checked at ([`WorldChecker::edge_midpoints_free`], raked as every edge; the pieces
/// of edges a random shortcut or a corner cut made, at all their points). Where the simplified
/// path grazes an obstacle between the points first checked (random shortcuts and corner cuts
/// make edges no search visited), the search's own path is simplified again with its new edges
/// checked at half the resolution, else taken through the greedy pass alone, if either passes
/// the same check; else the search runs again at that finer resolution (at most twice), so a
/// returned path is free at `resolution / 2` wherever it was checked. [`RrtPath::refinements`]
/// counts the reruns. With [`RrtOptions::certified`] the path is proved free in continuous
/// motion instead (see there).
pub fn rrt_connect(
    objective: &Objective,
    world: &World,
    start: &[f64],
    goal: &[f64],
    options: &RrtOptions,
) -> Result<RrtPath, PlanError> {
    options.check()?;
    let mut checker = objective.world_checker(world)?;
    rrt_connect_in(
        &mut checker,
        &objective.active().bounds(),
        start,
        goal,
        options,
    )
}

/// [`rrt_connect`] with a checker already made for the robot and the world (a planner's, kept
/// between queries: nothing is compiled per query), sampling within `bounds` (lower and upper
/// limits of the checker's coordinates). [`RrtPath::checks`] counts this query's checks only.
pub fn rrt_connect_in(
    checker: &mut WorldChecker,
    bounds: &(Vec<f64>, Vec<f64>),
    start: &[f64],
    goal: &[f64],
    options: &RrtOptions,
) -> Result<RrtPath, PlanError> {
    options.check()?;
    let began = Instant::now();
    let growth = Growth::new(checker, start, goal, options)?;
    growth.finish(checker, bounds, options, began)
}

/// An RRT-Connect query under way: its two trees grow in as many rounds as its caller wants
/// ([`Growth::grow`]), and [`Growth::finish`] ends it as [`rrt_connect_in`] would have (a
/// planner tries its graph between a first round and the rest).
pub(crate) struct Growth {
    start: Vec<f64>,
    goal: Vec<f64>,
    /// The tree the next sample extends, and the other.
    a: Tree,
    b: Tree,
    a_is_start: bool,
    rng: ChaCha8Rng,
    samples: Samples,
    sample: Vec<f64>,
    draws: usize,
    /// Draws from the dynamic domains ([`domain_draw`]), a stream of its own.
    domain_rng: ChaCha8Rng,
    /// Draws of the current sample so far that fell outside every domain.
    rejected: usize,
    /// [`weigh_domains`] of the growing tree for the current sample, once `weighed`.
    domains: Vec<f64>,
    weighed: bool,
    /// Which way of drawing lands in a domain more often.
    tally: DrawTally,
    result: RrtPath,
    /// The path the trees made, once they met (or the straight segment).
    raw: Option<Vec<Vec<f64>>>,
    /// The checker's count when the query began.
    before: u64,
}

impl Growth {
    /// A query from `start` to `goal` at `options.resolution`: both checked, then the straight
    /// segment (many queries need nothing else).
    pub(crate) fn new(
        checker: &mut WorldChecker,
        start: &[f64],
        goal: &[f64],
        options: &RrtOptions,
    ) -> Result<Self, PlanError> {
        let dim = checker.dim();
        for (what, q) in [("start", start), ("goal", goal)] {
            if q.len() != dim || q.iter().any(|v| !v.is_finite()) {
                return Err(PlanError::InvalidGoal {
                    problem: format!(
                        "the {what} has {} values (or a non-finite one) for {dim} active motors",
                        q.len()
                    ),
                    fix: format!("give {dim} finite values"),
                });
            }
        }
        let before = checker.checks;
        if !checker.free(start) {
            return Err(PlanError::InvalidStart("it collides in the world".into()));
        }
        if !checker.free(goal) {
            return Err(PlanError::Unreachable {
                reason: format!("{GOAL_COLLIDES} in the world"),
                closest_node: None,
                closest_distance: f64::INFINITY,
            });
        }
        let raw = checker
            .edge_free(start, goal, options.resolution)
            .then(|| vec![start.to_vec(), goal.to_vec()]);
        Ok(Growth {
            start: start.to_vec(),
            goal: goal.to_vec(),
            a: Tree::new(start),
            b: Tree::new(goal),
            a_is_start: true,
            rng: ChaCha8Rng::seed_from_u64(options.seed),
            samples: Samples::new(options.sampler, options.seed, dim),
            sample: vec![0.0; dim],
            draws: 0,
            domain_rng: {
                let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
                rng.set_stream(1);
                rng
            },
            rejected: 0,
            domains: Vec::new(),
            weighed: false,
            tally: DrawTally::default(),
            result: RrtPath::default(),
            raw,
            before,
        })
    }

    /// Samples drawn so far.
    pub(crate) fn iterations(&self) -> usize {
        self.result.iterations
    }

    /// Grows the trees until they meet, `max_iterations` samples in all are drawn, or
    /// `options.max_seconds` from `began` have passed; whether they met.
    pub(crate) fn grow(
        &mut self,
        checker: &mut WorldChecker,
        (lower, upper): &(Vec<f64>, Vec<f64>),
        options: &RrtOptions,
        max_iterations: usize,
        began: Instant,
    ) -> bool {
        let Growth {
            a, b, a_is_start, ..
        } = self;
        while self.raw.is_none() && self.result.iterations < max_iterations {
            // the clock read once per [`CLOCK_EVERY`] draws: most draws of a grown tree cost
            // less
            if self.draws.is_multiple_of(CLOCK_EVERY)
                && options
                    .max_seconds
                    .is_some_and(|s| began.elapsed().as_secs_f64() > s)
            {
                break;
            }
            self.draws += 1;
            if self.draws > options.max_iterations.saturating_mul(MAX_DRAWS_PER_SAMPLE) {
                break;
            }
            // after a few draws outside every domain, drawn from the domains themselves where
            // that lands in one more often
            let missing = options.dynamic_domain && self.rejected >= BOX_DRAWS_BEFORE_DOMAINS;
            if missing && !self.weighed {
                weigh_domains(&a.radii, a.dim, &mut self.domains);
                self.weighed = true;
            }
            let domain = missing && !self.domains.is_empty() && self.tally.next_from_domains();
            let step = if domain {
                let bounds = (lower.as_slice(), upper.as_slice());
                let from = domain_draw(
                    (&a.nodes, &a.radii),
                    &self.domains,
                    &mut self.domain_rng,
                    bounds,
                    &mut self.sample,
                );
                match from.map(|i| (i, a.nearest(&self.sample))) {
                    Some((i, near)) if near.0 == i => {
                        extend_from(a, near, &self.sample, options, checker, true)
                    }
                    // outside the box, or nearer another node
                    _ => Extend::Outside,
                }
            } else {
                self.samples.next(lower, upper, &mut self.sample);
                extend(a, &self.sample, options, checker, options.dynamic_domain)
            };
            let outside = matches!(step, Extend::Outside);
            if options.dynamic_domain {
                self.tally.record(domain, !outside);
            }
            let new = match step {
                // outside the dynamic domain: drawn again, not counted as a sample
                Extend::Outside => {
                    self.rejected += 1;
                    continue;
                }
                Extend::Trapped => None,
                Extend::Reached(i) | Extend::Advanced(i) => Some(i),
            };
            (self.rejected, self.weighed) = (0, false);
            self.result.iterations += 1;
            if let Some(i) = new {
                let target = a.node(i).to_vec();
                loop {
                    match extend(b, &target, options, checker, false) {
                        Extend::Advanced(_) => continue,
                        Extend::Trapped | Extend::Outside => break,
                        Extend::Reached(j) => {
                            let (from_a, from_b) = (a.path_to(i), b.path_to(j));
                            let (mut first, second) = if *a_is_start {
                                (from_a, from_b)
                            } else {
                                (from_b, from_a)
                            };
                            // the meeting point is in both halves
                            first.pop();
                            first.extend(second.into_iter().rev());
                            self.raw = Some(first);
                            break;
                        }
                    }
                }
            }
            // balanced: the next sample grows the smaller tree
            let (na, nb) = (a.len() as f64, b.len() as f64);
            if !options.balance || (na - nb).abs() / na < 1.0 {
                std::mem::swap(a, b);
                *a_is_start = !*a_is_start;
            }
        }
        self.raw.is_some()
    }

    /// Grows the trees within `options`' budget and ends the query as [`rrt_connect_in`]
    /// does: the path shortcut and checked again at half the resolution, the search run again
    /// at a finer resolution where the path grazes an obstacle (at most twice).
    pub(crate) fn finish(
        self,
        checker: &mut WorldChecker,
        bounds: &(Vec<f64>, Vec<f64>),
        options: &RrtOptions,
        began: Instant,
    ) -> Result<RrtPath, PlanError> {
        let before = self.before;
        let (start, goal) = (self.start.clone(), self.goal.clone());
        let (mut iterations, mut simplify) = (0, 0.0);
        let mut growth = Some(self);
        for refinement in 0..=REFINEMENTS {
            let resolution = options.resolution / f64::from(1u32 << refinement);
            let attempt = RrtOptions {
                resolution,
                ..options.clone()
            };
            let mut g = match growth.take() {
                Some(g) => g,
                None => Growth::new(checker, &start, &goal, &attempt)?,
            };
            g.grow(checker, bounds, &attempt, attempt.max_iterations, began);
            let simplifying = Instant::now();
            let (mut found, edges, raw) = g.shortcut(checker, &attempt, began)?;
            // a certified path is proved, which its points at half the resolution add nothing
            // to; a search whose checker proves every edge it accepts has proved its path
            found.proved = options.certified || checker.is_proving();
            let mut free = match (checker.is_proving(), options.certified) {
                (true, _) => true,
                (false, true) => {
                    prove_path(checker, bounds, &mut found.path, options)?;
                    true
                }
                (false, false) => {
                    recheck(checker, &found.path, &edges, resolution, options.resolution)
                }
            };
            if !free
                && let Some(again) = simplified_finer(checker, &raw, &attempt, options.resolution)
            {
                found.path = again;
                free = true;
            }
            if !free && (attempt.shortcuts > 0 || attempt.smoothing > 0) {
                // random shortcuts and corner cuts make edges no search visited, which may
                // graze an obstacle at every resolution (a finer search's paths are checked at
                // the first resolution's points too): the search's own path through the
                // greedy pass only, rather than a new search
                let greedy_only = RrtOptions {
                    shortcuts: 0,
                    smoothing: 0,
                    ..attempt.clone()
                };
                let mut plain = raw;
                // no random shortcut: the generator is not drawn from
                let mut unused = ChaCha8Rng::seed_from_u64(0);
                let edges = shortcut(&mut plain, &greedy_only, checker, &mut unused);
                if recheck(checker, &plain, &edges, resolution, options.resolution) {
                    found.path = plain;
                    free = true;
                }
            }
            iterations += found.iterations;
            simplify += simplifying.elapsed().as_secs_f64();
            if free {
                found.simplify_seconds = simplify;
                found.checks = checker.checks - before;
                found.iterations = iterations;
                found.refinements = refinement;
                found.seconds = began.elapsed().as_secs_f64();
                return Ok(found);
            }
        }
        Err(PlanError::Unreachable {
            reason: format!(
                "every path RRT-Connect found grazed an obstacle between its checked points, down to a resolution of {} rad",
                options.resolution / f64::from(1u32 << REFINEMENTS)
            ),
            closest_node: None,
            closest_distance: f64::INFINITY,
        })
    }

    /// The trees' path shortcut ([`shortcut`]), with how each edge was checked, and the path
    /// as the trees gave it; an error when the trees have not met.
    fn shortcut(
        mut self,
        checker: &mut WorldChecker,
        options: &RrtOptions,
        began: Instant,
    ) -> Result<Shortcut, PlanError> {
        self.result.nodes = self.a.len() + self.b.len();
        let Some(mut path) = self.raw.take() else {
            return Err(PlanError::Unreachable {
                reason: format!(
                    "RRT-Connect found no path in {} samples ({} nodes, {:.3} s)",
                    self.result.iterations,
                    self.result.nodes,
                    began.elapsed().as_secs_f64()
                ),
                closest_node: None,
                closest_distance: f64::INFINITY,
            });
        };
        self.result.raw_waypoints = path.len();
        let raw = path.clone();
        let edges = shortcut(&mut path, options, checker, &mut self.rng);
        self.result.path = path;
        self.result.checks = checker.checks - self.before;
        self.result.seconds = began.elapsed().as_secs_f64();
        Ok((self.result, edges, raw))
    }
}

/// A path shortcut, how each of its edges was checked, and the path before the shortcut.
type Shortcut = (RrtPath, Vec<EdgeCheck>, Vec<Vec<f64>>);

/// How the reason of the error of a query whose goal collides begins.
pub(crate) const GOAL_COLLIDES: &str = "the goal configuration collides";

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    #[test]
    fn the_blocked_scan_finds_the_first_nearest_node_as_a_plain_scan_does() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for dim in [1, 2, 7, 8, 41] {
            let mut samples = Samples::new(Sampler::Uniform, 5, dim);
            let (lower, upper) = (vec![-1.0; dim], vec![1.0; dim]);
            let mut q = vec![0.0; dim];
            samples.next(&lower, &upper, &mut q);
            let mut tree = Tree::new(&q);
            let mut plain = vec![q.clone()];
            for n in 1..40 {
                // repeated nodes too: ties go to the first
                if n % 7 == 0 {
                    q = plain[rng.random_range(0..plain.len())].clone();
                } else {
                    samples.next(&lower, &upper, &mut q);
                }
                assert!(q.iter().all(|v| (-1.0..1.0).contains(v)), "{q:?}");
                tree.push(&q, 0);
                plain.push(q.clone());
                for _ in 0..20 {
                    let mut target = vec![0.0; dim];
                    samples.next(&lower, &upper, &mut target);
                    if rng.random_range(0..4) == 0 {
                        target = plain[rng.random_range(0..plain.len())].clone();
                    }
                    let mut best = (0, f64::INFINITY);
                    for (i, p) in plain.iter().enumerate() {
                        let d: f64 = p.iter().zip(&target).map(|(x, y)| (x - y) * (x - y)).sum();
                        if d < best.1 {
                            best = (i, d);
                        }
                    }
                    assert_eq!(tree.nearest(&target), (best.0, best.1.sqrt()), "dim {dim}");
                    assert_eq!(tree.node(best.0), plain[best.0].as_slice());
                }
            }
        }
    }

    #[test]
    fn settings_out_of_range_are_refused_by_name() {
        let cases: [(&str, RrtOptions); 5] = [
            (
                "range",
                RrtOptions {
                    range: 0.0,
                    ..Default::default()
                },
            ),
            (
                "resolution",
                RrtOptions {
                    resolution: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "domain_radius",
                RrtOptions {
                    domain_radius: -1.0,
                    ..Default::default()
                },
            ),
            (
                "max_seconds",
                RrtOptions {
                    max_seconds: Some(0.0),
                    ..Default::default()
                },
            ),
            (
                "max_iterations",
                RrtOptions {
                    max_iterations: 0,
                    ..Default::default()
                },
            ),
        ];
        for (what, options) in cases {
            let e = options.check().unwrap_err().to_string();
            assert!(e.contains(what), "{what}: {e}");
        }
        assert!(RrtOptions::default().check().is_ok());
    }
}
