//! [`ActiveSet`]: which motors are optimisation variables, the rest locked at given values.

use crate::batch::PoseBatch;
use crate::error::{KinematicsError, Result};
use crate::fk::{AffineRow, Plan, PoseBuffer};
use crate::model::{RobotModel, check_batch, check_vector};

/// A selection of motors as variables (the *active values*), every other motor locked. It maps
/// an active vector straight to joint values (couplings and locked motors folded into one sparse
/// affine map) and runs forward kinematics. `Send + Sync`; share it between threads.
///
/// ```
/// # use trm_kinematics::RobotModel;
/// let urdf = r#"<robot name="r"><link name="a"/><link name="b"/>
///   <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
///   <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#;
/// let model = RobotModel::from_urdf_str(urdf, "<doc>")?;
/// let active = model.active_set(&["j"], &model.neutral_motors())?;
/// let mut poses = model.pose_buffer();
/// active.forward(&[0.5], &mut poses)?;
/// # Ok::<(), trm_kinematics::KinematicsError>(())
/// ```
#[derive(Debug, Clone)]
pub struct ActiveSet {
    model: RobotModel,
    active: Vec<usize>,
    locked: Vec<f64>,
    /// Per joint: constant (offset plus locked motors) and `(active index, factor)` terms.
    rows: Vec<(f64, Vec<(usize, f64)>)>,
    plan: Plan,
}

impl RobotModel {
    /// Makes the motors named in `selection` (motor or group names, in that order) the
    /// variables; every other motor is locked at its value in `locked` (a full motor vector,
    /// e.g. [`RobotModel::posture`] or [`RobotModel::neutral_motors`]).
    pub fn active_set<S: AsRef<str>>(&self, selection: &[S], locked: &[f64]) -> Result<ActiveSet> {
        let active = self.select_motors(selection)?;
        ActiveSet::new(self.clone(), active, locked)
    }

    /// Every motor active, in motor order.
    pub fn all_active(&self) -> ActiveSet {
        ActiveSet::new(
            self.clone(),
            (0..self.motors().len()).collect(),
            &self.neutral_motors(),
        )
        .expect("the neutral posture is valid")
    }
}

impl ActiveSet {
    /// An active set from motor indices and a full motor vector for the locked ones.
    pub fn new(model: RobotModel, active: Vec<usize>, locked: &[f64]) -> Result<Self> {
        let motors = model.motors();
        check_vector("locked motor values", locked, motors.len(), |i| {
            &motors[i].name
        })?;
        if let Some(&bad) = active.iter().find(|&&m| m >= motors.len()) {
            return Err(KinematicsError::WrongLength {
                what: "active motor index",
                expected: motors.len(),
                got: bad,
            });
        }
        let mut position = vec![None; motors.len()];
        for (k, &m) in active.iter().enumerate() {
            if position[m].is_some() {
                return Err(KinematicsError::OutOfRange {
                    what: "active motors".into(),
                    problem: format!("`{}` is given twice; give each motor once", motors[m].name),
                });
            }
            position[m] = Some(k);
        }
        // Per joint: locked motors folded into the constant, active terms by active index.
        let rows: Vec<(f64, Vec<(usize, f64)>)> = model
            .couplings()
            .iter()
            .map(|c| {
                let mut constant = c.offset;
                let mut terms = Vec::new();
                for &(m, f) in &c.terms {
                    match position[m] {
                        Some(k) => terms.push((k, f)),
                        None => constant += f * locked[m],
                    }
                }
                (constant, terms)
            })
            .collect();
        let affine_rows: Vec<AffineRow> = rows
            .iter()
            .map(|(c, t)| AffineRow {
                constant: *c,
                terms: t,
            })
            .collect();
        let frames: Vec<_> = model
            .named_frames()
            .iter()
            .map(|f| (f.link, f.local_offset))
            .collect();
        let plan = Plan::compile(model.tree(), &frames, &affine_rows);
        Ok(ActiveSet {
            model,
            active,
            locked: locked.to_vec(),
            rows,
            plan,
        })
    }

    /// Per movable joint: constant and `(active index, factor)` terms.
    pub(crate) fn rows(&self) -> &[(f64, Vec<(usize, f64)>)] {
        &self.rows
    }

    /// The model.
    pub fn model(&self) -> &RobotModel {
        &self.model
    }

    /// Number of active motors (the optimisation dimension).
    pub fn len(&self) -> usize {
        self.active.len()
    }

    /// Whether no motor is active.
    pub fn is_empty(&self) -> bool {
        self.active.is_empty()
    }

    /// Motor indices of the active values, in order.
    pub fn motor_indices(&self) -> &[usize] {
        &self.active
    }

    /// Names of the active motors.
    pub fn names(&self) -> impl ExactSizeIterator<Item = &str> {
        self.active
            .iter()
            .map(|&m| self.model.motors()[m].name.as_str())
    }

    /// Lower and upper limits of the active motors (box bounds for an optimiser).
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let m = self.model.motors();
        (
            self.active.iter().map(|&i| m[i].limits.lower).collect(),
            self.active.iter().map(|&i| m[i].limits.upper).collect(),
        )
    }

    /// A configuration drawn uniformly within the active motors' limits (a motor whose limits
    /// coincide keeps that value). Seed `rng` for reproducible samples.
    pub fn random(&self, rng: &mut impl rand::Rng) -> Vec<f64> {
        use rand::RngExt;
        let m = self.model.motors();
        self.active
            .iter()
            .map(|&i| {
                let (l, u) = (m[i].limits.lower, m[i].limits.upper);
                if l < u { rng.random_range(l..=u) } else { l }
            })
            .collect()
    }

    /// Active values taken from a full motor vector.
    pub fn from_motors(&self, motors: &[f64]) -> Vec<f64> {
        self.active.iter().map(|&m| motors[m]).collect()
    }

    /// The full motor vector for active values `q` (locked motors at their locked values).
    pub fn to_motors(&self, q: &[f64]) -> Vec<f64> {
        let mut motors = self.locked.clone();
        for (&m, &v) in self.active.iter().zip(q) {
            motors[m] = v;
        }
        motors
    }

    /// The same active set, its forward kinematics computing only the poses of `links` (link
    /// indices, as [`crate::PoseBuffer`] and [`crate::PoseBlock`] hold them) and of their
    /// ancestors, and only the joint values those need: the poses of the other links and
    /// frames are left as they were. For a caller that reads a few poses, e.g. a collision
    /// check (links without collision geometry skipped). Out-of-range indices are ignored.
    pub fn pruned_to(&self, links: impl IntoIterator<Item = usize>) -> ActiveSet {
        let mut keep = vec![false; self.model.num_links() + self.model.named_frames().len()];
        for l in links {
            if let Some(k) = keep.get_mut(l) {
                *k = true;
            }
        }
        ActiveSet {
            plan: self.plan.pruned(&keep),
            ..self.clone()
        }
    }

    /// Number of distinct joint values one FK pass computes (joints held constant by locked
    /// motors are folded away; joints that always share a value share one computation).
    pub fn num_distinct_joint_values(&self) -> usize {
        self.plan.num_slots()
    }

    /// Joint values for active values `q`, without checks.
    #[inline]
    pub fn joint_values_unchecked(&self, q: &[f64], joints: &mut [f64]) {
        for (value, (constant, terms)) in joints.iter_mut().zip(&self.rows) {
            *value = crate::fk::affine(*constant, terms, q);
        }
    }

    /// Forward kinematics of active values `q` into `buffer` (made by
    /// [`RobotModel::pose_buffer`]). Checks the length and that every value is finite; values
    /// outside the limits are allowed (optimisers may probe there).
    pub fn forward(&self, q: &[f64], buffer: &mut PoseBuffer) -> Result<()> {
        check_vector("active motor values", q, self.active.len(), |i| {
            &self.model.motors()[self.active[i]].name
        })?;
        self.model.check_buffer(buffer)?;
        self.forward_unchecked(q, buffer);
        Ok(())
    }

    /// [`ActiveSet::forward`] without checks, for the hot path. Panics on a wrong-sized `q` or
    /// buffer; NaN in `q` gives NaN poses.
    #[inline]
    pub fn forward_unchecked(&self, q: &[f64], buffer: &mut PoseBuffer) {
        self.plan.run(q, buffer);
    }

    /// Forward kinematics of [`LANES`](crate::LANES) active-value vectors at once, one after
    /// the other in `q` (`LANES × len` values), into `batch` (made by
    /// [`RobotModel::pose_batch`]). Each lane's poses equal [`ActiveSet::forward`]'s to ≤ 1e-12.
    pub fn forward_batch(&self, q: &[f64], batch: &mut PoseBatch) -> Result<()> {
        check_batch("active motor values", q, self.active.len(), |i| {
            &self.model.motors()[self.active[i]].name
        })?;
        self.model.check_batch_buffer(batch)?;
        self.forward_batch_unchecked(q, batch);
        Ok(())
    }

    /// [`ActiveSet::forward_batch`] without checks, for the hot path. Panics on a wrong-sized
    /// `q` or batch.
    #[inline]
    pub fn forward_batch_unchecked(&self, q: &[f64], batch: &mut PoseBatch) {
        self.plan.run_batch(q, self.active.len(), batch);
    }

    /// Single-precision forward kinematics of [`BLOCK_LANES`](crate::BLOCK_LANES) active-value
    /// vectors at once, one after the other in `q` (`BLOCK_LANES × len` values), into `block`
    /// (made by [`RobotModel::pose_block`]): the [`ActiveSet::forward`] poses rounded to `f32`
    /// along the chain (a few units of 2⁻²⁴ of relative error per joint).
    pub fn forward_block(&self, q: &[f64], block: &mut crate::PoseBlock) -> Result<()> {
        crate::model::check_lanes(
            "active motor values",
            q,
            self.active.len(),
            crate::BLOCK_LANES,
            |i| &self.model.motors()[self.active[i]].name,
        )?;
        self.model.check_block_buffer(block)?;
        self.forward_block_unchecked(q, block);
        Ok(())
    }

    /// [`ActiveSet::forward_block`] without checks, for the hot path. Panics on a wrong-sized
    /// `q` or block.
    #[inline]
    pub fn forward_block_unchecked(&self, q: &[f64], block: &mut crate::PoseBlock) {
        self.plan.run_block(q, self.active.len(), block);
    }
}
