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
//! | an open descriptor's link (`/dev/stdout`, `/dev/stderr`, `/dev/fd/N`, `/proc/PID/fd/N`, or a link chain through one) | written through as a stream: standard output and error through their own handles, so `>> log.txt` appends; another descriptor reopened in its mode (appending, or at its offset); nothing truncated, renamed or created, even when the file behind it is deleted |
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

use std::collections::HashSet;
use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::SystemTime;

use thiserror::Error;

/// A file or directory could not be published: the path concerned and why.
#[derive(Debug, Error)]
#[error("{path}: {source}")]
pub struct OutputError {
    /// The file or directory concerned.
    pub path: PathBuf,
    /// The underlying error.
    pub source: std::io::Error,
}

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

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError {
        path: path.to_path_buf(),
        source,
    }
}

fn refuse(path: &Path, kind: std::io::ErrorKind, why: &str) -> OutputError {
    OutputError {
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
    /// An open file descriptor's link (`/proc/PID/fd/N`, reached directly or through `/dev/fd`,
    /// `/dev/stdout`, `/dev/stderr`): written through as the stream it is.
    Descriptor(FdLink),
}

/// A link under `/proc/PID/fd/` (or `/proc/PID/task/TID/fd/`), and what its descriptor is.
struct FdLink {
    /// The link itself; opening it reopens the descriptor's file, even a deleted one.
    link: PathBuf,
    /// Whether the descriptor is this process's own.
    own: bool,
    /// The descriptor's number.
    fd: u32,
}

/// If `p` is an entry of a `/proc/*/fd` directory (its parent, links resolved, is `/proc/PID/fd`
/// or `/proc/PID/task/TID/fd`), that descriptor.
fn fd_link(p: &Path) -> Option<FdLink> {
    let fd: u32 = p.file_name()?.to_str()?.parse().ok()?;
    let parent = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let dir = fs::canonicalize(parent).ok()?;
    let parts: Vec<&str> = dir.iter().filter_map(|c| c.to_str()).collect();
    let pid = match parts.as_slice() {
        ["/", "proc", pid, "fd"] | ["/", "proc", pid, "task", _, "fd"] => *pid,
        _ => return None,
    };
    let pid: u32 = pid.parse().ok()?;
    Some(FdLink {
        link: dir.join(fd.to_string()),
        own: pid == std::process::id(),
        fd,
    })
}

/// The `flags` and `pos` of a descriptor from `/proc/PID/fdinfo/N` (octal flags, byte offset).
fn fd_info(link: &Path) -> Option<(u32, u64)> {
    let fd = link.file_name()?;
    let info = link.parent()?.parent()?.join("fdinfo").join(fd);
    let text = fs::read_to_string(info).ok()?;
    let field = |name: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(name))
            .map(|v| v.trim().to_string())
    };
    let flags = u32::from_str_radix(&field("flags:")?, 8).ok()?;
    let pos = field("pos:")?.parse().ok()?;
    Some((flags, pos))
}

/// Linux's `O_APPEND` (octal 010 on MIPS, SPARC and Alpha, 02000 elsewhere).
#[cfg(not(any(target_arch = "mips", target_arch = "mips64", target_arch = "sparc64")))]
const O_APPEND: u32 = 0o2000;
#[cfg(any(target_arch = "mips", target_arch = "mips64", target_arch = "sparc64"))]
const O_APPEND: u32 = 0o10;
/// Linux's access-mode bits of a descriptor's flags (0: read only).
const O_ACCMODE: u32 = 0o3;

/// Write `bytes` through an open descriptor's link: this process's standard output and error
/// through their own handles (sharing the shell's offset and append mode); any other descriptor
/// by reopening its link: appending where it appends, and a pipe, terminal or device as it is. A
/// descriptor open for reading only, or a regular file's that does not append (its offset could
/// not be moved past texel's bytes), is refused. Nothing is truncated, renamed or created.
fn write_descriptor(d: &FdLink, bytes: &[u8], path: &Path) -> Result<(), OutputError> {
    if d.own && (d.fd == 1 || d.fd == 2) {
        let written = if d.fd == 1 {
            let mut out = std::io::stdout().lock();
            out.write_all(bytes).and_then(|()| out.flush())
        } else {
            let mut err = std::io::stderr().lock();
            err.write_all(bytes).and_then(|()| err.flush())
        };
        return written.map_err(io_err(path));
    }
    let meta = fs::metadata(&d.link).map_err(io_err(path))?;
    if meta.is_dir() {
        return Err(refuse(
            path,
            std::io::ErrorKind::InvalidInput,
            "is an open directory, not a file",
        ));
    }
    let Some((flags, _pos)) = fd_info(&d.link) else {
        return Err(refuse(
            path,
            std::io::ErrorKind::InvalidInput,
            "names an open descriptor whose mode cannot be read (/proc/PID/fdinfo)",
        ));
    };
    if flags & O_ACCMODE == 0 {
        return Err(refuse(
            path,
            std::io::ErrorKind::PermissionDenied,
            "names a descriptor open for reading only: texel does not write into it",
        ));
    }
    let append = flags & O_APPEND != 0;
    if meta.is_file() && !append {
        // Reopened, the file would be written at the descriptor's offset without moving it, and
        // the descriptor's next write would overwrite texel's bytes.
        return Err(refuse(
            path,
            std::io::ErrorKind::InvalidInput,
            "names a descriptor on a regular file that is not open for appending: open it with \
             >> or give the file's own path",
        ));
    }
    let mut file = OpenOptions::new()
        .write(true)
        .append(append)
        .open(&d.link)
        .map_err(io_err(path))?;
    file.write_all(bytes)
        .and_then(|()| file.flush())
        .map_err(io_err(path))
}

/// Follow `path` through symbolic links (without following the last component of a missing one)
/// and classify what it names.
fn resolve(path: &Path) -> Result<Destination, OutputError> {
    // A path that reaches an open descriptor's link is that descriptor, whatever it holds: a
    // shell's `>> log.txt` behind /dev/stdout is appended to, never replaced, and a deleted file
    // behind the link is not recreated under its link text's name.
    if let Some(d) = descriptor_on_path(path)? {
        return Ok(Destination::Descriptor(d));
    }
    // What the path finally names, links followed by the kernel: anything neither a regular file
    // nor a directory (a device, a FIFO, a pipe) is written through at the path as given.
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

/// Follow `path`'s chain of symbolic links by hand and return the first `/proc/*/fd` entry on it.
fn descriptor_on_path(path: &Path) -> Result<Option<FdLink>, OutputError> {
    let mut p = path.to_path_buf();
    for _ in 0..=MAX_LINKS {
        if let Some(d) = fd_link(&p) {
            return Ok(Some(d));
        }
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = fs::read_link(&p).map_err(io_err(path))?;
                p = match p.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(None),
        }
    }
    Ok(None)
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

fn split_dest(path: &Path) -> Result<(PathBuf, String), OutputError> {
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
/// A directory that a killed [`publish_dir`] moved aside (`....old.tmp`) may hold files a user
/// saved into the published directory: unless everything in it is listed by its marker, it is
/// kept, renamed beside `target` as `NAME.texel-kept`, never deleted.
fn settle_stale_old(p: &Path, target: Option<&Path>) {
    let owned = Owned::of(p);
    let mut foreign = Vec::new();
    clashes_or_foreign(p, None, &owned, Path::new(""), &mut foreign);
    if foreign.is_empty() {
        let _ = fs::remove_dir_all(p);
    } else if let Some(target) = target {
        let kept = visible_sibling(target, "kept");
        if fs::rename(p, &kept).is_ok() {
            eprintln!(
                "texel: warning: an interrupted earlier publish of {} left files texel did not \
                 write; they are kept in {}",
                target.display(),
                kept.display()
            );
        }
    }
}

fn remove_stale(dir: &Path, tag: &str, target: Option<&Path>) {
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
            if entry.file_type().is_ok_and(|t| t.is_dir()) {
                if rest.ends_with(".old.tmp") {
                    settle_stale_old(&p, target);
                } else {
                    // A staging directory: only what texel wrote.
                    let _ = fs::remove_dir_all(&p);
                }
            } else {
                let _ = fs::remove_file(&p);
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
/// [`OutputError`] naming `path`: its directory is missing or not writable, it is a
/// directory or a socket, it has no file name, the disk or device is full. No temporary file is
/// left behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    let target = match resolve(path)? {
        Destination::Descriptor(d) => return write_descriptor(&d, bytes, path),
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
    remove_stale(&dir, &tag, None);
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

/// Whether an existing directory may be published over by [`publish_dir`]: it is empty, or it
/// holds [`OUTPUT_MARKER`] (every directory `publish_dir` publishes does). Anything else may hold
/// a user's own files and is refused.
fn replaceable_dir(dir: &Path) -> bool {
    match fs::read_dir(dir) {
        Ok(mut entries) => entries.next().is_none() || dir.join(OUTPUT_MARKER).is_file(),
        Err(_) => false,
    }
}

/// The first line of [`OUTPUT_MARKER`]; the files texel wrote follow the line `files:`.
const MARKER_HEADER: &str = "written by texel; may be replaced by texel";

/// Which entries of a published directory texel wrote, as its marker says.
enum Owned {
    /// The files listed in the marker (relative paths); an unmarked directory lists none.
    Listed(HashSet<PathBuf>),
    /// A marker without a list: the files older than the marker ([`older`]).
    Before(SystemTime),
}

impl Owned {
    /// Read the marker of `dir` (a directory without one owns nothing).
    fn of(dir: &Path) -> Owned {
        let marker = dir.join(OUTPUT_MARKER);
        let Ok(text) = fs::read_to_string(&marker) else {
            return Owned::Listed(HashSet::new());
        };
        let mut lines = text.lines();
        if lines.any(|l| l == "files:") {
            return Owned::Listed(lines.map(PathBuf::from).collect());
        }
        match fs::metadata(&marker).and_then(|m| m.modified()) {
            Ok(t) => Owned::Before(t),
            Err(_) => Owned::Listed(HashSet::new()),
        }
    }

    /// Whether texel wrote the file at `rel` (`full` is its path now).
    fn file(&self, rel: &Path, full: &Path) -> bool {
        if rel == Path::new(OUTPUT_MARKER) {
            return true;
        }
        match self {
            Owned::Listed(set) => set.contains(rel),
            Owned::Before(t) => fs::symlink_metadata(full).is_ok_and(|m| older(&m, *t)),
        }
    }

    /// Whether the directory at `rel` may hold files texel wrote.
    fn may_hold(&self, rel: &Path) -> bool {
        match self {
            Owned::Listed(set) => set.iter().any(|p| p.starts_with(rel)),
            Owned::Before(_) => true,
        }
    }
}

/// Whether a file's modification and (on Unix) status-change times both lie strictly before `t`:
/// a file moved or copied into a directory after its marker keeps an old modification time, but
/// gets a new change time.
fn older(m: &fs::Metadata, t: SystemTime) -> bool {
    let modified = m.modified().is_ok_and(|x| x < t);
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let since = |x: SystemTime| x.duration_since(SystemTime::UNIX_EPOCH).ok();
        let changed = since(t).is_some_and(|d| {
            let c = std::time::Duration::new(m.ctime().max(0) as u64, m.ctime_nsec().max(0) as u32);
            c < d
        });
        modified && changed
    }
    #[cfg(not(unix))]
    {
        modified
    }
}

/// The relative paths of every file under `dir` (directories themselves not listed), sorted.
fn list_files(dir: &Path, rel: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in fs::read_dir(dir.join(rel))? {
        let entry = entry?;
        let r = rel.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            list_files(dir, &r, out)?;
        } else {
            out.push(r);
        }
    }
    Ok(())
}

/// The marker of a staged directory: the header, then every file `fill` wrote.
fn write_marker(staging: &Path) -> std::io::Result<()> {
    let mut files = Vec::new();
    list_files(staging, Path::new(""), &mut files)?;
    files.sort();
    let mut text = format!("{MARKER_HEADER}\nfiles:\n");
    for f in files {
        // A name that is not UTF-8 (or holds a newline) cannot be listed; texel writes none.
        if let Some(s) = f.to_str().filter(|s| !s.contains('\n')) {
            text.push_str(s);
            text.push('\n');
        }
    }
    fs::write(staging.join(OUTPUT_MARKER), text)
}

/// Entries of `old` (a directory texel is about to replace) that texel did not write and whose
/// name is taken in `new`: carrying them over would replace the new output's file.
fn clashes(old: &Path, new: &Path, owned: &Owned, rel: &Path, out: &mut Vec<PathBuf>) {
    clashes_or_foreign(old, Some(new), owned, rel, out);
}

/// With `new`, [`clashes`]; without, every entry of `old` that texel did not write.
fn clashes_or_foreign(
    old: &Path,
    new: Option<&Path>,
    owned: &Owned,
    rel: &Path,
    out: &mut Vec<PathBuf>,
) {
    let Ok(entries) = fs::read_dir(old.join(rel)) else {
        return;
    };
    for entry in entries.flatten() {
        let r = rel.join(entry.file_name());
        let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
        if is_dir && owned.may_hold(&r) {
            clashes_or_foreign(old, new, owned, &r, out);
        } else if (is_dir || !owned.file(&r, &entry.path()))
            && new.is_none_or(|n| fs::symlink_metadata(n.join(&r)).is_ok())
        {
            out.push(r);
        }
    }
}

/// Move what texel did not write from `old` into `new` (same relative paths) and delete the files
/// texel wrote; entries whose name `new` already holds stay in `old`.
fn carry_over(old: &Path, new: &Path, owned: &Owned, rel: &Path) {
    let Ok(entries) = fs::read_dir(old.join(rel)) else {
        return;
    };
    for entry in entries.flatten() {
        let r = rel.join(entry.file_name());
        let from = entry.path();
        let is_dir = entry.file_type().is_ok_and(|t| t.is_dir());
        let to = new.join(&r);
        if is_dir && owned.may_hold(&r) {
            if fs::symlink_metadata(&to).is_err() {
                let _ = fs::create_dir(&to);
            }
            carry_over(old, new, owned, &r);
            let _ = fs::remove_dir(&from);
        } else if !is_dir && owned.file(&r, &from) {
            let _ = fs::remove_file(&from);
        } else if fs::symlink_metadata(&to).is_err() {
            if is_dir {
                let _ = fs::rename(&from, &to);
            } else if fs::hard_link(&from, &to).is_ok() {
                // A link fails where the name is taken meanwhile: nothing is replaced.
                let _ = fs::remove_file(&from);
            } else if !entry.file_type().is_ok_and(|t| t.is_file()) {
                // A symbolic link, FIFO or socket: moved as it is.
                let _ = fs::rename(&from, &to);
            }
        }
    }
}

/// A name beside `target` that nothing holds: `NAME.texel-WHAT`, or `NAME.texel-WHAT-2`, ...
fn visible_sibling(target: &Path, what: &str) -> PathBuf {
    let name = target
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    let dir = target.parent().unwrap_or(Path::new("."));
    (1..)
        .map(|k| match k {
            1 => dir.join(format!("{name}.texel-{what}")),
            k => dir.join(format!("{name}.texel-{what}-{k}")),
        })
        .find(|p| fs::symlink_metadata(p).is_err())
        .unwrap_or_else(|| dir.join(format!("{name}.texel-{what}")))
}

/// Publish a multi-file output at `dest` as a whole: `fill` writes everything into a new staging
/// directory beside `dest` (it receives its path), then the staging directory replaces `dest`.
///
/// `dest` may be missing (its parents are created), an empty directory, or a directory an earlier
/// run published (it holds [`OUTPUT_MARKER`], which lists the files that run wrote). A symbolic
/// link is followed and kept. What texel did not write is never lost: at the moment of publishing
/// the old directory is moved aside, the new one renamed into place, and every entry of the old
/// one that texel did not write (a file a user saved into `dest` during the run, say) is moved
/// into the new one; only the files the marker lists are deleted. A process killed between the
/// two renames leaves no `dest` at all, never a mixture, and its hidden leftovers are deleted by
/// the next publish to `dest`.
///
/// `inputs` are the files the command reads: an input inside `dest` is refused before any work,
/// since publishing could replace or move it.
///
/// # Errors
/// [`OutputError`] (converted into `E`) when `dest` is a file or device, a directory that
/// texel did not write, an open descriptor's link, holds one of `inputs`, or cannot be created or
/// renamed; when, at the moment of publishing, `dest` holds a file texel did not write under a
/// name the new output uses (the new output is then left beside `dest` as `NAME.texel-new`, and
/// `dest` is unchanged); any error of `fill`, after which the staging directory is deleted and
/// `dest` is unchanged.
pub fn publish_dir<T, E: From<OutputError>>(
    dest: &Path,
    inputs: &[&Path],
    fill: impl FnOnce(&Path) -> Result<T, E>,
) -> Result<T, E> {
    if descriptor_on_path(dest)?.is_some() {
        return Err(refuse(
            dest,
            std::io::ErrorKind::InvalidInput,
            "names an open file descriptor: give the output directory's own path",
        )
        .into());
    }
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
    let marked = exists && target.join(OUTPUT_MARKER).is_file();
    if exists {
        check_inputs_outside(dest, &target, inputs)?;
    }
    let (parent, tag) = split_dest(&target)?;
    fs::create_dir_all(&parent).map_err(io_err(dest))?;
    remove_stale(&parent, &tag, Some(&target));
    let staging = temporary(&parent, &tag, "");
    {
        let mut guard = pending();
        fs::create_dir(&staging).map_err(io_err(dest))?;
        guard.push(staging.clone());
    }
    let filled = fill(&staging).and_then(|v| {
        write_marker(&staging)
            .map_err(|e| E::from(io_err(dest)(e)))
            .map(|()| v)
    });
    let mut guard = pending();
    let result = filled.and_then(|v| {
        swap_in(dest, &target, &staging, marked, (&parent, &tag))
            .map(|()| v)
            .map_err(E::from)
    });
    if result.is_err() && fs::symlink_metadata(&staging).is_ok() {
        let _ = fs::remove_dir_all(&staging);
    }
    unregister(&mut guard, &staging);
    result
}

/// Refuse when one of `inputs` lies inside the existing directory `target`.
fn check_inputs_outside(dest: &Path, target: &Path, inputs: &[&Path]) -> Result<(), OutputError> {
    let Ok(dir) = fs::canonicalize(target) else {
        return Ok(());
    };
    for input in inputs {
        if let Ok(p) = fs::canonicalize(input) {
            if p.starts_with(&dir) {
                return Err(refuse(
                    dest,
                    std::io::ErrorKind::InvalidInput,
                    &format!(
                        "holds the input {}, which publishing the output there could replace \
                         or move: choose another output directory",
                        input.display()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Put the filled `staging` in `target`'s place, keeping whatever texel did not write. `marked`:
/// `target` held a marker when the run started (else it was empty or missing); `(parent, tag)`
/// name its temporaries.
fn swap_in(
    dest: &Path,
    target: &Path,
    staging: &Path,
    marked: bool,
    (parent, tag): (&Path, &str),
) -> Result<(), OutputError> {
    let exists = fs::symlink_metadata(target).is_ok();
    if !exists {
        return fs::rename(staging, target).map_err(io_err(dest));
    }
    // What the directory holds now, not what it held when the run started.
    let owned = Owned::of(target);
    let mut clash = Vec::new();
    if marked && !target.join(OUTPUT_MARKER).is_file() {
        clash.push(PathBuf::from(
            "(the whole directory: its .texel-output marker is gone)",
        ));
    } else {
        clashes(target, staging, &owned, Path::new(""), &mut clash);
    }
    if !clash.is_empty() {
        let kept = visible_sibling(target, "new");
        let at = match fs::rename(staging, &kept) {
            Ok(()) => format!("the new output is in {}", kept.display()),
            Err(_) => "the new output is discarded".to_string(),
        };
        let names: Vec<String> = clash.iter().map(|p| p.display().to_string()).collect();
        return Err(refuse(
            dest,
            std::io::ErrorKind::AlreadyExists,
            &format!(
                "now holds files texel did not write under names the new output uses ({}): it is \
                 left as it is, and {at}",
                names.join(", ")
            ),
        ));
    }
    let old = temporary(parent, tag, ".old");
    fs::rename(target, &old).map_err(io_err(dest))?;
    if let Err(e) = fs::rename(staging, target) {
        let _ = fs::rename(&old, target);
        return Err(io_err(dest)(e));
    }
    // Files saved into the old directory up to this moment move across; a few passes catch one
    // that lands while the first is running.
    for _ in 0..3 {
        carry_over(&old, target, &owned, Path::new(""));
        if fs::remove_dir(&old).is_ok() {
            return Ok(());
        }
    }
    let kept = visible_sibling(target, "kept");
    let _ = fs::rename(&old, &kept);
    eprintln!(
        "texel: warning: files saved into {} while texel published it clash with the new \
         output's names; they are kept in {}",
        dest.display(),
        kept.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("texel-io-{tag}-{}", std::process::id()));
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
        assert!(matches!(&e, OutputError { source, .. } if source.raw_os_error() == Some(28)));
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
        publish_dir::<_, OutputError>(&out, &[], |s| {
            fs::write(s.join("a.png"), b"1").map_err(io_err(s))
        })
        .unwrap();
        assert_eq!(names(&out), vec![OUTPUT_MARKER, "a.png"]);
        // A second run replaces everything: no file of the first run survives.
        publish_dir::<_, OutputError>(&out, &[], |s| {
            fs::write(s.join("b.png"), b"2").map_err(io_err(s))
        })
        .unwrap();
        assert_eq!(names(&out), vec![OUTPUT_MARKER, "b.png"]);
        // A failing run leaves the last published output and no staging directory.
        let e = publish_dir::<(), OutputError>(&out, &[], |s| {
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
        let e = publish_dir::<(), OutputError>(&mine, &[], |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("did not write"), "{e}");
        assert_eq!(names(&mine), vec!["notes.txt"]);
        fs::write(d.join("file"), b"f").unwrap();
        let e = publish_dir::<(), OutputError>(&d.join("file"), &[], |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("not a directory"), "{e}");
        fs::remove_dir_all(&d).unwrap();
    }

    fn fill_with<'a>(
        files: &'a [&'a str],
        also: impl FnOnce() + 'a,
    ) -> impl FnOnce(&Path) -> Result<(), OutputError> + 'a {
        move |s| {
            for f in files {
                fs::write(s.join(f), f.as_bytes()).map_err(io_err(s))?;
            }
            also();
            Ok(())
        }
    }

    #[test]
    fn publish_keeps_files_saved_during_the_run() {
        let d = scratch("atomic-keep");
        let out = d.join("out");
        publish_dir(&out, &[], fill_with(&["a.png", "b.png"], || ())).unwrap();
        // A user saves a file into the published directory while the next run works, and one
        // into a sub-directory of their own.
        let saved = out.join("notes.txt");
        publish_dir(
            &out,
            &[],
            fill_with(&["a.png"], || {
                fs::write(&saved, b"mine").unwrap();
                fs::create_dir(out.join("sub")).unwrap();
                fs::write(out.join("sub/x"), b"x").unwrap();
            }),
        )
        .unwrap();
        assert_eq!(
            names(&out),
            vec![OUTPUT_MARKER, "a.png", "notes.txt", "sub"]
        );
        assert_eq!(fs::read(&saved).unwrap(), b"mine");
        assert_eq!(fs::read(out.join("sub/x")).unwrap(), b"x");
        // The marker lists texel's files only: the next run deletes b.png's successor a.png but
        // keeps the user's files again.
        let marker = fs::read_to_string(out.join(OUTPUT_MARKER)).unwrap();
        assert!(marker.ends_with("files:\na.png\n"), "{marker:?}");
        publish_dir(&out, &[], fill_with(&["c.png"], || ())).unwrap();
        assert_eq!(
            names(&out),
            vec![OUTPUT_MARKER, "c.png", "notes.txt", "sub"]
        );
        assert_eq!(names(&d), vec!["out"]);
        // An empty directory at the start: whatever appears in it during the run is kept.
        let empty = d.join("empty");
        fs::create_dir(&empty).unwrap();
        publish_dir(
            &empty,
            &[],
            fill_with(&["a.png"], || {
                fs::write(empty.join("late.txt"), b"l").unwrap()
            }),
        )
        .unwrap();
        assert_eq!(names(&empty), vec![OUTPUT_MARKER, "a.png", "late.txt"]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn publish_refuses_a_clash_and_leaves_the_output_beside() {
        let d = scratch("atomic-clash");
        let out = d.join("out");
        publish_dir(&out, &[], fill_with(&["a.png"], || ())).unwrap();
        // During the run a user saves their own file under a name the new output uses.
        let e = publish_dir(
            &out,
            &[],
            fill_with(&["a.png", "index.html"], || {
                fs::write(out.join("index.html"), b"mine").unwrap()
            }),
        )
        .unwrap_err();
        assert!(e.to_string().contains("index.html"), "{e}");
        assert!(e.to_string().contains("out.texel-new"), "{e}");
        assert_eq!(fs::read(out.join("index.html")).unwrap(), b"mine");
        assert_eq!(fs::read(out.join("a.png")).unwrap(), b"a.png");
        assert_eq!(
            names(&d.join("out.texel-new")),
            vec![OUTPUT_MARKER, "a.png", "index.html"]
        );
        // A marker removed during the run: the directory is no longer texel's to replace.
        let other = d.join("other");
        publish_dir(&other, &[], fill_with(&["a.png"], || ())).unwrap();
        let e = publish_dir(
            &other,
            &[],
            fill_with(&["b.png"], || {
                fs::remove_file(other.join(OUTPUT_MARKER)).unwrap()
            }),
        )
        .unwrap_err();
        assert!(e.to_string().contains("marker is gone"), "{e}");
        assert_eq!(names(&other), vec!["a.png"]);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn publish_never_touches_its_input() {
        let d = scratch("atomic-input");
        let out = d.join("out");
        publish_dir(&out, &[], fill_with(&["level-00.png"], || ())).unwrap();
        let input = out.join("brick.png");
        fs::write(&input, b"brick").unwrap();
        let e = publish_dir(&out, &[&input], fill_with(&["level-00.png"], || ())).unwrap_err();
        assert!(e.to_string().contains("holds the input"), "{e}");
        assert_eq!(fs::read(&input).unwrap(), b"brick");
        // Texel's own earlier output read as the input is refused the same way.
        let own = out.join("level-00.png");
        assert!(publish_dir(&out, &[&own], fill_with(&["level-00.png"], || ())).is_err());
        assert_eq!(fs::read(&own).unwrap(), b"level-00.png");
        // An input elsewhere is fine.
        let outside = d.join("t.png");
        fs::write(&outside, b"t").unwrap();
        publish_dir(&out, &[&outside], fill_with(&["level-00.png"], || ())).unwrap();
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn publish_reads_a_marker_without_a_list() {
        let d = scratch("atomic-legacy");
        let out = d.join("out");
        fs::create_dir(&out).unwrap();
        fs::write(out.join("old.png"), b"o").unwrap();
        // Files older than such a marker are texel's; a later one is the user's (the pauses are
        // longer than the kernel's coarse clock tick).
        std::thread::sleep(std::time::Duration::from_millis(50));
        fs::write(out.join(OUTPUT_MARKER), format!("{MARKER_HEADER}\n")).unwrap();
        std::thread::sleep(std::time::Duration::from_millis(50));
        // A file moved in keeps its old modification time, but not its change time.
        let moved = d.join("photo.jpg");
        fs::write(&moved, b"p").unwrap();
        let f = fs::File::options().write(true).open(&moved).unwrap();
        f.set_modified(SystemTime::UNIX_EPOCH + std::time::Duration::from_secs(1))
            .unwrap();
        drop(f);
        fs::rename(&moved, out.join("photo.jpg")).unwrap();
        publish_dir(
            &out,
            &[],
            fill_with(&["new.png"], || {
                fs::write(out.join("later.txt"), b"l").unwrap()
            }),
        )
        .unwrap();
        assert_eq!(
            names(&out),
            vec![OUTPUT_MARKER, "later.txt", "new.png", "photo.jpg"]
        );
        fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn descriptor_links_are_written_through() {
        use std::io::{Read, Seek};
        use std::os::fd::AsRawFd;
        let d = scratch("atomic-fd");
        // A descriptor opened for appending (a shell's `>>`): texel's bytes follow the old ones.
        let log = d.join("log.txt");
        fs::write(&log, b"earlier\n").unwrap();
        let f = OpenOptions::new().append(true).open(&log).unwrap();
        let link = PathBuf::from(format!("/proc/self/fd/{}", f.as_raw_fd()));
        write_atomic(&link, b"png").unwrap();
        let via_dev_fd = PathBuf::from(format!("/dev/fd/{}", f.as_raw_fd()));
        write_atomic(&via_dev_fd, b"!").unwrap();
        assert_eq!(fs::read(&log).unwrap(), b"earlier\npng!");
        // A symbolic link to such a link is the same descriptor.
        std::os::unix::fs::symlink(&link, d.join("alias")).unwrap();
        write_atomic(&d.join("alias"), b"?").unwrap();
        assert_eq!(fs::read(&log).unwrap(), b"earlier\npng!?");
        drop(f);
        // A regular file's descriptor that does not append: its offset could not be moved past
        // texel's bytes, so it is refused and the file is unchanged; so is a read-only one.
        let g_path = d.join("g.bin");
        fs::write(&g_path, b"0123456789").unwrap();
        let mut g = OpenOptions::new()
            .read(true)
            .write(true)
            .open(&g_path)
            .unwrap();
        g.seek(std::io::SeekFrom::Start(4)).unwrap();
        let g_link = PathBuf::from(format!("/proc/self/fd/{}", g.as_raw_fd()));
        let e = write_atomic(&g_link, b"ab").unwrap_err();
        assert!(e.to_string().contains("not open for appending"), "{e}");
        let r = fs::File::open(&g_path).unwrap();
        let e =
            write_atomic(&PathBuf::from(format!("/dev/fd/{}", r.as_raw_fd())), b"ab").unwrap_err();
        assert!(e.to_string().contains("reading only"), "{e}");
        assert_eq!(fs::read(&g_path).unwrap(), b"0123456789");
        drop((g, r));
        // A deleted file behind an appending descriptor: written to the open file, and no new
        // file appears.
        let h_path = d.join("h.bin");
        fs::write(&h_path, b"01").unwrap();
        let mut h = OpenOptions::new()
            .read(true)
            .append(true)
            .open(&h_path)
            .unwrap();
        fs::remove_file(&h_path).unwrap();
        write_atomic(
            &PathBuf::from(format!("/proc/self/fd/{}", h.as_raw_fd())),
            b"Z",
        )
        .unwrap();
        let mut all = Vec::new();
        h.seek(std::io::SeekFrom::Start(0)).unwrap();
        h.read_to_end(&mut all).unwrap();
        assert_eq!(all, b"01Z");
        assert_eq!(names(&d), vec!["alias", "g.bin", "log.txt"]);
        // A descriptor link is never an output directory.
        let e = publish_dir::<(), OutputError>(&link, &[], |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("descriptor"), "{e}");
        drop(h);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_killed_publish_never_costs_the_user_files() {
        let d = scratch("atomic-killed");
        let out = d.join("out");
        publish_dir(&out, &[], fill_with(&["a.png"], || ())).unwrap();
        // What a publish killed between its two renames leaves: the old directory moved aside,
        // holding texel's listed file and one the user saved; and one holding texel's files only.
        let tag = name_tag(std::ffi::OsStr::new("out"));
        let with_user = d.join(format!("{tag}4294967294.0.old.tmp"));
        let only_texel = d.join(format!("{tag}4294967294.1.old.tmp"));
        for dir in [&with_user, &only_texel] {
            fs::create_dir(dir).unwrap();
            fs::write(dir.join("a.png"), b"a").unwrap();
            fs::write(
                dir.join(OUTPUT_MARKER),
                format!("{MARKER_HEADER}\nfiles:\na.png\n"),
            )
            .unwrap();
        }
        fs::write(with_user.join("notes.txt"), b"mine").unwrap();
        publish_dir(&out, &[], fill_with(&["b.png"], || ())).unwrap();
        if Path::new("/proc/self").exists() {
            assert!(!with_user.exists() && !only_texel.exists());
            assert_eq!(
                fs::read(d.join("out.texel-kept/notes.txt")).unwrap(),
                b"mine"
            );
            assert_eq!(names(&d), vec!["out", "out.texel-kept"]);
        }
        fs::remove_dir_all(&d).unwrap();
    }
}
