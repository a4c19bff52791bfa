//! What a change of the world blocks in a map, without checking the rest: every node's
//! collision bodies and every edge's checked postures are bounded by axis-aligned boxes in two
//! BVHs (parry's), built once; a world is compared with the map's own, and only the objects that
//! differ (added, moved, reshaped) are looked up, then the nodes and edges whose boxes they touch
//! are checked exactly, as an exhaustive check would. Objects the map's world already had at the
//! same pose block nothing new (the map was built and connected collision-free among them), and
//! removed ones block nothing at all, so the result is exactly what checking every node and edge
//! against the whole world finds ([`blocked_exhaustive`], tested against it).

use parry3d_f64::bounding_volume::BoundingVolume;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use rayon::prelude::*;
use trm_collision::{Aabb, World, WorldObject};
use trm_tasks::Objective;

use crate::edges::{segment_is_collision_free, segment_point, segment_steps};
use crate::error::{Result, RoadmapError};
use crate::map::Roadmap;

/// What a world blocks in a map: node and edge indices (ascending), and the objects that
/// differ from the map's own world.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Blocked {
    /// Points whose posture collides with the world.
    pub nodes: Vec<usize>,
    /// Edges (indices into `Roadmap::edges`) with a checked posture that collides.
    pub edges: Vec<usize>,
    /// Names of the world's objects that the map's world does not have at that pose and shape.
    pub changed: Vec<String>,
}

/// Boxes around a map's nodes and edges, for [`BlockIndex::blocked`]: a BVH over the nodes'
/// boxes, one over the edges' (each the union of its samples' boxes), and every edge sample's
/// own box, so that only the samples near a changed object are checked.
pub struct BlockIndex {
    nodes: Bvh,
    edges: Bvh,
    /// The boxes of the samples of edge k: `samples[sample_start[k]..sample_start[k + 1]]`.
    samples: Vec<Aabb>,
    sample_start: Vec<usize>,
}

impl std::fmt::Debug for BlockIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BlockIndex")
            .field("nodes", &self.nodes.leaf_count())
            .field("edges", &self.edges.leaf_count())
            .finish()
    }
}

/// Checks that `objective` poses the map's postures.
fn check_fit(map: &Roadmap, objective: &Objective) -> Result<()> {
    if map.active.len() != objective.dim() {
        return Err(RoadmapError::Unsuitable(format!(
            "the map has {} active motors, the objective {}: use the map's own problem",
            map.active.len(),
            objective.dim()
        )));
    }
    Ok(())
}

impl BlockIndex {
    /// Boxes every node's placed collision bodies and, for every edge, the bodies at every
    /// posture its collision check samples (at the map's edge resolution); `objective` is the
    /// map's (its `Roadmap::problem`).
    pub fn new(map: &Roadmap, objective: &Objective) -> Result<Self> {
        check_fit(map, objective)?;
        let node_boxes: Vec<Aabb> = map
            .points
            .par_iter()
            .map_init(
                || objective.scratch(),
                |scratch, p| bodies_box(objective, &p.q, scratch),
            )
            .collect();
        let edge_samples: Vec<Vec<Aabb>> = map
            .edges
            .par_iter()
            .map_init(
                || (objective.scratch(), vec![0.0; objective.dim()]),
                |(scratch, q), &(a, b, _)| {
                    let (qa, qb) = (&map.points[a].q, &map.points[b].q);
                    let steps = segment_steps(qa, qb, map.edge_resolution);
                    (0..=steps)
                        .map(|s| {
                            segment_point(qa, qb, s, steps, q);
                            bodies_box(objective, q, scratch)
                        })
                        .collect()
                },
            )
            .collect();
        let edge_boxes: Vec<Aabb> = edge_samples
            .iter()
            .map(|boxes| {
                boxes
                    .iter()
                    .fold(Aabb::new_invalid(), |union, b| union.merged(b))
            })
            .collect();
        let mut sample_start = Vec::with_capacity(edge_samples.len() + 1);
        sample_start.push(0);
        for boxes in &edge_samples {
            sample_start.push(sample_start.last().copied().unwrap_or(0) + boxes.len());
        }
        Ok(BlockIndex {
            nodes: Bvh::from_leaves(BvhBuildStrategy::Binned, &node_boxes),
            edges: Bvh::from_leaves(BvhBuildStrategy::Binned, &edge_boxes),
            samples: edge_samples.into_iter().flatten().collect(),
            sample_start,
        })
    }

    /// The nodes and edges of `map` that `world` blocks (exactly those
    /// [`blocked_exhaustive`] finds), looking only at the objects that differ from the map's
    /// world and at the nodes and edges near them.
    pub fn blocked(&self, map: &Roadmap, objective: &Objective, world: &World) -> Result<Blocked> {
        check_fit(map, objective)?;
        let changed = changed_objects(objective, world);
        let mut only_changed = World::new();
        for o in &changed {
            only_changed
                .add(o.name(), o.shape().clone(), *o.pose())
                .map_err(|e| RoadmapError::Unsuitable(e.to_string()))?;
        }
        let boxes: Vec<Aabb> = changed.iter().map(|o| o.bounding_box()).collect();
        let near = |bvh: &Bvh| {
            let mut found: Vec<usize> = boxes
                .iter()
                .flat_map(|aabb| bvh.intersect_aabb(aabb).map(|i| i as usize))
                .collect();
            found.sort_unstable();
            found.dedup();
            found
        };
        let nodes = near(&self.nodes)
            .into_par_iter()
            .map_init(
                || objective.scratch(),
                |scratch, i| {
                    (!objective.all_clear_of(&map.points[i].q, &only_changed, scratch)).then_some(i)
                },
            )
            .flatten()
            .collect();
        // an edge is blocked when one of its samples is; only samples whose box meets a
        // changed object's can be
        let d = objective.dim();
        let edges = near(&self.edges)
            .into_par_iter()
            .map_init(
                || (objective.scratch(), Vec::new()),
                |(scratch, qs), k| {
                    let (a, b, _) = map.edges[k];
                    let (qa, qb) = (&map.points[a].q, &map.points[b].q);
                    let own = &self.samples[self.sample_start[k]..self.sample_start[k + 1]];
                    let steps = own.len() - 1;
                    qs.clear();
                    for (s, sample) in own.iter().enumerate() {
                        if boxes.iter().any(|b| b.intersects(sample)) {
                            qs.resize(qs.len() + d, 0.0);
                            let at = qs.len() - d;
                            segment_point(qa, qb, s, steps, &mut qs[at..]);
                        }
                    }
                    (!qs.is_empty() && !objective.all_clear_of(qs, &only_changed, scratch))
                        .then_some(k)
                },
            )
            .flatten()
            .collect();
        Ok(Blocked {
            nodes,
            edges,
            changed: changed.iter().map(|o| o.name().to_string()).collect(),
        })
    }
}

/// The box around the robot's bodies at `q` (an empty box for a robot without bodies).
fn bodies_box(objective: &Objective, q: &[f64], scratch: &mut trm_tasks::Scratch) -> Aabb {
    objective
        .placed(q, scratch)
        .bounding_box()
        .unwrap_or_else(Aabb::new_invalid)
}

/// The objects of `world` the objective's (the map's) world does not have at that pose and
/// shape.
fn changed_objects<'w>(objective: &Objective, world: &'w World) -> Vec<&'w WorldObject> {
    world
        .objects()
        .iter()
        .filter(|o| !objective.world().objects().iter().any(|m| same(m, o)))
        .collect()
}

/// The same object: name, shape and pose.
fn same(a: &WorldObject, b: &WorldObject) -> bool {
    a.name() == b.name() && a.shape() == b.shape() && a.pose() == b.pose()
}

fn edge_blocked(
    map: &Roadmap,
    objective: &Objective,
    world: &World,
    k: usize,
    samples: &mut Vec<f64>,
    scratch: &mut trm_tasks::Scratch,
) -> bool {
    let (a, b, _) = map.edges[k];
    !segment_is_collision_free(
        objective,
        world,
        &map.points[a].q,
        &map.points[b].q,
        map.edge_resolution,
        samples,
        scratch,
    )
}

/// What `world` blocks in `map`, by checking every node and every edge against the whole
/// world: the reference [`BlockIndex::blocked`] equals.
pub fn blocked_exhaustive(map: &Roadmap, objective: &Objective, world: &World) -> Result<Blocked> {
    check_fit(map, objective)?;
    let nodes = (0..map.points.len())
        .into_par_iter()
        .map_init(
            || objective.scratch(),
            |scratch, i| {
                (!objective.is_collision_free_in(&map.points[i].q, world, scratch)).then_some(i)
            },
        )
        .flatten()
        .collect();
    let edges = (0..map.edges.len())
        .into_par_iter()
        .map_init(
            || (objective.scratch(), Vec::new()),
            |(scratch, samples), k| {
                edge_blocked(map, objective, world, k, samples, scratch).then_some(k)
            },
        )
        .flatten()
        .collect();
    let changed = changed_objects(objective, world)
        .iter()
        .map(|o| o.name().to_string())
        .collect();
    Ok(Blocked {
        nodes,
        edges,
        changed,
    })
}
