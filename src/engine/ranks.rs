//! Runs over MPI ranks (cargo feature `mpi`): under `mpirun -np N smithwalk run CONFIG`, rank
//! R walks share R/N of the work, exactly as `--shard R/N` would, and rank 0 gathers the raw
//! accumulators of every rank and merges them with exact integer sums. The outputs are
//! therefore bit-identical to the unsplit run's, like `smithwalk merge` of N shards.

use anyhow::{Context, Result};
use mpi::Threading;
use mpi::environment::Universe;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives, Destination, Source};

use crate::engine::run::Shard;

/// The rank that gathers the accumulators and writes the outputs.
const ROOT: i32 = 0;

/// Largest message: MPI counts elements in `i32`, so a shard is sent in pieces below 2^31 bytes.
const PIECE: usize = 1 << 30;

/// The MPI job this process belongs to.
pub struct Ranks {
    /// Keeps MPI initialised; dropping it finalises MPI.
    _universe: Universe,
    world: SimpleCommunicator,
}

impl Ranks {
    /// Joins the MPI job this process was started in; `None` for a job of one rank (a plain
    /// `smithwalk run`, or `mpirun -np 1`), which runs as usual. Only the main thread talks
    /// to MPI, while the walk's worker threads never do (`MPI_THREAD_FUNNELED`).
    pub fn join() -> Result<Option<Ranks>> {
        let (universe, _) = mpi::initialize_with_threading(Threading::Funneled)
            .context("cannot initialise MPI (was it initialised twice?)")?;
        let world = universe.world();
        Ok((world.size() > 1).then_some(Ranks { _universe: universe, world }))
    }

    /// This rank's share of the work.
    pub fn shard(&self) -> Shard {
        Shard { index: self.world.rank() as u64, count: self.world.size() as u64 }
    }

    pub fn is_root(&self) -> bool {
        self.world.rank() == ROOT
    }

    /// Worker threads for this rank when none are asked for: the machine's cores shared among
    /// the ranks on this machine (those that share its memory), at least one.
    pub fn default_threads(&self) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let here = self.world.split_shared(self.world.rank()).size() as usize;
        (cores / here.max(1)).max(1)
    }

    /// Sends this rank's `bytes` to the root. On the root, returns every rank's bytes in rank
    /// order (its own first), each named `rank R`; elsewhere `None`.
    pub fn gather(&self, bytes: Vec<u8>) -> Option<Vec<(String, Vec<u8>)>> {
        if !self.is_root() {
            let root = self.world.process_at_rank(ROOT);
            root.send(&(bytes.len() as u64));
            for piece in bytes.chunks(PIECE) {
                root.send(piece);
            }
            return None;
        }
        let mut all = vec![(format!("rank {ROOT}"), bytes)];
        for rank in 1..self.world.size() {
            let from = self.world.process_at_rank(rank);
            let (len, _) = from.receive::<u64>();
            let mut received = Vec::with_capacity(len as usize);
            while (received.len() as u64) < len {
                received.extend(from.receive_vec::<u8>().0);
            }
            all.push((format!("rank {rank}"), received));
        }
        Some(all)
    }

    /// Waits until every rank gets here.
    pub fn barrier(&self) {
        self.world.barrier();
    }

    /// Ends the whole job when this rank failed: the error, named by rank, goes to stderr and
    /// every rank stops with a non-zero exit (the others may be waiting for this one).
    pub fn abort_on_error<T>(&self, result: Result<T>) -> T {
        result.unwrap_or_else(|e| {
            let Shard { index, count } = self.shard();
            eprintln!("error (rank {index} of {count}): {e:#}");
            self.world.abort(1)
        })
    }
}
