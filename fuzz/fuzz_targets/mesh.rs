//! Mesh bytes (STL, OBJ, COLLADA through mesh-loader; the first byte picks the format) → the
//! vertices of a convex hull or an error, never a panic, a hang or a stack overflow.
#![no_main]
use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&kind, bytes)) = data.split_first() else {
        return;
    };
    let name = ["fuzz.stl", "fuzz.obj", "fuzz.dae"][usize::from(kind % 3)];
    if let Ok(hull) =
        trm_collision::mesh::convex_hull_of_mesh_bytes(bytes, Path::new(name), [1.0, 1.0, 1.0])
    {
        assert!(hull.len() >= 4 && hull.iter().flatten().all(|c| c.is_finite()));
    }
});
