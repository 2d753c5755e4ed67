//! The viewer's render thread: it renders the newest request continuously, away from the window's
//! event loop, so input is handled every frame however slow the filter.
//!
//! - **One frame** renders each half (or the whole screen) through a scissor rectangle
//!   ([`texel::raster::RenderSettings::scissor`]), so a split screen costs one frame, and each half
//!   is bit for bit what `texel render` gives that filter.
//! - **Never freeze**: while the camera moves, a frame whose measured cost (ms per pixel, per
//!   mode) would exceed [`BUDGET_MS`] is rendered at 1/s resolution (`s` up to 8) and shown
//!   enlarged; when the camera stops, it is rendered at full resolution in bands of rows of
//!   about [`BUDGET_MS`] each, abandoned between bands as soon as a newer request arrives.
//! - **The reference** (mode 0) accumulates passes of 2 x 2 stratified jittered level-0 samples
//!   per pixel (`render_reference_strata` with a new seed per pass) while nothing changes, up to
//!   [`MAX_REFERENCE_SAMPLES`], then stops; any change restarts it. While moving it shows one
//!   sample per pixel.
//! - **Statistics** for the HUD (mean texels per covered pixel, lod range) come from one extra
//!   full-resolution pass with texel counting and footprints, once the camera is still, so they
//!   never slow the frames timed.

use std::collections::HashMap;
use std::sync::{Arc, Condvar, Mutex};
use std::time::Instant;

use anyhow::{Context, Result};
use rayon::prelude::*;
use texel::lab::{Gl, GlScene, Names, ShaderDraws};
use texel::quality::Encoding;
use texel::raster::{
    draw_into, render_reference_strata, ColorTarget, DrawCall, Frame, ProgressiveReference,
    ReferencePlan, RenderSettings, View,
};
use texel::scene::Camera;
use texel::{Filter, FrameOptions, PreparedScene, Sampler, SamplerDescriptor};
use texel_gpu::{Gpu, GpuDraws, GpuFilter};

use crate::controls::{Mode, ViewState};

/// Time one frame (or one band of rows) should take, milliseconds.
pub(crate) const BUDGET_MS: f64 = 40.0;

/// Samples per pixel at which the reference stops refining.
pub(crate) const MAX_REFERENCE_SAMPLES: u32 = 512;

/// Largest reduction of resolution while moving.
const MAX_SCALE: u32 = 8;

/// What the window asks the render thread for.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Request {
    /// Increases with every request.
    pub generation: u64,
    /// Filters, view and modes.
    pub state: ViewState,
    /// The camera.
    pub camera: Camera,
    /// The window's size in pixels.
    pub width: u32,
    /// The window's size in pixels.
    pub height: u32,
    /// The camera is moving: keep frames within the budget, do not accumulate.
    pub moving: bool,
}

impl Request {
    /// Whether two requests give the same image (the HUD, help and the moving flag aside).
    pub(crate) fn same_image(&self, other: &Request) -> bool {
        let strip = |s: &ViewState| ViewState {
            hud: false,
            help: false,
            ..s.clone()
        };
        strip(&self.state) == strip(&other.state)
            && self.camera == other.camera
            && (self.width, self.height) == (other.width, other.height)
    }
}

/// The mailbox between the window and the render thread: the newest request wins.
#[derive(Default)]
pub(crate) struct Shared {
    slot: Mutex<Slot>,
    wake: Condvar,
}

#[derive(Default)]
struct Slot {
    request: Option<Request>,
    newest: u64,
    quit: bool,
}

impl Shared {
    /// Hand the render thread a new request (replacing one it has not started).
    pub(crate) fn submit(&self, request: Request) {
        let mut slot = self.slot.lock().unwrap_or_else(|e| e.into_inner());
        slot.newest = request.generation;
        slot.request = Some(request);
        self.wake.notify_all();
    }

    /// Ask the render thread to stop.
    pub(crate) fn quit(&self) {
        self.slot.lock().unwrap_or_else(|e| e.into_inner()).quit = true;
        self.wake.notify_all();
    }

    /// Whether a request newer than `generation` (or quitting) is waiting.
    fn superseded(&self, generation: u64) -> bool {
        let slot = self.slot.lock().unwrap_or_else(|e| e.into_inner());
        slot.quit || slot.newest > generation
    }

    /// The next request: a new one if there is one, else `current` again unless `idle`, else
    /// wait. `None` when quitting.
    fn next(&self, current: Option<Request>, idle: bool) -> Option<Request> {
        let mut slot = self.slot.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if slot.quit {
                return None;
            }
            if let Some(r) = slot.request.take() {
                return Some(r);
            }
            if let (Some(c), false) = (&current, idle) {
                return Some(c.clone());
            }
            slot = self.wake.wait(slot).unwrap_or_else(|e| e.into_inner());
        }
    }
}

/// What the HUD says about one half of the screen.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct PartInfo {
    /// The mode shown.
    pub mode: Mode,
    /// `"gpu"` when texel-gpu rendered it, `"cpu"` otherwise.
    pub backend: &'static str,
    /// Reference samples per pixel accumulated so far.
    pub samples: Option<u32>,
    /// For a still reference of at least two passes: the share of its pixels whose displayed
    /// value's 95 % interval, from the spread of the passes, is within half an 8-bit step
    /// ([`texel::raster::display_half_width`]).
    pub within: Option<f64>,
    /// Mean texels read per covered pixel and the lod range (min, max) over covered pixels,
    /// once measured for this image.
    pub stats: Option<Stats>,
}

/// Measured texel reads and lods of one half.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Stats {
    /// Mean texels read per covered pixel.
    pub texels_mean: f64,
    /// Smallest and largest lod over covered pixels (see [`lod_range`]).
    pub lod: Option<(f32, f32)>,
}

/// One frame for the window.
pub(crate) struct Rendered {
    /// The request's generation.
    pub generation: u64,
    /// Window-sized `0x00RRGGBB` pixels.
    pub pixels: Vec<u32>,
    /// Width of `pixels`.
    pub width: u32,
    /// Height of `pixels`.
    pub height: u32,
    /// Milliseconds the frame took to render (not counting encoding for display).
    pub ms: f64,
    /// Resolution divisor (1: full resolution).
    pub scale: u32,
    /// Per half.
    pub parts: Vec<PartInfo>,
    /// An error to show instead of a new image (the pixels are then empty).
    pub error: Option<String>,
    /// A message to show beside the image (a student's shader that no longer compiles while the
    /// last good one keeps running).
    pub notice: Option<String>,
}

/// What the render thread owns.
pub(crate) struct Worker {
    /// The scene for the other colour handling, and the memory account.
    pub source: Box<dyn crate::SceneSource>,
    /// The scene as loaded for each colour handling (index: `texel::ColorHandling as usize`).
    pub scenes: [Option<PreparedScene>; 2],
    /// Worker threads; `None`: all cores.
    pub threads: Option<u32>,
    /// The device of the GPU modes.
    pub gpu: Option<Gpu>,
    /// The student's fragment shader, drawn on OpenGL in the left half.
    pub shader: Option<std::path::PathBuf>,
}

/// The student's shader: an OpenGL thread of its own (a context is current on one thread, and
/// the frame may be rendered on a pool's), whether it holds a built program, the file's
/// modification time it was built from, and the last compile error while an older build keeps
/// running.
#[derive(Default)]
struct ShaderState {
    thread: Option<ShaderThread>,
    built: bool,
    modified: Option<std::time::SystemTime>,
    notice: Option<String>,
    /// The file's modification time when a frame of it took longer than [`SHADER_FRAME_LIMIT`]:
    /// its thread is left behind, and no new one starts until the file changes.
    stuck: Option<Option<std::time::SystemTime>>,
}

/// The longest a frame of the student's shader may take before the viewer gives up on it.
const SHADER_FRAME_LIMIT: std::time::Duration = std::time::Duration::from_secs(10);

/// The student's shader (`--shader`) drawn in lab mode `mode` over `draws` at `size`, top row
/// first. The file is read again when its modification time changes; a version that does not
/// compile leaves the last good one running and its error in `ShaderState::notice`.
fn shader_frame(
    state: &mut ShaderState,
    path: Option<&std::path::Path>,
    draws: &[DrawCall],
    settings: &RenderSettings,
    clip: glam::Mat4,
    size: (u32, u32),
    mode: i32,
) -> Result<Vec<[u8; 4]>> {
    let path = path.context("no --shader")?;
    let modified = std::fs::metadata(path).and_then(|m| m.modified()).ok();
    if let Some(when) = state.stuck {
        if when == modified {
            anyhow::bail!(
                "{}: a frame took longer than {} s and the shader was stopped; save a new version to try again",
                path.display(),
                SHADER_FRAME_LIMIT.as_secs()
            );
        }
        state.stuck = None;
    }
    if state.thread.is_none() {
        state.thread = Some(ShaderThread::start().map_err(|e| anyhow::anyhow!(e))?);
        state.built = false;
    }
    // A job's answer, or `Err(())` when the thread did not answer in time.
    let ask = |state: &ShaderState, job: ShaderJob| match &state.thread {
        Some(t) => t.run(job),
        None => Ok(Err("no OpenGL thread".to_string())),
    };
    if !state.built || modified != state.modified {
        state.modified = modified;
        let bg = settings
            .background
            .map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        let scene = texel::lab::device_scene(draws, size, bg, clip.to_cols_array());
        let source = texel::lab::read_shader(path, "shader").map_err(anyhow::Error::from);
        let built = match source {
            Ok(source) => match ask(state, ShaderJob::Build(source, scene)) {
                Ok(r) => r.map_err(|e| anyhow::anyhow!("{}: {e}", path.display())),
                Err(()) => return Err(stuck(state, modified, path)),
            },
            Err(e) => Err(e),
        };
        match built {
            Ok(_) => {
                state.built = true;
                state.notice = None;
            }
            Err(e) if state.built => {
                state.notice = Some(format!(
                    "{} (the last good shader keeps running)",
                    texel_io::chain_line(e.as_ref())
                ));
            }
            Err(e) => return Err(e),
        }
    }
    match ask(state, ShaderJob::Frame(size, clip.to_cols_array(), mode)) {
        Ok(r) => r
            .map_err(|e| anyhow::anyhow!(e))?
            .context("the OpenGL thread returned no frame"),
        Err(()) => Err(stuck(state, modified, path)),
    }
}

/// Give up on a shader thread that did not answer: leave it behind, remember the file's time.
fn stuck(
    state: &mut ShaderState,
    when: Option<std::time::SystemTime>,
    path: &std::path::Path,
) -> anyhow::Error {
    if let Some(t) = state.thread.take() {
        t.abandon();
    }
    state.stuck = Some(when);
    state.built = false;
    anyhow::anyhow!(
        "{}: a frame took longer than {} s and the shader was stopped; save a new version to try again",
        path.display(),
        SHADER_FRAME_LIMIT.as_secs()
    )
}

/// Work for the shader's OpenGL thread.
enum ShaderJob {
    /// Compile and link this source over this scene; an error keeps the last program.
    Build(String, GlScene),
    /// One frame at this size, seen through this `clip_from_world`, in this mode.
    Frame((u32, u32), [f32; 4 * 4], i32),
}

/// The OpenGL thread's two channels: jobs in, results out (a frame's pixels, or `None` for a
/// build).
struct ShaderThread {
    jobs: Option<std::sync::mpsc::Sender<ShaderJob>>,
    results: std::sync::mpsc::Receiver<Result<Option<Vec<[u8; 4]>>, String>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Drop for ShaderThread {
    /// Close the job channel and wait for the thread, so that its context is destroyed before
    /// the process exits (Mesa aborts at exit with a context still current on a live thread).
    fn drop(&mut self) {
        self.jobs = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl ShaderThread {
    /// Start the thread with its OpenGL context.
    fn start() -> Result<ShaderThread, String> {
        use std::sync::mpsc::channel;
        let (jobs, job_rx) = channel::<ShaderJob>();
        let (result_tx, results) = channel();
        let (ready_tx, ready) = channel();
        let thread = std::thread::Builder::new()
            .name("texel-view-glsl".into())
            .spawn(move || {
                let gl = match Gl::new() {
                    Ok(g) => g,
                    Err(e) => {
                        let _ = ready_tx.send(Err(e.to_string()));
                        return;
                    }
                };
                let _ = ready_tx.send(Ok(()));
                let mut prepared: Option<ShaderDraws<'_>> = None;
                for job in job_rx {
                    let out = match job {
                        ShaderJob::Build(source, scene) => {
                            match gl.prepare(&source, None, &Names::default(), &scene) {
                                Ok(s) => {
                                    prepared = Some(s);
                                    Ok(None)
                                }
                                Err(e) => Err(e.to_string()),
                            }
                        }
                        ShaderJob::Frame(size, clip, mode) => match prepared.as_mut() {
                            Some(s) => s
                                .resize(size.0, size.1)
                                .and_then(|()| {
                                    s.set_clip_from_world(clip);
                                    s.draw_frame(mode)
                                })
                                .map(Some)
                                .map_err(|e| e.to_string()),
                            None => Err("no shader is built".into()),
                        },
                    };
                    if result_tx.send(out).is_err() {
                        break;
                    }
                }
            })
            .map_err(|e| e.to_string())?;
        ready
            .recv()
            .map_err(|_| "the OpenGL thread ended".to_string())??;
        Ok(ShaderThread {
            jobs: Some(jobs),
            results,
            thread: Some(thread),
        })
    }

    /// Run `job` and wait for its result, at most [`SHADER_FRAME_LIMIT`]; `Ok(Err(..))` is the
    /// job's own error, `Err(())` a thread that did not answer in time.
    #[allow(clippy::type_complexity)]
    fn run(&self, job: ShaderJob) -> Result<Result<Option<Vec<[u8; 4]>>, String>, ()> {
        let ended = || Ok(Err("the OpenGL thread ended".to_string()));
        let Some(jobs) = self.jobs.as_ref() else {
            return ended();
        };
        if jobs.send(job).is_err() {
            return ended();
        }
        match self.results.recv_timeout(SHADER_FRAME_LIMIT) {
            Ok(r) => Ok(r),
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => Err(()),
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => ended(),
        }
    }

    /// Leave the thread running without waiting for it (a shader that never finishes).
    fn abandon(mut self) {
        self.jobs = None;
        self.thread = None;
    }
}

/// Per-image state kept between frames.
#[derive(Default)]
struct Progress {
    /// The request the accumulation and statistics belong to.
    image: Option<Request>,
    /// The reference's passes so far, per pixel.
    reference: ProgressiveReference,
    /// Samples per pixel so far.
    samples: u32,
    passes: u64,
    stats: Option<Vec<Option<Stats>>>,
    /// One full-resolution frame of this image was shown (statistics wait for the second).
    first_done: bool,
}

type SamplerKey = (Filter, u32, usize);

/// Run the render thread until [`Shared::quit`] or until `send` reports the window gone.
pub(crate) fn run(mut worker: Worker, shared: Arc<Shared>, send: impl Fn(Rendered) -> bool) {
    let pool = match worker.threads {
        Some(n) => match rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build()
        {
            Ok(p) => Some(p),
            Err(e) => {
                send(error_frame(0, &format!("cannot start worker threads: {e}")));
                return;
            }
        },
        None => None,
    };
    let gpu = worker.gpu.take();
    let mut shader = ShaderState::default();
    if worker.shader.is_some() {
        match ShaderThread::start() {
            Ok(t) => shader.thread = Some(t),
            Err(e) => {
                send(error_frame(0, &e));
                return;
            }
        }
    }
    let polling = shader.thread.is_some();
    let mut gpu_draws: HashMap<SamplerKey, GpuDraws<'_>> = HashMap::new();
    let mut samplers: HashMap<SamplerKey, Vec<Sampler>> = HashMap::new();
    let mut costs: HashMap<(Mode, View, bool), f64> = HashMap::new();
    let mut progress = Progress::default();
    let mut frame: Option<Frame> = None;
    let mut current: Option<Request> = None;
    let mut idle = false;
    while let Some(req) = shared.next(current.take(), idle) {
        let mut ctx = FrameContext {
            worker: &mut worker,
            gpu: gpu.as_ref(),
            gpu_draws: &mut gpu_draws,
            shader: &mut shader,
            samplers: &mut samplers,
            costs: &mut costs,
            progress: &mut progress,
            frame: &mut frame,
            shared: &shared,
        };
        let result = match &pool {
            Some(p) => p.install(|| ctx.render(&req)),
            None => ctx.render(&req),
        };
        idle = false;
        let out = match result {
            Ok(Some(r)) => {
                // A finished reference (every half one, at full resolution) stops; every other
                // image is rendered again and again.
                idle = r.scale == 1
                    && r.parts
                        .iter()
                        .all(|p| p.samples.is_some_and(|s| s >= MAX_REFERENCE_SAMPLES));
                r
            }
            Ok(None) => {
                current = Some(req);
                continue;
            }
            Err(e) => {
                // A student's shader is polled for a fixed file: keep trying.
                idle = !polling;
                if !idle {
                    std::thread::sleep(std::time::Duration::from_millis(200));
                }
                error_frame(req.generation, &texel_io::chain_line(e.as_ref()))
            }
        };
        if !send(out) {
            break;
        }
        current = Some(req);
    }
}

fn error_frame(generation: u64, message: &str) -> Rendered {
    Rendered {
        generation,
        pixels: Vec::new(),
        width: 0,
        height: 0,
        ms: 0.0,
        scale: 1,
        parts: Vec::new(),
        error: Some(message.to_string()),
        notice: None,
    }
}

struct FrameContext<'a, 'g> {
    worker: &'a mut Worker,
    gpu: Option<&'g Gpu>,
    gpu_draws: &'a mut HashMap<SamplerKey, GpuDraws<'g>>,
    shader: &'a mut ShaderState,
    samplers: &'a mut HashMap<SamplerKey, Vec<Sampler>>,
    costs: &'a mut HashMap<(Mode, View, bool), f64>,
    progress: &'a mut Progress,
    frame: &'a mut Option<Frame>,
    shared: &'a Shared,
}

/// The draws of the scene loaded for `key`'s colour handling with `key`'s samplers (built by
/// `FrameContext::samplers`), seen through `clip` (the fly camera).
fn camera_draws<'a>(
    scenes: &'a [Option<PreparedScene>; 2],
    samplers: &'a HashMap<SamplerKey, Vec<Sampler>>,
    key: SamplerKey,
    clip: glam::Mat4,
) -> Vec<DrawCall<'a>> {
    let scene = scenes[key.2].as_ref().expect("loaded with its samplers");
    let mut draws = scene.draws(&samplers[&key]);
    for d in &mut draws {
        d.clip_from_world = clip;
    }
    draws
}

/// `settings` with the environment of the scene loaded for `key` (if it has one) read through
/// `key`'s samplers and seen through `clip`.
fn with_environment<'a>(
    settings: &RenderSettings,
    scenes: &'a [Option<PreparedScene>; 2],
    samplers: &'a HashMap<SamplerKey, Vec<Sampler>>,
    key: SamplerKey,
    clip: glam::Mat4,
) -> RenderSettings<'a> {
    let scene = scenes[key.2].as_ref().expect("loaded with its samplers");
    RenderSettings {
        environment: scene.environment_through(&samplers[&key], clip),
        ..*settings
    }
}

/// The pixel rectangles `[x0, y0, x1, y1]` of the modes on screen at `w x h`.
pub(crate) fn part_rects(state: &ViewState, w: u32, h: u32) -> Vec<[u32; 4]> {
    if state.split && w >= 2 {
        let d = ((state.divider * w as f32).round() as u32).clamp(1, w - 1);
        vec![[0, 0, d, h], [d, 0, w, h]]
    } else {
        vec![[0, 0, w, h]]
    }
}

/// One mode's share of a frame ([`FrameContext::draw_part`]).
struct Part {
    mode: Mode,
    /// Its pixels `[x0, y0, x1, y1]`.
    rect: [u32; 4],
    /// Drawn by the GPU path.
    gpu: bool,
    /// Drawn by the student's shader (`--shader`) on OpenGL.
    shader: bool,
    /// The fly camera's `clip_from_world`.
    clip: glam::Mat4,
}

/// The reference's stratified samples per pixel in one pass: 1 x 1 while moving, else 2 x 2.
fn reference_spp(req: &Request) -> [u32; 2] {
    if req.moving {
        [1, 1]
    } else {
        [2, 2]
    }
}

/// The scene's settings for a `w x h` frame of `state`'s view, perspective and derivatives, on
/// every thread: into linear floats with `float` (the reference's passes accumulate them), else
/// into the 8-bit target the window shows, as `texel render` draws it.
fn view_settings(
    scene: &PreparedScene,
    state: &ViewState,
    w: u32,
    h: u32,
    float: bool,
) -> RenderSettings<'static> {
    let mut settings = scene.settings();
    settings.width = w;
    settings.height = h;
    let options = FrameOptions {
        view: state.view,
        derivatives: state.derivatives,
        perspective: state.perspective,
        float,
        threads: None,
    };
    options.apply(&mut settings, scene.color);
    settings
}

impl FrameContext<'_, '_> {
    fn scene(&mut self, color: texel::ColorHandling) -> Result<&PreparedScene> {
        let w = &mut *self.worker;
        let slot = color as usize;
        if w.scenes[slot].is_none() {
            let s = w
                .source
                .load(color)
                .context("cannot load the scene for the other colour handling")?;
            w.scenes[slot] = Some(s);
        }
        Ok(w.scenes[slot].as_ref().expect("loaded above"))
    }

    /// Samplers of `filter` with the lod bias, built (and their structures) once.
    fn samplers(&mut self, filter: Filter, state: &ViewState) -> Result<SamplerKey> {
        let key = (filter, state.lod_bias.to_bits(), state.color as usize);
        if !self.samplers.contains_key(&key) {
            let scene = self.scene(state.color)?;
            let list = scene
                .samplers(filter)?
                .iter()
                .map(|s| {
                    Sampler::new(SamplerDescriptor {
                        lod_bias: state.lod_bias,
                        ..*s.descriptor()
                    })
                })
                .collect::<Result<Vec<_>, _>>()?;
            let w = &mut *self.worker;
            let scene = w.scenes[state.color as usize].as_ref().expect("loaded");
            scene.build_structures_within(&list, w.source.budget())?;
            self.samplers.insert(key, list);
        }
        Ok(key)
    }

    /// Render one frame of `req`; `None` when a newer request superseded it mid-way.
    fn render(&mut self, req: &Request) -> Result<Option<Rendered>> {
        let state = &req.state;
        self.restart_progress(req);
        let modes = state.modes();
        let gpu_scene = self.gpu.is_some() && !self.lit(state.color);
        let use_gpu = |m: Mode| {
            gpu_scene
                && state.view == View::Color
                && matches!(m, Mode::Filter(f) if GpuFilter::of(f).is_some())
        };
        let scale = self.scale(req, &modes, use_gpu);
        let (w, h) = (req.width.div_ceil(scale), req.height.div_ceil(scale));
        let rects = part_rects(state, w, h);
        // Only the reference's mean needs floats; filters draw straight into 8 bits.
        let float = modes.contains(&Mode::Reference);
        let settings = view_settings(self.scene(state.color)?, state, w, h, float);
        let clip = req.camera.clip_from_world(w as f32 / h as f32);
        let mut frame = match self.frame.take() {
            Some(mut f) if f.width == w && f.height == h => {
                f.reset(&settings);
                f
            }
            _ => Frame::new(&settings),
        };
        let plan = ReferencePlan {
            srgb_display: req.state.color == texel::ColorHandling::Srgb,
            ..ReferencePlan::default()
        };
        if !self.progress.reference.fits(w, h, &plan) {
            self.progress.reference = ProgressiveReference::new(w, h, &plan);
        }
        let t0 = Instant::now();
        let mut parts = Vec::new();
        for (k, (&mode, &rect)) in modes.iter().zip(&rects).enumerate() {
            let started = Instant::now();
            let gpu = use_gpu(mode);
            // The student's shader draws the left half (or the whole frame) in the lab's modes.
            let shader = k == 0
                && self.shader.thread.is_some()
                && state.view == View::Color
                && matches!(mode, Mode::Filter(f) if f.lab_mode().is_some());
            let part = Part {
                mode,
                rect,
                gpu,
                shader,
                clip,
            };
            if !self.draw_part(req, &part, &settings, &mut frame)? {
                return Ok(self.abandon(frame));
            }
            let px = f64::from(rect[2] - rect[0]) * f64::from(rect[3] - rect[1]);
            let ms = started.elapsed().as_secs_f64() * 1e3;
            let c = self.costs.entry((mode, state.view, gpu)).or_insert(ms / px);
            *c = 0.5 * *c + 0.5 * ms / px.max(1.0);
            parts.push(PartInfo {
                mode,
                backend: if shader {
                    "glsl"
                } else if gpu {
                    "gpu"
                } else {
                    "cpu"
                },
                samples: None,
                within: None,
                stats: None,
            });
        }
        self.show_reference_mean(req, &rects, &mut parts, &mut frame);
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        // Statistics once per still image, after its first frame.
        if !req.moving && scale == 1 {
            self.attach_stats(req, &rects, &settings, clip, &mut parts)?;
        }
        let pixels = display(&frame, &rects, &modes, state, scale, req.width, req.height);
        *self.frame = Some(frame);
        Ok(Some(Rendered {
            generation: req.generation,
            pixels,
            width: req.width,
            height: req.height,
            ms,
            scale,
            parts,
            error: None,
            notice: self.shader.notice.clone(),
        }))
    }

    /// Start the reference's accumulation and the statistics again unless `req` shows the same
    /// still image as the last request.
    fn restart_progress(&mut self, req: &Request) {
        let same = self
            .progress
            .image
            .as_ref()
            .is_some_and(|r| r.same_image(req));
        if !same || req.moving {
            *self.progress = Progress {
                image: (!req.moving).then(|| req.clone()),
                ..Progress::default()
            };
        }
    }

    /// Whether the scene has lights, materials or per-pixel sphere mappings, which the GPU path
    /// lacks: such scenes stay on the CPU.
    fn lit(&self, color: texel::ColorHandling) -> bool {
        let scenes = &self.worker.scenes;
        scenes[color as usize]
            .as_ref()
            .or(scenes.iter().flatten().next())
            .is_some_and(|s| {
                !s.scene.lights.is_empty() || !s.scene.materials.is_empty() || s.maps_uv_per_pixel()
            })
    }

    /// The resolution divisor: 1, or while moving the smallest that keeps the predicted frame
    /// time within [`BUDGET_MS`] (at most [`MAX_SCALE`]).
    fn scale(&self, req: &Request, modes: &[Mode], use_gpu: impl Fn(Mode) -> bool) -> u32 {
        if !req.moving {
            return 1;
        }
        let full_rects = part_rects(&req.state, req.width, req.height);
        let predicted: f64 = modes
            .iter()
            .zip(&full_rects)
            .map(|(&m, r)| {
                let px = f64::from(r[2] - r[0]) * f64::from(r[3] - r[1]);
                self.cost(m, req.state.view, use_gpu(m)) * px
            })
            .sum();
        ((predicted / BUDGET_MS).sqrt().ceil() as u32).clamp(1, MAX_SCALE)
    }

    /// Draw one mode into its rectangle of `frame`: on the GPU, on the CPU in bands, or as one
    /// more reference pass added to the accumulation. `false` when a newer request superseded
    /// this one between bands.
    fn draw_part(
        &mut self,
        req: &Request,
        part: &Part,
        settings: &RenderSettings,
        frame: &mut Frame,
    ) -> Result<bool> {
        let (state, rect, w) = (&req.state, part.rect, frame.width);
        let filter = match part.mode {
            Mode::Filter(f) => f,
            Mode::Reference => Filter::Trilinear,
        };
        let key = self.samplers(filter, state)?;
        let draws = camera_draws(&self.worker.scenes, self.samplers, key, part.clip);
        let settings =
            with_environment(settings, &self.worker.scenes, self.samplers, key, part.clip);
        let bands = bands(rect, self.cost(part.mode, state.view, false), req.moving);
        match part.mode {
            Mode::Filter(f) if part.shader => {
                let mode = f.lab_mode().map_or(0, i32::from);
                let size = (w, frame.height);
                let path = self.worker.shader.as_deref();
                let px = shader_frame(self.shader, path, &draws, &settings, part.clip, size, mode)?;
                // The shader's codes are in the texture's own encoding (it filters the codes
                // as they are stored).
                let srgb = draws.first().is_some_and(|d| {
                    d.texture.source_format() == texel::texture::Format::Rgba8Srgb
                });
                let codes = if srgb {
                    ColorTarget::Srgb8
                } else {
                    ColorTarget::Unorm8
                };
                if frame.target == codes {
                    for_rect(rect, w, |k| frame.color8[k] = px[k]);
                } else {
                    let linear: Vec<[f32; 4]> = px.iter().map(|&p| codes.decode(p)).collect();
                    copy_rect(&linear, frame, rect);
                }
                frame.forget_clear();
            }
            Mode::Filter(f) if part.gpu => {
                let gpu_dev = self.gpu.expect("use_gpu checked");
                let g = match self.gpu_draws.entry(key) {
                    std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
                    std::collections::hash_map::Entry::Vacant(e) => {
                        e.insert(gpu_dev.prepare(&draws, GpuFilter::of(f).expect("checked"))?)
                    }
                };
                g.set_clip_from_world(part.clip);
                let out = g.render(&RenderSettings {
                    scissor: Some(rect),
                    derivatives: texel::raster::Derivatives::Quad,
                    ..settings
                })?;
                copy_frame_rect(&out, frame, rect);
                // Written by hand: later draws must load it, not redraw from the clear.
                frame.forget_clear();
            }
            Mode::Filter(_) => {
                for band in bands {
                    if self.shared.superseded(req.generation) {
                        return Ok(false);
                    }
                    let s = RenderSettings {
                        scissor: Some(band),
                        ..settings
                    };
                    draw_into(&s, &draws, frame)?;
                }
            }
            Mode::Reference => {
                self.progress.passes += 1;
                let seed = self.progress.passes;
                let spp = reference_spp(req);
                for band in bands {
                    if self.shared.superseded(req.generation) {
                        return Ok(false);
                    }
                    let s = RenderSettings {
                        scissor: Some(band),
                        view: View::Color,
                        ..settings
                    };
                    let pass = render_reference_strata(&s, &draws, spp, seed, None)?;
                    self.progress.reference.add(&pass, band);
                }
            }
        }
        Ok(true)
    }

    /// Count this frame's reference samples, and show in the reference's parts the mean of
    /// every pass so far.
    fn show_reference_mean(
        &mut self,
        req: &Request,
        rects: &[[u32; 4]],
        parts: &mut [PartInfo],
        frame: &mut Frame,
    ) {
        if req.state.modes().contains(&Mode::Reference) {
            let [a, b] = reference_spp(req);
            self.progress.samples += a * b;
        }
        let samples = self.progress.samples;
        let [a, b] = reference_spp(req);
        let passes = samples / (a * b);
        for (part, &rect) in parts.iter_mut().zip(rects) {
            if part.mode == Mode::Reference {
                part.samples = Some(samples);
                self.progress.reference.mean_into(rect, &mut frame.color);
                if !req.moving && passes >= 2 {
                    part.within = Some(self.progress.reference.share_within(rect));
                }
            }
        }
    }

    /// Give each part its statistics: measured once per still image, after its first frame,
    /// then kept.
    fn attach_stats(
        &mut self,
        req: &Request,
        rects: &[[u32; 4]],
        settings: &RenderSettings,
        clip: glam::Mat4,
        parts: &mut [PartInfo],
    ) -> Result<()> {
        if let Some(stats) = &self.progress.stats {
            for (p, s) in parts.iter_mut().zip(stats) {
                p.stats = *s;
            }
        } else if self.progress.image.is_some() && self.progress.first_done {
            if let Some(stats) = self.measure(req, rects, settings, clip)? {
                for (p, s) in parts.iter_mut().zip(&stats) {
                    p.stats = *s;
                }
                self.progress.stats = Some(stats);
            }
        } else {
            self.progress.first_done = true;
        }
        Ok(())
    }

    /// Give up the frame for a newer request: keep its buffers, and forget the reference's
    /// accumulation, which may now hold part of a pass.
    fn abandon(&mut self, frame: Frame) -> Option<Rendered> {
        *self.frame = Some(frame);
        self.progress.image = None;
        None
    }

    /// Milliseconds per pixel measured for `mode` (a guess of 20 ns before the first frame).
    fn cost(&self, mode: Mode, view: View, gpu: bool) -> f64 {
        self.costs.get(&(mode, view, gpu)).copied().unwrap_or(2e-5)
    }

    /// The HUD's statistics for each filter half: one counting pass at full resolution
    /// ([`lod_range`] for the lods). `None` if superseded.
    fn measure(
        &mut self,
        req: &Request,
        rects: &[[u32; 4]],
        settings: &RenderSettings,
        clip: glam::Mat4,
    ) -> Result<Option<Vec<Option<Stats>>>> {
        let state = &req.state;
        let mut out = Vec::new();
        for (&mode, &rect) in state.modes().iter().zip(rects) {
            let Mode::Filter(filter) = mode else {
                out.push(None);
                continue;
            };
            if self.shared.superseded(req.generation) {
                return Ok(None);
            }
            let key = self.samplers(filter, state)?;
            let draws = camera_draws(&self.worker.scenes, self.samplers, key, clip);
            let settings =
                with_environment(settings, &self.worker.scenes, self.samplers, key, clip);
            let s = RenderSettings {
                scissor: Some(rect),
                view: View::Color,
                count_texels: true,
                capture_footprints: true,
                ..settings
            };
            let counted = texel::raster::render(&s, &draws)?;
            let (mut texels, mut covered) = (0u64, 0u64);
            for_rect(rect, s.width, |k| {
                if counted.covered(k) {
                    texels += u64::from(counted.texels_read[k]);
                    covered += 1;
                }
            });
            let lod = lod_range(&s, &draws, &counted, rect)?;
            out.push(Some(Stats {
                texels_mean: texels as f64 / covered.max(1) as f64,
                lod,
            }));
        }
        Ok(Some(out))
    }
}

/// The smallest and largest lod of the covered pixels of `rect` in `frame` (rendered with
/// footprints). A pixel's lod depends on its mesh's texture size and sampler; when every draw
/// has the same texture size and lod settings the answer is exact from `frame`; otherwise each
/// group of draws that share them is rendered alone and its own covered pixels counted (pixels
/// hidden behind another group then count too).
pub(crate) fn lod_range(
    settings: &RenderSettings,
    draws: &[DrawCall],
    frame: &Frame,
    rect: [u32; 4],
) -> Result<Option<(f32, f32)>> {
    let group_of = |d: &DrawCall| {
        let s = d.sampler.descriptor();
        (
            d.texture.width(),
            d.texture.height(),
            s.lod_bias.to_bits(),
            s.lod_min_clamp.to_bits(),
            s.lod_max_clamp.to_bits(),
        )
    };
    let mut groups: Vec<_> = draws.iter().map(group_of).collect();
    groups.sort_unstable();
    groups.dedup();
    let mut range: Option<(f32, f32)> = None;
    let mut add = |lod: f32| {
        if lod.is_finite() {
            range = Some(range.map_or((lod, lod), |(a, b)| (a.min(lod), b.max(lod))));
        }
    };
    for g in &groups {
        let members: Vec<DrawCall> = draws
            .iter()
            .filter(|d| group_of(d) == *g)
            .copied()
            .collect();
        let alone;
        let f = if groups.len() == 1 {
            frame
        } else {
            alone = texel::raster::render(settings, &members)?;
            &alone
        };
        let d = &members[0];
        for_rect(rect, settings.width, |k| {
            if f.covered(k) {
                add(d.sampler.lod(d.texture, &f.footprints[k]));
            }
        });
    }
    Ok(range)
}

/// Row bands of `rect`, each about [`BUDGET_MS`] at `cost` ms per pixel (multiples of the 64-row
/// tile; the whole rectangle while moving, where the resolution already keeps it short).
fn bands(rect: [u32; 4], cost: f64, moving: bool) -> Vec<[u32; 4]> {
    let [x0, y0, x1, y1] = rect;
    let w = f64::from((x1 - x0).max(1));
    let rows = if moving {
        y1 - y0
    } else {
        let r = (BUDGET_MS / (cost * w)).max(1.0);
        ((r / 64.0).round().max(1.0) as u32).saturating_mul(64)
    };
    let mut out = Vec::new();
    let mut y = y0;
    while y < y1 {
        let e = y.saturating_add(rows.max(1)).min(y1);
        out.push([x0, y, x1, e]);
        y = e;
    }
    out
}

/// Call `f` with the index of every pixel of `rect` in a frame `width` wide.
fn for_rect(rect: [u32; 4], width: u32, mut f: impl FnMut(usize)) {
    let [x0, y0, x1, y1] = rect;
    for y in y0..y1 {
        let row = y as usize * width as usize;
        for x in x0..x1 {
            f(row + x as usize);
        }
    }
}

/// Copy `rect` of `from` (linear colour of a frame of `frame`'s size) into `frame`: as it is into
/// a float target, encoded into an 8-bit one.
fn copy_rect(from: &[[f32; 4]], frame: &mut Frame, rect: [u32; 4]) {
    let (width, target) = (frame.width, frame.target);
    if target.is_8bit() {
        for_rect(rect, width, |k| frame.color8[k] = target.encode(from[k]));
    } else {
        for_rect(rect, width, |k| frame.color[k] = from[k]);
    }
}

/// Copy `rect` of `from` into `frame`, a frame of the same size and target.
fn copy_frame_rect(from: &Frame, frame: &mut Frame, rect: [u32; 4]) {
    if frame.target.is_8bit() {
        for_rect(rect, frame.width, |k| frame.color8[k] = from.color8[k]);
    } else {
        for_rect(rect, frame.width, |k| frame.color[k] = from.color[k]);
    }
}

/// The frame as window pixels: each half encoded for display (colour as `--color` says, debug
/// views as sRGB, as `texel render` writes them; an 8-bit frame holds them so already), enlarged
/// `scale` times.
fn display(
    frame: &Frame,
    rects: &[[u32; 4]],
    modes: &[Mode],
    state: &ViewState,
    scale: u32,
    width: u32,
    height: u32,
) -> Vec<u32> {
    let enc_for = |m: Mode| -> Encoding {
        if state.view == View::Color || m == Mode::Reference {
            state.color.encoding()
        } else {
            Encoding::Srgb
        }
    };
    let pack = |[r, g, b, _]: [u8; 4]| u32::from(r) << 16 | u32::from(g) << 8 | u32::from(b);
    // Rows in parallel: encoding is a third of a cheap filter's frame time on one thread.
    let fw = frame.width as usize;
    let mut small = vec![0u32; fw * frame.height as usize];
    small.par_chunks_mut(fw).enumerate().for_each(|(y, out)| {
        let row = y * fw;
        for (&m, &[x0, y0, x1, y1]) in modes.iter().zip(rects) {
            if !(y0..y1).contains(&(y as u32)) {
                continue;
            }
            let (x0, x1) = (x0 as usize, x1 as usize);
            if frame.target.is_8bit() {
                let src = &frame.color8[row + x0..row + x1];
                for (o, &p) in out[x0..x1].iter_mut().zip(src) {
                    *o = pack(p);
                }
            } else {
                let enc = enc_for(m);
                let src = &frame.color[row + x0..row + x1];
                for (o, &c) in out[x0..x1].iter_mut().zip(src) {
                    *o = pack(enc.encode(c));
                }
            }
        }
    });
    if scale == 1 {
        return small;
    }
    let mut out = vec![0u32; width as usize * height as usize];
    for y in 0..height {
        let src = (y / scale) as usize * frame.width as usize;
        for x in 0..width {
            out[y as usize * width as usize + x as usize] = small[src + (x / scale) as usize];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use texel::{ColorHandling, MemoryBudget, Scene, SceneOptions};

    /// `builtin:ground` at `w x h`, prepared with the default options in any colour handling.
    struct Ground {
        size: (u32, u32),
        budget: MemoryBudget,
    }

    impl crate::SceneSource for Ground {
        fn load(&mut self, color: ColorHandling) -> Result<PreparedScene> {
            let options = SceneOptions {
                size: Some(self.size),
                color,
                ..SceneOptions::default()
            };
            Ok(PreparedScene::new(
                Scene::load("builtin:ground")?,
                &options,
                &mut self.budget,
            )?)
        }

        fn budget(&mut self) -> &mut MemoryBudget {
            &mut self.budget
        }
    }

    /// The render thread's state for `builtin:ground` at `w x h`, without a thread or a window.
    struct Harness {
        worker: Worker,
        samplers: HashMap<SamplerKey, Vec<Sampler>>,
        costs: HashMap<(Mode, View, bool), f64>,
        progress: Progress,
        frame: Option<Frame>,
        shared: Shared,
        camera: Camera,
    }

    impl Harness {
        fn new(w: u32, h: u32) -> Harness {
            let mut source = Ground {
                size: (w, h),
                budget: MemoryBudget::limit_or_default(None),
            };
            let scene = crate::SceneSource::load(&mut source, ColorHandling::Srgb).unwrap();
            let camera = scene.scene.camera;
            Harness {
                worker: Worker {
                    source: Box::new(source),
                    scenes: [Some(scene), None],
                    threads: None,
                    gpu: None,
                    shader: None,
                },
                samplers: HashMap::new(),
                costs: HashMap::new(),
                progress: Progress::default(),
                frame: None,
                shared: Shared::default(),
                camera,
            }
        }

        fn render(&mut self, req: &Request) -> Option<Rendered> {
            let mut gpu_draws = HashMap::new();
            let mut shader = ShaderState::default();
            let mut ctx = FrameContext {
                worker: &mut self.worker,
                gpu: None,
                gpu_draws: &mut gpu_draws,
                shader: &mut shader,
                samplers: &mut self.samplers,
                costs: &mut self.costs,
                progress: &mut self.progress,
                frame: &mut self.frame,
                shared: &self.shared,
            };
            ctx.render(req).unwrap()
        }

        fn request(&self, keys: &str, moving: bool) -> Request {
            let mut state =
                ViewState::new(Mode::Filter(Filter::Trilinear), texel::ColorHandling::Srgb);
            for p in crate::controls::parse_keys(keys).unwrap() {
                state.apply(p);
            }
            let scene = self.worker.scenes[0].as_ref().unwrap();
            let (width, height) = (scene.width, scene.height);
            Request {
                generation: 1,
                state,
                camera: self.camera,
                width,
                height,
                moving,
            }
        }
    }

    /// `texel render`'s pixels for `filter`: the same scene, encoded as the viewer shows them.
    fn rendered(h: &Harness, filter: Filter) -> Vec<u32> {
        let scene = h.worker.scenes[0].as_ref().unwrap();
        let samplers = scene.samplers(filter).unwrap();
        scene.build_structures(&samplers).unwrap();
        let frame = texel::render(&scene.settings(), &scene.draws(&samplers)).unwrap();
        frame
            .to_srgb8()
            .chunks_exact(4)
            .map(|p| {
                let [r, g, b] = [p[0], p[1], p[2]];
                u32::from(r) << 16 | u32::from(g) << 8 | u32::from(b)
            })
            .collect()
    }

    #[test]
    fn a_still_frame_is_render_bit_for_bit_and_halves_are_their_filters() {
        let mut h = Harness::new(160, 90);
        let r = h.render(&h.request("7", false)).unwrap();
        assert_eq!((r.scale, r.width, r.height), (1, 160, 90));
        assert!(
            r.pixels == rendered(&h, Filter::Aniso8),
            "differs from texel render"
        );
        // The second frame of the same image measures the statistics.
        assert!(r.parts[0].stats.is_none());
        let r = h.render(&h.request("7", false)).unwrap();
        let stats = r.parts[0].stats.unwrap();
        assert!(
            stats.texels_mean > 4.0 && stats.texels_mean <= 64.0,
            "{stats:?}"
        );
        let (lo, hi) = stats.lod.unwrap();
        assert!(lo < hi && hi > 4.0, "{stats:?}");
        // Split: left mip-nearest, right EWA.
        let r = h.render(&h.request("3,shift+9", false)).unwrap();
        let (left, right) = (rendered(&h, Filter::MipNearest), rendered(&h, Filter::Ewa));
        for y in 0..90usize {
            for x in 0..160usize {
                let want = if x < 80 { &left } else { &right };
                assert_eq!(r.pixels[y * 160 + x], want[y * 160 + x], "({x}, {y})");
            }
        }
    }

    #[test]
    fn moving_over_budget_renders_at_reduced_resolution() {
        let mut h = Harness::new(160, 90);
        // Pretend EWA costs 40 ms for 1/16 of the frame: the frame shrinks 4 times a side.
        h.costs.insert(
            (Mode::Filter(Filter::Ewa), View::Color, false),
            BUDGET_MS * 16.0 / 14400.0,
        );
        let r = h.render(&h.request("9", true)).unwrap();
        assert_eq!(r.scale, 4);
        assert_eq!((r.width, r.height), (160, 90));
        // Each 4x4 block is one pixel of the small frame.
        for y in 0..90usize {
            for x in 0..160usize {
                assert_eq!(
                    r.pixels[y * 160 + x],
                    r.pixels[(y / 4 * 4) * 160 + x / 4 * 4]
                );
            }
        }
        assert!(r.parts[0].stats.is_none(), "no statistics while moving");
        // Still again: full resolution.
        let r = h.render(&h.request("9", false)).unwrap();
        assert_eq!(r.scale, 1);
    }

    #[test]
    fn the_reference_accumulates_and_restarts_on_change() {
        let mut h = Harness::new(64, 36);
        let req = h.request("0", false);
        let mut last = Vec::new();
        for k in 1..=3u32 {
            let r = h.render(&req).unwrap();
            assert_eq!(r.parts[0].samples, Some(4 * k));
            last = r.pixels;
        }
        // The mean of 12 samples equals the reference renderer's three passes averaged (in f64).
        let scene = h.worker.scenes[0].as_ref().unwrap();
        let samplers = scene.samplers(Filter::Trilinear).unwrap();
        let draws = scene.draws(&samplers);
        let mut sum = vec![[0.0f64; 4]; 64 * 36];
        for seed in 1..=3 {
            let pass =
                render_reference_strata(&scene.settings(), &draws, [2, 2], seed, None).unwrap();
            for (s, c) in sum.iter_mut().zip(&pass.color) {
                for i in 0..4 {
                    s[i] += f64::from(c[i]);
                }
            }
        }
        let want: Vec<u32> = sum
            .iter()
            .map(|s| {
                let [r, g, b, _] = Encoding::Srgb.encode(s.map(|c| (c / 3.0) as f32));
                u32::from(r) << 16 | u32::from(g) << 8 | u32::from(b)
            })
            .collect();
        let differ = last.iter().zip(&want).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{differ} pixels differ");
        // A camera step restarts it.
        let mut moved = req.clone();
        moved.camera.eye.y += 0.1;
        let r = h.render(&moved).unwrap();
        assert_eq!(r.parts[0].samples, Some(4));
    }

    /// The share of the reference's pixels within half a step equals one computed from the
    /// passes themselves: each pixel's mean and standard error over its passes, in `f64`.
    #[test]
    fn the_reference_reports_the_share_within_half_a_step() {
        let mut h = Harness::new(64, 36);
        let req = h.request("0", false);
        assert_eq!(h.render(&req).unwrap().parts[0].within, None, "one pass");
        let passes = 4u32;
        let mut got = None;
        for _ in 1..passes {
            got = h.render(&req).unwrap().parts[0].within;
        }
        let got = got.expect("a share after two passes");
        let scene = h.worker.scenes[0].as_ref().unwrap();
        let samplers = scene.samplers(Filter::Trilinear).unwrap();
        let draws = scene.draws(&samplers);
        let frames: Vec<_> = (1..=u64::from(passes))
            .map(|seed| {
                render_reference_strata(&scene.settings(), &draws, [2, 2], seed, None).unwrap()
            })
            .collect();
        let n = f64::from(passes);
        let within = (0..64 * 36)
            .filter(|&k| {
                let mean: [f64; 3] = std::array::from_fn(|c| {
                    frames.iter().map(|f| f64::from(f.color[k][c])).sum::<f64>() / n
                });
                let se = std::array::from_fn(|c| {
                    let ss: f64 = frames
                        .iter()
                        .map(|f| (f64::from(f.color[k][c]) - mean[c]).powi(2))
                        .sum();
                    (ss / (n - 1.0) / n).sqrt()
                });
                let half = texel::raster::display_half_width(mean, se, passes, true);
                half <= 0.5 / 255.0
            })
            .count();
        let want = within as f64 / (64.0 * 36.0);
        // Welford's update differs from the two-pass form in the last bits of a few pixels at
        // most.
        assert!(
            (got - want).abs() <= 2.0 / (64.0 * 36.0),
            "{got} against {want}"
        );
        assert!(
            want > 0.0 && want < 1.0,
            "the ground is neither converged nor all noise: {want}"
        );
    }

    #[test]
    fn a_newer_request_abandons_a_frame_between_bands() {
        let mut h = Harness::new(160, 200);
        // Slow enough for 64-row bands: four bands.
        h.costs.insert(
            (Mode::Filter(Filter::Ewa), View::Color, false),
            BUDGET_MS / (160.0 * 64.0),
        );
        let req = Request {
            width: 160,
            height: 200,
            ..h.request("9", false)
        };
        h.shared.submit(Request {
            generation: 2,
            ..req.clone()
        });
        assert!(h.render(&req).is_none());
    }

    #[test]
    fn an_abandoned_reference_pass_restarts_the_accumulation() {
        let mut h = Harness::new(160, 200);
        let req = h.request("0", false);
        for k in 1..=2u32 {
            assert_eq!(h.render(&req).unwrap().parts[0].samples, Some(4 * k));
        }
        // Now slow enough for 64-row bands, and superseded before the pass ends: part of the
        // pass may be summed, so the next frame of the same image starts again.
        h.costs.insert(
            (Mode::Reference, View::Color, false),
            BUDGET_MS / (160.0 * 64.0),
        );
        let newer = Request {
            generation: 2,
            ..req.clone()
        };
        h.shared.submit(newer.clone());
        assert!(h.render(&req).is_none());
        assert_eq!(h.render(&newer).unwrap().parts[0].samples, Some(4));
    }

    #[test]
    fn bands_cover_the_rectangle_once_in_tile_rows() {
        for (rect, cost) in [
            ([0, 0, 1280, 720], 1e-5),
            ([5, 3, 700, 719], 1e-3),
            ([0, 0, 1, 1], 1.0),
        ] {
            let b = bands(rect, cost, false);
            assert_eq!(b.first().unwrap()[1], rect[1]);
            assert_eq!(b.last().unwrap()[3], rect[3]);
            for w in b.windows(2) {
                assert_eq!(w[0][3], w[1][1]);
            }
            for band in &b[..b.len() - 1] {
                assert_eq!((band[3] - band[1]) % 64, 0);
            }
        }
        // Cheap filters: one band; slow ones: 64-row bands.
        assert_eq!(bands([0, 0, 1280, 720], 1e-6, false).len(), 1);
        assert_eq!(bands([0, 0, 1280, 720], 1e-3, false).len(), 12);
        assert_eq!(bands([0, 0, 1280, 720], 1e-3, true).len(), 1);
    }

    #[test]
    fn halves_meet_at_the_divider() {
        let mut s = ViewState::new(Mode::Reference, texel::ColorHandling::Srgb);
        assert_eq!(part_rects(&s, 100, 50), vec![[0, 0, 100, 50]]);
        s.split = true;
        s.divider = 0.3;
        assert_eq!(
            part_rects(&s, 100, 50),
            vec![[0, 0, 30, 50], [30, 0, 100, 50]]
        );
        s.divider = 0.0;
        assert_eq!(part_rects(&s, 100, 50)[0], [0, 0, 1, 50]);
    }
}
