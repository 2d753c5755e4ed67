//! The command line's view of [`texel::Filter`]: a clap value parser over its names, and lists;
//! with `--gpu`, lists of texel-gpu's filters and the device's own sampler.

use anyhow::Result;
use clap::builder::{PossibleValuesParser, TypedValueParser};
pub(crate) use texel::Filter;
use texel_gpu::GpuFilter;

/// One row `--gpu` renders: its label, the texel filter whose samplers and pyramid it is given,
/// and the GPU mode.
pub(crate) type GpuJob = (&'static str, Filter, GpuFilter);

/// Parses one filter name for clap, listing [`Filter::NAMES`] in `--help` and in usage errors.
pub(crate) fn filter_parser() -> impl TypedValueParser<Value = Filter> {
    PossibleValuesParser::new(Filter::NAMES).map(|s| s.parse::<Filter>().expect("a listed name"))
}

/// Parse a filter list: `all`, or comma-separated names ([`Filter::parse_list`]).
pub(crate) fn parse_list(list: &str) -> Result<Vec<Filter>> {
    Ok(Filter::parse_list(list)?)
}

/// The device's own sampler as `texel bench --gpu` and `texel compare --gpu` name it: label, the
/// texel filter whose samplers and pyramid it is given, and the GPU mode.
pub(crate) const HARDWARE_ROWS: [GpuJob; 2] = [
    ("hw-trilinear", Filter::Trilinear, GpuFilter::HwTrilinear),
    ("hw-aniso16", Filter::Trilinear, GpuFilter::HwAniso16),
];

/// What `texel bench --gpu` times, from `--filters`: texel's shaders for the named filters and
/// the device's own sampler for `hw-trilinear` and `hw-aniso16`, names' case ignored, in the
/// list's order, each once. `all` alone is every filter the GPU path has and both hardware rows.
/// An error names an unknown name, or a filter the GPU path lacks, with what it has.
pub(crate) fn parse_gpu_list(list: &str) -> Result<Vec<GpuJob>> {
    if list.trim() == "all" {
        let mut jobs: Vec<_> = GpuFilter::filters()
            .filter_map(|f| GpuFilter::of(f).map(|g| (f.name(), f, g)))
            .collect();
        jobs.extend(HARDWARE_ROWS);
        return Ok(jobs);
    }
    let has = || {
        GpuFilter::filters()
            .map(|f| f.name())
            .chain(HARDWARE_ROWS.iter().map(|r| r.0))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut jobs: Vec<GpuJob> = Vec::new();
    for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let job = match HARDWARE_ROWS
            .iter()
            .find(|(label, ..)| label.eq_ignore_ascii_case(item))
        {
            Some(&row) => row,
            None => {
                let Ok(filter) = item.parse::<Filter>() else {
                    anyhow::bail!(
                        "unknown filter {item:?} for --gpu: valid are {}, or all alone",
                        has()
                    );
                };
                let Some(gpu) = GpuFilter::of(filter) else {
                    anyhow::bail!("--gpu has no {} filter (it has {})", filter.name(), has());
                };
                (filter.name(), filter, gpu)
            }
        };
        if !jobs.iter().any(|j| j.0 == job.0) {
            jobs.push(job);
        }
    }
    if jobs.is_empty() {
        // parse_list's own error for an empty list.
        parse_list(list)?;
    }
    Ok(jobs)
}
