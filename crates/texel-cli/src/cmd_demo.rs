//! `texel demo`: the comparison on every built-in scene, with an index page linking the reports.
//!
//! Defaults: each scene at half its own size (640 x 360 for the ground planes) and the lit scenes
//! glossy, bricks and terrain at a quarter of theirs, against a 256-sample reference (8 passes of
//! 4 x 8); `--full` doubles both sides (the README gives both times). `--size` and `--spp` change
//! them.

use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use anyhow::{Context, Result};
use indicatif::ProgressBar;
use texel::quality::html_escape as escape;
use texel::quality::Report;
use texel_io::{publish_dir, write_atomic};

use crate::cli::DemoArgs;
use crate::cli::DEFAULT_TOLERANCE_STEPS;
use crate::filters::Filter;
use crate::input::{load_scene_with, Input};
use crate::progress::{self, Bars};
use texel::compare::CompareJob;
use texel::raster::{UvEvaluation, View};
use texel::FrameOptions;

/// Run `texel demo`: every scene's report is written into one staging directory, published as a
/// whole at `--out` when all are done. One bar counts every reference and filter image (and the
/// ambient-occlusion page) with an estimate of the time left.
pub(crate) fn run(args: &DemoArgs, input: &mut Input) -> Result<()> {
    let started = std::time::Instant::now();
    let shaded = texel::scene::shaded_builtin_names();
    let scenes: Vec<&str> = texel::scene::builtin_names()
        .iter()
        .chain(shaded)
        .copied()
        .collect();
    let steps =
        scenes.len() * (Filter::ALL.len() + 1) + GLOBES.len() * (MAPPING_FILTERS.len() + 1) + 1;
    let pb = progress::bar(steps as u64, "demo");
    let note = |pb: &ProgressBar, line: String| pb.suspend(|| texel_io::stderr_line(line));
    let reports = publish_dir(&args.out, &[], |dir| -> Result<Vec<(String, Report)>> {
        let mut reports: Vec<(String, Report)> = Vec::new();
        for name in &scenes {
            let label = format!("builtin:{name}");
            note(&pb, format!("texel demo: {label} ..."));
            // Scenes are rendered one after another: each gets the whole memory account.
            let mut scene_input = Input {
                budget: input.budget.clone(),
                sanitize: input.sanitize,
            };
            let size = scene_size(args, name)?;
            let scene = load_scene_with(
                &label,
                texel::ColorHandling::Srgb,
                size,
                Default::default(),
                &mut scene_input,
            )?;
            let report = report_in(
                &dir.join(name),
                &scene,
                &label,
                &Filter::ALL,
                args.spp,
                &pb,
                &mut scene_input,
            )?;
            reports.push((name.to_string(), report));
        }
        note(&pb, "texel demo: spherical mappings per vertex ...".into());
        let mappings = mapping_rows(dir, args, input, &reports, &pb)?;
        note(&pb, "texel demo: baked ambient occlusion ...".into());
        pb.set_message("ambient occlusion");
        let sub = dir.join("ao");
        std::fs::create_dir(&sub).with_context(|| format!("cannot create {}", sub.display()))?;
        let size = match scene_size(args, "knot")? {
            Some(s) => s,
            None => own_size("knot", 1)?,
        };
        let mut ao_input = Input {
            budget: input.budget.clone(),
            sanitize: input.sanitize,
        };
        let ao = demo_page(&sub, (size.width, size.height), &mut ao_input)
            .context("cannot bake the ambient occlusion page")?;
        pb.inc(1);
        let html = index_html(&reports, &mappings, &ao, started.elapsed().as_secs_f64());
        write_atomic(&dir.join("index.html"), html.as_bytes())?;
        Ok(reports)
    })
    .with_context(|| format!("cannot write the demo to {}", args.out.display()))?;
    pb.finish_and_clear();
    let index = args.out.join("index.html");
    texel_io::stdout_line(format_args!(
        "texel demo: {} scenes in {:.0} s",
        reports.len(),
        started.elapsed().as_secs_f64()
    ))
    .context(crate::cmd_render::STDOUT)?;
    texel_io::stdout_line(format_args!("open {}", index.display()))
        .context(crate::cmd_render::STDOUT)?;
    Ok(())
}

/// The size `name` is rendered at: `--size`, or a fraction of the scene's own. Lit scenes shade
/// every sub-sample of the reference (and bricks draws a finely tessellated relief), so they run
/// at half the unlit scenes' fraction. `None` is the scene's own size.
fn scene_size(args: &DemoArgs, name: &str) -> Result<Option<crate::cli::Size>> {
    if let Some(s) = args.size {
        return Ok(Some(s));
    }
    let lit = texel::scene::shaded_builtin_names().contains(&name);
    let divisor = match (args.full, lit) {
        (true, false) => return Ok(None),
        (true, true) | (false, false) => 2,
        (false, true) => 4,
    };
    own_size(name, divisor).map(Some)
}

/// Compare `filters` on `scene` against a `spp`-sample reference into the new directory `sub`,
/// charging the comparison's images to `input`'s account.
fn report_in(
    sub: &std::path::Path,
    scene: &texel::PreparedScene,
    label: &str,
    filters: &[Filter],
    spp: u32,
    pb: &ProgressBar,
    input: &mut Input,
) -> Result<Report> {
    let plan = crate::cli::reference_plan(
        spp,
        spp,
        DEFAULT_TOLERANCE_STEPS,
        true,
        texel::raster::DEFAULT_SEED,
    )?
    // Unlit textured pixels computed, not sampled; lit ones sampled.
    .with_exact(true);
    let bars = Bars::shared(pb.clone(), label);
    let job = CompareJob {
        progress: Some(&bars),
        ..CompareJob::new(label, filters, plan)
    };
    job.charge(scene, &mut input.budget)?;
    std::fs::create_dir(sub).with_context(|| format!("cannot create {}", sub.display()))?;
    Ok(texel::compare::compare(
        scene,
        &job,
        Some(sub),
        &mut input.budget,
    )?)
}

/// The globes the demo compares evaluated per pixel (their reports from the scene loop) and
/// per vertex.
const GLOBES: [&str; 2] = ["globe", "globe-equirect"];

/// The filters of the per-vertex reports.
const MAPPING_FILTERS: [Filter; 3] = [Filter::Trilinear, Filter::Aniso16, Filter::Ewa];

/// One row of the demo's spherical-mapping table: a globe, where its uv is evaluated, its report
/// directory and report, and its level-of-detail view.
struct MappingRow {
    scene: &'static str,
    evaluation: UvEvaluation,
    dir: String,
    report: Report,
    lod_image: String,
}

/// The spherical-mapping page's rows: each globe's per-pixel report (already in `reports`) and a
/// per-vertex one compared here (into `GLOBE-per-vertex/`) on the same prepared scene, with a
/// `--view lod` image of each (trilinear) in `mapping/`.
fn mapping_rows(
    dir: &std::path::Path,
    args: &DemoArgs,
    input: &Input,
    reports: &[(String, Report)],
    pb: &ProgressBar,
) -> Result<Vec<MappingRow>> {
    let views = dir.join("mapping");
    std::fs::create_dir(&views).with_context(|| format!("cannot create {}", views.display()))?;
    let mut rows = Vec::new();
    for scene_name in GLOBES {
        let Some((_, per_pixel)) = reports.iter().find(|(n, _)| n == scene_name) else {
            continue;
        };
        let label = format!("builtin:{scene_name}");
        let mut scene_input = Input {
            budget: input.budget.clone(),
            sanitize: input.sanitize,
        };
        let mut scene = load_scene_with(
            &label,
            texel::ColorHandling::Srgb,
            scene_size(args, scene_name)?,
            Default::default(),
            &mut scene_input,
        )?;
        for evaluation in [UvEvaluation::PerPixel, UvEvaluation::PerVertex] {
            scene.set_surface_uv(evaluation);
            let (sub, report) = match evaluation {
                UvEvaluation::PerPixel => (scene_name.to_string(), per_pixel.clone()),
                UvEvaluation::PerVertex => {
                    let sub = format!("{scene_name}-per-vertex");
                    let report = report_in(
                        &dir.join(&sub),
                        &scene,
                        &format!("{label} --surface-uv vertex"),
                        &MAPPING_FILTERS,
                        args.spp,
                        pb,
                        &mut scene_input,
                    )?;
                    (sub, report)
                }
            };
            let frame_plan = scene.plan(Some(Filter::Trilinear), &mut scene_input.budget)?;
            let (frame, encoding) = frame_plan.render(&FrameOptions {
                view: View::Lod,
                ..Default::default()
            })?;
            let lod_image = format!("{scene_name}-lod-{}.png", evaluation.name());
            texel::frame_image(&frame, encoding)?.write_png(views.join(&lod_image))?;
            rows.push(MappingRow {
                scene: scene_name,
                evaluation,
                dir: sub,
                report,
                lod_image: format!("mapping/{lod_image}"),
            });
        }
    }
    Ok(rows)
}

/// The index page's spherical-mapping section.
fn mapping_html(rows: &[MappingRow]) -> String {
    let mut s = String::from(
        "<h2>Spherical mappings</h2>\n<p>The built-in sphere wearing a globe's map (parallels and meridians every 15 \
         degrees, Tissot's discs of 6 degrees, the seam as the red meridian facing the camera) in two projections: \
         Mercator (cut at 85.05 degrees; the polar cap takes the map's edge row) and equirect. <em>Per pixel</em> \
         evaluates the projection at every pixel's surface point with its exact derivatives; <em>per vertex</em> \
         interpolates the uv given at the vertices (5.6-degree rings). Every row is scored against the same \
         reference, which evaluates the projection at every sample; the level-of-detail views (trilinear) show no \
         seam line.</p>\n<table>\n<tr><th>scene</th><th>uv</th><th>trilinear</th><th>aniso16</th><th>ewa</th></tr>\n",
    );
    let psnr = |r: &Report, name: &str| {
        r.rows
            .iter()
            .find(|row| row.name == name)
            .map_or("-".to_string(), |row| format!("{:.2}", row.psnr_all))
    };
    for r in rows {
        let _ = writeln!(
            s,
            "<tr><td><a href=\"{d}/index.html\">{scene}</a></td><td>per {e}</td><td>{t}</td><td>{a}</td><td>{w}</td></tr>",
            d = escape(&r.dir),
            scene = escape(r.scene),
            e = r.evaluation.name(),
            t = psnr(&r.report, "trilinear"),
            a = psnr(&r.report, "aniso16"),
            w = psnr(&r.report, "ewa"),
        );
    }
    s += "</table>\n<div class=\"cards\">\n";
    for r in rows {
        let image = r
            .report
            .rows
            .iter()
            .find(|row| row.name == "aniso16")
            .map(|row| format!("{}/{}", r.dir, row.image));
        let caption = format!("{}, per {}", r.scene, r.evaluation.name());
        if let Some(image) = image {
            let _ = writeln!(
                s,
                "<div class=\"card\"><a href=\"{i}\"><img src=\"{i}\" alt=\"{c}\"></a><br>{c}, aniso16</div>",
                i = escape(&image),
                c = escape(&caption)
            );
        }
        let _ = writeln!(
            s,
            "<div class=\"card\"><a href=\"{i}\"><img src=\"{i}\" alt=\"{c}\"></a><br>{c}, level of detail</div>",
            i = escape(&r.lod_image),
            c = escape(&caption)
        );
    }
    s += "</div>\n";
    s
}

/// The output size of built-in scene `name`, each side divided by `divisor`.
fn own_size(name: &str, divisor: u32) -> Result<crate::cli::Size> {
    let o = texel::scene::builtin(name)?.output;
    Ok(crate::cli::Size {
        width: (o.width / divisor).max(1),
        height: (o.height / divisor).max(1),
    })
}

/// The index page: one row per scene with the best filter and a few reference points, and links.
fn index_html(
    reports: &[(String, Report)],
    mappings: &[MappingRow],
    ao: &DemoAo,
    seconds: f64,
) -> String {
    let mut s = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>texel demo</title>\n<style>\n\
         body { font-family: sans-serif; margin: 1.5em; color: #222; }\n\
         table { border-collapse: collapse; } td, th { padding: 0.3em 0.8em; border-bottom: 1px solid #ddd; text-align: right; }\n\
         td:first-child, th:first-child { text-align: left; }\n\
         .cards { display: flex; flex-wrap: wrap; gap: 1em; } .card { width: 330px; }\n\
         .card img { width: 320px; image-rendering: pixelated; }\n</style>\n</head>\n<body>\n\
         <h1>texel demo</h1>\n<p>Every texture filter on the built-in scenes, scored against a supersampled reference \
         (PSNR in dB over the covered pixels, and over the band just below the horizon). Click a scene for its full report: \
         images, error heat maps, horizon crops and the quality/time chart.</p>\n",
    );
    let _ = writeln!(
        s,
        "<table>\n<tr><th>scene</th><th>best filter</th><th>its PSNR</th><th>trilinear</th><th>aniso16</th><th>ewa</th><th>nearest</th></tr>"
    );
    let psnr = |r: &Report, name: &str| {
        r.rows
            .iter()
            .find(|row| row.name == name)
            .map_or("-".to_string(), |row| format!("{:.2}", row.psnr_all))
    };
    for (dir, r) in reports {
        let best = r
            .rows
            .iter()
            .max_by(|a, b| a.psnr_all.total_cmp(&b.psnr_all));
        let _ = writeln!(
            s,
            "<tr><td><a href=\"{d}/index.html\">{scene}</a></td><td>{best}</td><td>{bp}</td><td>{t}</td><td>{a}</td><td>{e}</td><td>{n}</td></tr>",
            d = escape(dir),
            scene = escape(&r.scene),
            best = best.map_or("-".to_string(), |b| escape(&b.name)),
            bp = best.map_or("-".to_string(), |b| format!("{:.2}", b.psnr_all)),
            t = psnr(r, "trilinear"),
            a = psnr(r, "aniso16"),
            e = psnr(r, "ewa"),
            n = psnr(r, "nearest"),
        );
    }
    s += "</table>\n<div class=\"cards\">\n";
    for (dir, r) in reports {
        let _ = writeln!(
            s,
            "<div class=\"card\"><a href=\"{d}/index.html\"><img src=\"{d}/{img}\" alt=\"{scene}\"></a><br>{scene} ({w}x{h}, reference {spp} spp)</div>",
            d = escape(dir),
            img = escape(&r.reference_image),
            scene = escape(&r.scene),
            w = r.width,
            h = r.height,
            spp = r.spp
        );
    }
    s += "</div>\n";
    s += &mapping_html(mappings);
    s += "<h2>Baked ambient occlusion</h2>\n<p>The lecture's three pictures: a model under ambient \
          light and a sun, the same model with its ambient occlusion (the map dims the ambient light only), \
          and the occlusion map baked from it by <code>texel bake-ao</code> (its uv layout: the tube's two \
          halves above, the ground below).</p>\n<div class=\"cards\">\n";
    for (img, caption) in ao.images.iter().zip([
        "without occlusion",
        "with baked occlusion",
        "the occlusion map",
    ]) {
        let _ = writeln!(
            s,
            "<div class=\"card\"><a href=\"ao/{img}\"><img src=\"ao/{img}\" alt=\"{caption}\"></a><br>{caption}</div>"
        );
    }
    let _ = writeln!(
        s,
        "</div>\n<p>{}.</p>\n<p>Generated by <code>texel demo</code> in {seconds:.0} s.</p>\n</body>\n</html>",
        escape(&ao.summary)
    );
    s
}

/// Side of the demo's map; its rays per texel.
const DEMO_MAP: u32 = 512;
const DEMO_RAYS: u32 = 128;

/// What the demo's ambient occlusion page shows: the lecture's three pictures.
struct DemoAo {
    /// The knot without its occlusion map, with it, and the map (file names in the page's directory).
    pub images: [&'static str; 3],
    /// One line on the bake.
    pub summary: String,
}

/// The demo's ambient occlusion page in `dir`: `builtin:knot` baked (a `DEMO_MAP` map, or the
/// frame's width rounded up to a power of two when `size` is smaller, `DEMO_RAYS` rays), then
/// rendered (trilinear) without and with the map as its material's `occlusion`, and the map.
fn demo_page(dir: &Path, size: (u32, u32), input: &mut Input) -> Result<DemoAo> {
    use texel::ao::{bake_ao, AoMesh, AoSettings};
    use texel::scene::{EncodedImage, Scene, TextureSource, TextureSpec};

    let mut scene = Scene::load("builtin:knot")?;
    let side = DEMO_MAP.min(size.0.next_power_of_two().max(32));
    let settings = AoSettings {
        size: side,
        rays: DEMO_RAYS,
        ..AoSettings::default()
    };
    let started = Instant::now();
    let map = bake_ao(
        &AoMesh::from_meshes(&scene.meshes),
        &settings,
        &mut input.budget,
        &|_| {},
        &AtomicBool::new(false),
    )?;
    let seconds = started.elapsed().as_secs_f64();
    let ao = map.image()?;
    ao.write_png(dir.join("ao-map.png"))?;
    let options = texel::RenderOptions {
        filter: Some(texel::Filter::Trilinear),
        size: Some(size),
        max_memory: Some(input.budget.remaining()),
        ..Default::default()
    };
    texel::render_image(&scene, &options)?.write_png(dir.join("plain.png"))?;
    scene.textures.insert(
        "ao".into(),
        TextureSpec::new(
            TextureSource::Encoded(EncodedImage {
                bytes: ao.to_png()?.into(),
                origin: "the baked ambient occlusion".into(),
            }),
            texel::texture::ColorSpace::Linear,
        ),
    );
    for m in scene.materials.values_mut() {
        m.occlusion = Some("ao".into());
    }
    texel::render_image(&scene, &options)?.write_png(dir.join("with-ao.png"))?;
    Ok(DemoAo {
        images: ["plain.png", "with-ao.png", "ao-map.png"],
        summary: format!(
            "builtin:knot, {} triangles, baked at {side}x{side} with {DEMO_RAYS} rays per texel ({:.1} M rays) in {seconds:.1} s",
            scene.meshes.iter().map(|m| m.triangles.len()).sum::<usize>(),
            map.rays as f64 / 1e6
        ),
    })
}
