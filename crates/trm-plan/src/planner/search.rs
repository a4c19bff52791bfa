//! The lazy search's graph and its A*: the map and kept nodes with a query's start and goal,
//! searched over what is not known blocked, a search at a time.

use std::time::Instant;

use petgraph::graph::{EdgeReference, NodeIndex, UnGraph};
use petgraph::visit::{EdgeFiltered, EdgeRef, IntoEdges};

use super::{Edge, Planner, State, Target};
use crate::PlanError;
use crate::query::{Goal, PlanOptions, PlanStats, Planned};

/// One query's lazy search through the graph, resumable: the query's own edges (the start's
/// and goal's joins to the graph) with what their checks found, and the A* graph, outlive a
/// call of [`Planner::search_lazily`], so that [`Planner::connect`] can give the search more
/// searches later without checking anything twice (the graph's own nodes and edges keep their
/// states in the planner).
pub(super) struct LazySearch {
    start: Vec<f64>,
    goal: Goal,
    /// The goal's configuration (node n + 1), for a configuration goal.
    goal_q: Option<Vec<f64>>,
    /// The goal's task point (a configuration goal's, through the task function).
    goal_t: Vec<f64>,
    extra: Vec<Edge>,
    extra_state: Vec<State>,
    /// Built for the first search: the graph and A*'s heuristic (a map node's distance to a
    /// configuration goal), each node's worked out when a search first reaches it.
    graph: Option<(UnGraph<(), usize>, Vec<f64>)>,
    stats: PlanStats,
    /// No path is left through what is not known blocked: more searches cannot help.
    exhausted: bool,
}

impl LazySearch {
    /// Whether more searches cannot help (no path is left through the graph).
    pub(super) fn exhausted(&self) -> bool {
        self.exhausted
    }

    /// Records that the straight segment from the start to a configuration goal is blocked
    /// (checked at the search's resolution by the caller), so that no search checks it again.
    pub(super) fn straight_blocked(&mut self) {
        if self.goal_q.is_some()
            && let Some(last) = self.extra_state.last_mut()
        {
            *last = State::Invalid;
        }
    }
}

impl Planner {
    /// A lazy search from `start` to `goal` through the graph, before its first search: the two
    /// joined to their nearest nodes (and to each other, for a configuration goal); an error
    /// when a configuration goal collides or no node meets a task-space goal.
    pub(super) fn lazy_search(
        &mut self,
        start: &[f64],
        goal: &Goal,
        options: &PlanOptions,
    ) -> Result<LazySearch, PlanError> {
        let n = self.nodes.len();
        // graph: map nodes, then the start (n) and, for a configuration goal, the goal (n + 1)
        let (extra, goal_q) = self.query_edges(start, goal, options)?;
        let goal_t = match goal {
            Goal::Configuration(q) => self.task_of(q),
            Goal::TaskPoint { t, .. } => t.clone(),
            Goal::TaskRegion { min, max } => {
                min.iter().zip(max).map(|(a, b)| (a + b) / 2.0).collect()
            }
        };
        let target = Target { goal, n };
        if goal_q.is_none() && !(0..n).any(|i| target.holds(i, &self.nodes)) {
            let closest = self.closest_to(0..n, &goal_t);
            return Err(self.unreachable(
                "no map node lies within the goal's tolerance or region",
                closest,
                &goal_t,
            ));
        }
        Ok(LazySearch {
            start: start.to_vec(),
            goal: goal.clone(),
            goal_q,
            goal_t,
            extra_state: vec![State::Unknown; extra.len()],
            extra,
            graph: None,
            stats: PlanStats::default(),
            exhausted: false,
        })
    }

    /// Runs `lazy`'s searches until one finds a path whose nodes and edges are free (that path
    /// shortcut, finished and timed as `options` ask, [`Planner::finish`]), no path is left, or
    /// `max_searches` searches in all (counted over every call) have run.
    pub(super) fn search_lazily(
        &mut self,
        lazy: &mut LazySearch,
        options: &PlanOptions,
        max_searches: Option<usize>,
        began: Instant,
    ) -> Result<Planned, PlanError> {
        let n = self.nodes.len();
        loop {
            if max_searches.is_some_and(|m| lazy.stats.searches >= m) {
                return Err(PlanError::Unreachable {
                    reason: format!(
                        "the search through the maps found no free path in {} searches",
                        lazy.stats.searches
                    ),
                    closest_node: None,
                    closest_distance: f64::INFINITY,
                });
            }
            lazy.stats.searches += 1;
            let LazySearch {
                start,
                goal,
                goal_q,
                goal_t,
                extra,
                extra_state,
                graph,
                stats,
                exhausted,
            } = lazy;
            // A*'s heuristic, worked out for the nodes a search reaches (NaN: not yet)
            if graph.is_none() {
                *graph = Some((self.query_graph(extra), vec![f64::NAN; n]));
            }
            let (graph, estimate) = graph.as_mut().expect("made above");
            let target = Target { goal, n };
            let to = goal_q.as_deref();
            let path = match self.search(graph, extra, extra_state, &target, to, estimate) {
                Ok(path) => path,
                Err(reachable) => {
                    *exhausted = true;
                    let closest = self.closest_to(reachable.into_iter(), goal_t);
                    return Err(self.unreachable(
                        "no collision-free path through the maps in the current world",
                        closest,
                        goal_t,
                    ));
                }
            };
            let config = |i: usize, this: &Self| -> Vec<f64> {
                if i < n {
                    this.nodes[i].0.clone()
                } else if i == n {
                    start.clone()
                } else {
                    goal_q.clone().unwrap_or_default()
                }
            };
            if !self.path_valid(&path, extra, extra_state, stats, options, config) {
                continue;
            }
            let node_ids: Vec<usize> = path.iter().map(|&(v, _)| v).filter(|&i| i < n).collect();
            let waypoints: Vec<Vec<f64>> = path.iter().map(|&(v, _)| config(v, self)).collect();
            stats.path_nodes = node_ids.len();
            let stats = stats.clone();
            return self.finish(waypoints, node_ids, goal, options, stats, began);
        }
    }

    /// The graph a query searches: the map and kept nodes, the start (node n) and goal
    /// (node n + 1), and every edge (the graph's, then `extra`), weighted by its index. The
    /// part without `extra` is built once for the planner's graph and copied per query.
    pub(super) fn query_graph(&mut self, extra: &[Edge]) -> UnGraph<(), usize> {
        let (nodes, edges) = (self.nodes.len(), &self.edges);
        let mut graph = self
            .query_base
            .get_or_insert_with(|| {
                let mut graph = UnGraph::<(), usize>::with_capacity(nodes + 2, edges.len());
                for _ in 0..nodes + 2 {
                    graph.add_node(());
                }
                for (k, &(a, b, _)) in edges.iter().enumerate() {
                    graph.add_edge(NodeIndex::new(a), NodeIndex::new(b), k);
                }
                graph
            })
            .clone();
        debug_assert_eq!(
            (graph.node_count(), graph.edge_count()),
            (nodes + 2, self.edges.len()),
            "the query graph was kept past a change of the planner's graph"
        );
        graph.reserve_edges(extra.len());
        for (k, &(a, b, _)) in extra.iter().enumerate() {
            graph.add_edge(NodeIndex::new(a), NodeIndex::new(b), self.edges.len() + k);
        }
        graph
    }

    /// A* on `graph` ([`Planner::query_graph`]) from the start (node n) to a goal node over the
    /// nodes and edges not known invalid, `estimate[v]` the heuristic of map node v (its
    /// distance to the configuration goal `goal_q`, worked out where NaN): the path's
    /// nodes, each with the edge that reaches it (`usize::MAX` for the first; edges past the
    /// map's are `extra`'s). Without a path, the map nodes reachable from the start.
    pub(super) fn search(
        &self,
        graph: &UnGraph<(), usize>,
        extra: &[Edge],
        extra_state: &[State],
        target: &Target,
        goal_q: Option<&[f64]>,
        estimate: &mut [f64],
    ) -> Result<Vec<(usize, usize)>, Vec<usize>> {
        let n = target.n;
        let node_ok = |i: usize| i >= n || self.node_state[i] != State::Invalid;
        let state = |k: usize| {
            if k < self.edges.len() {
                self.edge_state[k]
            } else {
                extra_state[k - self.edges.len()]
            }
        };
        let open = EdgeFiltered::from_fn(graph, |e: EdgeReference<'_, usize>| {
            state(*e.weight()) != State::Invalid
                && node_ok(e.source().index())
                && node_ok(e.target().index())
        });
        let length = |k: usize| {
            if k < self.edges.len() {
                self.edges[k].2
            } else {
                extra[k - self.edges.len()].2
            }
        };
        let found = petgraph::algo::astar(
            &open,
            NodeIndex::new(n),
            |v| target.holds(v.index(), &self.nodes),
            |e| length(*e.weight()),
            |v| match (goal_q, estimate.get_mut(v.index())) {
                (Some(q), Some(e)) => {
                    if e.is_nan() {
                        *e = super::distance(&self.nodes[v.index()].0, q);
                    }
                    *e
                }
                _ => 0.0,
            },
        );
        let Some((_, path)) = found else {
            let reachable =
                petgraph::algo::dijkstra(&open, NodeIndex::new(n), None, |e| length(*e.weight()));
            return Err(reachable
                .keys()
                .map(|v| v.index())
                .filter(|&v| v < n)
                .collect());
        };
        let mut steps = vec![(path[0].index(), usize::MAX)];
        for w in path.windows(2) {
            let k = open
                .edges(w[0])
                .find(|e| e.target() == w[1])
                .map_or(usize::MAX, |e| *e.weight());
            steps.push((w[1].index(), k));
        }
        Ok(steps)
    }
}
