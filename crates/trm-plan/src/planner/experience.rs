//! A planner's kept paths (its experience) written to a file and read into another planner.

use std::path::Path;

use super::Planner;
use crate::PlanError;

/// The `"format"` of an experience file.
pub const EXPERIENCE_FORMAT: &str = "trm-experience";

/// The version of the experience files this software writes and reads.
pub const EXPERIENCE_VERSION: u32 = 1;

/// An experience file: the moving motors' names and each kept path's waypoints (their values,
/// in the motors' order).
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ExperienceFile {
    format: String,
    version: u32,
    motors: Vec<String>,
    paths: Vec<Vec<Vec<f64>>>,
}

impl Planner {
    /// Every kept path's waypoints (active values), in the order the paths were kept
    /// ([`Planner::add_path`]).
    pub fn kept_paths(&self) -> Vec<Vec<Vec<f64>>> {
        self.kept
            .iter()
            .map(|(ids, _)| ids.iter().map(|&i| self.nodes[i].0.clone()).collect())
            .collect()
    }

    /// Forgets every kept path ([`Planner::add_path`], [`Planner::load_experience`]): their
    /// nodes, their edges and the edges joining them to the rest of the graph. The maps stay,
    /// with what their checks found (a map attached after paths loses its joins to them), so
    /// that a planner kept across queries can be given other experience without compiling
    /// the robot or its world again; it then answers as a planner made with the same maps and
    /// given the new paths.
    pub fn forget_paths(&mut self) {
        if self.kept.is_empty() {
            return;
        }
        self.graph_changed();
        // what the forgotten paths were worth says nothing of the next ones
        self.graph_record = Default::default();
        // the maps' nodes, renumbered; their own edges and joins
        let keep_node = self.map_node.clone();
        let mut renumbered = vec![usize::MAX; self.nodes.len()];
        for (new, old) in (0..self.nodes.len()).filter(|&i| keep_node[i]).enumerate() {
            renumbered[old] = new;
        }
        let mut keep_edge: Vec<bool> = (self.edges.iter())
            .map(|&(a, b, _)| keep_node[a] && keep_node[b])
            .collect();
        for &e in self.kept.iter().flat_map(|(_, edges)| edges) {
            keep_edge[e] = false;
        }
        retain_marked(&mut self.nodes, &keep_node);
        retain_marked(&mut self.node_state, &keep_node);
        retain_marked(&mut self.map_node, &keep_node);
        retain_marked(&mut self.edges, &keep_edge);
        retain_marked(&mut self.edge_state, &keep_edge);
        for (a, b, _) in &mut self.edges {
            (*a, *b) = (renumbered[*a], renumbered[*b]);
        }
        self.kept.clear();
        self.kept_ends.clear();
        self.kept_keys.clear();
        self.kept_from.clear();
    }

    /// Forgets the path kept last ([`Planner::add_path`]) when no map was attached after it:
    /// the graph goes back to what it was before that path was kept, in time proportional to
    /// the path (not to the graph), so that a planner can be given experience and have it
    /// taken back in stack order without a rebuild. Whether a path was forgotten (not when
    /// none is kept, or a map came after it).
    pub fn forget_last_path(&mut self) -> bool {
        let Some(&(nodes, edges, maps)) = self.kept_from.last() else {
            return false;
        };
        if maps != self.maps {
            return false;
        }
        self.graph_changed();
        let k = self.kept.len() - 1;
        self.kept_from.pop();
        self.kept.pop();
        let d = self.active.len();
        self.kept_ends.truncate(2 * d * k);
        let at = (self.kept_keys.iter().rposition(|&(_, path)| path == k))
            .expect("every kept path has a key");
        self.kept_keys.remove(at);
        self.nodes.truncate(nodes);
        self.node_state.truncate(nodes);
        self.map_node.truncate(nodes);
        self.edges.truncate(edges);
        self.edge_state.truncate(edges);
        true
    }

    /// Writes the kept paths to `path` (a versioned JSON file, [`EXPERIENCE_FORMAT`]: the
    /// moving motors' names and every path's waypoints), atomically: a file that exists stays
    /// whole until the new one replaces it.
    pub fn save_experience(&self, path: impl AsRef<Path>) -> Result<(), PlanError> {
        let file = ExperienceFile {
            format: EXPERIENCE_FORMAT.into(),
            version: EXPERIENCE_VERSION,
            motors: self.active.names().map(str::to_string).collect(),
            paths: self.kept_paths(),
        };
        Ok(trm_io::save_json(path.as_ref(), &file, EXPERIENCE_FORMAT)?)
    }

    /// Keeps the paths of an experience file ([`Planner::save_experience`]), as
    /// [`Planner::add_path`] keeps a path: checked in the current world when a search wants
    /// them. A file written for other moving motors, or holding a waypoint that is not finite
    /// values of them, is refused whole (nothing is kept). Returns the number of paths kept.
    pub fn load_experience(&mut self, path: impl AsRef<Path>) -> Result<usize, PlanError> {
        let path = path.as_ref();
        let file: ExperienceFile =
            trm_io::load_versioned(path, EXPERIENCE_FORMAT, EXPERIENCE_VERSION)?;
        let refuse = |problem: String, fix: &str| PlanError::IncompatibleExperience {
            path: path.to_path_buf(),
            problem,
            fix: fix.into(),
        };
        if file
            .motors
            .iter()
            .map(String::as_str)
            .ne(self.active.names())
        {
            let ours: Vec<&str> = self.active.names().collect();
            return Err(refuse(
                format!(
                    "its paths move {} (in that order), the planner moves {}",
                    file.motors.join(", "),
                    ours.join(", ")
                ),
                "load it into a planner of the motors it was written for",
            ));
        }
        let n = file.motors.len();
        for (k, waypoints) in file.paths.iter().enumerate() {
            if waypoints.len() < 2 {
                return Err(refuse(
                    format!("path {k} has {} waypoints", waypoints.len()),
                    "give at least a start and a goal per path",
                ));
            }
            if let Some(w) = waypoints
                .iter()
                .position(|q| q.len() != n || q.iter().any(|v| !v.is_finite()))
            {
                return Err(refuse(
                    format!(
                        "path {k}, waypoint {w}: {} values, not {n} finite ones",
                        waypoints[w].len()
                    ),
                    "write the file again with save_experience",
                ));
            }
        }
        for waypoints in &file.paths {
            self.add_path(waypoints)?;
        }
        Ok(file.paths.len())
    }
}

/// Keeps the items of `items` whose place in `keep` is true, in order.
fn retain_marked<T>(items: &mut Vec<T>, keep: &[bool]) {
    let mut at = 0;
    items.retain(|_| {
        at += 1;
        keep[at - 1]
    });
}
