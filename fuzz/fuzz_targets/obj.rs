//! OBJ import: any bytes either fail with an error or yield one mesh whose indices are in range
//! and whose attributes match its positions.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use texel_scene::{load_obj_bytes, SceneLimits};

fuzz_target!(|data: &[u8]| {
    let limits = SceneLimits {
        max_triangles: 1 << 16,
        max_vertices: 1 << 16,
        ..SceneLimits::default()
    };
    if let Ok(mesh) = load_obj_bytes(data, Path::new("fuzz.obj"), "t", &limits) {
        let n = mesh.positions.len();
        assert_eq!(mesh.uvs.len(), n);
        assert!(!mesh.triangles.is_empty());
        assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
        if let Some(v) = &mesh.normals {
            assert_eq!(v.len(), n);
        }
    }
});
