//! Whole-body motions with switching contacts and their safe trajectory optimisation, after
//! Modugno, Nava, Pucci, Nori, Oriolo and Ivaldi, "Safe trajectory optimization for whole-body
//! motion of humanoids" (Humanoids 2017): a robot stands up from a chair by tracking an
//! RBF-parametrised centre-of-mass trajectory; (1+1)-CMA-ES finds a feasible trajectory, then
//! (1+1)-CMA-ES with constrained covariance adaptation improves it without ever accepting one
//! that violates a constraint.
//!
//! What is modelled, and what is not (we have no dynamics simulator):
//! * **Kinematic, quasi-static.** Both feet stay flat on the ground; the robot moves
//!   symmetrically in its sagittal plane (the `icub_sagittal` model couples left and right
//!   joints), which keeps the closed double-support chain closed exactly. The pelvis pose
//!   follows from the feet.
//! * **Controller.** A prioritised damped least-squares differential IK tracks the desired CoM
//!   (x, z), then optionally a hand reaching a target, with a minimum-jerk keyframe posture task
//!   in the null space of both; joint velocities pass a first-order filter; motors listed as
//!   locked in a phase (the legs while seated) do not move. Not the paper's torque-level
//!   centroidal-momentum QP.
//! * **Torques** are static: ∂(m g z_com)/∂q with the feet fixed, split equally between the left
//!   and right joint a motor drives; while the seat supports the robot, the locked legs carry
//!   nothing (the seat/foot load split is statically indeterminate and not modelled).
//! * **Balance.** The cart-table ZMP x_zmp = x_com − z_com ẍ_com / g (ẍ by central
//!   differences of the simulated CoM) must stay in the conservative support polygon: the feet
//!   shrunk by a margin, plus the seat while seated. Leaving the unshrunk polygon counts as a
//!   fall.
//!
//! Constraints along the whole motion: position, velocity and static-torque limits, ZMP,
//! self-collision and collision with the world (the seat's contact links excepted while it
//! supports); [`WholeBody::verify`] re-checks a rollout independently. Spec format:
//! [`formats::motion_spec`].
//!
//! ```no_run
//! let problem = trm_wholebody::WholeBody::load("specs/wholebody/standup.ron")?;
//! let hand = problem.hand_tuned()?;
//! println!("{} violations", hand.violations());
//! # Ok::<(), trm_wholebody::WholeBodyError>(())
//! ```

// errors carry the file, place and fix of a spec problem; they are cold, so their size is fine

mod error;
pub mod motion;
pub mod optimize;
pub mod spec;

pub use motion::{Costs, Rollout, WholeBody, constraint_names};
pub use optimize::{Comparison, StandUpResult, optimize};
pub use spec::{MotionSpec, Support};

pub use error::WholeBodyError;

/// The file formats this crate reads and writes.
pub mod formats {
    #[doc = include_str!("../docs/motion-spec.md")]
    pub mod motion_spec {}
}

/// Result alias of this crate.
pub type Result<T, E = WholeBodyError> = std::result::Result<T, E>;
