//! texel-lab: the texture-filtering lab, hosted. A student writes the lab's eight modes as a GLSL
//! fragment shader (`uniform sampler2D texSlot; uniform int texMode;`, the coordinate in a varying
//! `texCoord`, texture access through `texelFetch` and `textureSize` only); texel runs it unchanged
//! on OpenGL ([`gl`], through EGL: Mesa's llvmpipe without a GPU), checks the access rule
//! ([`source`]), and grades every mode on every scene against its own mode under the OpenGL rules
//! and under the handout's formulas ([`grading`]), with the supersampled reference beside it.
//!
//! The work is split in two so that a shader that never finishes cannot hang the grader:
//! [`run_device`] renders (the CLI runs it in a child process with a time limit) and writes what
//! it rendered into a folder; [`grade()`] reads that folder and makes the [`LabReport`], which
//! [`LabReport::write`] writes as JSON, Markdown and HTML. docs/guide/lab.md walks a student
//! through it.

pub mod gl;
pub mod grading;
pub mod report;
pub mod scene;
pub mod source;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use texel_prepare::ReferenceRun;
use texel_quality::{Encoding, Image8, Mask};
use texel_raster::ReferencePlan;
use texel_texture::Convention;

pub use gl::{Capture, Gl, GlError, Names};
pub use grading::Verdict;
pub use scene::{LabScene, LAB_SCENES};
pub use source::Violation;

/// The largest shader file [`read_shader`] reads.
const MAX_SHADER_BYTES: u64 = 1 << 20;

/// The text of a shader file: a regular file of at most 1 MiB, UTF-8. `what` names it in the
/// errors ("fragment shader").
///
/// # Errors
/// [`Error::Io`]: the file cannot be read (not a regular file, over 1 MiB, an I/O error), or it is
/// not UTF-8 text.
pub fn read_shader(path: &Path, what: &str) -> Result<String, Error> {
    let bytes = texel_io::read_regular(path, MAX_SHADER_BYTES)
        .map_err(|e| Error::Io(format!("cannot read the {what} {}: {e}", path.display())))?;
    String::from_utf8(bytes).map_err(|e| {
        Error::Io(format!(
            "the {what} {} is not UTF-8 text: {e}",
            path.display()
        ))
    })
}

/// The lab's GLSL solutions and texel's vertex shader, as shipped in `crates/texel-lab/glsl/`.
pub mod solutions {
    /// The eight modes by the OpenGL / Vulkan rules.
    pub const GL: &str = include_str!("../glsl/solution-gl.frag");
    /// The eight modes by the lab handout's formulas.
    pub const LAB: &str = include_str!("../glsl/solution-lab.frag");
}

/// Why the lab failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The GL path failed (no driver, a compile or link error, a missing uniform).
    #[error(transparent)]
    Gl(#[from] GlError),
    /// A scene could not be loaded.
    #[error("{0}")]
    Scene(String),
    /// A scene the lab cannot run.
    #[error("{0}")]
    Unsupported(String),
    /// Reading a shader file, or reading or writing the work folder, failed.
    #[error("{0}")]
    Io(String),
    /// Scoring or writing an image failed.
    #[error(transparent)]
    Quality(#[from] texel_quality::QualityError),
    /// The reference failed.
    #[error("the reference: {0}")]
    Reference(String),
}

/// What to run: the student's shaders, the names of the lab's interface, the scenes and modes.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Job {
    /// The fragment shader's source.
    pub fragment: String,
    /// The vertex shader's source; `None`: texel's own ([`gl::vertex_shader`]).
    pub vertex: Option<String>,
    /// The interface's names.
    pub names: Names,
    /// Scenes: lab scene names ([`LAB_SCENES`]), `builtin:NAME` or scene files.
    pub scenes: Vec<String>,
    /// Modes 1-8 to run.
    pub modes: Vec<u8>,
    /// Timed frames per mode (after one untimed).
    pub frames: usize,
    /// Frame size overriding the scenes'.
    pub size: Option<(u32, u32)>,
}

impl Job {
    /// The default job of `fragment`: every lab scene, all eight modes, five timed frames.
    pub fn new(fragment: String) -> Job {
        Job {
            fragment,
            vertex: None,
            names: Names::default(),
            scenes: LAB_SCENES.iter().map(|s| s.0.to_string()).collect(),
            modes: (1..=8).collect(),
            frames: 5,
            size: None,
        }
    }
}

/// What the device reported.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct DeviceRun {
    /// `GL_RENDERER`.
    pub renderer: String,
    /// `GL_VERSION`.
    pub version: String,
    /// Per scene, the median milliseconds of a frame per mode.
    pub times_ms: Vec<BTreeMap<u8, f64>>,
}

fn io(what: &Path, e: std::io::Error) -> Error {
    Error::Io(format!("{}: {e}", what.display()))
}

fn capture_path(dir: &Path, k: usize) -> PathBuf {
    dir.join(format!("scene-{k}.capture"))
}

fn frame_path(dir: &Path, k: usize, mode: u8) -> PathBuf {
    dir.join(format!("scene-{k}-mode-{mode}.rgba"))
}

/// Render `job` on the device and write what it rendered into `dir` (an existing, empty
/// folder): per scene the capture and one frame per mode, and `device.json`.
///
/// # Errors
/// [`Error::Gl`] (no driver, the shader does not compile or link, a missing uniform),
/// [`Error::Scene`], [`Error::Unsupported`], [`Error::Io`].
pub fn run_device(job: &Job, dir: &Path) -> Result<DeviceRun, Error> {
    let gl = Gl::new()?;
    let (renderer, version) = gl.driver();
    let mut run = DeviceRun {
        renderer,
        version,
        times_ms: Vec::new(),
    };
    for (k, spec) in job.scenes.iter().enumerate() {
        let scene = LabScene::load(spec, job.size)?;
        let prepared = gl.prepare(
            &job.fragment,
            job.vertex.as_deref(),
            &job.names,
            &scene.device_scene(),
        )?;
        let capture = prepared.capture()?;
        let mut raw = Vec::new();
        for p in capture.uv_dx.iter().chain(&capture.dy_draw) {
            raw.extend(p.iter().flat_map(|x| x.to_le_bytes()));
        }
        let path = capture_path(dir, k);
        std::fs::write(&path, raw).map_err(|e| io(&path, e))?;
        let mut times = BTreeMap::new();
        for &mode in &job.modes {
            let (image, ms) = prepared.frame(i32::from(mode), job.frames)?;
            let path = frame_path(dir, k, mode);
            std::fs::write(&path, image.concat()).map_err(|e| io(&path, e))?;
            times.insert(mode, ms);
        }
        run.times_ms.push(times);
    }
    let path = dir.join("device.json");
    let text = serde_json::to_string_pretty(&run).map_err(|e| Error::Io(e.to_string()))?;
    std::fs::write(&path, text).map_err(|e| io(&path, e))?;
    Ok(run)
}

/// The result of one mode on one scene.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ModeResult {
    /// Lab mode 1-8.
    pub mode: u8,
    /// The scene's name.
    pub scene: String,
    /// `gl`, `lab` or `neither`.
    pub verdict: Verdict,
    /// Share of covered pixels within [`grading::AGREE_CODES`] of texel's mode under GL's rules.
    pub agreement_gl: f64,
    /// The same under the lab's formulas.
    pub agreement_lab: f64,
    /// PSNR of the shader's frame against the supersampled reference (dB, covered pixels).
    pub psnr_reference: f64,
    /// PSNR of texel's mode (the convention agreed with, or the closer) against the reference.
    pub psnr_reference_texel: f64,
    /// Likely mistakes for a `neither`, best first.
    pub diagnosis: Vec<String>,
    /// Median milliseconds of a frame on the device.
    pub time_ms: f64,
    /// Texels texel's mode reads a covered pixel.
    pub texels_per_pixel: f64,
    /// Images in the report folder: the shader's, texel's, the error heat map (shader against
    /// texel's), relative to the folder.
    pub images: [String; 3],
}

/// The lab's questions, answered with figures measured on the scenes graded.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Questions {
    /// Per scene: the share of covered pixels magnified (N < 0) and the range of N.
    pub levels: Vec<LevelRange>,
    /// Per scene texture: bytes of level 0 and of the whole pyramid, grey and RGB.
    pub memory: Vec<PyramidMemory>,
    /// Per mode (over all scenes): mean PSNR of the shader on magnified and on minified pixels.
    pub magnification: Vec<(u8, f64, f64)>,
}

/// The level of detail over a scene's covered pixels.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct LevelRange {
    /// Scene.
    pub scene: String,
    /// The scene's reference image in the report folder.
    pub reference_image: String,
    /// The smallest N (the lab's formula, before its clamp at M).
    pub n_min: f64,
    /// The largest N.
    pub n_max: f64,
    /// M, the coarsest level.
    pub m: f64,
    /// Share of covered pixels with N < 0 (magnified).
    pub magnified: f64,
    /// Share of covered pixels whose anisotropy is below 1.5 (one probe with rounding; where
    /// `i / (lambda - 1)` is undefined at exactly 1).
    pub isotropic: f64,
}

/// A texture's pyramid against its level 0.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct PyramidMemory {
    /// Scene.
    pub scene: String,
    /// Width, height.
    pub size: (u32, u32),
    /// Bytes of level 0 with one byte a texel (grey).
    pub grey_level0: u64,
    /// Bytes of every level (grey).
    pub grey_pyramid: u64,
    /// Bytes of level 0 with three bytes a texel (RGB).
    pub rgb_level0: u64,
    /// Bytes of every level (RGB).
    pub rgb_pyramid: u64,
}

/// A rubric part: its weight and the modes it covers.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RubricPart {
    /// What it grades.
    pub part: String,
    /// Weight in percent.
    pub weight: f64,
    /// The modes.
    pub modes: Vec<u8>,
    /// Points earned: the weight times the share of (mode, scene) results with a `gl` or `lab`
    /// verdict.
    pub earned: f64,
}

/// The lab's rubric: nearest and bilinear 30 %, mip bilinear and trilinear 40 %, anisotropic 30 %.
pub const RUBRIC: [(&str, f64, &[u8]); 3] = [
    ("nearest and bilinear", 30.0, &[1, 2]),
    ("bilinear with mipmaps and trilinear", 40.0, &[3, 4]),
    ("anisotropic 2x to 16x", 30.0, &[5, 6, 7, 8]),
];

/// Everything `texel lab` reports.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct LabReport {
    /// The shader's file.
    pub shader: String,
    /// The device: `GL_RENDERER`.
    pub renderer: String,
    /// `GL_VERSION`.
    pub gl_version: String,
    /// Calls of texture built-ins the lab forbids, with their lines.
    pub rule_violations: Vec<Violation>,
    /// Lines with a comment, and lines of code.
    pub comment_lines: (usize, usize),
    /// Lines that ask `textureSize` for a level other than 0 ([`source::level_size_queries`]):
    /// on Mesa's llvmpipe those sizes are wrong where a quad's pixels read different levels.
    pub level_size_queries: Vec<usize>,
    /// The agreement measure: codes per channel, and the share needed.
    pub agreement_measure: (u8, f64),
    /// Every mode on every scene.
    pub modes: Vec<ModeResult>,
    /// The rubric.
    pub rubric: Vec<RubricPart>,
    /// The summary score, 0-100: the rubric's weights over the modes' verdicts.
    pub score: f64,
    /// The lab's questions.
    pub questions: Questions,
    /// The reference's samples a pixel.
    pub reference_spp: u32,
}

/// How [`grade()`] scores.
#[derive(Clone, Copy, Debug)]
pub struct GradeOptions {
    /// Samples a pixel of the reference.
    pub reference_spp: u32,
    /// Worker threads (`None`: all cores).
    pub threads: Option<usize>,
}

impl Default for GradeOptions {
    fn default() -> Self {
        GradeOptions {
            reference_spp: 256,
            threads: None,
        }
    }
}

/// The images a report shows, by file name relative to the report folder.
pub type Images = Vec<(String, Image8)>;

fn read_capture(path: &Path, n: usize) -> Result<Capture, Error> {
    let raw = std::fs::read(path).map_err(|e| io(path, e))?;
    if raw.len() != n * 32 {
        return Err(Error::Io(format!("{}: truncated", path.display())));
    }
    let px: Vec<[f32; 4]> = raw
        .chunks_exact(16)
        .map(|c| {
            let f =
                |k: usize| f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]]);
            [f(0), f(1), f(2), f(3)]
        })
        .collect();
    let (a, b) = px.split_at(n);
    Ok(Capture {
        uv_dx: a.to_vec(),
        dy_draw: b.to_vec(),
    })
}

fn read_frame(path: &Path, n: usize) -> Result<Vec<[u8; 4]>, Error> {
    let raw = std::fs::read(path).map_err(|e| io(path, e))?;
    if raw.len() != n * 4 {
        return Err(Error::Io(format!("{}: truncated", path.display())));
    }
    Ok(raw
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect())
}

/// Grade what [`run_device`] wrote into `dir` for `job` (`shader` names the fragment shader in
/// the report): the report and the images it shows.
///
/// # Errors
/// [`Error::Scene`], [`Error::Io`] for a missing or truncated device output,
/// [`Error::Reference`], [`Error::Quality`].
pub fn grade(
    job: &Job,
    shader: &str,
    dir: &Path,
    options: &GradeOptions,
) -> Result<(LabReport, Images), Error> {
    let device = read_device(dir)?;
    let mut images: Images = Vec::new();
    let mut modes = Vec::new();
    let mut questions = Questions::default();
    let mut mag = Magnification::new();
    for (k, spec) in job.scenes.iter().enumerate() {
        let scene = LabScene::load(spec, job.size)?;
        let file_stem = file_stem(k, &scene.name);
        let (w, h) = scene.size();
        let n = (w as usize) * (h as usize);
        let capture = read_capture(&capture_path(dir, k), n)?;
        let mask = grading::covered(&capture);
        let (reference, ref_covered) = reference(&scene, options)?;
        let ref_mask: Vec<bool> = mask
            .iter()
            .zip(&ref_covered)
            .map(|(a, b)| *a && *b)
            .collect();
        let ref_name = format!("images/{file_stem}-reference.png");
        images.push((ref_name.clone(), reference.clone()));
        let mut levels = level_range(&scene, &capture, &mask);
        levels.0.reference_image = ref_name;
        questions.levels.push(levels.0);
        questions.memory.push(memory(&scene));
        let graded = GradedScene {
            scene: &scene,
            capture: &capture,
            ref_mask: Mask::new(w, h, ref_mask)?,
            mask,
            reference,
            magnified: levels.1,
            file_stem,
        };
        for &mode in &job.modes {
            let shader_px = read_frame(&frame_path(dir, k, mode), n)?;
            let time_ms = device
                .times_ms
                .get(k)
                .and_then(|t| t.get(&mode))
                .copied()
                .unwrap_or(f64::NAN);
            let result = graded.mode(mode, shader_px, time_ms, &mut mag, &mut images)?;
            modes.push(result);
        }
    }
    rank_across_scenes(&mut modes);
    let scenes = job.scenes.len().max(1) as f64;
    questions.magnification = mag
        .into_iter()
        .map(|(m, (a, b, n))| (m, a / scenes, b / (n.max(1) as f64)))
        .collect();
    let rubric = rubric(&modes);
    let score = rubric.iter().map(|r| r.earned).sum();
    Ok((
        LabReport {
            shader: shader.to_string(),
            renderer: device.renderer,
            gl_version: device.version,
            rule_violations: source::violations(&job.fragment),
            comment_lines: source::comment_lines(&job.fragment),
            level_size_queries: source::level_size_queries(&job.fragment),
            agreement_measure: (grading::AGREE_CODES, grading::AGREE_SHARE),
            modes,
            rubric,
            score,
            questions,
            reference_spp: options.reference_spp,
        },
        images,
    ))
}

/// Per mode, the sums of the shader's PSNR over each scene's magnified pixels and over its
/// minified ones, and the number of scenes that have minified pixels.
type Magnification = BTreeMap<u8, (f64, f64, usize)>;

/// The device run's record, `device.json`, as the capture step writes it.
fn read_device(dir: &Path) -> Result<DeviceRun, Error> {
    let path = dir.join("device.json");
    let text = std::fs::read_to_string(&path).map_err(|e| io(&path, e))?;
    serde_json::from_str(&text).map_err(|e| Error::Io(format!("{}: {e}", path.display())))
}

/// File names from the scene's name: letters, digits and `-` only, and the scene's position, so
/// that two scenes of one name keep their own images.
fn file_stem(k: usize, name: &str) -> String {
    let safe: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{k}-{safe}")
}

/// The rubric's parts, each earning its weight times the share of its modes' results that match
/// a convention.
fn rubric(modes: &[ModeResult]) -> Vec<RubricPart> {
    RUBRIC
        .iter()
        .map(|(part, weight, ms)| {
            let rows: Vec<&ModeResult> = modes.iter().filter(|r| ms.contains(&r.mode)).collect();
            let good = rows
                .iter()
                .filter(|r| r.verdict != Verdict::Neither)
                .count();
            RubricPart {
                part: part.to_string(),
                weight: *weight,
                modes: ms.to_vec(),
                earned: if rows.is_empty() {
                    0.0
                } else {
                    weight * good as f64 / rows.len() as f64
                },
            }
        })
        .collect()
}

/// One scene's capture and reference, against which each mode's frame is graded.
struct GradedScene<'a> {
    scene: &'a LabScene,
    capture: &'a Capture,
    /// The pixels the scene covers.
    mask: Vec<bool>,
    /// The reference image.
    reference: Image8,
    /// The covered pixels the reference covers too.
    ref_mask: Mask,
    /// Whether each pixel is magnified (its level of detail below 0).
    magnified: Vec<bool>,
    file_stem: String,
}

impl GradedScene<'_> {
    /// One mode's result for the student's frame `shader_px`, its images added to `images` and
    /// its magnified and minified PSNR to `mag`.
    fn mode(
        &self,
        mode: u8,
        shader_px: Vec<[u8; 4]>,
        time_ms: f64,
        mag: &mut Magnification,
        images: &mut Images,
    ) -> Result<ModeResult, Error> {
        let (scene, capture, mask) = (self.scene, self.capture, &self.mask[..]);
        let (w, h) = scene.size();
        let gl = grading::convention_match(scene, capture, mode, Convention::Gl, &shader_px, mask);
        let lab =
            grading::convention_match(scene, capture, mode, Convention::Lab, &shader_px, mask);
        let verdict = grading::verdict(gl.agreement, lab.agreement);
        let diagnosis = if verdict == Verdict::Neither {
            grading::diagnose(scene, capture, mode, &shader_px, mask, (&gl, &lab))
        } else {
            Vec::new()
        };
        let closer = if lab.agreement > gl.agreement {
            &lab
        } else {
            &gl
        };
        let shader_img = Image8::new(w, h, shader_px)?;
        let texel_img = Image8::new(w, h, closer.image.clone())?;
        let psnr_reference =
            texel_quality::psnr(&self.reference, &shader_img, Some(&self.ref_mask))?;
        let psnr_reference_texel =
            texel_quality::psnr(&self.reference, &texel_img, Some(&self.ref_mask))?;
        let mask_img = Mask::new(w, h, mask.to_vec())?;
        let heat = texel_quality::heat_map(&texel_img, &shader_img, Some(&mask_img), 32.0)?;
        self.add_magnification(mode, &shader_img, mag)?;
        let stem = format!("images/{}-mode{mode}", self.file_stem);
        let names = [
            format!("{stem}-shader.png"),
            format!("{stem}-texel.png"),
            format!("{stem}-heat.png"),
        ];
        images.push((names[0].clone(), shader_img));
        images.push((names[1].clone(), texel_img));
        images.push((names[2].clone(), heat));
        let covered = mask.iter().filter(|c| **c).count().max(1);
        Ok(ModeResult {
            mode,
            scene: scene.name.clone(),
            verdict,
            agreement_gl: gl.agreement,
            agreement_lab: lab.agreement,
            psnr_reference,
            psnr_reference_texel,
            diagnosis,
            time_ms,
            texels_per_pixel: closer.reads as f64 / covered as f64,
            images: names,
        })
    }

    /// Adds the shader's PSNR over the magnified and over the minified covered pixels, where
    /// there are any, to `mag`.
    fn add_magnification(
        &self,
        mode: u8,
        shader_img: &Image8,
        mag: &mut Magnification,
    ) -> Result<(), Error> {
        let (w, h) = self.scene.size();
        for (part, magnified_part) in [(0, true), (1, false)] {
            let m: Vec<bool> = self
                .mask
                .iter()
                .zip(&self.magnified)
                .map(|(c, g)| *c && *g == magnified_part)
                .collect();
            if m.iter().any(|x| *x) {
                let p =
                    texel_quality::psnr(&self.reference, shader_img, Some(&Mask::new(w, h, m)?))?;
                let e = mag.entry(mode).or_insert((0.0, 0.0, 0));
                if part == 0 {
                    e.0 += p.min(99.0);
                } else {
                    e.1 += p.min(99.0);
                    e.2 += 1;
                }
            }
        }
        Ok(())
    }
}

/// A diagnosis without its figures: the same mistake on two scenes has the same key.
fn diagnosis_key(d: &str) -> String {
    d.split(" agree")
        .next()
        .unwrap_or(d)
        .chars()
        .filter(|c| !c.is_ascii_digit() && *c != '.' && *c != '%')
        .collect()
}

/// Put first, on every scene of a mode, the mistake that explains the most of that mode's
/// failing scenes (a scene can be explained by two mistakes at once where its footprints make
/// them coincide, as a constant level does for a level rule and a texel offset).
fn rank_across_scenes(modes: &mut [ModeResult]) {
    for mode in 1..=8u8 {
        let mut count: BTreeMap<String, usize> = BTreeMap::new();
        for r in modes.iter().filter(|r| r.mode == mode) {
            for d in &r.diagnosis {
                *count.entry(diagnosis_key(d)).or_default() += 1;
            }
        }
        for r in modes.iter_mut().filter(|r| r.mode == mode) {
            // Stable: equal counts keep their order (best agreement first).
            r.diagnosis.sort_by_key(|d| {
                std::cmp::Reverse(count.get(&diagnosis_key(d)).copied().unwrap_or(0))
            });
        }
    }
}

/// The scene's reference (raw colour) and its coverage.
fn reference(scene: &LabScene, options: &GradeOptions) -> Result<(Image8, Vec<bool>), Error> {
    let spp = options.reference_spp;
    let plan =
        ReferencePlan::new(spp, spp, 0.5, false, 1).map_err(|e| Error::Reference(e.to_string()))?;
    let run = ReferenceRun {
        plan,
        threads: options.threads,
        scissor: None,
        progress: None,
        stop: None,
    };
    let est = scene
        .prepared
        .reference(&scene.prepared.scene.camera, &run)
        .map_err(|e| Error::Reference(e.to_string()))?;
    let (w, h) = scene.size();
    let image = Image8::from_linear(w, h, &est.frame.color, Encoding::Linear)?;
    Ok((image, est.frame.coverage()))
}

/// The lab's N over the covered pixels, and which pixels are magnified.
fn level_range(scene: &LabScene, capture: &Capture, mask: &[bool]) -> (LevelRange, Vec<bool>) {
    let draws = scene.draws();
    let mut r = LevelRange {
        scene: scene.name.clone(),
        n_min: f64::INFINITY,
        n_max: f64::NEG_INFINITY,
        ..Default::default()
    };
    let (mut n, mut mag, mut iso) = (0usize, 0usize, 0usize);
    let mut magnified = vec![false; mask.len()];
    for (i, ((a, b), &m)) in capture
        .uv_dx
        .iter()
        .zip(&capture.dy_draw)
        .zip(mask)
        .enumerate()
    {
        let Some(d) = (b[2].round() as usize)
            .checked_sub(1)
            .and_then(|k| draws.get(k))
        else {
            continue;
        };
        if !m {
            continue;
        }
        let side = d.texture.width().max(d.texture.height()) as f64;
        let px = f64::from(a[2]).hypot(f64::from(a[3]));
        let py = f64::from(b[0]).hypot(f64::from(b[1]));
        let big = side.log2();
        let level = big + px.max(py).log2();
        if level.is_finite() {
            r.n_min = r.n_min.min(level);
            r.n_max = r.n_max.max(level);
        }
        r.m = big;
        n += 1;
        if level < 0.0 {
            mag += 1;
            magnified[i] = true;
        }
        if px.max(py) < 1.5 * px.min(py) {
            iso += 1;
        }
    }
    let n = n.max(1) as f64;
    r.magnified = mag as f64 / n;
    r.isotropic = iso as f64 / n;
    (r, magnified)
}

fn memory(scene: &LabScene) -> PyramidMemory {
    let draws = scene.draws();
    let Some(d) = draws.first() else {
        return PyramidMemory::default();
    };
    let t = d.texture;
    let level0 = u64::from(t.width()) * u64::from(t.height());
    let all: u64 = t
        .levels()
        .iter()
        .map(|l| u64::from(l.width) * u64::from(l.height))
        .sum();
    PyramidMemory {
        scene: scene.name.clone(),
        size: (t.width(), t.height()),
        grey_level0: level0,
        grey_pyramid: all,
        rgb_level0: 3 * level0,
        rgb_pyramid: 3 * all,
    }
}
