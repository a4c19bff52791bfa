//! Single-precision collision checks, [`FAST_LANES`] configurations at once: sphere models as
//! they are, other models (mesh hulls) through spheres that enclose their bodies.
//!
//! VAMP's way (Thomason, Kingston and Kavraki, ICRA 2024): the robot as spheres, and every
//! number of a block of eight configurations one `f32` lane, so that each arithmetic step is one
//! 8-wide vector instruction (AVX2, chosen at run time; two 4-wide ones with SSE or NEON).
//! Spheres are screened link by link: a link's bounding sphere first, its own spheres only when
//! some lane's bounding spheres come close.
//!
//! **Exact verdicts, not approximate ones.** Single precision moves a sphere's centre by far less
//! than the [`FastWorld::margin`]; a pair whose distance exceeds the sum of its radii by more than
//! the margin is *clear*, one that falls short of it by more than the margin is *colliding*, and
//! anything between is *uncertain*. A lane with an uncertain pair and no certain collision is
//! handed back ([`Verdict::uncertain`]) for the exact `f64` check, so a caller that checks those
//! lanes exactly answers as the `f64` path does, configuration by configuration (tested on
//! random configurations of the Panda against [`CollisionModel::is_colliding`](crate::CollisionModel::is_colliding)).
//! [`FastChecker`] checks them pair by pair: only the link pairs and (link, object) pairs that
//! left the lane uncertain, each body placed alone.
//!
//! Robot bodies that are spheres (a spherized URDF, or one written by
//! [`fit::urdf_with_spheres`](crate::fit::urdf_with_spheres)) are the model itself. In other
//! models, a link whose bodies are all boxes, capsules or spheres (a model fitted by
//! `fit-proxies`, the iCub's capsules and boxes) is tested **as those bodies** against other
//! such links and against spheres, capsules and boxes in the world: boxes by their separating
//! axes, capsules by the closest points of their segments, a capsule against a box by
//! projections and bisection along its segment, each with the same exactness contract (a
//! tolerance of the margin scaled by the bodies' size; see `solid.rs`). Other bodies (mesh
//! hulls, cylinders) are *screened* through the spheres enclosing them
//! ([`CollisionModel::enclosing_spheres`](crate::CollisionModel::enclosing_spheres): a mesh's
//! convex hull cut into cells, each enclosed exactly), so that contact is only a reason to look
//! exactly, and through spheres inside them ([`Shape::inscribed_spheres`](crate::Shape::inscribed_spheres)),
//! whose contact is a certain collision. A link that is one box, against a link screened
//! through spheres, is tested as that box: the other link's spheres are taken into its frame. A
//! block whose lanes are left uncertain by two links of convex hulls gets a second, tighter
//! screen before the exact checks: each link's spheres against the other's 18-sided bounding
//! polytope (k-DOP). Of such models, a pair that one or two revolute joints alone move
//! relative to each other (a forearm and the links beyond its wrist) is first looked up in its
//! clearance table: cells of those joints' angles proved free or colliding when compiling
//! (`table.rs`). World objects of every
//! shape are taken: spheres, capsules and boxes are checked in single precision, cylinders and
//! convex hulls through their bounding spheres (a lane near one is uncertain). Point clouds sit in a counting-sorted uniform grid whose cells
//! know their clearance (`cloud.rs`): a sphere, capsule or box is measured to the points within
//! its reach, so points are decided in single precision as the primitives are; a triangle mesh
//! is screened through samples at most 4 mm apart on its triangles (a lane within that of
//! contact is uncertain).

// Lane loops index several arrays at once, the form the vectoriser turns into one instruction;
// `!(x > limit)` is the NaN-inclusive test on purpose.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod avx;
mod checker;
mod cloud;
mod kdop;
mod lanes;
mod model;
mod outcome;
mod solid;
mod table;
#[cfg(all(test, target_arch = "x86_64"))]
mod tests;
mod walk;
mod world;

pub use checker::FastChecker;
pub use model::FastModel;
pub use outcome::{Tally, Verdict};
pub use walk::FastScratch;
pub use world::FastWorld;

use trm_kinematics::BLOCK_LANES;

/// Configurations per block ([`BLOCK_LANES`] of single-precision forward kinematics).
pub const FAST_LANES: usize = BLOCK_LANES;

/// One bit per configuration of a block (bit `l`: configuration `l`).
pub type LaneMask = u8;

/// Every configuration of a block.
pub const ALL_LANES: LaneMask = u8::MAX;
