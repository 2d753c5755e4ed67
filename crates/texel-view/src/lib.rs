//! texel-view: an interactive window rendering continuously with texel's own renderer — the
//! lab's keys 1-8, a fly camera, split-screen comparison and a progressive reference. `texel
//! view` parses its flags, loads the scene and calls [`run`].
//!
//! Everything but the window is tested without one:
//! - `controls`: keys, the state they change and the key table ([`key_table`]: `--help` and the
//!   overlay);
//! - `worker`: the render thread (scissored halves, reduced resolution while moving, bands, the
//!   accumulating reference, HUD statistics, the student's shader on OpenGL);
//! - `fly` and `hud`: the camera's motion and the overlay's text;
//! - `window`: winit's event loop and softbuffer's surface.

mod controls;
mod fly;
mod hud;
mod window;
mod worker;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{anyhow, Context, Result};
use texel::quality::Image8;
use texel::{ColorHandling, MemoryBudget, PreparedScene};
use texel_gpu::Gpu;
use winit::event_loop::EventLoop;

pub use controls::{key_table, parse_keys, Press};

use controls::{Mode, ViewState};
use fly::Fly;
use window::{App, Options};
use worker::{Rendered, Shared, Worker};

/// Where the viewer's scene comes from: the scene loaded again for the other colour handling
/// (the key C), and the memory account its textures and tables are charged to.
pub trait SceneSource: Send {
    /// The scene loaded with `color` handling, as the first one was.
    ///
    /// # Errors
    /// The loader's: the scene or a texture cannot be read, the account is exceeded.
    fn load(&mut self, color: ColorHandling) -> Result<PreparedScene>;

    /// The account the viewer's samplers' ripmaps and summed-area tables are charged to.
    fn budget(&mut self) -> &mut MemoryBudget;
}

/// What the viewer opens.
pub struct Viewer {
    /// The window's title.
    pub title: String,
    /// The scene as first shown.
    pub scene: PreparedScene,
    /// Its colour handling (the key C switches).
    pub color: ColorHandling,
    /// The scene for the other colour handling, and the account.
    pub source: Box<dyn SceneSource>,
    /// Worker threads; `None`: all cores.
    pub threads: Option<u32>,
    /// The device of the GPU modes; `None`: every mode on the CPU.
    pub gpu: Option<Gpu>,
    /// A student's fragment shader, drawn on OpenGL in the left half and read again when the
    /// file changes.
    pub shader: Option<PathBuf>,
    /// Close after this many frames.
    pub frames: Option<u64>,
    /// Write the last frame shown here at exit (F12 writes one at any time).
    pub screenshot: Option<PathBuf>,
    /// How a screenshot is written.
    pub save: fn(&Path, &Image8) -> Result<()>,
    /// Keys pressed before the first frame ([`parse_keys`]).
    pub presses: Vec<Press>,
    /// Whether the overlay's text is shown (the key H switches).
    pub hud: bool,
}

/// Open the window and render until it closes: a render thread draws the frames the window asks
/// for, newest first. A shader that does not compile at the start is an error before any window
/// opens; later edits that do not compile are shown in the window. At the end the frame counts
/// and times go to standard error, as one line.
///
/// # Errors
/// The shader's, no display to open a window on, the render thread's start and the event loop's
/// failure, and the first error a frame met.
pub fn run(viewer: Viewer) -> Result<()> {
    if let Some(path) = &viewer.shader {
        let source = texel::lab::read_shader(path, "shader")?;
        let gl = texel::lab::Gl::new()?;
        let empty =
            texel::lab::device_scene(&[], (2, 2), [0; 4], glam::Mat4::IDENTITY.to_cols_array());
        gl.prepare(&source, None, &texel::lab::Names::default(), &empty)
            .with_context(|| format!("the shader {}", path.display()))?;
    }
    let scene = viewer.scene;
    let size = (scene.width, scene.height);
    let fly = Fly::new(scene.scene.camera, fly::movement_speed(&scene));
    let state = ViewState::new(Mode::Filter(texel::Filter::Trilinear), viewer.color);
    // The window first: without a display, say so before any thread starts.
    let event_loop = EventLoop::<Rendered>::with_user_event()
        .build()
        .map_err(|e| {
            anyhow!(
                "cannot open a window ({e}); texel view needs an X11 or Wayland display (DISPLAY or \
                 WAYLAND_DISPLAY); for a headless machine run it under Xvfb (xvfb-run texel view)"
            )
        })?;
    let proxy = event_loop.create_proxy();
    let mut scenes = [None, None];
    scenes[viewer.color as usize] = Some(scene);
    let worker = Worker {
        source: viewer.source,
        scenes,
        threads: viewer.threads,
        gpu: viewer.gpu,
        shader: viewer.shader,
    };
    let shared = Arc::new(Shared::default());
    let thread = {
        let shared = shared.clone();
        std::thread::Builder::new()
            .name("texel-view-render".into())
            .spawn(move || worker::run(worker, shared, move |r| proxy.send_event(r).is_ok()))
            .context("cannot start the render thread")?
    };
    let mut app = App::new(
        Options {
            title: viewer.title,
            size,
            max_frames: viewer.frames,
            screenshot: viewer.screenshot,
            save: viewer.save,
        },
        state,
        fly,
        shared.clone(),
    );
    app.script(&viewer.presses);
    if !viewer.hud {
        app.hide_hud();
    }
    let ran = event_loop.run_app(&mut app);
    shared.quit();
    let _ = thread.join();
    ran.context("the window's event loop failed")?;
    texel_io::stderr_line(app.summary());
    match app.failure {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
