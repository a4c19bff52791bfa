//! `build-map --mpi`: the build shared among the ranks of an MPI job (feature `mpi`): each rank
//! runs some of the concurrent searches and a slice of the edge checks, every rank holds the
//! map, rank 0 shows progress and writes it.

use anyhow::Result;
use trm_roadmap::Checkpoint;

use crate::build_map::Job;

/// Runs `job` as this process's part of the MPI job.
#[cfg(feature = "mpi")]
pub fn build_map(job: Job, resumed: Option<Checkpoint>) -> Result<()> {
    use mpi::traits::*;
    let universe =
        mpi::initialize().ok_or_else(|| anyhow::anyhow!("--mpi: MPI could not be initialised"))?;
    let world = universe.world();
    if world.rank() == 0 {
        println!(
            "MPI: {} ranks × {} threads",
            world.size(),
            rayon::current_num_threads()
        );
    }
    let mut ranks = trm_roadmap::mpi::Ranks::new(&world);
    job.run(resumed, Some(&mut ranks))
}

/// Without the `mpi` feature: says how to get it.
#[cfg(not(feature = "mpi"))]
pub fn build_map(_job: Job, _resumed: Option<Checkpoint>) -> Result<()> {
    anyhow::bail!(
        "--mpi: this trm was built without MPI\n  fix: install an MPI library (Debian: libopenmpi-dev openmpi-bin libclang-dev), build with `cargo build --release -p trm --features mpi` and run `mpirun -n 2 target/release/trm build-map SPEC --mpi`"
    )
}
