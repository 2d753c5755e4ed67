//! `texel compare`: every filter against the supersampled reference, with a report.
//!
//! Per filter: one untimed warm-up frame, [`TIMED_FRAMES`] timed frames (the median is the "ms per
//! frame"), then one frame with texel counting on, whose image (identical to the uncounted ones) is
//! written and scored. Quality is measured on the 8-bit images exactly as written (texel-quality's
//! decision), so anyone can recompute it from the PNG files.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use texel_io::publish_dir;
use texel_quality::{
    block_psnr, crop_enlarge, default_band_rows, excess_change, heat_map, horizon_crop_rect,
    mean_abs_change, psnr, Encoding, FilterRow, Image8, Mask, Orbit, ReferenceError,
    ReferenceSummary, Report, Scores, DEFAULT_BLOCK,
};
use texel_raster::{render, Frame, ReferencePlan, RenderSettings};

use crate::cli::CompareArgs;
use crate::cmd_bench::{median, time_frames};
use crate::cmd_reference::{self as reference, reference_estimate};
use crate::filters::{parse_list, Filter};
use crate::input::{check_storage, load_scene, Input};
use crate::output::encoding;
use crate::progress;
use texel::memory::FRAME_BYTES_PER_PIXEL;
use texel::REFERENCE_BYTES_PER_PIXEL;
use texel::{MemoryBudget, PreparedScene};
use texel_gpu::GpuFilter;

/// Timed frames per filter in a comparison.
pub const TIMED_FRAMES: u32 = 3;

/// Error (8-bit units) at the top of the heat maps' colour ramp.
pub const HEAT_MAP_MAX: f32 = 64.0;

/// Enlargement of the horizon crops (nearest neighbour).
pub const CROP_FACTOR: u32 = 4;

/// Parse `LABEL=PATH`.
pub fn parse_extra(s: &str) -> Result<(String, PathBuf)> {
    match s.split_once('=') {
        Some((label, path)) if !label.trim().is_empty() && !path.is_empty() => {
            Ok((label.trim().to_string(), PathBuf::from(path)))
        }
        _ => bail!("--extra {s:?} is not LABEL=IMAGE (e.g. --extra llvmpipe=trilinear.png)"),
    }
}

/// A file-name-safe version of a label.
fn slug(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// What every scored image shares: the reference, the coverage and the output directory.
struct Scoring<'a> {
    reference: Image8,
    encoding: Encoding,
    coverage: Mask,
    band_rows: u32,
    crop: Option<texel_quality::Rect>,
    dir: &'a Path,
}

impl Scoring<'_> {
    /// Write `image` (as `{stem}.png`), its heat map and horizon crop; return its row.
    fn row(&self, name: &str, stem: &str, image: &Image8, write_image: bool) -> Result<FilterRow> {
        let scores = Scores::compute(&self.reference, image, &self.coverage, self.band_rows)
            .with_context(|| format!("cannot score {name}"))?;
        let file = format!("{stem}.png");
        if write_image {
            image.write_png(self.dir.join(&file))?;
        }
        let mut row = FilterRow::new(name, scores, file);
        row.psnr_block = Some(block_psnr(
            &self.reference,
            image,
            Some(&self.coverage),
            DEFAULT_BLOCK,
            self.encoding,
        )?);
        let heat = heat_map(&self.reference, image, Some(&self.coverage), HEAT_MAP_MAX)?;
        let heat_file = format!("{stem}-error.png");
        heat.write_png(self.dir.join(&heat_file))?;
        row.heat_map = Some(heat_file);
        if let Some(rect) = self.crop {
            let crop_file = format!("{stem}-horizon.png");
            crop_enlarge(image, rect, CROP_FACTOR)?.write_png(self.dir.join(&crop_file))?;
            row.horizon_crop = Some(crop_file);
        }
        Ok(row)
    }
}

/// What a comparison holds per pixel besides the prepared scene's one frame: the reference frame
/// ([`FRAME_BYTES_PER_PIXEL`]) and its statistics ([`REFERENCE_BYTES_PER_PIXEL`]), the coverage
/// mask (1), the reference and current 8-bit images (8), the heat map (4) and the encoder's
/// copies (8), rounded up; each row's 8-bit image is kept besides ([`ROW_BYTES_PER_PIXEL`]) to rank
/// the rows against each other. An `--extra` image, checked
/// against the comparison's size from its header first, adds [`EXTRA_BYTES_PER_PIXEL`] while it
/// is decoded and scored.
pub const COMPARE_BYTES_PER_PIXEL: u64 = FRAME_BYTES_PER_PIXEL + REFERENCE_BYTES_PER_PIXEL + 32;

/// Each row's 8-bit image, kept until the rows are ranked.
pub const ROW_BYTES_PER_PIXEL: u64 = 4;

/// An `--extra` image while it is decoded (the decoder's buffer, up to 16-bit RGBA: 8) and held as
/// 8-bit RGBA (4), rounded up; one at a time.
pub const EXTRA_BYTES_PER_PIXEL: u64 = 16;

/// Check `--extra` entries against each other and the filters: every label names one row and one
/// file, so two labels that are equal, or whose file names would be equal, or a label equal to a
/// compared filter's name, are refused, and so is a label holding control or bidirectional
/// characters (it is a row of the report).
pub fn check_extras(extras: &[(String, PathBuf)], filters: &[Filter]) -> Result<()> {
    for (i, (label, _)) in extras.iter().enumerate() {
        // A label is a row of the report (Markdown, HTML, JSON) that a terminal may show.
        if label.chars().any(texel_io::term::needs_escape) {
            bail!(
                "--extra label {} holds control or bidirectional characters: give a label of \
                 printable characters",
                texel_io::escape(label)
            );
        }
        if let Some(f) = filters.iter().find(|f| f.name() == label) {
            bail!(
                "--extra label {label:?} is also the name of a compared filter ({}): give the extra image another label",
                f.name()
            );
        }
        for (other, _) in &extras[..i] {
            if other == label {
                bail!(
                    "--extra label {label:?} is given twice: each extra image needs its own label"
                );
            }
            // Case-insensitive file systems (macOS, Windows) would merge `a` and `A`.
            if slug(other).eq_ignore_ascii_case(&slug(label)) {
                bail!(
                    "--extra labels {other:?} and {label:?} would both be written as extra-{}.png: make them differ in letters, digits, - or _",
                    slug(label)
                );
            }
        }
    }
    Ok(())
}

/// Rows scored beside the filters: images from files (`--extra LABEL=PATH`) and frames rendered
/// elsewhere (`--gpu`: label, frame, median ms per frame).
#[derive(Default)]
pub struct Extras {
    /// `--extra` images.
    pub files: Vec<(String, PathBuf)>,
    /// Rendered frames.
    pub frames: Vec<(String, Frame, f64)>,
    /// A bar that counts the reference and each filter, where a caller shows one bar over several
    /// comparisons (`texel demo`); `None` draws the comparison's own.
    pub progress: Option<indicatif::ProgressBar>,
}

/// Render `filters` (those the GPU path has) with texel's shaders and the device's own sampler:
/// rows `gpu-NAME`, `hw-trilinear`, `hw-aniso16`, each the last of [`TIMED_FRAMES`] timed frames.
fn gpu_rows(
    scene: &PreparedScene,
    filters: &[Filter],
    adapter: Option<&str>,
    budget: &mut MemoryBudget,
) -> Result<Vec<(String, Frame, f64)>> {
    let gpu = texel_gpu::Gpu::new(adapter)?;
    texel_io::stderr_line(format_args!("gpu: {}", gpu.info()));
    let mut settings = scene.settings();
    settings.derivatives = texel_raster::Derivatives::Quad;
    let mut jobs: Vec<(String, Filter, GpuFilter)> = filters
        .iter()
        .filter_map(|&f| GpuFilter::of(f).map(|g| (format!("gpu-{}", f.name()), f, g)))
        .collect();
    jobs.extend(
        crate::filters::HARDWARE_ROWS
            .iter()
            .map(|&(label, f, g)| (label.to_string(), f, g)),
    );
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
        let mut frame = prepared.render(&settings)?;
        for _ in 0..TIMED_FRAMES {
            let t0 = std::time::Instant::now();
            frame = prepared.render(&settings)?;
            times.push(t0.elapsed().as_secs_f64() * 1e3);
        }
        rows.push((label, frame, median(&mut times)));
        drop(prepared);
        budget.release(uploads);
    }
    Ok(rows)
}

/// A camera orbit to measure flicker over (`--orbit`, `--orbit-step`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitSpec {
    /// Frames, the scene's own view first (at least 2).
    pub frames: u32,
    /// Degrees per frame.
    pub step_deg: f32,
}

/// The reference's figures for the report, over the covered pixels.
fn reference_summary(
    estimate: &texel_raster::ReferenceEstimate,
    error: &ReferenceError,
    coverage: &Mask,
) -> Result<ReferenceSummary> {
    let covered = coverage.bits();
    Ok(ReferenceSummary {
        min_spp: estimate.plan.min_spp,
        max_spp: estimate.plan.max_spp,
        mean_spp: estimate.mean_spp(Some(covered)),
        tolerance: estimate.plan.tolerance * 255.0,
        converged: estimate.converged_share(Some(covered)),
        noise_floor: error.noise_floor(Some(coverage))?,
        noise_floor_block: error.block_noise_floor(Some(coverage), DEFAULT_BLOCK)?,
        block: DEFAULT_BLOCK,
    })
}

/// What one comparison measures: the scene's name in the report, the filters, how the
/// reference is made and, optionally, an orbit.
pub struct Comparison<'a> {
    /// Names the scene in the report.
    pub label: &'a str,
    /// The filters, one row each.
    pub filters: &'a [Filter],
    /// How the reference is made.
    pub plan: &'a ReferencePlan,
    /// With an orbit, the filters' rows also get their flicker and orbit PSNR
    /// ([`orbit_scores`]).
    pub orbit: Option<OrbitSpec>,
}

/// Run comparison `job` on a prepared scene, write everything into `dir` (which must exist: the
/// caller publishes it, see [`texel_io::publish_dir`]) and return the report. Every row gets its
/// block-mean PSNR and the rows the reference cannot rank it against.
pub fn compare(
    scene: &PreparedScene,
    job: &Comparison,
    extras: &Extras,
    dir: &Path,
    budget: &mut MemoryBudget,
) -> Result<Report> {
    let Comparison {
        label,
        filters,
        plan,
        orbit,
    } = *job;
    let enc = encoding(scene.color);
    if let Some(pb) = &extras.progress {
        pb.set_message(format!("{label}: reference"));
    }
    let bar = match &extras.progress {
        Some(_) => indicatif::ProgressBar::hidden(),
        None => progress::bar(1, "reference"),
    };
    let estimate = reference_estimate(scene, plan, &scene.scene.camera, None, &bar, None)?;
    bar.finish_and_clear();
    if let Some(pb) = &extras.progress {
        pb.inc(1);
    }
    let reference = &estimate.frame;
    let (w, h) = (reference.width, reference.height);
    let ref_image = Image8::from_linear(w, h, &reference.color, enc)?;
    ref_image.write_png(dir.join("reference.png"))?;
    let coverage = Mask::new(w, h, reference.coverage())?;
    if coverage.count() == 0 {
        bail!("the scene covers no pixel: nothing to compare");
    }
    let error = ReferenceError {
        width: w,
        height: h,
        mean: &reference.color,
        std_error: &estimate.std_error,
        encoding: enc,
    };
    let reference_error = reference_summary(&estimate, &error, &coverage)?;
    let rows_count = filters.len() + extras.frames.len() + extras.files.len();
    let kept = u64::from(w) * u64::from(h) * ROW_BYTES_PER_PIXEL * rows_count as u64;
    budget.take("the rows' images, kept to rank them", kept)?;
    let crop = horizon_crop_rect(&coverage, (w / 5).max(16), (h / 8).max(8));
    let scoring = Scoring {
        reference: ref_image,
        encoding: enc,
        coverage,
        band_rows: default_band_rows(h),
        crop,
        dir,
    };
    let reference_crop = match crop {
        Some(rect) => {
            crop_enlarge(&scoring.reference, rect, CROP_FACTOR)?
                .write_png(dir.join("reference-horizon.png"))?;
            Some("reference-horizon.png".to_string())
        }
        None => None,
    };

    let mut rows = Vec::new();
    let mut images = Vec::new();
    let pb = match &extras.progress {
        Some(pb) => pb.clone(),
        None => progress::bar(filters.len() as u64, "filters"),
    };
    for &filter in filters {
        match &extras.progress {
            Some(_) => pb.set_message(format!("{label}: {}", filter.name())),
            None => pb.set_message(filter.name()),
        }
        let frame_plan = scene.plan(Some(filter), budget)?;
        let bytes = frame_plan.structure_bytes();
        let draws = frame_plan.draws();
        let settings = frame_plan.settings();
        let mut times = time_frames(&settings, &draws, 1, Duration::ZERO, TIMED_FRAMES)?;
        let mut counting = settings;
        counting.count_texels = true;
        let frame = render(&counting, &draws)?;
        let image = texel::frame_image(&frame, enc)?;
        let mut row = scoring.row(filter.name(), filter.name(), &image, true)?;
        let (mean, max) = frame.texels_per_pixel();
        row.texels_per_pixel_mean = Some(mean);
        row.texels_per_pixel_max = Some(max);
        row.ms_per_frame = Some(median(&mut times.draw_ms));
        row.texture_bytes = Some(bytes);
        rows.push(row);
        images.push(image);
        pb.inc(1);
    }
    if extras.progress.is_none() {
        pb.finish_and_clear();
    }
    let orbit = match orbit {
        Some(spec) => Some(orbit_scores(
            scene,
            filters,
            plan,
            spec,
            (&scoring, &images),
            &mut rows,
            budget,
        )?),
        None => None,
    };

    for (label, frame, ms) in &extras.frames {
        let image = texel::frame_image(frame, enc)?;
        let mut row = scoring.row(label, label, &image, true)?;
        row.extra = true;
        row.ms_per_frame = Some(*ms);
        rows.push(row);
        images.push(image);
    }
    for (label, path) in &extras.files {
        let cannot = || format!("cannot load --extra image {label}={}", path.display());
        // The size comes from the header, so a mismatched (or huge) image is refused undecoded.
        let (iw, ih) = Image8::dimensions(path).with_context(cannot)?;
        if (iw, ih) != (w, h) {
            bail!(
                "--extra image {} is {iw}x{ih} but the comparison is {w}x{h} (pass --size to match)",
                path.display(),
            );
        }
        let image = Image8::load(path).with_context(cannot)?;
        let stem = format!("extra-{}", slug(label));
        let mut row = scoring.row(label, &stem, &image, true)?;
        row.extra = true;
        rows.push(row);
        images.push(image);
    }
    let refs: Vec<&Image8> = images.iter().collect();
    let ties = error.within_noise(&scoring.reference, &refs, Some(&scoring.coverage))?;
    let names: Vec<String> = rows.iter().map(|r| r.name.clone()).collect();
    for (row, tied) in rows.iter_mut().zip(ties) {
        row.within_noise_of = tied.into_iter().map(|j| names[j].clone()).collect();
    }
    drop(images);
    budget.release(kept);

    let report = Report {
        scene: label.to_string(),
        width: w,
        height: h,
        spp: plan.min_spp,
        // The colour handling, and the filtering arithmetic where it is not the exact default.
        color: format!(
            "{}{}",
            match scene.color {
                texel::ColorHandling::Srgb => "srgb",
                texel::ColorHandling::Raw => "raw",
            },
            match scene.precision {
                texel::raster::Precision::Exact => "",
                texel::raster::Precision::Gpu => ", gpu precision",
            }
        ),
        reference_image: "reference.png".to_string(),
        reference_crop,
        band_rows: scoring.band_rows,
        heat_map_max: HEAT_MAP_MAX,
        rows,
        orbit,
        reference_error: Some(reference_error),
    };
    report.write(dir)?;
    Ok(report)
}

/// Render the rest of an orbit (frames 1 to `frames - 1`; frame 0 is the comparison's own, its
/// reference in `scoring` and its images in `images`, one per filter) and set each filter row's
/// [`FilterRow::flicker`] ([`excess_change`] averaged over consecutive pairs) and
/// [`FilterRow::psnr_orbit`]. Change is measured over the pixels the reference covers in both
/// frames of a pair.
fn orbit_scores(
    scene: &PreparedScene,
    filters: &[Filter],
    plan: &ReferencePlan,
    spec: OrbitSpec,
    (scoring, images): (&Scoring, &[Image8]),
    rows: &mut [FilterRow],
    budget: &mut MemoryBudget,
) -> Result<Orbit> {
    let enc = encoding(scene.color);
    let (w, h) = (scene.width, scene.height);
    let mut prev_ref = scoring.reference.clone();
    let mut prev_cov = scoring.coverage.clone();
    let mut prev = images[..filters.len()].to_vec();
    let mut ref_change = 0.0;
    let mut change = vec![0.0; filters.len()];
    let mut psnr_sum: Vec<f64> = rows.iter().map(|r| r.psnr_all).collect();
    for k in 1..spec.frames {
        texel_io::stderr_line(format_args!("orbit frame {k} of {}", spec.frames - 1));
        let camera = scene.scene.camera.orbited(spec.step_deg * k as f32);
        let bar = progress::bar(1, "reference");
        let estimate = reference_estimate(scene, plan, &camera, None, &bar, None)?;
        bar.finish_and_clear();
        let reference = estimate.frame;
        let ref_image = Image8::from_linear(w, h, &reference.color, enc)?;
        let coverage = Mask::new(w, h, reference.coverage())?;
        ref_change += mean_abs_change(&prev_ref, &ref_image, &prev_cov, &coverage)?;
        for (i, &filter) in filters.iter().enumerate() {
            let frame_plan = scene.plan(Some(filter), budget)?;
            let frame = render(
                &frame_plan.settings_from(&camera),
                &frame_plan.draws_from(&camera),
            )?;
            let image = texel::frame_image(&frame, enc)?;
            change[i] += excess_change(
                [&prev[i], &image],
                [&prev_ref, &ref_image],
                [&prev_cov, &coverage],
            )?;
            psnr_sum[i] += psnr(&ref_image, &image, Some(&coverage))?;
            prev[i] = image;
        }
        (prev_ref, prev_cov) = (ref_image, coverage);
    }
    let pairs = f64::from(spec.frames - 1);
    let reference_flicker = ref_change / pairs;
    for (i, row) in rows.iter_mut().take(filters.len()).enumerate() {
        row.flicker = Some(change[i] / pairs);
        row.psnr_orbit = Some(psnr_sum[i] / f64::from(spec.frames));
    }
    Ok(Orbit {
        frames: spec.frames,
        step_deg: spec.step_deg,
        reference_flicker,
    })
}

/// What `compare` can tell before the reference: the frame holds SSIM's window, every `--extra`
/// image (its header read, not decoded) has the comparison's size, and the scene covers a pixel
/// where that window fits (seen in one nearest-filtered frame: where pixel centres meet a
/// triangle).
fn check_before_work(
    scene: &PreparedScene,
    extras: &[(String, PathBuf)],
    budget: &mut MemoryBudget,
) -> Result<()> {
    let (w, h) = (scene.width, scene.height);
    let side = texel_quality::ssim::WINDOW as u32;
    anyhow::ensure!(
        w >= side && h >= side,
        "invalid --size {w}x{h}: compare scores SSIM over {side}x{side} windows, so each side must \
         be at least {side} pixels"
    );
    let probe = scene.plan(Some(Filter::Nearest), budget)?;
    let covered = render(&probe.settings(), &probe.draws())?.coverage();
    anyhow::ensure!(
        covered.iter().any(|&c| c),
        "the scene covers no pixel centre at {w}x{h}: nothing to compare (check the camera)"
    );
    let half = side / 2;
    let inner = (half..h - half).any(|y| (half..w - half).any(|x| covered[(y * w + x) as usize]));
    anyhow::ensure!(
        inner,
        "the scene covers no pixel at least {half} pixels from the frame's edge, where SSIM's \
         {side}x{side} window fits: nothing to score (a larger --size, or a camera that sees more \
         of the scene)"
    );
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
pub fn run(args: &CompareArgs, input: &mut Input) -> Result<()> {
    let filters = parse_list(&args.filters)?;
    let extras = args
        .extra
        .iter()
        .map(|e| parse_extra(e))
        .collect::<Result<Vec<_>>>()?;
    check_extras(&extras, &filters)?;
    let plan = reference::plan(
        args.spp,
        args.max_spp.unwrap_or(args.spp),
        args.tolerance,
        args.scene.color == texel::ColorHandling::Srgb,
        texel_raster::adaptive::DEFAULT_SEED,
    )?;
    check_storage(&args.scene, args.gpu)?;
    let scene = load_scene(&args.scene, input)?;
    check_before_work(&scene, &extras, &mut input.budget)?;
    let frames = if args.gpu {
        gpu_rows(&scene, &filters, args.adapter.as_deref(), &mut input.budget)?
    } else {
        Vec::new()
    };
    let extras = Extras {
        files: extras,
        frames,
        progress: None,
    };
    let per_pixel = COMPARE_BYTES_PER_PIXEL
        + if extras.files.is_empty() {
            0
        } else {
            EXTRA_BYTES_PER_PIXEL
        };
    input.budget.take(
        "the comparison's reference and images",
        u64::from(scene.width) * u64::from(scene.height) * per_pixel,
    )?;
    let orbit = args.orbit.map(|frames| OrbitSpec {
        frames,
        step_deg: args.orbit_step,
    });
    if orbit.is_some() {
        // The previous frame's 8-bit images (reference and one per filter) and coverage.
        input.budget.take(
            "the orbit's previous frames",
            u64::from(scene.width) * u64::from(scene.height) * (4 * filters.len() as u64 + 5),
        )?;
    }
    // What the command reads must not lie inside what it replaces.
    let mut inputs: Vec<&Path> = vec![Path::new(&args.scene.scene)];
    inputs.extend(extras.files.iter().map(|(_, p)| p.as_path()));
    let report = publish_dir(&args.out, &inputs, |dir| {
        // The scene's name as the report shows it: control and bidirectional characters escaped.
        let label = texel_io::escape(&args.scene.scene);
        let job = Comparison {
            label: &label,
            filters: &filters,
            plan: &plan,
            orbit,
        };
        compare(&scene, &job, &extras, dir, &mut input.budget)
    })
    .with_context(|| format!("cannot write the report to {}", args.out.display()))?;
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
        assert_eq!(slug("llvm pipe/1"), "llvm_pipe_1");
    }

    #[test]
    fn extras_distinct() {
        let e = |l: &str| (l.to_string(), PathBuf::from("x.png"));
        let f = [Filter::Trilinear];
        assert!(check_extras(&[e("gpu"), e("llvmpipe")], &f).is_ok());
        let msg = check_extras(&[e("gpu"), e("gpu")], &f)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("given twice"), "{msg}");
        let msg = check_extras(&[e("a b"), e("a_b")], &f)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("extra-a_b.png"), "{msg}");
        let msg = check_extras(&[e("gpu"), e("GPU")], &f)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("extra-GPU.png"), "{msg}");
        let msg = check_extras(&[e("trilinear")], &f).unwrap_err().to_string();
        assert!(msg.contains("compared filter"), "{msg}");
    }
}
