//! Constraints along a motion: their names, collision depths, and the independent re-check of
//! a recorded rollout.

use nalgebra::Vector2;
use trm_collision::{Other, World};

use crate::Result;
use crate::spec::Support;

use super::*;

/// The names of the constraints, in the order of [`Rollout::constraints`]: per motor lower and
/// upper position limit, velocity and torque; the four sides of the support polygon;
/// self-collision; world collision; and, with a reach, the final distance to its target.
pub fn constraint_names(problem: &WholeBody) -> Vec<String> {
    let mut names = Vec::new();
    for m in problem.model().motors() {
        for kind in ["lower limit", "upper limit", "velocity", "torque"] {
            names.push(format!("{} {kind}", m.name));
        }
    }
    for s in ["ZMP behind", "ZMP ahead", "ZMP right", "ZMP left"] {
        names.push(s.to_string());
    }
    names.push("self-collision".into());
    names.push("world collision".into());
    if problem.reach.is_some() {
        names.push("reach target".into());
    }
    names
}

impl WholeBody {
    /// The world objects, in the ground frame (x forward, y left, z up, between the soles).
    pub fn ground_world(&self) -> &World {
        &self.ground_world
    }

    /// A copy of the world for a rollout; [`WholeBody::world_penetration`] moves its objects
    /// into the root frame at every step.
    pub(super) fn world(&self) -> Result<World> {
        Ok(self.ground_world.clone())
    }

    pub(super) fn reach_gain(&self) -> f64 {
        self.spec.reach.as_ref().map_or(0.0, |r| r.gain)
    }

    /// Total penetration depth of the robot with itself at the posture in `frame` (0 if free).
    pub(super) fn self_penetration(&self, frame: &mut Frame) -> f64 {
        self.collision.place(&frame.poses, &mut frame.placed);
        if !self.spec.limits.self_collision || !self.collision.any_self_collision(&frame.placed) {
            return 0.0;
        }
        self.collision
            .colliding_pairs(&frame.placed, &World::new())
            .iter()
            .map(|p| -p.distance)
            .sum::<f64>()
            .max(1e-9)
    }

    /// Total penetration depth of the robot with the world objects (the seat's contact links
    /// excepted while it supports), after [`WholeBody::self_penetration`] placed the bodies.
    pub(super) fn world_penetration(
        &self,
        frame: &mut Frame,
        world: &mut World,
        support: Support,
    ) -> f64 {
        if self.ground_world.is_empty() {
            return 0.0;
        }
        let ground_to_root = frame.root_in_ground.inverse();
        for (i, o) in self.ground_world.objects().iter().enumerate() {
            let _ = world.set_pose_at(i, ground_to_root * o.pose());
        }
        if !self.collision.any_world_collision(&frame.placed, world) {
            return 0.0;
        }
        let seated = support == Support::FeetAndSeat;
        self.collision
            .colliding_pairs(&frame.placed, world)
            .iter()
            .filter(|p| match (&p.other, &self.seat) {
                (Other::Object(o), Some((seat, contacts, _))) if seated && o == seat => {
                    let link = self.collision.bodies()[p.body_index].link;
                    !contacts
                        .iter()
                        .any(|c| self.model().tree().links[link].name == *c)
                }
                (Other::Object(_), _) => true,
                _ => false,
            })
            .map(|p| -p.distance)
            .sum::<f64>()
            .max(0.0)
    }

    /// Re-checks a recorded rollout against every constraint without the controller's own
    /// bookkeeping: motor limits from the model, velocities from differences of the recorded
    /// positions, torques from central differences of the potential energy m g z_com, the ZMP
    /// from the recorded CoM, collisions from fresh queries. Returns one line per violated
    /// constraint (empty = feasible).
    pub fn verify(&self, r: &Rollout) -> Vec<String> {
        let mut found = std::collections::BTreeMap::<String, (usize, f64)>::new();
        let mut note = |what: String, t: f64| {
            found.entry(what).or_insert((0, t)).0 += 1;
        };
        let model = self.model();
        let dt = self.spec.dt;
        let mut frame = Frame::new(self);
        let mut world = self.world().unwrap_or_default();
        let h = 1e-6;
        let r_len = r.q.len();
        for (i, q) in r.q.iter().enumerate() {
            let t = r.times[i];
            let phase = &self.spec.phases[r.phase[i]];
            for (k, m) in model.motors().iter().enumerate() {
                if q[k] < m.limits.lower - 1e-12 || q[k] > m.limits.upper + 1e-12 {
                    note(format!("{} position", m.name), t);
                }
                if i + 1 < r.q.len()
                    && ((r.q[i + 1][k] - q[k]) / dt).abs() > self.velocity[k] + 1e-9
                {
                    note(format!("{} velocity", m.name), t);
                }
                if !phase.locked.contains(&m.name) {
                    let (mut up, mut down) = (q.clone(), q.clone());
                    up[k] += h;
                    down[k] -= h;
                    let dz = (self.com_at(&up)[2] - self.com_at(&down)[2]) / (2.0 * h);
                    let tau = self.mass * G * dz / self.joints_per_motor[k];
                    if tau.abs() > self.torque[k] * (1.0 + 1e-6) {
                        note(format!("{} torque", m.name), t);
                    }
                }
            }
            if i > 0 && i + 1 < r.com.len() {
                let (a, b, c) = (r.com[i - 1], r.com[i], r.com[i + 1]);
                let ax = (a[0] - 2.0 * b[0] + c[0]) / (dt * dt);
                let x = b[0] - b[2] * ax / G;
                let s = self.support_polygon(phase.support);
                if x < s[0] - 1e-9 || x > s[1] + 1e-9 || b[1] < s[2] || b[1] > s[3] {
                    note("ZMP outside the support polygon".into(), t);
                }
            }
            frame.update(self, q);
            if self.self_penetration(&mut frame) > 0.0 {
                note("self-collision".into(), t);
            }
            if self.world_penetration(&mut frame, &mut world, phase.support) > 0.0 {
                note("world collision".into(), t);
            }
            if let (Some((hand, target, _)), Some(r)) = (self.reach, &self.spec.reach) {
                if i + 1 == r_len {
                    let p = frame.point(self, hand);
                    if (Vector2::new(p.x, p.z) - target).norm() > r.tolerance + 1e-9 {
                        note("reach target missed".into(), t);
                    }
                }
            }
        }
        found
            .into_iter()
            .map(|(what, (n, t))| format!("{what}: {n} samples, first at t = {t:.2} s"))
            .collect()
    }
}
