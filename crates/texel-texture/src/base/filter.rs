//! The filter vocabulary: [`FilterMode`] (within a level, WebGPU's `GPUFilterMode` plus the
//! lectures' filters), [`MipmapFilterMode`] (across levels) and the Mitchell-Netravali [`Cubic`].

/// Filter used within one mip level (WebGPU `GPUFilterMode`, plus cubic).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum FilterMode {
    /// The texel containing the sample point (1 read).
    #[default]
    Nearest,
    /// Bilinear interpolation of the 2x2 nearest texel centres (4 reads).
    Linear,
    /// Bicubic Mitchell-Netravali with the given `(B, C)` over 4x4 texels (16 reads).
    Cubic(Cubic),
    /// Elliptically weighted average (Heckbert 1989, pbrt-v4 structure) over the footprint's
    /// ellipse in two pyramid levels; `min_filter` only. See [`crate::technique::ewa`].
    Ewa,
    /// EWA's Gaussian from Gaussian-weighted trilinear probes along the ellipse's major axis
    /// (Mavridis and Papaioannou 2011); `min_filter` only. See [`crate::technique::ewa_probes`].
    EwaProbes,
    /// Anisotropically reduced images `(W >> a) x (H >> b)` chosen from the footprint's
    /// axis-aligned bounding box, four blended; `min_filter` only. See [`crate::technique::ripmap`].
    Ripmap,
    /// Box mean over the footprint's axis-aligned bounding rectangle from a summed-area table
    /// (Crow 1984); `min_filter` only. See [`crate::technique::sat`].
    SummedArea,
}

impl FilterMode {
    /// Whether this filter is valid only as `min_filter` (`Ewa`, `EwaProbes`, `Ripmap`,
    /// `SummedArea`).
    pub fn is_minification_only(self) -> bool {
        matches!(
            self,
            FilterMode::Ewa | FilterMode::EwaProbes | FilterMode::Ripmap | FilterMode::SummedArea
        )
    }
}

/// EWA's eccentricity clamp when `anisotropy_clamp` is left at its WebGPU default of 1.
pub const EWA_DEFAULT_ANISOTROPY: u16 = 16;

/// How mip levels are chosen and combined when minifying (WebGPU `GPUMipmapFilterMode`, plus `None`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MipmapFilterMode {
    /// No mipmapping: minification filters level 0 only (OpenGL's `GL_LINEAR`/`GL_NEAREST` min filter).
    None,
    /// The nearest level (Vulkan rounding `ceil(lod + 1/2) - 1`).
    #[default]
    Nearest,
    /// Linear blend of the two levels around `lod` (trilinear when the min filter is Linear).
    Linear,
}

/// Largest `|B|` and `|C|` a sampler accepts. Mitchell and Netravali's family is drawn for B and C
/// in `[0, 1]` and Keys' cubics need C up to 1; unbounded values overflow `f32` (found by fuzzing:
/// B = 6e17 gave infinite samples). Within the bound the 4 weights of an axis sum in absolute value
/// to at most 7/3 (at B = -2, C = ±2; 1.19 for Catmull-Rom), so a 4x4 sample lies within
/// (7/3)^2 < 5.5 times the largest texel magnitude.
pub const MAX_CUBIC_PARAMETER: f32 = 2.0;

/// Mitchell-Netravali cubic parameters `(B, C)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cubic {
    /// B (blur): 0 for Catmull-Rom, 1 for the B-spline.
    pub b: f32,
    /// C (ringing): 1/2 for Catmull-Rom, 0 for the B-spline.
    pub c: f32,
}

impl Default for Cubic {
    /// Catmull-Rom.
    fn default() -> Self {
        Cubic::CATMULL_ROM
    }
}

impl Cubic {
    /// Catmull-Rom `(0, 1/2)`: interpolating, sharp, slight overshoot.
    pub const CATMULL_ROM: Cubic = Cubic { b: 0.0, c: 0.5 };
    /// Mitchell `(1/3, 1/3)`: the filter Mitchell and Netravali recommend.
    pub const MITCHELL: Cubic = Cubic {
        b: 1.0 / 3.0,
        c: 1.0 / 3.0,
    };
    /// Cubic B-spline `(1, 0)`: smooth, non-negative, approximating (does not interpolate).
    pub const B_SPLINE: Cubic = Cubic { b: 1.0, c: 0.0 };

    /// The kernel `k(x)`.
    pub fn kernel(&self, x: f32) -> f32 {
        let (b, c) = (self.b, self.c);
        let x = x.abs();
        let v = if x < 1.0 {
            ((12.0 - 9.0 * b - 6.0 * c) * x + (-18.0 + 12.0 * b + 6.0 * c)) * x * x
                + (6.0 - 2.0 * b)
        } else if x < 2.0 {
            (((-b - 6.0 * c) * x + (6.0 * b + 30.0 * c)) * x + (-12.0 * b - 48.0 * c)) * x
                + (8.0 * b + 24.0 * c)
        } else {
            0.0
        };
        v / 6.0
    }

    /// The four tap weights for fractional offset `t` in `[0, 1)`.
    #[inline]
    pub fn weights(&self, t: f32) -> [f32; 4] {
        [
            self.kernel(1.0 + t),
            self.kernel(t),
            self.kernel(1.0 - t),
            self.kernel(2.0 - t),
        ]
    }
}
