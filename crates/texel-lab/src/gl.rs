//! A student's shaders on real OpenGL: a context without a window through EGL (Mesa's llvmpipe on
//! a machine without a GPU, a GPU's own driver where there is one), the scene's triangles, the
//! texture with texel's own mip levels (`GL_NEAREST` filters, no anisotropy, so only the shader
//! filters), one frame per mode read back, and a capture pass that records what the student's
//! fragment shader receives: the interpolated coordinate and its `dFdx` / `dFdy` at every pixel.
//!
//! Every call into the driver is `unsafe` (raw OpenGL and EGL through `glow` and `khronos-egl`);
//! the safety argument is the same for all: the context is current on this thread for the
//! [`Gl`]'s lifetime, every object named was created by that context, and every slice handed to
//! the driver is as long as the size passed with it.
#![allow(unsafe_code)]

use std::time::Instant;

use glow::HasContext;
use khronos_egl as egl;

use crate::source::{version_of, GlslVersion};

/// Why the GL path failed.
#[derive(Debug, thiserror::Error)]
pub enum GlError {
    /// No EGL library or no OpenGL context could be made.
    #[error("OpenGL through EGL is not available: {0} (on Debian: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri)")]
    Unavailable(String),
    /// A shader did not compile; the driver's log.
    #[error("the {stage} shader does not compile:\n{log}")]
    Compile {
        /// `vertex` or `fragment`.
        stage: &'static str,
        /// The driver's info log.
        log: String,
    },
    /// The program did not link; the driver's log.
    #[error("the shaders do not link:\n{0}")]
    Link(String),
    /// The shader lacks part of the lab's interface.
    #[error("{0}")]
    Interface(String),
    /// The driver reported an error.
    #[error("OpenGL error: {0}")]
    Failed(String),
}

/// The names the student's shaders use for the lab's interface.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Names {
    /// The texture's sampler uniform (`texSlot`).
    pub sampler: String,
    /// The mode uniform (`texMode`).
    pub mode: String,
    /// The texture coordinate passed from the vertex to the fragment shader (`texCoord`).
    pub varying: String,
}

impl Default for Names {
    fn default() -> Self {
        Names {
            sampler: "texSlot".into(),
            mode: "texMode".into(),
            varying: "texCoord".into(),
        }
    }
}

/// The vertex attributes and uniform texel's draw feeds a vertex shader (texel's own, or the
/// student's `--vertex`): `position` (vec3, world space), `texCoordIn` (vec2, texel's uv: `(0, 0)`
/// the top-left of the image) and `clipFromWorld` (mat4).
pub const ATTRIBUTES: (&str, &str, &str) = ("position", "texCoordIn", "clipFromWorld");

/// One draw: triangles of one texture.
#[derive(Clone, Debug)]
pub struct GlDraw {
    /// World-space positions.
    pub positions: Vec<[f32; 3]>,
    /// Texture coordinates, one per position.
    pub uvs: Vec<[f32; 2]>,
    /// Three indices per triangle.
    pub indices: Vec<u32>,
    /// The texture's levels, finest first: width, height, RGBA8 codes row by row (row 0 the top
    /// of the image, which `texelFetch` row 0 reads).
    pub levels: Vec<(u32, u32, Vec<[u8; 4]>)>,
}

/// What one scene gives the device.
#[derive(Clone, Debug)]
pub struct GlScene {
    /// Frame width in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// The clear colour, RGBA8.
    pub background: [u8; 4],
    /// World to clip space (column major), as texel's renderer uses it.
    pub clip_from_world: [f32; 16],
    /// The draws.
    pub draws: Vec<GlDraw>,
}

/// What the student's fragment shader receives at each pixel, top row first.
#[derive(Clone, Debug, Default)]
pub struct Capture {
    /// Per pixel: `u, v, du/dx, dv/dx` (`x` to the right).
    pub uv_dx: Vec<[f32; 4]>,
    /// Per pixel: `du/dy, dv/dy` (`y` down, as texel's footprints have it), the draw's index plus
    /// one (0 where nothing covers the pixel), 0.
    pub dy_draw: Vec<[f32; 4]>,
}

/// An OpenGL context without a window, current on the thread that made it.
pub struct Gl {
    egl: egl::DynamicInstance<egl::EGL1_4>,
    display: egl::Display,
    context: egl::Context,
    gl: glow::Context,
}

/// EGL_PLATFORM_SURFACELESS_MESA.
const PLATFORM_SURFACELESS: egl::Enum = 0x31DD;

impl Gl {
    /// Make a desktop OpenGL context (compatibility profile, the driver's highest version, so
    /// that every GLSL version from 110 up that the driver has compiles).
    ///
    /// # Errors
    /// [`GlError::Unavailable`].
    pub fn new() -> Result<Gl, GlError> {
        let unavailable = |e: &dyn std::fmt::Display| GlError::Unavailable(e.to_string());
        // SAFETY: loads libEGL and resolves its entry points; no other code runs in between.
        let egl = unsafe { egl::DynamicInstance::<egl::EGL1_4>::load_required() }
            .map_err(|e| unavailable(&e))?;
        let display = Self::display(&egl)?;
        egl.initialize(display).map_err(|e| unavailable(&e))?;
        egl.bind_api(egl::OPENGL_API).map_err(|e| unavailable(&e))?;
        // EGL_SURFACE_TYPE defaults to windows; a context without a window needs none (texel
        // renders into its own framebuffer), so pbuffer configurations or any are asked for.
        let mut config = None;
        for surface in [egl::PBUFFER_BIT, 0] {
            let attribs = [
                egl::SURFACE_TYPE,
                surface,
                egl::RENDERABLE_TYPE,
                egl::OPENGL_BIT,
                egl::NONE,
            ];
            config = egl
                .choose_first_config(display, &attribs)
                .map_err(|e| unavailable(&e))?;
            if config.is_some() {
                break;
            }
        }
        let config = config.ok_or_else(|| unavailable(&"no EGL configuration renders OpenGL"))?;
        let context = egl
            .create_context(display, config, None, &[egl::NONE])
            .map_err(|e| unavailable(&e))?;
        egl.make_current(display, None, None, Some(context))
            .map_err(|e| unavailable(&format!("{e} (no surfaceless context)")))?;
        // SAFETY: the context is current; the loader returns entry points of its library.
        let gl = unsafe {
            glow::Context::from_loader_function_cstr(|name| {
                egl.get_proc_address(name.to_str().unwrap_or(""))
                    .map_or(std::ptr::null(), |f| f as *const std::ffi::c_void)
            })
        };
        Ok(Gl {
            egl,
            display,
            context,
            gl,
        })
    }

    fn display(egl: &egl::DynamicInstance<egl::EGL1_4>) -> Result<egl::Display, GlError> {
        if let Some(egl15) = egl.upcast::<egl::EGL1_5>() {
            // SAFETY: the surfaceless platform takes the default display and no attributes.
            let d = unsafe {
                egl15.get_platform_display(
                    PLATFORM_SURFACELESS,
                    egl::DEFAULT_DISPLAY,
                    &[egl::ATTRIB_NONE],
                )
            };
            if let Ok(d) = d {
                return Ok(d);
            }
        }
        // SAFETY: the default display needs no native handle.
        unsafe { egl.get_display(egl::DEFAULT_DISPLAY) }
            .ok_or_else(|| GlError::Unavailable("no EGL display".into()))
    }

    /// The driver: `GL_RENDERER` and `GL_VERSION`.
    pub fn driver(&self) -> (String, String) {
        // SAFETY: see the module docs.
        unsafe {
            (
                self.gl.get_parameter_string(glow::RENDERER),
                self.gl.get_parameter_string(glow::VERSION),
            )
        }
    }

    fn compile(&self, stage: u32, source: &str) -> Result<glow::Shader, GlError> {
        let name = if stage == glow::VERTEX_SHADER {
            "vertex"
        } else {
            "fragment"
        };
        // SAFETY: see the module docs.
        unsafe {
            let s = self.gl.create_shader(stage).map_err(GlError::Failed)?;
            self.gl.shader_source(s, source);
            self.gl.compile_shader(s);
            if !self.gl.get_shader_compile_status(s) {
                let log = self.gl.get_shader_info_log(s);
                self.gl.delete_shader(s);
                return Err(GlError::Compile { stage: name, log });
            }
            Ok(s)
        }
    }

    /// Link `vertex` and `fragment` with texel's attribute locations (0 position, 1 texCoordIn)
    /// and, for the capture shader, its two outputs.
    fn link(
        &self,
        vertex: &str,
        fragment: &str,
        outputs: &[&str],
    ) -> Result<glow::Program, GlError> {
        let vs = self.compile(glow::VERTEX_SHADER, vertex)?;
        let fs = self.compile(glow::FRAGMENT_SHADER, fragment)?;
        // SAFETY: see the module docs.
        unsafe {
            let p = self.gl.create_program().map_err(GlError::Failed)?;
            self.gl.attach_shader(p, vs);
            self.gl.attach_shader(p, fs);
            self.gl.bind_attrib_location(p, 0, ATTRIBUTES.0);
            self.gl.bind_attrib_location(p, 1, ATTRIBUTES.1);
            for (k, o) in outputs.iter().enumerate() {
                self.gl.bind_frag_data_location(p, k as u32, o);
            }
            self.gl.link_program(p);
            self.gl.delete_shader(vs);
            self.gl.delete_shader(fs);
            if !self.gl.get_program_link_status(p) {
                let log = self.gl.get_program_info_log(p);
                self.gl.delete_program(p);
                return Err(GlError::Link(log));
            }
            Ok(p)
        }
    }

    fn check(&self, what: &str) -> Result<(), GlError> {
        // SAFETY: see the module docs.
        let e = unsafe { self.gl.get_error() };
        if e == glow::NO_ERROR {
            Ok(())
        } else {
            Err(GlError::Failed(format!("{what}: error 0x{e:04X}")))
        }
    }
}

impl Drop for Gl {
    fn drop(&mut self) {
        let _ = self.egl.make_current(self.display, None, None, None);
        let _ = self.egl.destroy_context(self.display, self.context);
        let _ = self.egl.terminate(self.display);
    }
}

/// texel's vertex shader for a fragment shader of `version`, writing the coordinate to `varying`.
pub fn vertex_shader(version: &GlslVersion, varying: &str) -> String {
    let (a, o) = if version.has_in_out() {
        ("in", "out")
    } else {
        ("attribute", "varying")
    };
    let (p, t, m) = ATTRIBUTES;
    format!(
        "{line}\n// texel's vertex shader: the world-space position and texel's uv, unchanged.\n\
         {a} vec3 {p};\n{a} vec2 {t};\nuniform mat4 {m};\n{o} vec2 {varying};\n\
         void main() {{\n    {varying} = {t};\n    gl_Position = {m} * vec4({p}, 1.0);\n}}\n",
        line = version.line()
    )
}

/// The capture pass's fragment shader: the coordinate and its derivatives, as the student's
/// fragment shader would compute them from the same varying.
fn capture_shader(version: &GlslVersion, varying: &str) -> (String, &'static [&'static str]) {
    let body = |a: &str, b: &str| {
        format!(
            "uniform float texelDrawIndex;\nvoid main() {{\n    vec2 dx = dFdx({varying});\n    \
             vec2 dy = dFdy({varying});\n    {a} = vec4({varying}, dx);\n    \
             {b} = vec4(-dy, texelDrawIndex, 0.0);\n}}\n"
        )
    };
    if version.has_in_out() {
        let layout = if version.es || version.number >= 330 {
            ("layout(location = 0) ", "layout(location = 1) ")
        } else {
            ("", "")
        };
        let precision = if version.es {
            "precision highp float;\n"
        } else {
            ""
        };
        (
            format!(
                "{}\n{precision}in vec2 {varying};\n{}out vec4 captureA;\n{}out vec4 captureB;\n{}",
                version.line(),
                layout.0,
                layout.1,
                body("captureA", "captureB")
            ),
            &["captureA", "captureB"],
        )
    } else {
        (
            format!(
                "{}\nvarying vec2 {varying};\n{}",
                version.line(),
                body("gl_FragData[0]", "gl_FragData[1]")
            ),
            &[],
        )
    }
}

/// One uploaded draw.
struct Uploaded {
    vao: glow::VertexArray,
    buffers: [glow::Buffer; 3],
    texture: glow::Texture,
    count: i32,
}

/// The student's shaders linked and a scene uploaded, with render targets of its size.
pub struct ShaderDraws<'g> {
    gl: &'g Gl,
    student: glow::Program,
    capture: glow::Program,
    draws: Vec<Uploaded>,
    framebuffer: glow::Framebuffer,
    renderbuffers: Vec<glow::Renderbuffer>,
    scene: (u32, u32, [u8; 4], [f32; 16]),
    names: Names,
}

impl Gl {
    /// Link the student's `fragment` shader (and `vertex`, or texel's own for its GLSL version)
    /// and upload `scene`.
    ///
    /// # Errors
    /// [`GlError::Compile`], [`GlError::Link`]; [`GlError::Interface`] when the program has no
    /// active mode uniform or sampler uniform under `names`; [`GlError::Failed`].
    pub fn prepare(
        &self,
        fragment: &str,
        vertex: Option<&str>,
        names: &Names,
        scene: &GlScene,
    ) -> Result<ShaderDraws<'_>, GlError> {
        let version = version_of(fragment);
        let own;
        let vertex = match vertex {
            Some(v) => v,
            None => {
                own = vertex_shader(&version, &names.varying);
                &own
            }
        };
        let student = self.link(vertex, fragment, &[])?;
        let gl = &self.gl;
        // SAFETY: see the module docs.
        unsafe {
            for (what, name) in [("mode", &names.mode), ("sampler", &names.sampler)] {
                if gl.get_uniform_location(student, name).is_none() {
                    gl.delete_program(student);
                    return Err(GlError::Interface(format!(
                        "the fragment shader has no active {what} uniform `{name}` (declare it and use it; \
                         --{} names another)",
                        if what == "mode" { "mode-uniform" } else { "sampler" }
                    )));
                }
            }
        }
        let vversion = version_of(vertex);
        let (capture_fs, outputs) = capture_shader(&vversion, &names.varying);
        let capture = self.link(vertex, &capture_fs, outputs)?;
        let mut prepared = ShaderDraws {
            gl: self,
            student,
            capture,
            draws: Vec::new(),
            framebuffer: unsafe { gl.create_framebuffer() }.map_err(GlError::Failed)?,
            renderbuffers: Vec::new(),
            scene: (
                scene.width,
                scene.height,
                scene.background,
                scene.clip_from_world,
            ),
            names: names.clone(),
        };
        for d in &scene.draws {
            let up = prepared.upload(d)?;
            prepared.draws.push(up);
        }
        prepared.targets()?;
        Ok(prepared)
    }
}

fn bytes<T: Copy, const N: usize>(v: &[[T; N]], f: impl Fn(T) -> [u8; 4]) -> Vec<u8> {
    v.iter().flatten().flat_map(|&x| f(x)).collect()
}

impl ShaderDraws<'_> {
    fn upload(&self, d: &GlDraw) -> Result<Uploaded, GlError> {
        let gl = &self.gl.gl;
        // SAFETY: see the module docs; each buffer holds exactly the bytes the attribute
        // pointers and the index count describe.
        unsafe {
            let vao = gl.create_vertex_array().map_err(GlError::Failed)?;
            gl.bind_vertex_array(Some(vao));
            let mut buffers = Vec::new();
            for (k, (data, size)) in [
                (bytes(&d.positions, f32::to_le_bytes), 3),
                (bytes(&d.uvs, f32::to_le_bytes), 2),
            ]
            .into_iter()
            .enumerate()
            {
                let b = gl.create_buffer().map_err(GlError::Failed)?;
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(b));
                gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, &data, glow::STATIC_DRAW);
                gl.vertex_attrib_pointer_f32(k as u32, size, glow::FLOAT, false, 0, 0);
                gl.enable_vertex_attrib_array(k as u32);
                buffers.push(b);
            }
            let ib = gl.create_buffer().map_err(GlError::Failed)?;
            gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(ib));
            let idx: Vec<u8> = d.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
            gl.buffer_data_u8_slice(glow::ELEMENT_ARRAY_BUFFER, &idx, glow::STATIC_DRAW);
            buffers.push(ib);
            gl.bind_vertex_array(None);
            let texture = gl.create_texture().map_err(GlError::Failed)?;
            gl.bind_texture(glow::TEXTURE_2D, Some(texture));
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            for (k, (w, h, texels)) in d.levels.iter().enumerate() {
                let data: Vec<u8> = texels.iter().flatten().copied().collect();
                gl.tex_image_2d(
                    glow::TEXTURE_2D,
                    k as i32,
                    glow::RGBA8 as i32,
                    *w as i32,
                    *h as i32,
                    0,
                    glow::RGBA,
                    glow::UNSIGNED_BYTE,
                    glow::PixelUnpackData::Slice(Some(&data)),
                );
            }
            let last = d.levels.len().saturating_sub(1) as i32;
            for (p, v) in [
                (
                    glow::TEXTURE_MIN_FILTER,
                    glow::NEAREST_MIPMAP_NEAREST as i32,
                ),
                (glow::TEXTURE_MAG_FILTER, glow::NEAREST as i32),
                (glow::TEXTURE_WRAP_S, glow::REPEAT as i32),
                (glow::TEXTURE_WRAP_T, glow::REPEAT as i32),
                (glow::TEXTURE_BASE_LEVEL, 0),
                (glow::TEXTURE_MAX_LEVEL, last),
            ] {
                gl.tex_parameter_i32(glow::TEXTURE_2D, p, v);
            }
            self.gl.check("uploading the scene")?;
            Ok(Uploaded {
                vao,
                buffers: [buffers[0], buffers[1], buffers[2]],
                texture,
                count: d.indices.len() as i32,
            })
        }
    }

    /// The frame's render targets: an RGBA8 colour, two RGBA32F capture targets, a depth buffer.
    fn targets(&mut self) -> Result<(), GlError> {
        let gl = &self.gl.gl;
        let (w, h) = (self.scene.0 as i32, self.scene.1 as i32);
        // SAFETY: see the module docs.
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.framebuffer));
            for (attachment, format) in [
                (glow::COLOR_ATTACHMENT0, glow::RGBA8),
                (glow::COLOR_ATTACHMENT1, glow::RGBA32F),
                (glow::COLOR_ATTACHMENT2, glow::RGBA32F),
                (glow::DEPTH_ATTACHMENT, glow::DEPTH_COMPONENT24),
            ] {
                let rb = gl.create_renderbuffer().map_err(GlError::Failed)?;
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
                gl.renderbuffer_storage(glow::RENDERBUFFER, format, w, h);
                gl.framebuffer_renderbuffer(
                    glow::FRAMEBUFFER,
                    attachment,
                    glow::RENDERBUFFER,
                    Some(rb),
                );
                self.renderbuffers.push(rb);
            }
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            if status != glow::FRAMEBUFFER_COMPLETE {
                return Err(GlError::Failed(format!(
                    "the {w}x{h} render targets are incomplete (0x{status:04X})"
                )));
            }
            gl.viewport(0, 0, w, h);
            gl.enable(glow::DEPTH_TEST);
            gl.depth_func(glow::LESS);
        }
        self.gl.check("making the render targets")
    }

    /// Draw every draw with `program` into the attachments `buffers` (after clearing them).
    fn draw(&self, program: glow::Program, buffers: &[u32], mode: Option<i32>) {
        let gl = &self.gl.gl;
        let (_, _, bg, m) = self.scene;
        // SAFETY: see the module docs.
        unsafe {
            gl.draw_buffers(buffers);
            let c = |k: usize| f32::from(bg[k]) / 255.0;
            if buffers[0] == glow::COLOR_ATTACHMENT0 {
                gl.clear_color(c(0), c(1), c(2), c(3));
            } else {
                gl.clear_color(0.0, 0.0, 0.0, 0.0);
            }
            gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
            gl.use_program(Some(program));
            let matrix = gl.get_uniform_location(program, ATTRIBUTES.2);
            gl.uniform_matrix_4_f32_slice(matrix.as_ref(), false, &m);
            let sampler = gl.get_uniform_location(program, &self.names.sampler);
            gl.uniform_1_i32(sampler.as_ref(), 0);
            if let Some(mode) = mode {
                let loc = gl.get_uniform_location(program, &self.names.mode);
                gl.uniform_1_i32(loc.as_ref(), mode);
            }
            let draw_index = gl.get_uniform_location(program, "texelDrawIndex");
            gl.active_texture(glow::TEXTURE0);
            for (k, d) in self.draws.iter().enumerate() {
                if let Some(l) = &draw_index {
                    gl.uniform_1_f32(Some(l), (k + 1) as f32);
                }
                gl.bind_texture(glow::TEXTURE_2D, Some(d.texture));
                gl.bind_vertex_array(Some(d.vao));
                gl.draw_elements(glow::TRIANGLES, d.count, glow::UNSIGNED_INT, 0);
            }
            gl.bind_vertex_array(None);
        }
    }

    /// The RGBA pixels of `attachment` as `ty` (`bytes` a pixel), top row first.
    fn read(&self, attachment: u32, ty: u32, bytes: usize) -> Vec<u8> {
        let gl = &self.gl.gl;
        let (w, h) = (self.scene.0 as usize, self.scene.1 as usize);
        let mut raw = vec![0u8; bytes * w * h];
        // SAFETY: `raw` holds exactly `w * h` RGBA pixels of `ty`.
        unsafe {
            gl.read_buffer(attachment);
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            gl.read_pixels(
                0,
                0,
                w as i32,
                h as i32,
                glow::RGBA,
                ty,
                glow::PixelPackData::Slice(Some(&mut raw)),
            );
        }
        // GL's row 0 is the bottom of the frame; texel's is the top.
        raw.chunks_exact(bytes * w)
            .rev()
            .flatten()
            .copied()
            .collect()
    }

    /// What the student's fragment shader receives at each pixel.
    ///
    /// # Errors
    /// [`GlError::Failed`].
    pub fn capture(&self) -> Result<Capture, GlError> {
        self.draw(
            self.capture,
            &[glow::COLOR_ATTACHMENT1, glow::COLOR_ATTACHMENT2],
            None,
        );
        let uv_dx = floats(&self.read(glow::COLOR_ATTACHMENT1, glow::FLOAT, 16));
        let dy_draw = floats(&self.read(glow::COLOR_ATTACHMENT2, glow::FLOAT, 16));
        self.gl.check("the capture pass")?;
        Ok(Capture { uv_dx, dy_draw })
    }

    /// Move the camera: the frames drawn after this call see the scene through `clip_from_world`.
    pub fn set_clip_from_world(&mut self, clip_from_world: [f32; 16]) {
        self.scene.3 = clip_from_world;
    }

    /// Make the render targets `width x height` (nothing is done at the current size).
    ///
    /// # Errors
    /// [`GlError::Failed`] when the driver refuses the size.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), GlError> {
        if (width, height) == (self.scene.0, self.scene.1) {
            return Ok(());
        }
        // SAFETY: see the module docs; the renderbuffers were made by these draws.
        unsafe {
            for rb in self.renderbuffers.drain(..) {
                self.gl.gl.delete_renderbuffer(rb);
            }
        }
        self.scene.0 = width;
        self.scene.1 = height;
        let made = self.targets();
        if made.is_err() {
            // No targets of any size now: the next call makes them again.
            self.scene.0 = 0;
            self.scene.1 = 0;
        }
        made
    }

    /// One frame of the student's shader in `mode`, top row first.
    ///
    /// # Errors
    /// [`GlError::Failed`].
    pub fn draw_frame(&self, mode: i32) -> Result<Vec<[u8; 4]>, GlError> {
        self.draw(self.student, &[glow::COLOR_ATTACHMENT0], Some(mode));
        self.student_image()
    }

    /// The student's frame as drawn last, top row first.
    fn student_image(&self) -> Result<Vec<[u8; 4]>, GlError> {
        let image = self
            .read(glow::COLOR_ATTACHMENT0, glow::UNSIGNED_BYTE, 4)
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        self.gl.check("the student's frame")?;
        Ok(image)
    }

    /// The student's frame in `mode`, top row first, and the median time of `frames` frames in
    /// milliseconds (each drawn and finished; the first, which compiles the driver's code, not
    /// counted).
    ///
    /// # Errors
    /// [`GlError::Failed`].
    pub fn frame(&self, mode: i32, frames: usize) -> Result<(Vec<[u8; 4]>, f64), GlError> {
        let gl = &self.gl.gl;
        let mut times = Vec::new();
        for k in 0..=frames.max(1) {
            let start = Instant::now();
            self.draw(self.student, &[glow::COLOR_ATTACHMENT0], Some(mode));
            // SAFETY: see the module docs.
            unsafe { gl.finish() };
            if k > 0 {
                times.push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        times.sort_by(f64::total_cmp);
        Ok((self.student_image()?, times[times.len() / 2]))
    }
}

impl Drop for ShaderDraws<'_> {
    fn drop(&mut self) {
        let gl = &self.gl.gl;
        // SAFETY: see the module docs; every object was made by these draws.
        unsafe {
            for d in &self.draws {
                gl.delete_vertex_array(d.vao);
                for b in d.buffers {
                    gl.delete_buffer(b);
                }
                gl.delete_texture(d.texture);
            }
            for rb in &self.renderbuffers {
                gl.delete_renderbuffer(*rb);
            }
            gl.delete_framebuffer(self.framebuffer);
            gl.delete_program(self.student);
            gl.delete_program(self.capture);
        }
    }
}

/// RGBA32F pixels from the driver's bytes (native endian).
fn floats(raw: &[u8]) -> Vec<[f32; 4]> {
    raw.chunks_exact(16)
        .map(|c| {
            let f =
                |k: usize| f32::from_ne_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]]);
            [f(0), f(1), f(2), f(3)]
        })
        .collect()
}
