//! Lever arms: how far a point of a robot's bodies can move per unit change of each active
//! coordinate, bounded for every configuration at once. A step `Δq` moves no point of link
//! `L` by more than `Σᵢ |Δqᵢ| λᵢ(L)` (and so by more than `‖Δq‖₂ ‖λ(L)‖₂`): for a revolute
//! joint, a point's distance from the joint's axis is at most the lengths of the fixed offsets
//! between the joint and the link plus the point's distance from the link's origin; a
//! prismatic joint moves every point beyond it by its own displacement. The bounds size
//! planners' steps by the robot instead of by hand ([`Levers::max_reach`]) and bound how far
//! bodies sweep between checked configurations.

use trm_kinematics::{ActiveSet, JointKind};

use crate::{CollisionModel, Result};

/// Per link with bodies: the largest displacement of its points per unit of each active
/// coordinate (m/rad for revolute joints, m/m for prismatic ones).
#[derive(Debug, Clone, PartialEq)]
pub struct Levers {
    /// `(link index, λ per active coordinate)`, for the links that have bodies.
    links: Vec<(usize, Vec<f64>)>,
    /// Per link with bodies (indexed by link): its chain to the root, each movable joint's tree
    /// index and joint-value index with the displacement of the link's points per unit of that
    /// joint's value.
    chains: Vec<Vec<(usize, usize, f64)>>,
    /// Per joint value: `|∂ joint value / ∂ active coordinate|` for each active coordinate.
    slopes: Vec<Vec<f64>>,
    /// The number of active coordinates.
    coordinates: usize,
}

impl Levers {
    /// The lever arms of `collision`'s bodies for the coordinates of `active` (an error for an
    /// active set of another robot). Coupled motors count every joint they drive.
    pub fn new(collision: &CollisionModel, active: &ActiveSet) -> Result<Levers> {
        collision.check_active(active)?;
        let robot = collision.robot();
        let tree = robot.tree();
        // the joints' values are affine in the active coordinates: their slopes, exactly
        let (n, joints) = (active.len(), robot.num_joints());
        let (mut at_zero, mut moved) = (vec![0.0; joints], vec![0.0; joints]);
        active.joint_values_unchecked(&vec![0.0; n], &mut at_zero);
        let mut slopes = vec![vec![0.0; n]; joints];
        for i in 0..n {
            let unit: Vec<f64> = (0..n).map(|k| f64::from(u8::from(k == i))).collect();
            active.joint_values_unchecked(&unit, &mut moved);
            for (row, (m, z)) in slopes.iter_mut().zip(moved.iter().zip(&at_zero)) {
                row[i] = (m - z).abs();
            }
        }
        // each link's farthest body point from its origin
        let mut extent = vec![None::<f64>; tree.links.len()];
        for (b, body) in collision.bodies().iter().enumerate() {
            for s in collision.enclosing_spheres(b) {
                let far = s.center.coords.norm() + s.radius;
                let e = extent[body.link].get_or_insert(0.0);
                *e = e.max(far);
            }
        }
        let mut links = Vec::new();
        let mut chains = vec![Vec::new(); tree.links.len()];
        for (link, e) in extent.iter().enumerate() {
            let Some(e) = *e else { continue };
            let mut lambda = vec![0.0; n];
            // up the chain: `arm` bounds the distance from the current joint's origin (its
            // child link's origin) to the link's points
            let (mut child, mut arm) = (link, e);
            while let Some(j) = tree.links[child].parent_joint {
                let joint = &tree.joints[j];
                if let Some(c) = joint.coordinate {
                    let per_unit = match joint.kind {
                        JointKind::Prismatic => 1.0,
                        _ => arm,
                    };
                    for (l, &slope) in lambda.iter_mut().zip(&slopes[c]) {
                        *l += slope * per_unit;
                    }
                    chains[link].push((j, c, per_unit));
                }
                arm += joint.local_origin.translation.vector.norm();
                if joint.kind == JointKind::Prismatic {
                    arm += joint.limits.lower.abs().max(joint.limits.upper.abs())
                        + crate::certify::TRAVEL_SLACK;
                }
                child = joint.parent;
            }
            links.push((link, lambda));
        }
        Ok(Levers {
            links,
            chains,
            slopes,
            coordinates: n,
        })
    }

    /// The displacement of link `link`'s points per unit of joint `joint`'s value (tree joint
    /// index), when the joint moves the link.
    pub(crate) fn arm(&self, link: usize, joint: usize) -> Option<f64> {
        let chain = self.chains.get(link)?;
        chain
            .iter()
            .find(|&&(j, _, _)| j == joint)
            .map(|&(_, _, per_unit)| per_unit)
    }

    /// Link `link`'s chain to the root, from the link up: each movable joint's tree index and
    /// joint-value index with the displacement of the link's points per unit of that joint's
    /// value (empty for a link without bodies).
    pub(crate) fn chain(&self, link: usize) -> &[(usize, usize, f64)] {
        &self.chains[link]
    }

    /// The number of active coordinates.
    pub fn num_coordinates(&self) -> usize {
        self.coordinates
    }

    /// `(link index, λ per active coordinate)` for every link with bodies.
    pub fn links(&self) -> &[(usize, Vec<f64>)] {
        &self.links
    }

    /// λ of link `a`'s points *relative to* link `b`'s, per active coordinate: the joints the
    /// two links' chains share move both rigidly together and leave their distance unchanged,
    /// so only the joints below their common ancestor count (a step `Δq` changes the distance
    /// between a body of `a` and a body of `b` by at most `Σᵢ |Δqᵢ| λᵢ`). Written into `out`
    /// (one value per active coordinate); a link without bodies counts as not moving.
    ///
    /// # Panics
    /// If a link index is out of range or `out` does not hold one value per active coordinate.
    pub fn relative_into(&self, a: usize, b: usize, out: &mut [f64]) {
        assert_eq!(
            out.len(),
            self.coordinates,
            "one value per active coordinate"
        );
        out.fill(0.0);
        let (ca, cb) = (&self.chains[a], &self.chains[b]);
        for (own, other) in [(ca, cb), (cb, ca)] {
            for &(joint, c, per_unit) in own {
                if other.iter().any(|&(j, _, _)| j == joint) {
                    continue;
                }
                for (o, s) in out.iter_mut().zip(&self.slopes[c]) {
                    *o += s * per_unit;
                }
            }
        }
    }

    /// λ of link `link`'s points per active coordinate (zeros for a link without bodies).
    ///
    /// # Panics
    /// If `link` is out of range or `out` does not hold one value per active coordinate.
    pub fn link_into(&self, link: usize, out: &mut [f64]) {
        assert_eq!(
            out.len(),
            self.coordinates,
            "one value per active coordinate"
        );
        out.fill(0.0);
        for &(_, c, per_unit) in &self.chains[link] {
            for (o, s) in out.iter_mut().zip(&self.slopes[c]) {
                *o += s * per_unit;
            }
        }
    }

    /// The largest displacement of any body point per unit Euclidean step in the active
    /// coordinates: `maxₗ ‖λ(L)‖₂` (0 for a robot no coordinate moves).
    pub fn max_reach(&self) -> f64 {
        self.links
            .iter()
            .map(|(_, lambda)| lambda.iter().map(|l| l * l).sum::<f64>().sqrt())
            .fold(0.0, f64::max)
    }

    /// The farthest any body point moves along the straight step `dq` (active coordinates):
    /// `maxₗ Σᵢ |dqᵢ| λᵢ(L)`.
    ///
    /// # Panics
    /// If `dq` does not hold one value per active coordinate.
    pub fn displacement(&self, dq: &[f64]) -> f64 {
        self.links
            .iter()
            .map(|(_, lambda)| {
                assert_eq!(lambda.len(), dq.len(), "one value per active coordinate");
                lambda.iter().zip(dq).map(|(l, d)| l * d.abs()).sum::<f64>()
            })
            .fold(0.0, f64::max)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use trm_kinematics::RobotModel;

    /// A planar arm of two 1 m links (revolute about z), a 0.1 m sphere at each link's end.
    pub(crate) fn arm() -> CollisionModel {
        let urdf = r#"<robot name="arm">
          <link name="base"/>
          <link name="a"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.1"/></geometry></collision></link>
          <link name="b"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.1"/></geometry></collision></link>
          <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
            <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
          <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="1 0 0"/>
            <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
        </robot>"#;
        let robot = RobotModel::from_urdf_str(urdf, "<arm>").unwrap();
        CollisionModel::new(&robot).unwrap()
    }

    #[test]
    fn levers_bound_the_motion_of_every_point() {
        let collision = arm();
        let active = collision.robot().all_active();
        let levers = Levers::new(&collision, &active).unwrap();
        // link b's sphere: 1.1 m from j2, at most 2.1 m from j1
        let (_, b) = levers.links().iter().find(|(l, _)| *l == 2).unwrap();
        assert!(
            (b[0] - 2.1).abs() < 1e-5 && (b[1] - 1.1).abs() < 1e-5,
            "{b:?}"
        );
        assert!((levers.max_reach() - (2.1f64.powi(2) + 1.1f64.powi(2)).sqrt()).abs() < 1e-5);
        // stretched out, j1 alone moves b's far point at 2.1 m/rad: the bound is tight there
        assert!((levers.displacement(&[0.5, 0.0]) - 1.05).abs() < 1e-5);
        assert!((levers.displacement(&[0.0, -0.5]) - 0.55).abs() < 1e-5);
    }
}
