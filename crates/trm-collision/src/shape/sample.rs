//! Points on a shape's surface, spread evenly by area: what a depth camera would see of it, for
//! point-cloud worlds made from known scenes (benchmarks, tests).

use std::f64::consts::PI;

use nalgebra::{Point3, Vector3};
use rand::{Rng, RngExt};

use super::Shape;

impl Shape {
    /// `count` points drawn uniformly by area on the shape's surface, in its own frame: a
    /// sphere's, a box's six faces, a cylinder's side and caps, a capsule's side and half
    /// spheres, a mesh's triangles, a convex hull's faces; a point cloud's own points, drawn
    /// with replacement. Empty for a shape that fails [`Shape::check`].
    pub fn surface_samples(&self, count: usize, rng: &mut impl Rng) -> Vec<[f64; 3]> {
        if self.check().is_err() {
            return Vec::new();
        }
        let on_sphere = |rng: &mut dyn FnMut() -> f64| {
            let z: f64 = 2.0 * rng() - 1.0;
            let phi = 2.0 * PI * rng();
            let s = (1.0 - z * z).max(0.0).sqrt();
            Vector3::new(s * phi.cos(), s * phi.sin(), z)
        };
        let mut unit = || rng.random::<f64>();
        match self {
            Shape::Sphere { radius } => (0..count)
                .map(|_| (on_sphere(&mut unit) * *radius).into())
                .collect(),
            Shape::Capsule { radius, length } => {
                let (side, ends) = (2.0 * PI * radius * length, 4.0 * PI * radius * radius);
                (0..count)
                    .map(|_| {
                        if unit() * (side + ends) < side {
                            let phi = 2.0 * PI * unit();
                            let z = (unit() - 0.5) * length;
                            [radius * phi.cos(), radius * phi.sin(), z]
                        } else {
                            let d = on_sphere(&mut unit) * *radius;
                            let z = d.z + d.z.signum() * 0.5 * length;
                            [d.x, d.y, z]
                        }
                    })
                    .collect()
            }
            Shape::Cylinder { radius, length } => {
                let (side, cap) = (2.0 * PI * radius * length, PI * radius * radius);
                (0..count)
                    .map(|_| {
                        let phi = 2.0 * PI * unit();
                        let pick = unit() * (side + 2.0 * cap);
                        if pick < side {
                            [
                                radius * phi.cos(),
                                radius * phi.sin(),
                                (unit() - 0.5) * length,
                            ]
                        } else {
                            let r = radius * unit().sqrt();
                            let z = (if pick < side + cap { -0.5 } else { 0.5 }) * length;
                            [r * phi.cos(), r * phi.sin(), z]
                        }
                    })
                    .collect()
            }
            Shape::Box { size } => {
                // faces in pairs along each axis, each pair weighted by its area
                let area = [size[1] * size[2], size[0] * size[2], size[0] * size[1]];
                let total: f64 = area.iter().sum();
                (0..count)
                    .map(|_| {
                        let mut pick = unit() * total;
                        let axis = (0..2)
                            .find(|&a| {
                                pick -= area[a];
                                pick < 0.0
                            })
                            .unwrap_or(2);
                        std::array::from_fn(|k| {
                            if k == axis {
                                (if unit() < 0.5 { -0.5 } else { 0.5 }) * size[k]
                            } else {
                                (unit() - 0.5) * size[k]
                            }
                        })
                    })
                    .collect()
            }
            Shape::Points { points, .. } => (0..count)
                .map(|_| points[((unit() * points.len() as f64) as usize).min(points.len() - 1)])
                .collect(),
            Shape::Mesh {
                vertices,
                triangles,
            } => {
                let corners: Vec<[Point3<f64>; 3]> = triangles
                    .iter()
                    .map(|t| t.map(|v| Point3::from(vertices[v as usize])))
                    .collect();
                on_triangles(&corners, count, &mut unit)
            }
            Shape::Convex { .. } => {
                let Some((_, hull)) = self.to_parry() else {
                    return Vec::new();
                };
                let Some(polyhedron) = hull.as_convex_polyhedron() else {
                    return Vec::new();
                };
                let (vertices, indices) = polyhedron.to_trimesh();
                let corners: Vec<[Point3<f64>; 3]> = indices
                    .iter()
                    .map(|t| t.map(|v| vertices[v as usize]))
                    .collect();
                on_triangles(&corners, count, &mut unit)
            }
        }
    }
}

/// `count` points uniform by area on the triangles.
fn on_triangles(
    corners: &[[Point3<f64>; 3]],
    count: usize,
    unit: &mut impl FnMut() -> f64,
) -> Vec<[f64; 3]> {
    let mut cumulative = Vec::with_capacity(corners.len());
    let mut total = 0.0;
    for [a, b, c] in corners {
        total += 0.5 * (b - a).cross(&(c - a)).norm();
        cumulative.push(total);
    }
    (0..count)
        .map(|_| {
            let pick = unit() * total;
            let t = cumulative
                .partition_point(|&c| c < pick)
                .min(corners.len() - 1);
            let [a, b, c] = corners[t];
            let (mut u, mut v) = (unit(), unit());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            (a + (b - a) * u + (c - a) * v).coords.into()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Every sample lies on the surface: its signed distance to the shape is ~0, and the
    /// samples of a box reach all six faces.
    #[test]
    fn samples_lie_on_the_surface() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let shapes = [
            Shape::Sphere { radius: 0.1 },
            Shape::Box {
                size: [0.3, 0.2, 0.05],
            },
            Shape::Cylinder {
                radius: 0.04,
                length: 0.3,
            },
            Shape::Capsule {
                radius: 0.05,
                length: 0.2,
            },
            Shape::Convex {
                points: vec![
                    [0.0, 0.0, 0.0],
                    [0.2, 0.0, 0.0],
                    [0.0, 0.2, 0.0],
                    [0.0, 0.0, 0.2],
                ],
            },
        ];
        for shape in shapes {
            let samples = shape.surface_samples(2000, &mut rng);
            assert_eq!(samples.len(), 2000);
            let (iso, parry) = shape.to_parry().unwrap();
            for p in &samples {
                let projected = parry.project_point(&iso, &Point3::from(*p), false);
                let gap = (projected.point - Point3::from(*p)).norm();
                assert!(
                    gap < 1e-9,
                    "{}: {p:?} is {gap} off the surface",
                    shape.kind()
                );
            }
            if let Shape::Box { size } = shape {
                for k in 0..3 {
                    for side in [-0.5, 0.5] {
                        assert!(
                            samples
                                .iter()
                                .any(|p| (p[k] - side * size[k]).abs() < 1e-12)
                        );
                    }
                }
            }
        }
    }
}
