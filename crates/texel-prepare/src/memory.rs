//! A memory budget: the bytes a piece of work may hold at once, and the running account against it.
//!
//! Every allocation that grows with the input is charged before it is made ([`MemoryBudget::take`]):
//! [`crate::PreparedScene::new`] charges the meshes, one frame and each texture (the texture's own
//! [`texel_texture::Limits::max_bytes`] is set to what is left while it loads, so its file, decoded
//! image, texels and pyramid scratch are bounded too, then its pyramid is charged). The per-pixel and
//! per-element figures are upper bounds read off the code, listed with each constant.
//!
//! A refusal states the whole need: what the refused step needs, what is already held, and their
//! sum, rounded up, so that a limit of the sum gets past that step. A texture's own refusal under
//! limits set from what the budget had left ([`MemoryBudget::texture_limits`]) is restated so
//! ([`MemoryBudget::restate`]).

use texel_scene::SceneLimits;
use texel_texture::{Limits, TextureError};

use crate::Error;

/// What a rendered frame holds per pixel, at most: colour (16 for a float target, the reference's
/// and the viewer's; 4 for the CLI's 8-bit targets), depth (4), a coverage mask derived from the
/// depth (1), texel counts (4), the 8-bit image (4), its RGBA bytes for the encoder (4) and the
/// PNG (at most about 4 plus headers) = 37, rounded up. (Footprint capture, 24 more, is a debug option the
/// scene path does not use.)
pub const FRAME_BYTES_PER_PIXEL: u64 = 40;

/// What a scene keeps per vertex, at most: the scene's position, uv, normal and colour (48 bytes)
/// and the rasterizer's [`texel_raster::Vertex`].
pub const VERTEX_BYTES: u64 = 48 + std::mem::size_of::<texel_raster::Vertex>() as u64;

/// What a scene keeps per mesh beyond its vertices and triangles, as an allowance: the mesh's
/// record and names, its vectors' allocations, and the renderer's per-draw state.
pub const MESH_BYTES: u64 = 4096;

/// What a scene keeps per triangle: its indices (12 bytes). The rasterizer's per-frame set-up and
/// tile bins depend on where the triangle lands on screen: [`raster_bytes`].
pub const TRIANGLE_BYTES: u64 = 12;

/// One rasterizer set-up (`texel_raster::setup::TriangleSetup`), kept twice at most: the reference
/// renderer concatenates the per-chunk vectors, and a chunk's vector may double once when clipping
/// adds sub-triangles.
const SETUP_BYTES: u64 = 2 * std::mem::size_of::<texel_raster::setup::TriangleSetup>() as u64;

/// One tile-bin entry (a set-up reference of at most 16 bytes), twice for the vectors' growth.
const BIN_ENTRY_BYTES: u64 = 32;

/// An upper bound of what the rasterizer allocates per frame for `scene`'s triangles at
/// `width x height`: per triangle, its set-ups (one if all three vertices lie inside the clip
/// volume and the guard band, else up to eight sub-triangles of the clipped polygon) and one bin
/// entry per 64 x 64 tile its screen box overlaps (every tile for a clipped triangle). One pass
/// over the vertices, projected as the rasterizer projects them.
pub fn raster_bytes(scene: &texel_scene::Scene, width: u32, height: u32) -> u64 {
    const TILE: u64 = 64;
    const GUARD: f64 = 8.0;
    let (w, h) = (f64::from(width), f64::from(height));
    let tiles_x = u64::from(width).div_ceil(TILE);
    let tiles_y = u64::from(height).div_ceil(TILE);
    let all_tiles = tiles_x * tiles_y;
    let m = scene
        .camera
        .clip_from_world(width as f32 / height as f32)
        .as_dmat4();
    let mut bytes = 0u64;
    for mesh in &scene.meshes {
        // Screen position of each vertex, or None outside the clip volume or the guard band.
        let screen: Vec<Option<(f64, f64)>> = mesh
            .positions
            .iter()
            .map(|p| {
                let c = m * p.as_dvec3().extend(1.0);
                let inside = c.w > 0.0
                    && c.z.abs() <= c.w
                    && c.x.abs() <= GUARD * c.w
                    && c.y.abs() <= GUARD * c.w;
                inside.then(|| ((c.x / c.w + 1.0) * 0.5 * w, (1.0 - c.y / c.w) * 0.5 * h))
            })
            .collect();
        for t in &mesh.triangles {
            let v = t.map(|i| screen.get(i as usize).copied().flatten());
            let (setups, tiles) = match v {
                [Some(a), Some(b), Some(c)] => {
                    let tile =
                        |x: f64, n: u64| ((x.max(0.0) as u64) / TILE).min(n.saturating_sub(1));
                    let (x0, x1) = (a.0.min(b.0).min(c.0), a.0.max(b.0).max(c.0));
                    let (y0, y1) = (a.1.min(b.1).min(c.1), a.1.max(b.1).max(c.1));
                    let nx = tile(x1, tiles_x) - tile(x0, tiles_x) + 1;
                    let ny = tile(y1, tiles_y) - tile(y0, tiles_y) + 1;
                    (1, nx * ny)
                }
                _ => (8, all_tiles),
            };
            bytes = bytes
                .saturating_add(setups * SETUP_BYTES)
                .saturating_add(tiles * BIN_ENTRY_BYTES);
        }
    }
    bytes
}

/// The budget when the machine's memory cannot be read: 8 GiB.
pub const FALLBACK_BYTES: u64 = 8 << 30;

/// `bytes` in MiB with one decimal, for messages.
pub fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / f64::from(1 << 20))
}

/// `bytes` in MiB with one decimal, rounded up: a need, which a limit of the figure printed
/// covers.
pub fn mib_up(bytes: u64) -> String {
    let tenths = (u128::from(bytes) * 10).div_ceil(1 << 20);
    format!("{}.{} MiB", tenths / 10, tenths % 10)
}

/// ` on top of X already held, Y in all` when `used > 0`, for [`Error::OverBudget`]'s message
/// (the sum rounded up).
pub(crate) fn held(used: u64, bytes: u64) -> String {
    if used == 0 {
        String::new()
    } else {
        format!(
            " on top of {} already held, {} in all",
            mib(used),
            mib_up(used.saturating_add(bytes))
        )
    }
}

/// The machine's memory in bytes, where it can be read: the smaller of `MemTotal`
/// (`/proc/meminfo`) and the cgroup v2 limit (`/sys/fs/cgroup/memory.max`).
pub fn machine_memory() -> Option<u64> {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find_map(|l| l.strip_prefix("MemTotal:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            .map(|kb| kb * 1024)
    });
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok());
    match (total, cgroup) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

/// A field of a `/proc` text file (`Key: value ...`), its first number.
fn proc_field(text: &str, key: &str) -> Option<u64> {
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
}

/// The soft limit in bytes of a `/proc/self/limits` row (`None` for "unlimited").
fn soft_limit(limits: &str, row: &str) -> Option<u64> {
    limits
        .lines()
        .find_map(|l| l.strip_prefix(row))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
}

/// The memory limits of the process's own cgroup and every cgroup above it, as `(file, bytes)`:
/// cgroup v2 `memory.max` along the `0::PATH` line of `/proc/self/cgroup`, v1
/// `memory.limit_in_bytes` along the `memory` controller's line ("max" and v1's huge "no limit"
/// value are larger than any machine's memory, so the smallest of all still decides).
fn cgroup_limits(self_cgroup: &str) -> Vec<(String, u64)> {
    let mut out = Vec::new();
    let mut walk = |root: &str, file: &str, path: &str| {
        let mut dir = std::path::PathBuf::from(root).join(path.trim_start_matches('/'));
        loop {
            let p = dir.join(file);
            if let Some(b) = std::fs::read_to_string(&p)
                .ok()
                .and_then(|s| s.trim().parse::<u64>().ok())
            {
                out.push((p.display().to_string(), b));
            }
            if dir.as_os_str() == root || !dir.pop() {
                break;
            }
        }
    };
    for line in self_cgroup.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(_), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next())
        else {
            continue;
        };
        if controllers.is_empty() {
            walk("/sys/fs/cgroup", "memory.max", path);
        } else if controllers.split(',').any(|c| c == "memory") {
            walk("/sys/fs/cgroup/memory", "memory.limit_in_bytes", path);
        }
    }
    if self_cgroup.trim().is_empty() {
        // No /proc/self/cgroup: the roots.
        walk("/sys/fs/cgroup", "memory.max", "/");
        walk("/sys/fs/cgroup/memory", "memory.limit_in_bytes", "/");
    }
    out
}

/// The share of a process limit's headroom that the default budget grants: the rest covers what
/// no account charges (the allocator's arenas, thread stacks, decoders' and encoders' scratch).
const PROCESS_LIMIT_SHARE: u64 = 2;

/// The default memory limit of a piece of work and what set it: the smallest of half of the
/// machine's memory (`MemTotal`), the cgroup's limit (v2 `memory.max`, v1
/// `memory.limit_in_bytes`), and half of what the address-space (`ulimit -v`, `RLIMIT_AS`) and
/// data (`ulimit -d`, `RLIMIT_DATA`) limits leave above what the process already maps. Where none
/// can be read, [`FALLBACK_BYTES`].
pub fn default_limit() -> (u64, String) {
    process_limit(true).unwrap_or((FALLBACK_BYTES, "texel's fallback limit".into()))
}

/// The most an explicit limit may grant, and what sets it: [`default_limit`]'s figures with the
/// whole of the machine's memory rather than half (the cgroup's limit and half of what the
/// process limits leave stay as they are: past them an allocation fails, and the process aborts,
/// whatever the account allows). `None` where none can be read.
pub fn hard_limit() -> Option<(u64, String)> {
    process_limit(false)
}

/// An explicit limit of `requested` bytes held to [`hard_limit`]: the bytes a budget may grant
/// and its name for errors, `name` itself or, when capped, `name` followed by the cap and what
/// set it (`--max-memory 1048576.0 MiB, capped at 23984.1 MiB (this machine's memory)`).
fn capped_limit(requested: u64, name: &str) -> (u64, String) {
    match hard_limit() {
        Some((hard, why)) if hard < requested => {
            (hard, format!("{name}, capped at {} ({why})", mib(hard)))
        }
        _ => (requested, name.to_string()),
    }
}

/// The smallest of `MemTotal` (half of it with `half_of_machine`), the cgroup limits and half of
/// what the process limits leave, with what set it (see [`default_limit`]).
fn process_limit(half_of_machine: bool) -> Option<(u64, String)> {
    let read = |p: &str| std::fs::read_to_string(p).ok();
    let mut best: Option<(u64, String)> = None;
    let mut offer = |bytes: u64, why: String| {
        if best.as_ref().is_none_or(|(b, _)| bytes < *b) {
            best = Some((bytes, why));
        }
    };
    if let Some(kb) = read("/proc/meminfo").and_then(|s| proc_field(&s, "MemTotal:")) {
        if half_of_machine {
            offer(kb * 1024 / 2, "half of this machine's memory".into());
        } else {
            offer(kb * 1024, "this machine's memory".into());
        }
    }
    for (p, b) in cgroup_limits(&read("/proc/self/cgroup").unwrap_or_default()) {
        offer(b, format!("the cgroup's memory limit ({p})"));
    }
    if let (Some(limits), Some(status)) = (read("/proc/self/limits"), read("/proc/self/status")) {
        let rows = [
            (
                "Max address space",
                "VmSize:",
                "the address-space limit (ulimit -v)",
            ),
            (
                "Max data size",
                "VmData:",
                "the data-size limit (ulimit -d)",
            ),
        ];
        for (row, held, name) in rows {
            if let Some(limit) = soft_limit(&limits, row) {
                let used = proc_field(&status, held).unwrap_or(0) * 1024;
                let room = limit.saturating_sub(used) / PROCESS_LIMIT_SHARE;
                offer(
                    room,
                    format!(
                        "half of what {name} of {} leaves above the {} this process maps",
                        mib(limit),
                        mib(used)
                    ),
                );
            }
        }
    }
    best
}

/// The running account of one piece of work against a limit.
#[derive(Clone, Debug)]
pub struct MemoryBudget {
    limit: u64,
    used: u64,
    name: String,
}

impl MemoryBudget {
    /// A budget of `limit` bytes; `name` says what set it, in errors (e.g. `--max-memory 4.0 GiB`).
    pub fn new(limit: u64, name: impl Into<String>) -> Self {
        MemoryBudget {
            limit,
            used: 0,
            name: name.into(),
        }
    }

    /// A budget of `limit` bytes when given (named "the memory limit of N MiB"), held to
    /// [`hard_limit`] ([`MemoryBudget::explicit`]), else [`MemoryBudget::process_default`].
    pub fn limit_or_default(limit: Option<u64>) -> Self {
        match limit {
            Some(b) => Self::explicit(b, &format!("the memory limit of {}", mib(b))),
            None => Self::process_default(),
        }
    }

    /// A budget of the `requested` bytes a user asked for, held to [`hard_limit`], and named
    /// `name` or, when capped, `name` followed by the cap and what set it (`--max-memory
    /// 1048576.0 MiB, capped at 23984.1 MiB (this machine's memory)`).
    pub fn explicit(requested: u64, name: &str) -> Self {
        let (limit, name) = capped_limit(requested, name);
        Self::new(limit, name)
    }

    /// The default budget: [`default_limit`], named after the limit that set it.
    pub fn process_default() -> Self {
        let (limit, why) = default_limit();
        Self::new(limit, format!("the memory limit of {} ({why})", mib(limit)))
    }

    /// Half of [`machine_memory`] (or [`FALLBACK_BYTES`] where it cannot be read).
    pub fn half_of_machine() -> Self {
        let limit = machine_memory().map_or(FALLBACK_BYTES, |m| m / 2);
        Self::new(
            limit,
            format!(
                "the memory limit of {} (half of this machine's memory)",
                mib(limit)
            ),
        )
    }

    /// The limit in bytes.
    pub fn limit(&self) -> u64 {
        self.limit
    }

    /// Bytes not yet accounted for.
    pub fn remaining(&self) -> u64 {
        self.limit.saturating_sub(self.used)
    }

    /// How the limit is described in errors.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Account for `bytes` that `what` will hold, or refuse (the account unchanged).
    ///
    /// # Errors
    /// [`Error::OverBudget`] with the figures.
    pub fn take(&mut self, what: &str, bytes: u64) -> Result<(), Error> {
        let total = self.used.saturating_add(bytes);
        if total > self.limit {
            return Err(Error::OverBudget {
                what: what.to_string(),
                bytes,
                used: self.used,
                limit: self.name.clone(),
            });
        }
        self.used = total;
        Ok(())
    }

    /// Return `bytes` taken earlier whose memory is freed (at most what is in use).
    pub fn release(&mut self, bytes: u64) {
        self.used = self.used.saturating_sub(bytes);
    }

    /// Bytes accounted for.
    pub fn used(&self) -> u64 {
        self.used
    }

    /// The texture limits of work done within what is left: [`Limits::default`] with
    /// [`Limits::max_bytes`] set to [`MemoryBudget::remaining`]. A texture made under them keeps
    /// them, and they bound its ripmap and summed-area table too.
    pub fn texture_limits(&self) -> Limits {
        Limits {
            max_bytes: self.remaining(),
            ..Limits::default()
        }
    }

    /// The scene limits of loading within what is left: [`SceneLimits::default`], lowered where
    /// [`MemoryBudget::remaining`] is smaller. Allowances read off the loaders, not measured peaks:
    /// a glTF/GLB file is held up to three times while it loads (the file, its binary chunk, the
    /// buffers) and an OBJ file about as often with `tobj`'s vectors, so files get a quarter of
    /// what is left; the TOML parser's tables get a sixteenth for the text; a triangle may bring
    /// three vertices of its own and needs at least one rasterizer set-up and bin entry (about 700
    /// bytes; [`raster_bytes`] counts them exactly once the mesh is loaded).
    pub fn scene_limits(&self) -> SceneLimits {
        let remaining = self.remaining();
        let d = SceneLimits::default();
        SceneLimits {
            max_scene_bytes: d.max_scene_bytes.min(remaining / 16),
            max_mesh_file_bytes: d.max_mesh_file_bytes.min(remaining / 4),
            max_triangles: d
                .max_triangles
                .min(remaining / (TRIANGLE_BYTES + 3 * VERTEX_BYTES + 700)),
            max_vertices: d.max_vertices.min(remaining / VERTEX_BYTES),
            max_meshes: d.max_meshes.min(remaining / MESH_BYTES),
        }
    }

    /// `e` stated against this budget where it is a texture's refusal of memory
    /// ([`TextureError::OverMemoryLimit`], [`TextureError::StructureOverMemoryLimit`], bare or in
    /// a [`texel_scene::SceneError::Texture`]) under limits this budget gave
    /// ([`MemoryBudget::texture_limits`], now or earlier, before later charges): an
    /// [`Error::OverBudget`] whose sum is the limit this budget would need for the texture to
    /// fit, the texture's own limit being what that budget would have left. Other errors are
    /// returned as they are.
    pub fn restate(&self, e: impl Into<Error>) -> Error {
        let e = e.into();
        let (name, path, source) = match &e {
            Error::Scene(texel_scene::SceneError::Texture { name, path, source }) => {
                (Some(name.as_str()), path.as_deref(), source)
            }
            Error::Texture(source) => (None, None, source),
            _ => return e,
        };
        let texture = match (name, path) {
            (Some(n), Some(p)) => format!("texture {n:?} from {}", p.display()),
            (Some(n), None) => format!("texture {n:?}"),
            (None, _) => "a texture".to_string(),
        };
        let (what, bytes, max) = match *source {
            TextureError::OverMemoryLimit {
                width,
                height,
                bytes,
                max,
            } => (
                format!("loading {texture} ({width}x{height}, with its mip pyramid)"),
                bytes,
                max,
            ),
            TextureError::StructureOverMemoryLimit {
                structure,
                width,
                height,
                bytes,
                max,
            } => (
                format!("building the {structure} of {texture} ({width}x{height})"),
                bytes,
                max,
            ),
            _ => return e,
        };
        // The texture's limit moves with this budget's: it is short by `bytes - max`.
        let total = self.limit.saturating_add(bytes.saturating_sub(max));
        Error::OverBudget {
            what,
            bytes: total.saturating_sub(self.used),
            used: self.used,
            limit: self.name.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn explicit_limits_are_capped_by_the_hard_limit() {
        // Where `ulimit -v`/`-d` binds, the figure moves with what the process maps (other tests'
        // threads), so no two reads are compared for equality.
        let Some((hard, _)) = hard_limit() else {
            println!("skipped: neither /proc/meminfo nor a cgroup or process limit can be read");
            return;
        };
        // Never more than the machine: MemTotal itself is one of the figures.
        let total = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|s| proc_field(&s, "MemTotal:"))
            .map_or(u64::MAX, |kb| kb * 1024);
        assert!(hard <= total, "{hard}");
        let (b, name) = capped_limit(u64::MAX, "--max-memory huge");
        assert!(b <= total, "{b}");
        assert!(name.starts_with("--max-memory huge, capped at "), "{name}");
        assert!(name.ends_with(')') && name.contains(" MiB ("), "{name}");
        let (b, name) = capped_limit(1 << 20, "--max-memory 1.0 MiB");
        assert_eq!((b, name.as_str()), (1 << 20, "--max-memory 1.0 MiB"));
        let budget = MemoryBudget::limit_or_default(Some(u64::MAX));
        assert!(budget.name().contains("capped at"), "{}", budget.name());
    }

    #[test]
    fn scene_limits_follow_what_is_left() {
        let d = SceneLimits::default();
        assert_eq!(MemoryBudget::new(u64::MAX, "all").scene_limits(), d);
        let mut b = MemoryBudget::new(64 << 20, "--max-memory 64.0 MiB");
        b.take("a frame", 32 << 20).unwrap();
        let left: u64 = 32 << 20;
        let l = b.scene_limits();
        assert_eq!(l.max_scene_bytes, (left / 16).min(d.max_scene_bytes));
        assert_eq!(l.max_mesh_file_bytes, left / 4);
        assert_eq!(
            l.max_triangles,
            left / (TRIANGLE_BYTES + 3 * VERTEX_BYTES + 700)
        );
        assert_eq!(l.max_vertices, left / VERTEX_BYTES);
        assert_eq!(l.max_meshes, (left / MESH_BYTES).min(d.max_meshes));
        // Each is no larger than the default, and a spent budget admits nothing.
        assert!(l.max_mesh_file_bytes < d.max_mesh_file_bytes);
        assert!(l.max_triangles < d.max_triangles && l.max_vertices < d.max_vertices);
        b.take("the rest", left).unwrap();
        let none = b.scene_limits();
        assert_eq!(
            [
                none.max_scene_bytes,
                none.max_mesh_file_bytes,
                none.max_triangles,
                none.max_vertices,
                none.max_meshes
            ],
            [0; 5]
        );
    }

    #[test]
    fn account_refuses_with_figures() {
        let mut b = MemoryBudget::new(10 << 20, "--max-memory 10.0 MiB");
        b.take("a", 6 << 20).unwrap();
        assert_eq!(b.remaining(), 4 << 20);
        b.release(1 << 20);
        assert_eq!(b.remaining(), 5 << 20);
        b.take("a", 1 << 20).unwrap();
        let e = b.take("the frame", 5 << 20).unwrap_err().to_string();
        assert!(e.contains("the frame needs about 5.0 MiB on top of 6.0 MiB already held, 11.0 MiB in all, over --max-memory 10.0 MiB"), "{e}");
        assert_eq!(b.remaining(), 4 << 20);
        let e = MemoryBudget::new(1 << 20, "X")
            .take("y", 2 << 20)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("y needs about 2.0 MiB, over X: raise"), "{e}");
    }

    #[test]
    fn needs_round_up() {
        assert_eq!(mib_up(0), "0.0 MiB");
        assert_eq!(mib_up(1 << 20), "1.0 MiB");
        assert_eq!(mib_up((1 << 20) + 1), "1.1 MiB");
        assert_eq!(mib_up((5 << 20) + (1 << 20) / 2), "5.5 MiB");
        // Rounded to the nearest tenth, this need would print below itself.
        let e = MemoryBudget::new(1 << 20, "X")
            .take("y", (2 << 20) + 1000)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("y needs about 2.1 MiB, over X"), "{e}");
    }

    #[test]
    fn a_texture_refusal_is_restated_with_the_whole_need() {
        let mut b = MemoryBudget::new(100 << 20, "--max-memory 100.0 MiB");
        b.take("the frame", 30 << 20).unwrap();
        let limits = b.texture_limits();
        assert_eq!(limits.max_bytes, 70 << 20);
        // A texture refused under what was left: the whole need is what is held plus its bytes.
        let refusal = TextureError::OverMemoryLimit {
            width: 4096,
            height: 4096,
            bytes: 90 << 20,
            max: limits.max_bytes,
        };
        let scene = texel_scene::SceneError::Texture {
            name: "t".into(),
            path: None,
            source: refusal,
        };
        match b.restate(scene) {
            Error::OverBudget {
                what, bytes, used, ..
            } => {
                assert_eq!((bytes, used), (90 << 20, 30 << 20));
                assert!(
                    what.starts_with("loading texture \"t\" (4096x4096"),
                    "{what}"
                );
            }
            e => panic!("{e}"),
        }
        // A structure refused later, under the limits the texture kept from its load, after
        // more was charged: the budget needs its limit plus what the texture is short by.
        b.take("texture t", 20 << 20).unwrap();
        let later = TextureError::StructureOverMemoryLimit {
            structure: "ripmap",
            width: 4096,
            height: 4096,
            bytes: 120 << 20,
            max: limits.max_bytes,
        };
        let e = b.restate(later);
        let text = e.to_string();
        assert!(
            text.contains(
                "needs about 100.0 MiB on top of 50.0 MiB already held, 150.0 MiB in all"
            ),
            "{text}"
        );
        // Other errors pass through.
        let other = b.restate(TextureError::InvalidLodBias(f32::NAN));
        assert!(matches!(other, Error::Texture(_)), "{other}");
    }
}

#[cfg(test)]
mod raster_tests {
    use super::*;

    fn scene(z_third: f32) -> texel_scene::Scene {
        let text = format!(
            r#"[output]
width = 128
height = 128
[camera]
eye = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fovy_deg = 90.0
near = 0.1
far = 10.0
[textures.t]
procedural = "solid"
[[meshes]]
texture = "t"
positions = [[-2.9, -2.9, 0.0], [2.9, -2.9, 0.0], [0.0, 2.9, {z_third}]]
uvs = [[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]]
triangles = [[0, 1, 2]]
"#
        );
        texel_scene::Scene::from_toml_str(&text, std::path::Path::new("t.toml")).unwrap()
    }

    #[test]
    fn raster_bytes_counts_setups_and_tiles() {
        // On screen, spanning all four 64x64 tiles of a 128x128 frame: one set-up, four bins.
        assert_eq!(
            raster_bytes(&scene(0.0), 128, 128),
            SETUP_BYTES + 4 * BIN_ENTRY_BYTES
        );
        // At 256x256 the frame has 16 tiles and the triangle's box covers all of them.
        assert_eq!(
            raster_bytes(&scene(0.0), 256, 256),
            SETUP_BYTES + 16 * BIN_ENTRY_BYTES
        );
        // A vertex behind the eye: the clipped polygon may make eight set-ups and cover every tile.
        assert_eq!(
            raster_bytes(&scene(5.0), 128, 128),
            8 * SETUP_BYTES + 4 * BIN_ENTRY_BYTES
        );
    }
}
