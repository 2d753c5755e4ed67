//! `texel compare`: every filter against the supersampled reference, with a report
//! ([`texel::compare`], which does the job; this face parses, shows progress and prints).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use texel::compare::{CompareJob, Extra, OrbitSpec, TIMED_FRAMES};
use texel::quality::Image8;
use texel::raster::{Frame, RenderSettings};
use texel::timing::median;
use texel::{MemoryBudget, PreparedScene};
use texel_gpu::GpuFilter;
use texel_io::publish_dir;

use crate::cli::CompareArgs;
use crate::filters::{parse_list, Filter};
use crate::input::{check_storage, load_scene, Input};
use crate::progress;

/// Parse `LABEL=PATH`.
pub(crate) fn parse_extra(s: &str) -> Result<(String, PathBuf)> {
    match s.split_once('=') {
        Some((label, path)) if !label.trim().is_empty() && !path.is_empty() => {
            Ok((label.trim().to_string(), PathBuf::from(path)))
        }
        _ => bail!("--extra {s:?} is not LABEL=IMAGE (e.g. --extra llvmpipe=trilinear.png)"),
    }
}

/// The rows `--gpu` adds to a comparison of `filters`, with what draws each: `gpu-NAME` for each
/// filter the GPU path has, then the device's own sampler's rows.
fn gpu_jobs(filters: &[Filter]) -> Vec<(String, Filter, GpuFilter)> {
    let mut jobs: Vec<(String, Filter, GpuFilter)> = filters
        .iter()
        .filter_map(|&f| GpuFilter::of(f).map(|g| (format!("gpu-{}", f.name()), f, g)))
        .collect();
    jobs.extend(
        crate::filters::HARDWARE_ROWS
            .iter()
            .map(|&(label, f, g)| (label.to_string(), f, g)),
    );
    jobs
}

/// Render `filters` (those the GPU path has) with texel's shaders and the device's own sampler:
/// rows `gpu-NAME`, `hw-trilinear`, `hw-aniso16`, each the last of [`TIMED_FRAMES`] timed frames.
fn gpu_rows(
    scene: &PreparedScene,
    filters: &[Filter],
    adapter: Option<&str>,
    budget: &mut MemoryBudget,
) -> Result<Vec<Extra>> {
    let gpu = texel_gpu::Gpu::new(adapter)?;
    texel_io::stderr_line(format_args!("gpu: {}", gpu.info()));
    let mut settings = scene.settings();
    settings.derivatives = texel::raster::Derivatives::Quad;
    let jobs = gpu_jobs(filters);
    let mut rows = Vec::new();
    for (label, filter, gpu_filter) in jobs {
        budget.take(
            "a GPU frame and its read-back",
            texel_gpu::frame_bytes(settings.width, settings.height),
        )?;
        let frame_plan = scene.plan(Some(filter), budget)?;
        let draws = frame_plan.draws();
        // The uploads are held while this row renders; its frame is kept.
        let uploads = texel_gpu::prepare_bytes(&draws);
        budget.take("the GPU's copies of the textures and meshes", uploads)?;
        let prepared = gpu.prepare(&draws, gpu_filter)?;
        let settings = RenderSettings {
            environment: frame_plan.settings().environment,
            ..settings
        };
        let mut times = Vec::new();
        let mut frame: Frame = prepared.render(&settings)?;
        for _ in 0..TIMED_FRAMES {
            let t0 = std::time::Instant::now();
            frame = prepared.render(&settings)?;
            times.push(t0.elapsed().as_secs_f64() * 1e3);
        }
        rows.push(Extra::Frame {
            label,
            frame,
            ms: median(&mut times),
        });
        drop(prepared);
        budget.release(uploads);
    }
    Ok(rows)
}

/// What `compare` can tell before the reference: the scene can be scored
/// ([`texel::compare::check_scene`]) and every `--extra` image (its header read, not decoded) has
/// the comparison's size.
fn check_before_work(
    scene: &PreparedScene,
    extras: &[(String, PathBuf)],
    budget: &mut MemoryBudget,
) -> Result<()> {
    texel::compare::check_scene(scene, budget)?;
    let (w, h) = (scene.width, scene.height);
    for (label, path) in extras {
        let (iw, ih) = Image8::dimensions(path)
            .with_context(|| format!("cannot load --extra image {label}={}", path.display()))?;
        anyhow::ensure!(
            (iw, ih) == (w, h),
            "--extra image {} is {iw}x{ih} but the comparison is {w}x{h} (pass --size to match)",
            path.display(),
        );
    }
    Ok(())
}

/// Run `texel compare`.
pub(crate) fn run(args: &CompareArgs, input: &mut Input) -> Result<()> {
    let filters = parse_list(&args.filters)?;
    let files = args
        .extra
        .iter()
        .map(|e| parse_extra(e))
        .collect::<Result<Vec<_>>>()?;
    // Every extra row's label is checked before any work: the GPU's rows' too.
    let gpu_labels: Vec<String> = if args.gpu {
        gpu_jobs(&filters).into_iter().map(|(l, ..)| l).collect()
    } else {
        Vec::new()
    };
    texel::compare::check_labels(
        gpu_labels
            .iter()
            .chain(files.iter().map(|(label, _)| label))
            .map(String::as_str),
        &filters,
    )?;
    let plan = crate::cli::reference_plan(
        args.spp,
        args.max_spp.unwrap_or(args.spp),
        args.tolerance,
        args.scene.color == texel::ColorHandling::Srgb,
        texel::raster::DEFAULT_SEED,
    )?
    .with_exact(args.exact);
    check_storage(&args.scene, args.gpu)?;
    let scene = load_scene(&args.scene, input)?;
    check_before_work(&scene, &files, &mut input.budget)?;
    let mut extras = if args.gpu {
        gpu_rows(&scene, &filters, args.adapter.as_deref(), &mut input.budget)?
    } else {
        Vec::new()
    };
    extras.extend(files.iter().map(|(label, path)| Extra::File {
        label: label.clone(),
        path: path.clone(),
    }));
    // The scene's name as the report shows it: control and bidirectional characters escaped.
    let label = texel_io::escape(&args.scene.scene);
    let bars = progress::Bars::own(filters.len());
    let job = CompareJob {
        orbit: args.orbit.map(|frames| OrbitSpec {
            frames,
            step_deg: args.orbit_step,
        }),
        extras: &extras,
        progress: Some(&bars),
        ..CompareJob::new(&label, &filters, plan)
    };
    job.charge(&scene, &mut input.budget)?;
    // What the command reads must not lie inside what it replaces.
    let mut inputs: Vec<&Path> = vec![Path::new(&args.scene.scene)];
    inputs.extend(files.iter().map(|(_, p)| p.as_path()));
    let report = publish_dir(&args.out, &inputs, |dir| {
        Ok::<_, anyhow::Error>(texel::compare::compare(
            &scene,
            &job,
            Some(dir),
            &mut input.budget,
        )?)
    });
    bars.finish();
    let report =
        report.with_context(|| format!("cannot write the report to {}", args.out.display()))?;
    texel_io::stdout_text(&report.to_markdown()).context(crate::cmd_render::STDOUT)?;
    texel_io::stderr_line(format_args!(
        "report: {}",
        args.out.join("index.html").display()
    ));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extras_parse() {
        assert_eq!(
            parse_extra("gpu=out/a.png").unwrap(),
            ("gpu".to_string(), PathBuf::from("out/a.png"))
        );
        assert_eq!(
            parse_extra("a=b=c").unwrap(),
            ("a".to_string(), PathBuf::from("b=c"))
        );
        assert!(parse_extra("nolabel").is_err());
        assert!(parse_extra("=x.png").is_err());
        assert!(parse_extra("x=").is_err());
    }
}
