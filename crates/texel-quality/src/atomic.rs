//! Atomic file writing: an interrupted run never leaves a truncated PNG or report behind.
//!
//! The bytes go to a new temporary file in the destination's directory (same file system, so the
//! rename is atomic on POSIX), which is flushed to disk (`sync_all`) and then renamed over the
//! destination. On any error the temporary file is removed. The temporary name is
//! `.NAME.PID.COUNTER.tmp`, created with `create_new` so concurrent writers never share one.

use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use image::ImageEncoder;

use crate::error::QualityError;
use crate::image8::checked_len;

static COUNTER: AtomicU64 = AtomicU64::new(0);

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> QualityError + '_ {
    move |source| QualityError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Write `bytes` to `path` atomically (module docs): readers see the old file or the whole new one.
///
/// # Errors
/// [`QualityError::Io`] with the path concerned: the directory does not exist or is not writable,
/// `path` names a directory or has no file name, the disk is full. No temporary file is left behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), QualityError> {
    let name = path.file_name().ok_or_else(|| QualityError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidInput, "no file name"),
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = dir.join(format!(
        ".{}.{}.{n}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let mut file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .map_err(io_err(path))?;
    let result = file
        .write_all(bytes)
        .and_then(|()| file.sync_all())
        .map_err(io_err(path))
        .and_then(|()| {
            drop(file);
            fs::rename(&tmp, path).map_err(io_err(path))
        });
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}

/// Encode packed `RGBARGBA...` 8-bit bytes as PNG in memory.
pub(crate) fn encode_png(width: u32, height: u32, rgba8: &[u8]) -> Result<Vec<u8>, QualityError> {
    let n = checked_len(width, height)?;
    if rgba8.len() != 4 * n {
        return Err(QualityError::DataLength {
            width,
            height,
            expected: 4 * n,
            got: rgba8.len(),
        });
    }
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(rgba8, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|source| QualityError::Image {
            path: PathBuf::new(),
            source,
        })?;
    Ok(out)
}

/// Encode `width x height` packed 8-bit RGBA bytes (`4 * width * height`, row 0 at the top) as PNG
/// and write it with [`write_atomic`].
///
/// # Errors
/// Size errors ([`QualityError::DataLength`], ...), [`QualityError::Image`] from the encoder, and
/// the errors of [`write_atomic`].
pub fn write_png_atomic(
    path: &Path,
    width: u32,
    height: u32,
    rgba8: &[u8],
) -> Result<(), QualityError> {
    write_atomic(path, &encode_png(width, height, rgba8)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("texel-quality-{tag}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_and_replaces() {
        let d = scratch("atomic-ok");
        let p = d.join("r.json");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second, longer").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"second, longer");
        assert_eq!(names(&d), vec!["r.json"]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn failure_leaves_nothing_behind() {
        let d = scratch("atomic-err");
        // Renaming a file over a non-empty directory fails after the temporary was written.
        let target = d.join("out.png");
        fs::create_dir_all(target.join("inside")).unwrap();
        let e = write_atomic(&target, b"data").unwrap_err();
        assert!(e.to_string().contains("out.png"), "{e}");
        assert_eq!(names(&d), vec!["out.png"]);
        // A missing directory: the error names the path.
        let missing = d.join("no/such/dir/x.png");
        let e = write_png_atomic(&missing, 1, 1, &[1, 2, 3, 4]).unwrap_err();
        assert!(matches!(e, QualityError::Io { .. }));
        assert!(e.to_string().contains("no/such/dir/x.png"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn png_length_checked() {
        let d = scratch("atomic-len");
        let e = write_png_atomic(&d.join("a.png"), 2, 2, &[0; 15]).unwrap_err();
        assert!(matches!(
            e,
            QualityError::DataLength {
                expected: 16,
                got: 15,
                ..
            }
        ));
        assert!(names(&d).is_empty());
        fs::remove_dir_all(&d).unwrap();
    }
}
