//! Scenes from Python: `render` (the image `texel render` writes), the converging reference with
//! its error bars (whole, or one scissor rectangle of it), `compare`, and the files a scene reads
//! (`scene_files`).
//!
//! A scene argument is classified by what it names, not by the string's shape ([`scene_arg`]):
//! `builtin:NAME`, an existing file (its extension says TOML scene, OBJ or glTF/GLB mesh), TOML
//! text (a `str` of more than one line that names no file), else a path.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use texel::compare::CompareJob;
use texel::quality::{FilterRow, Image8, Report};
use texel::raster::{ReferencePlan, View};
use texel::{
    ColorHandling, Error, Filter, MemoryBudget, PreparedScene, ReferenceOptions, RenderOptions,
    Scene, SceneOptions, TextureStorage,
};

use crate::arrays::{array_out, rgba_out};
use crate::errors::{py_err, to_py};
use crate::pool::threads_of;
use crate::run_released;
use crate::texture::{filter_named, srgb_named};

/// A reference plan from Python's arguments, checked ([`ReferencePlan::new`]).
fn plan_of(
    spp: u32,
    max_spp: u32,
    tolerance: f64,
    seed: u64,
    color: ColorHandling,
) -> PyResult<ReferencePlan> {
    ReferencePlan::new(spp, max_spp, tolerance, color == ColorHandling::Srgb, seed)
        .map_err(py_err(""))
}

/// The values of the pixels inside `[x0, y0, x1, y1]` of a `width`-wide frame (a rectangle the
/// reference accepted), row by row.
fn crop<T: Copy>(values: &[T], width: u32, [x0, y0, x1, y1]: [u32; 4]) -> Vec<T> {
    values
        .chunks(width as usize)
        .skip(y0 as usize)
        .take((y1 - y0) as usize)
        .flat_map(|row| row[x0 as usize..x1 as usize].iter().copied())
        .collect()
}

/// What a scene argument names.
pub(crate) enum SceneArg {
    /// `builtin:NAME`.
    Builtin(String),
    /// A TOML scene file.
    Toml(PathBuf),
    /// A mesh file: OBJ (`obj`) or glTF/GLB, framed by a camera of its own ([`mesh_scene`]).
    Mesh {
        /// The file.
        path: PathBuf,
        /// Whether it is OBJ (else glTF or GLB).
        obj: bool,
    },
    /// TOML text, whose relative paths resolve from the working directory.
    Text(String),
}

impl SceneArg {
    /// The argument as errors name it.
    fn describe(&self) -> String {
        match self {
            SceneArg::Builtin(s) => s.clone(),
            SceneArg::Toml(p) | SceneArg::Mesh { path: p, .. } => p.display().to_string(),
            SceneArg::Text(_) => "<scene text>".into(),
        }
    }
}

/// A path by its extension, ASCII case ignored: `.obj` OBJ, `.gltf` and `.glb` glTF, anything
/// else a TOML scene (as the command line reads a mesh argument).
fn by_extension(path: PathBuf) -> SceneArg {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => SceneArg::Mesh { path, obj: true },
        Some("gltf" | "glb") => SceneArg::Mesh { path, obj: false },
        _ => SceneArg::Toml(path),
    }
}

/// Classify a scene argument. A `str`: `builtin:NAME`; else an existing file, by its extension
/// ([`by_extension`]); else TOML text when it holds a line break; else a path (which the loader
/// reports missing). An `os.PathLike` is always a path.
pub(crate) fn scene_arg(obj: &Bound<'_, PyAny>) -> PyResult<SceneArg> {
    if let Ok(s) = obj.extract::<String>() {
        if s.starts_with("builtin:") {
            return Ok(SceneArg::Builtin(s));
        }
        let path = Path::new(&s);
        if path.is_file() || !s.contains('\n') {
            return Ok(by_extension(PathBuf::from(s)));
        }
        return Ok(SceneArg::Text(s));
    }
    let path: PathBuf = obj.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "a scene is a str (a path, builtin:NAME or TOML text) or an os.PathLike; got {}",
            obj.get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        ))
    })?;
    Ok(by_extension(path))
}

/// Side lengths of the frame of a mesh file's scene.
const MESH_SCENE_SIZE: (u32, u32) = (640, 480);

/// Vertical field of view of a mesh file's camera, degrees.
const MESH_FOVY_DEG: f32 = 45.0;

/// How far above the mesh's centre a mesh file's camera looks from, degrees.
const MESH_ELEVATION_DEG: f32 = 30.0;

/// `s` as a TOML basic string: quoted, with quotes, backslashes and control characters escaped.
fn toml_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The scene of a mesh file: the mesh (an OBJ drawn with the procedural checker, since texel
/// reads no OBJ materials; a glTF with its own materials and textures, white without) unlit,
/// seen by a camera that frames its bounding sphere: from +z, raised [`MESH_ELEVATION_DEG`]
/// above its centre, up +y, [`MESH_FOVY_DEG`] tall, at [`MESH_SCENE_SIZE`].
fn mesh_scene(path: &Path, obj: bool) -> Result<Scene, Error> {
    let bad = |why: &str| {
        Error::Scene(texel::scene::SceneError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, why.to_string()),
        })
    };
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return Err(bad("names no file, or a file whose name is not UTF-8"));
    };
    let (w, h) = MESH_SCENE_SIZE;
    let mesh = if obj {
        format!("[textures.checker]\nprocedural = \"checker\"\n[[meshes]]\ntexture = \"checker\"\nobj = {}\n", toml_string(name))
    } else {
        format!("[[meshes]]\ngltf = {}\n", toml_string(name))
    };
    let text = format!(
        "[output]\nwidth = {w}\nheight = {h}\n[camera]\neye = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nfovy_deg = {MESH_FOVY_DEG:?}\nnear = 0.01\nfar = 10.0\n{mesh}"
    );
    let mut scene = Scene::from_toml_str(&text, path)?;
    let mut lo = glam::Vec3::splat(f32::INFINITY);
    let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
    for p in scene.meshes.iter().flat_map(|m| &m.positions) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let (centre, radius) = if lo.cmple(hi).all() {
        ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
    } else {
        (glam::Vec3::ZERO, 1.0)
    };
    let radius = if radius > 0.0 { radius } else { 1.0 };
    let distance = radius / (MESH_FOVY_DEG.to_radians() * 0.5).sin();
    let e = MESH_ELEVATION_DEG.to_radians();
    let camera = &mut scene.camera;
    camera.target = centre;
    camera.eye = centre + distance * glam::Vec3::new(0.0, e.sin(), e.cos());
    camera.up = glam::Vec3::Y;
    camera.near = (distance - radius) * 0.5;
    camera.far = (distance + radius) * 2.0;
    scene.validate()?;
    Ok(scene)
}

/// Load the scene `arg` names.
///
/// # Errors
/// texel's, for a scene that cannot be read or is malformed.
pub(crate) fn load(arg: &SceneArg) -> Result<Scene, Error> {
    Ok(match arg {
        SceneArg::Builtin(s) => Scene::load(s)?,
        SceneArg::Toml(p) => Scene::from_path(p)?,
        SceneArg::Mesh { path, obj } => mesh_scene(path, *obj)?,
        SceneArg::Text(t) => Scene::from_toml_str(t, Path::new("<scene text>"))?,
    })
}

/// [`load`] with Python's exception, its message naming the scene.
pub(crate) fn load_py(arg: &SceneArg) -> PyResult<Scene> {
    load(arg).map_err(|e| match arg {
        SceneArg::Text(_) => to_py(e, "cannot load the scene text"),
        _ => to_py(e, &format!("cannot load scene {}", arg.describe())),
    })
}

/// Colour handling by name: `"srgb"`, or `"raw"` (`"linear"`).
fn color_named(name: &str) -> PyResult<ColorHandling> {
    Ok(if srgb_named(name)? {
        ColorHandling::Srgb
    } else {
        ColorHandling::Raw
    })
}

/// A debug view by its command-line name.
fn view_named(name: &str) -> PyResult<View> {
    name.parse()
        .map_err(|e| PyValueError::new_err(format!("view: {e}")))
}

/// How 8-bit textures are kept, by its command-line name (`--texture-storage`).
fn storage_named(name: &str) -> PyResult<TextureStorage> {
    name.parse()
        .map_err(|e| PyValueError::new_err(format!("texture_storage: {e}")))
}

/// Output size from Python, checked for zero sides.
fn size_of(size: Option<(u32, u32)>) -> PyResult<Option<(u32, u32)>> {
    if let Some((w, h)) = size {
        if w == 0 || h == 0 {
            return Err(PyValueError::new_err(format!(
                "size must be (width, height) with both at least 1; got ({w}, {h})"
            )));
        }
    }
    Ok(size)
}

/// The size a scene renders at: `size`, else the scene's own (640 x 480 for a mesh file).
#[pyfunction]
#[pyo3(signature = (scene, size = None))]
pub(crate) fn scene_size(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    size: Option<(u32, u32)>,
) -> PyResult<(u32, u32)> {
    let size = size_of(size)?;
    let arg = scene_arg(scene)?;
    let loaded = run_released(py, move |_| load_py(&arg))?;
    Ok(size.unwrap_or((loaded.output.width, loaded.output.height)))
}

/// Every file `scene` reads, in the order texel first opens them: the scene file, its meshes
/// (OBJ, glTF and the glTF's buffers and images), textures and environment maps, each once, as
/// the paths texel opens (relative paths joined to the directory of the file that names them).
/// Found by loading and preparing the scene as `render` does (so by the code that reads the
/// files; the preparation is bounded by `max_memory`, else the process's memory limit). A
/// builtin scene reads none.
#[pyfunction]
#[pyo3(signature = (scene, max_memory = None))]
pub(crate) fn scene_files(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    max_memory: Option<u64>,
) -> PyResult<Vec<OsString>> {
    let arg = scene_arg(scene)?;
    let files = run_released(py, move |_| {
        let context = format!("cannot load scene {}", arg.describe());
        let named = match &arg {
            SceneArg::Builtin(s) => Some(s.clone()),
            SceneArg::Toml(p) => p
                .to_str()
                .filter(|s| !s.starts_with("builtin:"))
                .map(str::to_string),
            _ => None,
        };
        match named {
            // A scene `texel` loads by name: its own account of the files.
            Some(name) => texel::scene_inputs(&name, max_memory).map_err(|e| to_py(e, &context)),
            // A mesh file, scene text, or a path that is no UTF-8 string: the same preparation,
            // recorded.
            None => {
                let (done, files) = texel_io::record_opened(|| -> Result<(), Error> {
                    let scene = load(&arg)?;
                    let mut budget = MemoryBudget::limit_or_default(max_memory);
                    let options = SceneOptions {
                        replace_non_finite: false,
                        ..SceneOptions::default()
                    };
                    PreparedScene::new(scene, &options, &mut budget)?;
                    Ok(())
                });
                done.map(|()| files).map_err(|e| to_py(e, &context))
            }
        }
    })?;
    Ok(files.into_iter().map(PathBuf::into_os_string).collect())
}

/// Render `scene` with `filter` (`None`: a glTF mesh's own sampler, else trilinear) and return the
/// `H x W x 4` `uint8` image `texel render SCENE -o FILE.png` writes, bit for bit.
///
/// `scene` is `"builtin:NAME"`, a path (`str` or `os.PathLike`) or TOML text. A `str` naming an
/// existing file is that file, whatever its name holds; else a `str` with a line break is TOML
/// text (relative paths resolve from the working directory); an `os.PathLike` is always a path.
/// A file's extension says what it is: `.obj` an OBJ mesh, `.gltf`/`.glb` a glTF mesh (each
/// rendered unlit at 640 x 480 by a camera framing its bounding sphere from +z, 30 degrees up;
/// an OBJ with the procedural checker, a glTF with its own materials), anything else a TOML
/// scene. `reference`, `reference_estimate`, `compare`, `scene_size` and `scene_files` read
/// `scene` the same way.
#[pyfunction]
#[pyo3(signature = (scene, filter = Some("trilinear"), size = None, color = "srgb", view = "color", threads = None, max_memory = None, texture_storage = "stored"))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    filter: Option<&str>,
    size: Option<(u32, u32)>,
    color: &str,
    view: &str,
    threads: Option<usize>,
    max_memory: Option<u64>,
    texture_storage: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let options = RenderOptions {
        filter: filter.map(filter_named).transpose()?,
        size: size_of(size)?,
        color: color_named(color)?,
        view: view_named(view)?,
        max_memory,
        threads: threads_of(threads)?,
        texture_storage: storage_named(texture_storage)?,
    };
    let arg = scene_arg(scene)?;
    let image = run_released(py, move |_| {
        let loaded = load_py(&arg)?;
        texel::render_image(&loaded, &options).map_err(|e| to_py(e, ""))
    })?;
    Ok(rgba_out(py, image.width(), image.height(), image.pixels())?.into_any())
}

/// The converging reference of `scene` as `texel reference` makes it, with its error bars: a dict
/// of `image` (the `uint8` PNG values), `linear` (mean linear RGBA, `float32`), `std_error`
/// (standard error per channel, linear), `spp` (samples per pixel, `uint32`), `converged`
/// (`bool`), `exact` (`bool`: the pixel's integral was computed, `texel reference --exact`), all
/// `H x W (x 4)`, and `interrupted`. With `scissor=(x0, y0, x1, y1)` only those pixels are
/// rendered and returned, each exactly as in the whole frame. With `exact=True` every pixel whose
/// visible surface is unlit textured triangles is computed, not sampled (standard error 0, no
/// samples).
#[pyfunction]
#[pyo3(signature = (scene, spp = 256, max_spp = 65536, tolerance = 0.5, seed = texel::raster::DEFAULT_SEED, size = None, color = "srgb", threads = None, scissor = None, max_memory = None, exact = false))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn reference_estimate<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    spp: u32,
    max_spp: u32,
    tolerance: f64,
    seed: u64,
    size: Option<(u32, u32)>,
    color: &str,
    threads: Option<usize>,
    scissor: Option<(u32, u32, u32, u32)>,
    max_memory: Option<u64>,
    exact: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let color = color_named(color)?;
    let options = ReferenceOptions {
        plan: plan_of(spp, max_spp, tolerance, seed, color)?.with_exact(exact),
        size: size_of(size)?,
        color,
        threads: threads_of(threads)?,
        scissor: scissor.map(|(a, b, c, d)| [a, b, c, d]),
        max_memory,
    };
    let arg = scene_arg(scene)?;
    let e = run_released(py, move |stop| {
        let loaded = load_py(&arg)?;
        texel::reference_scene(&loaded, &options, Some(stop)).map_err(|e| to_py(e, ""))
    })?;
    let (w, h) = (e.frame.width, e.frame.height);
    let rect @ [x0, y0, x1, y1] = options.scissor.unwrap_or([0, 0, w, h]);
    let (tw, th) = (x1 - x0, y1 - y0);
    let linear = crop(&e.frame.color, w, rect);
    let std_error = crop(&e.std_error, w, rect);
    let spp = crop(&e.spp, w, rect);
    let converged = crop(&e.converged, w, rect);
    let exact = crop(&e.exact, w, rect);
    let out = PyDict::new(py);
    if tw > 0 && th > 0 {
        let encoding = options.color.encoding();
        let image = Image8::from_linear(tw, th, &linear, encoding).map_err(py_err(""))?;
        out.set_item("image", rgba_out(py, tw, th, image.pixels())?)?;
    } else {
        out.set_item(
            "image",
            array_out::<u8>(py, &[th as usize, tw as usize, 4], Vec::new())?,
        )?;
    }
    out.set_item("linear", rgba_out(py, tw, th, &linear)?)?;
    out.set_item("std_error", rgba_out(py, tw, th, &std_error)?)?;
    out.set_item("spp", array_out(py, &[th as usize, tw as usize], spp)?)?;
    out.set_item(
        "converged",
        array_out(py, &[th as usize, tw as usize], converged)?,
    )?;
    out.set_item("exact", array_out(py, &[th as usize, tw as usize], exact)?)?;
    out.set_item("interrupted", e.interrupted)?;
    Ok(out)
}

/// Every filter of `filters` (default: all) on `scene` against its converging reference, as
/// `texel compare` scores them: a dict from filter name to a dict of `psnr` (dB over the covered
/// pixels, 8-bit images as written), `psnr_band` (the horizon band), `ssim`, `psnr_block` (8x8
/// block means in linear light), `texels_per_pixel`, `texels_per_pixel_max`, `ms_per_frame`
/// (median of 3 after a warm-up), `texture_bytes`, `noise_floor` (the PSNR a perfect filter would
/// get against this reference), `noise_floor_block` and `within_noise_of` (the filters the
/// reference's error bars cannot rank this one against). As `texel compare`, the reference is
/// `texel reference --exact`'s (unlit textured pixels computed, the others sampled); with
/// `exact=False` it is sampled everywhere (`--sampled-reference`).
#[pyfunction]
#[pyo3(signature = (scene, filters = None, spp = 256, max_spp = None, tolerance = 0.5, seed = texel::raster::DEFAULT_SEED, size = None, color = "srgb", threads = None, max_memory = None, exact = true))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn compare<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    filters: Option<Vec<String>>,
    spp: u32,
    max_spp: Option<u32>,
    tolerance: f64,
    seed: u64,
    size: Option<(u32, u32)>,
    color: &str,
    threads: Option<usize>,
    max_memory: Option<u64>,
    exact: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let filters = filters_of(filters)?;
    let (threads, color) = (threads_of(threads)?, color_named(color)?);
    let options = SceneOptions {
        size: size_of(size)?,
        color,
        ..SceneOptions::default()
    };
    let plan = plan_of(spp, max_spp.unwrap_or(spp), tolerance, seed, color)?.with_exact(exact);
    let arg = scene_arg(scene)?;
    let report = run_released(py, move |stop| {
        let loaded = load_py(&arg)?;
        let mut budget = MemoryBudget::limit_or_default(max_memory);
        let (label, stop) = (arg.describe(), Some(stop));
        let job = CompareJob {
            threads,
            stop,
            ..CompareJob::new(&label, &filters, plan)
        };
        compare_prepared(loaded, &options, &job, &mut budget).map_err(|e| to_py(e, ""))
    })?;
    let out = PyDict::new(py);
    for row in &report.rows {
        out.set_item(&row.name, row_dict(py, row, &report)?)?;
    }
    Ok(out)
}

/// The filters named by a Python list in the command line's syntax (names, or `"all"`); every
/// filter when there is no list.
fn filters_of(filters: Option<Vec<String>>) -> PyResult<Vec<Filter>> {
    match filters {
        Some(names) => Filter::parse_list(&names.join(",")).map_err(py_err("")),
        None => Ok(Filter::ALL.to_vec()),
    }
}

/// `job` on `scene` prepared with `options`, its memory charged before the first pixel.
fn compare_prepared(
    scene: Scene,
    options: &SceneOptions,
    job: &CompareJob,
    budget: &mut MemoryBudget,
) -> Result<Report, Error> {
    let prepared = PreparedScene::new(scene, options, budget)?;
    job.charge(&prepared, budget)?;
    texel::compare::compare(&prepared, job, None, budget)
}

/// One row of a comparison as Python's `compare` returns it.
fn row_dict<'py>(
    py: Python<'py>,
    row: &FilterRow,
    report: &Report,
) -> PyResult<Bound<'py, PyDict>> {
    let floors = report.reference_error.as_ref();
    let d = PyDict::new(py);
    d.set_item("psnr", row.psnr_all)?;
    d.set_item("psnr_band", row.psnr_band)?;
    d.set_item("ssim", row.ssim)?;
    d.set_item("psnr_block", row.psnr_block)?;
    d.set_item("texels_per_pixel", row.texels_per_pixel_mean)?;
    d.set_item("texels_per_pixel_max", row.texels_per_pixel_max)?;
    d.set_item("ms_per_frame", row.ms_per_frame)?;
    d.set_item("texture_bytes", row.texture_bytes)?;
    d.set_item("noise_floor", floors.map(|f| f.noise_floor))?;
    d.set_item("noise_floor_block", floors.map(|f| f.noise_floor_block))?;
    d.set_item("within_noise_of", &row.within_noise_of)?;
    Ok(d)
}
