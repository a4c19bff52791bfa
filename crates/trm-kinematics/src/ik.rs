//! Differential inverse kinematics: damped least squares and strict task priorities — the one
//! resolved-rate solver behind the task-map reaching motions and the whole-body controller.

use nalgebra::{DMatrix, DVector};

/// The damped pseudo-inverse J⁺ = Jᵀ (J Jᵀ + λ² I)⁻¹ of an m × n Jacobian (`damping` = λ);
/// `None` when J holds non-finite values.
///
/// ```
/// use trm_kinematics::ik::damped_pseudo_inverse;
/// use trm_kinematics::nalgebra::DMatrix;
/// let j = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
/// let p = damped_pseudo_inverse(&j, 0.0).unwrap();
/// assert!(((&j * &p)[(0, 0)] - 1.0).abs() < 1e-12);
/// ```
pub fn damped_pseudo_inverse(j: &DMatrix<f64>, damping: f64) -> Option<DMatrix<f64>> {
    let rows = j.nrows();
    let gram = j * j.transpose() + DMatrix::identity(rows, rows) * (damping * damping);
    let inverse = gram.try_inverse()?;
    let p = j.transpose() * inverse;
    p.iter().all(|v| v.is_finite()).then_some(p)
}

/// Joint velocities for tasks in strict priority: each `(J, v)` (Jacobian, desired task
/// velocity) is solved by damped least squares in the null space of the ones before, and
/// `posture` (a joint velocity) acts in the null space of all of them. A task whose damped
/// inverse fails (non-finite Jacobian) contributes nothing.
///
/// With one task this is the classic resolved-rate step q̇ = J⁺ v + (I − J⁺ J) q̇₀.
pub fn prioritised_velocities(
    tasks: &[(DMatrix<f64>, DVector<f64>)],
    posture: &DVector<f64>,
    damping: f64,
) -> DVector<f64> {
    let n = posture.len();
    let mut qdot = DVector::zeros(n);
    let mut null = DMatrix::<f64>::identity(n, n);
    for (j, v) in tasks {
        let jn = j * &null;
        let Some(pinv) = damped_pseudo_inverse(&jn, damping) else {
            continue;
        };
        qdot += &pinv * (v - j * &qdot);
        null -= &pinv * &jn;
    }
    qdot + null * posture
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_higher_priority_task_is_met_exactly_and_the_posture_only_uses_what_is_left() {
        // 3 joints; task 1 fixes q̇0 + q̇1 = 1, task 2 wants q̇2 = 2, posture pulls q̇0 up
        let j1 = DMatrix::from_row_slice(1, 3, &[1.0, 1.0, 0.0]);
        let j2 = DMatrix::from_row_slice(1, 3, &[0.0, 0.0, 1.0]);
        let tasks = [
            (j1.clone(), DVector::from_element(1, 1.0)),
            (j2.clone(), DVector::from_element(1, 2.0)),
        ];
        let posture = DVector::from_row_slice(&[1.0, 0.0, 0.0]);
        let qdot = prioritised_velocities(&tasks, &posture, 1e-9);
        assert!(((&j1 * &qdot)[0] - 1.0).abs() < 1e-6);
        assert!(((&j2 * &qdot)[0] - 2.0).abs() < 1e-6);
        // the posture moved q̇0 up and q̇1 down by the same amount (null space of task 1)
        assert!(qdot[0] > qdot[1]);
    }

    #[test]
    fn a_non_finite_jacobian_gives_none_not_nan() {
        let j = DMatrix::from_row_slice(1, 2, &[f64::NAN, 1.0]);
        assert!(damped_pseudo_inverse(&j, 0.1).is_none());
    }
}
