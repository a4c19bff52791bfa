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

use crate::error::{Result, RoadmapError};
use crate::map::Roadmap;
use trm_collision::WorldChecker;
use trm_collision::edge::{edge_point, span_steps};

/// The most edge samples a [`BlockIndex`] boxes (24 bytes per body group and sample: about
/// 0.7 GB at the most for the iCub's 6 groups).
pub const MAX_SAMPLES: usize = 5_000_000;

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

/// Boxes around a map's nodes and edges, for [`BlockIndex::blocked`] and
/// [`BlockIndex::changes`]: the robot's bodies are grouped by kinematic branch (torso, head,
/// each arm…), and a BVH holds one box per node and group, another one per edge and group (the
/// union over the edge's samples); every edge sample's box around the whole robot is kept too,
/// so that only the samples near a changed object are checked. Nodes and edges added to the map
/// later are boxed by [`BlockIndex::extend`].
pub struct BlockIndex {
    nodes: Bvh,
    edges: Bvh,
    /// Body → group, and the number of groups (leaves per node and per edge).
    group_of: Vec<usize>,
    groups: usize,
    /// The nodes and edges boxed so far.
    node_count: usize,
    /// The group boxes of the samples of edge k: sample s of edge k has boxes
    /// `samples[(sample_start[k] + s) · groups..][..groups]` (single precision, rounded
    /// outwards).
    samples: Vec<SmallBox>,
    sample_start: Vec<usize>,
}

/// An axis-aligned box in single precision, enclosing the double-precision box it was made
/// from (widened by a millionth).
#[derive(Debug, Clone, Copy)]
struct SmallBox {
    mins: [f32; 3],
    maxs: [f32; 3],
}

impl SmallBox {
    fn new(aabb: &Aabb) -> Self {
        // a margin of a millionth (relative, at least a micrometre) is more than the half
        // unit in the last place f32 rounding can move a value by
        let margin = |v: f64| 1e-6 * v.abs().max(1.0);
        let down = |v: f64| (v - margin(v)) as f32;
        let up = |v: f64| (v + margin(v)) as f32;
        SmallBox {
            mins: [down(aabb.mins.x), down(aabb.mins.y), down(aabb.mins.z)],
            maxs: [up(aabb.maxs.x), up(aabb.maxs.y), up(aabb.maxs.z)],
        }
    }

    /// Whether it meets `aabb` (touching counts).
    fn intersects(&self, aabb: &Aabb) -> bool {
        (0..3).all(|k| {
            f64::from(self.mins[k]) <= aabb.maxs[k] && f64::from(self.maxs[k]) >= aabb.mins[k]
        })
    }
}

impl std::fmt::Debug for BlockIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BlockIndex")
            .field("nodes", &self.node_count)
            .field("edges", &(self.sample_start.len() - 1))
            .finish()
    }
}

/// How the nodes and edges of a map change status from one world to another
/// ([`BlockIndex::changes`]): indices ascending.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Changes {
    /// Nodes clear before and blocked now.
    pub blocked_nodes: Vec<usize>,
    /// Edges clear before and blocked now.
    pub blocked_edges: Vec<usize>,
    /// Nodes blocked before and clear now.
    pub freed_nodes: Vec<usize>,
    /// Edges blocked before and clear now.
    pub freed_edges: Vec<usize>,
    /// Names of the objects that differ between the two worlds (added, moved, reshaped or
    /// removed).
    pub changed: Vec<String>,
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
        let (group_of, groups) = branch_groups(objective);
        let mut index = BlockIndex {
            nodes: Bvh::new(),
            edges: Bvh::new(),
            group_of,
            groups,
            node_count: 0,
            samples: Vec::new(),
            sample_start: vec![0],
        };
        let (node_boxes, edge_boxes) = index.boxes(map, objective)?;
        index.nodes = Bvh::from_leaves(BvhBuildStrategy::Binned, &node_boxes);
        index.edges = Bvh::from_leaves(BvhBuildStrategy::Binned, &edge_boxes);
        Ok(index)
    }

    /// Boxes the nodes and edges `map` has beyond those indexed (a map only ever grows at its
    /// end: nodes and edges appended, none removed or renumbered).
    pub fn extend(&mut self, map: &Roadmap, objective: &Objective) -> Result<()> {
        check_fit(map, objective)?;
        let (first_node, first_edge) = (self.node_count, self.sample_start.len() - 1);
        if map.points.len() < first_node || map.edges.len() < first_edge {
            return Err(RoadmapError::Unsuitable(format!(
                "the index holds {first_node} nodes and {first_edge} edges, the map {} and {}: index the map anew",
                map.points.len(),
                map.edges.len()
            )));
        }
        let (node_boxes, edge_boxes) = self.boxes(map, objective)?;
        let leaf = |first: usize, k: usize| (first * self.groups + k) as u32;
        for (k, aabb) in node_boxes.into_iter().enumerate() {
            self.nodes.insert(aabb, leaf(first_node, k));
        }
        for (k, aabb) in edge_boxes.into_iter().enumerate() {
            self.edges.insert(aabb, leaf(first_edge, k));
        }
        Ok(())
    }

    /// The group boxes of the nodes and edges not yet indexed (leaves in order); records the
    /// edges' sample boxes and the new counts.
    fn boxes(&mut self, map: &Roadmap, objective: &Objective) -> Result<(Vec<Aabb>, Vec<Aabb>)> {
        let (first_node, first_edge) = (self.node_count, self.sample_start.len() - 1);
        let new_edges = &map.edges[first_edge..];
        let samples: usize = self.sample_start.last().copied().unwrap_or(0)
            + new_edges
                .iter()
                .map(|&(a, b, _)| {
                    span_steps(&map.points[a].q, &map.points[b].q, map.edge_resolution) + 1
                })
                .sum::<usize>();
        if samples > MAX_SAMPLES {
            return Err(RoadmapError::Unsuitable(format!(
                "the map's edges hold {samples} checked postures (edge resolution {} rad), over the {MAX_SAMPLES} the index boxes: connect the map at a coarser resolution",
                map.edge_resolution
            )));
        }
        let groups = self.groups;
        let group_of = &self.group_of;
        let grouped = |placed: &trm_collision::PlacedBodies, out: &mut Vec<Aabb>| {
            let start = out.len();
            out.resize(start + groups, Aabb::new_invalid());
            for (body, aabb) in objective.collision().tight_boxes(placed).enumerate() {
                let g = &mut out[start + group_of[body]];
                *g = g.merged(&aabb);
            }
        };
        let d = objective.dim();
        let node_boxes: Vec<Aabb> = map.points[first_node..]
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
        let per_edge: Vec<(Vec<Aabb>, Vec<SmallBox>)> = new_edges
            .par_iter()
            .map_init(
                || (objective.scratch(), Vec::new(), Vec::new()),
                |(scratch, qs, boxes), &(a, b, _)| {
                    let (qa, qb) = (&map.points[a].q, &map.points[b].q);
                    let steps = span_steps(qa, qb, map.edge_resolution);
                    qs.clear();
                    qs.resize((steps + 1) * d, 0.0);
                    for (s, q) in qs.chunks_exact_mut(d).enumerate() {
                        edge_point(qa, qb, s, steps, q);
                    }
                    let mut union = vec![Aabb::new_invalid(); groups];
                    let mut samples = Vec::with_capacity((steps + 1) * groups);
                    objective.all_placed(qs, scratch, |placed| {
                        boxes.clear();
                        grouped(placed, boxes);
                        for (u, g) in union.iter_mut().zip(boxes.iter()) {
                            *u = u.merged(g);
                        }
                        samples.extend(boxes.iter().map(SmallBox::new));
                        true
                    });
                    (union, samples)
                },
            )
            .collect();
        let mut edge_boxes = Vec::with_capacity(per_edge.len() * groups);
        for (union, samples) in per_edge {
            edge_boxes.extend(union);
            self.samples.extend(samples);
            self.sample_start.push(self.samples.len() / groups);
        }
        self.node_count = map.points.len();
        debug_assert_eq!(self.sample_start.len() - 1, map.edges.len());
        Ok((node_boxes, edge_boxes))
    }

    /// Checks that the index boxes exactly `map`'s nodes and edges.
    fn check_indexed(&self, map: &Roadmap) -> Result<()> {
        if map.points.len() != self.node_count || map.edges.len() != self.sample_start.len() - 1 {
            return Err(RoadmapError::Unsuitable(format!(
                "the index holds {} nodes and {} edges, the map {} and {}: extend the index first",
                self.node_count,
                self.sample_start.len() - 1,
                map.points.len(),
                map.edges.len()
            )));
        }
        Ok(())
    }

    /// The nodes and edges of `map` that `world` blocks (exactly those
    /// [`blocked_exhaustive`] finds), looking only at the objects that differ from the map's
    /// world and at the nodes and edges near them.
    pub fn blocked(&self, map: &Roadmap, objective: &Objective, world: &World) -> Result<Blocked> {
        let clear_nodes = vec![false; map.points.len()];
        let clear_edges = vec![false; map.edges.len()];
        let c = self.changes(
            map,
            objective,
            objective.world(),
            world,
            &clear_nodes,
            &clear_edges,
        )?;
        Ok(Blocked {
            nodes: c.blocked_nodes,
            edges: c.blocked_edges,
            changed: changed_objects(objective.world(), world)
                .iter()
                .map(|o| o.name().to_string())
                .collect(),
        })
    }

    /// How the map's nodes and edges change status when the world goes from `before` to
    /// `after`, given which were blocked in `before` (`node_blocked`, `edge_blocked`; the map's
    /// own nodes and edges are clear in the world it was built in). Only nodes and edges whose
    /// boxes touch an object that differs between the two worlds (at its old or new pose) are
    /// looked at: one clear before is checked against the objects new in `after`, one blocked
    /// before against all of `after` — of an edge, only the samples whose box touches such an
    /// object. Map nodes and edges are free of self-collisions (they were checked when made),
    /// so only objects can block them. Everything else keeps its status, so the result is
    /// exactly what checking everything in both worlds would give.
    pub fn changes(
        &self,
        map: &Roadmap,
        objective: &Objective,
        before: &World,
        after: &World,
        node_blocked: &[bool],
        edge_blocked: &[bool],
    ) -> Result<Changes> {
        check_fit(map, objective)?;
        self.check_indexed(map)?;
        if node_blocked.len() != map.points.len() || edge_blocked.len() != map.edges.len() {
            return Err(RoadmapError::Unsuitable(format!(
                "{} node and {} edge flags for a map of {} nodes and {} edges",
                node_blocked.len(),
                edge_blocked.len(),
                map.points.len(),
                map.edges.len()
            )));
        }
        let added = changed_objects(before, after);
        let gone = changed_objects(after, before);
        let mut new_objects = World::new();
        for o in &added {
            new_objects
                .add(o.name(), o.shape().clone(), *o.pose())
                .map_err(|e| RoadmapError::Unsuitable(e.to_string()))?;
        }
        let new_boxes: Vec<Aabb> = added.iter().map(|o| o.tight_box()).collect();
        let all_boxes: Vec<Aabb> = added.iter().chain(&gone).map(|o| o.tight_box()).collect();
        let near = |bvh: &Bvh| {
            let mut found: Vec<usize> = all_boxes
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
        // every object of `after`: a node or edge sample away from all their boxes is clear
        // (the map's nodes and edges are free of self-collisions: only objects can block them)
        let after_boxes: Vec<Aabb> = after.objects().iter().map(|o| o.tight_box()).collect();
        // (index, was blocked, is blocked) of every node near a change
        let nodes: Vec<(usize, bool, bool)> = near(&self.nodes)
            .into_par_iter()
            .map_init(
                || objective.scratch(),
                |scratch, i| {
                    let q = &map.points[i].q;
                    let was = node_blocked[i];
                    let is =
                        !objective.all_clear_of(q, if was { after } else { &new_objects }, scratch);
                    (i, was, is)
                },
            )
            .collect();
        // an edge is blocked when one of its samples near an object that could block it is:
        // one clear before, near a new object; one blocked before, near any object
        let d = objective.dim();
        let edges: Vec<(usize, bool, bool)> = near(&self.edges)
            .into_par_iter()
            .map_init(
                || (objective.scratch(), Vec::new()),
                |(scratch, qs), k| {
                    let (a, b, _) = map.edges[k];
                    let (qa, qb) = (&map.points[a].q, &map.points[b].q);
                    let was = edge_blocked[k];
                    let (boxes, objects) = if was {
                        (&after_boxes, after)
                    } else {
                        (&new_boxes, &new_objects)
                    };
                    let g = self.groups;
                    let own = &self.samples[self.sample_start[k] * g..self.sample_start[k + 1] * g];
                    let steps = own.len() / g - 1;
                    qs.clear();
                    for (s, sample) in own.chunks_exact(g).enumerate() {
                        if sample.iter().any(|a| boxes.iter().any(|b| a.intersects(b))) {
                            qs.resize(qs.len() + d, 0.0);
                            let at = qs.len() - d;
                            edge_point(qa, qb, s, steps, &mut qs[at..]);
                        }
                    }
                    let is = !qs.is_empty() && !objective.all_clear_of(qs, objects, scratch);
                    (k, was, is)
                },
            )
            .collect();
        let pick = |items: &[(usize, bool, bool)], was: bool| -> Vec<usize> {
            items
                .iter()
                .filter(|&&(_, w, i)| w == was && i != was)
                .map(|&(k, _, _)| k)
                .collect()
        };
        let mut changed: Vec<String> = added
            .iter()
            .chain(&gone)
            .map(|o| o.name().to_string())
            .collect();
        changed.sort();
        changed.dedup();
        Ok(Changes {
            blocked_nodes: pick(&nodes, false),
            blocked_edges: pick(&edges, false),
            freed_nodes: pick(&nodes, true),
            freed_edges: pick(&edges, true),
            changed,
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

/// The objects of `world` that `reference` does not have at that pose and shape.
fn changed_objects<'w>(reference: &World, world: &'w World) -> Vec<&'w WorldObject> {
    world
        .objects()
        .iter()
        .filter(|o| !reference.objects().iter().any(|m| same(m, o)))
        .collect()
}

/// The same object: name, shape and pose.
fn same(a: &WorldObject, b: &WorldObject) -> bool {
    a.name() == b.name() && a.shape() == b.shape() && a.pose() == b.pose()
}

/// Whether edge `k` of `map` is blocked in the checker's world.
fn edge_blocked(map: &Roadmap, checker: &mut WorldChecker, k: usize) -> bool {
    let (a, b, _) = map.edges[k];
    !checker.span_free(&map.points[a].q, &map.points[b].q, map.edge_resolution)
}

/// What `world` blocks in `map`, by checking every node and every edge against the whole
/// world: the reference [`BlockIndex::blocked`] equals.
pub fn blocked_exhaustive(map: &Roadmap, objective: &Objective, world: &World) -> Result<Blocked> {
    check_fit(map, objective)?;
    let checker = objective.world_checker(world)?;
    let nodes = (0..map.points.len())
        .into_par_iter()
        .map_init(
            || checker.clone(),
            |checker, i| (!checker.free(&map.points[i].q)).then_some(i),
        )
        .flatten()
        .collect();
    let edges = (0..map.edges.len())
        .into_par_iter()
        .map_init(
            || checker.clone(),
            |checker, k| edge_blocked(map, checker, k).then_some(k),
        )
        .flatten()
        .collect();
    let changed = changed_objects(objective.world(), world)
        .iter()
        .map(|o| o.name().to_string())
        .collect();
    Ok(Blocked {
        nodes,
        edges,
        changed,
    })
}
