//! Collision proxies fitted to meshes: the smallest sphere, capsule or box (by volume) that
//! encloses every given point — a mesh's vertices, or its convex hull's — for the fast analytic
//! collision path, with the volume against the points' convex hull.
//!
//! Capsules: axis candidates from the points' principal axes and the frame's own axes; for an
//! axis, the radius starts at the smallest circle enclosing the points projected across the
//! axis (exact, incremental) and grows in steps while that shortens the capsule; the cap
//! centres are the tightest that enclose every point. Boxes: the principal frame and the
//! frame's own axes. Spheres: an iterative centre (Bădoiu–Clarkson), then the farthest point.
//! Every fit encloses every point (to 1e-9 m).

use nalgebra::{
    Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector2, Vector3,
};
use parry3d_f64::shape::ConvexPolyhedron;

use crate::{CollisionError, CollisionModel, Shape};

/// A primitive around a set of points: its shape, its pose in the points' frame, its volume.
#[derive(Debug, Clone, PartialEq)]
pub struct Fitted {
    /// Sphere, capsule (along its z) or box.
    pub shape: Shape,
    /// Pose of the shape frame in the points' frame.
    pub pose: Isometry3<f64>,
    /// Volume, m³.
    pub volume: f64,
}

/// The three fits and the convex hull's volume.
#[derive(Debug, Clone, PartialEq)]
pub struct Fits {
    /// The smallest enclosing sphere found.
    pub sphere: Fitted,
    /// The smallest enclosing capsule found.
    pub capsule: Fitted,
    /// The smallest enclosing box found.
    pub cuboid: Fitted,
    /// Volume of the points' convex hull (0 when they span no volume).
    pub hull_volume: f64,
}

impl Fits {
    /// The smallest of the three, preferring the simpler (sphere, then capsule, then box)
    /// within 1 % of it.
    pub fn best(&self) -> &Fitted {
        let all = [&self.sphere, &self.capsule, &self.cuboid];
        let least = all.iter().map(|f| f.volume).fold(f64::INFINITY, f64::min);
        all.into_iter()
            .find(|f| f.volume <= 1.01 * least)
            .unwrap_or(&self.cuboid)
    }
}

/// Fits a sphere, a capsule and a box around `points` (at least one point; finite).
pub fn fit(points: &[Point3<f64>]) -> Option<Fits> {
    if points.is_empty()
        || points
            .iter()
            .any(|p| !p.coords.iter().all(|v| v.is_finite()))
    {
        return None;
    }
    let frames = candidate_frames(points);
    let cuboid = frames
        .iter()
        .map(|r| fit_box(points, r))
        .min_by(|a, b| a.volume.total_cmp(&b.volume))?;
    let capsule = frames
        .iter()
        .flat_map(|r| (0..3).map(move |k| r.matrix().column(k).into_owned()))
        .map(|axis| fit_capsule(points, &axis))
        .min_by(|a, b| a.volume.total_cmp(&b.volume))?;
    let hull_volume = ConvexPolyhedron::from_convex_hull(points).map_or(0.0, |h| {
        use parry3d_f64::shape::Shape as _;
        h.mass_properties(1.0).mass()
    });
    Some(Fits {
        sphere: fit_sphere(points),
        capsule,
        cuboid,
        hull_volume,
    })
}

/// The direction along which the points spread most (the covariance's largest eigenvector).
fn principal_axis(points: &[Point3<f64>]) -> Vector3<f64> {
    let n = points.len() as f64;
    let mean = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n;
    let mut cov = Matrix3::zeros();
    for p in points {
        let d = p.coords - mean;
        cov += d * d.transpose();
    }
    let eigen = cov.symmetric_eigen();
    let k = (0..3)
        .max_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]))
        .unwrap_or(0);
    let axis = eigen.eigenvectors.column(k).into_owned();
    if axis.iter().all(|v| v.is_finite()) {
        axis
    } else {
        Vector3::x()
    }
}

/// The points' principal axes (eigenvectors of their covariance) and the identity.
fn candidate_frames(points: &[Point3<f64>]) -> Vec<Rotation3<f64>> {
    let n = points.len() as f64;
    let mean = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / n;
    let mut cov = Matrix3::zeros();
    for p in points {
        let d = p.coords - mean;
        cov += d * d.transpose();
    }
    let eigen = (cov / n).symmetric_eigen();
    let mut axes = eigen.eigenvectors;
    // a right-handed frame
    if axes.determinant() < 0.0 {
        axes.set_column(2, &-axes.column(2));
    }
    let mut frames = vec![Rotation3::identity()];
    if axes.iter().all(|v| v.is_finite()) {
        frames.push(Rotation3::from_matrix(&axes));
    }
    frames
}

/// The box along the columns of `r` enclosing the points.
fn fit_box(points: &[Point3<f64>], r: &Rotation3<f64>) -> Fitted {
    let local: Vec<Vector3<f64>> = points.iter().map(|p| r.inverse() * p.coords).collect();
    let lo = local
        .iter()
        .fold(Vector3::repeat(f64::INFINITY), |m, v| m.inf(v));
    let hi = local
        .iter()
        .fold(Vector3::repeat(f64::NEG_INFINITY), |m, v| m.sup(v));
    let size = (hi - lo).map(|s| s.max(1e-6) + 2e-9);
    let centre = r * ((lo + hi) / 2.0);
    Fitted {
        shape: Shape::Box {
            size: [size.x, size.y, size.z],
        },
        pose: Isometry3::from_parts(
            Translation3::from(centre),
            UnitQuaternion::from_rotation_matrix(r),
        ),
        volume: size.x * size.y * size.z,
    }
}

/// The smallest circle enclosing 2-D points (incremental, exact up to rounding).
fn enclosing_circle(points: &[Vector2<f64>]) -> (Vector2<f64>, f64) {
    let inside =
        |c: &Vector2<f64>, r: f64, p: &Vector2<f64>| (p - c).norm() <= r * (1.0 + 1e-12) + 1e-15;
    let mut c = points[0];
    let mut r = 0.0;
    for i in 1..points.len() {
        if inside(&c, r, &points[i]) {
            continue;
        }
        c = points[i];
        r = 0.0;
        for j in 0..i {
            if inside(&c, r, &points[j]) {
                continue;
            }
            c = (points[i] + points[j]) / 2.0;
            r = (points[i] - points[j]).norm() / 2.0;
            for k in 0..j {
                if inside(&c, r, &points[k]) {
                    continue;
                }
                if let Some(cc) = circumcentre(&points[i], &points[j], &points[k]) {
                    c = cc;
                    r = (points[i] - cc).norm();
                }
            }
        }
    }
    // rounding: grow to the farthest point
    let r = points.iter().map(|p| (p - c).norm()).fold(r, f64::max);
    (c, r)
}

fn circumcentre(a: &Vector2<f64>, b: &Vector2<f64>, c: &Vector2<f64>) -> Option<Vector2<f64>> {
    let (b, c) = (b - a, c - a);
    let d = 2.0 * (b.x * c.y - b.y * c.x);
    if d.abs() < 1e-18 {
        return None;
    }
    let (b2, c2) = (b.norm_squared(), c.norm_squared());
    Some(a + Vector2::new(c.y * b2 - b.y * c2, b.x * c2 - c.x * b2) / d)
}

/// The smallest capsule along `axis` enclosing the points (radius from the enclosing circle
/// across the axis, grown in 2 % steps while that lowers the volume).
fn fit_capsule(points: &[Point3<f64>], axis: &Vector3<f64>) -> Fitted {
    let u = axis.normalize();
    let e1 = u
        .cross(&if u.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        })
        .normalize();
    let e2 = u.cross(&e1);
    let across: Vec<Vector2<f64>> = points
        .iter()
        .map(|p| Vector2::new(p.coords.dot(&e1), p.coords.dot(&e2)))
        .collect();
    let along: Vec<f64> = points.iter().map(|p| p.coords.dot(&u)).collect();
    let (c, r0) = enclosing_circle(&across);
    let rho: Vec<f64> = across.iter().map(|p| (p - c).norm()).collect();
    let mut best: Option<(f64, f64, f64, f64)> = None; // volume, radius, a, b
    for step in 0..=40 {
        let r = (r0 + 1e-9) * (1.0 + 0.02 * step as f64);
        // every point within the caps: t − h ≤ b and t + h ≥ a with h = √(r² − ρ²)
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        for (t, p) in along.iter().zip(&rho) {
            let h = (r * r - p * p).max(0.0).sqrt();
            a = a.min(t + h);
            b = b.max(t - h);
        }
        let (a, b) = if a <= b {
            (a, b)
        } else {
            ((a + b) / 2.0, (a + b) / 2.0)
        };
        // a degenerate segment (a > b above) must still hold every point: check and skip
        let ok = along.iter().zip(&rho).all(|(t, p)| {
            let z = t.clamp(a, b);
            (t - z).powi(2) + p * p <= r * r * (1.0 + 1e-9)
        });
        if !ok {
            continue;
        }
        let volume = capsule_volume(r, b - a);
        if best.is_none_or(|(v, ..)| volume < v) {
            best = Some((volume, r, a, b));
        }
    }
    let (volume, r, a, b) = best.unwrap_or_else(|| {
        // fall back to the enclosing sphere's radius around the segment's middle
        let far = points.iter().map(|p| p.coords.norm()).fold(0.0, f64::max);
        (f64::INFINITY, far, 0.0, 0.0)
    });
    let centre = e1 * c.x + e2 * c.y + u * ((a + b) / 2.0);
    let rotation = UnitQuaternion::rotation_between(&Vector3::z(), &u).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    });
    Fitted {
        shape: Shape::Capsule {
            radius: r,
            length: b - a,
        },
        pose: Isometry3::from_parts(Translation3::from(centre), rotation),
        volume,
    }
}

fn capsule_volume(radius: f64, length: f64) -> f64 {
    Shape::Capsule { radius, length }
        .volume()
        .unwrap_or(f64::INFINITY)
}

/// An enclosing sphere: Bădoiu–Clarkson iterations for the centre, the farthest point for the
/// radius.
fn fit_sphere(points: &[Point3<f64>]) -> Fitted {
    let farthest = |c: &Vector3<f64>| {
        points
            .iter()
            .map(|p| (p.coords - c).norm())
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, 0.0))
    };
    let mut c = points.iter().fold(Vector3::zeros(), |s, p| s + p.coords) / points.len() as f64;
    for k in 1..=400 {
        let (i, _) = farthest(&c);
        c += (points[i].coords - c) / (k as f64 + 1.0);
    }
    let shape = Shape::Sphere {
        radius: (farthest(&c).1 + 1e-9).max(1e-6),
    };
    Fitted {
        volume: shape.volume().unwrap_or(f64::INFINITY),
        shape,
        pose: Isometry3::from_parts(Translation3::from(c), UnitQuaternion::identity()),
    }
}

/// The largest signed distance of a point outside `fitted` (≤ 0 when it encloses them all).
pub fn worst_outside(fitted: &Fitted, points: &[Point3<f64>]) -> f64 {
    let inv = fitted.pose.inverse();
    points
        .iter()
        .map(|p| {
            let q = inv * p;
            match &fitted.shape {
                Shape::Sphere { radius } => q.coords.norm() - radius,
                Shape::Capsule { radius, length } => {
                    let z = q.z.clamp(-length / 2.0, length / 2.0);
                    (q.coords - Vector3::new(0.0, 0.0, z)).norm() - radius
                }
                Shape::Box { size } => (0..3)
                    .map(|k| q[k].abs() - size[k] / 2.0)
                    .fold(f64::NEG_INFINITY, f64::max),
                _ => f64::NAN,
            }
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Added to every fitted sphere's radius: where a cell's corner is computed (a hull edge cut by a
/// plane), rounding moves it by about 1e-16 m; a micrometre leaves room for other tools too.
const SPHERE_MARGIN: f64 = 1e-6;

/// At most `count` spheres (centre, radius) whose union encloses the convex hull of `points`
/// exactly, not a sample of it: the hull is cut into cells by planes — the cell with the largest
/// sphere cut across its principal axis, halfway along its extent — until there are `count`
/// cells or the largest cannot be cut; each cell's sphere encloses the cell's corners (the
/// hull's vertices on its side and the points where the plane cuts the hull's edges), hence the
/// cell. Radii are rounded up by a micrometre. `None` without points or with a point that is
/// not finite.
pub fn fit_convex_spheres(points: &[Point3<f64>], count: usize) -> Option<Vec<(Point3<f64>, f64)>> {
    if points.is_empty()
        || count == 0
        || points
            .iter()
            .any(|p| !p.coords.iter().all(|v| v.is_finite()))
    {
        return None;
    }
    let sphere = |corners: &[Point3<f64>]| {
        let f = fit_sphere(corners);
        let Shape::Sphere { radius } = f.shape else {
            unreachable!("fit_sphere fits spheres")
        };
        (
            Point3::from(f.pose.translation.vector),
            radius + SPHERE_MARGIN,
        )
    };
    // each cell as its corners and its sphere
    type Cell = (Vec<Point3<f64>>, (Point3<f64>, f64));
    let mut cells: Vec<Cell> = vec![(points.to_vec(), sphere(points))];
    let mut whole = Vec::new(); // cells that cannot be cut (flat or a point)
    while cells.len() + whole.len() < count {
        let Some(k) = (0..cells.len()).max_by(|&a, &b| cells[a].1.1.total_cmp(&cells[b].1.1))
        else {
            break;
        };
        let (corners, s) = cells.swap_remove(k);
        match cut_hull(&corners) {
            Some(halves) => cells.extend(halves.map(|h| {
                let s = sphere(&h);
                (h, s)
            })),
            None => whole.push((corners, s)),
        }
    }
    Some(cells.into_iter().chain(whole).map(|(_, s)| s).collect())
}

/// The corners of the two cells the convex hull of `points` falls into when cut across its
/// principal axis halfway along its extent; `None` when the hull is flat (no volume to cut).
fn cut_hull(points: &[Point3<f64>]) -> Option<[Vec<Point3<f64>>; 2]> {
    let (vertices, triangles) = parry3d_f64::transformation::try_convex_hull(points).ok()?;
    if triangles.is_empty() {
        return None;
    }
    let axis = principal_axis(&vertices);
    let along: Vec<f64> = vertices.iter().map(|v| v.coords.dot(&axis)).collect();
    let (lo, hi) = along
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let middle = 0.5 * (lo + hi);
    if hi <= lo {
        return None; // a single point (the extent is finite: the points are)
    }
    let mut halves = [Vec::new(), Vec::new()];
    for (v, &x) in vertices.iter().zip(&along) {
        if x <= middle {
            halves[0].push(*v);
        }
        if x >= middle {
            halves[1].push(*v);
        }
    }
    for t in &triangles {
        for (i, j) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let (i, j) = (i as usize, j as usize);
            // where an edge crosses the plane (found from both its triangles: repeats are harmless)
            if (along[i] - middle) * (along[j] - middle) < 0.0 {
                let f = (middle - along[i]) / (along[j] - along[i]);
                let p = vertices[i] + (vertices[j] - vertices[i]) * f;
                halves[0].push(p);
                halves[1].push(p);
            }
        }
    }
    Some(halves)
}

/// One link's proxy, as [`fit_model`] fits it.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkFit {
    /// The link's name.
    pub link: String,
    /// The proxy: the smallest of the link's [`Fits`] ([`Fits::best`]).
    pub fitted: Fitted,
    /// Volume of the convex hull of the link's mesh vertices, m³.
    pub hull: f64,
    /// Largest distance of a vertex outside the proxy ([`worst_outside`]; ≤ 0: all enclosed).
    pub worst: f64,
}

/// Fits a proxy to every link of `collision` that has mesh collisions, in link order. An error
/// when no link has any (the meshes were not found, or the URDF has none) or a link's vertices
/// are not finite.
pub fn fit_model(collision: &CollisionModel) -> Result<Vec<LinkFit>, CollisionError> {
    fit_mesh_links(collision, |l, name| {
        let points = collision.link_mesh_points(l);
        if points.is_empty() {
            return Ok(None);
        }
        let all = fit(&points).ok_or_else(|| no_finite_vertices(name))?;
        let fitted = all.best().clone();
        let worst = worst_outside(&fitted, &points);
        Ok(Some(LinkFit {
            link: name.to_string(),
            fitted,
            hull: all.hull_volume,
            worst,
        }))
    })
}

/// `fit_link(index, name)` for every link of `collision`, in link order: the fits of the links
/// it fits (`Some`), an error when it fits none (the meshes were not found, or the URDF has
/// none).
fn fit_mesh_links<T>(
    collision: &CollisionModel,
    mut fit_link: impl FnMut(usize, &str) -> Result<Option<T>, CollisionError>,
) -> Result<Vec<T>, CollisionError> {
    let mut fits = Vec::new();
    for (l, link) in collision.robot().tree().links.iter().enumerate() {
        fits.extend(fit_link(l, &link.name)?);
    }
    if fits.is_empty() {
        return Err(CollisionError::InvalidValue {
            what: collision.robot().name().to_string(),
            problem: "no link has mesh collisions to fit\n  fix: give a URDF whose <collision> elements are meshes (found through the package paths)".into(),
        });
    }
    Ok(fits)
}

/// The error for a link whose mesh vertices are none of them finite.
fn no_finite_vertices(link: &str) -> CollisionError {
    CollisionError::InvalidValue {
        what: format!("link `{link}`'s meshes"),
        problem: "have no finite vertices to fit".into(),
    }
}

/// Added to radii and half sizes written with six decimals, so that the rounded primitive
/// still encloses every vertex (rounding moves the origin by at most 5e-7 m).
pub const WRITE_MARGIN: f64 = 2e-6;

/// `urdf` (the text of the URDF the model was read from; `origin` names it in errors) with each
/// fitted link's `<collision>` elements replaced by one holding its proxy, padded by
/// [`WRITE_MARGIN`]; every other byte is kept.
pub fn urdf_with_proxies(
    urdf: &str,
    origin: &str,
    fits: &[LinkFit],
) -> Result<String, CollisionError> {
    let replacements: Vec<(&str, String)> = fits
        .iter()
        .map(|f| (f.link.as_str(), collision_xml(&f.fitted)))
        .collect();
    replace_collisions(urdf, origin, &replacements)
}

/// `urdf` with each link of `sets` given its spheres as `<collision>` elements (radii padded by
/// [`WRITE_MARGIN`]) in place of its own; every other byte is kept.
pub fn urdf_with_spheres(
    urdf: &str,
    origin: &str,
    sets: &[LinkSpheres],
) -> Result<String, CollisionError> {
    let replacements: Vec<(&str, String)> = sets
        .iter()
        .map(|set| {
            let xml: Vec<String> = set
                .spheres
                .iter()
                .map(|(c, r)| {
                    collision_xml(&Fitted {
                        shape: Shape::Sphere { radius: *r },
                        pose: Isometry3::from_parts(
                            Translation3::from(c.coords),
                            UnitQuaternion::identity(),
                        ),
                        volume: 0.0,
                    })
                })
                .collect();
            (set.link.as_str(), xml.join("\n    "))
        })
        .collect();
    replace_collisions(urdf, origin, &replacements)
}

/// `urdf` with the `<collision>` elements of each named link replaced by the given text (the
/// first element's place; the others removed).
fn replace_collisions(
    urdf: &str,
    origin: &str,
    replacements: &[(&str, String)],
) -> Result<String, CollisionError> {
    let invalid = |problem: String| CollisionError::InvalidValue {
        what: origin.to_string(),
        problem,
    };
    trm_io::check_xml_nesting(urdf.as_bytes(), trm_io::XML_NESTING_LIMIT)
        .map_err(|e| invalid(e.to_string()))?;
    let doc = roxmltree::Document::parse(urdf).map_err(|e| invalid(e.to_string()))?;
    // (start, end, replacement) of every collision element of a replaced link
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    for link in doc
        .root_element()
        .children()
        .filter(|n| n.has_tag_name("link"))
    {
        let Some((_, replacement)) = replacements
            .iter()
            .find(|(name, _)| Some(*name) == link.attribute("name"))
        else {
            continue;
        };
        let collisions = link.children().filter(|n| n.has_tag_name("collision"));
        for (k, c) in collisions.enumerate() {
            let text = if k == 0 {
                replacement.clone()
            } else {
                String::new()
            };
            edits.push((c.range().start, c.range().end, text));
        }
    }
    edits.sort_by_key(|e| e.0);
    let mut out = String::with_capacity(urdf.len());
    let mut at = 0;
    for (start, end, replacement) in edits {
        out.push_str(&urdf[at..start]);
        out.push_str(&replacement);
        at = end;
    }
    out.push_str(&urdf[at..]);
    Ok(out)
}

/// One link's spheres, as [`fit_model_spheres`] fits them.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkSpheres {
    /// The link's name.
    pub link: String,
    /// The spheres: centre (link frame) and radius.
    pub spheres: Vec<(Point3<f64>, f64)>,
    /// Total volume of the link's convex bodies, m³.
    pub hull: f64,
    /// Sum of the spheres' volumes (overlaps counted twice), m³.
    pub volume: f64,
}

/// At most `count` spheres for every link of `collision` with mesh collisions, enclosing every
/// point of the convex hull of the link's convex bodies ([`fit_convex_spheres`]). An error when
/// no link has meshes.
pub fn fit_model_spheres(
    collision: &CollisionModel,
    count: usize,
) -> Result<Vec<LinkSpheres>, CollisionError> {
    if count == 0 {
        return Err(CollisionError::InvalidValue {
            what: "0 spheres per link".into(),
            problem: "give at least 1 sphere".into(),
        });
    }
    fit_mesh_links(collision, |l, name| {
        let mut corners = Vec::new();
        let mut hull = 0.0;
        for body in collision.bodies().iter().filter(|b| b.link == l) {
            let Shape::Convex { points } = &body.shape else {
                continue;
            };
            let local: Vec<Point3<f64>> = points
                .iter()
                .map(|v| body.local * Point3::new(v[0], v[1], v[2]))
                .collect();
            hull += ConvexPolyhedron::from_convex_hull(&local).map_or(0.0, |h| {
                use parry3d_f64::shape::Shape as _;
                h.mass_properties(1.0).mass()
            });
            corners.extend(local);
        }
        if corners.is_empty() {
            return Ok(None);
        }
        let spheres =
            fit_convex_spheres(&corners, count).ok_or_else(|| no_finite_vertices(name))?;
        let volume = spheres
            .iter()
            .map(|(_, r)| 4.0 / 3.0 * std::f64::consts::PI * r.powi(3))
            .sum();
        Ok(Some(LinkSpheres {
            link: name.to_string(),
            spheres,
            hull,
            volume,
        }))
    })
}

/// A `<collision>` element for a fitted primitive.
fn collision_xml(f: &Fitted) -> String {
    let t = f.pose.translation.vector;
    let (r, p, y) = f.pose.rotation.euler_angles();
    let geometry = match &f.shape {
        Shape::Sphere { radius } => format!("<sphere radius=\"{:.6}\"/>", radius + WRITE_MARGIN),
        Shape::Capsule { radius, length } => format!(
            "<capsule radius=\"{:.6}\" length=\"{length:.6}\"/>",
            radius + WRITE_MARGIN
        ),
        Shape::Box { size } => format!(
            "<box size=\"{:.6} {:.6} {:.6}\"/>",
            size[0] + 2.0 * WRITE_MARGIN,
            size[1] + 2.0 * WRITE_MARGIN,
            size[2] + 2.0 * WRITE_MARGIN
        ),
        other => format!("<!-- {} -->", other.kind()),
    };
    format!(
        "<collision>\n      <origin xyz=\"{:.6} {:.6} {:.6}\" rpy=\"{r:.6} {p:.6} {y:.6}\"/>\n      <geometry>\n        {geometry}\n      </geometry>\n    </collision>",
        t.x, t.y, t.z
    )
}
