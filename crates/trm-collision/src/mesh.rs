//! Mesh files: `package://` and relative URIs resolved as ROS does, meshes loaded with
//! `mesh-loader` (STL, COLLADA, OBJ) and reduced to their convex hull.

use std::path::{Path, PathBuf};

use nalgebra::Point3;
use parry3d_f64::shape::ConvexPolyhedron;

/// Where a mesh URI may live, in the order they are tried.
///
/// * `package://NAME/REST`: for every directory `D` of `package_paths`, `D/NAME/REST`, then
///   `D/REST` when `D` itself is named `NAME` (as `ROS_PACKAGE_PATH` entries work); then the
///   same for the URDF's directory and each directory above it, nearest first (a robot's files
///   kept together as they ship, no package path needed);
/// * `file:///ABS` or an absolute path: that path;
/// * a relative path: relative to the URDF's directory, when known.
pub fn mesh_candidates(
    uri: &str,
    urdf_dir: Option<&Path>,
    package_paths: &[PathBuf],
) -> Vec<PathBuf> {
    if let Some(rest) = uri.strip_prefix("package://") {
        let (package, inner) = rest.split_once('/').unwrap_or((rest, ""));
        let mut out = Vec::new();
        let ancestors = urdf_dir.into_iter().flat_map(Path::ancestors);
        for dir in package_paths.iter().map(PathBuf::as_path).chain(ancestors) {
            if dir.as_os_str().is_empty() {
                continue;
            }
            out.push(dir.join(package).join(inner));
            if dir.file_name().is_some_and(|n| n == package) {
                out.push(dir.join(inner));
            }
        }
        return out;
    }
    let path = Path::new(uri.strip_prefix("file://").unwrap_or(uri));
    if path.is_absolute() {
        vec![path.to_path_buf()]
    } else {
        urdf_dir.map(|d| vec![d.join(path)]).unwrap_or_default()
    }
}

/// The first existing candidate of [`mesh_candidates`], or every path tried.
pub fn resolve_mesh(
    uri: &str,
    urdf_dir: Option<&Path>,
    package_paths: &[PathBuf],
) -> Result<PathBuf, Vec<PathBuf>> {
    let candidates = mesh_candidates(uri, urdf_dir, package_paths);
    candidates
        .iter()
        .find(|p| p.is_file())
        .cloned()
        .ok_or(candidates)
}

/// The farthest a scaled mesh vertex may lie from its mesh's origin, m: a robot link's mesh
/// spans metres, and a vertex a kilometre away is a misread file or a wrong scale.
pub const MAX_VERTEX_DISTANCE: f64 = 1e3;

/// Loads a mesh file (STL, COLLADA or OBJ; at most [`trm_io::MAX_INPUT_BYTES`]),
/// scales it and returns the vertices of its convex hull.
pub fn convex_hull_of_mesh(path: &Path, scale: [f64; 3]) -> Result<Vec<[f64; 3]>, String> {
    let bytes = trm_io::read_input_bytes(path).map_err(|e| e.to_string())?;
    convex_hull_of_mesh_bytes(&bytes, path, scale)
}

/// [`convex_hull_of_mesh`] of a file's bytes; `path` gives the format (by extension, else by
/// content) and names the file in errors. An OBJ file's material library is not read (a
/// hull needs no materials); COLLADA is refused nested deeper than
/// [`trm_io::XML_NESTING_LIMIT`] before it is parsed.
pub fn convex_hull_of_mesh_bytes(
    bytes: &[u8],
    path: &Path,
    scale: [f64; 3],
) -> Result<Vec<[f64; 3]>, String> {
    let (points, _) = triangles_of_mesh_bytes(bytes, path, scale)?;
    let points: Vec<Point3<f64>> = points.into_iter().map(Point3::from).collect();
    let flat = || "the mesh is flat: its convex hull has no volume".to_string();
    if !crate::shape::spans_volume(&points) {
        return Err(flat());
    }
    let hull = ConvexPolyhedron::from_convex_hull(&points).ok_or_else(flat)?;
    let corners: Vec<Point3<f64>> = hull.points().to_vec();
    if corners.len() < 4 || !crate::shape::spans_volume(&corners) {
        return Err(flat());
    }
    Ok(corners.iter().map(|p| [p.x, p.y, p.z]).collect())
}

/// Loads a mesh file (STL, COLLADA or OBJ; at most [`trm_io::MAX_INPUT_BYTES`]) and scales
/// it: its vertices and triangles (every mesh of the file in one), for a world object
/// ([`crate::Shape::Mesh`]).
pub fn triangles_of_mesh(path: &Path, scale: [f64; 3]) -> Result<Triangles, String> {
    let bytes = trm_io::read_input_bytes(path).map_err(|e| e.to_string())?;
    triangles_of_mesh_bytes(&bytes, path, scale)
}

/// A mesh's vertices and its triangles as indices into them.
pub type Triangles = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// [`triangles_of_mesh`] of a file's bytes (see [`convex_hull_of_mesh_bytes`]); vertices must
/// be finite and within [`MAX_VERTEX_DISTANCE`] of the mesh's origin.
pub fn triangles_of_mesh_bytes(
    bytes: &[u8],
    path: &Path,
    scale: [f64; 3],
) -> Result<Triangles, String> {
    let no_materials = |p: &Path| -> std::io::Result<Vec<u8>> {
        Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            format!("{}: materials are not read", p.display()),
        ))
    };
    let scene = load_scene(bytes, path, no_materials)?;
    let (mut points, mut triangles) = (Vec::new(), Vec::new());
    for mesh in &scene.meshes {
        let base = points.len() as u32;
        points.extend(mesh.vertices.iter().map(|v| scaled(v, scale)));
        triangles.extend(mesh.faces.iter().map(|f| f.map(|i| base + i)));
    }
    check_vertices(&points)?;
    Ok((points, triangles))
}

/// One part of a mesh file drawn in one material: its vertices (coincident ones merged), its
/// triangles and the material's diffuse colour (RGBA in 0..=1), when the file gives one.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshPart {
    /// Vertices, m, scaled.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
    /// The material's diffuse colour.
    pub color: Option<[f32; 4]>,
}

/// Loads a mesh file for drawing (a URDF `<visual>`): one [`MeshPart`] per mesh of the file,
/// with its material's colour (COLLADA effects, an OBJ's material library beside it). The
/// checks of [`triangles_of_mesh`] apply.
pub fn parts_of_mesh(path: &Path, scale: [f64; 3]) -> Result<Vec<MeshPart>, String> {
    let bytes = trm_io::read_input_bytes(path).map_err(|e| e.to_string())?;
    parts_of_mesh_bytes(&bytes, path, scale)
}

/// [`parts_of_mesh`] of a file's bytes; `path` gives the format (by extension, else by
/// content), names the file in errors and locates an OBJ's material library.
pub fn parts_of_mesh_bytes(
    bytes: &[u8],
    path: &Path,
    scale: [f64; 3],
) -> Result<Vec<MeshPart>, String> {
    let library = |p: &Path| -> std::io::Result<Vec<u8>> {
        trm_io::read_input_bytes(p).map_err(|e| std::io::Error::other(e.to_string()))
    };
    let scene = load_scene(bytes, path, library)?;
    let mut parts = Vec::new();
    for (k, mesh) in scene.meshes.iter().enumerate() {
        if mesh.faces.is_empty() {
            continue;
        }
        // mesh-loader gives every corner its own vertex: merge those at one place
        let mut index = std::collections::HashMap::new();
        let mut vertices = Vec::new();
        let mut corner = |v: &[f32; 3]| -> u32 {
            *index.entry(v.map(f32::to_bits)).or_insert_with(|| {
                vertices.push(scaled(v, scale));
                vertices.len() as u32 - 1
            })
        };
        let triangles: Vec<[u32; 3]> = mesh
            .faces
            .iter()
            .filter(|f| f.iter().all(|&i| (i as usize) < mesh.vertices.len()))
            .map(|f| f.map(|i| corner(&mesh.vertices[i as usize])))
            .collect();
        let color = scene.materials.get(k).and_then(|m| m.color.diffuse);
        parts.push(MeshPart {
            vertices,
            triangles,
            color,
        });
    }
    let all: Vec<[f64; 3]> = parts.iter().flat_map(|p| p.vertices.clone()).collect();
    check_vertices(&all)?;
    Ok(parts)
}

/// The file read by mesh-loader (COLLADA's nesting checked first); `library` reads an OBJ's
/// material library.
fn load_scene(
    bytes: &[u8],
    path: &Path,
    library: impl FnMut(&Path) -> std::io::Result<Vec<u8>> + std::panic::UnwindSafe,
) -> Result<mesh_loader::Scene, String> {
    let collada = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("dae"))
        || bytes.trim_ascii_start().starts_with(b"<");
    if collada {
        trm_io::check_xml_nesting(bytes, trm_io::XML_NESTING_LIMIT)
            .map_err(|e| format!("{e}: flatten the COLLADA scene"))?;
    }
    // mesh-loader panics on some malformed files (found by fuzzing: a COLLADA accessor
    // longer than its array): an error, not a crash
    trm_kinematics::quietly(|| {
        mesh_loader::Loader::default().load_from_slice_with_reader(bytes, path, library)
    })
    .map_err(|_| "the mesh reader failed on this file (malformed mesh)".to_string())?
    .map_err(|e| e.to_string())
}

fn scaled(v: &[f32; 3], scale: [f64; 3]) -> [f64; 3] {
    [
        f64::from(v[0]) * scale[0],
        f64::from(v[1]) * scale[1],
        f64::from(v[2]) * scale[2],
    ]
}

/// Some vertices, all finite and within [`MAX_VERTEX_DISTANCE`] of the origin.
fn check_vertices(points: &[[f64; 3]]) -> Result<(), String> {
    if points.is_empty() {
        return Err("the file holds no vertices".to_string());
    }
    if points.iter().flatten().any(|c| !c.is_finite()) {
        return Err("the file holds non-finite vertices".to_string());
    }
    if let Some(far) = points
        .iter()
        .find(|p| p.iter().any(|c| c.abs() > MAX_VERTEX_DISTANCE))
    {
        return Err(format!(
            "a vertex lies at ({:e}, {:e}, {:e}), more than {MAX_VERTEX_DISTANCE} m from the mesh's origin: check the file's format and the scale",
            far[0], far[1], far[2]
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn misread_or_degenerate_meshes_are_errors() {
        // found by fuzzing: ASCII STL with a damaged `solid` line is read as binary, giving
        // vertices 1e34 m away whose hull is numerically flat
        let mut text = String::from("solid$t\n");
        for f in [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]] {
            let v = [[0, 0, 0], [0, 1, 0], [1, 0, 0], [0, 0, 1]];
            text.push_str("facet normal 0 0 0\n outer loop\n");
            for i in f {
                text.push_str(&format!(" vertex {} {} {}\n", v[i][0], v[i][1], v[i][2]));
            }
            text.push_str(" endloop\nendfacet\n");
        }
        text.push_str("endsolid t\n");
        let e = convex_hull_of_mesh_bytes(text.as_bytes(), Path::new("t.stl"), [1.0; 3]);
        assert!(e.is_err(), "{e:?}");
        let good = text.replacen("solid$t", "solid t", 1);
        let hull =
            convex_hull_of_mesh_bytes(good.as_bytes(), Path::new("t.stl"), [1.0; 3]).unwrap();
        assert_eq!(hull.len(), 4);
        let far = convex_hull_of_mesh_bytes(good.as_bytes(), Path::new("t.stl"), [1e4; 3]);
        assert!(far.unwrap_err().contains("more than 1000 m"));
        // found by fuzzing: an accessor of 5 points over an array of 4 made mesh-loader panic
        let dae = format!(
            "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n<library_geometries><geometry id=\"g\"><mesh>\n<source id=\"p\"><float_array id=\"pa\" count=\"12\">0 0 0 1 0 0 0 1 0 0 0 1</float_array>\n<technique_common><accessor source=\"#pa\" count=\"{}\" stride=\"3\"><param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>\n<triangles count=\"4\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles>\n</mesh></geometry></library_geometries>\n<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\"><instance_geometry url=\"#g\"/></node></visual_scene></library_visual_scenes>\n<scene><instance_visual_scene url=\"#s\"/></scene>\n</COLLADA>\n",
            "{}"
        );
        let ok = dae.replacen("{}", "4", 1);
        assert_eq!(
            convex_hull_of_mesh_bytes(ok.as_bytes(), Path::new("t.dae"), [1.0; 3])
                .unwrap()
                .len(),
            4
        );
        let bad = dae.replacen("{}", "5", 1);
        assert!(convex_hull_of_mesh_bytes(bad.as_bytes(), Path::new("t.dae"), [1.0; 3]).is_err());
    }

    #[test]
    fn package_uris_follow_ros_rules() {
        let paths = [PathBuf::from("/opt/share"), PathBuf::from("/ws/iCub")];
        let c = mesh_candidates("package://iCub/meshes/a.stl", None, &paths);
        assert_eq!(
            c,
            [
                PathBuf::from("/opt/share/iCub/meshes/a.stl"),
                PathBuf::from("/ws/iCub/iCub/meshes/a.stl"),
                PathBuf::from("/ws/iCub/meshes/a.stl"),
            ]
        );
        assert_eq!(
            mesh_candidates("meshes/b.dae", Some(Path::new("/robots/x")), &paths),
            [PathBuf::from("/robots/x/meshes/b.dae")]
        );
        assert_eq!(
            mesh_candidates("file:///abs/c.obj", None, &[]),
            [PathBuf::from("/abs/c.obj")]
        );
        assert!(mesh_candidates("rel.stl", None, &[]).is_empty());
        // then beside the URDF and above it
        assert_eq!(
            mesh_candidates(
                "package://p/m.stl",
                Some(Path::new("/r/p/urdf")),
                &paths[..1]
            ),
            [
                PathBuf::from("/opt/share/p/m.stl"),
                PathBuf::from("/r/p/urdf/p/m.stl"),
                PathBuf::from("/r/p/p/m.stl"),
                PathBuf::from("/r/p/m.stl"),
                PathBuf::from("/r/p/m.stl"),
                PathBuf::from("/p/m.stl"),
            ]
        );
    }
}
