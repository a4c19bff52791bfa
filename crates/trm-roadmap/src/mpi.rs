//! Map builds across processes and machines with MPI (feature `mpi`, over the system's MPI
//! library through rsmpi). Rank 0 runs Algorithm 2 — selection, the searches' asks and tells,
//! h_map, CHECK, the map — and every generation spreads its candidates over all ranks in
//! contiguous slices; each rank evaluates its slice on its own threads and sends h and g back.
//! An evaluation gives the same bits wherever it runs, so a seed and P give the same map on any
//! number of ranks × threads.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use mpi::traits::*;
//! let universe = mpi::initialize().ok_or("MPI is already initialised")?;
//! let world = universe.world();
//! let problem = trm_tasks::Problem::load("specs/reach.ron")?;
//! if world.rank() == 0 {
//!     let mut ranks = trm_roadmap::mpi::Ranks::new(&world);
//!     let map = trm_roadmap::build_with(&problem, &Default::default(), &mut ranks, |_| {})?;
//!     map.save("reach.map.json")?;
//! } else {
//!     trm_roadmap::mpi::serve(&world, &problem.objective)?;
//! }
//! # Ok(())
//! # }
//! ```

use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::traits::*;
use trm_tasks::Objective;

use crate::build::{Evaluator, evaluate_on_threads};
use crate::error::{Result, RoadmapError};
use trm_tasks::ScratchPool;

/// Message tags: a slice of postures to evaluate, and the end of the build.
const WORK: i32 = 1;
const STOP: i32 = 2;

/// Batches with fewer candidates per rank than this stay on rank 0 (a round trip costs more
/// than a few evaluations).
const MIN_PER_RANK: usize = 4;

/// The slice of `n` candidates rank `rank` of `size` evaluates.
fn slice(n: usize, size: usize, rank: usize) -> std::ops::Range<usize> {
    n * rank / size..n * (rank + 1) / size
}

/// Rank 0's [`Evaluator`]: every batch spread over all ranks of `world` (rank 0 included) in
/// contiguous slices, one message to each rank and one back; small batches stay on rank 0. The
/// other ranks run [`serve`]. Dropping it releases them.
pub struct Ranks<'w> {
    world: &'w SimpleCommunicator,
    flat: Vec<f64>,
    scratch: ScratchPool,
}

impl<'w> Ranks<'w> {
    /// The evaluator of rank 0 of `world`.
    pub fn new(world: &'w SimpleCommunicator) -> Self {
        Ranks {
            world,
            flat: Vec::new(),
            scratch: ScratchPool::default(),
        }
    }
}

impl Evaluator for Ranks<'_> {
    fn evaluate(
        &mut self,
        objective: &Objective,
        qs: &[&[f64]],
        fitness: &mut [f64],
        tasks: &mut [f64],
    ) -> Result<()> {
        let n = qs.len();
        let dim = objective.task().map_or(0, |t| t.dim());
        let size = (self.world.size() as usize).min(n / MIN_PER_RANK).max(1);
        for rank in 1..size {
            self.flat.clear();
            for q in &qs[slice(n, size, rank)] {
                self.flat.extend_from_slice(q);
            }
            self.world
                .process_at_rank(rank as i32)
                .send_with_tag(&self.flat[..], WORK);
        }
        let own = slice(n, size, 0);
        evaluate_on_threads(
            objective,
            &qs[own.clone()],
            &mut fitness[own.clone()],
            &mut tasks[own.start * dim..own.end * dim],
            &self.scratch,
        );
        for rank in 1..size {
            // h of the slice, then g of each of its candidates
            let part = slice(n, size, rank);
            let (reply, _) = self.world.process_at_rank(rank as i32).receive_vec::<f64>();
            if reply.len() != part.len() * (1 + dim) {
                return Err(RoadmapError::Unsuitable(format!(
                    "MPI rank {rank} answered {} values for {} candidates of {dim} task dimensions",
                    reply.len(),
                    part.len()
                )));
            }
            let (h, g) = reply.split_at(part.len());
            fitness[part.clone()].copy_from_slice(h);
            tasks[part.start * dim..part.end * dim].copy_from_slice(g);
        }
        Ok(())
    }
}

impl Drop for Ranks<'_> {
    fn drop(&mut self) {
        for rank in 1..self.world.size() {
            self.world
                .process_at_rank(rank)
                .send_with_tag(&[0.0f64][..], STOP);
        }
    }
}

/// Evaluates rank 0's slices (ranks 1, 2, … of `world`) until its [`Ranks`] is dropped.
/// Every rank must hold the same objective (start them all with the same spec); a slice of
/// another posture size is an error.
pub fn serve(world: &SimpleCommunicator, objective: &Objective) -> Result<()> {
    let root = world.process_at_rank(0);
    let d = objective.active().len();
    let dim = objective.task().map_or(0, |t| t.dim());
    let mut reply = Vec::new();
    let scratch = ScratchPool::default();
    loop {
        let (flat, status) = root.receive_vec::<f64>();
        if status.tag() == STOP {
            return Ok(());
        }
        if flat.len() % d != 0 {
            return Err(RoadmapError::Unsuitable(format!(
                "MPI rank {}: rank 0 sent {} values, not postures of this rank's {d} motors; start every rank with the same spec",
                world.rank(),
                flat.len()
            )));
        }
        let qs: Vec<&[f64]> = flat.chunks(d).collect();
        let n = qs.len();
        reply.clear();
        reply.resize(n * (1 + dim), 0.0);
        let (h, g) = reply.split_at_mut(n);
        evaluate_on_threads(objective, &qs, h, g, &scratch);
        root.send(&reply[..]);
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn slices_cover_every_candidate_once() {
        for n in [0, 1, 5, 31, 120] {
            for size in 1..6 {
                let mut next = 0;
                for rank in 0..size {
                    let s = super::slice(n, size, rank);
                    assert_eq!(s.start, next);
                    next = s.end;
                }
                assert_eq!(next, n);
            }
        }
    }
}
