//! The window: winit's event loop and a softbuffer surface. It turns keys, the mouse and resizes
//! into [`Request`]s for the render thread, shows the newest frame with the HUD over it, and
//! counts frames for `--frames`.

use std::collections::HashSet;
use std::num::NonZeroU32;
use std::path::PathBuf;
use std::rc::Rc;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{anyhow, Context as _, Result};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow};
use winit::keyboard::{KeyCode, ModifiersState, PhysicalKey};
use winit::window::{Window, WindowId};

use super::fly::{Fly, Motion};
use super::hud::{scale_for, Canvas};
use super::worker::{part_rects, Rendered, Request, Shared, MAX_REFERENCE_SAMPLES};
use crate::controls::{key_table, Effect, Key, Mode, Press, ViewState};

/// How long after the last movement the camera counts as still (then frames refine).
const SETTLE: Duration = Duration::from_millis(200);

/// Degrees turned per pixel of mouse drag.
const LOOK_DEG_PER_PIXEL: f32 = 0.2;

/// Seconds of movement one scripted movement key stands for.
pub(crate) const SCRIPTED_STEP_S: f32 = 0.25;

/// Options fixed for the window's life.
pub(crate) struct Options {
    /// Window title.
    pub title: String,
    /// Initial inner size, pixels.
    pub size: (u32, u32),
    /// Exit after this many frames (from the render thread) were shown.
    pub max_frames: Option<u64>,
    /// Write the last frame shown here at exit.
    pub screenshot: Option<PathBuf>,
    /// How a screenshot is written.
    pub save: fn(&std::path::Path, &texel::quality::Image8) -> Result<()>,
}

/// The window's state.
pub(crate) struct App {
    options: Options,
    state: ViewState,
    fly: Fly,
    home: Fly,
    shared: Arc<Shared>,
    generation: u64,
    submitted: Option<Request>,
    window: Option<Rc<Window>>,
    surface: Option<softbuffer::Surface<Rc<Window>, Rc<Window>>>,
    latest: Option<Rendered>,
    composed: Vec<u32>,
    composed_size: (u32, u32),
    error: Option<String>,
    fresh: bool,
    presented: u64,
    frame_times: Vec<Instant>,
    held: HashSet<Key>,
    modifiers: ModifiersState,
    cursor: (f64, f64),
    drag: Option<Drag>,
    last_tick: Instant,
    last_motion: Option<Instant>,
    status: Option<(String, Instant)>,
    /// Render milliseconds of every full-resolution frame shown, and when the first and last
    /// frames were shown.
    full_ms: Vec<f64>,
    shown: Option<(Instant, Instant)>,
    /// The first error that ends the viewer.
    pub failure: Option<anyhow::Error>,
}

#[derive(Clone, Copy)]
enum Drag {
    Look,
    Divider,
}

impl App {
    /// A window showing `state` through `fly`, asking `shared`'s render thread for frames.
    pub(crate) fn new(options: Options, state: ViewState, fly: Fly, shared: Arc<Shared>) -> App {
        App {
            options,
            state,
            fly,
            home: fly,
            shared,
            generation: 0,
            submitted: None,
            window: None,
            surface: None,
            latest: None,
            composed: Vec::new(),
            composed_size: (0, 0),
            error: None,
            fresh: false,
            presented: 0,
            frame_times: Vec::new(),
            held: HashSet::new(),
            modifiers: ModifiersState::empty(),
            cursor: (0.0, 0.0),
            drag: None,
            last_tick: Instant::now(),
            last_motion: None,
            status: None,
            full_ms: Vec::new(),
            shown: None,
            failure: None,
        }
    }

    /// Apply a `--keys` script before the first frame: state keys as typed, movement keys as
    /// [`SCRIPTED_STEP_S`] seconds of movement, F12 as a screenshot at exit, Esc as exit after
    /// the first frame.
    pub(crate) fn script(&mut self, presses: &[Press]) {
        for &p in presses {
            match self.state.apply(p) {
                Effect::Quit => self.options.max_frames = Some(1),
                Effect::Screenshot => {
                    if self.options.screenshot.is_none() {
                        self.options.screenshot = Some(PathBuf::from(self.state.file_name()));
                    }
                }
                Effect::ResetCamera => self.fly = self.home,
                Effect::Move => self.fly.step(motion_of([p.key]), SCRIPTED_STEP_S, p.shift),
                Effect::None => {}
            }
        }
    }

    /// One line on what was shown: frames, the median render time of the full-resolution ones
    /// and frames per second of wall time between the first and the last frame shown.
    pub(crate) fn summary(&self) -> String {
        let mut ms = self.full_ms.clone();
        ms.sort_by(f64::total_cmp);
        let median = ms.get(ms.len() / 2).copied().unwrap_or(f64::NAN);
        let fps = match self.shown {
            Some((a, b)) if self.presented > 1 && b > a => {
                (self.presented - 1) as f64 / (b - a).as_secs_f64()
            }
            _ => f64::NAN,
        };
        format!(
            "texel view: {} frames shown ({} at full resolution), median {median:.2} ms to render, {fps:.1} frames per second",
            self.presented,
            ms.len()
        )
    }

    /// Start with the HUD and the divider line hidden (`--no-hud`).
    pub(crate) fn hide_hud(&mut self) {
        self.state.hud = false;
    }

    fn size(&self) -> (u32, u32) {
        match &self.window {
            Some(w) => {
                let s = w.inner_size();
                (s.width.max(1), s.height.max(1))
            }
            None => self.options.size,
        }
    }

    /// Send the render thread the current state (unless it already has this image).
    fn submit(&mut self, moving: bool) {
        let (width, height) = self.size();
        let request = Request {
            generation: self.generation + 1,
            state: self.state.clone(),
            camera: self.fly.camera,
            width,
            height,
            moving,
        };
        if let Some(s) = &self.submitted {
            if s.same_image(&request) && s.moving == moving {
                // Nothing the render thread draws changed (at most the HUD): keep its request,
                // show the overlay again.
                self.submitted = Some(Request {
                    generation: s.generation,
                    ..request
                });
                self.request_redraw();
                return;
            }
        }
        self.generation += 1;
        self.shared.submit(request.clone());
        self.submitted = Some(request);
    }

    fn request_redraw(&self) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }

    fn moved(&mut self) {
        self.last_motion = Some(Instant::now());
        self.submit(true);
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, press: Press) {
        match self.state.apply(press) {
            Effect::Quit => event_loop.exit(),
            Effect::Screenshot => {
                let name = unique_name(&self.state.file_name());
                match self.write_screenshot(&name) {
                    Ok(()) => {
                        self.status = Some((format!("wrote {}", name.display()), Instant::now()))
                    }
                    Err(e) => {
                        self.status = Some((format!("screenshot failed: {e:#}"), Instant::now()))
                    }
                }
            }
            Effect::ResetCamera => {
                self.fly = self.home;
                self.moved();
            }
            Effect::Move => {
                self.held.insert(press.key);
            }
            Effect::None => {}
        }
        self.submit(self.last_motion.is_some());
        self.request_redraw();
    }

    fn write_screenshot(&self, path: &std::path::Path) -> Result<()> {
        let (w, h) = self.composed_size;
        if self.composed.is_empty() {
            return Err(anyhow!("no frame has been shown yet"));
        }
        let pixels = self
            .composed
            .iter()
            .map(|&p| [(p >> 16) as u8, (p >> 8) as u8, p as u8, 255])
            .collect();
        let image = texel::quality::Image8::new(w, h, pixels)?;
        (self.options.save)(path, &image)
    }

    /// Compose the newest frame and the overlays into `composed` and show it.
    fn present(&mut self) -> Result<()> {
        let (w, h) = self.size();
        let n = w as usize * h as usize;
        self.composed.clear();
        self.composed.resize(n, 0);
        self.composed_size = (w, h);
        if let Some(r) = &self.latest {
            // After a resize the old frame shows at its size until the new one arrives.
            for y in 0..h.min(r.height) {
                let src = &r.pixels[(y * r.width) as usize..][..w.min(r.width) as usize];
                self.composed[(y * w) as usize..][..src.len()].copy_from_slice(src);
            }
        }
        // Overlays: the HUD and the divider line (not with --no-hud), then the key table below.
        let lines = if self.state.hud {
            self.hud_lines()
        } else {
            Vec::new()
        };
        let scale = scale_for(h);
        let mut canvas = Canvas {
            pixels: &mut self.composed,
            width: w,
            height: h,
        };
        let mut top = 0;
        if self.state.hud {
            if self.state.split {
                canvas.vline(part_rects(&self.state, w, h)[1][0], 0x00ff_ffff);
            }
            top = canvas.panel(0, 0, &lines, scale) + 4;
        }
        if self.state.help {
            let table: Vec<String> = key_table().lines().map(str::to_string).collect();
            canvas.panel(0, top, &table, scale);
        }
        let (Some(surface), Some(nw), Some(nh)) = (
            self.surface.as_mut(),
            NonZeroU32::new(w),
            NonZeroU32::new(h),
        ) else {
            return Ok(());
        };
        surface
            .resize(nw, nh)
            .map_err(|e| anyhow!("cannot resize the window's buffer: {e}"))?;
        let mut buffer = surface
            .buffer_mut()
            .map_err(|e| anyhow!("cannot map the window's buffer: {e}"))?;
        buffer.copy_from_slice(&self.composed);
        buffer
            .present()
            .map_err(|e| anyhow!("cannot show the frame: {e}"))?;
        Ok(())
    }

    /// The HUD's lines: each half's mode and statistics, timing, settings, messages.
    fn hud_lines(&self) -> Vec<String> {
        let mut lines = Vec::new();
        let (ms, frame_scale, parts) = match &self.latest {
            Some(r) => (r.ms, r.scale, r.parts.clone()),
            None => (0.0, 1, Vec::new()),
        };
        let sides = if self.state.split {
            ["[L] ", "[R] "]
        } else {
            ["", ""]
        };
        for (k, p) in parts.iter().enumerate() {
            let mut s = format!("{}{} ({})", sides[k.min(1)], p.mode.name(), p.backend);
            if let Some(n) = p.samples {
                s.push_str(&format!("  {n}/{MAX_REFERENCE_SAMPLES} samples/px"));
            }
            if let Some(share) = p.within {
                s.push_str(&format!(
                    "  {:.0}% within {} step",
                    100.0 * share,
                    texel::raster::DEFAULT_TOLERANCE_STEPS
                ));
            }
            match p.stats {
                Some(st) => {
                    s.push_str(&format!("  {:.1} texels/px", st.texels_mean));
                    if let Some((a, b)) = st.lod {
                        s.push_str(&format!("  lod {a:.2}..{b:.2}"));
                    }
                }
                None if p.mode != Mode::Reference => s.push_str("  (measuring)"),
                None => {}
            }
            lines.push(s);
        }
        let fps = if self.frame_times.len() >= 2 {
            let span = self.frame_times[self.frame_times.len() - 1] - self.frame_times[0];
            (self.frame_times.len() - 1) as f64 / span.as_secs_f64().max(1e-9)
        } else {
            0.0
        };
        let mut timing = format!("{ms:.1} ms/frame  {fps:.1} fps");
        if frame_scale > 1 {
            timing.push_str(&format!("  (1/{frame_scale} resolution while moving)"));
        }
        lines.push(timing);
        lines.push(format!(
            "view {}  {}  {} derivatives  lod bias {:+.1}  {}  fov {:.0}",
            self.state.view.name(),
            match self.state.perspective {
                texel::raster::Perspective::Correct => "perspective-correct",
                texel::raster::Perspective::Affine => "affine",
            },
            match self.state.derivatives {
                texel::raster::Derivatives::Analytic => "analytic",
                texel::raster::Derivatives::Quad => "quad",
            },
            self.state.lod_bias,
            match self.state.color {
                texel::ColorHandling::Srgb => "sRGB",
                texel::ColorHandling::Raw => "raw",
            },
            self.fly.camera.fovy_deg,
        ));
        if let Some(e) = &self.error {
            lines.push(format!("error: {e}"));
        }
        if let Some((s, t)) = &self.status {
            if t.elapsed() < Duration::from_secs(4) {
                lines.push(s.clone());
            }
        }
        lines.push("H: keys".to_string());
        lines
    }

    fn tick(&mut self) {
        let now = Instant::now();
        let dt = (now - self.last_tick).as_secs_f32().min(0.1);
        self.last_tick = now;
        let motion = motion_of(self.held.iter().copied());
        if motion.is_moving() {
            self.fly.step(motion, dt, self.modifiers.shift_key());
            self.moved();
        } else if self.last_motion.is_some_and(|t| now - t > SETTLE) && self.drag.is_none() {
            self.last_motion = None;
            self.submit(false);
        }
    }
}

/// The movement of the keys `held`.
fn motion_of(held: impl IntoIterator<Item = Key>) -> Motion {
    let mut m = Motion::default();
    for k in held {
        match k {
            Key::Letter('w') | Key::Up => m.forward += 1.0,
            Key::Letter('s') | Key::Down => m.forward -= 1.0,
            Key::Letter('d') | Key::Right => m.right += 1.0,
            Key::Letter('a') | Key::Left => m.right -= 1.0,
            Key::PageUp => m.up += 1.0,
            Key::PageDown => m.up -= 1.0,
            _ => {}
        }
    }
    m
}

/// `name`, or `name` with `-2`, `-3`, ... before the extension if it exists.
fn unique_name(name: &str) -> PathBuf {
    let path = PathBuf::from(name);
    if !path.exists() {
        return path;
    }
    let stem = name.trim_end_matches(".png");
    (2..)
        .map(|k| PathBuf::from(format!("{stem}-{k}.png")))
        .find(|p| !p.exists())
        .expect("some name is free")
}

/// The viewer's key for a physical key.
pub(crate) fn key_of(code: KeyCode) -> Option<Key> {
    use KeyCode as C;
    Some(match code {
        C::Digit0 | C::Numpad0 => Key::Digit(0),
        C::Digit1 | C::Numpad1 => Key::Digit(1),
        C::Digit2 | C::Numpad2 => Key::Digit(2),
        C::Digit3 | C::Numpad3 => Key::Digit(3),
        C::Digit4 | C::Numpad4 => Key::Digit(4),
        C::Digit5 | C::Numpad5 => Key::Digit(5),
        C::Digit6 | C::Numpad6 => Key::Digit(6),
        C::Digit7 | C::Numpad7 => Key::Digit(7),
        C::Digit8 | C::Numpad8 => Key::Digit(8),
        C::Digit9 | C::Numpad9 => Key::Digit(9),
        C::KeyA => Key::Letter('a'),
        C::KeyB => Key::Letter('b'),
        C::KeyC => Key::Letter('c'),
        C::KeyD => Key::Letter('d'),
        C::KeyE => Key::Letter('e'),
        C::KeyH => Key::Letter('h'),
        C::KeyM => Key::Letter('m'),
        C::KeyP => Key::Letter('p'),
        C::KeyQ => Key::Letter('q'),
        C::KeyR => Key::Letter('r'),
        C::KeyS => Key::Letter('s'),
        C::KeyT => Key::Letter('t'),
        C::KeyV => Key::Letter('v'),
        C::KeyW => Key::Letter('w'),
        C::Tab => Key::Tab,
        C::Escape => Key::Escape,
        C::F12 => Key::F12,
        C::BracketLeft => Key::BracketLeft,
        C::BracketRight => Key::BracketRight,
        C::ArrowLeft => Key::Left,
        C::ArrowRight => Key::Right,
        C::ArrowUp => Key::Up,
        C::ArrowDown => Key::Down,
        C::PageUp => Key::PageUp,
        C::PageDown => Key::PageDown,
        _ => return None,
    })
}

impl ApplicationHandler<Rendered> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attrs = Window::default_attributes()
            .with_title(self.options.title.clone())
            .with_inner_size(PhysicalSize::new(self.options.size.0, self.options.size.1));
        let made = event_loop
            .create_window(attrs)
            .context("cannot create the window")
            .and_then(|w| {
                let w = Rc::new(w);
                let context = softbuffer::Context::new(w.clone())
                    .map_err(|e| anyhow!("cannot draw into the window: {e}"))?;
                let surface = softbuffer::Surface::new(&context, w.clone())
                    .map_err(|e| anyhow!("cannot draw into the window: {e}"))?;
                Ok((w, surface))
            });
        match made {
            Ok((w, surface)) => {
                self.window = Some(w);
                self.surface = Some(surface);
                self.submit(false);
            }
            Err(e) => {
                self.failure = Some(e);
                event_loop.exit();
            }
        }
    }

    fn user_event(&mut self, _event_loop: &ActiveEventLoop, r: Rendered) {
        if let Some(e) = r.error {
            self.error = Some(e);
        } else {
            self.error = r.notice.clone();
            // Frames of an older request still show (they are newer than what is on screen),
            // but only the current request's count towards --frames.
            let current = self.submitted.as_ref().map_or(0, |s| s.generation);
            self.fresh = r.generation == current;
            self.latest = Some(r);
        }
        self.request_redraw();
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => self.submit(self.last_motion.is_some()),
            WindowEvent::ModifiersChanged(m) => self.modifiers = m.state(),
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return;
                };
                let Some(key) = key_of(code) else { return };
                let press = Press {
                    key,
                    shift: self.modifiers.shift_key(),
                };
                match event.state {
                    ElementState::Pressed => {
                        let repeatable = matches!(key, Key::BracketLeft | Key::BracketRight);
                        if !event.repeat || repeatable {
                            self.key(event_loop, press);
                        }
                    }
                    ElementState::Released => {
                        self.held.remove(&key);
                    }
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                if state == ElementState::Pressed {
                    let (w, h) = self.size();
                    let near_divider = self.state.split
                        && part_rects(&self.state, w, h)
                            .get(1)
                            .is_some_and(|r| (self.cursor.0 - f64::from(r[0])).abs() <= 6.0);
                    self.drag = Some(if near_divider {
                        Drag::Divider
                    } else {
                        Drag::Look
                    });
                } else {
                    self.drag = None;
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (dx, dy) = (position.x - self.cursor.0, position.y - self.cursor.1);
                self.cursor = (position.x, position.y);
                match self.drag {
                    Some(Drag::Look) => {
                        self.fly.look(
                            dx as f32 * LOOK_DEG_PER_PIXEL,
                            -dy as f32 * LOOK_DEG_PER_PIXEL,
                        );
                        self.moved();
                    }
                    Some(Drag::Divider) => {
                        let w = self.size().0 as f32;
                        self.state.divider = (position.x as f32 / w).clamp(0.05, 0.95);
                        self.moved();
                    }
                    None => {}
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.fly.zoom(-2.5 * lines);
                self.moved();
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.present() {
                    self.failure = Some(e);
                    event_loop.exit();
                    return;
                }
                if std::mem::take(&mut self.fresh) {
                    self.presented += 1;
                    let now = Instant::now();
                    self.frame_times.push(now);
                    self.frame_times
                        .retain(|t| now - *t < Duration::from_secs(1));
                    self.shown = Some((self.shown.map_or(now, |s| s.0), now));
                    let full = self.latest.as_ref().is_some_and(|r| r.scale == 1);
                    if let (true, Some(r)) = (full, &self.latest) {
                        self.full_ms.push(r.ms);
                    }
                    if full && self.options.max_frames.is_some_and(|m| self.presented >= m) {
                        event_loop.exit();
                    }
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        self.tick();
        if !self.held.is_empty() || self.last_motion.is_some() {
            event_loop.set_control_flow(ControlFlow::WaitUntil(
                Instant::now() + Duration::from_millis(15),
            ));
        } else {
            event_loop.set_control_flow(ControlFlow::Wait);
        }
    }

    fn exiting(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(path) = self.options.screenshot.clone() {
            if let Err(e) = self.write_screenshot(&path) {
                self.failure.get_or_insert(
                    e.context(format!("cannot write the screenshot {}", path.display())),
                );
            }
        }
    }
}
