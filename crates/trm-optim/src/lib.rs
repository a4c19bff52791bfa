//! Seeded ask/tell black-box optimisers: the engine of NGIK, usable on its own.
//!
//! Every algorithm implements [`Optimizer`]: `ask(&mut rng)` hands out candidates as one
//! contiguous [`Population`] (a reused buffer, no allocation), `tell(&fitness)` updates, `stop()` lists every [`StopReason`] that
//! fired. [`minimize`] runs the loop over a batch objective (evaluate the population in parallel
//! if you like) and returns a [`Report`] with the best point, when it was found, and the
//! best-so-far trace.
//!
//! ```
//! use rand::SeedableRng;
//! use trm_optim::{Start, StopOptions, Xnes, XnesOptions, functions::TestFunction, minimize_fn};
//!
//! let f = TestFunction::by_name("rosenbrock", 5, 0)?;
//! let start = Start::new(f.start(), 0.5).with_stop(StopOptions {
//!     target: Some(1e-8),
//!     max_evaluations: Some(50_000),
//!     ..Default::default()
//! });
//! let mut xnes = Xnes::new(&start, &XnesOptions::default())?;
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let report = minimize_fn(&mut xnes, &mut rng, |x| f.eval(x));
//! assert!(report.best_f <= 1e-8);
//! # Ok::<(), trm_optim::OptimError>(())
//! ```
//!
//! | module | algorithm | source |
//! |---|---|---|
//! | [`xnes`] | xNES | Glasmachers et al., GECCO 2010 |
//! | [`snes`] | separable NES | Schaul et al., GECCO 2011 |
//! | [`cmaes`] | CMA-ES, Hansen's defaults with active weights | Hansen, arXiv:1604.00772 |
//! | [`oneplusone`] | (1+1)-CMA-ES and its constrained variant, with bootstrap | Igel et al. 2006; Arnold & Hansen 2012; Modugno et al. |
//! | [`sir`] | SIR and SIRD particle methods | Stollenga et al., IROS 2013 |
//! | [`mh`] | Metropolis–Hastings | Stollenga et al., IROS 2013 |
//! | [`simplex`] | Nelder–Mead | Nelder & Mead 1965 |
//! | [`rprop`] | iRprop− (gradient-based, sign only) | Igel & Hüsken 2000 |
//!
//! Bounds: every algorithm clamps its candidates into the [`Bounds`] box before handing them
//! out; the distributions are not truncated.

// Numeric kernels index several arrays in step, and `!(x > 0.0)` deliberately catches NaN.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod algorithms;
pub mod cmaes;
mod core;
mod error;
pub mod functions;
mod linalg;
pub mod mh;
pub mod oneplusone;
pub mod rprop;
mod runner;
pub mod simplex;
pub mod sir;
pub mod snes;
pub mod xnes;

pub use algorithms::{ALGORITHMS, by_name};
pub use cmaes::{Cmaes, CmaesOptions};
pub use core::{Bounds, Optimizer, Population, Start, State, StepSize, StopOptions, StopReason};
pub use error::{OptimError, Result};
pub use mh::{MetropolisHastings, MhOptions};
pub use oneplusone::{ConstrainedReport, OnePlusOne, OnePlusOneOptions, minimize_constrained};
pub use rprop::{Rprop, RpropOptions};
pub use runner::{Generation, Report, minimize, minimize_fn};
pub use simplex::{NelderMead, SimplexOptions};
pub use sir::{Sir, SirOptions};
pub use snes::{Snes, SnesOptions};
pub use xnes::{Xnes, XnesOptions, XnesSnapshot};
