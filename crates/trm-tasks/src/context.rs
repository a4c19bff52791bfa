//! What cost and task functions see: one candidate's active values, motors, link poses and
//! placed collision bodies, plus the world.

use trm_collision::{CollisionModel, PlacedBatch, PlacedBodies, World};
use trm_kinematics::nalgebra::{Isometry3, Point3, Vector3};
use trm_kinematics::{FrameId, LANES, PoseBatch, PoseBuffer, RobotModel};

/// One evaluated candidate. Built by [`crate::Objective`] after one forward-kinematics pass.
pub struct Context<'a> {
    /// The robot.
    pub robot: &'a RobotModel,
    /// Active values (the optimisation variables).
    pub q: &'a [f64],
    /// World poses of every frame.
    pub poses: &'a PoseBuffer,
    /// Collision geometry.
    pub collision: &'a CollisionModel,
    /// Collision bodies placed at this posture (placed only when a term needs them).
    pub placed: &'a PlacedBodies,
    /// The world.
    pub world: &'a World,
}

/// A point of interest: a frame of the robot, a world object's origin, or a fixed point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Anchor {
    /// A link or named frame.
    Frame(FrameId),
    /// A world object, by index.
    Object(usize),
    /// A fixed point in the world frame.
    Point([f64; 3]),
}

impl Anchor {
    /// The frame the anchor reads, if it is one.
    pub fn frame(&self) -> Option<FrameId> {
        match self {
            Anchor::Frame(f) => Some(*f),
            Anchor::Object(_) | Anchor::Point(_) => None,
        }
    }
}

/// What cost and task formulas read of one candidate, whether it was evaluated alone
/// ([`Context`]) or as a lane of a batch ([`LaneView`]): a term written once against it serves
/// `eval` and `eval_batch` alike, with the same values bit for bit.
pub trait Frames {
    /// Active values (the optimisation variables).
    fn q(&self) -> &[f64];
    /// The world.
    fn world(&self) -> &World;
    /// World pose of a link or named frame.
    fn pose(&self, frame: FrameId) -> Isometry3<f64>;
    /// World position of a link or named frame (cheaper than the whole [`Frames::pose`]).
    fn frame_position(&self, frame: FrameId) -> Point3<f64>;

    /// World position of an anchor.
    #[inline]
    fn position(&self, anchor: &Anchor) -> Point3<f64> {
        match anchor {
            Anchor::Frame(f) => self.frame_position(*f),
            Anchor::Object(o) => Point3::from(self.world().objects()[*o].pose().translation.vector),
            Anchor::Point(p) => Point3::from(*p),
        }
    }

    /// A frame's axis (given in the frame) in world coordinates.
    #[inline]
    fn axis(&self, frame: FrameId, local: &Vector3<f64>) -> Vector3<f64> {
        self.pose(frame).rotation * local
    }
}

impl Context<'_> {
    /// World position of an anchor.
    #[inline]
    pub fn position(&self, anchor: &Anchor) -> Point3<f64> {
        Frames::position(self, anchor)
    }

    /// A frame's axis (given in the frame) in world coordinates.
    #[inline]
    pub fn axis(&self, frame: FrameId, local: &Vector3<f64>) -> Vector3<f64> {
        Frames::axis(self, frame, local)
    }
}

impl Frames for Context<'_> {
    #[inline]
    fn q(&self) -> &[f64] {
        self.q
    }
    #[inline]
    fn world(&self) -> &World {
        self.world
    }
    #[inline]
    fn pose(&self, frame: FrameId) -> Isometry3<f64> {
        *self.poses.pose(frame)
    }
    #[inline]
    fn frame_position(&self, frame: FrameId) -> Point3<f64> {
        Point3::from(self.poses.pose(frame).translation.vector)
    }
}

/// One lane of a [`BatchContext`] seen as one candidate, read in place (no copy).
#[derive(Clone, Copy)]
pub struct LaneView<'b, 'a> {
    batch: &'b BatchContext<'a>,
    lane: usize,
}

impl Frames for LaneView<'_, '_> {
    #[inline]
    fn q(&self) -> &[f64] {
        self.batch.q[self.lane]
    }
    #[inline]
    fn world(&self) -> &World {
        self.batch.world
    }
    #[inline]
    fn pose(&self, frame: FrameId) -> Isometry3<f64> {
        self.batch.poses.pose(self.lane, frame)
    }
    #[inline]
    fn frame_position(&self, frame: FrameId) -> Point3<f64> {
        self.batch.frame_position(frame, self.lane)
    }
}

/// Up to [`LANES`](trm_kinematics::LANES) candidates evaluated together: their poses after one
/// batched forward-kinematics pass and their bodies placed in one batch. Built by
/// [`crate::Objective`]; costs and task functions that implement `eval_batch` read it directly,
/// the others see one [`Context`] per lane through [`BatchContext::lane`].
pub struct BatchContext<'a> {
    /// The robot.
    pub robot: &'a RobotModel,
    /// Active values of each candidate (one slice per lane in use).
    pub q: &'a [&'a [f64]],
    /// World poses of every frame in every lane.
    pub poses: &'a PoseBatch,
    /// Collision geometry.
    pub collision: &'a CollisionModel,
    /// Collision bodies placed in every lane (placed only when a term needs them).
    pub placed: &'a PlacedBatch,
    /// The world.
    pub world: &'a World,
    /// One-candidate copies of the poses and placed bodies, made when some term reads them.
    pub(crate) lane_poses: &'a [PoseBuffer],
    pub(crate) lane_placed: &'a [PlacedBodies],
    /// Per lane, colliding link pairs and (link, object) pairs, when the objective counted
    /// them with the single-precision screen.
    pub(crate) counts: Option<&'a [[usize; 2]]>,
}

impl<'a> BatchContext<'a> {
    /// Per lane, the number of colliding checked link pairs
    /// ([`CollisionModel::count_self`]): counted by the objective's screen when its terms read
    /// collisions only through these counts ([`crate::Cost::counts_collisions_only`]), else
    /// from the placed bodies.
    pub fn count_self(&self) -> [usize; LANES] {
        match self.counts {
            Some(counts) => std::array::from_fn(|l| counts.get(l).map_or(0, |c| c[0])),
            None => self.collision.count_self_batch(self.placed),
        }
    }

    /// Per lane, the number of colliding (link, world object) pairs
    /// ([`CollisionModel::count_world`]), as [`BatchContext::count_self`] gives its counts.
    pub fn count_world(&self) -> [usize; LANES] {
        match self.counts {
            Some(counts) => std::array::from_fn(|l| counts.get(l).map_or(0, |c| c[1])),
            None => self.collision.count_world_batch(self.placed, self.world),
        }
    }

    /// Number of candidates (lanes in use).
    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// Whether the batch holds no candidate.
    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }

    /// World position of a frame in lane `lane`, as [`Context::position`] gives it.
    #[inline]
    pub fn frame_position(&self, frame: FrameId, lane: usize) -> Point3<f64> {
        let p = &self.poses.lanes()[frame.index()];
        Point3::new(p[4][lane], p[5][lane], p[6][lane])
    }

    /// Lane `lane` as one candidate, read in place: what batched terms written against
    /// [`Frames`] evaluate.
    #[inline]
    pub fn view(&self, lane: usize) -> LaneView<'_, 'a> {
        debug_assert!(lane < self.len());
        LaneView { batch: self, lane }
    }

    /// The one-candidate context of lane `lane` (what the default `eval_batch` of costs and task
    /// functions evaluates).
    ///
    /// # Panics
    /// When the objective did not make one-candidate copies: it makes them whenever one of its
    /// terms or its task function does not say it is `batched`.
    pub fn lane(&self, lane: usize) -> Context<'a> {
        Context {
            robot: self.robot,
            q: self.q[lane],
            poses: &self.lane_poses[lane],
            collision: self.collision,
            placed: &self.lane_placed[lane],
            world: self.world,
        }
    }
}
