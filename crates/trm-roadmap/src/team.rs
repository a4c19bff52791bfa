//! The processes or threads a map build is shared among ([`Team`]): one ([`Solo`]), threads of
//! this process ([`on_threads`]), or MPI ranks (the `mpi` feature's `trm_roadmap::mpi`).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use crate::error::{Result, RoadmapError};

/// The processes a build is shared among. Every process runs the same build (the same problem,
/// options and seed) and keeps the same map; each owns some of the P concurrent searches, whose
/// asks, evaluations, h_map and tells it runs on its own threads, and after every generation
/// they exchange the searches' centres and outcomes. Every evaluation gives the same bits
/// wherever it runs and the map changes only between generations, in search order, so a seed
/// and P give the same map on any number of processes × threads. [`Solo`] is this process
/// alone, [`on_threads`] makes threads of this process a team (what [`crate::Builder::run`] does on
/// several threads), the `mpi` feature's `trm_roadmap::mpi::Ranks` are the ranks of an MPI
/// communicator.
pub trait Team {
    /// This process's index, `0..size()`. Rank 0 writes the checkpoints.
    fn rank(&self) -> usize;
    /// The number of processes.
    fn size(&self) -> usize;
    /// Every process's `mine`, in rank order, on every process. Collective: every process
    /// calls it at the same point of the build.
    fn all_gather(&mut self, mine: &[u8]) -> Result<Vec<Vec<u8>>>;
}

/// A team of one: the build runs in this process, on the threads of the current rayon pool.
#[derive(Debug, Default, Clone, Copy)]
pub struct Solo;

impl Team for Solo {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn all_gather(&mut self, mine: &[u8]) -> Result<Vec<Vec<u8>>> {
        Ok(vec![mine.to_vec()])
    }
}

/// The contiguous slice of `n` items that rank `rank` of `size` takes.
pub(crate) fn share(n: usize, size: usize, rank: usize) -> std::ops::Range<usize> {
    n * rank / size..n * (rank + 1) / size
}

/// Each process's values, gathered on every process and concatenated in rank order: `mine` as
/// little-endian bits, so every f64 arrives bit for bit.
pub(crate) fn all_gather_f64(team: &mut dyn Team, mine: &[f64]) -> Result<Vec<f64>> {
    let bytes: Vec<u8> = mine.iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut all = Vec::new();
    for (rank, part) in team.all_gather(&bytes)?.into_iter().enumerate() {
        if part.len() % 8 != 0 {
            return Err(RoadmapError::Unsuitable(format!(
                "process {rank} of the build sent {} bytes, not whole numbers; start every process with the same spec and options",
                part.len()
            )));
        }
        all.extend(
            part.chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap_or_default())),
        );
    }
    Ok(all)
}

/// What the members of a team of threads exchange through: the current round's deposits, and
/// the last complete round's.
struct Board {
    round: Mutex<Round>,
    turn: Condvar,
    /// `round.completed`, readable without the lock (members spin on it before they sleep).
    completed: AtomicU64,
}

/// How long a member waiting for the others spins before it sleeps: most waits of a
/// generation are microseconds, and waking a sleeping thread costs about as much again.
const SPIN: Duration = Duration::from_micros(200);

#[derive(Default)]
struct Round {
    slots: Vec<Vec<u8>>,
    arrived: usize,
    /// Complete rounds so far.
    completed: u64,
    last: Arc<Vec<Vec<u8>>>,
    /// A member stopped (an error or a panic): the others stop at their next exchange.
    aborted: bool,
}

impl Board {
    fn abort(&self) {
        if let Ok(mut round) = self.round.lock() {
            round.aborted = true;
        }
        // wakes spinning members too
        self.completed.fetch_add(1 << 63, Ordering::AcqRel);
        self.turn.notify_all();
    }
}

/// A member of a team of threads ([`on_threads`]).
struct Member {
    rank: usize,
    size: usize,
    board: Arc<Board>,
}

fn member_stopped() -> RoadmapError {
    RoadmapError::Unsuitable("another thread of the build stopped".into())
}

impl Team for Member {
    fn rank(&self) -> usize {
        self.rank
    }
    fn size(&self) -> usize {
        self.size
    }
    fn all_gather(&mut self, mine: &[u8]) -> Result<Vec<Vec<u8>>> {
        let mut round = self.board.round.lock().map_err(|_| member_stopped())?;
        if round.aborted {
            return Err(member_stopped());
        }
        round.slots[self.rank] = mine.to_vec();
        round.arrived += 1;
        if round.arrived == self.size {
            let slots = std::mem::replace(&mut round.slots, vec![Vec::new(); self.size]);
            round.last = Arc::new(slots);
            round.arrived = 0;
            round.completed += 1;
            self.board.completed.fetch_add(1, Ordering::AcqRel);
            self.board.turn.notify_all();
        } else {
            let waiting_for = round.completed;
            drop(round);
            let started = Instant::now();
            let mut spins = 0u32;
            while self.board.completed.load(Ordering::Acquire) == waiting_for {
                std::hint::spin_loop();
                spins += 1;
                if spins.is_multiple_of(64) && started.elapsed() > SPIN {
                    break;
                }
            }
            round = self.board.round.lock().map_err(|_| member_stopped())?;
            while round.completed == waiting_for && !round.aborted {
                round = self.board.turn.wait(round).map_err(|_| member_stopped())?;
            }
            if round.completed == waiting_for {
                return Err(member_stopped());
            }
        }
        Ok(round.last.as_ref().clone())
    }
}

/// Stops the other members when a member's thread ends without finishing (an error or a
/// panic).
struct AbortOnDrop<'a> {
    board: &'a Board,
    finished: bool,
}

impl Drop for AbortOnDrop<'_> {
    fn drop(&mut self) {
        if !self.finished {
            self.board.abort();
        }
    }
}

/// Runs `job` as `members` threads of this process, each a member of one [`Team`] with a
/// rayon pool of its own of `threads_each` threads (its evaluations and edge checks run
/// there), and returns rank 0's result. Rank 0's progress reports reach `progress` on the
/// calling thread. The first error of any member is returned (the others stop at their next
/// exchange).
pub fn on_threads<T: Send>(
    members: usize,
    threads_each: usize,
    job: impl Fn(&mut dyn Team, &mut dyn FnMut(&crate::Progress)) -> Result<T> + Sync,
    mut progress: impl FnMut(&crate::Progress),
) -> Result<T> {
    let members = members.max(1);
    let board = Board {
        round: Mutex::new(Round {
            slots: vec![Vec::new(); members],
            ..Default::default()
        }),
        turn: Condvar::new(),
        completed: AtomicU64::new(0),
    };
    let board = Arc::new(board);
    let (report, reports) = mpsc::channel::<crate::Progress>();
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..members)
            .map(|rank| {
                let (job, board, report) = (&job, board.clone(), report.clone());
                scope.spawn(move || -> Result<T> {
                    let mut guard = AbortOnDrop {
                        board: &board,
                        finished: false,
                    };
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads_each.max(1))
                        .build()
                        .map_err(|e| {
                            RoadmapError::Unsuitable(format!("cannot start build threads: {e}"))
                        })?;
                    let mut team = Member {
                        rank,
                        size: members,
                        board: board.clone(),
                    };
                    let mut forward = |p: &crate::Progress| {
                        if rank == 0 {
                            let _ = report.send(*p);
                        }
                    };
                    let result = pool.install(|| job(&mut team, &mut forward));
                    guard.finished = result.is_ok();
                    result
                })
            })
            .collect();
        drop(report);
        for p in reports {
            progress(&p);
        }
        let mut first = None;
        let mut failure = None;
        for handle in handles {
            match handle.join() {
                Ok(Ok(value)) => {
                    if first.is_none() {
                        first = Some(value);
                    }
                }
                Ok(Err(e)) => {
                    // a member's own error before "another thread stopped"
                    let secondary = e.to_string() == member_stopped().to_string();
                    if failure.is_none()
                        || (!secondary && failure.as_ref().is_some_and(|(s, _)| *s))
                    {
                        failure = Some((secondary, e));
                    }
                }
                Err(panic) => std::panic::resume_unwind(panic),
            }
        }
        match (failure, first) {
            (Some((_, e)), _) => Err(e),
            (None, Some(value)) => Ok(value),
            (None, None) => Err(member_stopped()),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_cover_every_item_once() {
        for n in [0, 1, 5, 31, 120] {
            for size in 1..6 {
                let mut next = 0;
                for rank in 0..size {
                    let s = share(n, size, rank);
                    assert_eq!(s.start, next);
                    next = s.end;
                }
                assert_eq!(next, n);
            }
        }
    }
}
