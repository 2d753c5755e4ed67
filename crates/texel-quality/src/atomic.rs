//! Publishing output files: readers see the old output or the whole new one, never a torn one, and
//! nothing but a regular file (or a new path) is ever replaced.
//!
//! What [`write_atomic`] does depends on what the destination is (found with `lstat`, following
//! symbolic links by hand so that the link itself is kept):
//!
//! | destination | what happens |
//! |---|---|
//! | missing, or a regular file | bytes go to a temporary file in the same directory, `sync_all`, then `rename` over it (atomic on POSIX); a replaced file keeps its permissions |
//! | a symbolic link (chain) | its final target is published as above; the link stays a link |
//! | a character/block device or a FIFO | opened for writing (no create, no truncate) and written through: `/dev/null` stays `/dev/null`, `/dev/full` reports "No space left on device" |
//! | a directory (or a socket) | refused with an error naming the path |
//!
//! The temporary name is `.texel-HHHHHHHHHHHHHHHH.PID.N.tmp` (`H`: FNV-1a of the destination's
//! file name), 40-odd bytes whatever the destination is called, so every name the file system
//! accepts as an output also has a valid temporary. Temporaries in progress are registered:
//! [`remove_pending_and_exit`] (the CLI calls it on SIGINT/SIGTERM/SIGHUP) deletes them, and a
//! temporary left by a killed process (SIGKILL) is deleted by the next write to the same path once
//! its process is gone.
//!
//! [`publish_dir`] does the same for a multi-file output (a report): everything is written into a
//! hidden staging directory beside the destination, which then replaces the destination as a
//! whole, so an interrupted run never leaves an `index.html` describing another run's images.

use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

use image::ImageEncoder;

use crate::error::QualityError;
use crate::image8::check_data_len;

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Temporary files and staging directories this process has created and not yet published.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Symbolic links followed before giving up (Linux's `MAXSYMLINKS`).
const MAX_LINKS: usize = 40;

/// The marker file [`publish_dir`] leaves in every directory it publishes; a directory holding it
/// may be replaced by a later run.
pub const OUTPUT_MARKER: &str = ".texel-output";

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> QualityError + '_ {
    move |source| QualityError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn refuse(path: &Path, kind: std::io::ErrorKind, why: &str) -> QualityError {
    QualityError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(kind, why.to_string()),
    }
}

/// Delete every temporary file and staging directory this process has not yet published, then
/// exit with `code`. Meant for a signal handler (SIGINT, SIGTERM): it holds the registry's lock
/// until the process is gone, so no rename can publish a half-deleted output meanwhile.
pub fn remove_pending_and_exit(code: i32) -> ! {
    let guard = pending();
    for p in guard.iter() {
        if fs::remove_file(p).is_err() {
            let _ = fs::remove_dir_all(p);
        }
    }
    std::process::exit(code)
}

/// What a destination path turned out to be.
enum Destination {
    /// A regular file or a path that does not exist yet: publish by rename.
    Replaceable(PathBuf),
    /// A device node or FIFO: write through.
    Special(PathBuf),
}

/// Follow `path` through symbolic links (without following the last component of a missing one)
/// and classify what it names.
fn resolve(path: &Path) -> Result<Destination, QualityError> {
    // What the path finally names, links followed by the kernel: anything neither a regular file
    // nor a directory (a device, a FIFO, a pipe behind /dev/stdout or /proc/self/fd/N) is written
    // through at the path as given.
    if let Ok(meta) = fs::metadata(path) {
        let ft = meta.file_type();
        if !ft.is_file() && !ft.is_dir() && !is_socket(&ft) {
            return Ok(Destination::Special(path.to_path_buf()));
        }
    }
    let mut p = path.to_path_buf();
    for _ in 0..=MAX_LINKS {
        let meta = match fs::symlink_metadata(&p) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(Destination::Replaceable(p))
            }
            Err(e) => return Err(io_err(path)(e)),
        };
        let ft = meta.file_type();
        if ft.is_symlink() {
            let target = fs::read_link(&p).map_err(io_err(path))?;
            p = match p.parent() {
                Some(dir) if target.is_relative() => dir.join(target),
                _ => target,
            };
            continue;
        }
        if ft.is_file() {
            return Ok(Destination::Replaceable(p));
        }
        if ft.is_dir() {
            return Err(refuse(
                path,
                std::io::ErrorKind::InvalidInput,
                "is a directory, not a file",
            ));
        }
        if is_socket(&ft) {
            return Err(refuse(
                path,
                std::io::ErrorKind::InvalidInput,
                "is a socket: texel writes files, devices and FIFOs",
            ));
        }
        return Ok(Destination::Special(p));
    }
    Err(refuse(
        path,
        std::io::ErrorKind::InvalidInput,
        "too many levels of symbolic links",
    ))
}

#[cfg(unix)]
fn is_socket(ft: &fs::FileType) -> bool {
    use std::os::unix::fs::FileTypeExt;
    ft.is_socket()
}

#[cfg(not(unix))]
fn is_socket(_ft: &fs::FileType) -> bool {
    false
}

/// FNV-1a (64-bit) of a file name: the tag that ties a temporary to its destination.
fn name_tag(name: &std::ffi::OsStr) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in name.as_encoded_bytes() {
        h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!(".texel-{h:016x}.")
}

fn split_dest(path: &Path) -> Result<(PathBuf, String), QualityError> {
    let name = path.file_name().ok_or_else(|| {
        refuse(
            path,
            std::io::ErrorKind::InvalidInput,
            "names no file (it ends in .. or /)",
        )
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((dir, name_tag(name)))
}

/// Whether process `pid` still runs (Linux: `/proc/PID`). Elsewhere, a temporary counts as stale
/// once it is a day old.
fn owner_gone(pid: u32, entry: &fs::DirEntry) -> bool {
    if pid == std::process::id() {
        return false;
    }
    if Path::new("/proc/self").exists() {
        return !Path::new("/proc").join(pid.to_string()).exists();
    }
    entry
        .metadata()
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.elapsed().ok())
        .is_some_and(|age| age.as_secs() > 24 * 3600)
}

/// Remove temporaries `dir/{tag}PID.N...tmp` whose process is gone (left by a SIGKILL).
fn remove_stale(dir: &Path, tag: &str) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(rest) = name.to_str().and_then(|n| n.strip_prefix(tag)) else {
            continue;
        };
        if !rest.ends_with(".tmp") {
            continue;
        }
        let Some(pid) = rest.split('.').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        if owner_gone(pid, &entry) {
            let p = entry.path();
            if fs::remove_file(&p).is_err() {
                let _ = fs::remove_dir_all(&p);
            }
        }
    }
}

/// A fresh temporary name in `dir` for a destination tagged `tag`, registered as pending.
fn temporary(dir: &Path, tag: &str, suffix: &str) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    dir.join(format!("{tag}{}.{n}{suffix}.tmp", std::process::id()))
}

fn unregister(guard: &mut MutexGuard<'static, Vec<PathBuf>>, p: &Path) {
    guard.retain(|q| q != p);
}

/// Write `bytes` to `path` as the module docs say: atomically over a regular file or a new path,
/// through to a device or FIFO, to a symbolic link's target.
///
/// # Errors
/// [`QualityError::Io`] naming `path`: its directory is missing or not writable, it is a
/// directory or a socket, it has no file name, the disk or device is full. No temporary file is
/// left behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), QualityError> {
    let target = match resolve(path)? {
        Destination::Special(p) => {
            return OpenOptions::new()
                .write(true)
                .open(&p)
                .and_then(|mut f| f.write_all(bytes).and_then(|()| f.flush()))
                .map_err(io_err(path));
        }
        Destination::Replaceable(p) => p,
    };
    let (dir, tag) = split_dest(&target)?;
    remove_stale(&dir, &tag);
    let tmp = temporary(&dir, &tag, "");
    let mut file = {
        let mut guard = pending();
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(io_err(path))?;
        guard.push(tmp.clone());
        file
    };
    // A replaced file keeps its permissions (a fresh one gets the umask's).
    if let Ok(meta) = fs::metadata(&target) {
        let _ = file.set_permissions(meta.permissions());
    }
    let written = file
        .write_all(bytes)
        .and_then(|()| file.sync_all())
        .map_err(io_err(path));
    drop(file);
    let mut guard = pending();
    let result = written.and_then(|()| fs::rename(&tmp, &target).map_err(io_err(path)));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    unregister(&mut guard, &tmp);
    result
}

/// Whether an existing directory may be replaced by [`publish_dir`]: it is empty, or it holds
/// [`OUTPUT_MARKER`] (every directory `publish_dir` publishes does). Anything else may hold a
/// user's own files and is never replaced.
fn replaceable_dir(dir: &Path) -> bool {
    match fs::read_dir(dir) {
        Ok(mut entries) => entries.next().is_none() || dir.join(OUTPUT_MARKER).is_file(),
        Err(_) => false,
    }
}

/// Publish a multi-file output at `dest` as a whole: `fill` writes everything into a new staging
/// directory beside `dest` (it receives its path), then the staging directory replaces `dest`.
///
/// `dest` may be missing (its parents are created), an empty directory, or a directory an earlier
/// run published (it holds [`OUTPUT_MARKER`], which every published directory gets). A symbolic
/// link is followed and kept. The old directory is moved aside, the new one renamed into place and
/// the old one deleted; a process killed between the two renames leaves no `dest` at all, never a
/// mixture, and its hidden leftovers are deleted by the next publish to `dest`.
///
/// # Errors
/// [`QualityError::Io`] (converted into `E`) when `dest` is a file or device, a directory that
/// texel did not write, or cannot be created or renamed; any error of `fill`, after which the
/// staging directory is deleted and `dest` is unchanged.
pub fn publish_dir<T, E: From<QualityError>>(
    dest: &Path,
    fill: impl FnOnce(&Path) -> Result<T, E>,
) -> Result<T, E> {
    let mut target = dest.to_path_buf();
    let mut links = 0;
    let exists =
        loop {
            match fs::symlink_metadata(&target) {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => break false,
                Err(e) => return Err(io_err(dest)(e).into()),
                Ok(m) if m.file_type().is_symlink() && links < MAX_LINKS => {
                    links += 1;
                    let t = fs::read_link(&target).map_err(io_err(dest))?;
                    target = match target.parent() {
                        Some(dir) if t.is_relative() => dir.join(t),
                        _ => t,
                    };
                }
                Ok(m) if m.is_dir() => break true,
                Ok(_) => return Err(refuse(
                    dest,
                    std::io::ErrorKind::AlreadyExists,
                    "exists and is not a directory: choose a new or empty directory for the output",
                )
                .into()),
            }
        };
    if exists && !replaceable_dir(&target) {
        return Err(refuse(
            dest,
            std::io::ErrorKind::AlreadyExists,
            "is a directory texel did not write (it is not empty and has no .texel-output marker): \
             choose a new or empty directory, or remove it",
        )
        .into());
    }
    let (parent, tag) = split_dest(&target)?;
    fs::create_dir_all(&parent).map_err(io_err(dest))?;
    remove_stale(&parent, &tag);
    let staging = temporary(&parent, &tag, "");
    {
        let mut guard = pending();
        fs::create_dir(&staging).map_err(io_err(dest))?;
        guard.push(staging.clone());
    }
    let filled = fill(&staging).and_then(|v| {
        fs::write(
            staging.join(OUTPUT_MARKER),
            b"written by texel; may be replaced by texel\n",
        )
        .map_err(|e| E::from(io_err(dest)(e)))?;
        Ok(v)
    });
    let mut guard = pending();
    let result = filled.and_then(|v| {
        if exists {
            let old = temporary(&parent, &tag, ".old");
            fs::rename(&target, &old).map_err(|e| E::from(io_err(dest)(e)))?;
            if let Err(e) = fs::rename(&staging, &target) {
                let _ = fs::rename(&old, &target);
                return Err(io_err(dest)(e).into());
            }
            let _ = fs::remove_dir_all(&old);
        } else {
            fs::rename(&staging, &target).map_err(|e| E::from(io_err(dest)(e)))?;
        }
        Ok(v)
    });
    if result.is_err() {
        let _ = fs::remove_dir_all(&staging);
    }
    unregister(&mut guard, &staging);
    result
}

/// Encode packed `RGBARGBA...` 8-bit bytes as PNG in memory.
pub(crate) fn encode_png(width: u32, height: u32, rgba8: &[u8]) -> Result<Vec<u8>, QualityError> {
    check_data_len(width, height, 4, rgba8.len())?;
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

/// Encode `width x height` linear RGBA floats (row 0 at the top) as OpenEXR (32-bit float
/// channels R, G, B, A) in memory.
///
/// # Errors
/// Size errors ([`QualityError::DataLength`], ...) and [`QualityError::Image`] from the encoder.
pub fn encode_exr(width: u32, height: u32, rgba: &[[f32; 4]]) -> Result<Vec<u8>, QualityError> {
    check_data_len(width, height, 1, rgba.len())?;
    let bytes: Vec<u8> = rgba
        .iter()
        .flatten()
        .flat_map(|c| c.to_le_bytes())
        .collect();
    let mut out = std::io::Cursor::new(Vec::new());
    image::codecs::openexr::OpenExrEncoder::new(&mut out)
        .write_image(&bytes, width, height, image::ExtendedColorType::Rgba32F)
        .map_err(|source| QualityError::Image {
            path: PathBuf::new(),
            source,
        })?;
    Ok(out.into_inner())
}

/// Encode linear RGBA floats as OpenEXR ([`encode_exr`]) and write them with [`write_atomic`].
///
/// # Errors
/// As [`encode_exr`] and [`write_atomic`].
pub fn write_exr_atomic(
    path: &Path,
    width: u32,
    height: u32,
    rgba: &[[f32; 4]],
) -> Result<(), QualityError> {
    write_atomic(path, &encode_exr(width, height, rgba)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trips_floats_exactly() {
        let px: Vec<[f32; 4]> = (0..6)
            .map(|k| [k as f32 * 0.25, 3.5e3, -1.0 / 3.0, 1.0])
            .collect();
        let bytes = encode_exr(3, 2, &px).unwrap();
        let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::OpenExr)
            .unwrap()
            .to_rgba32f();
        assert_eq!((img.width(), img.height()), (3, 2));
        for (got, want) in img.pixels().zip(&px) {
            assert_eq!(&got.0, want);
        }
        assert!(matches!(
            encode_exr(3, 2, &px[..5]),
            Err(QualityError::DataLength { .. })
        ));
    }

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
        // A directory is refused before anything is written.
        let target = d.join("out.png");
        fs::create_dir_all(target.join("inside")).unwrap();
        let e = write_atomic(&target, b"data").unwrap_err();
        assert!(e.to_string().contains("out.png"), "{e}");
        assert!(e.to_string().contains("is a directory"), "{e}");
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

    #[cfg(unix)]
    #[test]
    fn symlink_target_written_and_link_kept() {
        let d = scratch("atomic-link");
        fs::create_dir_all(d.join("real")).unwrap();
        fs::write(d.join("real/t.png"), b"old").unwrap();
        std::os::unix::fs::symlink("real/t.png", d.join("link.png")).unwrap();
        write_atomic(&d.join("link.png"), b"new").unwrap();
        assert!(fs::symlink_metadata(d.join("link.png"))
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(fs::read(d.join("real/t.png")).unwrap(), b"new");
        // A dangling link creates its target.
        std::os::unix::fs::symlink("real/new.png", d.join("dangling.png")).unwrap();
        write_atomic(&d.join("dangling.png"), b"x").unwrap();
        assert_eq!(fs::read(d.join("real/new.png")).unwrap(), b"x");
        assert_eq!(names(&d.join("real")), vec!["new.png", "t.png"]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn devices_are_written_through() {
        write_atomic(Path::new("/dev/null"), b"discarded").unwrap();
        assert!(!fs::symlink_metadata("/dev/null").unwrap().is_file());
        let e = write_atomic(Path::new("/dev/full"), b"x").unwrap_err();
        assert!(e.to_string().contains("/dev/full"), "{e}");
        assert!(matches!(&e, QualityError::Io { source, .. } if source.raw_os_error() == Some(28)));
    }

    #[test]
    fn long_names_and_stale_temporaries() {
        let d = scratch("atomic-long");
        let long = "n".repeat(250);
        write_atomic(&d.join(&long), b"ok").unwrap();
        assert_eq!(fs::read(d.join(&long)).unwrap(), b"ok");
        // A temporary of a process that no longer runs (pid beyond pid_max) is swept away by the
        // next write to the same path; another destination's temporary is left alone.
        let tag = name_tag(std::ffi::OsStr::new("a.png"));
        let stale = d.join(format!("{tag}4294967294.0.tmp"));
        fs::write(&stale, b"half").unwrap();
        let other = d.join(format!("{}4294967294.0.tmp", name_tag("b.png".as_ref())));
        fs::write(&other, b"half").unwrap();
        write_atomic(&d.join("a.png"), b"whole").unwrap();
        if Path::new("/proc/self").exists() {
            assert!(!stale.exists());
        }
        assert!(other.exists());
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn publish_dir_replaces_whole() {
        let d = scratch("atomic-dir");
        let out = d.join("report");
        publish_dir::<_, QualityError>(&out, |s| {
            fs::write(s.join("a.png"), b"1").map_err(io_err(s))
        })
        .unwrap();
        assert_eq!(names(&out), vec![OUTPUT_MARKER, "a.png"]);
        // A second run replaces everything: no file of the first run survives.
        publish_dir::<_, QualityError>(&out, |s| {
            fs::write(s.join("b.png"), b"2").map_err(io_err(s))
        })
        .unwrap();
        assert_eq!(names(&out), vec![OUTPUT_MARKER, "b.png"]);
        // A failing run leaves the last published output and no staging directory.
        let e = publish_dir::<(), QualityError>(&out, |s| {
            fs::write(s.join("c.png"), b"3").unwrap();
            Err(refuse(s, std::io::ErrorKind::Other, "stopped"))
        });
        assert!(e.is_err());
        assert_eq!(names(&out), vec![OUTPUT_MARKER, "b.png"]);
        assert_eq!(names(&d), vec!["report"]);
        // A directory with someone else's files is refused, untouched; so is a file.
        let mine = d.join("mine");
        fs::create_dir_all(&mine).unwrap();
        fs::write(mine.join("notes.txt"), b"keep").unwrap();
        let e = publish_dir::<(), QualityError>(&mine, |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("did not write"), "{e}");
        assert_eq!(names(&mine), vec!["notes.txt"]);
        fs::write(d.join("file"), b"f").unwrap();
        let e = publish_dir::<(), QualityError>(&d.join("file"), |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("not a directory"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }
}
