// texel's filters as a fragment shader that reads the texture only through textureLoad,
// textureDimensions and textureNumLevels (the filtering lab's rule), with the conventions of
// the conventions page: texel (i, j) covers [i, i+1) x [j, j+1) of xy = uv * (W, H); address modes
// act on integer texel indices; 8-bit sRGB texels are decoded through the same 256-entry table as
// the CPU path (uploaded), alpha as b / 255.

struct Params {
    clip_from_world: mat4x4<f32>,
    border: vec4<f32>,
    // x: address mode u, y: address mode v (0 clamp-to-edge, 1 repeat, 2 mirror-repeat,
    // 3 clamp-to-border, 4 mirror-clamp-to-edge)
    address: vec4<u32>,
    // x: mode (1-8 the lab's modes, 9 bicubic Catmull-Rom, 10 EWA, 20 hardware trilinear,
    // 21 hardware anisotropic), y: 1 if the texels are sRGB-encoded 8-bit, z: anisotropy clamp
    // (EWA's eccentricity clamp)
    mode: vec4<u32>,
    // x: lod bias, y: lod min clamp, z: lod max clamp
    lod: vec4<f32>,
}

// The mode as a pipeline constant (the same numbers as `params.mode.x`): each mode gets its own
// pipeline, so the compiler drops the other modes' code instead of branching around it per pixel.
override MODE: u32 = 4u;

// Which rules modes 1-8 follow, as a pipeline constant: 0 the OpenGL / Vulkan rules (texel's
// default), 1 the lab handout's formulas (`--convention lab`, texel_texture::technique::lab).
override CONVENTION: u32 = 0u;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var tex: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> srgb: array<f32, 256>;
@group(0) @binding(3) var hw: sampler;
// The CPU's tables: EWA's Gaussian weights (texel_texture::ewa::weight_lut), LUT[k] for r^2 in
// [k / 128, (k + 1) / 128), at 0..128; then EWA from probes' table
// (texel_texture::ewa_probes::probe_table) for n probes: positions at 128 + 16 (n - 1) + i,
// weights at 384 + 16 (n - 1) + i, spacing at 640 + n - 1.
@group(0) @binding(4) var<storage, read> ewa_lut: array<f32, 656>;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) color: vec4<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) color: vec4<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    let c = params.clip_from_world * vec4<f32>(v.position, 1.0);
    // The camera is OpenGL's (z in [-w, w]); the device clips z to [0, w].
    out.clip = vec4<f32>(c.x, c.y, 0.5 * (c.z + c.w), c.w);
    out.uv = v.uv;
    out.color = v.color;
    return out;
}

// ---- Texel fetches -----------------------------------------------------------------------------

// An integer texel index wrapped into [0, n) by an address mode; -1 where the border colour applies.
fn wrap(i: i32, n: i32, mode: u32) -> i32 {
    switch mode {
        case 1u: { // repeat
            return ((i % n) + n) % n;
        }
        case 2u: { // mirror repeat
            let r = ((i % (2 * n)) + 2 * n) % (2 * n);
            return select(2 * n - 1 - r, r, r < n);
        }
        case 3u: { // clamp to border
            return select(-1, i, i >= 0 && i < n);
        }
        case 4u: { // mirror clamp to edge
            return min(select(i, -1 - i, i < 0), n - 1);
        }
        default: { // clamp to edge
            return clamp(i, 0, n - 1);
        }
    }
}

// The size of `level`: Vulkan's rule max(1, floor(size0 / 2^level)), from level 0's size. (Asking
// textureDimensions for a level that differs between neighbouring pixels returned another pixel's
// level's size on lavapipe 22.3.6, and loads outside the level read zeros.)
fn level_size(level: i32) -> vec2<i32> {
    let size0 = textureDimensions(tex);
    return vec2<i32>(max(size0 >> vec2<u32>(u32(level)), vec2<u32>(1u)));
}

// Texel (i, j) of `level` in linear RGBA, after address wrapping (or the border colour).
fn fetch(i: i32, j: i32, level: i32) -> vec4<f32> {
    let size = level_size(level);
    let wi = wrap(i, size.x, params.address.x);
    let wj = wrap(j, size.y, params.address.y);
    if wi < 0 || wj < 0 {
        return params.border;
    }
    let t = textureLoad(tex, vec2<i32>(wi, wj), level);
    if params.mode.y == 0u {
        return t;
    }
    // The 8-bit code, exactly: Rgba8Unorm loads b / 255.
    let b = vec3<u32>(round(t.rgb * 255.0));
    return vec4<f32>(srgb[b.x], srgb[b.y], srgb[b.z], t.a);
}

fn size_of(level: i32) -> vec2<f32> {
    return vec2<f32>(level_size(level));
}

// ---- Filters inside one level --------------------------------------------------------------------

// Nearest: the texel containing xy = uv * size; under the lab's formulas xy rounded,
// floor(xy + 1/2).
fn nearest(uv: vec2<f32>, level: i32) -> vec4<f32> {
    let ij = vec2<i32>(floor(uv * size_of(level) + select(0.0, 0.5, CONVENTION == 1u)));
    return fetch(ij.x, ij.y, level);
}

// Bilinear: the 2x2 texels around xy - 1/2, weighted by the fractions; under the lab's formulas
// the texels floor(xy) and floor(xy) + 1 (the handout's ceiling, the same image), weighted by
// fract(xy).
fn bilinear(uv: vec2<f32>, level: i32) -> vec4<f32> {
    let x = uv * size_of(level) - select(0.5, 0.0, CONVENTION == 1u);
    let f = floor(x);
    let ij = vec2<i32>(f);
    let ab = x - f;
    let top = mix(fetch(ij.x, ij.y, level), fetch(ij.x + 1, ij.y, level), ab.x);
    let bottom = mix(fetch(ij.x, ij.y + 1, level), fetch(ij.x + 1, ij.y + 1, level), ab.x);
    return mix(top, bottom, ab.y);
}

// Catmull-Rom weights (Mitchell-Netravali B = 0, C = 1/2) of the four taps around t in [0, 1).
fn catmull_rom(t: f32) -> vec4<f32> {
    let t2 = t * t;
    let t3 = t2 * t;
    return vec4<f32>(
        -0.5 * t3 + t2 - 0.5 * t,
        1.5 * t3 - 2.5 * t2 + 1.0,
        -1.5 * t3 + 2.0 * t2 + 0.5 * t,
        0.5 * t3 - 0.5 * t2,
    );
}

// Bicubic: 4x4 taps around xy - 1/2.
fn bicubic(uv: vec2<f32>, level: i32) -> vec4<f32> {
    let x = uv * size_of(level) - 0.5;
    let f = floor(x);
    let ij = vec2<i32>(f);
    let wx = catmull_rom(x.x - f.x);
    let wy = catmull_rom(x.y - f.y);
    var acc = vec4<f32>(0.0);
    for (var dj = 0; dj < 4; dj++) {
        var row = vec4<f32>(0.0);
        for (var di = 0; di < 4; di++) {
            row += fetch(ij.x + di - 1, ij.y + dj - 1, level) * wx[di];
        }
        acc += row * wy[dj];
    }
    return acc;
}

// ---- Levels --------------------------------------------------------------------------------------

fn last_level() -> f32 {
    return f32(textureNumLevels(tex) - 1u);
}

// lod = log2(rho) + bias, clamped; rho = the longer screen axis in texels of level 0. A rho that
// is not finite (derivatives beyond the horizon of a plane) selects the coarsest allowed level, as
// on the CPU; comparisons with NaN are false, so `rho < FLT_MAX` also rejects NaN.
fn lod_of(rho: f32) -> f32 {
    if !(rho < 3.4e38) {
        return params.lod.z;
    }
    return clamp(log2(rho) + params.lod.x, params.lod.y, params.lod.z);
}

// Vulkan's nearest level: ceil(clamp(lod, 0, q) + 1/2) - 1.
fn mip_nearest(uv: vec2<f32>, lod: f32) -> vec4<f32> {
    let level = max(ceil(clamp(lod, 0.0, last_level()) + 0.5) - 1.0, 0.0);
    return bilinear(uv, i32(level));
}

// Trilinear: bilinear in levels floor(d) and floor(d) + 1, lerped by fract(d), d = clamp(lod, 0, q).
fn trilinear(uv: vec2<f32>, lod: f32) -> vec4<f32> {
    let q = last_level();
    let d = clamp(lod, 0.0, q);
    let k = floor(d);
    let delta = d - k;
    let a = bilinear(uv, i32(k));
    if delta > 0.0 && k < q {
        return mix(a, bilinear(uv, i32(k) + 1), delta);
    }
    return a;
}

// Anisotropic (conventions.md, EXT_texture_filter_anisotropic): N = min(ceil(|Pmax| / |Pmin|), max)
// trilinear probes along the longer axis at lod log2(|Pmax| / N):
// c = 1/N sum_i trilinear(uv + ((i + 0.5) / N - 0.5) Pmax_uv).
fn anisotropic(uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>, px: vec2<f32>, py: vec2<f32>,
               iso_lod: f32) -> vec4<f32> {
    let lx = length(px);
    let ly = length(py);
    let major = max(lx, ly);
    let minor = min(lx, ly);
    let axis = select(duv_dy, duv_dx, lx >= ly);
    if !(major < 3.4e38) {
        // Non-finite axes: one trilinear probe at the isotropic lod (the coarsest allowed).
        return trilinear(uv, iso_lod);
    }
    let max_n = f32(params.mode.z);
    let ratio = major / minor * (1.0 - 1e-5);
    let n = select(clamp(ceil(ratio), 1.0, max_n), max_n, ratio > max_n);
    if n <= 1.0 {
        return trilinear(uv, iso_lod);
    }
    let lod = lod_of(major / n);
    var sum = vec4<f32>(0.0);
    for (var i = 0.0; i < n; i += 1.0) {
        sum += trilinear(uv + ((i + 0.5) / n - 0.5) * axis, lod);
    }
    return sum / n;
}

// ---- The lab's formulas (CONVENTION 1) ------------------------------------------------------------

// A length in texels that is NaN or not below FLT_MAX becomes FLT_MAX, which `lab_lod` maps to
// the coarsest level (the CPU's NaN and infinity).
fn lab_sane(l: f32) -> f32 {
    return select(3.4e38, l, l < 3.4e38);
}

// log2 of a length in texels, unbiased and unclamped: the handout's N = M + log2 |P|; FLT_MAX (a
// footprint beyond the horizon) the coarsest level.
fn lab_lod(len: f32) -> f32 {
    if !(len < 3.4e38) {
        return last_level();
    }
    return log2(len);
}

// Mode 3: bilinear in the coarser level ceil(N), N clamped to [0, q].
fn lab_mip_nearest(uv: vec2<f32>, lod: f32) -> vec4<f32> {
    return bilinear(uv, i32(ceil(clamp(lod, 0.0, last_level()))));
}

// Modes 5-8: lambda = min(|Pmax| / |Pmin|, max), n = ceil(lambda) bilinear-trilinear probes at
// P + (i / (n - 1) - 1/2) Pmax, averaged; the level from |Pmin|, or from |Pmax| / max where the
// ratio exceeds max; one probe (lambda <= 1) is trilinear at P. `lx`, `ly` are the axes' lengths
// in texels (the uv length times the longer side).
fn lab_anisotropic(uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>, lx: f32, ly: f32)
    -> vec4<f32> {
    let x_major = lx >= ly;
    let lmaj = select(ly, lx, x_major);
    let lmin = select(lx, ly, x_major);
    let axis = select(duv_dy, duv_dx, x_major);
    let max_n = f32(params.mode.z);
    let finite = lmaj < 3.4e38 && all(abs(axis) < vec2<f32>(3.4e38));
    let ratio = select(1.0, lmaj / lmin, finite);
    // The count as the CPU's `probe_count`: ceil of the ratio less its rounding tolerance; a
    // ratio that is NaN (0 / 0) one probe.
    let r = lmaj / lmin * (1.0 - 1e-5);
    var n = 1.0;
    if r > max_n {
        n = max_n;
    } else if r >= 1.0 {
        n = clamp(ceil(r), 1.0, max_n);
    }
    let lod = lab_lod(select(lmin, lmaj / max_n, ratio > max_n));
    if n <= 1.0 {
        return trilinear(uv, lod);
    }
    var sum = vec4<f32>(0.0);
    for (var i = 0.0; i < n; i += 1.0) {
        sum += trilinear(uv + (i / (n - 1.0) - 0.5) * axis, lod);
    }
    return sum / n;
}

// Lab mode `mode` (1-8) under the handout's formulas. Magnification (N <= 0) reads level 0 in
// modes 3 and 4; the anisotropic modes probe there as everywhere.
fn lab_mode(mode: u32, uv: vec2<f32>, duv_dx: vec2<f32>, duv_dy: vec2<f32>) -> vec4<f32> {
    let size0 = size_of(0);
    let side = max(size0.x, size0.y);
    let lx = lab_sane(length(duv_dx) * side);
    let ly = lab_sane(length(duv_dy) * side);
    let lod = lab_lod(max(lx, ly));
    if mode == 1u {
        return nearest(uv, 0);
    }
    if mode == 2u || (mode <= 4u && lod <= 0.0) {
        return bilinear(uv, 0);
    }
    if mode == 3u {
        return lab_mip_nearest(uv, lod);
    }
    if mode == 4u {
        return trilinear(uv, lod);
    }
    return lab_anisotropic(uv, duv_dx, duv_dy, lx, ly);
}

// ---- EWA (Heckbert 1989, pbrt-v4's MIPMap::EWA; texel-texture/src/ewa.rs) --------------------

// The filter ellipse of the screen axes px, py (texels of level 0), its minor axis grown so that
// major / minor <= max_ecc: S = M M^T's eigen-decomposition. Returns (s00, s01, s11, minor).
fn ellipse(px: vec2<f32>, py: vec2<f32>, max_ecc: f32) -> vec4<f32> {
    let a = px.x * px.x + py.x * py.x;
    let b = px.x * px.y + py.x * py.y;
    let c = px.y * px.y + py.y * py.y;
    let half = (a - c) * 0.5;
    let l1 = (a + c) * 0.5 + sqrt(half * half + b * b);
    let det_m = px.x * py.y - px.y * py.x;
    let l2 = select(0.0, min(det_m * det_m / l1, l1), l1 > 0.0);
    // The major axis: the eigenvector of l1, from its cancellation-free form.
    let v = select(vec2<f32>(b, l1 - a), vec2<f32>(l1 - c, b), a >= c);
    let len = length(v);
    let e1 = select(vec2<f32>(1.0, 0.0), v / len, len > 0.0 && len < 3.4e38);
    let major = sqrt(l1);
    let minor = max(sqrt(l2), major / max_ecc);
    let q1 = major * major;
    let q2 = minor * minor;
    return vec4<f32>(
        q1 * e1.x * e1.x + q2 * e1.y * e1.y,
        (q1 - q2) * e1.x * e1.y,
        q1 * e1.y * e1.y + q2 * e1.x * e1.x,
        minor,
    );
}

const MAX_ELLIPSE_AREA: f32 = 4096.0;
const PI: f32 = 3.14159265;

// The area in texels, pi sqrt(det Q), of an ellipse (q00, q01, q11, det Q).
fn ellipse_area(q: vec4<f32>) -> f32 {
    return PI * sqrt(max(q.w, 0.0));
}

// The CPU's ewa::KERNEL_SCALE, set by the pipeline: the weights' covariance is
// (D (S + I) D + I) / 12, the pixel box's carried through the Jacobian plus level 0's bilinear
// tent and the level's own spread.
override KERNEL_SCALE: f32;

// The kernel's ellipse in level `level`: Q = KERNEL_SCALE (D (S + I) D + I), D = diag(level size
// / level-0 size); shrunk to MAX_ELLIPSE_AREA texels when `shrink`. Returns (q00, q01, q11, det Q).
fn in_level(s: vec4<f32>, level: i32, shrink: bool) -> vec4<f32> {
    let d = size_of(level) / size_of(0);
    var q = KERNEL_SCALE * vec3<f32>(
        d.x * d.x * (s.x + 1.0) + 1.0,
        d.x * d.y * s.y,
        d.y * d.y * (s.z + 1.0) + 1.0,
    );
    var det = q.x * q.z - q.y * q.y;
    let area = ellipse_area(vec4<f32>(q, det));
    if shrink && area > MAX_ELLIPSE_AREA {
        let f = MAX_ELLIPSE_AREA / area;
        q *= f;
        det *= f * f;
    }
    return vec4<f32>(q, det);
}

// EWA in one level: sum(w T) / sum(w) over the texel centres with
// r^2 = (q11 dx^2 - 2 q01 dx dy + q00 dy^2) / det < 1, w = LUT[floor(r^2 * 128)], scanning the
// ellipse's bounding box (half-extents sqrt(q00), sqrt(q11)); bilinear if no centre is inside.
fn ewa_level(uv: vec2<f32>, level: i32, q: vec4<f32>) -> vec4<f32> {
    let xy = uv * size_of(level);
    let lo = vec2<i32>(ceil(xy - 0.5 - sqrt(vec2<f32>(q.x, q.z))));
    let hi = vec2<i32>(floor(xy - 0.5 + sqrt(vec2<f32>(q.x, q.z))));
    var sum = vec4<f32>(0.0);
    var wsum = 0.0;
    var visits = 0;
    for (var j = lo.y; j <= hi.y && visits < 16384; j++) {
        let dy = f32(j) + 0.5 - xy.y;
        for (var i = lo.x; i <= hi.x && visits < 16384; i++) {
            visits++;
            let dx = f32(i) + 0.5 - xy.x;
            let r2 = (q.z * dx * dx - 2.0 * q.y * dx * dy + q.x * dy * dy) / q.w;
            if r2 < 1.0 {
                let w = ewa_lut[clamp(i32(r2 * 128.0), 0, 127)];
                sum += fetch(i, j, level) * w;
                wsum += w;
            }
        }
    }
    if wsum > 0.0 {
        return sum / wsum;
    }
    return bilinear(uv, level);
}

// EWA at level k, moving to coarser levels while the ellipse covers more than MAX_ELLIPSE_AREA.
fn ewa_at(uv: vec2<f32>, s: vec4<f32>, k0: i32) -> vec4<f32> {
    let last = i32(last_level());
    var k = min(k0, last);
    var q = in_level(s, k, false);
    loop {
        if k >= last || ellipse_area(q) <= MAX_ELLIPSE_AREA {
            break;
        }
        k++;
        q = in_level(s, k, false);
    }
    // A 1x1 level is its one texel under every address mode but clamp-to-border.
    if all(level_size(k) == vec2<i32>(1)) && params.address.x != 3u && params.address.y != 3u {
        return fetch(0, 0, k);
    }
    // Only the last level's ellipse can still exceed the area; it is shrunk to it.
    if ellipse_area(q) > MAX_ELLIPSE_AREA {
        q = in_level(s, k, true);
    }
    return ewa_level(uv, k, q);
}

// EWA in the one level floor(lod), lod = log2(minor semi-axis) + bias: there the minor semi-axis
// spans 1 to 2 texels.
fn ewa(uv: vec2<f32>, px: vec2<f32>, py: vec2<f32>, iso_lod: f32) -> vec4<f32> {
    if !(all(abs(px) < vec2<f32>(3.4e38)) && all(abs(py) < vec2<f32>(3.4e38))) {
        return trilinear(uv, iso_lod);
    }
    let s = ellipse(px, py, f32(params.mode.z));
    let d = clamp(lod_of(s.w), 0.0, last_level());
    return ewa_at(uv, s, i32(floor(d)));
}

// ---- EWA from trilinear probes (texel_texture::technique::ewa_probes) -----------------------------

const PROBES_MAX: i32 = 16;
const PROBES_SPACING: f32 = 3.0;
const PROBES_LOD_OFFSET: f32 = 0.25;
const PROBES_ONE: f32 = 0.1;

// The lod whose trilinear sample has per-axis variance `v` (level-0 texels^2): level k where
// v_k = (3 4^k - 1) / 12 <= v < v_(k+1), plus the share of the way to v_(k+1); 0 up to 1/6.
fn lod_of_variance(v: f32) -> f32 {
    if !(v > 1.0 / 6.0) {
        return 0.0;
    }
    let k = max(floor(log2((12.0 * v + 1.0) / 3.0) * 0.5), 0.0);
    let p = exp2(2.0 * k);
    return k + clamp((v - (3.0 * p - 1.0) / 12.0) / (0.75 * p), 0.0, 1.0);
}

// The reference's covariance C = (S + 2 I) / 12 from N Gaussian-weighted trilinear probes along
// the ellipse's major axis: one probe's variance is the minor eigenvalue (its lod a quarter
// level coarser), the probes' positions carry the rest of the major one.
fn ewa_probes(uv: vec2<f32>, px: vec2<f32>, py: vec2<f32>, iso_lod: f32) -> vec4<f32> {
    if !(all(abs(px) < vec2<f32>(3.4e38)) && all(abs(py) < vec2<f32>(3.4e38))) {
        return trilinear(uv, iso_lod);
    }
    let s = ellipse(px, py, f32(params.mode.z));
    let half = (s.x - s.z) * 0.5;
    let r1 = (s.x + s.z) * 0.5 + sqrt(half * half + s.y * s.y);
    let v = select(vec2<f32>(s.y, r1 - s.x), vec2<f32>(r1 - s.z, s.y), s.x >= s.z);
    let len = length(v);
    let e1 = select(vec2<f32>(1.0, 0.0), v / len, len > 0.0 && len < 3.4e38);
    let l1 = (r1 + 2.0) / 12.0;
    let l2 = (s.w * s.w + 2.0) / 12.0;
    var n = 1;
    var var_p = l2;
    if l1 > (1.0 + PROBES_ONE) * l2 {
        let rs = sqrt(l1 - l2);
        n = 2;
        loop {
            if n >= PROBES_MAX || ewa_lut[640 + n - 1] * rs <= PROBES_SPACING * sqrt(l2) {
                break;
            }
            n++;
        }
        if ewa_lut[640 + n - 1] * rs > PROBES_SPACING * sqrt(l2) {
            let g2 = ewa_lut[640 + PROBES_MAX - 1] * ewa_lut[640 + PROBES_MAX - 1];
            var_p = max(g2 * l1 / (PROBES_SPACING * PROBES_SPACING + g2), l2);
        }
    }
    let lod = clamp(lod_of_variance(var_p) + PROBES_LOD_OFFSET + params.lod.x, params.lod.y,
                    params.lod.z);
    if n == 1 {
        return trilinear(uv, lod);
    }
    let axis = e1 * sqrt(max(l1 - var_p, 0.0)) / size_of(0);
    var sum = vec4<f32>(0.0);
    for (var i = 0; i < n; i++) {
        let t = ewa_lut[128 + 16 * (n - 1) + i];
        sum += trilinear(uv + t * axis, lod) * ewa_lut[384 + 16 * (n - 1) + i];
    }
    return sum;
}

// ---- The fragment shader -------------------------------------------------------------------------

// Both targets hold f32 bit patterns in unsigned-integer formats (`Rgba32Uint`, `R32Uint`): every
// device renders to those, where `Rgba32Float` and `R32Float` are not renderable on some (GL, and
// GLES without EXT_color_buffer_float), and the bits read back are the shader's f32 values exactly.
struct FragmentOut {
    // The colour's f32 bits.
    @location(0) color: vec4<u32>,
    // The f32 bits of the fragment's NDC depth in the CPU's convention (OpenGL's z / w in [-1, 1]);
    // the target is cleared to +inf's bits, so coverage is implied by depth, as in the CPU's frame.
    @location(1) depth: u32,
}

@fragment
fn fs_main(in: VertexOut) -> FragmentOut {
    // Derivatives first, in uniform control flow (2x2 quad differences, as the CPU's quad mode).
    let duv_dx = dpdxFine(in.uv);
    let duv_dy = dpdyFine(in.uv);
    let size0 = size_of(0);
    let px = duv_dx * size0;
    let py = duv_dy * size0;
    let lod = lod_of(max(length(px), length(py)));
    let mode = MODE;
    var c: vec4<f32>;
    if CONVENTION == 1u && mode <= 8u {
        c = lab_mode(mode, in.uv, duv_dx, duv_dy);
    } else if mode >= 20u {
        // The device's own sampler (the hardware rows): sRGB is decoded by the texture format.
        c = textureSampleGrad(tex, hw, in.uv, duv_dx, duv_dy);
    } else if mode == 1u {
        c = nearest(in.uv, 0);
    } else if mode == 9u {
        c = bicubic(in.uv, 0);
    } else if mode == 10u && lod > 0.0 {
        c = ewa(in.uv, px, py, lod);
    } else if mode == 11u && lod > 0.0 {
        c = ewa_probes(in.uv, px, py, lod);
    } else if mode == 2u || lod <= 0.0 {
        // Bilinear without mips, and magnification for modes 3-8 (their mag filter is linear).
        c = bilinear(in.uv, 0);
    } else if mode == 3u {
        c = mip_nearest(in.uv, lod);
    } else if mode == 4u {
        c = trilinear(in.uv, lod);
    } else {
        c = anisotropic(in.uv, duv_dx, duv_dy, px, py, lod);
    }
    var out: FragmentOut;
    out.color = bitcast<vec4<u32>>(c * in.color);
    out.depth = bitcast<u32>(2.0 * in.clip.z - 1.0);
    return out;
}
