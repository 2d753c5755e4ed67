//! Scenes from Python: `render` (the image `texel render` writes), the converging reference with
//! its error bars (whole, or one scissor rectangle of it) and `compare`.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Instant;

use clap::ValueEnum;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use texel::quality::{
    block_psnr, default_band_rows, Image8, Mask, ReferenceError, Scores, DEFAULT_BLOCK,
};
use texel::raster::{draw_into, ReferencePlan, View};
use texel::{
    ColorHandling, Error, Filter, Frame, MemoryBudget, PreparedScene, ReferenceOptions,
    ReferenceRun, RenderOptions, Scene, SceneOptions, TextureStorage,
};

use crate::arrays::{array_out, rgba_out};
use crate::errors::{py_err, to_py};
use crate::run_released;
use crate::texture::{filter_named, srgb_named};

/// Timed frames per filter in `compare`, after one warm-up frame (the command's count).
const TIMED_FRAMES: usize = 3;

/// The most worker threads a call may ask for.
const MAX_THREADS: usize = 1024;

/// A `threads=` argument, checked: 1 to [`MAX_THREADS`], or `None` for all cores.
fn threads_of(threads: Option<usize>) -> PyResult<Option<usize>> {
    match threads {
        Some(n) if !(1..=MAX_THREADS).contains(&n) => Err(PyValueError::new_err(format!(
            "threads must be 1 to {MAX_THREADS}, or None for all cores; got {n}"
        ))),
        t => Ok(t),
    }
}

/// A reference plan from Python's arguments, checked: `spp` to `max_spp` samples a pixel,
/// `tolerance` in 8-bit steps of the display `color` encodes to.
fn plan_of(
    spp: u32,
    max_spp: u32,
    tolerance: f64,
    seed: u64,
    color: ColorHandling,
) -> PyResult<ReferencePlan> {
    if max_spp < spp {
        return Err(PyValueError::new_err(format!(
            "max_spp {max_spp} is below spp {spp}: the maximum must be at least the minimum"
        )));
    }
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(PyValueError::new_err(format!(
            "tolerance must be a finite number of 8-bit steps, 0 or more; got {tolerance}"
        )));
    }
    Ok(ReferencePlan {
        min_spp: spp,
        max_spp,
        tolerance: tolerance / 255.0,
        srgb_display: color == ColorHandling::Srgb,
        seed,
    })
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

/// Load a scene: `"builtin:NAME"`, a path (`str` or `os.PathLike`) to a TOML, OBJ or glTF file,
/// or TOML text of more than one line (whose relative paths resolve from the working directory).
pub(crate) fn load_scene(arg: &Path) -> PyResult<Scene> {
    let Some(arg) = arg.to_str() else {
        return Err(PyValueError::new_err(format!(
            "scene path {} is not UTF-8",
            arg.display()
        )));
    };
    if arg.contains('\n') {
        return Scene::from_toml_str(arg, Path::new("<scene text>"))
            .map_err(py_err("cannot load the scene text"));
    }
    Scene::load(arg).map_err(py_err(&format!("cannot load scene {arg}")))
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
    View::from_str(name, false).map_err(|_| {
        let names: Vec<String> = View::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_string()))
            .collect();
        PyValueError::new_err(format!(
            "unknown view {name:?}: valid views are {}",
            names.join(", ")
        ))
    })
}

/// How 8-bit textures are kept, by its command-line name (`--texture-storage`).
fn storage_named(name: &str) -> PyResult<TextureStorage> {
    TextureStorage::from_str(name, false).map_err(|_| {
        PyValueError::new_err(format!(
            "unknown texture_storage {name:?}: valid values are stored, float"
        ))
    })
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

/// The size a scene renders at: `size`, else the scene's own.
#[pyfunction]
#[pyo3(signature = (scene, size = None))]
pub fn scene_size(scene: PathBuf, size: Option<(u32, u32)>) -> PyResult<(u32, u32)> {
    let loaded = load_scene(&scene)?;
    Ok(size_of(size)?.unwrap_or((loaded.output.width, loaded.output.height)))
}

/// Render `scene` with `filter` (`None`: a glTF mesh's own sampler, else trilinear) and return the
/// `H x W x 4` `uint8` image `texel render SCENE -o FILE.png` writes, bit for bit.
#[pyfunction]
#[pyo3(signature = (scene, filter = Some("trilinear"), size = None, color = "srgb", view = "color", threads = None, max_memory = None, texture_storage = "stored"))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    scene: PathBuf,
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
    let loaded = load_scene(&scene)?;
    let image = run_released(py, move |_| {
        texel::render_image(&loaded, &options).map_err(|e| to_py(e, ""))
    })?;
    Ok(rgba_out(py, image.width(), image.height(), image.pixels())?.into_any())
}

/// The converging reference of `scene` as `texel reference` makes it, with its error bars: a dict
/// of `image` (the `uint8` PNG values), `linear` (mean linear RGBA, `float32`), `std_error`
/// (standard error per channel, linear), `spp` (samples per pixel, `uint32`), `converged`
/// (`bool`), all `H x W (x 4)`, and `interrupted`. With `scissor=(x0, y0, x1, y1)` only those
/// pixels are rendered and returned, each exactly as in the whole frame.
#[pyfunction]
#[pyo3(signature = (scene, spp = 256, max_spp = 65536, tolerance = 0.5, seed = texel::raster::adaptive::DEFAULT_SEED, size = None, color = "srgb", threads = None, scissor = None, max_memory = None))]
#[allow(clippy::too_many_arguments)]
pub fn reference_estimate<'py>(
    py: Python<'py>,
    scene: PathBuf,
    spp: u32,
    max_spp: u32,
    tolerance: f64,
    seed: u64,
    size: Option<(u32, u32)>,
    color: &str,
    threads: Option<usize>,
    scissor: Option<(u32, u32, u32, u32)>,
    max_memory: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let color = color_named(color)?;
    let options = ReferenceOptions {
        plan: plan_of(spp, max_spp, tolerance, seed, color)?,
        size: size_of(size)?,
        color,
        threads: threads_of(threads)?,
        scissor: scissor.map(|(a, b, c, d)| [a, b, c, d]),
        max_memory,
    };
    let loaded = load_scene(&scene)?;
    let e = run_released(py, move |stop| {
        texel::reference_scene(&loaded, &options, Some(stop)).map_err(|e| to_py(e, ""))
    })?;
    let (w, h) = (e.frame.width, e.frame.height);
    let rect @ [x0, y0, x1, y1] = options.scissor.unwrap_or([0, 0, w, h]);
    let (tw, th) = (x1 - x0, y1 - y0);
    let linear = crop(&e.frame.color, w, rect);
    let std_error = crop(&e.std_error, w, rect);
    let spp = crop(&e.spp, w, rect);
    let converged = crop(&e.converged, w, rect);
    let out = PyDict::new(py);
    if tw > 0 && th > 0 {
        let image = crate::texture::encoded(tw, th, &linear, options.color == ColorHandling::Srgb)?;
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
    out.set_item("interrupted", e.interrupted)?;
    Ok(out)
}

/// One filter's scores against the reference.
struct Row {
    filter: Filter,
    scores: Scores,
    psnr_block: f64,
    texels: (f64, u64),
    ms: f64,
    texture_bytes: u64,
    image: Image8,
}

/// Render `filter` on `scene`: timed frames, then one counting texels, scored against `reference`.
fn score_filter(
    scene: &PreparedScene,
    filter: Filter,
    threads: Option<usize>,
    reference: (&Image8, &Mask),
    budget: &mut MemoryBudget,
) -> Result<Row, Error> {
    let (ref_image, coverage) = reference;
    let plan = scene.plan(Some(filter), budget)?;
    let texture_bytes = plan.structure_bytes();
    let draws = plan.draws();
    let mut settings = plan.settings();
    settings.threads = threads;
    let mut frame = Frame::new(&settings);
    let mut ms = Vec::new();
    for k in 0..=TIMED_FRAMES {
        let t0 = Instant::now();
        frame.reset(&settings);
        draw_into(&settings, &draws, &mut frame)?;
        if k > 0 {
            ms.push(t0.elapsed().as_secs_f64() * 1e3);
        }
    }
    ms.sort_by(f64::total_cmp);
    settings.count_texels = true;
    let counted = texel::render(&settings, &draws)?;
    let image = texel::frame_image(&counted, texel::encoding(scene.color))?;
    let scores = Scores::compute(
        ref_image,
        &image,
        coverage,
        default_band_rows(image.height()),
    )?;
    let psnr_block = block_psnr(
        ref_image,
        &image,
        Some(coverage),
        DEFAULT_BLOCK,
        texel::encoding(scene.color),
    )?;
    Ok(Row {
        filter,
        scores,
        psnr_block,
        texels: counted.texels_per_pixel(),
        ms: ms[ms.len() / 2],
        texture_bytes,
        image,
    })
}

/// Every filter of `filters` (default: all) on `scene` against its converging reference, as
/// `texel compare` scores them: a dict from filter name to a dict of `psnr` (dB over the covered
/// pixels, 8-bit images as written), `psnr_band` (the horizon band), `ssim`, `psnr_block` (8x8
/// block means in linear light), `texels_per_pixel`, `texels_per_pixel_max`, `ms_per_frame`
/// (median of 3 after a warm-up), `texture_bytes`, `noise_floor` (the PSNR a perfect filter would
/// get against this reference), `noise_floor_block` and `within_noise_of` (the filters the
/// reference's error bars cannot rank this one against).
#[pyfunction]
#[pyo3(signature = (scene, filters = None, spp = 256, max_spp = None, tolerance = 0.5, seed = texel::raster::adaptive::DEFAULT_SEED, size = None, color = "srgb", threads = None, max_memory = None))]
#[allow(clippy::too_many_arguments)]
pub fn compare<'py>(
    py: Python<'py>,
    scene: PathBuf,
    filters: Option<Vec<String>>,
    spp: u32,
    max_spp: Option<u32>,
    tolerance: f64,
    seed: u64,
    size: Option<(u32, u32)>,
    color: &str,
    threads: Option<usize>,
    max_memory: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let filters = match filters {
        // The command line's list syntax: names, or "all".
        Some(names) => Filter::parse_list(&names.join(",")).map_err(py_err(""))?,
        None => Filter::ALL.to_vec(),
    };
    let threads = threads_of(threads)?;
    let color = color_named(color)?;
    let size = size_of(size)?;
    let plan = plan_of(spp, max_spp.unwrap_or(spp), tolerance, seed, color)?;
    let loaded = load_scene(&scene)?;
    let (rows, floors, ties) = run_released(py, move |stop| {
        let run = || -> Result<_, Error> {
            let mut budget = MemoryBudget::limit_or_default(max_memory);
            let options = SceneOptions {
                size,
                color,
                ..SceneOptions::default()
            };
            let prepared = PreparedScene::new(loaded, &options, &mut budget)?;
            let pixels = u64::from(prepared.width) * u64::from(prepared.height);
            budget.take(
                "the reference, its statistics and the filters' images",
                pixels * (texel::REFERENCE_BYTES_PER_PIXEL + 32 + 4 * filters.len() as u64),
            )?;
            let run = ReferenceRun {
                plan,
                threads,
                stop: Some(stop),
                ..ReferenceRun::default()
            };
            let estimate = prepared.reference(&prepared.scene.camera, &run)?;
            let (w, h) = (estimate.frame.width, estimate.frame.height);
            let enc = texel::encoding(color);
            let ref_image = Image8::from_linear(w, h, &estimate.frame.color, enc)?;
            let coverage = Mask::new(w, h, estimate.frame.coverage())?;
            let error = ReferenceError {
                width: w,
                height: h,
                mean: &estimate.frame.color,
                std_error: &estimate.std_error,
                encoding: enc,
            };
            let floors = (
                error.noise_floor(Some(&coverage))?,
                error.block_noise_floor(Some(&coverage), DEFAULT_BLOCK)?,
            );
            let mut rows = Vec::new();
            for &f in &filters {
                if stop.load(Ordering::Relaxed) {
                    return Err(Error::Cancelled);
                }
                rows.push(score_filter(
                    &prepared,
                    f,
                    threads,
                    (&ref_image, &coverage),
                    &mut budget,
                )?);
            }
            let images: Vec<&Image8> = rows.iter().map(|r| &r.image).collect();
            let ties = error.within_noise(&ref_image, &images, Some(&coverage))?;
            Ok((rows, floors, ties))
        };
        run().map_err(|e| to_py(e, ""))
    })?;
    let out = PyDict::new(py);
    for (row, tied) in rows.iter().zip(&ties) {
        let d = PyDict::new(py);
        d.set_item("psnr", row.scores.psnr_all)?;
        d.set_item("psnr_band", row.scores.psnr_band)?;
        d.set_item("ssim", row.scores.ssim)?;
        d.set_item("psnr_block", row.psnr_block)?;
        d.set_item("texels_per_pixel", row.texels.0)?;
        d.set_item("texels_per_pixel_max", row.texels.1)?;
        d.set_item("ms_per_frame", row.ms)?;
        d.set_item("texture_bytes", row.texture_bytes)?;
        d.set_item("noise_floor", floors.0)?;
        d.set_item("noise_floor_block", floors.1)?;
        let names: Vec<&str> = tied.iter().map(|&j| rows[j].filter.name()).collect();
        d.set_item("within_noise_of", names)?;
        out.set_item(row.filter.name(), d)?;
    }
    Ok(out)
}
