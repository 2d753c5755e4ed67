//! Every texture filter texel offers, by name: the one type a filter choice has, from the
//! command line to the GPU's uniforms. Each filter derives the sampler descriptor the CPU
//! sampler validates ([`Filter::descriptor`]), the lab's mode number ([`Filter::lab_mode`]),
//! and, in texel-gpu, the shader's mode. The one list of filter names: the CLI, reports, benches
//! and the Python package use it.

use crate::base::address::AddressMode;
use crate::base::descriptor::SamplerDescriptor;
use crate::base::error::TextureError;
use crate::base::filter::{Cubic, FilterMode, MipmapFilterMode};

/// A texture filter, as the command line and the reports name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Filter {
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
    /// EWA's Gaussian from up to 16 Gaussian-weighted trilinear probes (Mavridis and
    /// Papaioannou 2011).
    EwaProbes,
    /// Ripmap: anisotropically reduced images, four neighbours blended.
    Ripmap,
    /// Summed-area table: box mean over the footprint's bounding rectangle.
    Sat,
}

impl Filter {
    /// Every filter, cheapest first.
    pub const ALL: [Filter; 13] = [
        Filter::Nearest,
        Filter::Bilinear,
        Filter::Bicubic,
        Filter::MipNearest,
        Filter::Trilinear,
        Filter::Aniso2,
        Filter::Aniso4,
        Filter::Aniso8,
        Filter::Aniso16,
        Filter::Ewa,
        Filter::EwaProbes,
        Filter::Ripmap,
        Filter::Sat,
    ];

    /// Every filter's name, in the order of [`Filter::ALL`].
    pub const NAMES: [&'static str; 13] = [
        "nearest",
        "bilinear",
        "bicubic",
        "mip-nearest",
        "trilinear",
        "aniso2",
        "aniso4",
        "aniso8",
        "aniso16",
        "ewa",
        "ewa-probes",
        "ripmap",
        "sat",
    ];

    /// The lab's mode number of this filter (1-8), `None` for bicubic, EWA, ripmap and
    /// summed-area table (the inverse of [`Filter::from_lab_mode`]).
    pub fn lab_mode(self) -> Option<u8> {
        (1..=8).find(|&m| Filter::from_lab_mode(m).ok() == Some(self))
    }

    /// The name (`mip-nearest`).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The lab's numbered modes: 1 nearest, 2 bilinear, 3 mip-nearest, 4 trilinear, 5-8
    /// anisotropic 2x-16x.
    ///
    /// # Errors
    /// [`TextureError::UnknownLabMode`] outside `1..=8`.
    pub fn from_lab_mode(mode: u8) -> Result<Self, TextureError> {
        Ok(match mode {
            1 => Filter::Nearest,
            2 => Filter::Bilinear,
            3 => Filter::MipNearest,
            4 => Filter::Trilinear,
            5 => Filter::Aniso2,
            6 => Filter::Aniso4,
            7 => Filter::Aniso8,
            8 => Filter::Aniso16,
            _ => return Err(TextureError::UnknownLabMode(mode)),
        })
    }

    /// The sampler descriptor this filter means, with the given address modes.
    pub fn descriptor(
        self,
        address_mode_u: AddressMode,
        address_mode_v: AddressMode,
    ) -> SamplerDescriptor {
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
        match self {
            Filter::Nearest => base(Nearest, Nearest, MipmapFilterMode::None, 1),
            Filter::Bilinear => base(Linear, Linear, MipmapFilterMode::None, 1),
            Filter::Bicubic => base(cubic, cubic, MipmapFilterMode::None, 1),
            Filter::MipNearest => base(Linear, Linear, MipmapFilterMode::Nearest, 1),
            Filter::Trilinear => base(Linear, Linear, MipmapFilterMode::Linear, 1),
            Filter::Aniso2 => base(Linear, Linear, MipmapFilterMode::Linear, 2),
            Filter::Aniso4 => base(Linear, Linear, MipmapFilterMode::Linear, 4),
            Filter::Aniso8 => base(Linear, Linear, MipmapFilterMode::Linear, 8),
            Filter::Aniso16 => base(Linear, Linear, MipmapFilterMode::Linear, 16),
            Filter::Ewa => minification(FilterMode::Ewa),
            Filter::EwaProbes => minification(FilterMode::EwaProbes),
            Filter::Ripmap => minification(FilterMode::Ripmap),
            Filter::Sat => minification(FilterMode::SummedArea),
        }
    }

    /// Parse a filter list: `all`, or comma-separated names (duplicates dropped, order kept).
    ///
    /// # Errors
    /// [`TextureError::UnknownFilter`] naming the valid filters,
    /// [`TextureError::EmptyFilterList`].
    pub fn parse_list(list: &str) -> Result<Vec<Filter>, TextureError> {
        if list.trim() == "all" {
            return Ok(Filter::ALL.to_vec());
        }
        let mut out = Vec::new();
        for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let f = item.parse::<Filter>()?;
            if !out.contains(&f) {
                out.push(f);
            }
        }
        if out.is_empty() {
            return Err(TextureError::EmptyFilterList);
        }
        Ok(out)
    }
}

impl From<Filter> for SamplerDescriptor {
    /// The filter's descriptor ([`Filter::descriptor`]) with the default address modes (clamp
    /// to edge; set others with [`SamplerDescriptor::with_address_mode`]).
    fn from(filter: Filter) -> Self {
        let d = SamplerDescriptor::default();
        filter.descriptor(d.address_mode_u, d.address_mode_v)
    }
}

impl std::fmt::Display for Filter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Filter {
    type Err = TextureError;
    /// A filter by name, ASCII case ignored (`Trilinear`, `mip-nearest`).
    fn from_str(s: &str) -> Result<Self, TextureError> {
        Filter::NAMES
            .iter()
            .position(|n| n.eq_ignore_ascii_case(s.trim()))
            .map(|k| Filter::ALL[k])
            .ok_or_else(|| TextureError::UnknownFilter {
                name: s.to_string(),
                valid: &Filter::NAMES,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_lists_parse() {
        for (k, f) in Filter::ALL.iter().enumerate() {
            assert_eq!(f.name(), Filter::NAMES[k]);
            assert_eq!(f.name().parse::<Filter>().unwrap(), *f);
        }
        assert_eq!(
            Filter::parse_list(" trilinear, EWA,trilinear ").unwrap(),
            vec![Filter::Trilinear, Filter::Ewa]
        );
        assert_eq!(Filter::parse_list("all").unwrap(), Filter::ALL.to_vec());
        let e = Filter::parse_list("trilinear,bogus")
            .unwrap_err()
            .to_string();
        assert!(e.contains("\"bogus\"") && e.contains("mip-nearest"), "{e}");
        assert!(Filter::parse_list(" , ").is_err());
        // The lab's table: 1-4 the core filters, 5-8 anisotropic 2x-16x with trilinear probes.
        let core = [
            (FilterMode::Nearest, MipmapFilterMode::None, 1),
            (FilterMode::Linear, MipmapFilterMode::None, 1),
            (FilterMode::Linear, MipmapFilterMode::Nearest, 1),
            (FilterMode::Linear, MipmapFilterMode::Linear, 1),
            (FilterMode::Linear, MipmapFilterMode::Linear, 2),
            (FilterMode::Linear, MipmapFilterMode::Linear, 4),
            (FilterMode::Linear, MipmapFilterMode::Linear, 8),
            (FilterMode::Linear, MipmapFilterMode::Linear, 16),
        ];
        for (m, want) in (1..=8).zip(core) {
            let f = Filter::from_lab_mode(m).unwrap();
            assert_eq!(f.lab_mode(), Some(m));
            let d = Filter::from_lab_mode(m)
                .map(SamplerDescriptor::from)
                .unwrap();
            assert_eq!((d.min_filter, d.mipmap_filter, d.anisotropy_clamp), want);
            assert_eq!(d.mag_filter, d.min_filter);
            assert_eq!(d, f.descriptor(d.address_mode_u, d.address_mode_v));
        }
        assert!(Filter::from_lab_mode(9).is_err());
        let modes = Filter::ALL.iter().filter_map(|f| f.lab_mode()).count();
        assert_eq!(modes, 8, "bicubic, EWA, ripmap and SAT have no lab mode");
    }
}
