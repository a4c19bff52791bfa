//! The lazy search's graph and its A*: the map and kept nodes with a query's start and goal,
//! searched over what is not known blocked.

use petgraph::graph::{EdgeReference, NodeIndex, UnGraph};
use petgraph::visit::{EdgeFiltered, EdgeRef, IntoEdges};

use super::{Edge, Planner, State, Target};

impl Planner {
    /// The graph a query searches: the map and kept nodes, the start (node n) and goal
    /// (node n + 1), and every edge (the graph's, then `extra`), weighted by its index.
    pub(super) fn query_graph(&self, extra: &[Edge]) -> UnGraph<(), usize> {
        let total = self.nodes.len() + 2;
        let mut graph = UnGraph::<(), usize>::with_capacity(total, self.edges.len() + extra.len());
        for _ in 0..total {
            graph.add_node(());
        }
        for (k, &(a, b, _)) in self.edges.iter().chain(extra).enumerate() {
            graph.add_edge(NodeIndex::new(a), NodeIndex::new(b), k);
        }
        graph
    }

    /// A* on `graph` ([`Planner::query_graph`]) from the start (node n) to a goal node over the
    /// nodes and edges not known invalid, `estimate[v]` the heuristic of map node v: the path's
    /// nodes, each with the edge that reaches it (`usize::MAX` for the first; edges past the
    /// map's are `extra`'s). Without a path, the map nodes reachable from the start.
    pub(super) fn search(
        &self,
        graph: &UnGraph<(), usize>,
        extra: &[Edge],
        extra_state: &[State],
        target: &Target,
        estimate: &[f64],
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
            |v| estimate.get(v.index()).copied().unwrap_or(0.0),
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
