//! OBJ and glTF meshes written here render like the inline quad; glTF sampler filters are used.

use crate::util::*;

#[test]
fn base64_known_values() {
    assert_eq!(base64(b""), "");
    assert_eq!(base64(b"f"), "Zg==");
    assert_eq!(base64(b"fo"), "Zm8=");
    assert_eq!(base64(b"foo"), "Zm9v");
    assert_eq!(base64(b"foobar"), "Zm9vYmFy");
}

#[test]
fn obj_and_gltf_meshes_render_like_the_inline_quad() {
    let d = Dir::new("meshes");
    d.write("quad.obj", QUAD_OBJ);
    d.write("quad.bin", quad_buffer());
    d.write("external.gltf", quad_gltf("quad.bin"));
    d.write(
        "embedded.gltf",
        quad_gltf(&format!(
            "data:application/octet-stream;base64,{}",
            base64(&quad_buffer())
        )),
    );
    let mesh = |source: &str| format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\n{source}\n");
    d.write("inline.toml", format!("{HEAD}{QUAD}"));
    d.write("obj.toml", mesh("obj = \"quad.obj\""));
    d.write("external.toml", mesh("gltf = \"external.gltf\""));
    d.write("embedded.toml", mesh("gltf = \"embedded.gltf\""));
    let mut images = Vec::new();
    for name in ["inline", "obj", "external", "embedded"] {
        let out = d.arg(&format!("{name}.png"));
        ok(&[
            "render",
            &d.arg(&format!("{name}.toml")),
            "--filter",
            "trilinear",
            "-o",
            &out,
        ]);
        images.push((name, file_bytes(&out)));
    }
    for (name, bytes) in &images[1..] {
        assert!(
            bytes == &images[0].1,
            "{name} renders differently from the inline quad"
        );
    }
    // The quad is actually drawn: black and white checks in the middle, blue background at the corner.
    let img = load(d.join("inline.png"));
    assert_eq!(img.size(), (64, 48));
    assert_eq!(img.pixel(0, 0), Some([0, 0, 255, 255]));
    let inside: Vec<[u8; 4]> = (16..48)
        .flat_map(|x| (12..36).map(move |y| (x, y)))
        .map(|(x, y)| img.pixel(x, y).unwrap())
        .collect();
    assert!(inside.contains(&[0, 0, 0, 255]) && inside.contains(&[255, 255, 255, 255]));
}

/// Without `--filter`, a glTF mesh is sampled with its own sampler's filters: a glTF asking for
/// NEAREST renders like `--filter nearest`, and differently from the trilinear default.
#[test]
fn gltf_sampler_filters_are_used_without_filter_flag() {
    let d = Dir::new("gltf-sampler");
    d.write("quad.bin", quad_buffer());
    let gltf = quad_gltf("quad.bin")
        .replace(r#""indices": 2}"#, r#""indices": 2, "material": 0}"#)
        .replace(
            r#""buffers":"#,
            r#""samplers": [{"magFilter": 9728, "minFilter": 9728}],
  "images": [{"uri": "never-loaded.png"}],
  "textures": [{"sampler": 0, "source": 0}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
  "buffers":"#,
        );
    d.write("nearest.gltf", gltf);
    d.write(
        "nearest.toml",
        format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\ngltf = \"nearest.gltf\"\n"),
    );
    d.write(
        "plain.toml",
        format!("{HEAD}\n[[meshes]]\ntexture = \"t\"\ngltf = \"quad.gltf\"\n"),
    );
    d.write("quad.gltf", quad_gltf("quad.bin"));
    let render = |scene: &str, filter: Option<&str>, out: &str| {
        let mut args = vec!["render".to_string(), d.arg(scene)];
        if let Some(f) = filter {
            args.extend(["--filter".to_string(), f.to_string()]);
        }
        args.extend(["-o".to_string(), d.arg(out)]);
        ok(&args);
        file_bytes(d.arg(out))
    };
    let own = render("nearest.toml", None, "own.png");
    assert_eq!(
        own,
        render("nearest.toml", Some("nearest"), "forced-nearest.png")
    );
    assert_ne!(
        own,
        render("nearest.toml", Some("trilinear"), "forced-trilinear.png")
    );
    // A glTF without a sampler gets the trilinear default.
    assert_eq!(
        render("plain.toml", None, "plain.png"),
        render("plain.toml", Some("trilinear"), "plain-trilinear.png")
    );
}
