//! A grasp evaluation in trm's kinematic world: the hand is placed at a pose relative to an
//! object, each finger closes (its motors together, in small steps) until it touches the object,
//! and the grasp succeeds when the thumb and at least two fingers touch from opposing sides
//! while nothing penetrates.

use trm_collision::{CollisionModel, PlacedBodies, World};
use trm_kinematics::nalgebra::{Isometry3, Vector3};
use trm_kinematics::{PoseBuffer, RobotModel};

/// A finger: the motors that close it and the collision bodies it is made of.
#[derive(Debug, Clone)]
pub struct Finger {
    /// Name, e.g. `thumb`.
    pub name: String,
    /// Motors closed together from their lower to their upper limit.
    pub motors: Vec<usize>,
    /// Collision bodies of the finger.
    pub bodies: Vec<usize>,
    /// The finger's last link (its direction from the object axis decides opposition).
    pub tip_link: usize,
}

/// A hand of a robot model, ready to evaluate grasps.
#[derive(Debug, Clone)]
pub struct Hand {
    model: RobotModel,
    collision: CollisionModel,
    /// The hand (palm) link whose pose the grasp parameters give.
    pub hand_link: usize,
    /// Bodies of the palm, which must not penetrate the object.
    pub palm_bodies: Vec<usize>,
    /// The fingers; index 0 is the thumb.
    pub fingers: Vec<Finger>,
    /// Motor values before closing (the open hand; everything else at the model's home).
    pub open: Vec<f64>,
    /// Closing steps per finger.
    pub steps: usize,
    /// Largest penetration accepted (m): a closing step can overshoot the first contact.
    pub tolerance: f64,
}

/// The outcome of one grasp evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct GraspResult {
    /// Thumb and ≥ 2 fingers touch from opposing sides, nothing penetrates.
    pub success: bool,
    /// Opposition in [−1, 1]: mean −cos of the angle between the thumb's and each touching
    /// finger's direction from the object axis (1 = diametrically opposed); −1 on failure.
    pub quality: f64,
    /// Names of the fingers touching the object.
    pub touching: Vec<String>,
    /// The final motor vector.
    pub motors: Vec<f64>,
}

impl Hand {
    /// The iCub's right (`side = "r"`) or left (`"l"`) hand of the shipped model: thumb (opposed,
    /// closed by `thumb_proximal` and `thumb_distal`), index, middle and ring+little (`pinky`).
    pub fn icub(
        model: &RobotModel,
        collision: &CollisionModel,
        side: &str,
    ) -> trm_kinematics::Result<Self> {
        let m = |n: &str| model.motor_index(&format!("{side}_{n}"));
        // a model without the iCub's hand links is an error naming the link, not a panic
        let link = |n: &str| -> trm_kinematics::Result<usize> {
            Ok(model.frame_link(model.frame_id(&format!("{side}_hand{n}"))?))
        };
        let bodies_of = |parts: &[&str]| -> Vec<usize> {
            collision
                .bodies()
                .iter()
                .enumerate()
                .filter(|(_, b)| {
                    let name = &model.tree().links[b.link].name;
                    parts
                        .iter()
                        .any(|p| name.starts_with(&format!("{side}_hand_{p}")))
                })
                .map(|(i, _)| i)
                .collect()
        };
        let finger = |name: &str,
                      motors: Vec<usize>,
                      parts: &[&str],
                      tip: &str|
         -> trm_kinematics::Result<Finger> {
            Ok(Finger {
                name: name.into(),
                motors,
                bodies: bodies_of(parts),
                tip_link: link(tip)?,
            })
        };
        let fingers = vec![
            finger(
                "thumb",
                vec![m("thumb_proximal")?, m("thumb_distal")?],
                &["thumb"],
                "_thumb_3",
            )?,
            finger(
                "index",
                vec![m("index_proximal")?, m("index_distal")?],
                &["index"],
                "_index_3",
            )?,
            finger(
                "middle",
                vec![m("middle_proximal")?, m("middle_distal")?],
                &["middle"],
                "_middle_3",
            )?,
            finger("pinky", vec![m("pinky")?], &["ring", "little"], "_little_3")?,
        ];
        let hand_link = link("")?;
        let palm_bodies = collision
            .bodies()
            .iter()
            .enumerate()
            .filter(|(_, b)| b.link == hand_link)
            .map(|(i, _)| i)
            .collect();
        let mut open = model.home_motors();
        for f in &fingers {
            for &k in &f.motors {
                open[k] = model.motors()[k].limits.lower;
            }
        }
        let oppose = m("thumb_oppose")?;
        open[oppose] = model.motors()[oppose].limits.upper;
        Ok(Hand {
            model: model.clone(),
            collision: collision.clone(),
            hand_link,
            palm_bodies,
            fingers,
            open,
            steps: 24,
            tolerance: 0.004,
        })
    }

    fn all_bodies(&self) -> impl Iterator<Item = usize> + '_ {
        self.palm_bodies
            .iter()
            .chain(self.fingers.iter().flat_map(|f| &f.bodies))
            .copied()
    }

    /// The object moved so that the hand link (at its forward-kinematics pose) sits at `g` in
    /// the object's frame; returns the object's new pose too.
    fn place_object(
        &self,
        object: &World,
        g: &Isometry3<f64>,
        poses: &PoseBuffer,
    ) -> Option<(World, Isometry3<f64>)> {
        let to_world = poses.poses()[self.hand_link] * g.inverse();
        let mut world = World::new();
        for o in object.objects() {
            world
                .add(o.name(), o.shape().clone(), to_world * o.pose())
                .ok()?;
        }
        Some((world, to_world))
    }

    fn distance(&self, placed: &PlacedBodies, world: &World, body: usize) -> f64 {
        (0..world.len())
            .map(|o| self.collision.object_distance(placed, body, world, o))
            .fold(f64::INFINITY, f64::min)
    }

    /// C(g) for exploration: the grasp quality if the grasp at goal parameters `g` succeeds,
    /// −1 otherwise (feasible when > 0).
    pub fn quality(&self, object: &World, g: &[f64; 6]) -> f64 {
        let r = self.evaluate(object, &crate::to_pose(g));
        if r.success { r.quality } else { -1.0 }
    }

    /// Signed distance of every hand body to the object with the hand open at pose `g` (for
    /// finding a first grasp and for debugging).
    pub fn open_distances(&self, object: &World, g: &Isometry3<f64>) -> Vec<(String, f64)> {
        let mut poses = self.model.pose_buffer();
        let mut placed = self.collision.placed_bodies();
        if self.model.forward_motors(&self.open, &mut poses).is_err() {
            return Vec::new();
        }
        let Some((world, _)) = self.place_object(object, g, &poses) else {
            return Vec::new();
        };
        self.collision.place(&poses, &mut placed);
        self.all_bodies()
            .map(|b| {
                (
                    self.collision.bodies()[b].name.clone(),
                    self.distance(&placed, &world, b),
                )
            })
            .collect()
    }

    /// Evaluates the grasp with the hand link at pose `g` in the object's frame; `object` holds
    /// the object's parts in its own frame (capsules or cylinders along their z axes, e.g. one
    /// stick, or the segments of a basket handle); opposition is measured about the axis of the
    /// part nearest to the thumb.
    pub fn evaluate(&self, object: &World, g: &Isometry3<f64>) -> GraspResult {
        let mut poses = self.model.pose_buffer();
        let mut placed = self.collision.placed_bodies();
        let mut motors = self.open.clone();
        let fail = |motors: Vec<f64>, touching: Vec<String>| GraspResult {
            success: false,
            quality: -1.0,
            touching,
            motors,
        };
        if self.model.forward_motors(&motors, &mut poses).is_err() {
            return fail(motors, Vec::new());
        }
        let Some((world, to_world)) = self.place_object(object, g, &poses) else {
            return fail(motors, Vec::new());
        };
        self.collision.place(&poses, &mut placed);
        if self
            .all_bodies()
            .any(|b| self.distance(&placed, &world, b) < -self.tolerance)
        {
            return fail(motors, Vec::new());
        }
        let mut touching = Vec::new();
        for (fi, f) in self.fingers.iter().enumerate() {
            for s in 1..=self.steps {
                let u = s as f64 / self.steps as f64;
                for &k in &f.motors {
                    let l = self.model.motors()[k].limits;
                    motors[k] = l.lower + u * (l.upper - l.lower);
                }
                if self.model.forward_motors(&motors, &mut poses).is_err() {
                    return fail(motors, Vec::new());
                }
                self.collision.place(&poses, &mut placed);
                if f.bodies
                    .iter()
                    .any(|&b| self.distance(&placed, &world, b) <= 0.0)
                {
                    touching.push(fi);
                    break;
                }
            }
        }
        let names: Vec<String> = touching
            .iter()
            .map(|&i| self.fingers[i].name.clone())
            .collect();
        self.collision.place(&poses, &mut placed);
        if self
            .all_bodies()
            .any(|b| self.distance(&placed, &world, b) < -self.tolerance)
            || !touching.contains(&0)
        {
            return fail(motors, names);
        }
        // opposition about the axis (z) of the object part nearest to the thumb tip
        let thumb_tip = poses.poses()[self.fingers[0].tip_link].translation.vector;
        let part = world
            .objects()
            .iter()
            .min_by(|a, b| {
                let da = (a.pose().translation.vector - thumb_tip).norm();
                let db = (b.pose().translation.vector - thumb_tip).norm();
                da.total_cmp(&db)
            })
            .map(|o| *o.pose())
            .unwrap_or(to_world);
        let axis = part.rotation * Vector3::z();
        let centre = part.translation.vector;
        let direction = |link: usize| {
            let p = poses.poses()[link].translation.vector - centre;
            (p - axis * axis.dot(&p))
                .try_normalize(1e-9)
                .unwrap_or_else(Vector3::zeros)
        };
        let thumb = direction(self.fingers[0].tip_link);
        let cosines: Vec<f64> = touching
            .iter()
            .filter(|&&i| i != 0)
            .map(|&i| thumb.dot(&direction(self.fingers[i].tip_link)))
            .collect();
        if cosines.is_empty() {
            return fail(motors, names);
        }
        let opposing = cosines.iter().filter(|c| **c < 0.0).count();
        let quality = -cosines.iter().sum::<f64>() / cosines.len() as f64;
        GraspResult {
            success: opposing >= 2,
            quality,
            touching: names,
            motors,
        }
    }
}

/// Searches `samples` random object poses relative to the hand (positions in the box
/// `lower`–`upper` of the hand frame, any orientation) for a successful grasp; returns the best
/// as goal parameters g (the hand in the object's frame) with its quality.
pub fn find_grasp(
    hand: &Hand,
    object: &World,
    lower: [f64; 3],
    upper: [f64; 3],
    samples: usize,
    seed: u64,
) -> Option<([f64; 6], f64)> {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut best: Option<([f64; 6], f64)> = None;
    for _ in 0..samples {
        let t = Vector3::from_fn(|i, _| rng.random_range(lower[i]..=upper[i]));
        let r =
            Vector3::from_fn(|_, _| rng.random_range(-std::f64::consts::PI..std::f64::consts::PI));
        let g = Isometry3::new(t, r).inverse();
        let result = hand.evaluate(object, &g);
        if result.success && best.is_none_or(|(_, q)| result.quality > q) {
            best = Some((crate::to_params(&g), result.quality));
        }
    }
    best
}
