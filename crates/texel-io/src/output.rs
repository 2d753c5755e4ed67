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
//! [`remove_pending_and_exit`] (the CLI calls it on SIGINT/SIGTERM/SIGHUP) deletes them. Each is
//! locked (`flock`) by its owner while it is in use, so a temporary left by a killed process
//! (SIGKILL) is deleted by the next write to the same path once nobody holds its lock: a texel in
//! another PID namespace or on another host sharing the directory keeps its lock and its files.
//!
//! Links are followed by hand under the rule the kernel's `fs.protected_symlinks` enforces: in a
//! sticky, world-writable directory (`/tmp`) a link is followed only when it belongs to the
//! directory's owner or to the user texel runs as. [`same_output`] tells whether two output paths
//! can reach one file or stream, and [`check_output`] checks a destination before any work.
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
use std::time::Duration;

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
    let append = descriptor_append(d, path)?;
    let mut file = OpenOptions::new()
        .write(true)
        .append(append)
        .open(&d.link)
        .map_err(io_err(path))?;
    file.write_all(bytes)
        .and_then(|()| file.flush())
        .map_err(io_err(path))
}

/// Whether texel may write through descriptor `d` (not this process's standard output or error),
/// and whether it appends: a directory, a descriptor open for reading only, or a regular file's
/// that does not append is refused.
fn descriptor_append(d: &FdLink, path: &Path) -> Result<bool, OutputError> {
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
    Ok(append)
}

/// Apply [`check_link`] to every directory of `path` that is a symbolic link (`d/link/x.png`):
/// the kernel applies its rule inside a path only where `fs.protected_symlinks` is on.
fn check_ancestors(path: &Path, original: &Path) -> Result<(), OutputError> {
    for dir in path.ancestors().skip(1) {
        if dir.as_os_str().is_empty() {
            break;
        }
        if let Ok(meta) = fs::symlink_metadata(dir) {
            if meta.file_type().is_symlink() {
                check_link(dir, &meta, original)?;
            }
        }
    }
    Ok(())
}

/// Follow `path` through symbolic links (without following the last component of a missing one)
/// and classify what it names.
fn resolve(path: &Path) -> Result<Destination, OutputError> {
    check_ancestors(path, path)?;
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
            check_link(&p, &meta, path)?;
            let target = fs::read_link(&p).map_err(io_err(path))?;
            p = match p.parent() {
                Some(dir) if target.is_relative() => dir.join(target),
                _ => target,
            };
            check_ancestors(&p, path)?;
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
                check_link(&p, &m, path)?;
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

/// The rule the kernel's `fs.protected_symlinks` enforces when it follows a link, applied to each
/// link texel follows by hand (the kernel checks the links inside a path itself): a link in a
/// sticky, world-writable directory (such as `/tmp`) is followed only when it belongs to the
/// directory's owner or to the user texel runs as. Another user's link planted there could
/// otherwise make texel replace a file that user may not write. `link`'s metadata is `meta`;
/// errors name `original`, the path the caller was given.
#[cfg(unix)]
fn check_link(link: &Path, meta: &fs::Metadata, original: &Path) -> Result<(), OutputError> {
    use std::os::unix::fs::MetadataExt;
    let dir = match link.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let Ok(dir_meta) = fs::metadata(dir) else {
        return Ok(());
    };
    let sticky_and_open = dir_meta.mode() & 0o1002 == 0o1002;
    let me = rustix::process::geteuid().as_raw();
    if sticky_and_open && meta.uid() != dir_meta.uid() && meta.uid() != me {
        return Err(refuse(
            original,
            std::io::ErrorKind::PermissionDenied,
            &format!(
                "leads through the symbolic link {}, which lies in a sticky, world-writable \
                 directory and belongs to neither you nor the directory's owner: texel does not \
                 follow it (the kernel's protected_symlinks rule)",
                link.display()
            ),
        ));
    }
    Ok(())
}

#[cfg(not(unix))]
fn check_link(_link: &Path, _meta: &fs::Metadata, _original: &Path) -> Result<(), OutputError> {
    Ok(())
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

/// How long a temporary whose lock is free is still kept while a process of its PID runs here
/// (the PID may have been reused, or the owner may be between creating and locking it).
const REUSED_PID_AGE: Duration = Duration::from_secs(3600);

/// How long a temporary is kept where its lock cannot be tried (a file system without locks).
const UNLOCKABLE_AGE: Duration = Duration::from_secs(24 * 3600);

/// Whether the temporary `p` (a file or directory whose name carries `pid`, with metadata
/// `meta`) is abandoned. Its owner holds an exclusive lock on it ([`hold`]) for as long as it
/// works on it, so a lock another process can take means the owner is gone, whatever PID
/// namespace or host it ran in; a PID alone decides nothing. Where the PID still runs here, the
/// temporary is kept for [`REUSED_PID_AGE`] all the same, and where no lock can be tried, for
/// [`UNLOCKABLE_AGE`].
fn abandoned(p: &Path, pid: u32, meta: &fs::Metadata) -> bool {
    let age = meta
        .modified()
        .ok()
        .and_then(|t| t.elapsed().ok())
        .unwrap_or_default();
    match lock_state(p, meta) {
        LockState::Held => false,
        LockState::Free => {
            let runs_here = Path::new("/proc/self").exists()
                && Path::new("/proc").join(pid.to_string()).exists();
            !runs_here || age > REUSED_PID_AGE
        }
        LockState::Unknown => age > UNLOCKABLE_AGE,
    }
}

/// Whether another open file holds a lock on a temporary.
enum LockState {
    /// Its owner holds it.
    Held,
    /// Nobody does.
    Free,
    /// It cannot be opened or locked here.
    Unknown,
}

/// Try the lock of temporary `p` (a regular file or directory, never followed if it is a link).
fn lock_state(p: &Path, meta: &fs::Metadata) -> LockState {
    if !meta.is_file() && !meta.is_dir() {
        return LockState::Unknown;
    }
    let Some(file) = open_no_follow(p) else {
        return LockState::Unknown;
    };
    match file.try_lock() {
        Ok(()) => LockState::Free,
        Err(fs::TryLockError::WouldBlock) => LockState::Held,
        Err(fs::TryLockError::Error(_)) => LockState::Unknown,
    }
}

/// Open `p` for reading without following a link or blocking on a FIFO.
#[cfg(unix)]
fn open_no_follow(p: &Path) -> Option<fs::File> {
    use rustix::fs::{Mode, OFlags};
    let flags = OFlags::RDONLY | OFlags::NOFOLLOW | OFlags::NONBLOCK | OFlags::CLOEXEC;
    rustix::fs::open(p, flags, Mode::empty())
        .ok()
        .map(fs::File::from)
}

#[cfg(not(unix))]
fn open_no_follow(p: &Path) -> Option<fs::File> {
    fs::File::open(p).ok()
}

/// Hold the lock that marks the temporary `p` as in use ([`abandoned`]) while the returned file is
/// open. Where locks are not supported the temporary is simply not marked.
fn hold(p: &Path) -> Option<fs::File> {
    let file = fs::File::open(p).ok()?;
    file.try_lock().ok()?;
    Some(file)
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
            crate::term::stderr_line(format_args!(
                "texel: warning: an interrupted earlier publish of {} left files texel did not \
                 write; they are kept in {}",
                target.display(),
                kept.display()
            ));
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
        let p = entry.path();
        let Ok(meta) = fs::symlink_metadata(&p) else {
            continue;
        };
        if abandoned(&p, pid, &meta) {
            if meta.is_dir() {
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
        // Marks the temporary as in use until it is renamed (see `abandoned`); a file system
        // without locks leaves it unmarked.
        let _ = file.try_lock();
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
    let mut guard = pending();
    let result = written.and_then(|()| fs::rename(&tmp, &target).map_err(io_err(path)));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    unregister(&mut guard, &tmp);
    // The lock lasts until the temporary is renamed or removed.
    drop(file);
    result
}

/// Check, before any work, that [`write_atomic`] (or a write to standard output for `-`) could
/// publish at `path`: a new or regular file's directory exists and takes a new file (a temporary
/// is created there and removed), a descriptor is open for writing as [`write_atomic`] needs; a
/// device or FIFO is not opened (a FIFO would wait for its reader). Nothing is written or
/// replaced.
///
/// # Errors
/// What [`write_atomic`] would report for the path: a directory, a socket, a missing or
/// read-only directory, a descriptor open for reading, a link it does not follow.
pub fn check_output(path: &Path) -> Result<(), OutputError> {
    if path.as_os_str() == "-" {
        return Ok(());
    }
    let target = match resolve(path)? {
        Destination::Descriptor(d) if d.own && (d.fd == 1 || d.fd == 2) => return Ok(()),
        Destination::Descriptor(d) => return descriptor_append(&d, path).map(|_| ()),
        Destination::Special(_) => return Ok(()),
        Destination::Replaceable(p) => p,
    };
    let (dir, tag) = split_dest(&target)?;
    let probe = temporary(&dir, &tag, "");
    let mut guard = pending();
    let made = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(io_err(path));
    if made.is_ok() {
        guard.push(probe.clone());
        let _ = fs::remove_file(&probe);
        unregister(&mut guard, &probe);
    }
    made.map(|_| ())
}

/// What an output path finally names, to tell two outputs apart: the stream (standard output
/// for `-` and its links), the file's device and inode, and the path it resolves to.
#[derive(Debug, Default)]
struct Identity {
    /// This process's descriptor the path reaches (1 for `-`).
    stream: Option<u32>,
    /// The device and inode of what it names, where that exists.
    node: Option<(u64, u64)>,
    /// The file it resolves to (a missing file through its directory).
    path: Option<PathBuf>,
}

#[cfg(unix)]
fn node_of(p: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    let m = fs::metadata(p).ok()?;
    // The null device swallows anything: two outputs there do not mix.
    let null = fs::metadata("/dev/null").ok();
    if m.file_type().is_char_device() && null.is_some_and(|n| n.rdev() == m.rdev()) {
        return None;
    }
    Some((m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn node_of(_p: &Path) -> Option<(u64, u64)> {
    None
}

fn identity(path: &Path) -> Identity {
    if path.as_os_str() == "-" {
        return Identity {
            stream: Some(1),
            node: node_of(Path::new("/proc/self/fd/1")),
            path: None,
        };
    }
    match resolve(path) {
        Ok(Destination::Descriptor(d)) => Identity {
            stream: d.own.then_some(d.fd),
            node: node_of(&d.link),
            path: None,
        },
        Ok(Destination::Special(p)) => Identity {
            node: node_of(&p),
            ..Identity::default()
        },
        Ok(Destination::Replaceable(p)) => {
            let (dir, name) = (
                p.parent().filter(|d| !d.as_os_str().is_empty()),
                p.file_name(),
            );
            let resolved = fs::canonicalize(dir.unwrap_or(Path::new(".")))
                .ok()
                .zip(name)
                .map(|(d, n)| d.join(n));
            Identity {
                stream: None,
                node: node_of(&p),
                path: resolved.or_else(|| std::path::absolute(&p).ok()),
            }
        }
        Err(_) => Identity {
            path: std::path::absolute(path).ok(),
            ..Identity::default()
        },
    }
}

/// Whether two output paths can name one file or one stream, whatever their spelling: `-`,
/// `/dev/stdout`, `/dev/fd/1` and `/proc/self/fd/1` are all standard output (and the file or pipe
/// behind it); links, dangling ones included, are followed to the file they would write; an
/// existing file is known by its device and inode. The null device is never one output.
pub fn same_output(a: &Path, b: &Path) -> bool {
    let (x, y) = (identity(a), identity(b));
    fn both<T: PartialEq>(p: Option<T>, q: Option<T>) -> bool {
        p.is_some() && p == q
    }
    both(x.stream, y.stream) || both(x.node, y.node) || both(x.path, y.path)
}

/// Whether an existing directory may be published over by [`publish_dir`]: it is empty, or it
/// holds texel's [`OUTPUT_MARKER`] (every directory `publish_dir` publishes does). Anything else,
/// a directory with an empty or foreign `.texel-output` included, may hold a user's own files
/// and is refused.
fn replaceable_dir(dir: &Path) -> bool {
    match fs::read_dir(dir) {
        Ok(mut entries) => entries.next().is_none() || texel_marker(dir).is_some(),
        Err(_) => false,
    }
}

/// The first line of [`OUTPUT_MARKER`]; the files texel wrote follow the line `files:`.
const MARKER_HEADER: &str = "written by texel; may be replaced by texel";

/// The text of `dir`'s marker, if it is texel's: a regular file (not a link) that starts with
/// [`MARKER_HEADER`].
fn texel_marker(dir: &Path) -> Option<String> {
    let marker = dir.join(OUTPUT_MARKER);
    if !fs::symlink_metadata(&marker).is_ok_and(|m| m.is_file()) {
        return None;
    }
    let text = fs::read_to_string(&marker).ok()?;
    (text.lines().next() == Some(MARKER_HEADER)).then_some(text)
}

/// Which entries of a published directory texel wrote: the files its marker lists (relative
/// paths). A directory without texel's marker, or a marker that lists nothing, owns nothing:
/// only listed files are ever replaced or removed.
struct Owned(HashSet<PathBuf>);

impl Owned {
    /// Read the marker of `dir`.
    fn of(dir: &Path) -> Owned {
        let Some(text) = texel_marker(dir) else {
            return Owned(HashSet::new());
        };
        let mut lines = text.lines();
        if lines.any(|l| l == "files:") {
            return Owned(lines.map(PathBuf::from).collect());
        }
        Owned(HashSet::new())
    }

    /// Whether texel wrote the file at `rel`.
    fn file(&self, rel: &Path) -> bool {
        rel == Path::new(OUTPUT_MARKER) || self.0.contains(rel)
    }

    /// Whether the directory at `rel` may hold files texel wrote.
    fn may_hold(&self, rel: &Path) -> bool {
        self.0.iter().any(|p| p.starts_with(rel))
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
        } else if (is_dir || !owned.file(&r))
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
        } else if !is_dir && owned.file(&r) {
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
    check_ancestors(dest, dest)?;
    let mut target = dest.to_path_buf();
    let mut links = 0;
    let exists =
        loop {
            match fs::symlink_metadata(&target) {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => break false,
                Err(e) => return Err(io_err(dest)(e).into()),
                Ok(m) if m.file_type().is_symlink() && links < MAX_LINKS => {
                    links += 1;
                    check_link(&target, &m, dest)?;
                    let t = fs::read_link(&target).map_err(io_err(dest))?;
                    target = match target.parent() {
                        Some(dir) if t.is_relative() => dir.join(t),
                        _ => t,
                    };
                    check_ancestors(&target, dest)?;
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
            "is a directory texel did not write (it is not empty and holds no .texel-output \
             marker written by texel): choose a new or empty directory, or remove it",
        )
        .into());
    }
    if exists {
        check_replaceable_dir(dest, &target)?;
    }
    let marked = exists && texel_marker(&target).is_some();
    if exists {
        if let Some(input) = inputs_inside(&target, inputs).first() {
            return Err(refuse(
                dest,
                std::io::ErrorKind::InvalidInput,
                &format!(
                    "holds the input {}, which publishing the output there could replace or \
                     move: choose another output directory",
                    input.display()
                ),
            )
            .into());
        }
    }
    let (parent, tag) = split_dest(&target)?;
    fs::create_dir_all(&parent).map_err(io_err(dest))?;
    remove_stale(&parent, &tag, Some(&target));
    let staging = temporary(&parent, &tag, "");
    let lock = {
        let mut guard = pending();
        fs::create_dir(&staging).map_err(io_err(dest))?;
        guard.push(staging.clone());
        hold(&staging)
    };
    let filled = fill(&staging).and_then(|v| {
        write_marker(&staging)
            .map_err(|e| E::from(io_err(dest)(e)))
            .map(|()| v)
    });
    if filled.is_ok() {
        keep_mode_and_owner(&target, &staging);
    }
    let mut guard = pending();
    let result = filled.and_then(|v| {
        swap_in(dest, &target, &staging, marked, inputs, (&parent, &tag))
            .map(|()| v)
            .map_err(E::from)
    });
    if result.is_err() && fs::symlink_metadata(&staging).is_ok() {
        let _ = fs::remove_dir_all(&staging);
    }
    unregister(&mut guard, &staging);
    drop(lock);
    result
}

/// Refuse, before any work, an existing directory `target` that publishing could not rename
/// (a mount point: `rename` fails with EBUSY) or should not (in a sticky, world-writable
/// directory, one that belongs to neither the user texel runs as nor that directory's owner:
/// another user's planted directory would get texel's output, and its owner).
fn check_replaceable_dir(dest: &Path, target: &Path) -> Result<(), OutputError> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let parent = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let (Ok(meta), Ok(up)) = (fs::metadata(target), fs::metadata(parent)) else {
            return Ok(());
        };
        if meta.dev() != up.dev() || is_mount_root(target) {
            return Err(refuse(
                dest,
                std::io::ErrorKind::InvalidInput,
                "is a mount point, which texel cannot replace (it publishes a directory by \
                 renaming it into place): give a directory inside it, such as OUT/report",
            ));
        }
        let me = rustix::process::geteuid().as_raw();
        if up.mode() & 0o1002 == 0o1002 && meta.uid() != me && meta.uid() != up.uid() {
            return Err(refuse(
                dest,
                std::io::ErrorKind::PermissionDenied,
                "lies in a sticky, world-writable directory and belongs to neither you nor that \
                 directory's owner: texel does not publish into another user's directory there",
            ));
        }
    }
    #[cfg(not(unix))]
    let _ = (dest, target);
    Ok(())
}

/// Whether `dir` is the root of a mount, a bind mount of the same file system included (statx's
/// `STATX_ATTR_MOUNT_ROOT`; `false` where the kernel does not say).
#[cfg(target_os = "linux")]
fn is_mount_root(dir: &Path) -> bool {
    use rustix::fs::{AtFlags, StatxAttributes, StatxFlags, CWD};
    rustix::fs::statx(CWD, dir, AtFlags::NO_AUTOMOUNT, StatxFlags::empty()).is_ok_and(|r| {
        r.stx_attributes_mask.contains(StatxAttributes::MOUNT_ROOT)
            && r.stx_attributes.contains(StatxAttributes::MOUNT_ROOT)
    })
}

#[cfg(all(unix, not(target_os = "linux")))]
fn is_mount_root(_dir: &Path) -> bool {
    false
}

/// The inputs inside the existing directory `target`: those of `inputs` and every file this
/// process has opened as an input ([`crate::input::files_opened`]: a scene's textures, meshes and
/// environment maps, `--extra` images), as the caller named them.
fn inputs_inside(target: &Path, inputs: &[&Path]) -> Vec<PathBuf> {
    let Ok(dir) = fs::canonicalize(target) else {
        return Vec::new();
    };
    let named = inputs
        .iter()
        .filter_map(|&input| Some((fs::canonicalize(input).ok()?, input.to_path_buf())));
    let opened = crate::input::files_opened()
        .into_iter()
        .map(|p| (p.clone(), p));
    named
        .chain(opened)
        .filter(|(canonical, _)| canonical.starts_with(&dir))
        .map(|(_, given)| given)
        .collect()
}

/// Give a staged directory the permissions (and, where the user may, the owner and group) of the
/// directory it replaces: `mkdir -m 700 out` stays private after a publish.
fn keep_mode_and_owner(target: &Path, staging: &Path) {
    let Ok(meta) = fs::metadata(target) else {
        return;
    };
    if !meta.is_dir() {
        return;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let _ = std::os::unix::fs::chown(staging, Some(meta.uid()), Some(meta.gid()));
    }
    let _ = fs::set_permissions(staging, meta.permissions());
}

/// Put the filled `staging` in `target`'s place, keeping whatever texel did not write. `marked`:
/// `target` held a marker when the run started (else it was empty or missing); `(parent, tag)`
/// name its temporaries.
fn swap_in(
    dest: &Path,
    target: &Path,
    staging: &Path,
    marked: bool,
    inputs: &[&Path],
    (parent, tag): (&Path, &str),
) -> Result<(), OutputError> {
    let exists = fs::symlink_metadata(target).is_ok();
    if !exists {
        return fs::rename(staging, target).map_err(io_err(dest));
    }
    // What the directory holds now, not what it held when the run started.
    let owned = Owned::of(target);
    let mut clash = Vec::new();
    if marked && texel_marker(target).is_none() {
        clash.push(PathBuf::from(
            "(the whole directory: its .texel-output marker is gone)",
        ));
    } else {
        clashes(target, staging, &owned, Path::new(""), &mut clash);
    }
    // An input the run has read since it started (an image the fill opened) is never replaced.
    let inside = inputs_inside(target, inputs);
    if !clash.is_empty() || !inside.is_empty() {
        let kept = visible_sibling(target, "new");
        let at = match fs::rename(staging, &kept) {
            Ok(()) => format!("the new output is in {}", kept.display()),
            Err(_) => "the new output is discarded".to_string(),
        };
        let list = |v: &[PathBuf]| {
            v.iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let why = if clash.is_empty() {
            format!("holds inputs of this run ({})", list(&inside))
        } else {
            format!(
                "now holds files texel did not write under names the new output uses ({})",
                list(&clash)
            )
        };
        return Err(refuse(
            dest,
            std::io::ErrorKind::AlreadyExists,
            &format!("{why}: it is left as it is, and {at}"),
        ));
    }
    let old = temporary(parent, tag, ".old");
    // Marks the directory moved aside as in use while its files are carried over.
    let _lock = hold(target);
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
    crate::term::stderr_line(format_args!(
        "texel: warning: files saved into {} while texel published it clash with the new \
         output's names; they are kept in {}",
        dest.display(),
        kept.display()
    ));
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
    fn a_marker_owns_only_the_files_it_lists() {
        let d = scratch("atomic-unlisted");
        // texel's header without a list: nothing is texel's, so nothing is removed.
        let out = d.join("out");
        fs::create_dir(&out).unwrap();
        fs::write(out.join("old.png"), b"o").unwrap();
        fs::write(out.join(OUTPUT_MARKER), format!("{MARKER_HEADER}\n")).unwrap();
        publish_dir(&out, &[], fill_with(&["new.png"], || ())).unwrap();
        assert_eq!(names(&out), vec![OUTPUT_MARKER, "new.png", "old.png"]);
        assert_eq!(fs::read(out.join("old.png")).unwrap(), b"o");
        // An empty marker (`touch .texel-output`) or a foreign one is not texel's: the directory is
        // refused and keeps every file.
        for text in ["", "files:\nthesis.tex\n"] {
            let mine = d.join("thesis");
            fs::create_dir_all(&mine).unwrap();
            fs::write(mine.join("thesis.tex"), b"chapter 1").unwrap();
            fs::write(mine.join(OUTPUT_MARKER), text).unwrap();
            let e = publish_dir(&mine, &[], fill_with(&["new.png"], || ())).unwrap_err();
            assert!(e.to_string().contains("did not write"), "{e}");
            assert_eq!(names(&mine), vec![OUTPUT_MARKER, "thesis.tex"]);
            assert_eq!(fs::read(mine.join("thesis.tex")).unwrap(), b"chapter 1");
        }
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_locked_temporary_is_never_stale() {
        let d = scratch("atomic-locked");
        let tag = name_tag(std::ffi::OsStr::new("out"));
        // A staging directory of a process this namespace cannot see (PID beyond pid_max): held by
        // its lock, it stays; once the lock is gone, the next publish removes it.
        let staging = d.join(format!("{tag}4294967294.0.tmp"));
        fs::create_dir(&staging).unwrap();
        fs::write(staging.join("half.png"), b"h").unwrap();
        let lock = hold(&staging).expect("this file system takes locks");
        publish_dir(&d.join("out"), &[], fill_with(&["a.png"], || ())).unwrap();
        assert!(staging.join("half.png").exists());
        drop(lock);
        publish_dir(&d.join("out"), &[], fill_with(&["a.png"], || ())).unwrap();
        assert!(!staging.exists());
        // The same for a file's temporary.
        let a = name_tag(std::ffi::OsStr::new("a.png"));
        let tmp = d.join(format!("{a}4294967294.0.tmp"));
        fs::write(&tmp, b"half").unwrap();
        let lock = hold(&tmp).unwrap();
        write_atomic(&d.join("a.png"), b"whole").unwrap();
        assert!(tmp.exists());
        drop(lock);
        write_atomic(&d.join("a.png"), b"whole").unwrap();
        assert!(!tmp.exists());
        fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_published_directory_keeps_its_mode() {
        use std::os::unix::fs::PermissionsExt;
        let d = scratch("atomic-mode");
        let out = d.join("priv");
        fs::create_dir(&out).unwrap();
        fs::set_permissions(&out, fs::Permissions::from_mode(0o700)).unwrap();
        publish_dir(&out, &[], fill_with(&["a.png"], || ())).unwrap();
        let mode = fs::metadata(&out).unwrap().permissions().mode() & 0o7777;
        assert_eq!(mode, 0o700);
        // And again over texel's own output.
        fs::set_permissions(&out, fs::Permissions::from_mode(0o750)).unwrap();
        publish_dir(&out, &[], fill_with(&["b.png"], || ())).unwrap();
        let mode = fs::metadata(&out).unwrap().permissions().mode() & 0o7777;
        assert_eq!(mode, 0o750);
        fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn publish_never_replaces_a_file_the_process_opened() {
        let d = scratch("atomic-opened");
        let out = d.join("mips");
        publish_dir(&out, &[], fill_with(&["level-00.png"], || ())).unwrap();
        // The run reads a file of the old output (a texture of its scene) without naming it.
        let texture = out.join("level-00.png");
        crate::input::read_regular(&texture, 1 << 20).unwrap();
        let e = publish_dir(&out, &[], fill_with(&["level-00.png"], || ())).unwrap_err();
        assert!(e.to_string().contains("holds the input"), "{e}");
        assert_eq!(fs::read(&texture).unwrap(), b"level-00.png");
        fs::remove_dir_all(&d).unwrap();
    }

    /// A link another user planted in a sticky, world-writable directory is not followed; the
    /// directory owner's and one's own are. Needs root (to give the link another owner).
    #[cfg(unix)]
    #[test]
    fn a_planted_link_in_a_sticky_directory_is_not_followed() {
        use std::os::unix::fs::PermissionsExt;
        if rustix::process::geteuid().as_raw() != 0 {
            eprintln!("skipped: needs root to give a link another owner");
            return;
        }
        let d = scratch("atomic-planted");
        let tmp = d.join("tmp");
        fs::create_dir(&tmp).unwrap();
        fs::set_permissions(&tmp, fs::Permissions::from_mode(0o1777)).unwrap();
        let victim = d.join("victim.conf");
        fs::write(&victim, b"root's settings").unwrap();
        let link = tmp.join("out.png");
        std::os::unix::fs::symlink(&victim, &link).unwrap();
        std::os::unix::fs::lchown(&link, Some(12345), Some(12345)).unwrap();
        let e = write_atomic(&link, b"png").unwrap_err();
        assert!(e.to_string().contains("protected_symlinks"), "{e}");
        assert_eq!(fs::read(&victim).unwrap(), b"root's settings");
        let e = publish_dir::<(), OutputError>(&link, &[], |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("protected_symlinks"), "{e}");
        // The same link owned by the directory's owner (root) is followed.
        std::os::unix::fs::lchown(&link, Some(0), Some(0)).unwrap();
        write_atomic(&link, b"png").unwrap();
        assert_eq!(fs::read(&victim).unwrap(), b"png");
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
