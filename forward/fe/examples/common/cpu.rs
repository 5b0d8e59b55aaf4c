//! CPU time of the running benchmark (shared by the FE examples).

/// User + system CPU seconds of this process (`self`: fields 14, 15 of
/// `/proc/self/stat`) or of its waited-for children (fields 16, 17), in
/// clock ticks of 1/100 s (Linux USER_HZ). NaN off Linux.
pub fn cpu_seconds(children: bool) -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    // after ")" only field 3 (state) is not numeric: field k is index k - 4
    let f: Vec<f64> = after
        .split_whitespace()
        .filter_map(|s| s.parse().ok())
        .collect();
    let k = if children { 12 } else { 10 };
    f.get(k)
        .zip(f.get(k + 1))
        .map_or(f64::NAN, |(u, s)| (u + s) / 100.0)
}
