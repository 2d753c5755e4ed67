//! A texture's whole pyramid as the filters see it: the [`Pyramid`] trait over the levels'
//! [`Fetch`] views, its stored form ([`Stored`]) for each format, the [`Counted`] wrapper that
//! counts every texel read, and [`with_pyramid`], which picks the view for a texture's format.

use std::cell::Cell;

use glam::Vec4;

use crate::storage::fetch::{table8, Codes8, Decode, Fetch, Float, Level, Table8, Unorm8};
use crate::storage::format::{Format, LevelInfo, Storage};
use crate::storage::lanes::Lanes;
use crate::storage::texture::Texture;

/// All mip levels of a texture.
pub(crate) trait Pyramid {
    /// One level's view.
    type Level<'a>: Fetch
    where
        Self: 'a;
    /// Number of levels (at least 1).
    fn level_count(&self) -> usize;
    /// Level `k < level_count()`.
    fn level(&self, k: usize) -> Self::Level<'_>;
    /// The texture these levels belong to (for its lazily built ripmap and summed-area table).
    fn texture(&self) -> &Texture;
    /// A view of another image stored in the same format as these levels (a ripmap image), decoded
    /// and counted exactly as the levels are. `info` locates the image inside `storage`.
    ///
    /// A storage of the other format (impossible for structures built from this texture) gives a
    /// 1x1 transparent-black view instead of a panic.
    fn image<'s>(&'s self, info: &LevelInfo, storage: &'s Storage) -> Self::Level<'s>;
    /// Record `n` reads of a structure that is not made of texels (summed-area table entries).
    /// Free for the plain views; [`Counted`] adds `n` to its counter.
    #[inline(always)]
    fn note_reads(&self, _n: u32) {}
}

/// The pyramid of a texture whose storage `D` decodes.
pub(crate) struct Stored<'a, D: Decode> {
    pub tex: &'a Texture,
    pub levels: &'a [LevelInfo],
    pub texels: &'a [D::Texel],
    pub decode: D,
}

fn level_slice<'t, T>(info: &LevelInfo, all: &'t [T]) -> &'t [T] {
    &all[info.offset..info.offset + info.width as usize * info.height as usize]
}

impl<D: Decode> Pyramid for Stored<'_, D> {
    type Level<'b>
        = Level<'b, D>
    where
        Self: 'b;
    #[inline(always)]
    fn level_count(&self) -> usize {
        self.levels.len()
    }
    #[inline(always)]
    fn level(&self, k: usize) -> Level<'_, D> {
        let info = &self.levels[k];
        Level {
            width: info.width,
            height: info.height,
            texels: level_slice(info, self.texels),
            decode: self.decode,
        }
    }
    #[inline(always)]
    fn texture(&self) -> &Texture {
        self.tex
    }
    #[inline]
    fn image<'s>(&'s self, info: &LevelInfo, storage: &'s Storage) -> Level<'s, D> {
        let (width, height, texels) = match D::texels(storage) {
            Some(v) => (info.width, info.height, level_slice(info, v)),
            None => (1, 1, D::BLACK),
        };
        Level {
            width,
            height,
            texels,
            decode: self.decode,
        }
    }
}

/// A pyramid view that counts texel reads.
pub(crate) struct Counted<P> {
    pub inner: P,
    pub count: Cell<u32>,
}

/// A level view that counts texel reads into its pyramid's counter.
#[derive(Clone, Copy)]
pub(crate) struct CountedLevel<'a, L> {
    inner: L,
    count: &'a Cell<u32>,
}

impl<L: Fetch> Fetch for CountedLevel<'_, L> {
    #[inline(always)]
    fn size(&self) -> (u32, u32) {
        self.inner.size()
    }
    #[inline(always)]
    fn texel(&self, i: u32, j: u32) -> Vec4 {
        self.count.set(self.count.get().saturating_add(1));
        self.inner.texel(i, j)
    }
    #[inline(always)]
    fn quad(&self, i: u32, j: u32) -> [Vec4; 4] {
        self.count.set(self.count.get().saturating_add(4));
        self.inner.quad(i, j)
    }
}

impl<P: Pyramid> Pyramid for Counted<P> {
    type Level<'b>
        = CountedLevel<'b, P::Level<'b>>
    where
        Self: 'b;
    fn level_count(&self) -> usize {
        self.inner.level_count()
    }
    fn level(&self, k: usize) -> Self::Level<'_> {
        CountedLevel {
            inner: self.inner.level(k),
            count: &self.count,
        }
    }
    fn texture(&self) -> &Texture {
        self.inner.texture()
    }
    fn image<'s>(&'s self, info: &LevelInfo, storage: &'s Storage) -> Self::Level<'s> {
        CountedLevel {
            inner: self.inner.image(info, storage),
            count: &self.count,
        }
    }
    fn note_reads(&self, n: u32) {
        self.count.set(self.count.get().saturating_add(n));
    }
}

/// Call `$body` with `$p` bound to the texture's pyramid view (8-bit or float), monomorphising once
/// per storage format; with `$lanes`, the linear 8-bit view blends bilinear quads with that
/// kernel ([`crate::storage::lanes`]), else with the scalar one.
macro_rules! with_pyramid {
    ($tex:expr, |$p:ident| $body:expr) => {
        $crate::storage::view::with_pyramid!($tex, $crate::storage::lanes::Lanes::scalar(), |$p| {
            $body
        })
    };
    ($tex:expr, $lanes:expr, |$p:ident| $body:expr) => {
        match $crate::storage::view::pyramid_with($tex, $lanes) {
            $crate::storage::view::AnyPyramid::U8($p) => $body,
            $crate::storage::view::AnyPyramid::Unorm8($p) => $body,
            $crate::storage::view::AnyPyramid::F32($p) => $body,
        }
    };
}
pub(crate) use with_pyramid;

pub(crate) enum AnyPyramid<'a> {
    /// 8-bit sRGB texels.
    U8(Stored<'a, Table8>),
    /// 8-bit linear texels.
    Unorm8(Stored<'a, Unorm8>),
    F32(Stored<'a, Float>),
}

/// The pyramid of an 8-bit texture read as stored codes ([`Codes8`], blending with the scalar
/// kernel); `None` for float storage.
pub(crate) fn codes_of(tex: &Texture) -> Option<Stored<'_, Codes8>> {
    Some(Stored {
        tex,
        levels: tex.levels(),
        texels: Codes8::texels(tex.storage())?,
        decode: Codes8::default(),
    })
}

/// The texture's pyramid view (8-bit sRGB, linear 8-bit or float), whose linear 8-bit view
/// blends bilinear quads with `lanes`' kernel.
pub(crate) fn pyramid_with(tex: &Texture, lanes: Lanes) -> AnyPyramid<'_> {
    match tex.storage() {
        Storage::U8(v) if tex.format() == Format::Rgba8Unorm => AnyPyramid::Unorm8(Stored {
            tex,
            levels: tex.levels(),
            texels: v,
            decode: Unorm8 { lanes },
        }),
        Storage::U8(v) => AnyPyramid::U8(Stored {
            tex,
            levels: tex.levels(),
            texels: v,
            decode: table8(tex.format()),
        }),
        Storage::F32(v) => AnyPyramid::F32(Stored {
            tex,
            levels: tex.levels(),
            texels: v,
            decode: Float,
        }),
    }
}
