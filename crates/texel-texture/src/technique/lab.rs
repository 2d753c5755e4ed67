//! The lab's eight modes under either convention, with every rule a knob ([`Rules`]).
//!
//! texel's samplers follow the OpenGL / Vulkan rules ([`Rules::GL`]: texel centres at `+0.5`,
//! `floor` for nearest, the nearest level by `ceil(lod + 0.5) - 1`, probes at
//! `((i + 0.5) / N - 0.5) Pmax`). The texture-filtering lab's handout states its own formulas
//! ([`Rules::LAB`], docs/guide/conventions.md, "The lab's formulas"): with `P` the coordinate in
//! uv units, `x = ||tau||.x P.x` and `y = ||tau||.y P.y` in texels of a level,
//!
//! - nearest: `(round(x), round(y))`;
//! - bilinear: `u0 = floor(x)`, `u1 = ceil(x)`, `du = x - u0` (and `v` alike), the usual two lerps;
//! - the level: `M = log2(max(||tau0||))`, `N = min(M, M + log2(max(|Px|, |Py|)))` with `Px`, `Py`
//!   the screen derivatives of `P`; mode 3 reads the coarser level `ceil(N)`, mode 4 blends
//!   `floor(N)` and `ceil(N)` by `N - floor(N)`; `N < 0` (magnification) reads level 0;
//! - anisotropic: `lambda = min(|Pmax| / |Pmin|, lambda_max)`, `ceil(lambda)` bilinear probes at
//!   `P + (i / (n - 1) - 1/2) Pmax`, averaged, blended between two levels as trilinear is, the level
//!   from `|Pmin|`, or from `|Pmax| / lambda_max` when the ratio exceeds `lambda_max`. One probe
//!   (`lambda <= 1`, where `i / (n - 1)` is `0 / 0`) is the trilinear sample at `P`.
//!
//! The evaluator ([`Texture::sample_rules`]) reads the levels texel by texel (no staged
//! kernels): it is the lab convention's route ([`crate::Sampler::with_convention`]) and the
//! grader's oracle for a student's shader and for its likely mistakes (each a [`Rules`] one knob
//! away from a convention). Under [`Rules::GL`] it equals the sampler's own modes (tested).

use glam::{Vec2, Vec4};

use crate::base::address::Address;
use crate::base::footprint::Footprint;
use crate::storage::fetch::Fetch;
use crate::storage::texture::Texture;
use crate::storage::view::{with_pyramid, Counted, Pyramid};

/// Which rules texel's lab modes 1-8 follow.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Convention {
    /// The OpenGL / Vulkan rules (the default).
    #[default]
    Gl,
    /// The lab handout's formulas, literally.
    Lab,
}

impl Convention {
    /// Both conventions, the default first.
    pub const ALL: [Convention; 2] = [Convention::Gl, Convention::Lab];

    /// `gl` or `lab`.
    pub fn name(self) -> &'static str {
        match self {
            Convention::Gl => "gl",
            Convention::Lab => "lab",
        }
    }

    /// The rules of this convention.
    pub fn rules(self) -> Rules {
        match self {
            Convention::Gl => Rules::GL,
            Convention::Lab => Rules::LAB,
        }
    }
}

impl std::fmt::Display for Convention {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Convention {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "gl" => Ok(Convention::Gl),
            "lab" => Ok(Convention::Lab),
            _ => Err(format!("unknown convention {s:?}: use gl or lab")),
        }
    }
}

/// How a footprint's length becomes a level of detail.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Each axis in texels of level 0, `(W du, H dv)` (OpenGL's `rho`).
    PerAxis,
    /// The uv length times the longer side, `max(W, H) |P|` (the lab's `M + log2 |P|`).
    LongerSide,
}

/// Which derivative sets the isotropic level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LevelAxis {
    /// The longer of `Px`, `Py` (both conventions).
    Longer,
    /// The shorter (a mistake: aliasing where the footprint is anisotropic).
    Shorter,
}

/// The level mode 3 reads for a level of detail `d >= 0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NearestLevel {
    /// The nearest, `ceil(d + 0.5) - 1` (Vulkan).
    Round,
    /// The coarser, `ceil(d)` (the lab).
    Coarser,
    /// The finer, `floor(d)`.
    Finer,
}

/// The probe count from the anisotropy ratio `lambda` (already clamped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Count {
    /// `ceil(lambda)` (both conventions).
    Ceil,
    /// `round(lambda)`.
    Round,
    /// `floor(lambda)`.
    Floor,
}

/// Where probe `i` of `n` lies along `Pmax`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// `(i + 0.5) / n - 0.5` (the `EXT_texture_filter_anisotropic` rule).
    Centred,
    /// `i / (n - 1) - 0.5`, the ends of the footprint included (the lab).
    Ends,
}

/// The level the anisotropic probes read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnisoLevel {
    /// `log2(|Pmax| / n)` (GL).
    MajorOverCount,
    /// `log2(|Pmin|)`, or `log2(|Pmax| / lambda_max)` past the clamp (the lab).
    Minor,
    /// `log2(|Pmax|)` (a mistake: as blurry as trilinear).
    Major,
}

/// How an integer texel index outside the level is brought back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// The sampler's address modes.
    Address,
    /// `i % n` with the remainder keeping the sign of a negative `i` (GLSL leaves `%` of a
    /// negative operand undefined; C and many drivers truncate): the fetch is out of range and
    /// reads zero.
    Truncated,
    /// Not wrapped at all: every index outside the level reads zero (`texelFetch` out of range).
    None,
}

/// Every rule of the eight modes that a convention fixes and a student may get wrong.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rules {
    /// Nearest reads texel `floor(x + nearest_offset)`: 0 (GL), 0.5 (the lab's rounding).
    pub nearest_offset: f32,
    /// Bilinear's first tap is `floor(x - bilinear_offset)`: 0.5 (GL), 0 (the lab).
    pub bilinear_offset: f32,
    /// Bilinear's weight is `fract(x - weight_offset)`; equal to `bilinear_offset` when right.
    pub weight_offset: f32,
    /// Texel-space length of the footprint.
    pub scale: Scale,
    /// The derivative the isotropic level comes from.
    pub level_axis: LevelAxis,
    /// Mode 3's level.
    pub nearest_level: NearestLevel,
    /// Trilinear blends toward the finer level by the fraction (the weights swapped).
    pub blend_reversed: bool,
    /// The level of detail is clamped to `[0, last]`; without it, levels outside read zero.
    pub clamp_level: bool,
    /// Magnification (`lod <= 0` on the isotropic level) reads level 0 with one bilinear (or
    /// nearest) sample in every mode (GL); otherwise the anisotropic modes probe level 0 too.
    pub magnify_plain: bool,
    /// The probe count.
    pub count: Count,
    /// The probes' positions.
    pub spacing: Spacing,
    /// The probes span `span * Pmax`: 1 when right.
    pub span: f32,
    /// The probes' level.
    pub aniso_level: AnisoLevel,
    /// Index wrapping.
    pub wrap: Wrap,
}

impl Rules {
    /// The OpenGL / Vulkan rules texel's samplers follow.
    pub const GL: Rules = Rules {
        nearest_offset: 0.0,
        bilinear_offset: 0.5,
        weight_offset: 0.5,
        scale: Scale::PerAxis,
        level_axis: LevelAxis::Longer,
        nearest_level: NearestLevel::Round,
        blend_reversed: false,
        clamp_level: true,
        magnify_plain: true,
        count: Count::Ceil,
        spacing: Spacing::Centred,
        span: 1.0,
        aniso_level: AnisoLevel::MajorOverCount,
        wrap: Wrap::Address,
    };

    /// The lab handout's formulas (module docs).
    pub const LAB: Rules = Rules {
        nearest_offset: 0.5,
        bilinear_offset: 0.0,
        weight_offset: 0.0,
        scale: Scale::LongerSide,
        level_axis: LevelAxis::Longer,
        nearest_level: NearestLevel::Coarser,
        blend_reversed: false,
        clamp_level: true,
        magnify_plain: false,
        count: Count::Ceil,
        spacing: Spacing::Ends,
        span: 1.0,
        aniso_level: AnisoLevel::Minor,
        wrap: Wrap::Address,
    };
}

/// The largest anisotropy of lab mode `mode` (1 for modes 1-4).
pub fn max_anisotropy(mode: u8) -> f32 {
    match mode {
        5 => 2.0,
        6 => 4.0,
        7 => 8.0,
        8 => 16.0,
        _ => 1.0,
    }
}

/// A level's texel coordinate of normalised `t` on an `n`-texel axis.
#[inline]
fn texel(t: f32, n: u32) -> f32 {
    t * n as f32
}

struct Eval<'a, P> {
    p: &'a P,
    addr: &'a Address,
    rules: &'a Rules,
}

impl<P: Pyramid> Eval<'_, P> {
    fn index(&self, i: i64, n: u32, u_axis: bool) -> Option<u32> {
        match self.rules.wrap {
            Wrap::Address => {
                let mode = if u_axis { self.addr.u } else { self.addr.v };
                mode.wrap(i, n)
            }
            Wrap::Truncated => {
                let r = i % i64::from(n);
                (r >= 0).then_some(r as u32)
            }
            Wrap::None => (0..i64::from(n)).contains(&i).then_some(i as u32),
        }
    }

    fn read(&self, level: &P::Level<'_>, i: i64, j: i64) -> Vec4 {
        let (w, h) = level.size();
        let (iu, jv) = (self.index(i, w, true), self.index(j, h, false));
        match (iu, jv) {
            (Some(i), Some(j)) => level.texel(i, j),
            _ if self.rules.wrap != Wrap::Address => Vec4::ZERO,
            _ => self.addr.border,
        }
    }

    /// A level by signed index: outside `[0, last]` (only without `clamp_level`) it reads zero.
    fn level_or_zero(&self, k: i64, f: impl Fn(&P::Level<'_>) -> Vec4) -> Vec4 {
        let last = self.p.level_count() as i64 - 1;
        if (0..=last).contains(&k) {
            f(&self.p.level(k as usize))
        } else {
            Vec4::ZERO
        }
    }

    fn nearest(&self, level: &P::Level<'_>, uv: Vec2) -> Vec4 {
        let (w, h) = level.size();
        let o = self.rules.nearest_offset;
        let i = (texel(uv.x, w) + o).floor() as i64;
        let j = (texel(uv.y, h) + o).floor() as i64;
        self.read(level, i, j)
    }

    fn bilinear(&self, level: &P::Level<'_>, uv: Vec2) -> Vec4 {
        let (w, h) = level.size();
        let (x, y) = (texel(uv.x, w), texel(uv.y, h));
        let (o, wo) = (self.rules.bilinear_offset, self.rules.weight_offset);
        let (i0, j0) = ((x - o).floor() as i64, (y - o).floor() as i64);
        let a = (x - wo) - (x - wo).floor();
        let b = (y - wo) - (y - wo).floor();
        let t00 = self.read(level, i0, j0);
        let t10 = self.read(level, i0.saturating_add(1), j0);
        let t01 = self.read(level, i0, j0.saturating_add(1));
        let t11 = self.read(level, i0.saturating_add(1), j0.saturating_add(1));
        let top = t00 + (t10 - t00) * a;
        let bottom = t01 + (t11 - t01) * a;
        top + (bottom - top) * b
    }

    fn last(&self) -> f32 {
        (self.p.level_count() - 1) as f32
    }

    /// The texel-space length of a uv step on level 0.
    fn length(&self, d: Vec2) -> f32 {
        let (w, h) = self.p.level(0).size();
        match self.rules.scale {
            Scale::PerAxis => Vec2::new(d.x * w as f32, d.y * h as f32).length(),
            Scale::LongerSide => d.length() * w.max(h) as f32,
        }
    }

    /// `log2(len)` with non-finite lengths the coarsest level.
    fn lod(&self, len: f32) -> f32 {
        if len.is_nan() || len == f32::INFINITY {
            return self.last();
        }
        len.log2()
    }

    /// The level pair and weight of a trilinear blend at `lod`, or `None` where the level is
    /// below 0 and magnification reads level 0.
    fn blend_levels(&self, lod: f32) -> (i64, i64, f32) {
        let d = if self.rules.clamp_level {
            lod.clamp(0.0, self.last())
        } else {
            lod.min(self.last())
        };
        let lo = d.floor();
        let t = d - lo;
        let t = if self.rules.blend_reversed {
            1.0 - t
        } else {
            t
        };
        (lo as i64, d.ceil() as i64, t)
    }

    fn trilinear(&self, uv: Vec2, lod: f32) -> Vec4 {
        let (lo, hi, t) = self.blend_levels(lod);
        let a = self.level_or_zero(lo, |l| self.bilinear(l, uv));
        if hi == lo || t == 0.0 && !self.rules.blend_reversed {
            return a;
        }
        let b = self.level_or_zero(hi, |l| self.bilinear(l, uv));
        a + (b - a) * t
    }

    fn mip_nearest(&self, uv: Vec2, lod: f32) -> Vec4 {
        let d = if self.rules.clamp_level {
            lod.clamp(0.0, self.last())
        } else {
            lod.min(self.last())
        };
        let k = match self.rules.nearest_level {
            NearestLevel::Round => {
                if self.rules.clamp_level {
                    crate::technique::mip::nearest_level(d, self.p.level_count() - 1) as i64
                } else {
                    ((d + 0.5).ceil() - 1.0) as i64
                }
            }
            NearestLevel::Coarser => d.ceil() as i64,
            NearestLevel::Finer => d.floor() as i64,
        };
        self.level_or_zero(k, |l| self.bilinear(l, uv))
    }

    fn sample(&self, mode: u8, fp: &Footprint) -> Vec4 {
        let uv = Vec2::new(fp.u, fp.v);
        let px = Vec2::new(fp.dudx, fp.dvdx);
        let py = Vec2::new(fp.dudy, fp.dvdy);
        let (lx, ly) = (self.length(px), self.length(py));
        let sane = |l: f32| if l.is_nan() { f32::INFINITY } else { l };
        let (lx, ly) = (sane(lx), sane(ly));
        let iso = match self.rules.level_axis {
            LevelAxis::Longer => lx.max(ly),
            LevelAxis::Shorter => lx.min(ly),
        };
        let lod = self.lod(iso);
        let magnified = lod <= 0.0;
        match mode {
            1 => self.nearest(&self.p.level(0), uv),
            2 => self.bilinear(&self.p.level(0), uv),
            3 if magnified && self.rules.clamp_level => self.bilinear(&self.p.level(0), uv),
            3 => self.mip_nearest(uv, lod),
            4 if magnified && self.rules.clamp_level => self.bilinear(&self.p.level(0), uv),
            4 => self.trilinear(uv, lod),
            _ if magnified && self.rules.magnify_plain => self.bilinear(&self.p.level(0), uv),
            _ => self.anisotropic(mode, uv, (px, lx), (py, ly)),
        }
    }

    fn anisotropic(&self, mode: u8, uv: Vec2, x: (Vec2, f32), y: (Vec2, f32)) -> Vec4 {
        let ((major, lmaj), (_, lmin)) = if x.1 >= y.1 { (x, y) } else { (y, x) };
        let max = max_anisotropy(mode);
        let finite = lmaj.is_finite() && major.is_finite();
        let ratio = if finite { lmaj / lmin } else { 1.0 };
        let lambda = if ratio.is_nan() { max } else { ratio.min(max) };
        let n = match self.rules.count {
            // The sampler's own count (`ceil` with its tolerance for rounding in the ratio).
            Count::Ceil => crate::technique::aniso::probe_count(lmaj, lmin, max as u32) as f32,
            Count::Round => lambda.round(),
            Count::Floor => lambda.floor(),
        }
        .clamp(1.0, max) as u32;
        let len = match self.rules.aniso_level {
            AnisoLevel::MajorOverCount => lmaj / n as f32,
            AnisoLevel::Minor if ratio > max => lmaj / max,
            AnisoLevel::Minor => lmin,
            AnisoLevel::Major => lmaj,
        };
        let lod = self.lod(len);
        if n == 1 {
            return self.trilinear(uv, lod);
        }
        let step = major * self.rules.span;
        let mut sum = Vec4::ZERO;
        for i in 0..n {
            let t = match self.rules.spacing {
                Spacing::Centred => (i as f32 + 0.5) / n as f32 - 0.5,
                Spacing::Ends => i as f32 / (n - 1) as f32 - 0.5,
            };
            sum += self.trilinear(uv + step * t, lod);
        }
        sum / n as f32
    }
}

/// Lab mode `mode` (1-8) of `footprint` under `rules`, reading `p`'s levels through `addr`.
pub(crate) fn sample_rules<P: Pyramid>(
    p: &P,
    addr: &Address,
    mode: u8,
    rules: &Rules,
    footprint: &Footprint,
) -> Vec4 {
    Eval { p, addr, rules }.sample(mode, footprint)
}

impl Texture {
    /// Lab mode `mode` (1-8) of `footprint` under `rules` and `address` (the evaluator of
    /// [`crate::technique::lab`]), with the texels it read. Non-finite `u`, `v` sample at 0.
    pub fn sample_rules(
        &self,
        address: &Address,
        mode: u8,
        rules: &Rules,
        footprint: &Footprint,
    ) -> ([f32; 4], u32) {
        let fp = Footprint {
            u: crate::base::footprint::finite_uv(footprint.u),
            v: crate::base::footprint::finite_uv(footprint.v),
            ..*footprint
        };
        with_pyramid!(self, |p| {
            let counted = Counted {
                inner: p,
                count: std::cell::Cell::new(0),
            };
            let c = sample_rules(&counted, address, mode, rules, &fp);
            (c.to_array(), counted.count.get())
        })
    }
}
