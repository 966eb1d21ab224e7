//! How a log's rows are thinned to fit points ([`Thinning`]): uniformly
//! in time (the calibration's and the diagnosis's rule), or evenly in an
//! arc length of time and the measured temperature's motion (the
//! commissioning's option, [`super::fit::CalOptions::commission_thinning`]).

use crate::measured::{Channel, MeasuredRun};

/// Rule that picks a channel's fit points among its rows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Thinning {
    /// Every `len/n`-th row from the first: points evenly in time
    /// ([`thin`]).
    Uniform,
    /// Points evenly in the arc length s = ½ t/T + ½ V(t)/V(T) of
    /// [`motion_arc`]: half of them spread in time (the steady parts, where
    /// the gains and the outer transfer show), half in proportion to the
    /// measured temperature's own motion V (the total variation of its
    /// [`MOTION_BIN_S`] means). Why: a parameter's information is where
    /// the model output is sensitive to it, and a capacity's or a fast
    /// film's sensitivity ∂T/∂ln C ≈ −τ dT/dt lives where the state moves:
    /// a cold start or a load step, which uniform thinning at a point per
    /// 15 s (1800 s logs, 120 points) samples with 2–4 points per case time
    /// constant. Same number of points per channel as [`Thinning::Uniform`].
    Motion,
}

/// Width of the bins whose means [`motion_arc`] differences, s: shorter than
/// the fastest time constants the fit must see (the case oil's ~30 s),
/// long enough to average a thermocouple's noise (5 samples at 2 s; at σ
/// 0.1 K the noise adds ~0.05 K of variation per bin, a time-like floor).
pub const MOTION_BIN_S: f64 = 10.0;

/// Share of the arc length given to time in [`Thinning::Motion`] (the rest
/// to the motion): ½, so a quiet hour and a fast start both get points.
pub const MOTION_TIME_SHARE: f64 = 0.5;

/// The arc length of [`Thinning::Motion`] at each of `rows` of channel
/// `ch` (rows with a sample, increasing): 0 at the first row, 1 at the
/// last. Without motion (a constant channel), time alone.
pub fn motion_arc(run: &MeasuredRun, ch: Channel, rows: &[usize]) -> Vec<f64> {
    let (Some(&first), Some(&last)) = (rows.first(), rows.last()) else { return Vec::new() };
    let col = run.get(ch).unwrap_or(&[]);
    let t = &run.time_s;
    let span = (t[last] - t[first]).max(f64::MIN_POSITIVE);
    // Means of MOTION_BIN_S bins, their centres' times, and the cumulative
    // variation between consecutive bins.
    let mut bins: Vec<(f64, f64)> = Vec::new();
    let (mut k0, mut sum_t, mut sum_y, mut n) = (0usize, 0.0, 0.0, 0usize);
    for &i in rows {
        let k = ((t[i] - t[first]) / MOTION_BIN_S) as usize;
        if k != k0 && n > 0 {
            bins.push((sum_t / n as f64, sum_y / n as f64));
            (sum_t, sum_y, n) = (0.0, 0.0, 0);
        }
        k0 = k;
        sum_t += t[i];
        sum_y += col[i].unwrap_or(0.0);
        n += 1;
    }
    if n > 0 {
        bins.push((sum_t / n as f64, sum_y / n as f64));
    }
    let mut cum = vec![0.0; bins.len()];
    for j in 1..bins.len() {
        cum[j] = cum[j - 1] + (bins[j].1 - bins[j - 1].1).abs();
    }
    let total = cum.last().copied().unwrap_or(0.0);
    let bt: Vec<f64> = bins.iter().map(|b| b.0).collect();
    rows.iter()
        .map(|&i| {
            let time = (t[i] - t[first]) / span;
            if total <= 0.0 {
                return time;
            }
            let j = bt.partition_point(|&x| x <= t[i]);
            let v = crate::simulation::sim::interpolate(&bt, &cum, j, t[i]).unwrap_or(0.0).clamp(0.0, total);
            MOTION_TIME_SHARE * time + (1.0 - MOTION_TIME_SHARE) * v / total
        })
        .collect()
}

/// `rows` of channel `ch` thinned to at most `n` by `rule` (all of them when
/// there are no more than `n`).
pub fn thin_rows(run: &MeasuredRun, ch: Channel, rows: &[usize], n: usize, rule: Thinning) -> Vec<usize> {
    match rule {
        Thinning::Uniform => thin(rows, n).collect(),
        Thinning::Motion if rows.len() <= n.max(1) => rows.to_vec(),
        Thinning::Motion => {
            // n targets evenly in s from 0; each the first row at or past its
            // target and after the previous point (so n distinct points).
            let s = motion_arc(run, ch, rows);
            let mut out = Vec::with_capacity(n);
            let mut j = 0usize;
            for k in 0..n {
                let target = k as f64 / n as f64;
                while j < rows.len() && s[j] < target {
                    j += 1;
                }
                let j_max = rows.len() - (n - k);
                j = j.min(j_max);
                out.push(rows[j]);
                j += 1;
            }
            out
        }
    }
}

/// `rows` uniformly thinned to at most `n`: from the first, every `step`-th
/// (step = len/n, at least 1, accumulated), all of them when there are no
/// more than `n`.
pub fn thin(rows: &[usize], n: usize) -> impl Iterator<Item = usize> + '_ {
    let step = (rows.len() as f64 / n.max(1) as f64).max(1.0);
    std::iter::successors(Some(0.0f64), move |k| Some(k + step)).take_while(|&k| (k as usize) < rows.len()).map(|k| rows[k as usize])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1800 s log at 2 s with a drain that rises 10 K with τ 30 s from
    /// the start, then holds: the motion rule puts several times the
    /// uniform rule's points into the first minute, keeps the count, and
    /// keeps points spread over the quiet rest; a constant channel is
    /// thinned evenly in time.
    #[test]
    fn motion_thinning_gives_the_start_its_share() {
        let t: Vec<f64> = (0..900).map(|i| 2.0 * i as f64).collect();
        let mut run = MeasuredRun::new(t.clone());
        run.channels.insert(Channel::TDrainC, t.iter().map(|&t| Some(30.0 + 10.0 * (1.0 - (-t / 30.0).exp()))).collect());
        run.channels.insert(Channel::TOilC, t.iter().map(|_| Some(30.0)).collect());
        let rows: Vec<usize> = (0..900).collect();
        let early = |p: &[usize]| p.iter().filter(|&&i| t[i] < 60.0).count();
        let late = |p: &[usize]| p.iter().filter(|&&i| t[i] >= 900.0).count();
        let u = thin_rows(&run, Channel::TDrainC, &rows, 120, Thinning::Uniform);
        let m = thin_rows(&run, Channel::TDrainC, &rows, 120, Thinning::Motion);
        assert_eq!((u.len(), m.len()), (120, 120));
        assert!(m.windows(2).all(|w| w[0] < w[1]), "points distinct and in order");
        // uniform: a point per 15 s, 4 in the first minute; motion: half the
        // points follow the 10 K rise, ~86 % of it within 60 s
        assert_eq!(early(&u), 4);
        assert!(early(&m) >= 4 * early(&u), "motion: {} points in the first minute", early(&m));
        // the quiet second half keeps the time share's points (60 · ½ ± 2)
        assert!((28..=32).contains(&late(&m)), "motion: {} points after 900 s", late(&m));
        let c = thin_rows(&run, Channel::TOilC, &rows, 120, Thinning::Motion);
        assert_eq!(early(&c), 4, "a constant channel: evenly in time");
    }
}
