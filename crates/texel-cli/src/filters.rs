//! The command line's view of [`texel::Filter`]: a clap value parser over its names, and lists.

use anyhow::Result;
use clap::builder::{PossibleValuesParser, TypedValueParser};
pub use texel::Filter;

/// Parses one filter name for clap, listing [`Filter::NAMES`] in `--help` and in usage errors.
pub fn filter_parser() -> impl TypedValueParser<Value = Filter> {
    PossibleValuesParser::new(Filter::NAMES).map(|s| s.parse::<Filter>().expect("a listed name"))
}

/// Parse a filter list: `all`, or comma-separated names ([`Filter::parse_list`]).
pub fn parse_list(list: &str) -> Result<Vec<Filter>> {
    Ok(Filter::parse_list(list)?)
}
