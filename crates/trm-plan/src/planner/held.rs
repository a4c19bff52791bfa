//! Objects the robot holds: attached to the planner's collision model, every check made again
//! for the robot's new shape.

use trm_collision::AttachedObject;

use super::Planner;
use crate::PlanError;

impl Planner {
    /// What the robot holds ([`Planner::attach`]).
    pub fn attached(&self) -> &[AttachedObject] {
        self.objective.collision().attached()
    }

    /// Holds `object`: it moves with its link and is checked against the world and the robot's
    /// other links but its touch links, in every later query. The checks are made again for the
    /// robot's new shape: every node and edge of the maps and kept paths will be checked again
    /// when a search wants it.
    pub fn attach(&mut self, object: AttachedObject) -> Result<(), PlanError> {
        let held = self.objective.collision().with_attached(object)?;
        self.set_collision(&held).map(drop)
    }

    /// Puts down the held object `name` (an error naming the held objects when there is none
    /// of that name); nodes and edges are checked again, as for [`Planner::attach`].
    pub fn detach(&mut self, name: &str) -> Result<(), PlanError> {
        let released = self.objective.collision().without_attached(name)?;
        self.set_collision(&released).map(drop)
    }

    /// Holds exactly `held` (a planning scene's or a request's attached objects), putting down
    /// the others; nothing changes when the robot already holds these. Whether it changed.
    pub fn set_attached(&mut self, held: Vec<AttachedObject>) -> Result<bool, PlanError> {
        let current = self.objective.collision();
        if current.attached() == held.as_slice() {
            return Ok(false);
        }
        let mut model = current.clone();
        for o in current.attached() {
            model = model.without_attached(&o.name)?;
        }
        for o in held {
            model = model.with_attached(o)?;
        }
        self.set_collision(&model)
    }

    /// Holds `objects` as well as what the robot already holds, each replacing a held object
    /// of the same name (a MoveIt request's start state over its scene's). Whether it changed.
    pub fn hold(&mut self, objects: &[AttachedObject]) -> Result<bool, PlanError> {
        let mut held = self.attached().to_vec();
        for object in objects {
            held.retain(|o| o.name != object.name);
            held.push(object.clone());
        }
        self.set_attached(held)
    }
}
