//! `texel reference`: the supersampled ground truth.

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::Result;
use texel::quality::{viridis, Image8};
use texel::raster::{ReferenceEstimate, ReferenceStatus};

use crate::cli::ReferenceArgs;
use crate::input::{load_scene, Input};
use crate::interrupt;
use crate::output::{check_outputs, write_frame, write_image};
use crate::progress;
use crate::threads::workers;

/// Run `texel reference`: the converging reference (`texel::raster::ReferencePlan`), its summary on
/// stderr, the image and, with `--error-map`, each pixel's error. Ctrl-C during the passes writes
/// what is done so far, says so, and exits with status 130.
pub(crate) fn run(args: &ReferenceArgs, input: &mut Input) -> Result<()> {
    let plan = crate::cli::reference_plan(
        args.spp,
        args.max_spp,
        args.tolerance,
        args.scene.color == texel::ColorHandling::Srgb,
        args.seed,
    )?
    .with_exact(args.exact);
    let mut outputs = vec![("-o", args.output.as_path())];
    outputs.extend(args.error_map.as_deref().map(|m| ("--error-map", m)));
    check_outputs(&outputs)?;
    let scene = load_scene(&args.scene, input)?;
    let started = Instant::now();
    let pb = progress::bar(1, "reference");
    let graceful = interrupt::Graceful::begin();
    let status = |s: &ReferenceStatus| crate::progress::show_status(&pb, s);
    let run = texel::ReferenceRun {
        plan,
        threads: workers(args.threads),
        scissor: None,
        progress: Some(&status),
        stop: Some(graceful.flag()),
    };
    let estimate = texel::reference_prepared(&scene, &scene.scene.camera, &run, &mut input.budget)
        .map_err(|e| match e {
            texel::Error::Cancelled => anyhow::Error::new(interrupt::Interrupted(
                texel::raster::RasterError::Interrupted.to_string(),
            )),
            e => e.into(),
        })?;
    drop(graceful);
    pb.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    if estimate.interrupted {
        return write_partial(args, &estimate, seconds);
    }
    write_frame(&args.output, &estimate.frame, args.scene.color.encoding())?;
    if let Some(path) = &args.error_map {
        write_error_map(path, &estimate, &[])?;
    }
    texel_io::stderr_line(summary(&estimate, args.tolerance, seconds));
    Ok(())
}

/// The keyword of the text entry (PNG `tEXt` chunk, OpenEXR attribute) that marks an interrupted
/// reference.
pub(crate) const PARTIAL_KEYWORD: &str = "texel:partial";

/// The outputs of an interrupted reference: each one that does not exist yet (or, with
/// `--keep-partial`, every one) gets the estimate so far, marked [`PARTIAL_KEYWORD`] with the
/// samples it reached; an existing file is otherwise left as it is. Always an
/// [`interrupt::Interrupted`] error, which says what was written.
fn write_partial(args: &ReferenceArgs, e: &ReferenceEstimate, seconds: f64) -> Result<()> {
    let min = e.spp.iter().copied().min().unwrap_or(0);
    let max = e.spp.iter().copied().max().unwrap_or(0);
    let note = format!(
        "interrupted: {min}-{max} samples per pixel (mean {:.1}) of --spp {} to --max-spp {}; \
         {:.2} % of pixels converged; seed {}",
        e.mean_spp(None),
        e.plan.min_spp,
        e.plan.max_spp,
        100.0 * e.converged_share(None),
        e.plan.seed
    );
    let text = [(PARTIAL_KEYWORD, note.as_str())];
    let exists = |p: &std::path::Path| {
        p.as_os_str() != "-" && std::fs::metadata(p).is_ok_and(|m| m.is_file())
    };
    let mut written = Vec::new();
    let mut kept = Vec::new();
    let outputs =
        std::iter::once((&args.output, false)).chain(args.error_map.iter().map(|m| (m, true)));
    for (path, is_map) in outputs {
        if exists(path) && !args.keep_partial {
            kept.push(path.display().to_string());
            continue;
        }
        if is_map {
            write_error_map(path, e, &text)?;
        } else {
            crate::output::write_frame_with_text(
                path,
                &e.frame,
                args.scene.color.encoding(),
                &text,
            )?;
        }
        written.push(path.display().to_string());
    }
    texel_io::stderr_line(summary(e, args.tolerance, seconds));
    let mut message = String::from("interrupted");
    if !written.is_empty() {
        let _ = write!(
            message,
            "; {} {} the passes completed so far, marked {PARTIAL_KEYWORD} (not a converged \
             reference; the share converged is above)",
            written.join(" and "),
            if written.len() == 1 { "holds" } else { "hold" }
        );
    }
    if !kept.is_empty() {
        let _ = write!(
            message,
            "; {} left as {} (--keep-partial writes a partial result over existing files)",
            kept.join(" and "),
            if kept.len() == 1 {
                "it was"
            } else {
                "they were"
            }
        );
    }
    Err(interrupt::Interrupted(message).into())
}

/// One line: the share converged, the samples taken and the time.
pub(crate) fn summary(e: &ReferenceEstimate, tolerance_steps: f64, seconds: f64) -> String {
    let min = e.spp.iter().copied().min().unwrap_or(0);
    let max = e.spp.iter().copied().max().unwrap_or(0);
    let unconverged = e.converged.iter().filter(|&&c| !c).count();
    let mut line = format!(
        "reference: {:.2} % of pixels within ±{tolerance_steps}/255 of the display at 95 % confidence; {min}-{max} samples per pixel (mean {:.0}); seed {}; {seconds:.1} s",
        100.0 * e.converged_share(None),
        e.mean_spp(None),
        e.plan.seed,
    );
    if e.plan.exact {
        let sampled: Vec<bool> = e.exact.iter().map(|&x| !x).collect();
        let sampled_spp: Vec<u32> = e
            .spp
            .iter()
            .zip(&e.exact)
            .filter(|(_, &x)| !x)
            .map(|(&n, _)| n)
            .collect();
        let _ = write!(
            line,
            "; {:.2} % of pixels exact (integral computed, error below 1e-6 of the value){}",
            100.0 * e.exact_share(None),
            if sampled_spp.is_empty() {
                String::new()
            } else {
                format!(
                    ", the others sampled: {}-{} samples (mean {:.0}), {:.2} % converged",
                    sampled_spp.iter().min().unwrap_or(&0),
                    sampled_spp.iter().max().unwrap_or(&0),
                    e.mean_spp(Some(&sampled)),
                    100.0 * e.converged_share(Some(&sampled))
                )
            }
        );
    }
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
pub(crate) const ERROR_MAP_MAX_STEPS: f32 = 4.0;

/// Write `--error-map`: the standard errors as OpenEXR, or their picture as PNG.
fn write_error_map(
    path: &std::path::Path,
    e: &ReferenceEstimate,
    text: &[(&str, &str)],
) -> Result<()> {
    let (w, h) = (e.frame.width, e.frame.height);
    if crate::output::is_exr(path) {
        let finite: Vec<[f32; 4]> = e
            .std_error
            .iter()
            .map(|s| s.map(|x| if x.is_finite() { x } else { f32::MAX }))
            .collect();
        let bytes = texel::quality::encode_exr_with_text(w, h, &finite, text)?;
        return crate::output::publish(path, &bytes);
    }
    let pixels: Vec<[u8; 4]> = e
        .display_half_width
        .iter()
        .zip(&e.converged)
        .zip(&e.exact)
        .map(|((&hw, &ok), &exact)| {
            if exact {
                [255, 255, 255, 255]
            } else if ok {
                let [r, g, b] = viridis(hw * 255.0 / ERROR_MAP_MAX_STEPS);
                [r, g, b, 255]
            } else {
                [255, 0, 0, 255]
            }
        })
        .collect();
    let image = Image8::new(w, h, pixels)?;
    if text.is_empty() {
        return write_image(path, &image);
    }
    crate::output::publish(path, &crate::output::with_text(image.to_png()?, text))
}
