//! Map builds across processes and machines with MPI (feature `mpi`, over the system's MPI
//! library through rsmpi). Every rank runs the build ([`Ranks`] is its [`Team`]): each owns
//! some of the P concurrent searches — their asks, evaluations, h_map and tells, on its own
//! threads — and keeps the same map; after every generation the ranks exchange the searches'
//! centres and outcomes (one all-gather), and the edges are checked a slice of the points per
//! rank. An evaluation gives the same bits wherever it runs, so a seed and P give the same map
//! on any number of ranks × threads. Give P ≥ the number of ranks × threads: a rank without a
//! search waits.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use mpi::traits::*;
//! let universe = mpi::initialize().ok_or("MPI is already initialised")?;
//! let world = universe.world();
//! let problem = trm_tasks::Problem::load("specs/reach.ron")?;
//! let mut ranks = trm_roadmap::mpi::Ranks::new(&world);
//! let map = trm_roadmap::Builder::new(&problem, &Default::default()).connected().run_with(&mut ranks, |_| {})?;
//! if world.rank() == 0 {
//!     map.save("reach.map.json")?;
//! }
//! # Ok(())
//! # }
//! ```

use mpi::Count;
use mpi::datatype::PartitionMut;
use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::traits::*;

use crate::error::{Result, RoadmapError};
use crate::team::Team;

/// The ranks of an MPI communicator as a build's [`Team`] (rank 0 writes the checkpoints).
pub struct Ranks<'w> {
    world: &'w SimpleCommunicator,
}

impl<'w> Ranks<'w> {
    /// The team of every rank of `world`; every rank makes its own and runs the build.
    pub fn new(world: &'w SimpleCommunicator) -> Self {
        Ranks { world }
    }
}

impl Team for Ranks<'_> {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn all_gather(&mut self, mine: &[u8]) -> Result<Vec<Vec<u8>>> {
        let too_long = || {
            RoadmapError::Unsuitable(format!(
                "MPI rank {}: {} bytes to exchange, more than MPI counts",
                self.world.rank(),
                mine.len()
            ))
        };
        let count = Count::try_from(mine.len()).map_err(|_| too_long())?;
        let mut counts = vec![0 as Count; self.size()];
        self.world.all_gather_into(&count, &mut counts[..]);
        let mut displacements = Vec::with_capacity(counts.len());
        let mut total: Count = 0;
        for &c in &counts {
            displacements.push(total);
            total = total.checked_add(c).ok_or_else(too_long)?;
        }
        let mut all = vec![0u8; total as usize];
        {
            let mut parts = PartitionMut::new(&mut all[..], &counts[..], &displacements[..]);
            self.world.all_gather_varcount_into(mine, &mut parts);
        }
        Ok(counts
            .iter()
            .zip(&displacements)
            .map(|(&c, &d)| all[d as usize..(d + c) as usize].to_vec())
            .collect())
    }
}
