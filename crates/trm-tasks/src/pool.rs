//! Scratch buffers kept between parallel evaluations of an [`Objective`].

use std::sync::{Mutex, PoisonError};

use crate::objective::{Objective, Scratch};

/// Scratch buffers of an [`Objective`] kept between parallel evaluations: each worker leases
/// one (or makes one) and gives it back when its share is done, so repeated parallel
/// evaluations (every generation of a search, every chunk of a map build) allocate nothing once
/// the pool is warm. A buffer that does not fit the objective at hand
/// ([`Objective::scratch_fits`]) is dropped, not used.
#[derive(Debug, Default)]
pub struct ScratchPool(Mutex<Vec<Scratch>>);

impl ScratchPool {
    /// A buffer for `objective`: one kept in the pool, or a new one. It goes back to the pool
    /// when the lease is dropped.
    pub fn lease(&self, objective: &Objective) -> Lease<'_> {
        let kept = self
            .0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .pop()
            .filter(|s| objective.scratch_fits(s));
        Lease {
            pool: self,
            scratch: Some(kept.unwrap_or_else(|| objective.scratch())),
        }
    }
}

/// A scratch buffer leased from a [`ScratchPool`] (use it as a [`Scratch`]); back to the pool
/// when dropped.
#[derive(Debug)]
pub struct Lease<'a> {
    pool: &'a ScratchPool,
    /// Always `Some` until dropped.
    scratch: Option<Scratch>,
}

impl std::ops::Deref for Lease<'_> {
    type Target = Scratch;
    fn deref(&self) -> &Scratch {
        self.scratch
            .as_ref()
            .unwrap_or_else(|| unreachable!("taken only on drop"))
    }
}

impl std::ops::DerefMut for Lease<'_> {
    fn deref_mut(&mut self) -> &mut Scratch {
        self.scratch
            .as_mut()
            .unwrap_or_else(|| unreachable!("taken only on drop"))
    }
}

impl Drop for Lease<'_> {
    fn drop(&mut self) {
        if let Some(s) = self.scratch.take() {
            self.pool
                .0
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .push(s);
        }
    }
}
