//! Every filter of a scene against its converging reference: the job `texel compare`,
//! `texel demo` and Python's `texel.compare` run, written once.
//!
//! Per filter: one untimed warm-up frame, [`TIMED_FRAMES`] timed frames (the median is the "ms per
//! frame"), then one frame with texel counting on, whose image (identical to the uncounted ones)
//! is scored. Quality is measured on the 8-bit images exactly as they are written, so anyone can
//! recompute it from the PNG files. [`compare`] returns the [`Report`]; given a folder it also
//! writes the report's images and files there.
//!
//! ```
//! use texel::compare::{compare, CompareJob};
//! use texel::raster::ReferencePlan;
//! use texel::{Filter, MemoryBudget, PreparedScene, Scene, SceneOptions};
//!
//! let mut budget = MemoryBudget::limit_or_default(None);
//! let options = SceneOptions { size: Some((48, 27)), ..SceneOptions::default() };
//! let scene = PreparedScene::new(Scene::load("builtin:ground")?, &options, &mut budget)?;
//! let plan = ReferencePlan::new(4, 4, 0.5, true, 1)?;
//! let filters = [Filter::Nearest, Filter::Aniso16];
//! let report = compare(&scene, &CompareJob::new("ground", &filters, plan), None, &mut budget)?;
//! // Nearest aliases at the horizon; the anisotropic filter is closer to the reference.
//! assert!(report.rows[1].psnr_all > report.rows[0].psnr_all);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use texel_prepare::memory::FRAME_BYTES_PER_PIXEL;
use texel_prepare::{Error, MemoryBudget, PreparedScene, ReferenceRun};
use texel_quality::{
    block_psnr, crop_enlarge, default_band_rows, excess_change, heat_map, horizon_crop_rect,
    mean_abs_change, psnr, Encoding, FilterRow, Image8, Mask, Orbit, QualityError, ReferenceError,
    ReferenceSummary, Report, Scores, DEFAULT_BLOCK,
};
use texel_raster::{render, Frame, ReferenceEstimate, ReferencePlan, ReferenceStatus};
use texel_scene::Camera;
use texel_texture::Filter;

use crate::entry::REFERENCE_BYTES_PER_PIXEL;
use crate::timing::{median, time_frames};

/// Timed frames per filter in a comparison.
pub const TIMED_FRAMES: u32 = 3;

/// Error (8-bit units) at the top of the heat maps' colour ramp.
pub(crate) const HEAT_MAP_MAX: f32 = 64.0;

/// Enlargement of the horizon crops (nearest neighbour).
pub(crate) const CROP_FACTOR: u32 = 4;

/// What a comparison holds per pixel besides the prepared scene's one frame: the reference frame
/// ([`FRAME_BYTES_PER_PIXEL`]) and its statistics ([`REFERENCE_BYTES_PER_PIXEL`]), the coverage
/// mask (1), the reference and current 8-bit images (8), the heat map (4) and the encoder's
/// copies (8), rounded up; each row's 8-bit image is kept besides ([`ROW_BYTES_PER_PIXEL`]) to rank
/// the rows against each other. An extra image, checked against the comparison's size from its
/// header first, adds [`EXTRA_BYTES_PER_PIXEL`] while it is decoded and scored.
pub(crate) const COMPARE_BYTES_PER_PIXEL: u64 =
    FRAME_BYTES_PER_PIXEL + REFERENCE_BYTES_PER_PIXEL + 32;

/// Each row's 8-bit image, kept until the rows are ranked.
pub(crate) const ROW_BYTES_PER_PIXEL: u64 = 4;

/// An extra image while it is decoded (the decoder's buffer, up to 16-bit RGBA: 8) and held as
/// 8-bit RGBA (4), rounded up; one at a time.
pub(crate) const EXTRA_BYTES_PER_PIXEL: u64 = 16;

/// A camera orbit to measure flicker over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitSpec {
    /// Frames, the scene's own view first (at least 2).
    pub frames: u32,
    /// Degrees per frame.
    pub step_deg: f32,
}

/// A row scored beside the filters.
#[derive(Clone, Debug)]
pub enum Extra {
    /// An image file (PNG, JPEG, ...) of the comparison's size, rendered elsewhere; decoded when
    /// its row is scored.
    File {
        /// The row's name.
        label: String,
        /// The image.
        path: PathBuf,
    },
    /// A frame rendered elsewhere (a GPU) and its median milliseconds per frame.
    Frame {
        /// The row's name.
        label: String,
        /// The frame.
        frame: Frame,
        /// Median milliseconds per frame.
        ms: f64,
    },
}

impl Extra {
    /// The row's name.
    pub fn label(&self) -> &str {
        match self {
            Extra::File { label, .. } | Extra::Frame { label, .. } => label,
        }
    }
}

/// Check the extra rows' labels against each other and the filters: every label names one row
/// and one file (`extra-{label}.png`, the label made file-name-safe), so two labels that are
/// equal, or whose file names would be equal on a file system that ignores case, or a label equal
/// to a compared filter's name, are refused, and so is a label holding control or bidirectional
/// characters (it is a row of the report, which a terminal may show). [`compare`] checks its
/// job's; a caller checks its own first to refuse them before any work.
///
/// # Errors
/// [`Error::Compare`], naming the label.
pub fn check_labels<'a>(
    labels: impl IntoIterator<Item = &'a str>,
    filters: &[Filter],
) -> Result<(), Error> {
    let bad = |m: String| Err(Error::Compare(m));
    let labels: Vec<&str> = labels.into_iter().collect();
    for (i, &label) in labels.iter().enumerate() {
        if label.chars().any(texel_io::term::needs_escape) {
            return bad(format!(
                "extra label {} holds control or bidirectional characters: give a label of \
                 printable characters",
                texel_io::escape(label)
            ));
        }
        if let Some(f) = filters.iter().find(|f| f.name() == label) {
            return bad(format!(
                "extra label {label:?} is also the name of a compared filter ({}): give the extra \
                 image another label",
                f.name()
            ));
        }
        for &other in &labels[..i] {
            if other == label {
                return bad(format!(
                    "extra label {label:?} is given twice: each extra image needs its own label"
                ));
            }
            if slug(other).eq_ignore_ascii_case(&slug(label)) {
                return bad(format!(
                    "extra labels {other:?} and {label:?} would both be written as extra-{}.png: \
                     make them differ in letters, digits, - or _",
                    slug(label)
                ));
            }
        }
    }
    Ok(())
}

/// What a comparison is at, for a progress display.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage<'a> {
    /// The reference of orbit frame `n` (0: the scene's own view) of `of`.
    Reference {
        /// The frame.
        n: u32,
        /// Frames in all.
        of: u32,
    },
    /// One filter's frames.
    Filter(&'a str),
}

/// Where a comparison shows its progress.
pub trait Progress: Sync {
    /// A stage begins.
    fn stage(&self, stage: Stage<'_>);
    /// A round of the reference ([`ReferenceRun::progress`]).
    fn reference(&self, status: &ReferenceStatus);
    /// A stage ends.
    fn done(&self, stage: Stage<'_>);
}

/// What one comparison measures.
#[derive(Clone, Copy)]
pub struct CompareJob<'a> {
    /// Names the scene in the report.
    pub label: &'a str,
    /// The filters, one row each.
    pub filters: &'a [Filter],
    /// How the reference is made.
    pub plan: ReferencePlan,
    /// With an orbit, the filters' rows also get their flicker and orbit PSNR.
    pub orbit: Option<OrbitSpec>,
    /// Rows scored beside the filters.
    pub extras: &'a [Extra],
    /// Worker threads for the reference and the frames; `None`: all cores.
    pub threads: Option<usize>,
    /// Once set, the comparison stops ([`Error::Cancelled`]) after the current pass or frame.
    pub stop: Option<&'a AtomicBool>,
    /// Where progress is shown.
    pub progress: Option<&'a dyn Progress>,
}

impl<'a> CompareJob<'a> {
    /// `filters` against a reference made as `plan` says, nothing else.
    pub fn new(label: &'a str, filters: &'a [Filter], plan: ReferencePlan) -> Self {
        CompareJob {
            label,
            filters,
            plan,
            orbit: None,
            extras: &[],
            threads: None,
            stop: None,
            progress: None,
        }
    }

    /// Charge `budget` for what a comparison of `scene` holds besides the scene: per pixel the
    /// reference's frame and statistics, the coverage mask, the 8-bit images, the heat map and
    /// the encoder's copies (264 bytes; 16 more with an extra image file), and
    /// with an orbit the previous frame's 8-bit images (the reference and one per filter) and
    /// coverage. The rows' images are charged while they are kept, in [`compare`].
    ///
    /// # Errors
    /// [`Error::OverBudget`].
    pub fn charge(&self, scene: &PreparedScene, budget: &mut MemoryBudget) -> Result<(), Error> {
        let pixels = u64::from(scene.width) * u64::from(scene.height);
        let files = self.extras.iter().any(|e| matches!(e, Extra::File { .. }));
        let extra = if files { EXTRA_BYTES_PER_PIXEL } else { 0 };
        budget.take(
            "the comparison's reference and images",
            pixels * (COMPARE_BYTES_PER_PIXEL + extra),
        )?;
        if self.orbit.is_some() {
            budget.take(
                "the orbit's previous frames",
                pixels * (4 * self.filters.len() as u64 + 5),
            )?;
        }
        Ok(())
    }

    fn stopped(&self) -> Result<(), Error> {
        match self.stop {
            Some(stop) if stop.load(Ordering::Relaxed) => Err(Error::Cancelled),
            _ => Ok(()),
        }
    }
}

/// A file-name-safe version of a label: ASCII letters, digits, `-` and `_` kept, every other
/// character `_`. An extra row's images are named `extra-{slug}`.
pub(crate) fn slug(label: &str) -> String {
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

/// What `compare` can tell before the reference: the frame holds SSIM's window, and the scene
/// covers a pixel where that window fits (seen in one nearest-filtered frame: where pixel centres
/// meet a triangle).
///
/// # Errors
/// [`Error::Compare`] saying which of these fails.
pub fn check_scene(scene: &PreparedScene, budget: &mut MemoryBudget) -> Result<(), Error> {
    let (w, h) = (scene.width, scene.height);
    let side = texel_quality::ssim::WINDOW as u32;
    let refuse = |why: String| Err(Error::Compare(why));
    if w < side || h < side {
        return refuse(format!(
            "invalid size {w}x{h}: compare scores SSIM over {side}x{side} windows, so each side \
             must be at least {side} pixels"
        ));
    }
    let probe = scene.plan(Some(Filter::Nearest), budget)?;
    let covered = render(&probe.settings(), &probe.draws())?.coverage();
    if !covered.iter().any(|&c| c) {
        return refuse(format!(
            "the scene covers no pixel centre at {w}x{h}: nothing to compare (check the camera)"
        ));
    }
    let half = side / 2;
    let inner = (half..h - half).any(|y| (half..w - half).any(|x| covered[(y * w + x) as usize]));
    if !inner {
        return refuse(format!(
            "the scene covers no pixel at least {half} pixels from the frame's edge, where SSIM's \
             {side}x{side} window fits: nothing to score (a larger --size, or a camera that sees \
             more of the scene)"
        ));
    }
    Ok(())
}

/// A prepared scene's converging reference seen by `camera`, as `job` says (its plan, threads,
/// stop flag and progress); an interruption is [`Error::Cancelled`].
fn reference(
    scene: &PreparedScene,
    job: &CompareJob,
    camera: &Camera,
) -> Result<ReferenceEstimate, Error> {
    let status = |s: &ReferenceStatus| {
        if let Some(p) = job.progress {
            p.reference(s);
        }
    };
    let run = ReferenceRun {
        plan: job.plan,
        threads: job.threads,
        scissor: None,
        progress: Some(&status),
        stop: job.stop,
    };
    scene
        .reference(camera, &run)
        .map_err(crate::entry::cancelled)
}

/// The reference's figures for the report, over the covered pixels.
fn reference_summary(
    estimate: &ReferenceEstimate,
    error: &ReferenceError,
    coverage: &Mask,
) -> Result<ReferenceSummary, Error> {
    let covered = coverage.bits();
    Ok(ReferenceSummary {
        min_spp: estimate.plan.min_spp,
        max_spp: estimate.plan.max_spp,
        mean_spp: estimate.mean_spp(Some(covered)),
        tolerance: estimate.plan.tolerance_steps(),
        converged: estimate.converged_share(Some(covered)),
        exact: estimate.exact_share(Some(covered)),
        noise_floor: error.noise_floor(Some(coverage))?,
        noise_floor_block: error.block_noise_floor(Some(coverage), DEFAULT_BLOCK)?,
        block: DEFAULT_BLOCK,
    })
}

/// What every scored image shares: the reference, the coverage and the output folder.
struct Scoring<'a> {
    reference: Image8,
    encoding: Encoding,
    coverage: Mask,
    band_rows: u32,
    crop: Option<texel_quality::Rect>,
    dir: Option<&'a Path>,
}

impl Scoring<'_> {
    /// Write `image` to the folder, if there is one, as `file`.
    fn write(&self, file: &str, image: &Image8) -> Result<(), Error> {
        if let Some(dir) = self.dir {
            image.write_png(dir.join(file))?;
        }
        Ok(())
    }

    /// Score `image` as row `name`, writing it (as `{stem}.png`), its heat map and horizon crop.
    fn row(&self, name: &str, stem: &str, image: &Image8) -> Result<FilterRow, Error> {
        let scores = Scores::compute(&self.reference, image, &self.coverage, self.band_rows)?;
        let file = format!("{stem}.png");
        self.write(&file, image)?;
        let mut row = FilterRow::new(name, scores, file);
        row.psnr_block = Some(block_psnr(
            &self.reference,
            image,
            Some(&self.coverage),
            DEFAULT_BLOCK,
            self.encoding,
        )?);
        if self.dir.is_some() {
            let heat = heat_map(&self.reference, image, Some(&self.coverage), HEAT_MAP_MAX)?;
            let heat_file = format!("{stem}-error.png");
            self.write(&heat_file, &heat)?;
            row.heat_map = Some(heat_file);
            if let Some(rect) = self.crop {
                let crop_file = format!("{stem}-horizon.png");
                self.write(&crop_file, &crop_enlarge(image, rect, CROP_FACTOR)?)?;
                row.horizon_crop = Some(crop_file);
            }
        }
        Ok(row)
    }
}

/// One filter's row: timed frames, then one frame counting texels, scored; and its image.
fn filter_row(
    scene: &PreparedScene,
    job: &CompareJob,
    filter: Filter,
    scoring: &Scoring,
    budget: &mut MemoryBudget,
) -> Result<(FilterRow, Image8), Error> {
    let frame_plan = scene.plan(Some(filter), budget)?;
    let bytes = frame_plan.structure_bytes();
    let draws = frame_plan.draws();
    let mut settings = frame_plan.settings();
    settings.threads = job.threads;
    let mut times = time_frames(&settings, &draws, 1, Duration::ZERO, TIMED_FRAMES)?;
    settings.count_texels = true;
    let frame = render(&settings, &draws)?;
    let image = crate::frame_image(&frame, scoring.encoding)?;
    let mut row = scoring.row(filter.name(), filter.name(), &image)?;
    let (mean, max) = frame.texels_per_pixel();
    row.texels_per_pixel_mean = Some(mean);
    row.texels_per_pixel_max = Some(max);
    row.ms_per_frame = Some(median(&mut times.draw_ms));
    row.texture_bytes = Some(bytes);
    Ok((row, image))
}

/// An extra row and its image.
fn extra_row(extra: &Extra, scoring: &Scoring) -> Result<(FilterRow, Image8), Error> {
    let (w, h) = (scoring.reference.width(), scoring.reference.height());
    let (label, image, ms) = match extra {
        Extra::Frame { label, frame, ms } => (
            label,
            crate::frame_image(frame, scoring.encoding)?,
            Some(*ms),
        ),
        Extra::File { label, path } => {
            let cannot = |e: QualityError| {
                Error::Compare(format!(
                    "cannot load extra image {label}={}: {e}",
                    path.display()
                ))
            };
            // The size comes from the header, so a mismatched (or huge) image is refused
            // undecoded.
            let (iw, ih) = Image8::dimensions(path).map_err(cannot)?;
            if (iw, ih) != (w, h) {
                return Err(Error::Compare(format!(
                    "extra image {} is {iw}x{ih} but the comparison is {w}x{h}",
                    path.display()
                )));
            }
            (label, Image8::load(path).map_err(cannot)?, None)
        }
    };
    let stem = match extra {
        Extra::Frame { .. } => label.clone(),
        Extra::File { .. } => format!("extra-{}", slug(label)),
    };
    let mut row = scoring.row(label, &stem, &image)?;
    row.extra = true;
    row.ms_per_frame = ms;
    Ok((row, image))
}

/// Run comparison `job` on a prepared scene and return its report. With `dir` (a folder that
/// exists: the caller publishes it, see [`texel_io::publish_dir`]) every image of the report, the
/// heat maps, the horizon crops and the report's files (`index.html`, `report.md`,
/// `report.json`) are written there; without, only the scores are computed. Every row gets its
/// block-mean PSNR and the rows the reference cannot rank it against.
///
/// # Errors
/// [`Error::Cancelled`] when `job.stop` is set; [`check_scene`]'s; an extra image cannot
/// be read or has another size; the budget is exceeded; writing fails.
pub fn compare(
    scene: &PreparedScene,
    job: &CompareJob,
    dir: Option<&Path>,
    budget: &mut MemoryBudget,
) -> Result<Report, Error> {
    check_scene(scene, budget)?;
    check_labels(job.extras.iter().map(Extra::label), job.filters)?;
    let enc = scene.color.encoding();
    let frames = job.orbit.map_or(1, |o| o.frames);
    let estimate = staged(job, Stage::Reference { n: 0, of: frames }, || {
        reference(scene, job, &scene.scene.camera)
    })?;
    let reference = &estimate.frame;
    let (w, h) = (reference.width, reference.height);
    let ref_image = Image8::from_linear(w, h, &reference.color, enc)?;
    if let Some(dir) = dir {
        ref_image.write_png(dir.join("reference.png"))?;
    }
    let coverage = Mask::new(w, h, reference.coverage())?;
    if coverage.count() == 0 {
        return Err(Error::Compare(
            "the scene covers no pixel: nothing to compare".into(),
        ));
    }
    let error = ReferenceError {
        width: w,
        height: h,
        mean: &reference.color,
        std_error: &estimate.std_error,
        encoding: enc,
    };
    let reference_error = reference_summary(&estimate, &error, &coverage)?;
    let rows_count = job.filters.len() + job.extras.len();
    let kept = u64::from(w) * u64::from(h) * ROW_BYTES_PER_PIXEL * rows_count as u64;
    budget.take("the rows' images, kept to rank them", kept)?;
    let (scoring, reference_crop) = scoring(ref_image, enc, coverage, dir)?;

    let mut rows = Vec::new();
    let mut images = Vec::new();
    for &filter in job.filters {
        job.stopped()?;
        let (row, image) = staged(job, Stage::Filter(filter.name()), || {
            filter_row(scene, job, filter, &scoring, budget)
        })?;
        rows.push(row);
        images.push(image);
    }
    let orbit = match job.orbit {
        Some(spec) => Some(orbit_scores(
            scene,
            job,
            spec,
            (&scoring, &images),
            &mut rows,
            budget,
        )?),
        None => None,
    };
    for extra in job.extras {
        let (row, image) = extra_row(extra, &scoring)?;
        rows.push(row);
        images.push(image);
    }
    mark_ties(&mut rows, &images, &error, &scoring)?;
    drop(images);
    budget.release(kept);

    let report = Report {
        scene: job.label.to_string(),
        width: w,
        height: h,
        spp: job.plan.min_spp,
        color: color_label(scene),
        reference_image: "reference.png".to_string(),
        reference_crop,
        band_rows: scoring.band_rows,
        heat_map_max: HEAT_MAP_MAX,
        rows,
        orbit,
        reference_error: Some(reference_error),
    };
    if let Some(dir) = dir {
        report.write(dir)?;
    }
    Ok(report)
}

/// What every row is scored against, and the name of the reference's enlarged horizon crop where
/// one is written.
fn scoring<'a>(
    reference: Image8,
    encoding: Encoding,
    coverage: Mask,
    dir: Option<&'a Path>,
) -> Result<(Scoring<'a>, Option<String>), Error> {
    let (w, h) = reference.size();
    let crop = horizon_crop_rect(&coverage, (w / 5).max(16), (h / 8).max(8));
    let scoring = Scoring {
        reference,
        encoding,
        coverage,
        band_rows: default_band_rows(h),
        crop,
        dir,
    };
    let reference_crop = match (crop, dir) {
        (Some(rect), Some(dir)) => {
            crop_enlarge(&scoring.reference, rect, CROP_FACTOR)?
                .write_png(dir.join("reference-horizon.png"))?;
            Some("reference-horizon.png".to_string())
        }
        _ => None,
    };
    Ok((scoring, reference_crop))
}

/// Runs one stage of the job between its progress marks.
fn staged<T>(
    job: &CompareJob,
    stage: Stage,
    work: impl FnOnce() -> Result<T, Error>,
) -> Result<T, Error> {
    if let Some(p) = job.progress {
        p.stage(stage);
    }
    let done = work()?;
    if let Some(p) = job.progress {
        p.done(stage);
    }
    Ok(done)
}

/// Names, on each row, the rows whose images are within the reference's noise of its own.
fn mark_ties(
    rows: &mut [FilterRow],
    images: &[Image8],
    error: &ReferenceError,
    scoring: &Scoring,
) -> Result<(), Error> {
    let refs: Vec<&Image8> = images.iter().collect();
    let ties = error.within_noise(&scoring.reference, &refs, Some(&scoring.coverage))?;
    let names: Vec<String> = rows.iter().map(|r| r.name.clone()).collect();
    for (row, tied) in rows.iter_mut().zip(ties) {
        row.within_noise_of = tied.into_iter().map(|j| names[j].clone()).collect();
    }
    Ok(())
}

/// The report's colour line: the colour handling, and the filtering arithmetic where it is not
/// the exact default.
fn color_label(scene: &PreparedScene) -> String {
    let precision = match scene.precision {
        texel_raster::Precision::Exact => "",
        texel_raster::Precision::Gpu => ", gpu precision",
    };
    format!("{}{precision}", scene.color.name())
}

/// Render the rest of an orbit (frames 1 to `frames - 1`; frame 0 is the comparison's own, its
/// reference in `scoring` and its images in `images`, one per filter) and set each filter row's
/// [`FilterRow::flicker`] ([`excess_change`] averaged over consecutive pairs) and
/// [`FilterRow::psnr_orbit`]. Change is measured over the pixels the reference covers in both
/// frames of a pair.
fn orbit_scores(
    scene: &PreparedScene,
    job: &CompareJob,
    spec: OrbitSpec,
    (scoring, images): (&Scoring, &[Image8]),
    rows: &mut [FilterRow],
    budget: &mut MemoryBudget,
) -> Result<Orbit, Error> {
    let filters = job.filters;
    let enc = scoring.encoding;
    let (w, h) = (scene.width, scene.height);
    let mut prev_ref = scoring.reference.clone();
    let mut prev_cov = scoring.coverage.clone();
    let mut prev = images[..filters.len()].to_vec();
    let mut ref_change = 0.0;
    let mut change = vec![0.0; filters.len()];
    let mut psnr_sum: Vec<f64> = rows.iter().map(|r| r.psnr_all).collect();
    for k in 1..spec.frames {
        let camera = scene.scene.camera.orbited(spec.step_deg * k as f32);
        let stage = Stage::Reference {
            n: k,
            of: spec.frames,
        };
        let reference = staged(job, stage, || reference(scene, job, &camera))?.frame;
        let ref_image = Image8::from_linear(w, h, &reference.color, enc)?;
        let coverage = Mask::new(w, h, reference.coverage())?;
        ref_change += mean_abs_change(&prev_ref, &ref_image, &prev_cov, &coverage)?;
        for (i, &filter) in filters.iter().enumerate() {
            job.stopped()?;
            let frame_plan = scene.plan(Some(filter), budget)?;
            let mut settings = frame_plan.settings_from(&camera);
            settings.threads = job.threads;
            let frame = render(&settings, &frame_plan.draws_from(&camera))?;
            let image = crate::frame_image(&frame, enc)?;
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
    for (i, row) in rows.iter_mut().take(filters.len()).enumerate() {
        row.flicker = Some(change[i] / pairs);
        row.psnr_orbit = Some(psnr_sum[i] / f64::from(spec.frames));
    }
    Ok(Orbit {
        frames: spec.frames,
        step_deg: spec.step_deg,
        reference_flicker: ref_change / pairs,
    })
}

#[cfg(test)]
mod tests {
    use super::{check_labels, slug};
    use texel_texture::Filter;

    #[test]
    fn extra_labels_name_one_row_and_one_file_each() {
        let f = [Filter::Trilinear];
        let msg = |labels: &[&str]| {
            check_labels(labels.iter().copied(), &f)
                .unwrap_err()
                .to_string()
        };
        assert!(check_labels(["gpu", "llvmpipe"], &f).is_ok());
        assert!(msg(&["gpu", "gpu"]).contains("given twice"));
        assert!(msg(&["a b", "a_b"]).contains("extra-a_b.png"));
        // Case-insensitive file systems (macOS, Windows) would merge `gpu` and `GPU`.
        assert!(msg(&["gpu", "GPU"]).contains("extra-GPU.png"));
        assert!(msg(&["trilinear"]).contains("compared filter"));
        assert!(msg(&["a\u{202e}b"]).contains("control or bidirectional"));
    }

    #[test]
    fn slugs() {
        assert_eq!(slug("llvm pipe/1"), "llvm_pipe_1");
        assert_eq!(slug("a-b_C9"), "a-b_C9");
        assert_eq!(slug("é"), "_");
    }
}
