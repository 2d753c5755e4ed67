//! Filter names as the command line spells them, the lab's numbered modes, and their samplers.

use anyhow::{bail, Result};
use clap::ValueEnum;
use texel_texture::{AddressMode, Cubic, FilterMode, MipmapFilterMode, SamplerDescriptor};

/// Every texture filter texel offers, by its command-line name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, ValueEnum)]
pub enum FilterName {
    /// Nearest texel of level 0 (lab mode 1).
    Nearest,
    /// Bilinear in level 0 (lab mode 2).
    Bilinear,
    /// Catmull-Rom bicubic in level 0.
    Bicubic,
    /// Bilinear in the nearest mip level (lab mode 3).
    MipNearest,
    /// Bilinear in the two nearest mip levels, blended (lab mode 4).
    Trilinear,
    /// Anisotropic, up to 2 trilinear probes (lab mode 5).
    Aniso2,
    /// Anisotropic, up to 4 probes (lab mode 6).
    Aniso4,
    /// Anisotropic, up to 8 probes (lab mode 7).
    Aniso8,
    /// Anisotropic, up to 16 probes (lab mode 8).
    Aniso16,
    /// Elliptical weighted average (Heckbert 1989), eccentricity clamped at 16.
    Ewa,
    /// Ripmap: anisotropically reduced images, four neighbours blended.
    Ripmap,
    /// Summed-area table: box mean over the footprint's bounding rectangle.
    Sat,
}

impl FilterName {
    /// Every filter, cheapest first.
    pub const ALL: [FilterName; 12] = [
        FilterName::Nearest,
        FilterName::Bilinear,
        FilterName::Bicubic,
        FilterName::MipNearest,
        FilterName::Trilinear,
        FilterName::Aniso2,
        FilterName::Aniso4,
        FilterName::Aniso8,
        FilterName::Aniso16,
        FilterName::Ewa,
        FilterName::Ripmap,
        FilterName::Sat,
    ];

    /// The command-line spelling (`mip-nearest`).
    pub fn name(self) -> &'static str {
        match self {
            FilterName::Nearest => "nearest",
            FilterName::Bilinear => "bilinear",
            FilterName::Bicubic => "bicubic",
            FilterName::MipNearest => "mip-nearest",
            FilterName::Trilinear => "trilinear",
            FilterName::Aniso2 => "aniso2",
            FilterName::Aniso4 => "aniso4",
            FilterName::Aniso8 => "aniso8",
            FilterName::Aniso16 => "aniso16",
            FilterName::Ewa => "ewa",
            FilterName::Ripmap => "ripmap",
            FilterName::Sat => "sat",
        }
    }

    /// The lab's numbered modes: 1 nearest, 2 bilinear, 3 mip-nearest, 4 trilinear, 5-8 aniso 2x-16x.
    pub fn from_lab_mode(mode: u8) -> Result<Self> {
        Ok(match mode {
            1 => FilterName::Nearest,
            2 => FilterName::Bilinear,
            3 => FilterName::MipNearest,
            4 => FilterName::Trilinear,
            5 => FilterName::Aniso2,
            6 => FilterName::Aniso4,
            7 => FilterName::Aniso8,
            8 => FilterName::Aniso16,
            _ => bail!("unknown lab mode {mode}: valid modes are 1 (nearest) to 8 (anisotropic 16x)"),
        })
    }

    /// The sampler descriptor for this filter with the given address modes.
    pub fn descriptor(self, address_mode_u: AddressMode, address_mode_v: AddressMode) -> Result<SamplerDescriptor> {
        use FilterMode::{Linear, Nearest};
        let base = |mag, min, mipmap_filter, anisotropy_clamp| SamplerDescriptor {
            address_mode_u,
            address_mode_v,
            mag_filter: mag,
            min_filter: min,
            mipmap_filter,
            anisotropy_clamp,
            ..SamplerDescriptor::default()
        };
        let cubic = FilterMode::Cubic(Cubic::CATMULL_ROM);
        let minification = |min| SamplerDescriptor {
            address_mode_u,
            address_mode_v,
            ..SamplerDescriptor::minification(min)
        };
        Ok(match self {
            FilterName::Nearest => base(Nearest, Nearest, MipmapFilterMode::None, 1),
            FilterName::Bilinear => base(Linear, Linear, MipmapFilterMode::None, 1),
            FilterName::Bicubic => base(cubic, cubic, MipmapFilterMode::None, 1),
            FilterName::MipNearest => base(Linear, Linear, MipmapFilterMode::Nearest, 1),
            FilterName::Trilinear => base(Linear, Linear, MipmapFilterMode::Linear, 1),
            FilterName::Aniso2 => base(Linear, Linear, MipmapFilterMode::Linear, 2),
            FilterName::Aniso4 => base(Linear, Linear, MipmapFilterMode::Linear, 4),
            FilterName::Aniso8 => base(Linear, Linear, MipmapFilterMode::Linear, 8),
            FilterName::Aniso16 => base(Linear, Linear, MipmapFilterMode::Linear, 16),
            FilterName::Ewa => minification(FilterMode::Ewa),
            FilterName::Ripmap => minification(FilterMode::Ripmap),
            FilterName::Sat => minification(FilterMode::SummedArea),
        })
    }
}

/// Parse a filter list: `all`, or comma-separated names.
pub fn parse_list(list: &str) -> Result<Vec<FilterName>> {
    if list.trim() == "all" {
        return Ok(FilterName::ALL.to_vec());
    }
    let mut out = Vec::new();
    for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let f = FilterName::from_str(item, true).map_err(|_| {
            let valid: Vec<&str> = FilterName::ALL.iter().map(|f| f.name()).collect();
            anyhow::anyhow!("unknown filter {item:?}: valid filters are {}, or all", valid.join(", "))
        })?;
        if !out.contains(&f) {
            out.push(f);
        }
    }
    if out.is_empty() {
        bail!("the filter list is empty: name at least one filter, or all");
    }
    Ok(out)
}
