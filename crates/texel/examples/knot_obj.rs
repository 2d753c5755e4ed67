//! Write the built-in knot model ([`texel::scene::knot_mesh`]) as an OBJ file at any resolution:
//! the mesh `texel bake-ao` is timed on.
//!
//! `cargo run --release -p texel --example knot_obj -- 1000 50 knot100k.obj` writes
//! 100 002 triangles (1000 segments along the tube, 50 around, and the ground's two).

use std::fmt::Write as _;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [segments, sides, path] = args.as_slice() else {
        return Err("usage: knot_obj SEGMENTS SIDES OUT.obj".into());
    };
    let m = texel::scene::knot_mesh(segments.parse()?, sides.parse()?);
    let mut s = String::new();
    for p in &m.positions {
        writeln!(s, "v {} {} {}", p.x, p.y, p.z)?;
    }
    // OBJ's v runs up the image; texel's (and glTF's) down.
    for uv in &m.uvs {
        writeln!(s, "vt {} {}", uv.x, 1.0 - uv.y)?;
    }
    for n in m.normals.as_deref().unwrap_or_default() {
        writeln!(s, "vn {} {} {}", n.x, n.y, n.z)?;
    }
    for t in &m.triangles {
        let [a, b, c] = t.map(|k| k + 1);
        writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")?;
    }
    std::fs::write(path, s)?;
    eprintln!("{} triangles written to {path}", m.triangles.len());
    Ok(())
}
