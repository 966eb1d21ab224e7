//! The CPU time a process has used, for benches and experiments that
//! report it beside the wall time (less sensitive to other jobs' load).

/// CPU time of this process so far (user + system, every thread), s, from
/// `/proc/self/stat` (Linux: fields 14 and 15, in clock ticks of 1/100 s);
/// NaN where it cannot be read.
pub fn process_cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command's closing parenthesis: utime and stime are
    // the 12th and 13th of them.
    let rest = stat.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<f64> = rest.split_whitespace().skip(11).take(2).filter_map(|x| x.parse().ok()).collect();
    if f.len() == 2 { (f[0] + f[1]) / 100.0 } else { f64::NAN }
}

#[cfg(test)]
mod tests {
    /// On Linux the counter parses (a format change gives NaN) and does not
    /// run backwards.
    #[test]
    fn cpu_time_reads_and_does_not_run_backwards() {
        let (a, b) = (super::process_cpu_s(), super::process_cpu_s());
        if cfg!(target_os = "linux") {
            assert!(a.is_finite() && b >= a, "{a} → {b} s");
        }
    }
}
