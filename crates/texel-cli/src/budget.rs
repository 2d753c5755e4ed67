//! `--max-memory`: parsing the size, and the account every command charges before it allocates
//! ([`texel::MemoryBudget`]; the figures per pixel and per element are in [`texel::memory`]).

use texel::memory::mib;
use texel::MemoryBudget;

/// A byte count from the command line: a number (decimals allowed, `170.8M`) with an optional
/// unit K, M, G, T (powers of 1024; `KiB`, `MB`, ... are read the same way), at least 1 MiB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ByteSize(pub u64);

impl std::str::FromStr for ByteSize {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let t = s.trim();
        let split = t
            .find(|c: char| !c.is_ascii_digit() && c != '.')
            .unwrap_or(t.len());
        let (num, unit) = t.split_at(split);
        let not_a_size = || format!("{s:?} is not a size (e.g. 512M, 1.5G or a number of bytes)");
        let (whole, fraction) = num.split_once('.').unwrap_or((num, ""));
        if whole.is_empty() && fraction.is_empty() || fraction.contains('.') {
            return Err(not_a_size());
        }
        let shift = match unit.trim().to_ascii_uppercase().as_str() {
            "" | "B" => 0,
            "K" | "KB" | "KIB" => 10,
            "M" | "MB" | "MIB" => 20,
            "G" | "GB" | "GIB" => 30,
            "T" | "TB" | "TIB" => 40,
            other => return Err(format!("{s:?}: unknown unit {other:?} (use K, M, G or T)")),
        };
        let too_large = || format!("{s:?} is too large");
        let whole: u64 = if whole.is_empty() {
            0
        } else {
            whole.parse().map_err(|_| not_a_size())?
        };
        let mut bytes = whole.checked_mul(1u64 << shift).ok_or_else(too_large)?;
        if !fraction.is_empty() {
            // The decimals as a fraction of the unit, rounded up to a whole byte: a figure texel
            // prints ("170.8 MiB") given back as a limit is never below it.
            let digits = fraction.len().min(18) as u32;
            let f: u128 = fraction[..digits as usize]
                .parse()
                .map_err(|_| not_a_size())?;
            let scale = 10u128.pow(digits);
            let part = (f * (1u128 << shift)).div_ceil(scale);
            bytes = bytes
                .checked_add(u64::try_from(part).map_err(|_| too_large())?)
                .ok_or_else(too_large)?;
        }
        if bytes < 1 << 20 {
            return Err(format!("{s:?} is below the minimum of 1M"));
        }
        Ok(ByteSize(bytes))
    }
}

/// The account for `--max-memory` if given, held to what the machine and the process's limits
/// allow ([`MemoryBudget::explicit`]: a request beyond them would end in an aborted
/// allocation, not an error), else for the process's default ([`texel::memory::default_limit`]:
/// the smallest of half the machine's memory, the cgroup's limit and what `ulimit -v`/`-d`
/// leave); errors name the flag.
pub(crate) fn budget(max_memory: Option<ByteSize>) -> MemoryBudget {
    match max_memory {
        Some(ByteSize(b)) => MemoryBudget::explicit(b, &format!("--max-memory {}", mib(b))),
        None => {
            let (limit, why) = texel::memory::default_limit();
            MemoryBudget::new(
                limit,
                format!("--max-memory's default {} ({why})", mib(limit)),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!("512M".parse::<ByteSize>(), Ok(ByteSize(512 << 20)));
        assert_eq!("4GiB".parse::<ByteSize>(), Ok(ByteSize(4 << 30)));
        assert_eq!("2g".parse::<ByteSize>(), Ok(ByteSize(2 << 30)));
        assert_eq!("1048576".parse::<ByteSize>(), Ok(ByteSize(1 << 20)));
        assert!("1K".parse::<ByteSize>().is_err());
        assert!("4X".parse::<ByteSize>().is_err());
        assert!("99999999999T".parse::<ByteSize>().is_err());
        assert!("".parse::<ByteSize>().is_err());
        // Decimals, as texel prints its figures, rounded up to a whole byte.
        assert_eq!("170.8M".parse::<ByteSize>(), Ok(ByteSize(179_096_781)));
        assert_eq!("1.5G".parse::<ByteSize>(), Ok(ByteSize(3 << 29)));
        assert_eq!(".5G".parse::<ByteSize>(), Ok(ByteSize(1 << 29)));
        for bad in [".", "1.5.2M", "1..5M", "-1M", "1,5M"] {
            assert!(bad.parse::<ByteSize>().is_err(), "{bad}");
        }
    }

    #[test]
    fn errors_name_the_flag() {
        let mut b = budget(Some(ByteSize(10 << 20)));
        b.take("a", 6 << 20).unwrap();
        let e = b.take("the frame", 5 << 20).unwrap_err().to_string();
        assert!(e.contains("over --max-memory 10.0 MiB"), "{e}");
        assert!(budget(None).name().starts_with("--max-memory's default"));
    }
}
