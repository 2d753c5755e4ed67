//! `texel render`: one filter (or a debug view), one PNG.

use anyhow::{bail, Context, Result};
use texel::raster::{Derivatives, UvEvaluation};
use texel::FrameOptions;
use texel_gpu::{Gpu, GpuFilter};

use crate::cli::RenderArgs;
use crate::filters::Filter;
use crate::input::{check_storage, load_scene, Input};
use crate::output::{is_exr, write_frame};
use crate::threads::workers;

/// Run `texel render`.
pub(crate) fn run(args: &RenderArgs, input: &mut Input) -> Result<()> {
    let filter = match args.lab_mode {
        Some(m) => Some(Filter::from_lab_mode(m)?),
        None => args.filter,
    };
    crate::output::check_outputs(&[("-o", &args.output)])?;
    check_storage(&args.scene, args.gpu)?;
    if args.scene.convention == texel::texture::Convention::Lab
        && filter.and_then(Filter::lab_mode).is_none()
    {
        bail!("--convention lab applies to the lab's eight modes: give --lab-mode 1..8 or one of nearest, bilinear, mip-nearest, trilinear, aniso2-aniso16");
    }
    let mut scene = load_scene(&args.scene, input)?;
    if args.gpu && args.scene.surface_uv.is_none() && scene.maps_uv_per_pixel() {
        // The shader interpolates the vertices' uv: say so rather than refuse the scene.
        texel_io::stderr_line(
            "texel: --gpu interpolates sphere mappings from the vertices (--surface-uv vertex)",
        );
        scene.set_surface_uv(UvEvaluation::PerVertex);
    }
    let plan = scene.plan(filter, &mut input.budget)?;
    // The frame is rendered into the 8-bit target the PNG holds (a debug view into sRGB);
    // OpenEXR keeps the colour in float, unclamped.
    let options = FrameOptions {
        view: args.view,
        derivatives: args.derivatives,
        perspective: args.perspective,
        float: is_exr(&args.output),
        threads: workers(args.threads),
    };
    let (frame, encoding) = if args.gpu {
        let (mut settings, encoding) = plan.settings_with(&options);
        let draws = plan.draws();
        let filter = filter.unwrap_or(Filter::Trilinear);
        let Some(gpu_filter) = GpuFilter::of(filter) else {
            let names: Vec<&str> = GpuFilter::filters().map(Filter::name).collect();
            bail!(
                "--gpu has no {} filter; it renders {}",
                filter.name(),
                names.join(", ")
            );
        };
        settings.derivatives = Derivatives::Quad;
        input.budget.take(
            "the GPU's copies of the textures and meshes",
            texel_gpu::prepare_bytes(&draws),
        )?;
        input.budget.take(
            "the GPU frame and its read-back",
            texel_gpu::frame_bytes(settings.width, settings.height),
        )?;
        let gpu = Gpu::new(args.adapter.as_deref())?;
        (
            texel_gpu::render(&gpu, &settings, &draws, gpu_filter)?,
            encoding,
        )
    } else {
        plan.render(&options)?
    };
    write_frame(&args.output, &frame, encoding)
}

/// The context of a failed write of a result to standard output.
pub(crate) const STDOUT: &str = "cannot write to standard output";

/// Run `texel gpu-info`: every adapter, and which one `--gpu` would pick.
pub(crate) fn gpu_info() -> Result<()> {
    let all = texel_gpu::adapters();
    if all.is_empty() {
        bail!(texel_gpu::GpuError::NoAdapter);
    }
    for a in &all {
        texel_io::stdout_line(a).context(STDOUT)?;
    }
    let gpu = Gpu::new(None)?;
    texel_io::stdout_line(format_args!("--gpu uses: {}", gpu.info().name)).context(STDOUT)?;
    Ok(())
}
