//! Task-relevant roadmaps: maps of postures that evenly cover a task space while satisfying a
//! task's costs (Stollenga et al., IROS 2013; parallel E-TRM of Stollenga, Schmidhuber and
//! Gomez). [`Builder`] grows a map with P concurrent xNES searches (writing [`Checkpoint`]s that
//! [`Builder::resume`] finishes exactly; [`Builder::run_with`] shares a build among processes,
//! e.g. the ranks of an MPI job with the `mpi` feature's `trm_roadmap::mpi`), [`connect`] adds
//! configuration-space edges, and [`Roadmap`] saves and loads map files.
//!
//! ```no_run
//! let problem = trm_tasks::Problem::load("specs/reach.ron")?;
//! // built and connected (the pieces: `Builder::run`, then `connect`)
//! let map = trm_roadmap::Builder::new(&problem, &Default::default()).connected().run(|p| eprintln!("{} points", p.points))?;
//! map.save("reach.map.json")?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod blocked;
mod build;
mod builder;
mod checkpoint;
mod edges;
mod error;
mod index;
mod map;
#[cfg(feature = "mpi")]
pub mod mpi;
mod repair;
mod team;

pub use blocked::{BlockIndex, Blocked, Changes, blocked_exhaustive};
pub use build::{MAX_POINTS, MAX_SEARCHES, Progress, evaluate_on_threads};
pub use builder::{BuildOptions, Builder, CheckpointOptions, DEFAULT_EDGE_RESOLUTION};
pub use checkpoint::{CHECKPOINT_FORMAT, CHECKPOINT_VERSION, Checkpoint};
pub use edges::{MIN_RESOLUTION, check_edge_resolution, connect, connect_with, segment_is_free};
pub use error::{Result, RoadmapError};
pub use index::TaskIndex;
pub use map::{BuildStats, FORMAT, MapPoint, MapSummary, Parked, Roadmap, VERSION};
pub use repair::{LiveMap, REPAIR_FAILURE_LIMIT, RepairOptions, RepairReport, repair};
pub use team::{Solo, Team, on_threads};
/// Scratch buffers kept between a build's parallel evaluations (from `trm_tasks`).
pub use trm_tasks::ScratchPool;
