//! texel's errors as Python exceptions: `MemoryError` for what the memory budget or a texture's
//! limit refuses, `OSError` for files that cannot be read, `KeyboardInterrupt` for a cancelled
//! run, `ValueError` for the rest (bad values, malformed scenes). The message is texel's,
//! followed by its causes.

use std::error::Error as StdError;

use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyOSError, PyValueError};
use pyo3::PyErr;
use texel::texture::TextureError;

/// `e`'s message and each cause's that adds something, joined by `": "`.
pub(crate) fn message(e: &(dyn StdError + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let part = c.to_string();
        if !text.contains(&part) {
            text = format!("{text}: {part}");
        }
        cause = c.source();
    }
    text
}

/// Whether anything in `e`'s chain is an I/O error.
fn from_io(e: &(dyn StdError + 'static)) -> bool {
    let mut cur = Some(e);
    while let Some(c) = cur {
        if c.downcast_ref::<std::io::Error>().is_some() {
            return true;
        }
        cur = c.source();
    }
    false
}

/// Whether `e`'s chain holds a texture's memory-limit refusal.
fn over_memory(e: &(dyn StdError + 'static)) -> bool {
    let mut cur = Some(e);
    while let Some(c) = cur {
        if matches!(
            c.downcast_ref::<TextureError>(),
            Some(
                TextureError::OverMemoryLimit { .. }
                    | TextureError::StructureOverMemoryLimit { .. }
            )
        ) {
            return true;
        }
        cur = c.source();
    }
    false
}

/// The Python exception for a texel error, its message prefixed by `context` when not empty.
pub(crate) fn to_py(e: texel::Error, context: &str) -> PyErr {
    let text = match context {
        "" => message(&e),
        c => format!("{c}: {}", message(&e)),
    };
    match &e {
        texel::Error::OverBudget { .. } => PyMemoryError::new_err(text),
        texel::Error::Cancelled => PyKeyboardInterrupt::new_err(text),
        _ if over_memory(&e) => PyMemoryError::new_err(text),
        _ if from_io(&e) => PyOSError::new_err(text),
        _ => PyValueError::new_err(text),
    }
}

/// [`to_py`] for any error the libraries return.
pub(crate) fn py_err<E: Into<texel::Error>>(context: &str) -> impl Fn(E) -> PyErr + '_ {
    move |e| to_py(e.into(), context)
}
