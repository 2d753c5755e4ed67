//! `texel bake-ao`: maps from OBJ, glTF and scenes, deterministic for a seed, bad input refused.

use crate::util::*;

/// A quad floor (uv over the whole map, facing +z) with a quad wall standing on its middle
/// (uvs outside the map: it occludes, is not baked), as OBJ.
const FLOOR_AND_WALL_OBJ: &str = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
v 0 -1 0\nv 0 1 0\nv 0 1 1\nv 0 -1 1\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 3 3\n\
f 1/1 2/2 3/3\nf 1/1 3/3 4/4\nf 5/5 6/5 7/5\nf 5/5 7/5 8/5\n";

#[test]
fn bakes_obj_gltf_and_scenes() {
    let d = Dir::new("bake-ao");
    d.write("fw.obj", FLOOR_AND_WALL_OBJ);
    // The floor and wall at 32 x 32 with 64 rays, plus `extra` arguments, into `out`.
    let fw = |extra: &[&str], out: &str| {
        let mut args = vec!["bake-ao".to_string(), d.arg("fw.obj")];
        args.extend(["--size", "32", "--rays", "64", "-o"].map(String::from));
        args.push(d.arg(out));
        args.extend(extra.iter().map(|s| s.to_string()));
        ok(&args)
    };
    let out = fw(&[], "fw.png");
    let err = stderr(&out);
    assert!(
        err.contains("32x32") && err.contains("1024 texels sampled"),
        "{err}"
    );
    assert!(err.contains("2 triangles not baked"), "{err}");
    let img = load(d.join("fw.png"));
    assert_eq!((img.width(), img.height()), (32, 32));
    // Grey, opaque; darkest beside the wall (the map's middle column), brightest at the sides.
    let px = |x: u32, y: u32| img.pixels()[(y * 32 + x) as usize];
    assert!(img
        .pixels()
        .iter()
        .all(|p| p[0] == p[1] && p[1] == p[2] && p[3] == 255));
    assert!(
        px(16, 16)[0] < 170 && px(15, 16)[0] < 170,
        "{:?}",
        px(16, 16)
    );
    assert!(px(0, 16)[0] > 200 && px(31, 16)[0] > 200, "{:?}", px(0, 16));
    // The same seed on one thread: the same bytes.
    fw(&["--threads", "1"], "fw1.png");
    assert_eq!(file_bytes(d.join("fw.png")), file_bytes(d.join("fw1.png")));
    // A glTF quad and a built-in scene.
    d.write("quad.bin", quad_buffer());
    d.write("quad.gltf", quad_gltf("quad.bin"));
    ok(&[
        "bake-ao",
        &d.arg("quad.gltf"),
        "--size",
        "8",
        "--rays",
        "4",
        "-o",
        &d.arg("q.png"),
    ]);
    // A lone quad is unoccluded: 255 everywhere.
    assert!(load(d.join("q.png")).pixels().iter().all(|p| p[0] == 255));
    ok(&[
        "bake-ao",
        "builtin:cube",
        "--size",
        "8",
        "--rays",
        "4",
        "--margin",
        "1",
        "-o",
        &d.arg("c.png"),
    ]);
    assert!(temp_files(d.path()).is_empty());
}

#[test]
fn bad_input_is_refused() {
    let d = Dir::new("bake-ao-bad");
    d.write("bad.obj", "v 1 2\nf 1 2 3\n");
    let out = d.arg("x.png");
    fails(&["bake-ao", &d.arg("bad.obj"), "-o", &out], 1, &["bad.obj"]);
    fails(
        &["bake-ao", &d.arg("missing.glb"), "-o", &out],
        1,
        &["missing.glb"],
    );
    fails(&["bake-ao", "builtin:nope", "-o", &out], 1, &["nope"]);
    fails(&["bake-ao", "--size", "0", "-o", &out], 2, &["--size"]);
    fails(&["bake-ao", "--rays", "100000", "-o", &out], 2, &["--rays"]);
    for d in ["nan", "-1", "0", "inf"] {
        let arg = format!("--max-distance={d}");
        fails(&["bake-ao", &arg, "-o", &out], 2, &["--max-distance"]);
    }
    assert!(!d.join("x.png").exists());
    // A map over the memory limit is refused before the bake starts.
    fails(
        &[
            "--max-memory",
            "64MiB",
            "bake-ao",
            "builtin:cube",
            "--size",
            "16384",
            "-o",
            &out,
        ],
        1,
        &["occlusion map"],
    );
    assert!(!d.join("x.png").exists());
    assert!(temp_files(d.path()).is_empty());
}
