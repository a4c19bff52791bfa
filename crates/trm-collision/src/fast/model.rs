use super::LaneMask;
use super::kdop::{KDOP, kdop_of};
use super::lanes::{F, inverse_axes, norm, to_f32};
use super::outcome::{Tally, Verdict};
use super::solid::{SLOTS, Solid, SolidPair};
use super::table::{AngleReader, Angles, PairTable};
use super::walk::{FastScratch, screen};
use super::world::{FastWorld, Object};
use crate::error::CollisionError;
use crate::error::Result;
use crate::model::CollisionModel;
use crate::shape::Shape;
use nalgebra::Vector3;
use nalgebra::{Isometry3, Point3};
use std::collections::BTreeMap;
use std::sync::Arc;
use trm_kinematics::JointKind;
use trm_kinematics::PoseLanes32;

/// A sphere in the frame of its link.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ball {
    pub(super) center: [f32; 3],
    pub(super) radius: f32,
}

/// A link's spheres and the sphere bounding them (in the frame they are placed from,
/// [`Group::frame`]).
#[derive(Debug, Clone)]
pub(super) struct Group {
    /// Index of the pose in the pose batches its balls are placed from: the link's, or in a
    /// sphere model the pose of the link it is rigidly attached to
    /// ([`trm_kinematics::Tree::rigid_ancestor`]; its balls' centres are then in that frame).
    pub(super) frame: usize,
    pub(super) bound: Ball,
    /// The link's spheres: indices into [`FastModel::balls`].
    pub(super) balls: std::ops::Range<usize>,
    /// Spheres inside the link's bodies, when its spheres enclose them (not a sphere model):
    /// indices into [`FastModel::inner`]. Touching one is a certain collision.
    pub(super) inner: std::ops::Range<usize>,
    /// The link's bodies (indices into [`CollisionModel::bodies`]).
    pub(super) bodies: Vec<u32>,
    /// The link's body in the link frame when it is one box: other links' spheres are tested
    /// against the box itself, not against the spheres enclosing it.
    pub(super) solid: Option<Object>,
    /// When every body of the link is a convex hull: the polytope bounding them along the
    /// [`KDOP`] directions in the link frame, `[lowest, highest]` per direction. A sphere
    /// beyond one of its slabs is clear of the link's bodies.
    pub(super) kdop: Option<[[f32; 2]; KDOP.len()]>,
    /// When every body of the link is a box, a capsule or a sphere (and the model is not a
    /// sphere model): the bodies as solids, in the order of `bodies` (indices into
    /// [`FastModel::solids`]), tested as themselves against other such links.
    pub(super) solids: Option<std::ops::Range<usize>>,
}

/// Two balls (indices into [`FastModel::balls`]) and the sum of their radii.
pub(super) type BallPair = (u32, u32, f32);

/// A link pair's ball pairs and checked body pairs, while compiling.
pub(super) type LinkPairTests = (Vec<BallPair>, Vec<(u32, u32)>);

/// Two links whose spheres are tested against each other.
#[derive(Debug, Clone)]
pub(super) struct GroupPair {
    pub(super) a: usize,
    pub(super) b: usize,
    /// The two links' bounding spheres' radii summed.
    pub(super) reach: f32,
    /// Per ball of link `a`: the ball and its pairs with link `b`'s balls.
    pub(super) runs: Vec<Run>,
    /// The checked body pairs of the two links (indices into [`CollisionModel::bodies`]).
    pub(super) bodies: Vec<(u32, u32)>,
    /// Pairs of spheres inside the two links' checked bodies (indices into
    /// [`FastModel::inner`]) and the sums of their radii: touching is a certain collision.
    pub(super) inner: Vec<BallPair>,
    /// `(solid, other)` when one link is a box ([`Group::solid`]) checked against every body of
    /// the other: the other's spheres are tested against the box in its link's frame instead
    /// of the sphere pairs.
    pub(super) solid: Option<(usize, usize)>,
    /// When both links are solids ([`Group::solids`]): their checked body pairs as solids,
    /// tested instead of the spheres.
    pub(super) solid_pairs: Vec<SolidPair>,
    /// When one or two revolute joints alone move the two links relative to each other: the
    /// pair's clearance table (an index into [`FastModel::tables`]), consulted first.
    pub(super) table: Option<u32>,
}

/// A ball of one link of a [`GroupPair`] and its pairs with the other link's balls.
#[derive(Debug, Clone, Copy)]
pub(super) struct Run {
    /// The ball (an index into [`FastModel::balls`]).
    pub(super) ball: u32,
    /// Its radius plus the other link's bounding sphere's: farther from that sphere's centre,
    /// the ball misses every ball of the other link.
    pub(super) reach: f32,
    /// Its pairs, `start..end` of [`FastModel::pairs`].
    pub(super) start: u32,
    pub(super) end: u32,
}

/// One step of the self-collision walk, in the order of [`crate::cull`]'s steps.
#[derive(Debug, Clone, Copy)]
pub(super) enum CullStep {
    /// When spheres `a` and `b` (indices into [`FastScratch::bounds`]: link groups' bounding
    /// spheres, then culling spheres about link origins) whose radii sum to `reach` are apart
    /// in every lane, continue at step `end`.
    Cull {
        a: u32,
        b: u32,
        reach: f32,
        end: u32,
    },
    /// A link pair: `k` an index into [`FastModel::group_pairs`], `a` and `b` its groups
    /// (their bounding spheres' indices into [`FastScratch::bounds`]) and `reach` the sum of
    /// those spheres' radii, so that the walk tests them without reading the pair.
    Pair { k: u32, a: u32, b: u32, reach: f32 },
}

/// One step of a world object's walk, in the order of [`crate::cull`]'s world steps.
#[derive(Debug, Clone, Copy)]
pub(super) enum WorldStep {
    /// When the object is farther than `radius` from the centre `ball` (an index into
    /// [`FastScratch::bounds`]) in every lane, continue at step `end`.
    Cull { ball: u32, radius: f32, end: u32 },
    /// A link group: an index into [`FastModel::groups`].
    Link(u32),
}

/// What left lanes of a block uncertain: checked exactly, only it, in those lanes.
#[derive(Debug, Clone, Copy)]
pub(super) enum Suspect {
    /// A link pair: an index into [`FastModel::group_pairs`].
    Pair(u32),
    /// A world object and a link group.
    Object { object: u32, group: u32 },
}

/// A collision model compiled for single-precision checks of [`FAST_LANES`](super::FAST_LANES) configurations at
/// once (made by [`FastModel::new`]): its spheres, or the spheres enclosing its bodies.
#[derive(Debug, Clone)]
pub struct FastModel {
    pub(super) balls: Vec<Ball>,
    /// Spheres inside the bodies ([`Shape::inscribed_spheres`]), grouped by link.
    pub(super) inner: Vec<Ball>,
    /// Bodies tested as themselves ([`Group::solids`]), grouped by link.
    pub(super) solids: Vec<Solid>,
    /// Each solid's [`Solid::extent`], for the tolerances of its tests against world objects.
    pub(super) solid_extents: Vec<f32>,
    /// For each ball, the index of the body it came from.
    pub(super) bodies: Vec<usize>,
    pub(super) groups: Vec<Group>,
    pub(super) group_pairs: Vec<GroupPair>,
    /// Ball pairs and the sums of their radii.
    pub(super) pairs: Vec<BallPair>,
    /// Clearance tables of the link pairs that one or two revolute joints alone move
    /// ([`GroupPair::table`]).
    pub(super) tables: Vec<PairTable>,
    /// The tabled joints' angle readers ([`PairTable::lookup`]), one per joint.
    pub(super) readers: Vec<AngleReader>,
    /// The self-collision walk through the culling spheres (when `culls`): culls and link
    /// pairs.
    pub(super) steps: Vec<CullStep>,
    /// Each world object's walk through the culling spheres (when `culls`): culls and links.
    /// Without `culls`, when a frame holds [`FRAME_CULL_GROUPS`] groups: the groups, the last
    /// in the tree first, those of such a frame behind a cull by the sphere enclosing them
    /// ([`FastModel::frame_balls`]), each step against every object. Empty: the groups one
    /// by one, the last in the tree first, each against every object.
    pub(super) world_steps: Vec<WorldStep>,
    /// Whether the self walk takes `steps` ([`CULLED_LINK_PAIRS`]); else the link pairs in
    /// order.
    pub(super) culls: bool,
    /// Pose index of each culling sphere's link (after the groups in [`FastScratch::bounds`]).
    pub(super) origins: Vec<u32>,
    /// Spheres enclosing the groups that share a frame (its pose index and the centre in
    /// it), after the culling spheres in [`FastScratch::bounds`].
    pub(super) frame_balls: Vec<(u32, [f32; 3])>,
    /// Largest distance of any point of the robot from the world origin, in any configuration
    /// (a bound from the joint offsets).
    pub(super) reach: f64,
    /// Most movable joints between the root and a link.
    pub(super) depth: usize,
    /// Whether the spheres are the model itself (a sphere model), so that a certain contact is
    /// a certain collision; otherwise they enclose the bodies and only screen: contact is
    /// uncertain.
    pub(super) exact: bool,
}

impl FastModel {
    /// Compiles `model`: its spheres as they are when every body is a sphere, else the spheres
    /// enclosing each body ([`CollisionModel::enclosing_spheres`]), which only screen.
    pub fn new(model: &CollisionModel) -> Result<Self> {
        let exact = Self::is_sphere_model(model);
        let spheres = Spheres::of(model, exact)?;
        let (pairs, mut group_pairs) = spheres.pairs(model);
        // sphere models decide every lane in the screen; others leave lanes to exact checks,
        // which tables spare
        let (tables, readers) = if exact {
            (Vec::new(), Vec::new())
        } else {
            tables(model, &spheres.groups, &mut group_pairs)?
        };
        let walks = Walks::of(model, &spheres, &group_pairs);
        let (reach, depth) = reach_and_depth(model, &spheres.balls);
        Ok(FastModel {
            exact,
            depth,
            balls: spheres.balls,
            inner: spheres.inner,
            solid_extents: spheres.solids.iter().map(Solid::extent).collect(),
            solids: spheres.solids,
            bodies: spheres.ball_bodies,
            groups: spheres.groups,
            group_pairs,
            tables,
            readers,
            pairs,
            steps: walks.steps,
            world_steps: walks.world_steps,
            culls: walks.culls,
            origins: walks.origins,
            frame_balls: walks.frame_balls,
            reach,
        })
    }

    /// `model` compiled by [`FastModel::new`] once and kept with it: later calls (from clones
    /// of `model` too) share that compilation, so that checkers made per query cost no
    /// compiling.
    pub fn of(model: &CollisionModel) -> Result<Arc<FastModel>> {
        let cell = model.fast_cell();
        if let Some(fast) = cell.get() {
            return Ok(fast.clone());
        }
        let fast = Arc::new(FastModel::new(model)?);
        Ok(cell.get_or_init(|| fast).clone())
    }

    /// Whether every body of `model` is a sphere: whether [`FastModel::new`] makes an exact
    /// model of it ([`FastModel::is_exact`]), known without compiling it.
    pub fn is_sphere_model(model: &CollisionModel) -> bool {
        model
            .bodies()
            .iter()
            .all(|b| matches!(b.shape, Shape::Sphere { .. }))
    }

    /// Whether the spheres are the model itself (every body a sphere): its certain contacts
    /// are certain collisions. Otherwise the spheres enclose the bodies and only screen.
    pub fn is_exact(&self) -> bool {
        self.exact
    }

    /// Number of spheres.
    pub fn num_spheres(&self) -> usize {
        self.balls.len()
    }

    /// Number of sphere pairs self-collision checks may test.
    pub fn num_pairs(&self) -> usize {
        self.pairs.len()
    }

    /// A scratch buffer for [`FastModel::check`].
    pub fn scratch(&self) -> FastScratch {
        FastScratch {
            balls: vec![[F::default(); 3]; self.balls.len()],
            inner: vec![[F::default(); 3]; self.inner.len()],
            solids: vec![[[F::default(); 3]; SLOTS]; self.solids.len()],
            solid_placed: vec![false; self.groups.len()],
            bounds: vec![
                [F::default(); 3];
                self.groups.len() + self.origins.len() + self.frame_balls.len()
            ],
            frames: vec![([F::default(); 9], [F::default(); 3]); self.groups.len()],
            placed: vec![false; self.groups.len()],
            framed: vec![false; self.groups.len()],
            angles: Angles::new(self.readers.len()),
            suspects: Vec::with_capacity(self.group_pairs.len() + self.groups.len()),
            last_hit: None,
        }
    }

    /// The body of the collision model a sphere came from (spheres are ordered by link).
    pub fn body_of_sphere(&self, sphere: usize) -> usize {
        self.bodies[sphere]
    }

    /// Checks the configurations of a block against themselves and `world`: `poses` holds their
    /// link poses ([`PoseBlock::lanes`](trm_kinematics::PoseBlock::lanes) of the collision model's robot), `live` the lanes in
    /// use. Stops at the first certain collision.
    ///
    /// # Panics
    /// If the poses or the scratch belong to another model.
    pub fn check(
        &self,
        poses: &[PoseLanes32],
        live: LaneMask,
        world: &FastWorld,
        scratch: &mut FastScratch,
    ) -> Verdict {
        screen::<Verdict>(self, poses, live, world, scratch)
    }

    /// Counts, in the configurations of a block (as [`FastModel::check`] takes them), the link
    /// pairs and (link, object) pairs that certainly collide; the pairs left uncertain are
    /// kept in `scratch` for an exact check ([`FastChecker::count_unchecked`](crate::fast::FastChecker::count_unchecked) does both).
    ///
    /// # Panics
    /// If the poses or the scratch belong to another model.
    pub fn count(
        &self,
        poses: &[PoseLanes32],
        live: LaneMask,
        world: &FastWorld,
        scratch: &mut FastScratch,
    ) -> Tally {
        screen::<Tally>(self, poses, live, world, scratch)
    }
}

/// Fewest link pairs for which the self-collision walk takes the culling spheres: with fewer,
/// testing every link pair's bounding spheres in order is faster (measured: the Panda, 1.12×,
/// and the Fetch, 1.11×, slower with culls; the iCub's 958 link pairs 1.3× faster with them).
pub(super) const CULLED_LINK_PAIRS: usize = 256;

/// The spheres of a model's bodies grouped by link, while compiling.
struct Spheres {
    balls: Vec<Ball>,
    /// The body each ball came from.
    ball_bodies: Vec<usize>,
    groups: Vec<Group>,
    inner: Vec<Ball>,
    solids: Vec<Solid>,
    /// Per body: its solid (when its link's bodies are solids).
    solid_of_body: Vec<Option<usize>>,
    /// Per body: its spheres inside it, its group, its balls.
    inner_of_body: Vec<std::ops::Range<usize>>,
    group_of_body: Vec<usize>,
    balls_of_body: Vec<std::ops::Range<usize>>,
}

impl Spheres {
    /// The balls grouped by link, in link order: the bodies themselves (a sphere model, when
    /// `exact`), or the spheres enclosing each body with the spheres inside it.
    fn of(model: &CollisionModel, exact: bool) -> Result<Self> {
        let bodies = model.bodies();
        let mut by_link: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for (i, b) in bodies.iter().enumerate() {
            by_link.entry(b.link).or_default().push(i);
        }
        let (mut balls, mut ball_bodies, mut groups) = (Vec::new(), Vec::new(), Vec::new());
        let mut inner = Vec::new();
        let mut inner_of_body = vec![0..0; bodies.len()];
        let mut group_of_body = vec![usize::MAX; bodies.len()];
        let mut balls_of_body = vec![0..0; bodies.len()];
        let (mut solids, mut solid_of_body) = (Vec::new(), vec![None; bodies.len()]);
        for (&link, members) in &by_link {
            // a sphere model's balls are placed from the link their link is rigidly attached
            // to (fixed joints between them), whose pose the screen's kinematics computes
            // anyway: the fixed links' poses are not computed
            let (frame, offset) = if exact {
                model.robot().tree().rigid_ancestor(link)
            } else {
                (link, Isometry3::identity())
            };
            let (start, inner_start) = (balls.len(), inner.len());
            let mut spheres: Vec<(Point3<f64>, f64)> = Vec::new();
            for &i in members {
                let first = balls.len();
                for s in model.enclosing_spheres(i) {
                    let center = offset * s.center;
                    spheres.push((center, s.radius));
                    balls.push(Ball {
                        center: to_f32(center.coords),
                        radius: s.radius as f32,
                    });
                    ball_bodies.push(i);
                }
                if balls.len() == first {
                    return Err(CollisionError::InvalidValue {
                        what: format!("body `{}`", bodies[i].name),
                        problem: "has no enclosing sphere (an invalid shape)".into(),
                    });
                }
                group_of_body[i] = groups.len();
                balls_of_body[i] = first..balls.len();
                if !exact {
                    let first = inner.len();
                    inner.extend(model.inscribed_spheres(i).iter().map(|s| Ball {
                        center: to_f32(s.center.coords),
                        radius: s.radius as f32,
                    }));
                    inner_of_body[i] = first..inner.len();
                }
            }
            let solid = match (members.as_slice(), exact) {
                (&[i], false) => match bodies[i].shape {
                    Shape::Box { size } => Some(Object::Box {
                        center: to_f32(bodies[i].local.translation.vector),
                        axes: inverse_axes(&bodies[i].local),
                        half: size.map(|s| (0.5 * s) as f32),
                    }),
                    _ => None,
                },
                _ => None,
            };
            let kdop = (!exact)
                .then(|| kdop_of(members.iter().map(|&i| &bodies[i])))
                .flatten();
            // a sphere model's spheres stay on the sphere kernels, tuned for them
            let as_solids: Option<Vec<Solid>> = (!exact)
                .then(|| members.iter().map(|&i| Solid::of(&bodies[i])).collect())
                .flatten();
            let group_solids = as_solids.map(|list| {
                let first = solids.len();
                for (&i, solid) in members.iter().zip(list) {
                    solid_of_body[i] = Some(solids.len());
                    solids.push(solid);
                }
                first..solids.len()
            });
            groups.push(Group {
                frame,
                bound: bounding_ball(&spheres),
                balls: start..balls.len(),
                inner: inner_start..inner.len(),
                bodies: members.iter().map(|&i| i as u32).collect(),
                solid,
                kdop,
                solids: group_solids,
            });
        }
        Ok(Spheres {
            solids,
            solid_of_body,
            balls,
            ball_bodies,
            groups,
            inner,
            inner_of_body,
            group_of_body,
            balls_of_body,
        })
    }

    /// The model's checked body pairs as ball pairs, grouped by link pair: the ball pairs and
    /// the group pairs holding ranges of them.
    fn pairs(&self, model: &CollisionModel) -> (Vec<BallPair>, Vec<GroupPair>) {
        let Spheres {
            balls,
            groups,
            inner,
            inner_of_body,
            group_of_body,
            balls_of_body,
            solids,
            solid_of_body,
            ..
        } = self;
        // the model's checked body pairs as ball pairs, grouped by link pair
        let mut by_pair: BTreeMap<(usize, usize), LinkPairTests> = BTreeMap::new();
        for p in model.pairs() {
            let (a, b) = (p.a as usize, p.b as usize);
            let (list, body_pairs) = by_pair
                .entry((group_of_body[a], group_of_body[b]))
                .or_default();
            body_pairs.push((p.a, p.b));
            for x in balls_of_body[a].clone() {
                for y in balls_of_body[b].clone() {
                    let r = balls[x].radius + balls[y].radius;
                    list.push((x as u32, y as u32, r));
                }
            }
        }
        let (mut pairs, mut group_pairs) = (Vec::new(), Vec::new());
        for ((a, b), (mut list, bodies)) in by_pair {
            list.sort_by_key(|&(x, y, _)| (x, y));
            let mut runs: Vec<Run> = Vec::new();
            for pair in list {
                let at = pairs.len() as u32;
                match runs.last_mut() {
                    Some(run) if run.ball == pair.0 => run.end += 1,
                    _ => runs.push(Run {
                        ball: pair.0,
                        reach: balls[pair.0 as usize].radius + groups[b].bound.radius,
                        start: at,
                        end: at + 1,
                    }),
                }
                pairs.push(pair);
            }
            let inner_pairs = bodies
                .iter()
                .flat_map(|&(x, y)| {
                    let (x, y) = (
                        inner_of_body[x as usize].clone(),
                        inner_of_body[y as usize].clone(),
                    );
                    x.flat_map(move |i| y.clone().map(move |j| (i, j)))
                })
                .map(|(i, j)| (i as u32, j as u32, inner[i].radius + inner[j].radius))
                .collect();
            // a box against every body of the other link: its spheres against the box
            let against = |s: usize, o: usize| {
                (groups[s].solid.is_some() && bodies.len() == groups[o].bodies.len())
                    .then_some((s, o))
            };
            let solid = against(a, b).or_else(|| against(b, a));
            let solid_pairs = bodies
                .iter()
                .map(|&(x, y)| {
                    let (x, y) = (solid_of_body[x as usize]?, solid_of_body[y as usize]?);
                    Some(SolidPair::new(solids, x, y))
                })
                .collect::<Option<Vec<_>>>()
                .unwrap_or_default();
            group_pairs.push(GroupPair {
                solid_pairs,
                a,
                b,
                reach: groups[a].bound.radius + groups[b].bound.radius,
                runs,
                bodies,
                inner: inner_pairs,
                solid,
                table: None,
            });
        }
        (pairs, group_pairs)
    }
}

/// The clearance tables of the link pairs that allow one ([`PairTable::build`]), each pair
/// given the index of its own, and the readers of their joints' angles.
fn tables(
    model: &CollisionModel,
    groups: &[Group],
    group_pairs: &mut [GroupPair],
) -> Result<(Vec<PairTable>, Vec<AngleReader>)> {
    use rayon::prelude::*;
    let levers = crate::levers::Levers::new(model, &model.robot().all_active())?;
    // pairs tested as solids leave few lanes to the exact checks: only pairs screened through
    // enclosing spheres get a table (built in parallel: each is the same on any thread)
    let built: Vec<_> = group_pairs
        .par_iter()
        .map(|gp| {
            let screened = gp.solid_pairs.is_empty() && gp.solid.is_none();
            let (a, b) = (groups[gp.a].frame, groups[gp.b].frame);
            screened
                .then(|| PairTable::build(model, &levers, a, b, &gp.bodies))
                .flatten()
        })
        .collect();
    // one reader per joint, shared by every table over it
    let (mut tables, mut readers) = (Vec::new(), Vec::<AngleReader>::new());
    for (gp, built) in group_pairs.iter_mut().zip(built) {
        let Some((mut table, own)) = built else {
            continue;
        };
        let indices: Vec<u32> = own
            .into_iter()
            .map(
                |r| match readers.iter().position(|x| x.joint() == r.joint()) {
                    Some(at) => at as u32,
                    None => {
                        readers.push(r);
                        readers.len() as u32 - 1
                    }
                },
            )
            .collect();
        table.attach(&indices);
        gp.table = Some(tables.len() as u32);
        tables.push(table);
    }
    Ok((tables, readers))
}

/// The screen's walks through the exact model's culling spheres, while compiling.
struct Walks {
    steps: Vec<CullStep>,
    world_steps: Vec<WorldStep>,
    culls: bool,
    origins: Vec<u32>,
    frame_balls: Vec<(u32, [f32; 3])>,
}

impl Walks {
    /// The culling steps of the exact model, each link pair's block one step (when the model
    /// has [`CULLED_LINK_PAIRS`] link pairs or more; else none, the walks go pair by pair).
    fn of(model: &CollisionModel, spheres: &Spheres, group_pairs: &[GroupPair]) -> Self {
        let (groups, group_of_body) = (&spheres.groups, &spheres.group_of_body);
        let index: BTreeMap<(usize, usize), u32> = group_pairs
            .iter()
            .enumerate()
            .map(|(k, gp)| ((gp.a, gp.b), k as u32))
            .collect();
        let culling = model.culling();
        let cull_ball = |ball: crate::cull::Ball| match ball {
            crate::cull::Ball::Origin { slot, radius } => (groups.len() as u32 + slot, radius),
            crate::cull::Ball::Body(b) => {
                let g = group_of_body[b as usize];
                (g as u32, f64::from(groups[g].bound.radius))
            }
        };
        let culls = group_pairs.len() >= CULLED_LINK_PAIRS;
        let steps: Vec<CullStep> = if !culls {
            Vec::new()
        } else {
            culling
                .self_steps
                .iter()
                .map(|step| match *step {
                    crate::cull::Step::Cull { a, b, end } => {
                        let ((a, ra), (b, rb)) = (cull_ball(a), cull_ball(b));
                        CullStep::Cull {
                            a,
                            b,
                            reach: (ra + rb) as f32,
                            end,
                        }
                    }
                    // a block of one checked link pair: `by_pair` made its group pair
                    crate::cull::Step::Test { start, .. } => {
                        let p = model.pairs()[start as usize];
                        let k = index[&(group_of_body[p.a as usize], group_of_body[p.b as usize])];
                        let gp = &group_pairs[k as usize];
                        let (ga, gb) = (&groups[gp.a], &groups[gp.b]);
                        CullStep::Pair {
                            k,
                            a: gp.a as u32,
                            b: gp.b as u32,
                            reach: ga.bound.radius + gb.bound.radius,
                        }
                    }
                })
                .collect()
        };
        // a block of one link's bodies: its group
        let (world_steps, frame_balls) = if !culls {
            frame_culls(groups)
        } else {
            let steps = culling
                .world_steps
                .iter()
                .map(|step| match *step {
                    crate::cull::Step::Cull { a, end, .. } => {
                        let (ball, radius) = cull_ball(a);
                        WorldStep::Cull {
                            ball,
                            radius: radius as f32,
                            end,
                        }
                    }
                    crate::cull::Step::Test { start, .. } => {
                        WorldStep::Link(group_of_body[start as usize] as u32)
                    }
                })
                .collect();
            (steps, Vec::new())
        };
        let origins = if culls {
            culling.origin_links.clone()
        } else {
            Vec::new()
        };
        Walks {
            steps,
            world_steps,
            culls,
            origins,
            frame_balls,
        }
    }
}

/// Link groups a frame must hold for the world walk of a model without culls to test them
/// behind one sphere enclosing them all (a gripper's links fixed to the wrist, placed from
/// its frame): an object far from that sphere skips them all.
pub(super) const FRAME_CULL_GROUPS: usize = 6;

/// The world walk of a model without culls (see [`FastModel::world_steps`]): the groups the
/// last in the tree first, those of a frame holding [`FRAME_CULL_GROUPS`] or more behind a
/// cull by the sphere enclosing them; and those spheres. None when no frame holds so many.
fn frame_culls(groups: &[Group]) -> (Vec<WorldStep>, Vec<(u32, [f32; 3])>) {
    let mut members: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for g in (0..groups.len()).rev() {
        members.entry(groups[g].frame).or_default().push(g);
    }
    if members.values().all(|m| m.len() < FRAME_CULL_GROUPS) {
        return (Vec::new(), Vec::new());
    }
    let (mut steps, mut balls, mut done) = (Vec::new(), Vec::new(), vec![false; groups.len()]);
    for g in (0..groups.len()).rev() {
        if done[g] {
            continue;
        }
        let frame = &members[&groups[g].frame];
        if frame.len() < FRAME_CULL_GROUPS {
            steps.push(WorldStep::Link(g as u32));
            continue;
        }
        let bounds: Vec<(Point3<f64>, f64)> = frame
            .iter()
            .map(|&k| {
                let b = &groups[k].bound;
                (Point3::from(b.center.map(f64::from)), f64::from(b.radius))
            })
            .collect();
        let ball = bounding_ball(&bounds);
        steps.push(WorldStep::Cull {
            ball: (groups.len() + balls.len()) as u32,
            radius: ball.radius,
            end: (steps.len() + 1 + frame.len()) as u32,
        });
        balls.push((groups[g].frame as u32, ball.center));
        for &k in frame {
            steps.push(WorldStep::Link(k as u32));
            done[k] = true;
        }
    }
    (steps, balls)
}

/// The largest distance of any point of the robot from the world origin in any configuration
/// (every joint offset and prismatic travel end to end, then the farthest ball), and the most
/// movable joints between the root and a link.
fn reach_and_depth(model: &CollisionModel, balls: &[Ball]) -> (f64, usize) {
    let tree = model.robot().tree();
    let chain: f64 = tree
        .joints
        .iter()
        .map(|j| {
            let travel = if j.kind == JointKind::Prismatic {
                j.limits.lower.abs().max(j.limits.upper.abs())
            } else {
                0.0
            };
            j.local_origin.translation.vector.norm() + travel
        })
        .sum();
    let farthest = balls
        .iter()
        .map(|b| norm(b.center) + f64::from(b.radius))
        .fold(0.0, f64::max);
    // joints are in tree order: a parent link's depth is known before its children's
    let mut depth_of = vec![0usize; tree.links.len()];
    for j in &tree.joints {
        depth_of[j.child] = depth_of[j.parent] + usize::from(j.kind != JointKind::Fixed);
    }
    (chain + farthest, depth_of.into_iter().max().unwrap_or(0))
}

/// A sphere enclosing the spheres (centre: the middle of their bounding box), rounded up so
/// that it still encloses them in `f32`.
pub(super) fn bounding_ball(spheres: &[(Point3<f64>, f64)]) -> Ball {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for (c, r) in spheres {
        lo = lo.inf(&(c.coords - Vector3::repeat(*r)));
        hi = hi.sup(&(c.coords + Vector3::repeat(*r)));
    }
    let center = (lo + hi) / 2.0;
    let radius = spheres
        .iter()
        .map(|(c, r)| (c.coords - center).norm() + r)
        .fold(0.0, f64::max);
    Ball {
        center: to_f32(center),
        radius: (radius * (1.0 + 1e-6) + 1e-7) as f32,
    }
}
