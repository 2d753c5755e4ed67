//! Reading input files safely: only regular files, never more than a stated number of bytes.
//!
//! A FIFO, a device or a directory where an input file belongs is an error before anything is
//! opened (opening a FIFO for reading blocks until a writer appears, and `/dev/zero` never ends);
//! a file larger than the caller's bound is an error carrying both figures, before it is read.
//! Every input texel reads (images, scene files, OBJ, glTF and their buffers) goes through here,
//! and every third-party image decoder runs inside [`guarded`].

use std::cell::Cell;
use std::collections::BTreeSet;
use std::fs::File;
use std::io::{self, Read};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Every file [`open_regular`] has opened in this process, as canonical paths: the inputs an
/// output directory must never replace or delete ([`crate::publish_dir`] refuses to publish over
/// a directory that holds one).
static OPENED: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());

/// The canonical paths of every input this process has opened through [`open_regular`] (and so
/// [`read_regular`]): scene files, meshes, glTF buffers, textures, environment maps, images.
pub fn files_opened() -> Vec<PathBuf> {
    let set = OPENED.lock().unwrap_or_else(|e| e.into_inner());
    set.iter().cloned().collect()
}

/// The recorders [`record_opened`] has running: each collects the paths opened while it runs.
static RECORDERS: Mutex<Vec<(u64, Vec<PathBuf>)>> = Mutex::new(Vec::new());

/// Numbers the recorders.
static NEXT_RECORDER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Run `work` and return, beside its result, every file [`open_regular`] opened while it ran, as
/// the paths it was given, in order, each once: the files a job reads, found by the code that
/// reads them (a scene's meshes, glTF buffers and images, textures, environment faces). Files
/// opened meanwhile by other threads are included too, so the list may hold more than `work`'s
/// own, never less.
pub fn record_opened<T>(work: impl FnOnce() -> T) -> (T, Vec<PathBuf>) {
    /// A running recorder; dropped (even when `work` panics), it takes its list out.
    struct Recorder(u64);
    impl Recorder {
        fn take(&self) -> Vec<PathBuf> {
            let mut all = RECORDERS.lock().unwrap_or_else(|e| e.into_inner());
            match all.iter().position(|(id, _)| *id == self.0) {
                Some(k) => all.swap_remove(k).1,
                None => Vec::new(),
            }
        }
    }
    impl Drop for Recorder {
        fn drop(&mut self) {
            self.take();
        }
    }
    let id = NEXT_RECORDER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    RECORDERS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push((id, Vec::new()));
    let recorder = Recorder(id);
    let value = work();
    let mut files = recorder.take();
    let mut seen = BTreeSet::new();
    files.retain(|p| seen.insert(p.clone()));
    (value, files)
}

thread_local! {
    /// Set while [`guarded`] runs a decoder on this thread.
    static GUARDED: Cell<bool> = const { Cell::new(false) };
}

/// Whether this thread is inside [`guarded`]: a panic hook can stay quiet for a decoder panic that
/// [`guarded`] turns into an error (the `texel` binary's hook does).
pub fn in_guarded_decode() -> bool {
    GUARDED.with(Cell::get)
}

/// Run a third-party decoder, turning a panic inside it into `Err(message)`.
///
/// Decoders are fuzzed upstream but not bug-free: zune-jpeg 0.5.15 (the `image` crate's JPEG
/// decoder) panics in its AVX2 IDCT on some valid-looking sampling factors (found by texel's
/// `image_decode` fuzz target). A corrupt file must be an error, never a crash, so every decode of
/// untrusted bytes goes through here. The closure must not leave shared state half-updated (the
/// decoders own everything they touch).
pub fn guarded<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    let was = GUARDED.with(|g| g.replace(true));
    let r = catch_unwind(AssertUnwindSafe(f));
    GUARDED.with(|g| g.set(was));
    r.map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".to_string())
    })
}

/// Open `path` for reading if it is a regular file (symbolic links followed).
///
/// # Errors
/// The `stat`/`open` error, or [`io::ErrorKind::InvalidInput`] saying what the path is instead
/// (a directory, a FIFO, a device, a socket).
pub fn open_regular(path: &Path) -> io::Result<File> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a directory"
        } else {
            special_kind(&meta.file_type())
        };
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("is {what}, not a regular file: texel reads inputs from regular files only"),
        ));
    }
    let file = File::open(path)?;
    // The path could have been swapped between the two calls; the open file is what counts.
    if !file.metadata()?.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "is not a regular file: texel reads inputs from regular files only",
        ));
    }
    {
        let mut recorders = RECORDERS.lock().unwrap_or_else(|e| e.into_inner());
        for (_, files) in recorders.iter_mut() {
            files.push(path.to_path_buf());
        }
    }
    if let Ok(canonical) = std::fs::canonicalize(path) {
        OPENED
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(canonical);
    }
    Ok(file)
}

#[cfg(unix)]
fn special_kind(ft: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if ft.is_fifo() {
        "a FIFO"
    } else if ft.is_char_device() {
        "a character device"
    } else if ft.is_block_device() {
        "a block device"
    } else if ft.is_socket() {
        "a socket"
    } else {
        "not a file"
    }
}

#[cfg(not(unix))]
fn special_kind(_ft: &std::fs::FileType) -> &'static str {
    "not a file"
}

/// Read the whole regular file `path`, refusing one larger than `max_bytes` before reading it.
///
/// # Errors
/// As [`open_regular`], read errors, and [`io::ErrorKind::InvalidData`] for a file over
/// `max_bytes` (with its size and the bound in the message).
pub fn read_regular(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    let file = open_regular(path)?;
    let len = file.metadata()?.len();
    if len > max_bytes {
        return Err(too_large(len, max_bytes));
    }
    if len == 0 {
        // A size of 0 is not trusted: kernel pseudo-files (`/proc/self/pagemap`, files under
        // `/sys`) report it and then yield bytes without end. Such a file may yield at most
        // PSEUDO_FILE_BYTES; a real empty file yields none.
        let mut out = Vec::new();
        let cap = max_bytes.min(PSEUDO_FILE_BYTES);
        // Whole blocks (some pseudo-files refuse reads that are not a multiple of 8 bytes).
        let mut file = file;
        let mut block = vec![0u8; 64 << 10];
        while out.len() as u64 <= cap {
            let n = match file.read(&mut block) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                r => r?,
            };
            if n == 0 {
                break;
            }
            out.extend_from_slice(&block[..n]);
        }
        if out.len() as u64 > cap {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "reports a size of 0 bytes but yields more than {cap}: a pseudo-file (such \
                     as /proc/self/pagemap), not an input texel reads"
                ),
            ));
        }
        return Ok(out);
    }
    let mut out = Vec::new();
    out.try_reserve_exact(len as usize).map_err(|_| {
        io::Error::new(
            io::ErrorKind::OutOfMemory,
            format!("cannot allocate {len} bytes to read it"),
        )
    })?;
    // `take` guards against a file that grows while it is read.
    file.take(max_bytes + 1).read_to_end(&mut out)?;
    if out.len() as u64 > max_bytes {
        return Err(too_large(out.len() as u64, max_bytes));
    }
    Ok(out)
}

/// The most bytes [`read_regular`] takes from a file whose reported size is 0.
pub const PSEUDO_FILE_BYTES: u64 = 1 << 20;

fn too_large(len: u64, max: u64) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("is {len} bytes, over the limit of {max} bytes for this input"),
    )
}

/// Check that a JPEG whose header claims `width x height` is whole, by walking its marker segments
/// from SOI to EOI (ITU T.81 B.1): every segment's length must fit in the file, every scan's
/// entropy-coded data must end in a marker, and EOI must come before the bytes run out (data
/// after EOI, such as a motion photo's video, is ignored). The scans must also hold at least one
/// bit per 8x8 block of the full-resolution component: every block's DC difference is a Huffman
/// code of at least one bit (F.1.2.1; arithmetic coding, which could go below, is not decoded by
/// texel's decoder anyway). The decoder itself fills what is missing with grey, so a truncated
/// file would otherwise load.
///
/// # Errors
/// A message saying where the stream ends or how many bytes are missing.
pub fn check_jpeg_complete(bytes: &[u8], width: u32, height: u32) -> Result<(), String> {
    let cut = |at: usize| {
        format!(
            "the JPEG ({} bytes) ends at byte {at}, before its end-of-image marker",
            bytes.len()
        )
    };
    if !bytes.starts_with(&[0xFF, 0xD8]) {
        return Err("the JPEG does not start with a start-of-image marker".into());
    }
    let mut i = 2;
    let mut coded = 0u64;
    loop {
        // Skip to the next marker (fill bytes 0xFF included).
        while i < bytes.len() && bytes[i] != 0xFF {
            i += 1;
        }
        while i < bytes.len() && bytes[i] == 0xFF {
            i += 1;
        }
        let Some(&m) = bytes.get(i) else {
            return Err(cut(bytes.len()));
        };
        i += 1;
        match m {
            0xD9 => break,
            0xD0..=0xD7 | 0x01 => continue,
            _ => {
                let len = match bytes.get(i..i + 2) {
                    Some(l) => usize::from(u16::from_be_bytes([l[0], l[1]])),
                    None => return Err(cut(bytes.len())),
                };
                if len < 2 {
                    return Err(format!(
                        "the JPEG has a segment of length {len} at byte {i}"
                    ));
                }
                i += len;
                if i > bytes.len() {
                    return Err(cut(bytes.len()));
                }
                if m == 0xDA {
                    // Entropy-coded data: up to a marker that is not a stuffed 0xFF00 or an RSTn.
                    let start = i;
                    loop {
                        match bytes.get(i..i + 2) {
                            Some([0xFF, n])
                                if *n != 0x00 && !(0xD0..=0xD7).contains(n) && *n != 0xFF =>
                            {
                                break
                            }
                            Some(_) => i += 1,
                            None => return Err(cut(bytes.len())),
                        }
                    }
                    coded += (i - start) as u64;
                }
            }
        }
    }
    let blocks = u64::from(width.div_ceil(8)) * u64::from(height.div_ceil(8));
    let need = blocks.div_ceil(8);
    if coded < need {
        return Err(format!(
            "a {width}x{height} JPEG has {blocks} blocks and needs at least {need} bytes of coded data, but its scans hold {coded}"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_opened_lists_each_file_once_in_order() {
        let d = std::env::temp_dir().join(format!("texel-io-record-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let (a, b) = (d.join("a.txt"), d.join("b.txt"));
        std::fs::write(&a, b"a").unwrap();
        std::fs::write(&b, b"b").unwrap();
        let (n, files) = record_opened(|| {
            read_regular(&b, 16).unwrap();
            read_regular(&a, 16).unwrap();
            read_regular(&b, 16).unwrap();
            // A refused input is not a file the job read.
            assert!(read_regular(&d, 16).is_err());
            3
        });
        assert_eq!(n, 3);
        // The recorder is the process's: other tests of this binary may read files meanwhile.
        let files: Vec<_> = files.into_iter().filter(|f| f.starts_with(&d)).collect();
        assert_eq!(files, vec![b.clone(), a.clone()]);
        // Nothing is recorded once the recorder is done.
        let ((), inner) = record_opened(|| ());
        assert!(inner.is_empty());
        assert!(files_opened().contains(&std::fs::canonicalize(&a).unwrap()));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn regular_files_only() {
        let dir = std::env::temp_dir().join(format!("texel-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("a.bin");
        std::fs::write(&f, b"0123456789").unwrap();
        assert_eq!(read_regular(&f, 10).unwrap(), b"0123456789");
        let e = read_regular(&f, 9).unwrap_err();
        assert!(
            e.to_string().contains("10 bytes, over the limit of 9"),
            "{e}"
        );
        let e = read_regular(&dir, 100).unwrap_err();
        assert!(e.to_string().contains("a directory"), "{e}");
        // An empty file is empty; a pseudo-file that reports 0 bytes and yields more is refused
        // after at most PSEUDO_FILE_BYTES.
        let empty = dir.join("empty");
        std::fs::write(&empty, b"").unwrap();
        assert!(read_regular(&empty, 100).unwrap().is_empty());
        #[cfg(target_os = "linux")]
        {
            let e = read_regular(Path::new("/proc/self/pagemap"), u64::MAX).unwrap_err();
            assert!(e.to_string().contains("pseudo-file"), "{e}");
            // One that yields less is read whole, within the caller's bound.
            let status = read_regular(Path::new("/proc/self/status"), 1 << 20).unwrap();
            assert!(status.starts_with(b"Name:"));
            assert!(read_regular(Path::new("/proc/self/status"), 4).is_err());
        }
        #[cfg(target_os = "linux")]
        {
            let e = read_regular(Path::new("/dev/zero"), 100).unwrap_err();
            assert!(e.to_string().contains("character device"), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
