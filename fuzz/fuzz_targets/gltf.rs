//! glTF/GLB import (embedded buffers only): any bytes either fail with an error or yield meshes
//! within the limits: triangles, vertices and meshes (index ranges are checked later, by
//! `Scene::validate`).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use texel_scene::{load_gltf_slice, SceneLimits};

fuzz_target!(|data: &[u8]| {
    let limits = SceneLimits {
        max_mesh_file_bytes: 1 << 20,
        max_triangles: 1 << 16,
        max_vertices: 1 << 16,
        max_meshes: 1 << 10,
        ..SceneLimits::default()
    };
    if let Ok(meshes) = load_gltf_slice(data, None, Path::new("fuzz.gltf"), "t", &limits) {
        let tris: usize = meshes.iter().map(|m| m.triangles.len()).sum();
        assert!(tris as u64 <= limits.max_triangles && tris > 0);
        let verts: usize = meshes.iter().map(|m| m.positions.len()).sum();
        assert!(verts as u64 <= limits.max_vertices);
        assert!(meshes.len() as u64 <= limits.max_meshes);
    }
});
