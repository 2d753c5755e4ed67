//! Scene TOML -> validated scene: any text either fails with an error or yields a scene that
//! passes validation and draws something.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use texel_scene::{Scene, SceneLimits};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // Mesh files are looked up beside a scene that does not exist, and kept small.
    let limits = SceneLimits {
        max_mesh_file_bytes: 1 << 16,
        ..SceneLimits::default()
    };
    if let Ok(scene) = Scene::from_toml_str_with(text, Path::new("/nonexistent/fuzz.toml"), &limits)
    {
        scene.validate().expect("a loaded scene is valid");
        assert!(!scene.meshes.is_empty());
        assert!(scene.meshes.iter().all(|m| !m.triangles.is_empty()));
    }
});
