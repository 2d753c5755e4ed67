//! Render a scene file or built-in scene with the texel library, as `texel render` does.
//!
//! ```sh
//! cargo run --release -p texel --example render_scene -- [SCENE] [--filter NAME] [-o out.png]
//! ```
//!
//! `SCENE` is a TOML scene file or `builtin:NAME` (default `builtin:ground`); the filter defaults to
//! trilinear (a glTF mesh's own sampler filters when none is given); the PNG defaults to
//! `render_scene.png`. The steps are the ones `texel::render_scene` takes, spelled out: load the
//! scene, prepare it within a memory budget, plan the frame for the filter, render, encode.

use texel::{Filter, FrameOptions, MemoryBudget, PreparedScene, Scene, SceneOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut scene_arg = "builtin:ground".to_string();
    let mut out = "render_scene.png".to_string();
    let mut filter = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "-o" | "--output" => out = args.next().ok_or("-o needs a path")?,
            "--filter" => {
                filter = Some(
                    args.next()
                        .ok_or("--filter needs a name")?
                        .parse::<Filter>()?,
                )
            }
            _ if a.starts_with('-') => return Err(format!("unknown option {a}").into()),
            _ => scene_arg = a,
        }
    }
    let scene = Scene::load(&scene_arg)?;
    let mut budget = MemoryBudget::half_of_machine();
    let prepared = PreparedScene::new(scene, &SceneOptions::default(), &mut budget)?;
    // The filter's samplers, with any ripmap or summed-area table built within the budget.
    let plan = prepared.plan(filter, &mut budget)?;
    let structure_bytes = plan.structure_bytes();
    let started = std::time::Instant::now();
    // Drawn as `texel render` draws it: the textured colour, analytic derivatives, all cores.
    let (frame, encoding) = plan.render(&FrameOptions::default())?;
    let ms = started.elapsed().as_secs_f64() * 1e3;
    texel::frame_image(&frame, encoding)?.write_png(&out)?;
    println!(
        "{scene_arg}: {}x{} with {} in {ms:.1} ms ({structure_bytes} bytes of texture structures) -> {out}",
        frame.width,
        frame.height,
        filter.map_or("each mesh's default filter", Filter::name),
    );
    Ok(())
}
