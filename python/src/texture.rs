//! `texel.Texture` (a texture with its mip pyramid, sampled by any filter on arrays of points),
//! `texel.warp` and the 8-bit encoding of linear colour.

use std::str::FromStr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use glam::DVec2;
use numpy::PyArrayDyn;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use rayon::prelude::*;
use texel::quality::Encoding;
use texel::raster::warp_perspective;
use texel::texture::{
    AddressMode, BorderColor, ColorSpace, FilterMode, Footprint, LevelTexels, Limits, Sampler,
    SamplerDescriptor,
};
use texel::{Filter, MemoryBudget};

use crate::arrays::{
    array_out, image_view, pairs_in, reserve, rgba_out, tuple, values_in, widen_one, ImageIn,
    ImageView, Pairs, Texels,
};
use crate::errors::py_err;
use crate::memory::{budget, bytes_of, take, texture_bytes};
use crate::{pool, run_released, run_released_on};

/// Points a worker samples at a time.
const POINTS_PER_TASK: usize = 4096;

/// Values a worker encodes at a time.
const VALUES_PER_TASK: usize = 16384;

/// A filter by its name (`"aniso16"`), as the command line names it.
pub(crate) fn filter_named(name: &str) -> PyResult<Filter> {
    Filter::from_str(name).map_err(py_err(""))
}

/// An address mode by name: WebGPU's (`"clamp-to-edge"`, `"repeat"`, `"mirror-repeat"`,
/// `"clamp-to-border"`, `"mirror-clamp-to-edge"`) or the short `"clamp"` and `"mirror"`.
fn address_named(name: &str) -> PyResult<AddressMode> {
    Ok(match name {
        "repeat" => AddressMode::Repeat,
        "clamp" | "clamp-to-edge" => AddressMode::ClampToEdge,
        "mirror" | "mirror-repeat" => AddressMode::MirrorRepeat,
        "clamp-to-border" | "border" => AddressMode::ClampToBorder,
        "mirror-clamp-to-edge" | "mirror-clamp" => AddressMode::MirrorClampToEdge,
        _ => {
            return Err(PyValueError::new_err(format!(
                "unknown address mode {name:?}: valid modes are repeat, clamp (clamp-to-edge), mirror (mirror-repeat), clamp-to-border, mirror-clamp-to-edge"
            )))
        }
    })
}

/// An address mode's WebGPU name (what [`address_named`] reads back).
fn address_name(mode: AddressMode) -> &'static str {
    match mode {
        AddressMode::Repeat => "repeat",
        AddressMode::ClampToEdge => "clamp-to-edge",
        AddressMode::MirrorRepeat => "mirror-repeat",
        AddressMode::ClampToBorder => "clamp-to-border",
        AddressMode::MirrorClampToEdge => "mirror-clamp-to-edge",
    }
}

/// A border colour by name.
fn border_named(name: &str) -> PyResult<BorderColor> {
    Ok(match name {
        "transparent-black" => BorderColor::TransparentBlack,
        "opaque-black" => BorderColor::OpaqueBlack,
        "opaque-white" => BorderColor::OpaqueWhite,
        _ => {
            return Err(PyValueError::new_err(format!(
                "unknown border colour {name:?}: valid colours are transparent-black, opaque-black, opaque-white"
            )))
        }
    })
}

/// A border colour's name (what [`border_named`] reads back).
fn border_name(color: BorderColor) -> &'static str {
    match color {
        BorderColor::OpaqueBlack => "opaque-black",
        BorderColor::OpaqueWhite => "opaque-white",
        _ => "transparent-black",
    }
}

/// How 8-bit values are stored: `"srgb"` (sRGB-encoded RGB) or `"linear"` (`"raw"`: the codes
/// as stored, `c / 255`).
pub(crate) fn srgb_named(name: &str) -> PyResult<bool> {
    match name {
        "srgb" => Ok(true),
        "linear" | "raw" => Ok(false),
        _ => Err(PyValueError::new_err(format!(
            "unknown colour handling {name:?}: valid values are linear (raw: the values as stored) and srgb"
        ))),
    }
}

/// How sample coordinates are given: normalised `(u, v)` or pixels of level 0.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Coords {
    /// `0..1` spans the texture once.
    Uv,
    /// `0..W` and `0..H`; texel `(i, j)`'s centre is `(i + 0.5, j + 0.5)`.
    Pixels,
}

/// Coordinates by name: `"uv"` or `"pixels"`.
fn coords_named(name: &str) -> PyResult<Coords> {
    match name {
        "uv" => Ok(Coords::Uv),
        "pixels" => Ok(Coords::Pixels),
        _ => Err(PyValueError::new_err(format!(
            "unknown coords {name:?}: valid values are uv (0..1 spans the texture) and pixels (0..W, 0..H, texel centres at +0.5)"
        ))),
    }
}

/// An image's texels copied within `budget`, with the limits its texture is built under:
/// [`memory::texture_bytes`](crate::memory::texture_bytes) charged first, the limits of what the
/// budget had left (at most a texture's default), which also bound its ripmap and summed-area
/// table.
fn texture_input(view: &ImageView<'_>, budget: &mut MemoryBudget) -> PyResult<(ImageIn, Limits)> {
    let (w, h) = (view.width, view.height);
    let limits = Limits {
        max_bytes: budget.remaining().min(Limits::default().max_bytes),
        ..Limits::default()
    };
    let storage = if view.is_float() {
        "RGBA float32"
    } else {
        "RGBA8"
    };
    take(
        budget,
        &format!("a {w}x{h} {storage} texture (its texels and mip pyramid)"),
        texture_bytes(w, h, view.is_float()),
    )?;
    Ok((view.texels()?, limits))
}

/// A texture of `image` under `limits` ([`texture_input`]): 8-bit decoded as `srgb` says, float
/// as linear values.
fn build_texture(image: ImageIn, srgb: bool, limits: &Limits) -> PyResult<texel::Texture> {
    let ImageIn {
        width,
        height,
        texels,
    } = image;
    match texels {
        Texels::U8(t) => {
            let color = if srgb {
                ColorSpace::Srgb
            } else {
                ColorSpace::Linear
            };
            texel::Texture::from_rgba8(width, height, t, color, limits)
        }
        Texels::F32(t) => texel::Texture::from_rgba32f(width, height, t, limits),
    }
    .map_err(py_err("cannot make a texture"))
}

/// A texture and its mip pyramid, with the address modes and border colour its samples use.
///
/// `array` is an `H x W x C` numpy array, `uint8` or `float32`, C in 1-4 (grey, grey and alpha,
/// RGB, RGBA; `H x W` is grey). Row 0 is the top of the image, where `v = 0`. 8-bit values are
/// read as `color` says: `"linear"` (the default, also `"raw"`: code `c` is `c / 255`, as OpenCV,
/// scipy, torch and a GPU's UNORM texture read it) or `"srgb"` (RGB decoded from sRGB, alpha
/// linear: photographs and colour textures, as a GPU's sRGB texture reads them); float values
/// are linear already and must be finite and within +-2^64. `address` sets both axes
/// (`address_u`/`address_v` override one): `"repeat"`, `"clamp"`, `"mirror"`, `"clamp-to-border"` or
/// `"mirror-clamp-to-edge"`; `border` is the colour outside the texture under `clamp-to-border`.
/// The copy and the pyramid are charged to `max_memory` bytes, else the process's default memory
/// limit (`MemoryError` with the figures when they do not fit). Textures pickle (the level-0
/// texels and the options; the pyramid is rebuilt).
#[pyclass(frozen, module = "texel")]
pub struct Texture {
    texture: Arc<texel::Texture>,
    address: (AddressMode, AddressMode),
    border: BorderColor,
    srgb: bool,
    /// Whether the ripmap and the summed-area table are built (sampling charges a structure to
    /// the call's budget until it is).
    built: [AtomicBool; 2],
}

impl Texture {
    /// The ripmap's or the summed-area table's slot in [`Texture::built`] for `filter`, if it
    /// reads one.
    fn structure_slot(desc_min: FilterMode) -> Option<usize> {
        match desc_min {
            FilterMode::Ripmap => Some(0),
            FilterMode::SummedArea => Some(1),
            _ => None,
        }
    }

    /// Charges `budget` for the ripmap or summed-area table `desc` reads, where it is not built
    /// yet (with the ripmap's scratch); returns the structure's slot in [`Texture::built`].
    fn charge_structure(
        &self,
        budget: &mut MemoryBudget,
        desc: &SamplerDescriptor,
    ) -> PyResult<Option<usize>> {
        let slot = Self::structure_slot(desc.min_filter);
        if let Some(k) = slot.filter(|&k| !self.built[k].load(Ordering::Acquire)) {
            let t = &self.texture;
            let structure = if k == 0 {
                "ripmap"
            } else {
                "summed-area table"
            };
            take(
                budget,
                &format!(
                    "the {structure} of the {}x{} texture",
                    t.width(),
                    t.height()
                ),
                t.structure_bytes(desc)
                    .saturating_sub(t.pyramid_bytes())
                    .saturating_add(t.build_scratch_bytes(desc)),
            )?;
        }
        Ok(slot)
    }
}

/// The derivatives `sample` is given, read and checked against `uv`'s shape, or else the grid
/// (its width and height) whose neighbours give them; a filter that reads level 0 needs no grid.
#[allow(clippy::type_complexity)]
fn derivatives<'py>(
    shape: &[usize],
    duv_dx: Option<&Bound<'py, PyAny>>,
    duv_dy: Option<&Bound<'py, PyAny>>,
    filter: Filter,
    budget: &mut MemoryBudget,
) -> PyResult<(Option<(Pairs<'py>, Pairs<'py>)>, Option<(usize, usize)>)> {
    let reads_level0 = matches!(filter, Filter::Nearest | Filter::Bilinear | Filter::Bicubic);
    let mut derivative = |d: &Bound<'py, PyAny>, what: &str| -> PyResult<Pairs<'py>> {
        let (s, v) = pairs_in(d, what, budget)?;
        if s != *shape {
            return Err(PyValueError::new_err(format!(
                "{what} has shape {} but uv has {}: they must match",
                tuple(&[s.as_slice(), &[2]].concat()),
                tuple(&[shape, &[2]].concat())
            )));
        }
        Ok(v)
    };
    let given =
        match (duv_dx, duv_dy) {
            (Some(dx), Some(dy)) => Some((derivative(dx, "duv_dx")?, derivative(dy, "duv_dy")?)),
            (None, None) => None,
            _ => return Err(PyValueError::new_err(
                "pass both duv_dx and duv_dy, or neither (then they are derived from the grid uv)",
            )),
        };
    // The grid whose neighbours give the derivatives: its width and height.
    let grid = match (&given, shape) {
        (Some(_), _) => None,
        (None, _) if reads_level0 => None,
        (None, [.., h, w]) => Some((*w, *h)),
        (None, _) => {
            return Err(PyValueError::new_err(format!(
                "filter {} reads mip levels chosen by the footprint: pass duv_dx and duv_dy, or uv as an (..., H, W, 2) grid whose neighbours give them (uv has shape {})",
                filter.name(),
                tuple(&[shape, &[2]].concat())
            )))
        }
    };
    Ok((given, grid))
}

/// The points being sampled, in the caller's units, and their derivatives: given, derived from a
/// grid's neighbours, or none.
struct Points<'a> {
    /// `(u, v)` or `(x, y)` pairs, one per point.
    uv: &'a [f32],
    /// The given derivatives in x, pairs as `uv`.
    dx: Option<&'a [f32]>,
    /// The given derivatives in y, pairs as `uv`.
    dy: Option<&'a [f32]>,
    /// The grid's width and height, when the derivatives come from its neighbours.
    grid: Option<(usize, usize)>,
    /// The units' size in texture coordinates' reciprocal: 1 for `uv`, the texture's size for
    /// pixels.
    scale: [f32; 2],
}

impl Points<'_> {
    /// Point `p`'s footprint in texture coordinates.
    fn footprint(&self, p: usize) -> Footprint {
        let (uv, scale) = (self.uv, self.scale);
        let pair = |d: Option<&[f32]>, p: usize| {
            d.map_or([0.0; 2], |d| [d[2 * p] / scale[0], d[2 * p + 1] / scale[1]])
        };
        let ([dudx, dvdx], [dudy, dvdy]) = match self.grid {
            None => (pair(self.dx, p), pair(self.dy, p)),
            Some((w, h)) => {
                let (x, y) = (p % w, (p / w) % h);
                // Point p's row starts at `row`; its column at row 0 of its grid is `column`.
                let (row, column) = (p - x, p - y * w);
                let along_x = quad_pair(x, w)
                    .map_or([0.0; 2], |(a, b)| pair_diff(uv, row + b, row + a, scale));
                let along_y = quad_pair(y, h).map_or([0.0; 2], |(a, b)| {
                    pair_diff(uv, column + b * w, column + a * w, scale)
                });
                (along_x, along_y)
            }
        };
        Footprint {
            u: uv[2 * p] / scale[0],
            v: uv[2 * p + 1] / scale[1],
            dudx,
            dvdx,
            dudy,
            dvdy,
        }
    }
}

/// The difference of `values`' pairs at `b` and `a` (point indices), converted by `scale`.
#[inline]
fn pair_diff(values: &[f32], b: usize, a: usize, scale: [f32; 2]) -> [f32; 2] {
    [
        values[2 * b] / scale[0] - values[2 * a] / scale[0],
        values[2 * b + 1] / scale[1] - values[2 * a + 1] / scale[1],
    ]
}

/// The two points whose difference is the derivative at index `k` of an axis of `n` points, as
/// a GPU's 2 x 2 quads take it: `k` and its partner in the pair `(2m, 2m + 1)` that holds it,
/// forward (the odd one minus the even one); the last point of an odd axis has no partner and
/// takes the backward difference. `None` for an axis of one point.
#[inline]
fn quad_pair(k: usize, n: usize) -> Option<(usize, usize)> {
    if n < 2 {
        return None;
    }
    let even = k & !1;
    Some(if even + 1 < n {
        (even, even + 1)
    } else {
        (k - 1, k)
    })
}

#[pymethods]
impl Texture {
    #[new]
    #[pyo3(signature = (array, color = "linear", address = "repeat", address_u = None, address_v = None, border = "transparent-black", max_memory = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        array: &Bound<'_, PyAny>,
        color: &str,
        address: &str,
        address_u: Option<&str>,
        address_v: Option<&str>,
        border: &str,
        max_memory: Option<u64>,
    ) -> PyResult<Self> {
        let srgb = srgb_named(color)?;
        let both = address_named(address)?;
        let u = address_u.map_or(Ok(both), address_named)?;
        let v = address_v.map_or(Ok(both), address_named)?;
        let border = border_named(border)?;
        let view = image_view(array, "array")?;
        // Float texels are linear whatever `color` says.
        let srgb = srgb && !view.is_float();
        let (image, limits) = texture_input(&view, &mut budget(max_memory))?;
        drop(view);
        let texture = run_released(py, move |_| build_texture(image, srgb, &limits))?;
        Ok(Texture {
            texture: Arc::new(texture),
            address: (u, v),
            border,
            srgb,
            built: [AtomicBool::new(false), AtomicBool::new(false)],
        })
    }

    /// Width of level 0 in texels.
    #[getter]
    fn width(&self) -> u32 {
        self.texture.width()
    }

    /// Height of level 0 in texels.
    #[getter]
    fn height(&self) -> u32 {
        self.texture.height()
    }

    /// `"uint8"` or `"float32"`: how the texels are stored.
    #[getter]
    fn dtype(&self) -> &'static str {
        match self.texture.level_texels(0) {
            Some(LevelTexels::Float(_)) => "float32",
            _ => "uint8",
        }
    }

    /// `"srgb"` or `"linear"`: how the 8-bit texels are decoded (`"linear"` for a float texture).
    #[getter]
    fn color(&self) -> &'static str {
        if self.srgb {
            "srgb"
        } else {
            "linear"
        }
    }

    /// The address mode along u (x), by its WebGPU name (`"clamp-to-edge"`).
    #[getter]
    fn address_u(&self) -> &'static str {
        address_name(self.address.0)
    }

    /// The address mode along v (y), by its WebGPU name.
    #[getter]
    fn address_v(&self) -> &'static str {
        address_name(self.address.1)
    }

    /// The colour read outside the texture under `clamp-to-border`.
    #[getter]
    fn border(&self) -> &'static str {
        border_name(self.border)
    }

    /// The mip pyramid, level 0 first, down to 1 x 1: one `H x W x 4` array per level in the
    /// texture's storage (`uint8` codes, sRGB-encoded when the texture is sRGB, or linear
    /// `float32`). Level k is `max(1, W >> k) x max(1, H >> k)`; each of its texels is the exact
    /// box mean, in linear light, of the area of the level above it covers: the 2 x 2 mean where
    /// that side is even, fractional weights where it is odd (a side of 5 reduces to 2 texels
    /// weighing the texels above 0.4, 0.4, 0.2 and 0.2, 0.4, 0.4), so every level's mean is level
    /// 0's. The copies are charged to the process's memory limit.
    fn levels<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        let mut b = budget(None);
        take(
            &mut b,
            "the copies of the mip levels",
            self.texture.pyramid_bytes(),
        )?;
        let mut out = Vec::new();
        for (k, info) in self.texture.levels().iter().enumerate() {
            let (w, h) = (info.width, info.height);
            let array = match self.texture.level_texels(k) {
                Some(LevelTexels::Unorm8(t)) => rgba_out(py, w, h, t)?.into_any(),
                Some(LevelTexels::Float(t)) => rgba_out(py, w, h, t)?.into_any(),
                None => break,
            };
            out.push(array);
        }
        Ok(out)
    }

    /// Sample the texture at `uv` with `filter`; returns linear RGBA as `float32` of shape
    /// `uv.shape[:-1] + (4,)`.
    ///
    /// `uv` has shape `(..., 2)`: with `coords="uv"` (the default) texture coordinates `(u, v)`,
    /// `0..1` spanning the texture once (`v = 0` is row 0, the top); with `coords="pixels"`,
    /// `(x, y)` in texels of level 0, texel `(i, j)`'s centre at `(i + 0.5, j + 0.5)` as in
    /// OpenGL and Direct3D (subtract 0.5 from OpenCV's `remap` maps and scipy's
    /// `map_coordinates`, whose centres are at integers). `duv_dx` and `duv_dy`, of the same
    /// shape and units, are the footprint: how the coordinates change from one output pixel to
    /// the next in x and in y. The filters that read mip levels or footprints (mip-nearest,
    /// trilinear, aniso2-16, ewa, ewa-probes, ripmap, sat) need them; when both are left out and `uv` is a
    /// grid `(..., H, W, 2)`, they are derived from its neighbours as a GPU's 2 x 2 quads derive
    /// them: within each quad, the forward difference of the two points of its row (for x) or
    /// column (for y), the same for both points; the last row or column of an odd side takes the
    /// backward difference. Nearest, bilinear and bicubic (Catmull-Rom) read level 0 and ignore
    /// them. `lod_bias` is added to the level of detail. `threads` sets the worker threads
    /// (`None`: all cores). Arrays are `float32` or `float64`, C-contiguous and finite. The output
    /// (and a `float64` array's conversion) is charged to `max_memory`, else the process's memory
    /// limit. The GIL is released while texel's threads sample.
    #[pyo3(signature = (uv, duv_dx = None, duv_dy = None, filter = "trilinear", lod_bias = 0.0, coords = "uv", threads = None, max_memory = None))]
    #[allow(clippy::too_many_arguments)]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        uv: &Bound<'py, PyAny>,
        duv_dx: Option<&Bound<'py, PyAny>>,
        duv_dy: Option<&Bound<'py, PyAny>>,
        filter: &str,
        lod_bias: f32,
        coords: &str,
        threads: Option<usize>,
        max_memory: Option<u64>,
    ) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let filter = filter_named(filter)?;
        let coords = coords_named(coords)?;
        let pool = pool::for_threads(threads)?;
        let mut budget = budget(max_memory);
        let (shape, points) = pairs_in(uv, "uv", &mut budget)?;
        let (given, grid) = derivatives(&shape, duv_dx, duv_dy, filter, &mut budget)?;
        if !lod_bias.is_finite() {
            return Err(PyValueError::new_err(format!(
                "lod_bias must be finite; got {lod_bias}"
            )));
        }
        let mut desc = filter.descriptor(self.address.0, self.address.1);
        desc.lod_bias = lod_bias;
        desc.border_color = self.border;
        let sampler = Sampler::new(desc).map_err(py_err(""))?;
        let mut full = shape;
        full.push(4);
        let values = full
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d))
            .ok_or_else(|| {
                PyValueError::new_err(format!("uv's shape {} is too large", tuple(&full)))
            })?;
        take(
            &mut budget,
            &format!("the samples ({} values of float32)", values),
            bytes_of(values as u64, 4),
        )?;
        take(
            &mut budget,
            "the footprints being sampled",
            bytes_of(
                (pool.current_num_threads() * POINTS_PER_TASK) as u64,
                std::mem::size_of::<Footprint>(),
            ),
        )?;
        let slot = self.charge_structure(&mut budget, &desc)?;
        let mut samples: Vec<f32> = Vec::new();
        reserve(&mut samples, values, "the samples")?;
        samples.resize(values, 0.0);
        let dst = samples.as_mut_slice();
        let points = Points {
            uv: points.values(),
            dx: given.as_ref().map(|(x, _)| x.values()),
            dy: given.as_ref().map(|(_, y)| y.values()),
            grid,
            scale: match coords {
                Coords::Uv => [1.0, 1.0],
                Coords::Pixels => [self.texture.width() as f32, self.texture.height() as f32],
            },
        };
        let texture = &*self.texture;
        let built = &self.built;
        run_released_on(py, &pool, move |_| {
            if let Some(k) = slot {
                // A structure that does not fit is a MemoryError, not a silent trilinear.
                texture.build_structures(&sampler).map_err(py_err(""))?;
                built[k].store(true, Ordering::Release);
            }
            let (quads, _) = dst.as_chunks_mut::<4>();
            quads
                .par_chunks_mut(POINTS_PER_TASK)
                .enumerate()
                .for_each(|(k, o)| {
                    let first = k * POINTS_PER_TASK;
                    let footprints: Vec<Footprint> = (first..first + o.len())
                        .map(|p| points.footprint(p))
                        .collect();
                    sampler.sample_batch(texture, &footprints[..], o);
                });
            Ok(())
        })?;
        array_out(py, &full, samples)
    }

    /// What pickling keeps: the level-0 texels (`H x W x 4`, as stored) and the options; the
    /// pyramid is rebuilt on loading, bit for bit the same.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let me = slf.get();
        let t = &me.texture;
        let mut b = budget(None);
        take(
            &mut b,
            "the copy of level 0 being pickled",
            u64::from(t.width()) * u64::from(t.height()) * t.format().texel_bytes(),
        )?;
        let (w, h) = (t.width(), t.height());
        let level0 = match t.level_texels(0) {
            Some(LevelTexels::Unorm8(v)) => rgba_out(py, w, h, v)?.into_any(),
            Some(LevelTexels::Float(v)) => rgba_out(py, w, h, v)?.into_any(),
            None => return Err(PyValueError::new_err("a texture without level 0")),
        };
        // Texture(array, color, address, address_u, address_v, border).
        let args = (
            level0,
            me.color(),
            me.address_u(),
            me.address_u(),
            me.address_v(),
            me.border(),
        );
        (slf.get_type(), args).into_pyobject(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "texel.Texture({}x{}, {}, {} levels, {}, address {}/{}, border {})",
            self.texture.width(),
            self.texture.height(),
            self.dtype(),
            self.texture.levels().len(),
            self.color(),
            self.address_u(),
            self.address_v(),
            self.border()
        )
    }
}

/// Warp `image` in perspective: the output's corners (top-left, top-right, bottom-right,
/// bottom-left) show the source points `corners` (pixels of `image`, eight numbers or four
/// pairs), each output pixel filtered over its exact footprint by `filter`. An 8-bit image is
/// read and written as `color` says (`"linear"`, the default: codes as stored; `"srgb"`: decoded
/// from sRGB and encoded back, what `texel warp` does with a PNG); a float one is linear in and
/// out. Outside the source is transparent black. The texture and the output are charged to
/// `max_memory`, else the process's memory limit.
#[pyfunction]
#[pyo3(signature = (image, corners, size = None, filter = "ewa", color = "linear", max_memory = None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn warp<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    corners: &Bound<'py, PyAny>,
    size: Option<(u32, u32)>,
    filter: &str,
    color: &str,
    max_memory: Option<u64>,
) -> PyResult<Bound<'py, PyAny>> {
    let filter = filter_named(filter)?;
    let srgb = srgb_named(color)?;
    let corners: Vec<f64> = match corners.extract::<Vec<f64>>() {
        Ok(flat) => flat,
        Err(_) => corners
            .extract::<Vec<(f64, f64)>>()
            .map(|pairs| pairs.into_iter().flat_map(|(x, y)| [x, y]).collect())
            .map_err(|_| {
                PyTypeError::new_err("corners must be eight numbers or four (x, y) pairs")
            })?,
    };
    if corners.len() != 8 {
        return Err(PyValueError::new_err(format!(
            "corners must be eight numbers (four x, y pairs); got {} numbers",
            corners.len()
        )));
    }
    let view = image_view(image, "image")?;
    let float = view.is_float();
    let (w, h) = size.unwrap_or((view.width, view.height));
    let mut budget = budget(max_memory);
    let pixels = u64::from(w) * u64::from(h);
    // The linear output, then its copy into the array (and the 8-bit encoding before it).
    let per_pixel = if float { 16 + 16 } else { 16 + 4 + 4 };
    take(
        &mut budget,
        &format!("the {w}x{h} warped image"),
        pixels.saturating_mul(per_pixel),
    )?;
    let (input, limits) = texture_input(&view, &mut budget)?;
    drop(view);
    let pool = pool::shared()?;
    let out = run_released_on(py, &pool, move |_| {
        let texture = build_texture(input, srgb, &limits)?;
        let mut desc = filter.descriptor(AddressMode::ClampToBorder, AddressMode::ClampToBorder);
        desc.border_color = BorderColor::TransparentBlack;
        let sampler = Sampler::new(desc).map_err(py_err(""))?;
        let quad = [0, 2, 4, 6].map(|k| DVec2::new(corners[k], corners[k + 1]));
        let pixels = warp_perspective(&texture, &sampler, quad, w, h)
            .map_err(|e| PyValueError::new_err(format!("cannot warp: {e}")))?;
        drop(texture);
        Ok(if float {
            Warped::Linear(pixels)
        } else {
            let encoding = encoding_of(srgb);
            Warped::Encoded(pixels.iter().map(|&c| encoding.encode(c)).collect())
        })
    })?;
    match out {
        Warped::Linear(p) => Ok(rgba_out(py, w, h, &p)?.into_any()),
        Warped::Encoded(p) => Ok(rgba_out(py, w, h, &p)?.into_any()),
    }
}

/// A warp's pixels: linear for a float image, encoded for an 8-bit one.
enum Warped {
    /// Linear RGBA.
    Linear(Vec<[f32; 4]>),
    /// 8-bit RGBA.
    Encoded(Vec<[u8; 4]>),
}

/// The 8-bit encoding `srgb` names.
pub(crate) fn encoding_of(srgb: bool) -> Encoding {
    if srgb {
        Encoding::Srgb
    } else {
        Encoding::Linear
    }
}

/// Encode linear `float32` values to the 8-bit values a PNG of them holds: `color="linear"` (the
/// default, also `"raw"`: `round(255 * c)`) or `"srgb"` (RGB sRGB-encoded), clamped to `[0, 1]`,
/// alpha linear. The last axis is channels (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA), widened to
/// RGBA: `(N, 4)` samples give `(N, 4)`, an `H x W x C` image `H x W x 4`. The output is
/// charged to `max_memory`, else the process's memory limit.
#[pyfunction]
#[pyo3(signature = (linear, color = "linear", max_memory = None))]
pub(crate) fn encode<'py>(
    py: Python<'py>,
    linear: &Bound<'py, PyAny>,
    color: &str,
    max_memory: Option<u64>,
) -> PyResult<Bound<'py, PyArrayDyn<u8>>> {
    let encoding = encoding_of(srgb_named(color)?);
    let input = values_in(linear, "linear")?;
    let c = input.channels;
    let n = input.values().len() / c;
    let mut budget = budget(max_memory);
    take(
        &mut budget,
        &format!("the {n} encoded RGBA values"),
        bytes_of(n as u64, 4),
    )?;
    let mut out: Vec<u8> = Vec::new();
    reserve(&mut out, 4 * n, "the encoded values")?;
    out.resize(4 * n, 0);
    let src = input.values();
    let dst = out.as_mut_slice();
    let pool = pool::shared()?;
    run_released_on(py, &pool, move |_| {
        dst.par_chunks_mut(4 * VALUES_PER_TASK)
            .zip(src.par_chunks(c * VALUES_PER_TASK))
            .for_each(|(o, i)| {
                for (o, i) in o.chunks_exact_mut(4).zip(i.chunks_exact(c)) {
                    o.copy_from_slice(&encoding.encode(widen_one(i, 1.0)));
                }
            });
        Ok(())
    })?;
    let mut shape = input.leading.clone();
    shape.push(4);
    array_out(py, &shape, out)
}
