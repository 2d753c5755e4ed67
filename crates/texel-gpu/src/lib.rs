//! texel-gpu: texel's filters as WGSL shaders on any Vulkan or GL device, through wgpu.
//!
//! The fragment shader (`shaders/filters.wgsl`) reads the texture only through `textureLoad`,
//! `textureDimensions` and `textureNumLevels` — the filtering lab's rule — so every filter's
//! arithmetic is written out: one function per technique (nearest, bilinear, mip-nearest,
//! trilinear, anisotropic 2x-16x, bicubic, EWA), address modes on integer texel indices and the sRGB
//! decode through the CPU's own 256-entry table, as `docs/guide/conventions.md` fixes them.
//! Modes 1-8 follow either convention of the CPU's samplers (`CONVENTION`, a pipeline constant:
//! the GL rules, or the lab's formulas of `texel_texture::technique::lab`). The pyramid is
//! texel-texture's, uploaded level by level in the texture's own format (`Rgba8Unorm` codes or
//! `Rgba32Float`), so both paths filter the same texels. The hardware sampler is the peer
//! ([`GpuFilter::HwTrilinear`], [`GpuFilter::HwAniso16`]: `textureSampleGrad`).
//!
//! Geometry is the CPU path's: the same vertices and `clip_from_world`, the device clipping,
//! depth-testing and interpolating perspective-correctly. Derivatives are the device's 2x2 quad
//! differences (`dpdxFine`/`dpdyFine`), so the CPU frame to compare with is rendered with
//! [`texel_raster::Derivatives::Quad`].
//!
//! ```no_run
//! # fn main() -> Result<(), texel_gpu::GpuError> {
//! let gpu = texel_gpu::Gpu::new(None)?; // or Some("llvmpipe"), or TEXEL_ADAPTER
//! println!("{}", gpu.info());
//! # Ok(()) }
//! ```

use std::cell::RefCell;
use std::fmt;
use std::sync::mpsc;

use texel_raster::{DrawCall, Frame, RenderSettings, View};
use texel_texture::{
    AddressMode, Filter, FilterMode, Format, LevelTexels, MipmapFilterMode, SamplerDescriptor,
    Texture,
};

/// Environment variable that picks an adapter by name (a case-insensitive substring), as
/// `--adapter` does.
pub const ADAPTER_ENV: &str = "TEXEL_ADAPTER";

/// The WGSL source of every filter.
pub const SHADER: &str = include_str!("../shaders/filters.wgsl");

/// What can go wrong on the GPU path.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No Vulkan or GL adapter at all.
    #[error(
        "no GPU adapter found (Vulkan or GL); on Debian install a driver, e.g. \
         `apt-get install mesa-vulkan-drivers` for Mesa's lavapipe on the CPU"
    )]
    NoAdapter,
    /// No adapter's name contains the requested one.
    #[error("no GPU adapter named like {wanted:?}; available: {available}")]
    AdapterNotFound {
        /// The requested name.
        wanted: String,
        /// The adapters there are, comma-separated.
        available: String,
    },
    /// The device could not be created.
    #[error("could not create a device on {adapter}: {reason}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// wgpu's reason.
        reason: String,
    },
    /// A texture or the frame exceeds the device's 2D texture limit.
    #[error("{what} is {width}x{height}, over this device's limit of {max} texels a side")]
    TooLarge {
        /// What was too large.
        what: &'static str,
        /// Its width.
        width: u32,
        /// Its height.
        height: u32,
        /// The device's `max_texture_dimension_2d`.
        max: u32,
    },
    /// The render settings are invalid ([`texel_raster::RenderSettings::validate`]).
    #[error(transparent)]
    Settings(#[from] texel_raster::RasterError),
    /// What the GPU path does not render (lighting, debug views, counting texels).
    #[error("the GPU path does not support {0}")]
    Unsupported(&'static str),
    /// The device reported an error or was lost while rendering.
    #[error("the GPU failed while rendering: {0}")]
    Failed(String),
}

/// What the GPU path renders with: one of texel's filters evaluated by the shader, or the
/// device's own sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuFilter {
    /// A texel filter, evaluated by `filters.wgsl` from texel fetches (every filter but the
    /// ripmap and the summed-area table: [`GpuFilter::of`]).
    Shader(Filter),
    /// The device's sampler, trilinear (`textureSampleGrad`).
    HwTrilinear,
    /// The device's sampler, trilinear with `anisotropy_clamp` 16.
    HwAniso16,
}

/// The shader's mode (`MODE` and `params.mode.x` in `filters.wgsl`) and its anisotropy clamp
/// (`params.mode.z`), read off the sampler descriptor a filter means: 1 nearest, 2 bilinear, 3
/// mip-nearest, 4 trilinear, 5-8 anisotropic 2x-16x, 9 bicubic, 10 EWA; `None` where the shader
/// has no such filter.
pub fn shader_mode(d: &SamplerDescriptor) -> Option<(u32, u32)> {
    use FilterMode::{Cubic, Ewa, EwaProbes, Linear, Nearest};
    use MipmapFilterMode as Mip;
    let aniso = u32::from(d.anisotropy_clamp);
    let mode = match (d.min_filter, d.mipmap_filter, aniso) {
        (Nearest, Mip::None, 1) => 1,
        (Linear, Mip::None, 1) => 2,
        (Linear, Mip::Nearest, 1) => 3,
        (Linear, Mip::Linear, 1) => 4,
        (Linear, Mip::Linear, 2 | 4 | 8 | 16) => 4 + aniso.trailing_zeros(),
        (Cubic(_), Mip::None, 1) => 9,
        (Ewa, _, _) => 10,
        (EwaProbes, _, _) => 11,
        _ => return None,
    };
    Some((mode, aniso))
}

impl GpuFilter {
    /// The GPU path's version of texel's `filter`, if it has one (every filter but the ripmap and
    /// the summed-area table).
    pub fn of(filter: Filter) -> Option<GpuFilter> {
        let d = filter.descriptor(AddressMode::ClampToEdge, AddressMode::ClampToEdge);
        shader_mode(&d).map(|_| GpuFilter::Shader(filter))
    }

    /// Every texel filter the GPU path has, in [`Filter::ALL`]'s order.
    pub fn filters() -> impl Iterator<Item = Filter> {
        Filter::ALL
            .into_iter()
            .filter(|&f| GpuFilter::of(f).is_some())
    }

    /// The shader's mode number and anisotropy clamp; `None` for a texel filter the shader
    /// lacks (the ripmap and the summed-area table, which [`GpuFilter::of`] refuses and
    /// [`Gpu::prepare`] rejects).
    fn shader(self) -> Option<(u32, u32)> {
        match self {
            GpuFilter::Shader(f) => {
                shader_mode(&f.descriptor(AddressMode::ClampToEdge, AddressMode::ClampToEdge))
            }
            GpuFilter::HwTrilinear => Some((20, 1)),
            GpuFilter::HwAniso16 => Some((21, 16)),
        }
    }

    /// [`GpuFilter::shader`] of a filter [`Gpu::prepare`] accepted.
    fn mode(self) -> (u32, u32) {
        self.shader()
            .expect("Gpu::prepare rejects filters the shader lacks")
    }

    fn is_hardware(self) -> bool {
        matches!(self, GpuFilter::HwTrilinear | GpuFilter::HwAniso16)
    }
}

/// An adapter as [`adapters`] lists it.
#[derive(Clone, Debug)]
pub struct AdapterSummary {
    /// The adapter's name (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
    pub name: String,
    /// Vulkan or GL.
    pub backend: String,
    /// Discrete, integrated, virtual or CPU.
    pub device_type: String,
    /// Driver name and version.
    pub driver: String,
    /// Largest 2D texture side.
    pub max_texture_dimension_2d: u32,
}

impl fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} ({}, {}, driver {}; 2D textures up to {})",
            self.name, self.backend, self.device_type, self.driver, self.max_texture_dimension_2d
        )
    }
}

/// On a machine without a display, turn off Mesa's Vulkan device-select layer for this process
/// (its documented switch `NODEVICE_SELECT=1`, unless the user set it): the layer orders devices by
/// the display's GPU, and without a display it only tries a Wayland connection that prints
/// `error: XDG_RUNTIME_DIR is invalid or not set` on every instance. texel picks its adapter by
/// name itself.
fn quiet_headless_layers() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let unset = |k: &str| std::env::var_os(k).is_none_or(|v| v.is_empty());
        if unset("WAYLAND_DISPLAY")
            && unset("DISPLAY")
            && std::env::var_os("NODEVICE_SELECT").is_none()
        {
            std::env::set_var("NODEVICE_SELECT", "1");
        }
    });
}

/// The adapters of one backend.
fn enumerate(backends: wgpu::Backends) -> Vec<wgpu::Adapter> {
    quiet_headless_layers();
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends,
        ..wgpu::InstanceDescriptor::new_without_display_handle_from_env()
    });
    pollster::block_on(instance.enumerate_adapters(backends))
}

/// The Vulkan adapters, or where there are none the GL ones (probing GL through EGL makes Mesa
/// print warnings on a machine without a display, so it is not done when Vulkan suffices).
fn all_adapters() -> Vec<wgpu::Adapter> {
    let vulkan = enumerate(wgpu::Backends::VULKAN);
    if vulkan.is_empty() {
        enumerate(wgpu::Backends::GL)
    } else {
        vulkan
    }
}

fn summary(a: &wgpu::Adapter) -> AdapterSummary {
    let info = a.get_info();
    AdapterSummary {
        name: info.name,
        backend: format!("{:?}", info.backend),
        device_type: format!("{:?}", info.device_type),
        driver: format!("{} {}", info.driver, info.driver_info)
            .trim()
            .to_string(),
        max_texture_dimension_2d: a.limits().max_texture_dimension_2d,
    }
}

/// The Vulkan adapters on this machine, or where there are none the GL ones.
pub fn adapters() -> Vec<AdapterSummary> {
    all_adapters().iter().map(summary).collect()
}

/// A device to render on.
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    info: AdapterSummary,
    module: wgpu::ShaderModule,
    srgb: wgpu::Buffer,
    ewa_lut: wgpu::Buffer,
    /// The device writes timestamps around render passes (`Features::TIMESTAMP_QUERY`).
    timestamps: bool,
}

impl Gpu {
    /// Open the adapter whose name contains `name` (case-insensitive), or the one
    /// [`ADAPTER_ENV`] names, or else the first one, preferring real GPUs to software ones
    /// (Vulkan adapters; GL ones only where there is no Vulkan adapter).
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`], [`GpuError::AdapterNotFound`], [`GpuError::Device`].
    pub fn new(name: Option<&str>) -> Result<Gpu, GpuError> {
        let mut all = all_adapters();
        if all.is_empty() {
            return Err(GpuError::NoAdapter);
        }
        let wanted = name
            .map(str::to_string)
            .or_else(|| std::env::var(ADAPTER_ENV).ok().filter(|s| !s.is_empty()));
        let rank = |a: &wgpu::Adapter| {
            let i = a.get_info();
            let kind = match i.device_type {
                wgpu::DeviceType::DiscreteGpu => 0,
                wgpu::DeviceType::IntegratedGpu => 1,
                wgpu::DeviceType::VirtualGpu => 2,
                _ => 3,
            };
            (kind, i.backend != wgpu::Backend::Vulkan)
        };
        all.sort_by_key(rank);
        let adapter = match &wanted {
            Some(w) => {
                let lw = w.to_lowercase();
                let pos = all
                    .iter()
                    .position(|a| a.get_info().name.to_lowercase().contains(&lw));
                match pos {
                    Some(p) => all.swap_remove(p),
                    None => {
                        let names: Vec<String> = all.iter().map(|a| a.get_info().name).collect();
                        return Err(GpuError::AdapterNotFound {
                            wanted: w.clone(),
                            available: names.join(", "),
                        });
                    }
                }
            }
            None => all.swap_remove(0),
        };
        let info = summary(&adapter);
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("texel"),
            required_features: features,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device {
            adapter: info.name.clone(),
            reason: e.to_string(),
        })?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("filters.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });

        let table: Vec<u8> = texel_texture::base::color::srgb_table()
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let srgb = buffer(&device, &queue, &table, wgpu::BufferUsages::STORAGE);
        let lut: Vec<u8> = shader_tables()
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        let ewa_lut = buffer(&device, &queue, &lut, wgpu::BufferUsages::STORAGE);
        Ok(Gpu {
            device,
            queue,
            info,
            module,
            srgb,
            ewa_lut,
            timestamps: features.contains(wgpu::Features::TIMESTAMP_QUERY),
        })
    }

    /// The adapter in use.
    pub fn info(&self) -> &AdapterSummary {
        &self.info
    }

    /// `Err(TooLarge)` with both figures if `what` (`width x height`) exceeds the device's 2D
    /// texture limit.
    fn check_size(&self, what: &'static str, width: u32, height: u32) -> Result<(), GpuError> {
        let max = self.device.limits().max_texture_dimension_2d;
        if width > max || height > max {
            return Err(GpuError::TooLarge {
                what,
                width,
                height,
                max,
            });
        }
        Ok(())
    }

    /// Whether [`GpuDraws::render_timed`] and [`GpuDraws::pass_times`] can measure device time
    /// (timestamp queries).
    pub fn has_timestamps(&self) -> bool {
        self.timestamps
    }
}

/// Linear colour as f32 bit patterns: unsigned-integer targets are renderable on every device
/// (`Rgba32Float` is not on GL: Mesa's llvmpipe through wgpu's GL backend, for one), and the bits
/// read back are the shader's f32 values exactly.
const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
/// The fragment's NDC depth as f32 bits (`R32Float` is not renderable on GL either).
const FRAG_DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// position (3), uv (2), colour (4) as `f32`.
const VERTEX_FLOATS: usize = 9;

/// The convention the shader's modes 1-8 follow for `draws`: the one their samplers share
/// ([`texel_texture::Sampler::convention`]).
///
/// # Errors
/// [`GpuError::Unsupported`] for draws of both conventions, and for the lab convention with a
/// filter other than the lab's eight modes.
fn convention_of(
    draws: &[DrawCall],
    filter: GpuFilter,
) -> Result<texel_texture::Convention, GpuError> {
    use texel_texture::Convention;
    let lab = draws
        .iter()
        .filter(|d| d.sampler.convention() == Convention::Lab)
        .count();
    if lab == 0 {
        return Ok(Convention::Gl);
    }
    if lab < draws.len() {
        return Err(GpuError::Unsupported(
            "draws of both conventions in one pass (one pipeline has one)",
        ));
    }
    match filter {
        GpuFilter::Shader(_) if (1..=8).contains(&filter.mode().0) => Ok(Convention::Lab),
        _ => Err(GpuError::Unsupported(
            "the lab convention with a filter other than the lab's eight modes",
        )),
    }
}

/// The tables the shader reads from its storage buffer (binding 4): EWA's weight table, then
/// EWA from probes' positions, weights and spacings, each row padded to its 16 probes.
fn shader_tables() -> Vec<f32> {
    use texel_texture::technique::ewa_probes::{probe_table, MAX_PROBES};
    let t = probe_table();
    let mut out = texel_texture::technique::ewa::weight_lut().to_vec();
    out.extend(t.positions.iter().flatten());
    out.extend(t.weights.iter().flatten());
    out.extend(t.spacing.iter().map(|&x| x.min(f64::from(f32::MAX)) as f32));
    debug_assert_eq!(out.len(), 128 + 2 * MAX_PROBES * MAX_PROBES + MAX_PROBES);
    out
}

/// The pipeline of one shader mode (`MODE`) under one convention (`CONVENTION`), both pipeline
/// constants, with EWA's kernel scale (`KERNEL_SCALE`) the CPU's.
fn create_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    mode: u32,
    convention: texel_texture::Convention,
) -> wgpu::RenderPipeline {
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x2, 2 => Float32x4];
    let lab = convention == texel_texture::Convention::Lab;
    let constants = [
        ("MODE", f64::from(mode)),
        ("CONVENTION", f64::from(u8::from(lab))),
        ("KERNEL_SCALE", texel_texture::technique::ewa::KERNEL_SCALE),
    ];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("texel filters"),
        layout: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: (VERTEX_FLOATS * 4) as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attributes,
            })],
        },
        primitive: wgpu::PrimitiveState {
            front_face: wgpu::FrontFace::Ccw,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_main"),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            },
            targets: &[Some(COLOR.into()), Some(FRAG_DEPTH.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}

fn buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    bytes: &[u8],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let b = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: (bytes.len() as u64).max(4).next_multiple_of(4),
        usage: usage | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut padded = bytes.to_vec();
    padded.resize(b.size() as usize, 0);
    queue.write_buffer(&b, 0, &padded);
    b
}

fn address_code(mode: AddressMode) -> u32 {
    match mode {
        AddressMode::ClampToEdge => 0,
        AddressMode::Repeat => 1,
        AddressMode::MirrorRepeat => 2,
        AddressMode::ClampToBorder => 3,
        AddressMode::MirrorClampToEdge => 4,
    }
}

fn wgpu_address(mode: AddressMode) -> wgpu::AddressMode {
    match mode {
        AddressMode::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        AddressMode::Repeat => wgpu::AddressMode::Repeat,
        AddressMode::MirrorRepeat => wgpu::AddressMode::MirrorRepeat,
        // The device's border colours are a fixed few; the hardware rows use transparent black.
        AddressMode::ClampToBorder => wgpu::AddressMode::ClampToBorder,
        AddressMode::MirrorClampToEdge => wgpu::AddressMode::MirrorRepeat,
    }
}

/// Upload `texture`'s pyramid, level by level, in its own format (`hardware`: an sRGB format for
/// 8-bit sRGB textures, so that the device's sampler decodes).
fn upload(gpu: &Gpu, texture: &Texture, hardware: bool) -> Result<wgpu::Texture, GpuError> {
    let (w, h) = (texture.width(), texture.height());
    gpu.check_size("a texture", w, h)?;
    let format = match texture.format() {
        Format::Rgba32Float => wgpu::TextureFormat::Rgba32Float,
        Format::Rgba8Srgb if hardware => wgpu::TextureFormat::Rgba8UnormSrgb,
        _ => wgpu::TextureFormat::Rgba8Unorm,
    };
    let levels = texture.levels().len() as u32;
    let t = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("texel texture"),
        size: wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (k, info) in texture.levels().iter().enumerate() {
        let (bytes, texel_bytes): (Vec<u8>, u32) = match texture.level_texels(k) {
            Some(LevelTexels::Unorm8(v)) => (v.iter().flatten().copied().collect(), 4),
            Some(LevelTexels::Float(v)) => (
                v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect(),
                16,
            ),
            None => continue,
        };
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &t,
                mip_level: k as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(info.width * texel_bytes),
                rows_per_image: Some(info.height),
            },
            wgpu::Extent3d {
                width: info.width,
                height: info.height,
                depth_or_array_layers: 1,
            },
        );
    }
    Ok(t)
}

/// The shader's uniforms for one draw (the layout of `Params` in `filters.wgsl`).
fn params(draw: &DrawCall, filter: GpuFilter) -> Vec<u8> {
    let d = draw.sampler.descriptor();
    let (mode, aniso) = filter.mode();
    let srgb = u32::from(draw.texture.format() == Format::Rgba8Srgb && !filter.is_hardware());
    let mut out = Vec::with_capacity(128);
    for x in draw.clip_from_world.to_cols_array() {
        out.extend(x.to_le_bytes());
    }
    for x in d.border_color.rgba() {
        out.extend(x.to_le_bytes());
    }
    let u32s = [
        address_code(d.address_mode_u),
        address_code(d.address_mode_v),
        0,
        0,
        mode,
        srgb,
        aniso,
        0,
    ];
    for x in u32s {
        out.extend(x.to_le_bytes());
    }
    for x in [d.lod_bias, d.lod_min_clamp, d.lod_max_clamp, 0.0] {
        out.extend(x.to_le_bytes());
    }
    out
}

/// Render `draws` with `filter` on `gpu`: the same frame [`texel_raster::render`] makes (linear
/// colour and depth; no texel counts), filtered by the shader. Uploads the textures and meshes
/// and renders once; [`GpuDraws`] keeps them for many frames.
///
/// # Errors
/// As [`Gpu::prepare`] and [`GpuDraws::render`].
pub fn render(
    gpu: &Gpu,
    settings: &RenderSettings,
    draws: &[DrawCall],
    filter: GpuFilter,
) -> Result<Frame, GpuError> {
    gpu.prepare(draws, filter)?.render(settings)
}

/// Bytes that [`Gpu::prepare`] of `draws` holds, device and host together, for a memory budget:
/// per draw its texture's pyramid on the device and in the staging copy the upload goes through,
/// the host's copy of the level being uploaded, and the vertex, index and uniform buffers (36 bytes
/// a vertex, 12 a triangle) on the host, in staging and on the device.
pub fn prepare_bytes(draws: &[DrawCall]) -> u64 {
    draws
        .iter()
        .map(|d| {
            let t = d.texture;
            let level0 = u64::from(t.width()) * u64::from(t.height()) * t.format().texel_bytes();
            let geometry = d.vertices.len() as u64 * 36 + d.triangles.len() as u64 * 12;
            2 * t.pyramid_bytes() + level0 + 3 * (geometry + 256)
        })
        .fold(0u64, u64::saturating_add)
}

/// Bytes that one frame of `width x height` holds: the render targets on the device (colour 16,
/// fragment depth 4 and depth 4 bytes a pixel), the read-back buffer (16) and its copy on the
/// host (16).
pub fn frame_bytes(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height) * FRAME_BYTES_PER_PIXEL
}

/// [`frame_bytes`] per pixel.
pub const FRAME_BYTES_PER_PIXEL: u64 = 56;

/// Draw calls uploaded to a device with one filter: textures (the whole pyramid), uniforms,
/// vertices, indices and bind groups, ready to render frames of any size.
pub struct GpuDraws<'g> {
    gpu: &'g Gpu,
    pipeline: wgpu::RenderPipeline,
    /// The render targets of the last frame, reused while the size stays.
    targets: RefCell<Option<Targets>>,
    /// Per draw: bind group, vertex buffer, index buffer, index count.
    draws: Vec<UploadedDraw>,
    /// Per draw: the uniform buffer, whose first 64 bytes are `clip_from_world`.
    uniforms: Vec<wgpu::Buffer>,
}

/// One uploaded draw: bind group, vertex buffer, index buffer, index count.
type UploadedDraw = (wgpu::BindGroup, wgpu::Buffer, wgpu::Buffer, u32);

impl Gpu {
    /// Upload `draws` for rendering with `filter`.
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] for a filter the shader lacks ([`GpuFilter::of`] gives `None`),
    /// and for draws with a material or a per-pixel sphere mapping (the
    /// shader interpolates the vertices' uv; `UvEvaluation::PerVertex` draws are accepted);
    /// [`GpuError::TooLarge`] for a texture over the device's limit; [`GpuError::Failed`] when
    /// the device reports an error.
    pub fn prepare(&self, draws: &[DrawCall], filter: GpuFilter) -> Result<GpuDraws<'_>, GpuError> {
        if filter.shader().is_none() {
            return Err(GpuError::Unsupported(
                "the ripmap and the summed-area table (the shader has no such filter)",
            ));
        }
        if draws.iter().any(|d| d.material.is_some()) {
            return Err(GpuError::Unsupported("materials"));
        }
        let convention = convention_of(draws, filter)?;
        let per_pixel = |d: &DrawCall| {
            d.uv_mapping
                .is_some_and(|m| m.evaluation == texel_raster::UvEvaluation::PerPixel)
        };
        if draws.iter().any(per_pixel) {
            return Err(GpuError::Unsupported(
                "per-pixel sphere mappings (--surface-uv vertex draws them)",
            ));
        }
        let device = &self.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let pipeline = create_pipeline(device, &self.module, filter.mode().0, convention);
        let mut prepared = Vec::new();
        let mut uniforms = Vec::new();
        for draw in draws {
            let (draw, u) = self.prepare_draw(&pipeline, draw, filter)?;
            prepared.push(draw);
            uniforms.push(u);
        }
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Failed(e.to_string()));
        }
        Ok(GpuDraws {
            gpu: self,
            pipeline,
            targets: RefCell::new(None),
            draws: prepared,
            uniforms,
        })
    }

    fn prepare_draw(
        &self,
        pipeline: &wgpu::RenderPipeline,
        draw: &DrawCall,
        filter: GpuFilter,
    ) -> Result<(UploadedDraw, wgpu::Buffer), GpuError> {
        let device = &self.device;
        let texture = upload(self, draw.texture, filter.is_hardware())?;
        let view = texture.create_view(&Default::default());
        let uniforms = buffer(
            device,
            &self.queue,
            &params(draw, filter),
            wgpu::BufferUsages::UNIFORM,
        );
        let vertices: Vec<u8> = draw
            .vertices
            .iter()
            .flat_map(|v| {
                let p = v.position.to_array();
                let t = v.uv.to_array();
                let c = v.color.to_array();
                p.into_iter().chain(t).chain(c).flat_map(f32::to_le_bytes)
            })
            .collect();
        let indices: Vec<u8> = draw
            .triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let d = draw.sampler.descriptor();
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: None,
            address_mode_u: wgpu_address(d.address_mode_u),
            address_mode_v: wgpu_address(d.address_mode_v),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            lod_min_clamp: d.lod_min_clamp,
            lod_max_clamp: d.lod_max_clamp,
            anisotropy_clamp: filter.mode().1 as u16,
            ..Default::default()
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.srgb.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: self.ewa_lut.as_entire_binding(),
                },
            ],
        });
        let vb = buffer(device, &self.queue, &vertices, wgpu::BufferUsages::VERTEX);
        let ib = buffer(device, &self.queue, &indices, wgpu::BufferUsages::INDEX);
        Ok(((bind, vb, ib, draw.triangles.len() as u32 * 3), uniforms))
    }
}

impl GpuDraws<'_> {
    /// Move the camera: every draw's `clip_from_world` becomes `clip_from_world` for the frames
    /// rendered after this call (a viewer's fly camera, without uploading the draws again).
    pub fn set_clip_from_world(&self, clip_from_world: glam::Mat4) {
        let bytes: Vec<u8> = clip_from_world
            .to_cols_array()
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        for u in &self.uniforms {
            self.gpu.queue.write_buffer(u, 0, &bytes);
        }
    }

    /// Render one frame and read it back. A scissor rectangle ([`RenderSettings::scissor`]) limits
    /// the pixels drawn; the rest keep the background.
    ///
    /// # Errors
    /// [`GpuError::Settings`] for invalid settings; [`GpuError::Unsupported`] for lighting, debug
    /// views or texel counting;
    /// [`GpuError::TooLarge`] for a frame over the device's limits; [`GpuError::Failed`] when the
    /// device reports an error or is lost.
    pub fn render(&self, settings: &RenderSettings) -> Result<Frame, GpuError> {
        Ok(self.render_timed(settings)?.0)
    }

    /// [`GpuDraws::render`], with the render pass's device time in milliseconds from timestamps
    /// written at its beginning and end (`None` where the device has no timestamp queries).
    ///
    /// The device idles while the frame is read back, and may lower its clock meanwhile (an
    /// H200's SM clock moved between 345 and 1980 MHz during such runs: docs/guide/gpu.md), so
    /// this time is one frame's as an application that waits for each frame sees it;
    /// [`GpuDraws::pass_times`] measures passes back to back.
    ///
    /// # Errors
    /// As [`GpuDraws::render`].
    pub fn render_timed(
        &self,
        settings: &RenderSettings,
    ) -> Result<(Frame, Option<f64>), GpuError> {
        self.check(settings)?;
        let gpu = self.gpu;
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let targets = self.take_targets(settings);
        let mut encoder = device.create_command_encoder(&Default::default());
        let queries = gpu.timestamps.then(|| query_set(device, 1));
        self.encode_pass(
            &mut encoder,
            &targets,
            settings,
            queries.as_ref().map(|q| (q, 0)),
        );
        let color_bytes = read_back(gpu, &mut encoder, &targets.color, 16);
        let frag_depth_bytes = read_back(gpu, &mut encoder, &targets.frag_depth, 4);
        let time_bytes = queries
            .as_ref()
            .map(|q| resolve_queries(device, &mut encoder, q, 1));
        gpu.queue.submit([encoder.finish()]);
        *self.targets.borrow_mut() = Some(targets);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Failed(e.to_string()));
        }
        let color_data = color_bytes.wait(gpu)?;
        let frag_depth_data = frag_depth_bytes.wait(gpu)?;
        let mut frame = Frame::new(settings);
        let f32_at = |b: &[u8], c: usize| {
            f32::from_le_bytes([b[4 * c], b[4 * c + 1], b[4 * c + 2], b[4 * c + 3]])
        };
        let target = settings.target;
        for (k, b) in color_data.chunks_exact(16).enumerate() {
            let c: [f32; 4] = std::array::from_fn(|c| f32_at(b, c));
            if target.is_8bit() {
                frame.color8[k] = target.encode(c);
            } else {
                frame.color[k] = c;
            }
        }
        for (z, b) in frame.depth.iter_mut().zip(frag_depth_data.chunks_exact(4)) {
            *z = f32_at(b, 0);
        }
        let ms = match time_bytes {
            Some(t) => Some(pass_milliseconds(gpu, &t.wait(gpu)?)[0]),
            None => None,
        };
        Ok((frame, ms))
    }

    /// Device time in milliseconds of each of `passes` render passes of the frame
    /// [`GpuDraws::render`] draws, recorded back to back (at most [`PASSES_PER_SUBMIT`] to a
    /// submission, submitted without waiting) with nothing read back between them, so that the
    /// device does not idle between passes; in order. `None` where the device has no timestamp
    /// queries. What a GPU benchmark's frame rate reflects; a frame that is read back before the
    /// next is drawn is [`GpuDraws::render_timed`]'s.
    ///
    /// # Errors
    /// As [`GpuDraws::render`].
    pub fn pass_times(
        &self,
        settings: &RenderSettings,
        passes: u32,
    ) -> Result<Option<Vec<f64>>, GpuError> {
        self.check(settings)?;
        let gpu = self.gpu;
        if !gpu.timestamps {
            return Ok(None);
        }
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let targets = self.take_targets(settings);
        let mut pending = Vec::new();
        let mut left = passes;
        while left > 0 {
            let n = left.min(PASSES_PER_SUBMIT);
            left -= n;
            let queries = query_set(device, n);
            let mut encoder = device.create_command_encoder(&Default::default());
            for k in 0..n {
                self.encode_pass(&mut encoder, &targets, settings, Some((&queries, k)));
            }
            pending.push(resolve_queries(device, &mut encoder, &queries, n));
            gpu.queue.submit([encoder.finish()]);
        }
        *self.targets.borrow_mut() = Some(targets);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Failed(e.to_string()));
        }
        let mut out = Vec::with_capacity(passes as usize);
        for t in pending {
            out.extend(pass_milliseconds(gpu, &t.wait(gpu)?));
        }
        Ok(Some(out))
    }

    /// The settings' refusals shared by every way of rendering: invalid settings, lighting,
    /// debug views, texel counting, a frame over the device's limits.
    fn check(&self, settings: &RenderSettings) -> Result<(), GpuError> {
        settings.validate()?;
        if settings.is_lit() {
            return Err(GpuError::Unsupported("lighting"));
        }
        if settings.view != View::Color {
            return Err(GpuError::Unsupported("debug views"));
        }
        if settings.counts_texels() {
            return Err(GpuError::Unsupported("counting texels"));
        }
        self.gpu
            .check_size("the frame", settings.width, settings.height)
    }

    /// The last frame's targets if they have the settings' size, else new ones; the caller puts
    /// them back.
    fn take_targets(&self, settings: &RenderSettings) -> Targets {
        let (w, h) = (settings.width, settings.height);
        match self.targets.borrow_mut().take() {
            Some(t) if t.size == (w, h) => t,
            _ => Targets::new(&self.gpu.device, w, h),
        }
    }

    /// Record one render pass of the frame into `targets`: cleared to the background, every draw
    /// inside the scissor; timestamps `2k` and `2k + 1` of `queries` at its beginning and end.
    fn encode_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &Targets,
        settings: &RenderSettings,
        queries: Option<(&wgpu::QuerySet, u32)>,
    ) {
        let color_view = targets.color.create_view(&Default::default());
        let frag_depth_view = targets.frag_depth.create_view(&Default::default());
        let depth_view = targets.depth.create_view(&Default::default());
        // The integer targets are cleared to the f32 bits of the background and of +inf (a u32 is
        // exact in f64; the backends convert the clear colour to u32 for uint targets).
        let [r, g, b, a] = settings.background.map(|c| f64::from(c.to_bits()));
        let attachment = |view, clear| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("texel frame"),
            color_attachments: &[
                attachment(&color_view, wgpu::Color { r, g, b, a }),
                attachment(
                    &frag_depth_view,
                    wgpu::Color {
                        r: f64::from(f32::INFINITY.to_bits()),
                        ..wgpu::Color::TRANSPARENT
                    },
                ),
            ],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: queries.map(|(q, k)| wgpu::RenderPassTimestampWrites {
                query_set: q,
                beginning_of_pass_write_index: Some(2 * k),
                end_of_pass_write_index: Some(2 * k + 1),
            }),
            ..Default::default()
        });
        pass.set_pipeline(&self.pipeline);
        let [x0, y0, x1, y1] = settings.scissor_rect();
        let draws = if x0 < x1 && y0 < y1 {
            pass.set_scissor_rect(x0, y0, x1 - x0, y1 - y0);
            &self.draws[..]
        } else {
            &[]
        };
        for (bind, vb, ib, count) in draws {
            pass.set_bind_group(0, bind, &[]);
            pass.set_vertex_buffer(0, vb.slice(..));
            pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..*count, 0, 0..1);
        }
    }
}

/// Most render passes [`GpuDraws::pass_times`] records into one submission (their `2 n`
/// timestamps in one query set; wgpu allows 4096 queries a set).
pub const PASSES_PER_SUBMIT: u32 = 256;

/// A timestamp query set for `passes` render passes (two queries each).
fn query_set(device: &wgpu::Device, passes: u32) -> wgpu::QuerySet {
    device.create_query_set(&wgpu::QuerySetDescriptor {
        label: Some("pass times"),
        ty: wgpu::QueryType::Timestamp,
        count: 2 * passes,
    })
}

/// Resolve `passes` passes' timestamps into a buffer to read back.
fn resolve_queries(
    device: &wgpu::Device,
    encoder: &mut wgpu::CommandEncoder,
    queries: &wgpu::QuerySet,
    passes: u32,
) -> ReadBack {
    let bytes = 16 * u64::from(passes);
    let resolve = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: bytes,
        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    encoder.resolve_query_set(queries, 0..2 * passes, &resolve, 0);
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: bytes,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_buffer_to_buffer(&resolve, 0, &out, 0, bytes);
    ReadBack {
        buffer: out,
        row: bytes as usize,
        padded: bytes as usize,
        rows: 1,
    }
}

/// Milliseconds of each pass from resolved timestamp pairs (begin, end ticks; the queue's
/// timestamp period converts ticks to nanoseconds). An end before its begin counts as 0.
fn pass_milliseconds(gpu: &Gpu, bytes: &[u8]) -> Vec<f64> {
    let period = f64::from(gpu.queue.get_timestamp_period());
    bytes
        .chunks_exact(16)
        .map(|pair| {
            let tick =
                |k: usize| u64::from_le_bytes(pair[8 * k..8 * k + 8].try_into().unwrap_or([0; 8]));
            tick(1).saturating_sub(tick(0)) as f64 * period * 1e-6
        })
        .collect()
}

/// A frame's render targets: linear colour (f32 bits in `Rgba32Uint`), fragment depth and the
/// depth buffer, `size` pixels.
struct Targets {
    size: (u32, u32),
    color: wgpu::Texture,
    /// The fragment shader's NDC depth (f32 bits in `R32Uint`, cleared to +inf): read back as the
    /// frame's depth.
    frag_depth: wgpu::Texture,
    depth: wgpu::Texture,
}

impl Targets {
    fn new(device: &wgpu::Device, w: u32, h: u32) -> Targets {
        let target = |format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width: w,
                    height: h,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let copy = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        Targets {
            size: (w, h),
            color: target(COLOR, copy),
            frag_depth: target(FRAG_DEPTH, copy),
            depth: target(DEPTH, wgpu::TextureUsages::RENDER_ATTACHMENT),
        }
    }
}

/// A texture's copy into a mappable buffer, with rows padded to wgpu's 256-byte alignment.
struct ReadBack {
    buffer: wgpu::Buffer,
    row: usize,
    padded: usize,
    rows: usize,
}

fn read_back(
    gpu: &Gpu,
    encoder: &mut wgpu::CommandEncoder,
    texture: &wgpu::Texture,
    texel_bytes: u32,
) -> ReadBack {
    let (w, h) = (texture.width(), texture.height());
    let row = w * texel_bytes;
    let padded = row.next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: u64::from(padded) * u64::from(h),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        texture.size(),
    );
    ReadBack {
        buffer,
        row: row as usize,
        padded: padded as usize,
        rows: h as usize,
    }
}

impl ReadBack {
    /// Map the buffer (waiting for the device) and return the unpadded rows.
    fn wait(self, gpu: &Gpu) -> Result<Vec<u8>, GpuError> {
        let slice = self.buffer.slice(..);
        let (tx, rx) = mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        gpu.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Failed(e.to_string()))?;
        rx.recv()
            .map_err(|e| GpuError::Failed(e.to_string()))?
            .map_err(|e| GpuError::Failed(e.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| GpuError::Failed(e.to_string()))?;
        let mut out = Vec::with_capacity(self.row * self.rows);
        for r in 0..self.rows {
            out.extend_from_slice(&data[r * self.padded..r * self.padded + self.row]);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each filter's shader mode and clamp, as `filters.wgsl` numbers them, derived from its
    /// descriptor; the ripmap and the summed-area table have none.
    #[test]
    fn shader_modes_follow_the_descriptors() {
        let want = [
            (Filter::Nearest, Some((1, 1))),
            (Filter::Bilinear, Some((2, 1))),
            (Filter::Bicubic, Some((9, 1))),
            (Filter::MipNearest, Some((3, 1))),
            (Filter::Trilinear, Some((4, 1))),
            (Filter::Aniso2, Some((5, 2))),
            (Filter::Aniso4, Some((6, 4))),
            (Filter::Aniso8, Some((7, 8))),
            (Filter::Aniso16, Some((8, 16))),
            (Filter::Ewa, Some((10, 16))),
            (Filter::EwaProbes, Some((11, 16))),
            (Filter::Ripmap, None),
            (Filter::Sat, None),
        ];
        assert_eq!(want.map(|w| w.0), Filter::ALL);
        for (f, mode) in want {
            assert_eq!(GpuFilter::of(f).map(GpuFilter::mode), mode, "{f}");
            assert_eq!(GpuFilter::of(f).is_some(), mode.is_some());
        }
        // Lab mode m is shader mode m.
        for m in 1..=8 {
            let f = Filter::from_lab_mode(m).unwrap();
            assert_eq!(GpuFilter::of(f).unwrap().mode().0, u32::from(m));
        }
        assert_eq!(GpuFilter::HwAniso16.mode(), (21, 16));
        // Built by hand, a filter the shader lacks has no mode (and `Gpu::prepare` refuses it).
        assert_eq!(GpuFilter::Shader(Filter::Ripmap).shader(), None);
        assert_eq!(GpuFilter::Shader(Filter::Sat).shader(), None);
        assert!(
            GpuFilter::HwTrilinear.is_hardware()
                && !GpuFilter::of(Filter::Ewa).unwrap().is_hardware()
        );
    }
}
