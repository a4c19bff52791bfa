//! Checkpoints of a map build: everything [`crate::build`] holds between two generations — the
//! map so far, every running search (its xNES distribution and bookkeeping, random stream
//! position, origin point and centre), the master stream and the counters — so that
//! [`crate::resume`] finishes with exactly the map an uninterrupted build gives.
//!
//! File format `trm-checkpoint`, version 1: trm's binary layout
//! ([`trm_io::binary_bytes`]: postcard, every f64 bit for bit), written atomically.

use std::path::Path;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use trm_optim::XnesSnapshot;
use trm_tasks::Problem;

use crate::error::{Result, RoadmapError};
use crate::map::MapPoint;

/// The checkpoint format's name.
pub const CHECKPOINT_FORMAT: &str = "trm-checkpoint";
/// Current checkpoint version.
pub const CHECKPOINT_VERSION: u32 = 1;

/// Position in a ChaCha stream of the build's seed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct StreamPosition {
    pub(crate) stream: u64,
    pub(crate) word_pos: u128,
}

impl StreamPosition {
    pub(crate) fn of(rng: &ChaCha8Rng) -> Self {
        StreamPosition {
            stream: rng.get_stream(),
            word_pos: rng.get_word_pos(),
        }
    }

    pub(crate) fn rng(&self, seed: u64) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(self.stream);
        rng.set_word_pos(self.word_pos);
        rng
    }
}

/// A running search, between generations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct SearchState {
    pub(crate) xnes: XnesSnapshot,
    pub(crate) rng: StreamPosition,
    pub(crate) from: Option<usize>,
    pub(crate) centre_t: Vec<f64>,
    pub(crate) centre_f: f64,
}

/// A map build between two generations; see the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    pub(crate) software: String,
    pub(crate) spec_path: String,
    pub(crate) spec: String,
    pub(crate) active: Vec<String>,
    pub(crate) seed: u64,
    pub(crate) searches: usize,
    pub(crate) target: usize,
    pub(crate) max_generations: u64,
    pub(crate) repel_weight: f64,
    pub(crate) every: usize,
    pub(crate) master: StreamPosition,
    pub(crate) points: Vec<MapPoint>,
    pub(crate) fails: Vec<usize>,
    pub(crate) running: Vec<SearchState>,
    pub(crate) started: u64,
    pub(crate) failures: usize,
    pub(crate) total_failures: u64,
    pub(crate) evaluations: u64,
    pub(crate) seconds: f64,
}

impl Checkpoint {
    /// Points in the map so far.
    pub fn points(&self) -> usize {
        self.points.len()
    }

    /// The point count the build was going to.
    pub fn target(&self) -> usize {
        self.target
    }

    /// The point count a resumed build goes to: `points` when given, else the build's own
    /// target. A count below the points the checkpoint already holds is an error (a map does
    /// not shrink by resuming).
    pub fn resume_target(&self, points: Option<usize>) -> crate::Result<usize> {
        match points {
            Some(n) if n < self.points() => Err(crate::RoadmapError::Unsuitable(format!(
                "the checkpoint already holds {} points, more than the {n} points asked for: \
                 ask for at least {} points, or leave the count out to go on to the build's {}",
                self.points(),
                self.points(),
                self.target
            ))),
            Some(n) => Ok(n),
            None => Ok(self.target),
        }
    }

    /// The interval (points) at which the build wrote checkpoints.
    pub fn every(&self) -> usize {
        self.every
    }

    /// Seed and concurrent searches P of the build.
    pub fn seed_and_searches(&self) -> (u64, usize) {
        (self.seed, self.searches)
    }

    /// Where the build's spec came from.
    pub fn spec_path(&self) -> &str {
        &self.spec_path
    }

    /// Writes the checkpoint atomically (a temporary file renamed over `path`), so a build
    /// killed while writing leaves the previous checkpoint whole.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        Ok(trm_io::write_file_bytes(path, &self.to_bytes(path)?)?)
    }

    /// The checkpoint file's bytes (`path` names it in errors).
    pub fn to_bytes(&self, path: &Path) -> Result<Vec<u8>> {
        Ok(trm_io::binary_bytes(
            path,
            self,
            CHECKPOINT_FORMAT,
            CHECKPOINT_VERSION,
        )?)
    }

    /// Reads a checkpoint; another format or version, a truncated or damaged file, and one
    /// whose parts do not fit together are clear errors naming the file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_bytes(&trm_io::read_file_bytes(path)?, path)
    }

    /// Reads a checkpoint from a file's bytes (`path` names it in errors), checked as
    /// [`Checkpoint::load`] checks a file.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self> {
        let checkpoint: Checkpoint =
            trm_io::parse_binary_versioned(path, bytes, CHECKPOINT_FORMAT, CHECKPOINT_VERSION)?;
        checkpoint.check().map_err(|problem| RoadmapError::File {
            path: path.display().to_string(),
            problem: format!("{problem}; start the build again"),
        })?;
        Ok(checkpoint)
    }

    /// The task the build is for, rebuilt from the spec the checkpoint carries (as
    /// [`crate::Roadmap::problem`] does for a map).
    pub fn problem(&self) -> Result<Problem> {
        self.problem_with(&trm_tasks::SpecLoaders::default())
    }

    /// [`Checkpoint::problem`], the spec's files read by `loaders`.
    pub fn problem_with(&self, loaders: &trm_tasks::SpecLoaders) -> Result<Problem> {
        crate::map::problem_from_spec(&self.spec_path, &self.spec, &self.active, loaders)
    }

    /// Checks that the parts fit together (sizes, indices, finite values, counts within the
    /// build's limits); the spec itself is checked when [`Checkpoint::problem`] loads it.
    fn check(&self) -> std::result::Result<(), String> {
        let n = self.active.len();
        let dim = self.points.first().map_or(0, |p| p.t.len());
        if self.searches == 0 || self.searches > crate::MAX_SEARCHES {
            return Err(format!("{} concurrent searches", self.searches));
        }
        if self.target == 0 || self.target > crate::MAX_POINTS {
            return Err(format!("a target of {} points", self.target));
        }
        if self.every == 0 || self.every > crate::MAX_POINTS {
            return Err(format!("a checkpoint every {} points", self.every));
        }
        if !(self.repel_weight.is_finite() && self.repel_weight >= 0.0 && self.seconds >= 0.0) {
            return Err("a non-finite or negative setting".into());
        }
        for (i, p) in self.points.iter().enumerate() {
            if p.q.len() != n || p.t.len() != dim {
                return Err(format!("points[{i}] has the wrong size"));
            }
            if !(p.q.iter().chain(&p.t).all(|v| v.is_finite()) && p.cost.is_finite()) {
                return Err(format!("points[{i}] holds a non-finite value"));
            }
        }
        // counters far below their types' ends, so the build can go on counting
        const COUNT_LIMIT: u64 = 1 << 60;
        let counts = [
            self.started,
            self.evaluations,
            self.total_failures,
            self.failures as u64,
        ];
        if counts.iter().any(|&c| c >= COUNT_LIMIT)
            || self.fails.iter().any(|&f| f as u64 >= COUNT_LIMIT)
        {
            return Err("a counter of 2^60 or more".into());
        }
        if self.fails.len() != self.points.len() {
            return Err("failure counts and points differ in number".into());
        }
        if self.running.len() > self.searches || self.running.len() as u64 > self.started {
            return Err(format!(
                "{} running searches for P = {} and {} started",
                self.running.len(),
                self.searches,
                self.started
            ));
        }
        for (k, s) in self.running.iter().enumerate() {
            let fits = s.from.is_none_or(|i| i < self.points.len())
                && (self.points.is_empty() || s.centre_t.len() == dim)
                && s.rng.stream <= self.started;
            if !fits {
                return Err(format!("running search {k} does not fit the map"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Counters at the end of their types (which the build would overflow going on) and parts
    /// that do not fit together are refused on reading.
    #[test]
    fn checkpoints_with_absurd_counters_are_refused() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../specs/reach_point.ron");
        let problem = Problem::load(root).unwrap();
        let path = std::env::temp_dir().join(format!("trm-ck-{}.checkpoint", std::process::id()));
        let options = crate::BuildOptions {
            points: Some(2),
            checkpoint: Some(crate::CheckpointOptions {
                path: path.clone(),
                every: 1,
            }),
            ..Default::default()
        };
        crate::Builder::new(&problem, &options).run(|_| {}).unwrap();
        let good = Checkpoint::load(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        let reread = |c: &Checkpoint| {
            Checkpoint::from_bytes(&c.to_bytes(&path).unwrap(), &path).map_err(|e| e.to_string())
        };
        assert!(reread(&good).is_ok());
        let mut bad = Vec::new();
        for change in 0..5 {
            let mut c = good.clone();
            match change {
                0 => c.started = u64::MAX,
                1 => c.evaluations = u64::MAX - 1,
                2 => c.failures = usize::MAX,
                3 => c.fails[0] = usize::MAX,
                _ => c.fails.pop().map_or((), drop),
            }
            bad.push(reread(&c).unwrap_err());
        }
        assert!(
            bad.iter().all(|e| e.contains("start the build again")),
            "{bad:?}"
        );
    }
}
