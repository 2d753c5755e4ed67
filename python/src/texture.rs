//! `texel.Texture` (a texture with its mip pyramid, sampled by any filter on arrays of points),
//! `texel.warp` and the 8-bit encoding of linear colour.

use std::str::FromStr;
use std::sync::Arc;

use glam::DVec2;
use numpy::PyArrayDyn;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use rayon::prelude::*;
use texel::quality::{Encoding, Image8};
use texel::raster::warp::warp_perspective;
use texel::texture::{
    AddressMode, BorderColor, ColorSpace, Footprint, LevelTexels, Limits, Sampler,
};
use texel::Filter;

use crate::arrays::{array_out, image_in, pairs_in, reserve, rgba_out, ImageIn, Pairs, Texels};
use crate::errors::py_err;
use crate::run_released;

/// Points a worker samples at a time.
const POINTS_PER_TASK: usize = 4096;

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

/// How 8-bit values are stored: `"srgb"` (sRGB-encoded RGB) or `"linear"` (`"raw"`).
pub(crate) fn srgb_named(name: &str) -> PyResult<bool> {
    match name {
        "srgb" => Ok(true),
        "linear" | "raw" => Ok(false),
        _ => Err(PyValueError::new_err(format!(
            "unknown colour handling {name:?}: valid values are srgb, linear (raw)"
        ))),
    }
}

/// A texture from an image array: 8-bit as `srgb` says, float as linear values.
fn texture_of(image: ImageIn, srgb: bool) -> PyResult<texel::Texture> {
    let limits = Limits::default();
    let (w, h) = (image.width, image.height);
    match image.texels {
        Texels::U8(t) => {
            let color = if srgb {
                ColorSpace::Srgb
            } else {
                ColorSpace::Linear
            };
            texel::Texture::from_rgba8(w, h, t, color, &limits)
        }
        Texels::F32(t) => texel::Texture::from_rgba32f(w, h, t, &limits),
    }
    .map_err(py_err("cannot make a texture"))
}

/// A texture and its mip pyramid, with the address modes and border colour its samples use.
///
/// `array` is an `H x W x C` numpy array, `uint8` or `float32`, C in 1-4 (grey, grey and alpha,
/// RGB, RGBA; `H x W` is grey). Row 0 is the top of the image, where `v = 0`. 8-bit RGB is
/// decoded as `color` says (`"srgb"`, or `"linear"` for data such as normal maps); float values
/// are linear already and must be finite and within +-2^64. `address` sets both axes
/// (`address_u`/`address_v` override one): `"repeat"`, `"clamp"`, `"mirror"`, `"clamp-to-border"` or
/// `"mirror-clamp-to-edge"`; `border` is the colour outside the texture under `clamp-to-border`.
#[pyclass(frozen, module = "texel")]
pub struct Texture {
    texture: Arc<texel::Texture>,
    address: (AddressMode, AddressMode),
    border: BorderColor,
    srgb: bool,
}

#[pymethods]
impl Texture {
    #[new]
    #[pyo3(signature = (array, color = "srgb", address = "repeat", address_u = None, address_v = None, border = "transparent-black"))]
    fn new(
        py: Python<'_>,
        array: &Bound<'_, PyAny>,
        color: &str,
        address: &str,
        address_u: Option<&str>,
        address_v: Option<&str>,
        border: &str,
    ) -> PyResult<Self> {
        let srgb = srgb_named(color)?;
        let both = address_named(address)?;
        let u = address_u.map_or(Ok(both), address_named)?;
        let v = address_v.map_or(Ok(both), address_named)?;
        let border = border_named(border)?;
        let image = image_in(array, "array")?;
        let texture = run_released(py, |_| texture_of(image, srgb))?;
        Ok(Texture {
            texture: Arc::new(texture),
            address: (u, v),
            border,
            srgb,
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

    /// The mip pyramid, level 0 first, down to 1 x 1: one `H x W x 4` array per level in the
    /// texture's storage (`uint8` codes, sRGB-encoded when the texture is sRGB, or linear
    /// `float32`). Each level is the 2 x 2 box mean of the one above, in linear light.
    fn levels<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
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
    /// `uv` has shape `(..., 2)`: texture coordinates `(u, v)`, `0..1` spanning the texture once
    /// (`v = 0` is row 0, the top). `duv_dx` and `duv_dy`, of the same shape, are the footprint:
    /// how `(u, v)` changes from one output pixel to the next in x and in y (uv units per pixel).
    /// The filters that read mip levels or footprints (mip-nearest, trilinear, aniso2-16, ewa,
    /// ripmap, sat) need them; nearest, bilinear and bicubic read level 0 and may omit them.
    /// `lod_bias` is added to the level of detail. Arrays are `float32` or `float64`, C-contiguous
    /// and finite. The GIL is released while texel's threads sample.
    #[pyo3(signature = (uv, duv_dx = None, duv_dy = None, filter = "trilinear", lod_bias = 0.0))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        uv: &Bound<'py, PyAny>,
        duv_dx: Option<&Bound<'py, PyAny>>,
        duv_dy: Option<&Bound<'py, PyAny>>,
        filter: &str,
        lod_bias: f32,
    ) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let filter = filter_named(filter)?;
        let (shape, points) = pairs_in(uv, "uv")?;
        let derivative = |d: Option<&Bound<'py, PyAny>>,
                          what: &str|
         -> PyResult<Option<Pairs<'py>>> {
            match d {
                Some(d) => {
                    let (s, v) = pairs_in(d, what)?;
                    if s != shape {
                        return Err(PyValueError::new_err(format!(
                            "{what} has shape {:?} but uv has {:?}: they must match",
                            [s.as_slice(), &[2]].concat(),
                            [shape.as_slice(), &[2]].concat()
                        )));
                    }
                    Ok(Some(v))
                }
                None if matches!(filter, Filter::Nearest | Filter::Bilinear | Filter::Bicubic) => {
                    Ok(None)
                }
                None => Err(PyValueError::new_err(format!(
                    "filter {} reads mip levels chosen by the footprint: pass duv_dx and duv_dy",
                    filter.name()
                ))),
            }
        };
        let dx = derivative(duv_dx, "duv_dx")?;
        let dy = derivative(duv_dy, "duv_dy")?;
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
            .ok_or_else(|| PyValueError::new_err(format!("uv's shape {full:?} is too large")))?;
        let mut samples: Vec<f32> = Vec::new();
        reserve(&mut samples, values, "the samples")?;
        samples.resize(values, 0.0);
        let dst = samples.as_mut_slice();
        let (uv, dx, dy) = (
            points.values(),
            dx.as_ref().map(Pairs::values),
            dy.as_ref().map(Pairs::values),
        );
        let texture = &*self.texture;
        run_released(py, move |_| {
            let (quads, _) = dst.as_chunks_mut::<4>();
            quads
                .par_chunks_mut(POINTS_PER_TASK)
                .enumerate()
                .for_each(|(k, o)| {
                    let first = k * POINTS_PER_TASK;
                    let pair = |d: Option<&[f32]>, p: usize| {
                        d.map_or([0.0; 2], |d| [d[2 * p], d[2 * p + 1]])
                    };
                    let footprints: Vec<Footprint> = (first..first + o.len())
                        .map(|p| {
                            let [dudx, dvdx] = pair(dx, p);
                            let [dudy, dvdy] = pair(dy, p);
                            Footprint {
                                u: uv[2 * p],
                                v: uv[2 * p + 1],
                                dudx,
                                dvdx,
                                dudy,
                                dvdy,
                            }
                        })
                        .collect();
                    sampler.sample_batch(texture, &footprints[..], o);
                });
            Ok(())
        })?;
        array_out(py, &full, samples)
    }

    fn __repr__(&self) -> String {
        format!(
            "texel.Texture({}x{}, {}, {} levels, {}, address {:?}/{:?})",
            self.texture.width(),
            self.texture.height(),
            self.dtype(),
            self.texture.levels().len(),
            if self.srgb { "srgb" } else { "linear" },
            self.address.0,
            self.address.1
        )
    }
}

/// Warp `image` in perspective: the output's corners (top-left, top-right, bottom-right,
/// bottom-left) show the source points `corners` (pixels of `image`, eight numbers or four
/// pairs), each output pixel filtered over its exact footprint by `filter`. Returns `uint8`
/// encoded as `color` says for an 8-bit image (what `texel warp` writes), linear `float32` for a
/// float one. Outside the source is transparent black.
#[pyfunction]
#[pyo3(signature = (image, corners, size = None, filter = "ewa", color = "srgb"))]
pub fn warp<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    corners: &Bound<'py, PyAny>,
    size: Option<(u32, u32)>,
    filter: &str,
    color: &str,
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
    let image = image_in(image, "image")?;
    let float = matches!(image.texels, Texels::F32(_));
    let (w, h) = size.unwrap_or((image.width, image.height));
    let pixels = run_released(py, move |_| {
        let texture = texture_of(image, srgb)?;
        let mut desc = filter.descriptor(AddressMode::ClampToBorder, AddressMode::ClampToBorder);
        desc.border_color = BorderColor::TransparentBlack;
        let sampler = Sampler::new(desc).map_err(py_err(""))?;
        let quad = [0, 2, 4, 6].map(|k| DVec2::new(corners[k], corners[k + 1]));
        warp_perspective(&texture, &sampler, quad, w, h)
            .map_err(|e| PyValueError::new_err(format!("cannot warp: {e}")))
    })?;
    if float {
        return Ok(rgba_out(py, w, h, &pixels)?.into_any());
    }
    let encoded = encoded(w, h, &pixels, srgb)?;
    Ok(rgba_out(py, w, h, encoded.pixels())?.into_any())
}

/// Linear RGBA as the 8-bit image texel writes.
pub(crate) fn encoded(w: u32, h: u32, pixels: &[[f32; 4]], srgb: bool) -> PyResult<Image8> {
    let encoding = if srgb {
        Encoding::Srgb
    } else {
        Encoding::Linear
    };
    Image8::from_linear(w, h, pixels, encoding).map_err(py_err(""))
}

/// Encode linear RGBA (`H x W x 4` `float32`) to the 8-bit values a PNG of it holds: sRGB
/// (`color="srgb"`) or `round(255 * c)` (`"linear"`), clamped to `[0, 1]`, alpha linear.
#[pyfunction]
#[pyo3(signature = (linear, color = "srgb"))]
pub fn encode<'py>(
    py: Python<'py>,
    linear: &Bound<'py, PyAny>,
    color: &str,
) -> PyResult<Bound<'py, PyArrayDyn<u8>>> {
    let srgb = srgb_named(color)?;
    let image = image_in(linear, "linear")?;
    let Texels::F32(pixels) = image.texels else {
        return Err(PyTypeError::new_err("linear must be a float32 array"));
    };
    let e = encoded(image.width, image.height, &pixels, srgb)?;
    rgba_out(py, image.width, image.height, e.pixels())
}
