//! Summaries, tables, CSV (measured-data format) and golden transcripts of PIL runs.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use eha_guard::product::wire::TickReply;

use super::qemu::TICKS_PER_INSTRUCTION;
use super::{PilRun, TickRecord};

/// Numbers that describe one run.
#[derive(Clone, Debug)]
pub struct Summary {
    /// Number of lockstep ticks.
    pub ticks: usize,
    /// Plant time covered, s.
    pub plant_time_s: f64,
    /// (plant time, open?) at every valve command change.
    pub valve_events: Vec<(f64, bool)>,
    /// max |firmware prediction − reference true drain temperature|, K
    pub max_abs_err_k: f64,
    /// max (reference − firmware), K (under-prediction; ≤ 0 means never under)
    pub max_under_k: f64,
    /// LNG used over the run as the firmware counts it, kg.
    pub lng_used_kg: f64,
    /// LNG left at the end as the firmware counts it, kg.
    pub lng_remaining_kg: f64,
    /// Instructions per tick (mean, max) when measured with `-icount`.
    pub instructions: Option<(f64, f64)>,
    /// Highest reference drain temperature, °C.
    pub peak_ref_c: f64,
    /// Highest firmware drain estimate, °C.
    pub peak_fw_c: f64,
}

impl Summary {
    /// The summary of `records`; `icount` says whether their tick counts
    /// are instruction counts.
    pub fn of(records: &[TickRecord], icount: bool) -> Self {
        let mut valve_events = Vec::new();
        let mut prev = false;
        let (mut max_abs, mut max_under) = (0.0f64, f64::NEG_INFINITY);
        let (mut peak_ref, mut peak_fw) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        let (mut tsum, mut tmax) = (0.0f64, 0.0f64);
        for r in records {
            let fw = f64::from(r.reply.out.drain_c);
            let reference = r.sensors.t_drain_c;
            max_abs = max_abs.max((fw - reference).abs());
            max_under = max_under.max(reference - fw);
            peak_ref = peak_ref.max(reference);
            peak_fw = peak_fw.max(fw);
            if r.reply.out.valve_open != prev {
                valve_events.push((r.t_s, r.reply.out.valve_open));
                prev = r.reply.out.valve_open;
            }
            let instr = f64::from(r.cycles) / TICKS_PER_INSTRUCTION;
            tsum += instr;
            tmax = tmax.max(instr);
        }
        let first = records.first().map_or(0.0, |r| f64::from(r.reply.out.lng_remaining_kg));
        let last = records.last().map_or(0.0, |r| f64::from(r.reply.out.lng_remaining_kg));
        let n = records.len();
        Summary {
            ticks: n,
            plant_time_s: match (records.first(), records.get(1), records.last()) {
                (Some(a), Some(b), Some(z)) => z.t_s + (b.t_s - a.t_s),
                _ => 0.0,
            },
            valve_events,
            max_abs_err_k: max_abs,
            max_under_k: max_under,
            lng_used_kg: first - last,
            lng_remaining_kg: last,
            instructions: (icount && n > 0).then(|| (tsum / n as f64, tmax)),
            peak_ref_c: peak_ref,
            peak_fw_c: peak_fw,
        }
    }
}

/// Compact table: every `every_s` of plant time, plus every valve change.
pub fn table(records: &[TickRecord], every_s: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{:>8} {:>10} {:>10} {:>8} {:>5} {:>6}", "time_s", "ref_drain", "fw_drain", "err_K", "valve", "faults");
    let mut next = 0.0;
    let mut prev_valve = false;
    for r in records {
        let valve = r.reply.out.valve_open;
        if r.t_s + 1e-9 >= next || valve != prev_valve {
            let fw = f64::from(r.reply.out.drain_c);
            let _ = writeln!(
                s,
                "{:>8.1} {:>10.3} {:>10.3} {:>+8.3} {:>5} {:>#6x}{}",
                r.t_s,
                r.sensors.t_drain_c,
                fw,
                fw - r.sensors.t_drain_c,
                if valve { "OPEN" } else { "shut" },
                r.reply.out.faults,
                if valve != prev_valve { "  <- valve" } else { "" }
            );
            if r.t_s + 1e-9 >= next {
                next += every_s;
            }
            prev_valve = valve;
        }
    }
    s
}

/// Human summary lines.
pub fn summary_text(run: &PilRun, s: &Summary) -> String {
    let mut t = String::new();
    let c = run.done.counters;
    let _ = writeln!(t, "firmware build      : {} ({} in QEMU)", run.build.name(), run.build.machine());
    let _ = writeln!(t, "ticks               : {} ({:.1} s of plant time)", s.ticks, s.plant_time_s);
    let _ = writeln!(t, "frames              : accepted {}, rejected crc {} framing {} sequence {}, missing ticks {}", c.accepted, c.rejected_crc, c.rejected_framing, c.rejected_sequence, c.missing);
    let ev: Vec<String> = s.valve_events.iter().map(|(t, o)| format!("{} at {t:.1} s", if *o { "open" } else { "close" })).collect();
    let _ = writeln!(t, "LNG valve events    : {}", if ev.is_empty() { "none".into() } else { ev.join(", ") });
    let crossing = run.records.iter().find(|r| r.sensors.t_drain_c >= 40.0).map(|r| r.t_s);
    let _ = writeln!(
        t,
        "reference drain 40°C: {}",
        crossing.map_or("never reached".to_string(), |c| format!("reached at {c:.1} s (where a perfect guard would open)"))
    );
    let _ = writeln!(t, "LNG used            : {:.4} kg ({:.4} kg left)", s.lng_used_kg, s.lng_remaining_kg);
    let _ = writeln!(t, "peak drain          : reference {:.3} °C, firmware {:.3} °C", s.peak_ref_c, s.peak_fw_c);
    let _ = writeln!(t, "max |fw − ref|      : {:.3} K (max under-prediction {:.3} K)", s.max_abs_err_k, s.max_under_k);
    match s.instructions {
        Some((mean, max)) => {
            let _ = writeln!(t, "instructions / tick : mean {mean:.0}, max {max:.0} (QEMU -icount, SysTick around App::tick: the whole product loop)");
        }
        None => {
            let _ = writeln!(t, "instructions / tick : not measured (run without -icount)");
        }
    }
    let _ = writeln!(t, "wall time           : {:.2} s ({:.0} ticks/s)", run.wall.as_secs_f64(), s.ticks as f64 / run.wall.as_secs_f64().max(1e-9));
    t
}

/// Deterministic transcript for golden-output diffs (no wall-clock numbers).
pub fn transcript(run: &PilRun, every_s: f64) -> String {
    let s = Summary::of(&run.records, run.icount);
    let mut t = String::new();
    let c = run.done.counters;
    let _ = writeln!(t, "build {} machine {}", run.build.name(), run.build.machine());
    let rejected = u32::from(c.rejected_crc) + u32::from(c.rejected_framing) + u32::from(c.rejected_sequence);
    let _ = writeln!(t, "ticks {} accepted {} rejected {} missing {}", s.ticks, c.accepted, rejected, c.missing);
    t.push_str(&table(&run.records, every_s));
    for (tm, open) in &s.valve_events {
        let _ = writeln!(t, "valve {} at {tm:.1} s", if *open { "open" } else { "close" });
    }
    let _ = writeln!(t, "lng used {:.4} kg", s.lng_used_kg);
    let _ = writeln!(t, "max abs err {:.3} K", s.max_abs_err_k);
    if let Some((mean, max)) = s.instructions {
        let _ = writeln!(t, "instructions per tick mean {mean:.0} max {max:.0}");
    }
    t.push_str("defmt log:\n");
    for l in &run.log {
        let _ = writeln!(t, "  {l}");
    }
    t
}

/// Bitwise equality of two tick replies (floats by bit pattern).
pub fn same_reply(a: &TickReply, b: &TickReply) -> bool {
    a.tick == b.tick
        && a.sample_seq == b.sample_seq
        && a.fresh == b.fresh
        && a.not_commissioned == b.not_commissioned
        && a.out.bit_eq(&b.out)
        && a.pins == b.pins
        && a.overruns == b.overruns
        && a.rejected == b.rejected
        && a.restore == b.restore
        && a.reset_cause == b.reset_cause
}

/// Per-tick comparison of two reply streams (firmware vs SIL).
#[derive(Clone, Debug, Default)]
pub struct Comparison {
    /// Steps compared (the shorter stream's length).
    pub ticks: usize,
    /// Steps whose replies are bit-identical (every field).
    pub identical: usize,
    /// Index of the first tick that is not bit-identical.
    pub first_difference: Option<usize>,
    /// Largest drain-estimate difference, K.
    pub max_drain_diff_k: f64,
    /// Largest LNG-remaining difference, kg.
    pub max_lng_diff_kg: f64,
    /// Largest relative difference of the LNG time left (∞ when only one
    /// side is finite).
    pub max_seconds_left_rel: f64,
    /// Steps whose valve/alarm/derate/faults differ.
    pub flag_mismatches: usize,
}

/// Compares the firmware's replies with the SIL's, tick by tick.
pub fn compare(fw: &[TickReply], sil: &[TickReply]) -> Comparison {
    let mut c = Comparison { ticks: fw.len().min(sil.len()), ..Default::default() };
    for (k, (a, b)) in fw.iter().zip(sil).enumerate() {
        let same = same_reply(a, b);
        if same {
            c.identical += 1;
        } else if c.first_difference.is_none() {
            c.first_difference = Some(k);
        }
        c.max_drain_diff_k = c.max_drain_diff_k.max(f64::from((a.out.drain_c - b.out.drain_c).abs()));
        c.max_lng_diff_kg = c.max_lng_diff_kg.max(f64::from((a.out.lng_remaining_kg - b.out.lng_remaining_kg).abs()));
        let (x, y) = (f64::from(a.out.lng_seconds_left), f64::from(b.out.lng_seconds_left));
        if x.is_finite() && y.is_finite() {
            c.max_seconds_left_rel = c.max_seconds_left_rel.max((x - y).abs() / x.abs().max(y.abs()).max(1.0));
        } else if x.to_bits() != y.to_bits() {
            c.max_seconds_left_rel = f64::INFINITY;
        }
        if a.out.flags() != b.out.flags() || a.out.faults != b.out.faults {
            c.flag_mismatches += 1;
        }
    }
    c
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |x| format!("{x}"))
}

/// Write the run as a measured-data CSV (`docs/measured-data-format.md`)
/// with extra columns: `t_drain_ref_c` (plant truth), `fw_*` (firmware reply).
/// Written to a temporary file and renamed, so a failure never leaves a
/// half-written file under the final name.
pub fn write_csv(path: &Path, records: &[TickRecord], meta: &[(&str, String)]) -> Result<()> {
    let tmp = path.with_extension("csv.tmp");
    {
        let f = std::fs::File::create(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
        let mut w = std::io::BufWriter::new(f);
        for (k, v) in meta {
            writeln!(w, "# {k}: {v}")?;
        }
        writeln!(
            w,
            "time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,position_mm,t_oil_c,lng_valve,\
             t_drain_ref_c,fw_drain_c,fw_alarm,fw_derate,fw_faults,fw_lng_remaining_kg,fw_lng_seconds_left,fw_tick_cycles,fw_seq"
        )?;
        for r in records {
            let s = &r.sensors;
            let o = &r.reply.out;
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                r.t_s,
                s.speed_rpm,
                s.current_a,
                s.p_a_bar,
                s.p_b_bar,
                s.ambient_c,
                s.position_mm,
                fmt_opt(s.t_oil_c),
                u8::from(o.valve_open),
                s.t_drain_c,
                o.drain_c,
                u8::from(o.alarm),
                u8::from(o.derate),
                o.faults.bits(),
                o.lng_remaining_kg,
                // The format forbids non-finite values: an infinite "seconds
                // left" (no dissipation) is written as an empty cell.
                if o.lng_seconds_left.is_finite() { o.lng_seconds_left.to_string() } else { String::new() },
                r.cycles,
                r.reply.sample_seq,
            )?;
        }
        w.flush()?;
    }
    std::fs::rename(&tmp, path).with_context(|| format!("renaming {} to {}", tmp.display(), path.display()))?;
    Ok(())
}

/// Write the decoded defmt log beside the results.
pub fn write_log(path: &Path, log: &[super::defmt_log::LogLine]) -> Result<()> {
    let mut s = String::new();
    for l in log {
        let _ = writeln!(s, "{l}");
    }
    std::fs::write(path, s).with_context(|| format!("writing {}", path.display()))
}

/// Deterministic transcript of an open-loop run (golden output): a row every
/// `every` ticks and at every change of valve/alarm/faults, the counters and
/// the decoded defmt log. No instruction counts: a compiler update must not
/// force a re-bless; they are checked by the firmware benchmark
/// (`eha-sim fw-budget`) against committed budgets with a regression margin.
pub fn open_loop_transcript(run: &super::OpenLoopRun, tick_s: f64, every: usize) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "build {} machine {} ticks {}", run.build.name(), run.build.machine(), run.ticks.len());
    let _ = writeln!(t, "{:>8} {:>6} {:>12} {:>5} {:>5} {:>6} {:>8}", "time_s", "seq", "fw_drain_c", "valve", "alarm", "faults", "lng_kg");
    let mut prev: Option<&TickReply> = None;
    for (k, r) in run.ticks.iter().map(|o| &o.reply).enumerate() {
        let changed = prev.is_some_and(|p| p.out.flags() != r.out.flags() || p.out.faults != r.out.faults);
        if k % every == 0 || changed {
            let _ = writeln!(
                t,
                "{:>8.2} {:>6} {:>12.4} {:>5} {:>5} {:>#6x} {:>8.4}{}",
                k as f64 * tick_s,
                r.sample_seq,
                r.out.drain_c,
                u8::from(r.out.valve_open),
                u8::from(r.out.alarm),
                r.out.faults,
                r.out.lng_remaining_kg,
                if changed { "  <- change" } else { "" }
            );
        }
        prev = Some(r);
    }
    let c = run.done.counters;
    let _ = writeln!(t, "done: accepted {} missing {} rejected crc {} framing {} sequence {}", c.accepted, c.missing, c.rejected_crc, c.rejected_framing, c.rejected_sequence);
    t.push_str("defmt log:\n");
    for l in &run.log {
        let _ = writeln!(t, "  {l}");
    }
    t
}
