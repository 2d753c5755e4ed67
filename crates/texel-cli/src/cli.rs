//! Command-line interface: every command, flag and its help text (clap derive).

use std::path::PathBuf;

use clap::builder::TypedValueParser;
use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::budget::ByteSize;
use crate::filters::{filter_parser, Filter};

/// `--tolerance`'s default: half an 8-bit step of the displayed value.
pub(crate) use texel::raster::DEFAULT_TOLERANCE_STEPS;

/// texel: texture mapping and texture filtering on the CPU, measured.
#[derive(Debug, Parser)]
#[command(name = "texel", version, about, long_about = None, propagate_version = true)]
pub(crate) struct Cli {
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
    /// Most memory the command may hold at once, e.g. 512M or 4G (K, M, G, T: powers of 1024;
    /// at least 1M). Work that would need more is refused before it starts, with the figures.
    /// Default: the smallest of half of this machine's memory, the cgroup's limit and half of what
    /// `ulimit -v`/`-d` leave; an explicit SIZE is held to the same figures with all of the
    /// machine's memory.
    #[arg(long, global = true, value_name = "SIZE")]
    pub max_memory: Option<ByteSize>,
    /// Replace NaN and infinite texels of float images (EXR) with 0 and +-65504, and finite ones
    /// beyond +-2^64 with +-2^64, with a warning, instead of refusing the image.
    #[arg(long, global = true)]
    pub sanitize: bool,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Render a scene with one texture filter (or a debug view) to a PNG.
    ///
    /// Example: texel render builtin:ground --filter trilinear -o ground.png
    ///
    /// Example: texel render scenes/ground.toml --lab-mode 8 --view aniso -o aniso.png
    Render(RenderArgs),
    /// Render the supersampled reference (ground truth) of a scene with its error bars: at least
    /// --spp samples a pixel, more where its 95 % interval is wider than --tolerance.
    ///
    /// Example: texel reference builtin:glossy --size 320x180 --max-spp 4096 --error-map err.png -o reference.png
    Reference(ReferenceArgs),
    /// Render every filter and the reference; write a report (Markdown, JSON, HTML) with images,
    /// error heat maps, horizon crops and a quality/time chart.
    ///
    /// Example: texel compare builtin:ground --filters all --spp 256 --out report/
    ///
    /// Example: texel compare scene.toml --extra gpu=gpu.png --out report/
    Compare(CompareArgs),
    /// Perspective-warp an image without aliasing: the output's corners show four source points.
    ///
    /// Example: texel warp photo.jpg --corners 0,0,4000,300,4000,2700,0,3000 --size 800x600 -o out.png
    Warp(WarpArgs),
    /// Write every mip level of a texture, and one image of the whole chain.
    ///
    /// Example: texel mips brick.png --out mips/
    Mips(MipsArgs),
    /// Bake a mesh's ambient occlusion into a texture of its uv layout (rays through a BVH,
    /// cosine-weighted), for a material's `occlusion` or glTF's occlusionTexture.
    ///
    /// Example: texel bake-ao model.glb --size 1024 --rays 256 -o ao.png
    ///
    /// Example: texel bake-ao builtin:knot --max-distance 1.5 -o knot-ao.png
    BakeAo(BakeAoArgs),
    /// The embedded demo: compare every filter on the built-in scenes, with an index page.
    ///
    /// Example: texel demo --out demo/   (then open demo/index.html)
    Demo(DemoArgs),
    /// Time whole frames per filter (median over frames, textures and pyramids prepared beforehand).
    ///
    /// Example: texel bench scenes/ground.toml --frames 10 --threads 2 --json
    Bench(BenchArgs),
    /// An interactive window: the lab's keys 1-8 switch the filter while you fly over the scene;
    /// split screen compares two filters on one frame; 0 accumulates the reference.
    ///
    /// Example: texel view builtin:ground --size 1280x720
    ///
    /// Example (scripted, as the tests run it): texel view --keys 5 --frames 3 --no-hud --screenshot s.png
    #[command(after_help = texel_view::key_table())]
    View(ViewArgs),
    /// Run and grade a student's GLSL fragment shader for the lab's eight modes on OpenGL (EGL:
    /// Mesa's llvmpipe without a GPU), against texel's modes under the GL rules and the lab's
    /// formulas and the supersampled reference; write a report (Markdown, JSON, HTML).
    ///
    /// Example: texel lab modes.frag --out texel-lab/
    ///
    /// Example: texel lab modes.frag --vertex lab.vert --scene builtin:ground --modes 1-4
    Lab(LabArgs),
    /// The device half of `texel lab`, run by it in a child process with a time limit.
    #[command(hide = true)]
    LabDevice {
        /// The work folder holding `job.json`.
        dir: std::path::PathBuf,
    },
    /// List the Vulkan and GL adapters the GPU path (`render --gpu`) can use.
    ///
    /// Example: texel gpu-info
    GpuInfo,
}

/// The scene and colour options every rendering command shares.
#[derive(Debug, Args)]
pub(crate) struct SceneArgs {
    /// Scene file (TOML) or built-in scene (builtin:ground, builtin:ground-rotated, builtin:zoneplate,
    /// builtin:cube, builtin:sphere, builtin:globe, builtin:globe-equirect, builtin:triangle,
    /// builtin:glossy, builtin:bricks, builtin:terrain, builtin:knot, builtin:mirror-spheres,
    /// builtin:mirror-plane).
    #[arg(default_value = "builtin:ground")]
    pub scene: String,
    /// Colour handling.
    #[arg(long, value_enum, default_value_t)]
    pub color: texel::ColorHandling,
    /// Output size WIDTHxHEIGHT, each side 1 to 16384, overriding the scene's (e.g. 640x360).
    #[arg(long)]
    pub size: Option<Size>,
    /// Specular antialiasing for every material, overriding the scene's `specular_aa` (scenes
    /// with lights and materials, e.g. builtin:glossy). The reference ignores it: its normals
    /// are exact.
    #[arg(long, value_enum)]
    pub specular_aa: Option<texel::raster::SpecularAa>,
    /// Adaptive shading supersampling for every material, overriding the scene's
    /// `shading_samples`: where the shading normal turns from one pixel to the next by more
    /// than the specular lobe is wide, shade up to N x N sub-samples per pixel (1 to 8; 1 is
    /// off) and average them. Lit scenes only; the reference ignores it.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=i64::from(texel::scene::MAX_SHADING_SAMPLES)))]
    pub shading_samples: Option<u32>,
    /// What every material's height map does, overriding the scene's `displacement` (materials
    /// without a height map are unaffected).
    #[arg(long, value_enum)]
    pub displacement: Option<texel::scene::Displacement>,
    /// With displacement = tessellate: the longest projected edge kept, in pixels (0.25 to 256;
    /// default 4).
    #[arg(long, value_name = "PX", value_parser = parse_edge_px)]
    pub edge_px: Option<f32>,
    /// Where every layered material blends its layers, overriding the scene's `layer_order`
    /// (e.g. builtin:terrain).
    #[arg(long, value_enum)]
    pub layer_order: Option<texel::scene::LayerOrder>,
    /// Lay the scene's procedural sky out as this mapping, at about the same texel angle
    /// (e.g. builtin:mirror-plane; a map from files keeps its own layout).
    #[arg(long, value_enum, value_name = "MAPPING")]
    pub environment_mapping: Option<texel::scene::Mapping>,
    /// Where meshes with a sphere mapping (builtin:sphere, builtin:globe, `sphere_uv` in a scene)
    /// get their uv: exactly at every pixel (the default), or at the vertices, interpolated.
    #[arg(long, value_enum, value_name = "AT")]
    pub surface_uv: Option<texel::raster::UvEvaluation>,
    /// Filtering arithmetic for 8-bit unorm textures (`--color raw`) with nearest, bilinear,
    /// mip-nearest or trilinear: exact f32, or as GPUs blend unorm8 texels (8-bit sub-texel and
    /// mip weights, each blend rounded to 8 bits; within about a code of exact, and on this CPU
    /// path slower than exact from bilinear on: README.md). sRGB textures, the other filters and
    /// the reference stay exact.
    #[arg(long, value_enum, default_value_t)]
    pub precision: texel::raster::Precision,
    /// How 8-bit textures are kept for the CPU's filters: as stored (4 bytes a texel, decoded at
    /// each read), or decoded once to float (16 bytes a texel; the same images, mip and
    /// anisotropic frames faster: docs/decisions.md). Default: float for `view`, stored
    /// elsewhere and with --gpu or --precision gpu. A texture whose float copy does not fit the
    /// memory budget stays stored.
    #[arg(long, value_enum, value_name = "STORAGE")]
    pub texture_storage: Option<texel::TextureStorage>,
    /// The rules the lab's modes 1-8 (`--lab-mode`, the filters nearest to aniso16, the viewer's
    /// keys 1-8) follow, on the CPU and in the WGSL shader of --gpu: gl (the OpenGL / Vulkan
    /// rules) or lab (the lab handout's formulas: docs/guide/conventions.md). The other filters
    /// and the reference have the GL rules only.
    #[arg(long, default_value = "gl", value_name = "RULES")]
    pub convention: texel::texture::Convention,
}

/// A finite number in `[lo, hi]` of `unit` (the error names both).
fn parse_in(s: &str, lo: f32, hi: f32, unit: &str) -> Result<f32, String> {
    let v: f32 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number of {unit}"))?;
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{s} {unit} is outside {lo} to {hi}"))
    }
}

/// `--edge-px`: pixels in `[0.25, 256]`.
fn parse_edge_px(s: &str) -> Result<f32, String> {
    parse_in(s, 0.25, 256.0, "pixels per edge")
}

/// `texel render`.
#[derive(Debug, Args)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Texture filter for every mesh (default: a glTF mesh's own sampler filters, else trilinear).
    #[arg(long, conflicts_with = "lab_mode", value_parser = filter_parser())]
    pub filter: Option<Filter>,
    /// The lab's numbered filter modes: 1 nearest, 2 bilinear, 3 mip-nearest, 4 trilinear, 5-8 anisotropic 2x-16x.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=8))]
    pub lab_mode: Option<u8>,
    /// Texture derivatives.
    #[arg(long, value_enum, default_value_t)]
    pub derivatives: texel::raster::Derivatives,
    /// Attribute interpolation.
    #[arg(long, value_enum, default_value_t)]
    pub perspective: texel::raster::Perspective,
    /// What each pixel shows.
    #[arg(long, value_enum, default_value_t)]
    pub view: texel::raster::View,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Render on a Vulkan or GL device with texel's shaders (texel-gpu): nearest, bilinear,
    /// mip-nearest, trilinear, aniso2-16, bicubic and EWA; derivatives are the device's 2x2 quad
    /// differences; colour views only.
    #[arg(long)]
    pub gpu: bool,
    /// With --gpu: the adapter whose name contains NAME (see `texel gpu-info`; default: the
    /// TEXEL_ADAPTER environment variable, else the first, real GPUs first).
    #[arg(long, value_name = "NAME", requires = "gpu")]
    pub adapter: Option<String>,
    /// Output PNG (`-` writes it to standard output); a name ending in `.exr` writes OpenEXR
    /// instead: the linear colour as 32-bit floats, unclamped.
    #[arg(short, long, value_parser = image_output())]
    pub output: PathBuf,
}

/// `texel view`.
#[derive(Debug, Args)]
pub(crate) struct ViewArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Worker threads for rendering, 1 to 1024 (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Render the filters texel-gpu has (nearest to aniso16, bicubic, EWA; colour view) on a
    /// Vulkan or GL device; the reference, ripmaps, summed-area tables and debug views stay on
    /// the CPU. The HUD says which ran where.
    #[arg(long)]
    pub gpu: bool,
    /// With --gpu: the adapter whose name contains NAME (default: TEXEL_ADAPTER, else the first).
    #[arg(long, value_name = "NAME", requires = "gpu")]
    pub adapter: Option<String>,
    /// A student's GLSL fragment shader for the lab's modes (`texel lab`'s interface), drawn on
    /// OpenGL in the left half with keys 1-8 setting texMode (Tab splits it against texel's own
    /// mode on the right); the file is read again when it changes, and a version that does not
    /// compile shows its error while the last good one keeps running.
    #[arg(long, value_name = "FRAG", conflicts_with = "gpu")]
    pub shader: Option<PathBuf>,
    /// Key presses applied before the first frame, comma-separated: 0-9, a-z, tab, esc, f12,
    /// [, ], left, right, up, down, pageup, pagedown, each optionally shift+KEY (e.g. 1,5,v,tab).
    /// A movement key moves the camera by a quarter second's travel.
    #[arg(long, value_name = "KEYS")]
    pub keys: Option<String>,
    /// Exit after this many frames were shown at full resolution, 1 to 1000000.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub frames: Option<u32>,
    /// Write the last frame shown (overlays included unless --no-hud) to this PNG at exit.
    #[arg(long, value_name = "PATH", value_parser = png_output())]
    pub screenshot: Option<PathBuf>,
    /// Hide the heads-up display and the split-screen divider line, so the window (and a
    /// screenshot) shows exactly the rendered frame; H still shows the key table.
    #[arg(long = "no-hud", action = clap::ArgAction::SetFalse)]
    pub hud: bool,
}

/// `texel reference`.
#[derive(Debug, Args)]
pub(crate) struct ReferenceArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Samples every pixel gets, 1 to 4096, in at least 8 independent passes (one per sample below
    /// 8; 256 = 8 passes of 4x8 stratified samples).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP))]
    pub spp: u32,
    /// The most samples a pixel gets, --spp to 1048576: pixels whose 95 % interval is wider than
    /// --tolerance get more passes, doubling, up to this (equal to --spp: no pixel gets more).
    #[arg(long, default_value_t = 65_536, value_parser = clap::value_parser!(u32).range(1..=i64::from(texel::raster::MAX_ADAPTIVE_SPP)))]
    pub max_spp: u32,
    /// Half-width of a converged pixel's 95 % interval, in 8-bit steps of the displayed value
    /// (clipped to 0..255, sRGB-encoded unless --color raw), 0 to 255.
    #[arg(long, default_value_t = DEFAULT_TOLERANCE_STEPS, value_parser = tolerance())]
    pub tolerance: f64,
    /// Seed of the jitter; two seeds give independent estimates.
    #[arg(long, default_value_t = texel::raster::DEFAULT_SEED)]
    pub seed: u64,
    /// Compute the box-filtered integral of every pixel whose visible surface is unlit textured
    /// triangles (standard error 0, accurate to about 1e-6 of its value), and sample only the
    /// others (lit materials, interpenetrating triangles, sphere mappings).
    #[arg(long)]
    pub exact: bool,
    /// Worker threads, 1 to 1024 (default: all cores); the image does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Also write each pixel's error: `.exr` the standard error of the linear mean per channel
    /// (RGBA floats), `.png` a picture of the 95 % interval's half-width on the display
    /// (viridis, 0 to 4 8-bit steps; red where a pixel did not converge).
    #[arg(long, value_name = "PATH", value_parser = image_output())]
    pub error_map: Option<PathBuf>,
    /// On an interrupt (Ctrl-C, SIGTERM, SIGHUP), write the partial reference over existing
    /// files too. Without it a partial result goes only to outputs that do not exist yet; either
    /// way it carries a `texel:partial` entry (PNG text chunk, OpenEXR attribute) with the
    /// samples it reached.
    #[arg(long)]
    pub keep_partial: bool,
    /// Output PNG (`-` writes it to standard output); a name ending in `.exr` writes OpenEXR
    /// instead: the linear colour as 32-bit floats, unclamped.
    #[arg(short, long, value_parser = image_output())]
    pub output: PathBuf,
}

/// `--tolerance`: a finite number of 8-bit steps in `0..=255`.
fn tolerance() -> impl clap::builder::TypedValueParser<Value = f64> {
    clap::builder::StringValueParser::new().try_map(|s: String| match s.trim().parse::<f64>() {
        Ok(t) if (0.0..=255.0).contains(&t) => Ok(t),
        _ => Err(format!(
            "{s:?} is not a tolerance in 8-bit steps from 0 to 255 (e.g. 0.5)"
        )),
    })
}

/// `texel compare`.
#[derive(Debug, Args)]
pub(crate) struct CompareArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Filters to compare: comma-separated names, or all.
    #[arg(long, default_value = "all")]
    pub filters: String,
    /// Reference samples every pixel gets, 1 to 4096, in at least 8 independent passes whose
    /// spread gives each pixel's standard error (256 = 8 passes of 4x8 stratified samples).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP))]
    pub spp: u32,
    /// The most reference samples a pixel gets, --spp to 1048576: pixels whose 95 % interval is
    /// wider than --tolerance get more passes, doubling, up to this (default: --spp, a fixed
    /// budget; the report says how much of the reference converged and what it can rank).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(texel::raster::MAX_ADAPTIVE_SPP)))]
    pub max_spp: Option<u32>,
    /// With --max-spp: half-width of a converged reference pixel's 95 % interval, in 8-bit steps
    /// of the displayed value, 0 to 255 (also the converged share the report gives).
    #[arg(long, default_value_t = DEFAULT_TOLERANCE_STEPS, value_parser = tolerance())]
    pub tolerance: f64,
    /// Score against a sampled reference everywhere. By default the reference is `texel
    /// reference --exact`'s: each unlit textured pixel's integral computed, the others sampled as
    /// --spp says.
    #[arg(long = "sampled-reference", action = clap::ArgAction::SetFalse)]
    pub exact: bool,
    /// An image rendered elsewhere to score against the same reference: LABEL=PATH (repeatable;
    /// labels must differ from each other and from the filters compared).
    #[arg(long, value_name = "LABEL=IMAGE")]
    pub extra: Vec<String>,
    /// Also render every compared filter the GPU path has with texel's shaders (rows gpu-NAME) and
    /// the device's own sampler (rows hw-trilinear, hw-aniso16), scored against the same
    /// reference; ms per frame is wall time on the device, reading the frame back included.
    #[arg(long)]
    pub gpu: bool,
    /// With --gpu: the adapter whose name contains NAME (default: TEXEL_ADAPTER, else the first).
    #[arg(long, value_name = "NAME", requires = "gpu")]
    pub adapter: Option<String>,
    /// Also render a slow camera orbit of N frames (2 to 1000; the scene's own view first) and
    /// report per filter its PSNR averaged over the frames and its flicker: its change between
    /// consecutive frames less the reference's, per pixel, as a mean absolute value in 8-bit
    /// units (sparkle shows in motion; motion itself cancels). Renders
    /// N references.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub orbit: Option<u32>,
    /// With --orbit: degrees the camera turns per frame about its up axis through the target
    /// (finite, 0 to 10).
    #[arg(long, value_name = "DEG", default_value_t = 0.1, requires = "orbit", value_parser = parse_orbit_step)]
    pub orbit_step: f32,
    /// Output directory: created, or replaced as a whole if texel wrote it before.
    #[arg(long)]
    pub out: PathBuf,
}

/// `--orbit-step`: degrees in `[0, 10]`.
fn parse_orbit_step(s: &str) -> Result<f32, String> {
    parse_in(s, 0.0, 10.0, "degrees per frame")
}

/// `texel demo`.
#[derive(Debug, Args)]
pub(crate) struct DemoArgs {
    /// Output directory: created, or replaced as a whole if texel wrote it before.
    #[arg(long, default_value = "texel-demo")]
    pub out: PathBuf,
    /// Image size of every scene (default: half of each scene's own size, e.g. 640x360 for the
    /// ground plane, and a quarter for the lit scenes; with --full, each unlit scene's own size
    /// and half for the lit ones).
    #[arg(long)]
    pub size: Option<Size>,
    /// Every unlit scene at its full size (the ground plane at 1280x720) and the lit ones at
    /// half: several minutes on two cores, where the default takes under two.
    #[arg(long)]
    pub full: bool,
    /// Reference samples per pixel, 1 to 4096, in at least 8 independent passes (256 = 8 passes
    /// of 4x8 stratified samples); each report gives the reference's noise floor.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP))]
    pub spp: u32,
}

/// `texel bench`.
#[derive(Debug, Args)]
pub(crate) struct BenchArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Filters to time: comma-separated names, or all.
    #[arg(
        long,
        default_value = "nearest,bilinear,mip-nearest,trilinear,aniso16,ewa"
    )]
    pub filters: String,
    /// Timed frames per filter, 1 to 10000 (the median is reported).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub frames: u32,
    /// Untimed warm-up frames per filter, 0 to 10000 (at least 0.2 s of them unless 0).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(0..=10000))]
    pub warmup: u32,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Print JSON in the shape of scripts/peers/llvmpipe_bench.py (plus the CPU, the SIMD level
    /// and the colour target).
    #[arg(long)]
    pub json: bool,
    /// The colour render target the frames are drawn into.
    #[arg(long, value_enum, default_value_t = TargetArg::Rgba8)]
    pub target: TargetArg,
    /// The instruction set of the tile rasterizer: the best the CPU has (x86-64-v4 where it has
    /// AVX-512, x86-64-v3 where it has AVX2 and FMA), or a lower copy, to measure the difference
    /// (images are the same). A level the CPU lacks runs the CPU's best; the report names the
    /// level that ran.
    #[arg(long, value_enum, default_value_t = SimdArg::Best)]
    pub simd: SimdArg,
    /// How frames are written (`texel::raster::Streaming`): `auto` draws the tiles of a frame
    /// larger than the last-level cache in scratch and streams them out with non-temporal
    /// stores (and clears it so); `always` and `never` force either way, to measure the
    /// difference (images are the same).
    #[arg(long, value_enum, default_value_t = texel::raster::Streaming::Auto)]
    pub streaming: texel::raster::Streaming,
    /// Time texel's shaders on a Vulkan or GL device instead (texel-gpu; the filters it has, and
    /// the device's own sampler as `hw-trilinear` and `hw-aniso16` in `--filters`; `all` is all of
    /// them): wall time per frame (submission, rendering, reading the frame back) and, where the
    /// device has timestamp queries, the device time of a render pass, from as many passes again
    /// recorded back to back so that the device does not idle between them (the last column;
    /// `device_ms` in JSON, which also names the adapter).
    #[arg(long)]
    pub gpu: bool,
    /// With --gpu: the adapter whose name contains NAME (default: TEXEL_ADAPTER, else the first).
    #[arg(long, value_name = "NAME", requires = "gpu")]
    pub adapter: Option<String>,
}

/// Which instruction-set copy the tile rasterizer and the sampler's batch kernels run
/// (`texel::raster::simd_level`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum SimdArg {
    /// The best the CPU has.
    Best,
    /// At most the x86-64-v4 (AVX-512) copy.
    V4,
    /// At most the x86-64-v3 (AVX2 and FMA) copy.
    V3,
    /// The x86-64 baseline (SSE2) copy.
    Baseline,
}

impl SimdArg {
    /// The highest level this choice allows.
    pub(crate) fn limit(self) -> texel::raster::SimdLevel {
        use texel::raster::SimdLevel;
        match self {
            SimdArg::Best | SimdArg::V4 => SimdLevel::X86_64V4,
            SimdArg::V3 => SimdLevel::X86_64V3,
            SimdArg::Baseline => SimdLevel::Baseline,
        }
    }
}

/// A colour render target ([`texel::ColorTarget`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum TargetArg {
    /// RGBA8 in the output's encoding (sRGB, or unorm with `--color raw`): what `texel render`
    /// writes, 4 bytes a pixel.
    Rgba8,
    /// Linear RGBA `f32`, 16 bytes a pixel.
    Float,
}

/// Output size `WIDTHxHEIGHT`, each side 1 to 16384.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Size {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// Most reference samples per pixel: 64 x 64, the rasterizer's largest stratification.
pub(crate) const MAX_SPP: i64 = 4096;

/// Largest output side accepted (pixels).
pub(crate) const MAX_SIDE: u32 = 16384;

impl std::str::FromStr for Size {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (w, h) = s
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("size {s:?} is not WIDTHxHEIGHT (e.g. 640x360)"))?;
        let side = |t: &str| -> Result<u32, String> {
            let v: u32 = t
                .trim()
                .parse()
                .map_err(|_| format!("size {s:?}: {t:?} is not a whole number"))?;
            if v == 0 || v > MAX_SIDE {
                return Err(format!(
                    "size {s:?}: each side must be between 1 and {MAX_SIDE}"
                ));
            }
            Ok(v)
        };
        Ok(Size {
            width: side(w)?,
            height: side(h)?,
        })
    }
}

/// Four source points `x0,y0,x1,y1,x2,y2,x3,y3` (pixels), parsed from one comma-separated value.
///
/// One value rather than clap's `value_delimiter` with `num_args = 8`: clap counts the 8 values
/// before splitting at commas, so it rejected the documented `--corners 0,0,4000,300,...`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Corners(pub [f64; 8]);

impl std::str::FromStr for Corners {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let items: Vec<&str> = s.split(',').map(str::trim).collect();
        if items.len() != 8 {
            return Err(format!(
                "{s:?} has {} numbers; give 8: x0,y0,x1,y1,x2,y2,x3,y3 (e.g. 0,0,4000,300,4000,2700,0,3000)",
                items.len()
            ));
        }
        let mut out = [0.0; 8];
        for (o, t) in out.iter_mut().zip(&items) {
            *o = t
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{t:?} in {s:?} is not a finite number"))?;
        }
        Ok(Corners(out))
    }
}

/// `texel warp`.
#[derive(Debug, Args)]
pub(crate) struct WarpArgs {
    /// Source image (PNG, JPEG or OpenEXR).
    pub input: PathBuf,
    /// Source pixel positions shown at the output's top-left, top-right, bottom-right and
    /// bottom-left corners: x0,y0,x1,y1,x2,y2,x3,y3 (pixels; (0,0) is the source's top-left corner).
    #[arg(long, allow_hyphen_values = true)]
    pub corners: Corners,
    /// Output size WIDTHxHEIGHT (each side 1 to 16384, at most 2^26 pixels); defaults to the source size.
    #[arg(long)]
    pub size: Option<Size>,
    /// Texture filter.
    #[arg(long, default_value = "ewa", value_parser = filter_parser())]
    pub filter: Filter,
    /// Colour handling.
    #[arg(long, value_enum, default_value_t)]
    pub color: texel::ColorHandling,
    /// Output PNG (`-` writes it to standard output); a name ending in `.exr` writes OpenEXR
    /// instead: the linear colour as 32-bit floats, unclamped.
    #[arg(short, long, value_parser = image_output())]
    pub output: PathBuf,
}

/// `texel mips`.
#[derive(Debug, Args)]
pub(crate) struct MipsArgs {
    /// The texture (PNG, JPEG or OpenEXR).
    pub texture: PathBuf,
    /// Colour handling: srgb averages in linear light, raw averages the bytes.
    #[arg(long, value_enum, default_value_t)]
    pub color: texel::ColorHandling,
    /// Output directory: created, or replaced as a whole if texel wrote it before.
    #[arg(long)]
    pub out: PathBuf,
}

/// `texel bake-ao`.
#[derive(Debug, Args)]
pub(crate) struct BakeAoArgs {
    /// The mesh: an OBJ or glTF (.gltf, .glb) file, or a scene (TOML file or builtin:NAME) whose
    /// meshes all bake into the one map. Its uvs must not overlap where they are to differ.
    #[arg(default_value = "builtin:knot")]
    pub mesh: String,
    /// Side of the square map in texels, 1 to 16384.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=i64::from(texel::ao::MAX_AO_SIZE)))]
    pub size: u32,
    /// Rays per texel, 1 to 65536 (the first floor(sqrt(N))^2 stratified).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=i64::from(texel::ao::MAX_AO_RAYS)))]
    pub rays: u32,
    /// Occluders farther than D (world units) do not count (default: any distance).
    #[arg(long, value_name = "D", value_parser = positive_f32)]
    pub max_distance: Option<f32>,
    /// Rings of texels filled around the uv islands. A margin of M keeps the islands' values
    /// alone in mip levels 0 to log2(M) - 1 (16 protects 4 levels). Default: the whole map (every
    /// level protected).
    #[arg(long, value_name = "PX")]
    pub margin: Option<u32>,
    /// Seed of the ray directions (the map is the same for a seed on any number of threads).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Output image: PNG, 8-bit grey, linear (1 = unoccluded; read it with color = "linear"), or
    /// for a name ending in `.exr`, OpenEXR with the occlusion as 32-bit floats.
    #[arg(short, long, value_parser = image_output())]
    pub output: PathBuf,
}

/// A finite number above 0.
fn positive_f32(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("{s:?} is not a finite number above 0")),
    }
}

/// clap's parser for `-o`: any path bytes, checked by [`crate::output::image_output`].
fn image_output() -> impl TypedValueParser<Value = PathBuf> {
    clap::builder::OsStringValueParser::new().try_map(crate::output::image_output)
}

/// clap's parser for `--screenshot`: [`crate::output::png_output`].
fn png_output() -> impl TypedValueParser<Value = PathBuf> {
    clap::builder::OsStringValueParser::new().try_map(crate::output::png_output)
}

/// `texel lab`'s arguments.
#[derive(Debug, Args)]
pub(crate) struct LabArgs {
    /// The student's fragment shader (GLSL, any version the driver accepts).
    pub shader: PathBuf,
    /// The student's vertex shader; it gets the attributes `position` (vec3, world space) and
    /// `texCoordIn` (vec2) and the uniform `clipFromWorld` (mat4), and must write the varying.
    /// Default: texel's own, which passes `texCoordIn` on unchanged.
    #[arg(long)]
    pub vertex: Option<PathBuf>,
    /// A scene to grade on (repeatable): lab-tunnel, lab-plane, lab-wall (the default: all
    /// three), builtin:NAME or a scene file; unlit scenes only.
    #[arg(long = "scene", value_name = "SCENE")]
    pub scenes: Vec<String>,
    /// The modes to run: a list and ranges of 1-8, e.g. 1-4 or 1,2,5-8.
    #[arg(long, default_value = "1-8", value_parser = parse_modes)]
    pub modes: ModeList,
    /// Report folder (made or replaced whole).
    #[arg(long, default_value = "texel-lab")]
    pub out: PathBuf,
    /// The sampler uniform's name.
    #[arg(long, default_value = "texSlot")]
    pub sampler: String,
    /// The mode uniform's name.
    #[arg(long = "mode-uniform", default_value = "texMode")]
    pub mode_uniform: String,
    /// The texture coordinate varying's name.
    #[arg(long, default_value = "texCoord")]
    pub varying: String,
    /// Seconds the device may take for every scene and mode together before the shader is
    /// stopped (an endless loop).
    #[arg(long, default_value_t = 120, value_parser = clap::value_parser!(u64).range(1..=86400))]
    pub timeout: u64,
    /// Frame size overriding the scenes' (320x240 for the lab's own).
    #[arg(long)]
    pub size: Option<Size>,
    /// Timed frames per mode on the device (after one untimed).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub frames: u64,
    /// Samples a pixel of the reference the PSNR is measured against.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub spp: u32,
    /// Worker threads for grading (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub threads: Option<u64>,
}

/// `texel lab --modes`: modes 1-8, in order, without repeats.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct ModeList(pub Vec<u8>);

pub(crate) fn parse_modes(s: &str) -> Result<ModeList, String> {
    let mut out = Vec::new();
    for part in s.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (a, b) = part.split_once('-').unwrap_or((part, part));
        let num = |t: &str| -> Result<u8, String> {
            t.trim()
                .parse::<u8>()
                .ok()
                .filter(|m| (1..=8).contains(m))
                .ok_or_else(|| format!("mode {t:?} is not 1 to 8"))
        };
        let (a, b) = (num(a)?, num(b)?);
        if a > b {
            return Err(format!("mode range {part:?} runs backwards"));
        }
        out.extend(a..=b);
    }
    out.sort_unstable();
    out.dedup();
    if out.is_empty() {
        return Err("no modes given".into());
    }
    Ok(ModeList(out))
}

/// A reference plan from the command line's numbers ([`texel::raster::ReferencePlan::new`]), its errors worded
/// with the flags' names.
///
/// # Errors
/// A maximum below the minimum, and the plan's other checks.
pub(crate) fn reference_plan(
    min_spp: u32,
    max_spp: u32,
    tolerance_steps: f64,
    srgb: bool,
    seed: u64,
) -> anyhow::Result<texel::raster::ReferencePlan> {
    texel::raster::ReferencePlan::new(min_spp, max_spp, tolerance_steps, srgb, seed).map_err(|e| {
        match e {
            texel::raster::RasterError::MaxSppBelowMin { min_spp, max_spp } => anyhow::anyhow!(
            "--max-spp {max_spp} is below --spp {min_spp}: the maximum must be at least the minimum"
        ),
            e => e.into(),
        }
    })
}

#[cfg(test)]
mod tests {
    use clap::ValueEnum;

    /// The names clap offers for an option enum (its `ValueEnum`).
    fn clap_names<T: ValueEnum>() -> Vec<String> {
        T::value_variants()
            .iter()
            .map(|v| v.to_possible_value().unwrap().get_name().to_string())
            .collect()
    }

    /// The command line offers exactly the names the libraries parse and print (which Python and
    /// the reports use), in the same order, and each parses back to its value.
    #[test]
    fn the_command_line_and_the_libraries_name_options_alike() {
        use texel::raster::{Precision, View};
        use texel::{ColorHandling, TextureStorage};
        let views: Vec<String> = View::ALL.iter().map(|v| v.to_string()).collect();
        assert_eq!(clap_names::<View>(), views);
        for v in View::ALL {
            assert_eq!(v.name().parse::<View>(), Ok(v));
        }
        let storage: Vec<String> = TextureStorage::ALL.iter().map(|t| t.to_string()).collect();
        assert_eq!(clap_names::<TextureStorage>(), storage);
        for t in TextureStorage::ALL {
            assert_eq!(t.name().to_uppercase().parse::<TextureStorage>(), Ok(t));
        }
        let colors: Vec<String> = ColorHandling::ALL.iter().map(|c| c.to_string()).collect();
        assert_eq!(clap_names::<ColorHandling>(), colors);
        let precisions = [Precision::Exact, Precision::Gpu].map(|p| p.name().to_string());
        assert_eq!(clap_names::<Precision>(), precisions);
        let err = "sideways".parse::<View>().unwrap_err();
        assert!(err.contains("valid views are color, uv, mip"), "{err}");
    }
}
