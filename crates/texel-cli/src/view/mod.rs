//! `texel view`: an interactive window rendering continuously with texel's own renderer — the
//! lab's keys 1-8, a fly camera, split-screen comparison and a progressive reference.
//!
//! Three parts, so that everything but the window is tested without one:
//! - [`controls`]: keys, the state they change and the key table (`--help` and the overlay);
//! - [`worker`]: the render thread (scissored halves, reduced resolution while moving, bands,
//!   the accumulating reference, HUD statistics);
//! - [`window`]: winit's event loop and softbuffer's surface.

pub(crate) mod fly;
pub(crate) mod hud;
pub(crate) mod window;
pub(crate) mod worker;

use std::sync::Arc;

use anyhow::{anyhow, Context, Result};
use texel_gpu::Gpu;
use winit::event_loop::EventLoop;

use crate::cli::ViewArgs;
use crate::controls::{parse_keys, Mode, ViewState};
use crate::input::{load_scene_with, texture_storage, Input, MaterialOverrides};
use fly::Fly;
use texel::TextureStorage;
use window::{App, Options};
use worker::{Rendered, Shared, Worker};

/// Run `texel view`.
pub(crate) fn run(args: &ViewArgs, input: Input) -> Result<()> {
    let presses =
        parse_keys(args.keys.as_deref().unwrap_or("")).map_err(|e| anyhow!("--keys: {e}"))?;
    let mut input = input;
    // The window's textures are decoded to float by default where its filters run on the CPU
    // (the same images, anisotropic frames faster; docs/decisions.md).
    let overrides = MaterialOverrides {
        texture_storage: texture_storage(&args.scene, args.gpu, TextureStorage::Float)?,
        ..MaterialOverrides::of(&args.scene)
    };
    let a = &args.scene;
    let scene = load_scene_with(&a.scene, a.color, a.size, overrides, &mut input)?;
    let gpu = if args.gpu {
        Some(Gpu::new(args.adapter.as_deref())?)
    } else {
        None
    };
    if let Some(path) = &args.shader {
        // A shader that does not compile at the start is an error before any window opens;
        // later edits that do not compile are shown in the window.
        let source = crate::cmd_lab::read_source(path, "shader")?;
        let gl = texel::lab::Gl::new()?;
        let empty =
            texel::lab::device_scene(&[], (2, 2), [0; 4], glam::Mat4::IDENTITY.to_cols_array());
        gl.prepare(&source, None, &texel::lab::Names::default(), &empty)
            .with_context(|| format!("the shader {}", path.display()))?;
    }
    let size = (scene.width, scene.height);
    let fly = Fly::new(scene.scene.camera, movement_speed(&scene));
    let state = ViewState::new(Mode::Filter(texel::Filter::Trilinear), args.scene.color);
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
    scenes[args.scene.color as usize] = Some(scene);
    let worker = Worker {
        scene_spec: args.scene.scene.clone(),
        size: args.scene.size,
        overrides,
        scenes,
        input,
        threads: args.threads,
        gpu,
        shader: args.shader.clone(),
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
            title: format!("texel view - {}", args.scene.scene),
            size,
            max_frames: args.frames.map(u64::from),
            screenshot: args.screenshot.clone(),
        },
        state,
        fly,
        shared.clone(),
    );
    app.script(&presses);
    if !args.hud {
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

/// Movement speed of the fly camera: half the distance from the eye to the point looked at per
/// second (the scene's scale where the camera is: the ground plane's camera stands 1 unit high and
/// looks 10 units ahead, so it moves 5 units a second), at most the scene's bounding-box diagonal
/// and at least 0.001 world units.
fn movement_speed(scene: &texel::PreparedScene) -> f32 {
    let mut lo = glam::Vec3::splat(f32::INFINITY);
    let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
    for m in &scene.scene.meshes {
        for &p in &m.positions {
            if p.is_finite() {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    let diagonal = (hi - lo).length();
    let c = &scene.scene.camera;
    let reach = (c.target - c.eye).length() / 2.0;
    let speed = if diagonal.is_finite() {
        reach.min(diagonal)
    } else {
        reach
    };
    if speed.is_finite() {
        speed.max(1e-3)
    } else {
        1.0
    }
}
