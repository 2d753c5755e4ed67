//! `texel reference`: the supersampled ground truth.

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::{Context, Result};
use texel_quality::{viridis, Image8};
use texel_raster::{ReferenceEstimate, ReferencePlan, ReferenceStatus};

use crate::cli::ReferenceArgs;
use crate::input::{load_scene, Input};
use crate::interrupt;
use crate::output::{encoding, write_frame, write_image};
use crate::progress;
use texel::PreparedScene;

/// A reference plan from the command line's numbers: `min_spp` to `max_spp` samples a pixel,
/// converged within `tolerance_steps` 8-bit steps of the display (sRGB-encoded when `srgb`), jitter
/// from `seed`.
///
/// # Errors
/// A maximum below the minimum.
pub fn plan(
    min_spp: u32,
    max_spp: u32,
    tolerance_steps: f64,
    srgb: bool,
    seed: u64,
) -> Result<ReferencePlan> {
    anyhow::ensure!(
        max_spp >= min_spp,
        "--max-spp {max_spp} is below --spp {min_spp}: the maximum must be at least the minimum"
    );
    Ok(ReferencePlan {
        min_spp,
        max_spp,
        tolerance: tolerance_steps / 255.0,
        srgb_display: srgb,
        seed,
    })
}

/// Render a prepared scene's converging reference seen by `camera`, as `plan` says
/// (`texel_raster::adaptive`), on `threads` workers (`None`: all cores), showing its rounds on
/// `pb`. `stop`, once set, ends it after the current pass (see `render_reference_adaptive`).
pub fn reference_estimate(
    scene: &PreparedScene,
    plan: &ReferencePlan,
    camera: &texel_scene::Camera,
    threads: Option<usize>,
    pb: &indicatif::ProgressBar,
    stop: Option<&std::sync::atomic::AtomicBool>,
) -> Result<ReferenceEstimate> {
    let status = |s: &ReferenceStatus| {
        pb.set_length(s.total.max(1));
        pb.set_position(s.done);
        pb.set_message(format!(
            "round {} ({} pixels to {} spp, {:.1} % converged)",
            s.round,
            s.active,
            s.spp,
            100.0 * s.converged
        ));
    };
    let run = texel::ReferenceRun {
        plan: *plan,
        threads,
        scissor: None,
        progress: Some(&status),
        stop,
    };
    scene.reference(camera, &run).map_err(|e| match e {
        texel::Error::Raster(e @ texel_raster::RasterError::Interrupted) => {
            anyhow::Error::new(interrupt::Interrupted(e.to_string()))
        }
        e => e.into(),
    })
}

/// Run `texel reference`: the converging reference (`texel_raster::adaptive`), its summary on
/// stderr, the image and, with `--error-map`, each pixel's error. Ctrl-C during the passes writes
/// what is done so far, says so, and exits with status 130.
pub fn run(args: &ReferenceArgs, input: &mut Input) -> Result<()> {
    let plan = plan(
        args.spp,
        args.max_spp,
        args.tolerance,
        args.scene.color == texel::ColorHandling::Srgb,
        args.seed,
    )?;
    if let Some(map) = &args.error_map {
        anyhow::ensure!(
            !same_destination(map, &args.output),
            "--error-map {} and -o {} name the same file: give the error map a path of its own",
            map.display(),
            args.output.display()
        );
    }
    let scene = load_scene(&args.scene, input)?;
    input.budget.take(
        "the reference's per-pixel statistics",
        u64::from(scene.width) * u64::from(scene.height) * texel::REFERENCE_BYTES_PER_PIXEL,
    )?;
    let started = Instant::now();
    let pb = progress::bar(1, "reference");
    let graceful = interrupt::Graceful::begin();
    let estimate = reference_estimate(
        &scene,
        &plan,
        &scene.scene.camera,
        args.threads.map(|n| n as usize),
        &pb,
        Some(graceful.flag()),
    )?;
    drop(graceful);
    pb.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    write_frame(&args.output, &estimate.frame, encoding(args.scene.color))?;
    if let Some(path) = &args.error_map {
        write_error_map(path, &estimate)?;
    }
    eprintln!("{}", summary(&estimate, args.tolerance, seconds));
    if estimate.interrupted {
        return Err(interrupt::Interrupted(format!(
            "interrupted: {} holds the passes completed so far, not a converged reference (the share converged is above)",
            args.output.display()
        ))
        .into());
    }
    Ok(())
}

/// Whether two output paths name one destination: both standard output, or one file, resolved
/// through links (a file that does not exist yet through its directory).
fn same_destination(a: &std::path::Path, b: &std::path::Path) -> bool {
    use std::path::Path;
    if a.as_os_str() == "-" || b.as_os_str() == "-" {
        return a == b;
    }
    let resolve = |p: &Path| {
        std::fs::canonicalize(p).ok().or_else(|| {
            let parent = p
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            Some(std::fs::canonicalize(parent).ok()?.join(p.file_name()?))
        })
    };
    match (resolve(a), resolve(b)) {
        (Some(x), Some(y)) => x == y,
        _ => std::path::absolute(a).ok() == std::path::absolute(b).ok(),
    }
}

/// One line: the share converged, the samples taken and the time.
pub fn summary(e: &ReferenceEstimate, tolerance_steps: f64, seconds: f64) -> String {
    let min = e.spp.iter().copied().min().unwrap_or(0);
    let max = e.spp.iter().copied().max().unwrap_or(0);
    let unconverged = e.converged.iter().filter(|&&c| !c).count();
    let mut line = format!(
        "reference: {:.2} % of pixels within ±{tolerance_steps}/255 of the display at 95 % confidence; {min}-{max} samples per pixel (mean {:.0}); seed {}; {seconds:.1} s",
        100.0 * e.converged_share(None),
        e.mean_spp(None),
        e.plan.seed,
    );
    if e.interrupted {
        line += "; interrupted";
    } else if unconverged > 0 {
        let _ = write!(
            line,
            "; {unconverged} pixels stopped unconverged at the maximum, {max} samples (--max-spp {} in whole passes)",
            e.plan.max_spp
        );
    }
    line
}

/// Top of the error picture's colour ramp, in 8-bit steps.
pub const ERROR_MAP_MAX_STEPS: f32 = 4.0;

/// Write `--error-map`: the standard errors as OpenEXR, or their picture as PNG.
fn write_error_map(path: &std::path::Path, e: &ReferenceEstimate) -> Result<()> {
    let (w, h) = (e.frame.width, e.frame.height);
    if crate::output::is_exr(path) {
        let finite: Vec<[f32; 4]> = e
            .std_error
            .iter()
            .map(|s| s.map(|x| if x.is_finite() { x } else { f32::MAX }))
            .collect();
        return texel_quality::write_exr_atomic(path, w, h, &finite)
            .with_context(|| format!("cannot write {}", path.display()));
    }
    let pixels: Vec<[u8; 4]> = e
        .display_half_width
        .iter()
        .zip(&e.converged)
        .map(|(&hw, &ok)| {
            if ok {
                let [r, g, b] = viridis(hw * 255.0 / ERROR_MAP_MAX_STEPS);
                [r, g, b, 255]
            } else {
                [255, 0, 0, 255]
            }
        })
        .collect();
    write_image(path, &Image8::new(w, h, pixels)?)
}
