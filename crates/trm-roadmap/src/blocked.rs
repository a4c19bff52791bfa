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
use trm_kinematics::LANES;
use trm_tasks::Objective;

use crate::edges::{segment_is_collision_free, segment_point, segment_steps};
use crate::error::{Result, RoadmapError};
use crate::map::Roadmap;

/// The most edge samples a [`BlockIndex`] boxes (a box is 48 bytes per body group).
pub const MAX_SAMPLES: usize = 20_000_000;

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

/// Boxes around a map's nodes and edges, for [`BlockIndex::blocked`]: the robot's bodies are
/// grouped by kinematic branch (torso, head, each arm…), and a BVH holds one box per node and
/// group, another one per edge and group (the union over the edge's samples); every edge
/// sample's box around the whole robot is kept too, so that only the samples near a changed
/// object are checked.
pub struct BlockIndex {
    nodes: Bvh,
    edges: Bvh,
    /// The number of body groups (leaves per node and per edge).
    groups: usize,
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
        let samples: usize = map
            .edges
            .iter()
            .map(|&(a, b, _)| {
                segment_steps(&map.points[a].q, &map.points[b].q, map.edge_resolution) + 1
            })
            .sum();
        if samples > MAX_SAMPLES {
            return Err(RoadmapError::Unsuitable(format!(
                "the map's edges hold {samples} checked postures (edge resolution {} rad), over the {MAX_SAMPLES} the index boxes: connect the map at a coarser resolution",
                map.edge_resolution
            )));
        }
        let (group_of, groups) = branch_groups(objective);
        let grouped = |placed: &trm_collision::PlacedBodies, out: &mut Vec<Aabb>| {
            let start = out.len();
            out.resize(start + groups, Aabb::new_invalid());
            for (body, aabb) in placed.body_boxes().enumerate() {
                let g = &mut out[start + group_of[body]];
                *g = g.merged(&aabb);
            }
        };
        let d = objective.dim();
        let node_boxes: Vec<Aabb> = map
            .points
            .par_chunks(LANES)
            .map_init(
                || (objective.scratch(), Vec::new()),
                |(scratch, qs), chunk| {
                    qs.clear();
                    for p in chunk {
                        qs.extend_from_slice(&p.q);
                    }
                    let mut boxes = Vec::with_capacity(chunk.len() * groups);
                    objective.all_placed(qs, scratch, |placed| {
                        grouped(placed, &mut boxes);
                        true
                    });
                    boxes
                },
            )
            .flatten_iter()
            .collect();
        // per edge: its groups' boxes over all samples, and each sample's whole-robot box
        let per_edge: Vec<(Vec<Aabb>, Vec<Aabb>)> = map
            .edges
            .par_iter()
            .map_init(
                || (objective.scratch(), Vec::new(), Vec::new()),
                |(scratch, qs, boxes), &(a, b, _)| {
                    let (qa, qb) = (&map.points[a].q, &map.points[b].q);
                    let steps = segment_steps(qa, qb, map.edge_resolution);
                    qs.clear();
                    qs.resize((steps + 1) * d, 0.0);
                    for (s, q) in qs.chunks_exact_mut(d).enumerate() {
                        segment_point(qa, qb, s, steps, q);
                    }
                    let mut union = vec![Aabb::new_invalid(); groups];
                    let mut samples = Vec::with_capacity(steps + 1);
                    objective.all_placed(qs, scratch, |placed| {
                        boxes.clear();
                        grouped(placed, boxes);
                        for (u, g) in union.iter_mut().zip(boxes.iter()) {
                            *u = u.merged(g);
                        }
                        samples.push(placed.bounding_box().unwrap_or_else(Aabb::new_invalid));
                        true
                    });
                    (union, samples)
                },
            )
            .collect();
        let mut sample_start = Vec::with_capacity(per_edge.len() + 1);
        sample_start.push(0);
        for (_, samples) in &per_edge {
            sample_start.push(sample_start.last().copied().unwrap_or(0) + samples.len());
        }
        let edge_boxes: Vec<Aabb> = per_edge
            .iter()
            .flat_map(|(u, _)| u.iter().copied())
            .collect();
        Ok(BlockIndex {
            nodes: Bvh::from_leaves(BvhBuildStrategy::Binned, &node_boxes),
            edges: Bvh::from_leaves(BvhBuildStrategy::Binned, &edge_boxes),
            groups,
            samples: per_edge.into_iter().flat_map(|(_, s)| s).collect(),
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
                .flat_map(|aabb| {
                    bvh.intersect_aabb(aabb)
                        .map(|leaf| leaf as usize / self.groups)
                })
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

/// Groups the robot's collision bodies by kinematic branch: a body belongs to the topmost link
/// of the unbranched chain above its link (a branch point is a link with two or more children
/// that carry bodies): torso, head, each arm, …. Returns body → group and the group count (at
/// least 1).
fn branch_groups(objective: &Objective) -> (Vec<usize>, usize) {
    let links = &objective.active().model().tree().links;
    let bodies = objective.collision().bodies();
    // which links have bodies at or below them, and how many such children each link has
    let mut carries = vec![false; links.len()];
    for b in bodies {
        let mut l = Some(b.link);
        while let Some(i) = l.filter(|&i| !carries[i]) {
            carries[i] = true;
            l = links[i].parent;
        }
    }
    let mut children = vec![0usize; links.len()];
    for (i, link) in links.iter().enumerate() {
        if let (Some(p), true) = (link.parent, carries[i]) {
            children[p] += 1;
        }
    }
    let top = |mut l: usize| {
        while let Some(p) = links[l].parent.filter(|&p| children[p] < 2) {
            l = p;
        }
        l
    };
    let mut tops: Vec<usize> = Vec::new();
    let group_of = bodies
        .iter()
        .map(|b| {
            let t = top(b.link);
            tops.iter().position(|&x| x == t).unwrap_or_else(|| {
                tops.push(t);
                tops.len() - 1
            })
        })
        .collect();
    (group_of, tops.len().max(1))
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
