//! `--memory SIZE`: the command line's sizes (the memory policy itself is the library's,
//! [`crate::memory`]).

/// `4G`, `512M`, `100k` or plain bytes (binary units).
pub(super) fn parse_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (num, shift) = match t.chars().last().map(|c| c.to_ascii_uppercase()) {
        Some('K') => (&t[..t.len() - 1], 10),
        Some('M') => (&t[..t.len() - 1], 20),
        Some('G') => (&t[..t.len() - 1], 30),
        Some('T') => (&t[..t.len() - 1], 40),
        _ => (t, 0),
    };
    let n: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a size: write e.g. 4G, 512M or 1000000"))?;
    if !(n.is_finite() && n > 0.0) {
        return Err(format!("{s:?}: the size must be above zero"));
    }
    Ok((n * (1u64 << shift) as f64) as u64)
}
