//! What the machine is and does: peak RSS, load average, CPU model (Linux `/proc`; figures
//! are NaN or `None` elsewhere).

use std::io::Write;

/// Peak resident set size of this process (VmHWM), in MB.
pub fn peak_rss_mb() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024.0 / 1e6)
}

/// Resets VmHWM to the current RSS (Linux ≥ 4.0), so each scene's peak is its own; whether
/// it could.
pub fn reset_peak_rss() -> bool {
    std::fs::OpenOptions::new()
        .write(true)
        .open("/proc/self/clear_refs")
        .and_then(|mut f| f.write_all(b"5"))
        .is_ok()
}

/// The 1-, 5- and 15-minute load averages.
pub fn load_avg() -> [f64; 3] {
    let s = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mut it = s.split_whitespace().map(|x| x.parse().unwrap_or(f64::NAN));
    [
        it.next().unwrap_or(f64::NAN),
        it.next().unwrap_or(f64::NAN),
        it.next().unwrap_or(f64::NAN),
    ]
}

/// The CPU's model name, `unknown` if `/proc/cpuinfo` has none.
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// Cores available to this process (at least 1).
pub fn nproc() -> u32 {
    std::thread::available_parallelism()
        .map(|n| n.get() as u32)
        .unwrap_or(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_agree_with_proc_where_it_exists() {
        assert!(nproc() >= 1);
        if std::path::Path::new("/proc/self/status").exists() {
            let rss = peak_rss_mb().expect("VmHWM on Linux");
            assert!(rss > 0.0 && rss.is_finite(), "{rss}");
            assert!(load_avg().iter().all(|x| *x >= 0.0), "{:?}", load_avg());
            assert!(!cpu_model().is_empty());
        }
    }
}
