//! `texel bake-ao`: a mesh's ambient occlusion baked into its uv layout ([`texel::ao`]), written
//! as an 8-bit linear grey PNG, or as 32-bit floats in OpenEXR for an `.exr` name.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use anyhow::{Context, Result};
use texel::ao::{bake_ao, protected_levels, AoMesh, AoSettings};
use texel::scene::{load_gltf_with, load_obj_with, Mesh, Scene};

use crate::cli::BakeAoArgs;
use crate::input::Input;
use crate::output::{is_exr, write_image, write_linear};
use crate::progress;
use crate::threads::{thread_count, workers};

/// Run `texel bake-ao`.
pub(crate) fn run(args: &BakeAoArgs, input: &mut Input) -> Result<()> {
    crate::output::check_outputs(&[("-o", &args.output)])?;
    let meshes = load_meshes(&args.mesh, input)?;
    let mesh = AoMesh::from_meshes(&meshes);
    drop(meshes);
    let settings = AoSettings {
        size: args.size,
        rays: args.rays,
        max_distance: args.max_distance,
        margin: args.margin,
        seed: args.seed,
    };
    let started = Instant::now();
    let bar = progress::bar(u64::from(args.size), "baking");
    let never = AtomicBool::new(false);
    let map = texel::raster::on_threads(workers(args.threads), || {
        bake_ao(
            &mesh,
            &settings,
            &mut input.budget,
            &|rows| bar.inc(rows),
            &never,
        )
    })?
    .with_context(|| format!("cannot bake {}", args.mesh))?;
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    if is_exr(&args.output) {
        let pixels: Vec<[f32; 4]> = map.values.iter().map(|&v| [v, v, v, 1.0]).collect();
        write_linear(
            &args.output,
            map.size,
            map.size,
            &pixels,
            texel::ColorHandling::Raw,
        )?;
    } else {
        write_image(&args.output, &map.image()?)?;
    }
    let texels = u64::from(map.size) * u64::from(map.size);
    let margin = match args.margin {
        None => "the whole map (every mip level protected)".to_string(),
        Some(m) => format!(
            "{m} texels (mip levels 0 to {} protected)",
            i64::from(protected_levels(m)) - 1
        ),
    };
    texel_io::stderr_line(format_args!(
        "texel bake-ao: {} triangles, {size}x{size}: {} texels sampled ({:.1} %), {} filled by the margin, {:.1} M rays in {seconds:.1} s on {} threads ({:.2} M rays/s); margin: {margin}",
        mesh.triangles.len(),
        map.sampled,
        100.0 * map.sampled as f64 / texels as f64,
        map.filled,
        map.rays as f64 / 1e6,
        thread_count(args.threads),
        map.rays as f64 / 1e6 / seconds.max(1e-9),
        size = map.size,
    ));
    if map.skipped_triangles > 0 {
        texel_io::stderr_line(format_args!(
            "texel bake-ao: warning: {} triangles not baked (zero area in uv or in space, or outside the map's [0, 1] uv square); they still occlude",
            map.skipped_triangles
        ));
    }
    Ok(())
}

/// The meshes of `arg`: an OBJ or glTF file by its extension, else a scene (a TOML file or
/// `builtin:NAME`).
fn load_meshes(arg: &str, input: &Input) -> Result<Vec<Mesh>> {
    let limits = input.budget.scene_limits();
    let path = Path::new(arg);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let meshes = match ext.as_deref() {
        Some("obj") => load_obj_with(path, "", &limits).map(|m| vec![m]),
        Some("gltf" | "glb") => load_gltf_with(path, "", &limits),
        _ => Scene::load_with(arg, &limits).map(|s| s.meshes),
    };
    meshes.with_context(|| format!("cannot load the mesh {arg}"))
}
