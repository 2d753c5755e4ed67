//! Batches of footprints for the batched sampler ([`crate::Sampler::sample_batch`] and its
//! siblings): a slice of [`Footprint`] structs, or [`FootprintLanes`], one slice per field.
//!
//! Why lanes. The batched sampler works on lanes (one array per field, so that its stages
//! vectorise), and a rasterizer computes its footprints in lanes too. Handing structs across
//! means interleaving six fields into 24-byte structs on one side and copying them back out on
//! the other, a large share of a bilinear frame's instructions outside the filter itself
//! (docs/decisions.md). A renderer that has lanes passes them as they are; the structs
//! remain for everyone else. Both give the same bits.
//!
//! Inside the crate each kind is a [`Source`]: the sampler's kernels are compiled once per kind,
//! not once per caller's type (`&Vec<Footprint>` and `&[Footprint; N]` are slices here).

use crate::base::footprint::Footprint;

/// Footprints as lanes: `u[k]`, `v[k]` and, where given, the derivatives `dudx[k]`, `dudy[k]`,
/// `dvdx[k]`, `dvdy[k]` of footprint `k` (the fields of [`Footprint`], same units). Without
/// derivatives every footprint's are zero, as [`Footprint::point`]'s: level 0 for samplers that
/// use derivatives, and no difference for those that do not
/// ([`crate::Sampler::uses_derivatives`]), which is what a renderer that skips them needs.
/// `Copy`: it borrows the slices.
#[derive(Clone, Copy, Debug)]
pub struct FootprintLanes<'a> {
    u: &'a [f32],
    v: &'a [f32],
    /// `[dudx, dudy, dvdx, dvdy]`, each as long as `u`.
    derivatives: Option<[&'a [f32]; 4]>,
}

impl<'a> FootprintLanes<'a> {
    /// Footprints at `(u[k], v[k])` with zero derivatives.
    ///
    /// # Panics
    /// If `u` and `v` differ in length (a programming error, not bad input).
    pub fn points(u: &'a [f32], v: &'a [f32]) -> Self {
        assert_eq!(u.len(), v.len(), "FootprintLanes: u and v differ in length");
        FootprintLanes {
            u,
            v,
            derivatives: None,
        }
    }

    /// Footprints with their derivatives: footprint `k` is `u[k]`, `v[k]`, and `d[0][k]`,
    /// `d[1][k]`, `d[2][k]`, `d[3][k]` as its `dudx`, `dudy`, `dvdx`, `dvdy` (the order of
    /// [`Footprint`]'s fields).
    ///
    /// # Panics
    /// If any slice's length differs from `u`'s (a programming error, not bad input).
    pub fn new(u: &'a [f32], v: &'a [f32], d: [&'a [f32]; 4]) -> Self {
        let n = u.len();
        assert!(
            v.len() == n && d.iter().all(|d| d.len() == n),
            "FootprintLanes: the lanes differ in length"
        );
        FootprintLanes {
            u,
            v,
            derivatives: Some(d),
        }
    }

    /// How many footprints.
    pub fn len(&self) -> usize {
        self.u.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.u.is_empty()
    }

    /// Footprint `k` as a struct (zero derivatives where none were given).
    ///
    /// # Panics
    /// If `k >= self.len()`.
    #[inline(always)]
    pub fn get(&self, k: usize) -> Footprint {
        let (u, v) = (self.u[k], self.v[k]);
        match self.derivatives {
            Some([dudx, dudy, dvdx, dvdy]) => Footprint {
                u,
                v,
                dudx: dudx[k],
                dudy: dudy[k],
                dvdx: dvdx[k],
                dvdy: dvdy[k],
            },
            None => Footprint::point(u, v),
        }
    }
}

/// A batch of footprints that the batched sampler takes: `&[Footprint]`, `&Vec<Footprint>`,
/// `&[Footprint; N]` or [`FootprintLanes`]. Sealed: its methods are the crate's own.
pub trait FootprintBatch: sealed::Batch {}

impl<T: sealed::Batch> FootprintBatch for T {}

pub(crate) use sealed::Source;

pub(crate) mod sealed {
    use super::FootprintLanes;
    use crate::base::footprint::Footprint;

    /// What a [`super::FootprintBatch`] becomes inside the crate: one of the two [`Source`]s.
    pub trait Batch: Copy {
        /// The source the kernels read.
        type Source: Source;
        /// This batch as that source.
        fn source(self) -> Self::Source;
    }

    /// A batch of footprints as the kernels read it: its length, a sub-range, and its fields
    /// copied into lanes (`batch::queries` and `batch::point_bytes` copy a chunk at a time; the
    /// later stages read the chunk, never the source).
    pub trait Source: Copy {
        /// How many footprints.
        fn len(self) -> usize;
        /// Footprints `start..end`.
        fn range(self, start: usize, end: usize) -> Self;
        /// `u` and `v` of every footprint into the first `len()` entries of `u` and `v`, which
        /// are at least that long (the lanes panic otherwise; structs stop at the shorter).
        /// A plain copy: `batch::queries` makes them finite in a second loop, which retires
        /// fewer instructions than one loop doing both (the copy is a `memcpy`, the second loop
        /// runs at full width with no remainder; docs/decisions.md).
        fn uv_into(self, u: &mut [f32], v: &mut [f32]);
        /// The derivatives of every footprint into the first `len()` entries of each lane of
        /// `d` (`[dudx, dvdx, dudy, dvdy]`, the order of `batch::queries`' lanes), each at least
        /// that long (as [`Source::uv_into`]); zeros for lanes given without derivatives.
        fn derivatives_into(self, d: [&mut [f32]; 4]);
    }

    impl<'a> Batch for &'a [Footprint] {
        type Source = &'a [Footprint];
        #[inline(always)]
        fn source(self) -> Self::Source {
            self
        }
    }

    impl<'a> Batch for &'a Vec<Footprint> {
        type Source = &'a [Footprint];
        #[inline(always)]
        fn source(self) -> Self::Source {
            self
        }
    }

    impl<'a, const N: usize> Batch for &'a [Footprint; N] {
        type Source = &'a [Footprint];
        #[inline(always)]
        fn source(self) -> Self::Source {
            self
        }
    }

    impl<'a> Batch for FootprintLanes<'a> {
        type Source = FootprintLanes<'a>;
        #[inline(always)]
        fn source(self) -> Self::Source {
            self
        }
    }

    impl Source for &[Footprint] {
        #[inline(always)]
        fn len(self) -> usize {
            <[Footprint]>::len(self)
        }
        #[inline(always)]
        fn range(self, start: usize, end: usize) -> Self {
            &self[start..end]
        }
        #[inline(always)]
        fn uv_into(self, u: &mut [f32], v: &mut [f32]) {
            for ((u, v), f) in u.iter_mut().zip(v.iter_mut()).zip(self) {
                (*u, *v) = (f.u, f.v);
            }
        }
        #[inline(always)]
        fn derivatives_into(self, [dudx, dvdx, dudy, dvdy]: [&mut [f32]; 4]) {
            let lanes = dudx.iter_mut().zip(dvdx.iter_mut());
            let lanes = lanes.zip(dudy.iter_mut().zip(dvdy.iter_mut()));
            for (((a, b), (c, d)), f) in lanes.zip(self) {
                (*a, *b, *c, *d) = (f.dudx, f.dvdx, f.dudy, f.dvdy);
            }
        }
    }

    impl Source for FootprintLanes<'_> {
        #[inline(always)]
        fn len(self) -> usize {
            self.u.len()
        }
        #[inline(always)]
        fn range(self, start: usize, end: usize) -> Self {
            FootprintLanes {
                u: &self.u[start..end],
                v: &self.v[start..end],
                derivatives: self.derivatives.map(|d| d.map(|d| &d[start..end])),
            }
        }
        #[inline(always)]
        fn uv_into(self, u: &mut [f32], v: &mut [f32]) {
            let n = self.u.len();
            u[..n].copy_from_slice(self.u);
            v[..n].copy_from_slice(self.v);
        }
        #[inline(always)]
        fn derivatives_into(self, [dudx, dvdx, dudy, dvdy]: [&mut [f32]; 4]) {
            let n = self.u.len();
            match self.derivatives {
                Some([a, b, c, d]) => {
                    dudx[..n].copy_from_slice(a);
                    dudy[..n].copy_from_slice(b);
                    dvdx[..n].copy_from_slice(c);
                    dvdy[..n].copy_from_slice(d);
                }
                None => {
                    for lane in [dudx, dvdx, dudy, dvdy] {
                        lane[..n].fill(0.0);
                    }
                }
            }
        }
    }
}

/// `source` in consecutive parts of `n` (the last may be shorter; none if it is empty).
#[inline(always)]
pub(crate) fn chunks<S: Source>(source: S, n: usize) -> impl Iterator<Item = S> {
    let len = source.len();
    (0..len)
        .step_by(n.max(1))
        .map(move |a| source.range(a, (a + n).min(len)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Structs and lanes of the same footprints read the same: every accessor, every range.
    #[test]
    fn lanes_read_as_structs() {
        let fps: Vec<Footprint> = (0..70)
            .map(|k| {
                let x = k as f32;
                Footprint {
                    u: x * 0.1,
                    v: -x,
                    dudx: x + 0.5,
                    dudy: x * 3.0,
                    dvdx: -0.25 * x,
                    dvdy: 1.0 / (x + 1.0),
                }
            })
            .collect();
        let field = |f: fn(&Footprint) -> f32| fps.iter().map(f).collect::<Vec<_>>();
        let (u, v) = (field(|f| f.u), field(|f| f.v));
        let d = [
            field(|f| f.dudx),
            field(|f| f.dudy),
            field(|f| f.dvdx),
            field(|f| f.dvdy),
        ];
        let lanes = FootprintLanes::new(&u, &v, [&d[0], &d[1], &d[2], &d[3]]);
        let structs: &[Footprint] = &fps;
        assert_eq!(lanes.len(), 70);
        for (a, b) in chunks(lanes, 64).zip(chunks(structs, 64)) {
            assert_eq!(Source::len(a), Source::len(b));
            let n = Source::len(a);
            let mut got = [[0.0f32; 64]; 2];
            let mut want = [[1.0f32; 64]; 2];
            let [gu, gv] = &mut got;
            a.uv_into(gu, gv);
            let [wu, wv] = &mut want;
            b.uv_into(wu, wv);
            assert_eq!(got[0][..n], want[0][..n]);
            assert_eq!(got[1][..n], want[1][..n]);
            let mut got = [[0.0f32; 64]; 4];
            let mut want = [[1.0f32; 64]; 4];
            let [g0, g1, g2, g3] = &mut got;
            a.derivatives_into([g0, g1, g2, g3]);
            let [w0, w1, w2, w3] = &mut want;
            b.derivatives_into([w0, w1, w2, w3]);
            assert_eq!(got.map(|l| l[..n].to_vec()), want.map(|l| l[..n].to_vec()));
        }
        for (k, f) in fps.iter().enumerate() {
            assert_eq!(lanes.get(k), *f);
        }
        // Without derivatives: zero derivatives, as `Footprint::point`.
        let points = FootprintLanes::points(&u, &v);
        for k in 0..70 {
            assert_eq!(points.get(k), Footprint::point(u[k], v[k]));
        }
        let mut d = [[1.0f32; 70]; 4];
        let [d0, d1, d2, d3] = &mut d;
        points.derivatives_into([d0, d1, d2, d3]);
        assert!(d.iter().flatten().all(|&x| x == 0.0));
        assert_eq!(chunks(points, 64).count(), 2);
        assert_eq!(chunks(FootprintLanes::points(&[], &[]), 64).count(), 0);
    }

    #[test]
    #[should_panic(expected = "differ in length")]
    fn points_of_different_lengths_panic() {
        let _ = FootprintLanes::points(&[0.0; 3], &[0.0; 2]);
    }

    #[test]
    #[should_panic(expected = "differ in length")]
    fn lanes_of_different_lengths_panic() {
        let _ = FootprintLanes::new(
            &[0.0; 3],
            &[0.0; 3],
            [&[0.0; 3], &[0.0; 2], &[0.0; 3], &[0.0; 3]],
        );
    }
}
