//! Numpy arrays in and out, with the checks a caller's mistakes need: dtype, shape, memory
//! layout and finite values, each refused with a message that names the argument and says what
//! its shape looks like (a channels-first image, a batch of one, a grey image).

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use texel::texture::{Format, Limits};
use texel::MemoryBudget;

use crate::errors::to_py;
use crate::memory::{bytes_of, take};

/// An image's texels as RGBA, as the array held them (8-bit or float).
pub(crate) enum Texels {
    /// From a `uint8` array.
    U8(Vec<[u8; 4]>),
    /// From a `float32` array.
    F32(Vec<[f32; 4]>),
}

/// An `H x W x C` image array, its channels widened to RGBA.
pub(crate) struct ImageIn {
    pub width: u32,
    pub height: u32,
    pub texels: Texels,
}

/// A checked image array, read in place: its size and channels, not yet copied.
pub(crate) struct ImageView<'py> {
    pub width: u32,
    pub height: u32,
    channels: usize,
    data: ViewData<'py>,
    what: String,
}

/// The element type of an [`ImageView`].
enum ViewData<'py> {
    U8(PyReadonlyArrayDyn<'py, u8>),
    F32(PyReadonlyArrayDyn<'py, f32>),
}

impl ImageView<'_> {
    /// Whether the array is `float32`.
    pub(crate) fn is_float(&self) -> bool {
        matches!(self.data, ViewData::F32(_))
    }

    /// The texels widened to RGBA (a copy; charge it first).
    pub(crate) fn texels(&self) -> PyResult<ImageIn> {
        let texels = match &self.data {
            ViewData::U8(a) => {
                let data = a.as_slice().map_err(|_| not_contiguous(&self.what))?;
                Texels::U8(widen(data, self.channels, 255, &self.what)?)
            }
            ViewData::F32(a) => {
                let data = a.as_slice().map_err(|_| not_contiguous(&self.what))?;
                Texels::F32(widen(data, self.channels, 1.0, &self.what)?)
            }
        };
        Ok(ImageIn {
            width: self.width,
            height: self.height,
            texels,
        })
    }
}

/// A shape as Python prints it: `(4, 64, 64)`, `(5,)`.
pub(crate) fn tuple(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The dtype's name of any object (`"float64"`, or its Python type for a non-array).
fn dtype_name(obj: &Bound<'_, PyAny>) -> String {
    obj.getattr("dtype")
        .and_then(|d| d.str().map(|s| s.to_string()))
        .unwrap_or_else(|_| {
            obj.get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        })
}

/// Widen `C` channels (1: grey, 2: grey and alpha, 3: RGB, 4: RGBA) to RGBA with `one` as opaque.
pub(crate) fn widen_one<T: Copy>(p: &[T], one: T) -> [T; 4] {
    match p.len() {
        1 => [p[0], p[0], p[0], one],
        2 => [p[0], p[0], p[0], p[1]],
        3 => [p[0], p[1], p[2], one],
        _ => [p[0], p[1], p[2], p[3]],
    }
}

/// [`widen_one`] over a whole array of `c`-channel values.
fn widen<T: Copy>(data: &[T], c: usize, one: T, what: &str) -> PyResult<Vec<[T; 4]>> {
    let mut out = Vec::new();
    reserve(&mut out, data.len() / c, what)?;
    out.extend(data.chunks_exact(c).map(|p| widen_one(p, one)));
    Ok(out)
}

/// Reserve room for `n` more values, or raise `MemoryError` naming `what`.
pub(crate) fn reserve<T>(v: &mut Vec<T>, n: usize, what: &str) -> PyResult<()> {
    v.try_reserve_exact(n).map_err(|_| {
        PyMemoryError::new_err(format!(
            "cannot allocate {n} values of {} bytes for {what}",
            std::mem::size_of::<T>()
        ))
    })
}

/// A read-only view of `a` whose slice is its data in row-major order: refused unless the array
/// is C-contiguous (a Fortran-ordered array is contiguous too, but its slice is column-major)
/// and aligned for `T`.
fn c_order<'py, T: numpy::Element>(
    a: &Bound<'py, PyArrayDyn<T>>,
    what: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    if !a.is_c_contiguous() {
        return Err(not_contiguous(what));
    }
    if !(a.data() as usize).is_multiple_of(std::mem::align_of::<T>()) {
        return Err(PyValueError::new_err(format!(
            "{what} is not aligned for its dtype (a view at an odd byte offset): pass numpy.require({what}, requirements=\"CA\")"
        )));
    }
    Ok(a.try_readonly()?)
}

/// What an image array's wrong shape looks like, for the error.
fn image_shape_hint(shape: &[usize], what: &str) -> String {
    let s = tuple(shape);
    match *shape {
        [c, _, w] if (1..=4).contains(&c) && w > 4 => format!(
            "{what} has shape {s}: it looks channels-first (C, H, W); texel takes (H, W, C): pass numpy.ascontiguousarray(numpy.moveaxis({what}, 0, -1))"
        ),
        [1, _, _, c] if (1..=4).contains(&c) => format!(
            "{what} has shape {s}: it looks like a batch of one image (1, H, W, C); texel takes one image (H, W, C): pass {what}[0]"
        ),
        [_, _, c] => format!(
            "{what} has shape {s}: {c} channels; texel takes 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA) in the last axis"
        ),
        _ => format!("{what} must have shape (H, W) or (H, W, C); got {s}"),
    }
}

/// The shape `(H, W, C)` of an image array (`(H, W)` is one channel), checked.
fn image_shape(shape: &[usize], what: &str) -> PyResult<(u32, u32, usize)> {
    let (h, w, c) = match *shape {
        [h, w] => (h, w, 1),
        [h, w, c] if (1..=4).contains(&c) => (h, w, c),
        _ => return Err(PyValueError::new_err(image_shape_hint(shape, what))),
    };
    if h == 0 || w == 0 {
        return Err(PyValueError::new_err(format!(
            "{what} is empty: shape {}",
            tuple(shape)
        )));
    }
    let side = |n: usize| {
        u32::try_from(n).map_err(|_| {
            PyValueError::new_err(format!("{what} has a side of {n} texels, too large"))
        })
    };
    Ok((side(h)?, side(w)?, c))
}

/// Refuse an image beyond a texture's default limits before its texels are copied.
fn check_size(width: u32, height: u32, format: Format, what: &str) -> PyResult<()> {
    Limits::default()
        .check(width, height, format)
        .map_err(|e| to_py(e.into(), &format!("{what} cannot be a texture")))
}

/// The message for an array that is not C-contiguous.
fn not_contiguous(what: &str) -> PyErr {
    PyValueError::new_err(format!(
        "{what} is not C-contiguous (a strided view, a transpose or Fortran order): pass numpy.ascontiguousarray({what})"
    ))
}

/// Check an `H x W x C` `uint8` or `float32` image array and view it in place.
pub(crate) fn image_view<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<ImageView<'py>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<u8>>() {
        let (height, width, channels) = image_shape(a.shape(), what)?;
        check_size(width, height, Format::Rgba8Unorm, what)?;
        return Ok(ImageView {
            width,
            height,
            channels,
            data: ViewData::U8(c_order(a, what)?),
            what: what.to_string(),
        });
    }
    if let Ok(a) = obj.cast::<PyArrayDyn<f32>>() {
        let (height, width, channels) = image_shape(a.shape(), what)?;
        check_size(width, height, Format::Rgba32Float, what)?;
        return Ok(ImageView {
            width,
            height,
            channels,
            data: ViewData::F32(c_order(a, what)?),
            what: what.to_string(),
        });
    }
    Err(PyTypeError::new_err(format!(
        "{what} must be a numpy array of dtype uint8 or float32; got {}",
        dtype_name(obj)
    )))
}

/// A `(..., C)` array of linear `float32` values, C in 1-4, read in place.
pub(crate) struct ValuesIn<'py> {
    /// The shape less the channel axis.
    pub leading: Vec<usize>,
    /// Channels per value.
    pub channels: usize,
    array: PyReadonlyArrayDyn<'py, f32>,
}

impl ValuesIn<'_> {
    /// The values, `channels` per point, row-major.
    pub(crate) fn values(&self) -> &[f32] {
        // `values_in` admits C-contiguous arrays only.
        self.array.as_slice().unwrap_or(&[])
    }
}

/// Read a `(..., C)` `float32` array whose last axis is channels (1 grey, 2 grey and alpha, 3 RGB,
/// 4 RGBA): `(N, 4)` is N RGBA values, `(H, W, 4)` an image.
pub(crate) fn values_in<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<ValuesIn<'py>> {
    let Ok(a) = obj.cast::<PyArrayDyn<f32>>() else {
        return Err(PyTypeError::new_err(format!(
            "{what} must be a numpy array of dtype float32; got {}",
            dtype_name(obj)
        )));
    };
    let shape = a.shape().to_vec();
    let s = tuple(&shape);
    let channels = match shape.as_slice() {
        [.., c] if (1..=4).contains(c) => *c,
        [c, .., last] if (1..=4).contains(c) && shape.len() >= 3 => {
            return Err(PyValueError::new_err(format!(
                "{what} has shape {s}: it looks channels-first ({c} channels, then {last} values along the last axis); texel reads the last axis as channels: pass numpy.ascontiguousarray(numpy.moveaxis({what}, 0, -1))"
            )))
        }
        [_, _] => {
            return Err(PyValueError::new_err(format!(
                "{what} has shape {s}: it looks like a grey (H, W) image; texel reads the last axis as channels (1-4): pass {what}[..., None]"
            )))
        }
        _ => {
            return Err(PyValueError::new_err(format!(
                "{what} must have shape (..., C) with C channels in the last axis (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA); got {s}"
            )))
        }
    };
    let array = c_order(a, what)?;
    Ok(ValuesIn {
        leading: shape[..shape.len() - 1].to_vec(),
        channels,
        array,
    })
}

/// A `(..., 2)` array's values: borrowed from a `float32` array, or converted from `float64`.
pub(crate) enum Pairs<'py> {
    /// A C-contiguous `float32` array, read in place.
    Borrowed(PyReadonlyArrayDyn<'py, f32>),
    /// Converted from `float64`.
    Owned(Vec<f32>),
}

impl Pairs<'_> {
    /// The values, two per point.
    pub(crate) fn values(&self) -> &[f32] {
        match self {
            // Contiguity was checked when the pairs were read.
            Pairs::Borrowed(a) => a.as_slice().unwrap_or(&[]),
            Pairs::Owned(v) => v,
        }
    }
}

/// Whether every value is finite: a fold without early exit over blocks, which the compiler
/// vectorises (a search for the first non-finite value does not).
fn all_finite(values: &[f32]) -> bool {
    values
        .chunks(1024)
        .all(|block| block.iter().fold(true, |ok, x| ok & x.is_finite()))
}

/// The leading shape of a `(..., 2)` array, or the error saying what its shape looks like.
fn pairs_shape(shape: &[usize], what: &str) -> PyResult<Vec<usize>> {
    match shape {
        [.., 2] => Ok(shape[..shape.len() - 1].to_vec()),
        [2, ..] if shape.len() >= 2 => Err(PyValueError::new_err(format!(
            "{what} has shape {}: it looks channels-first (2, ...); texel takes (..., 2): pass numpy.ascontiguousarray(numpy.moveaxis({what}, 0, -1))",
            tuple(shape)
        ))),
        _ => Err(PyValueError::new_err(format!(
            "{what} must have shape (..., 2); got {}",
            tuple(shape)
        ))),
    }
}

/// Read a `(..., 2)` array of `float32` or `float64` pairs, C-contiguous, every value finite;
/// returns the leading shape and the values. A `float64` array's conversion is charged to
/// `budget` first.
pub(crate) fn pairs_in<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
    budget: &mut MemoryBudget,
) -> PyResult<(Vec<usize>, Pairs<'py>)> {
    let non_finite = |k: usize| {
        PyValueError::new_err(format!(
            "{what} holds a NaN or infinite value at flat index {k}"
        ))
    };
    if let Ok(a) = obj.cast::<PyArrayDyn<f32>>() {
        let shape = pairs_shape(a.shape(), what)?;
        let ro = c_order(a, what)?;
        let data = ro.as_slice().map_err(|_| not_contiguous(what))?;
        if !all_finite(data) {
            let k = data.iter().position(|x| !x.is_finite()).unwrap_or(0);
            return Err(non_finite(k));
        }
        return Ok((shape, Pairs::Borrowed(ro)));
    }
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        let shape = pairs_shape(a.shape(), what)?;
        let ro = c_order(a, what)?;
        let data = ro.as_slice().map_err(|_| not_contiguous(what))?;
        take(
            budget,
            &format!("{what} as float32 ({} values)", data.len()),
            bytes_of(data.len() as u64, 4),
        )?;
        // A finite double beyond f32's range would become infinite.
        let mut values = Vec::new();
        reserve(&mut values, data.len(), what)?;
        values.extend(data.iter().map(|&x| x as f32));
        if !all_finite(&values) {
            let k = values.iter().position(|x| !x.is_finite()).unwrap_or(0);
            return Err(non_finite(k));
        }
        return Ok((shape, Pairs::Owned(values)));
    }
    Err(PyTypeError::new_err(format!(
        "{what} must be a numpy array of dtype float32 or float64; got {}",
        dtype_name(obj)
    )))
}

/// A flat vector as an array of `shape`.
pub(crate) fn array_out<'py, T: numpy::Element>(
    py: Python<'py>,
    shape: &[usize],
    flat: Vec<T>,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let a = ArrayD::from_shape_vec(IxDyn(shape), flat)
        .map_err(|e| PyValueError::new_err(format!("internal shape error: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// RGBA pixels as an `H x W x 4` array (a copy of `pixels`: callers charge `16 * len` bytes for
/// `f32`, `4 * len` for `u8`).
pub(crate) fn rgba_out<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    width: u32,
    height: u32,
    pixels: &[[T; 4]],
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    array_out(
        py,
        &[height as usize, width as usize, 4],
        pixels.iter().flatten().copied().collect(),
    )
}
