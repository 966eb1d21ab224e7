//! The 120 s Fig. 15 closed loop over the UART against the semihosting PIL.

use super::*;

/// 120 s of the Fig. 15 LNG case in closed loop over the UART.
///
/// - Every tick reply equals, bit for bit, the host build of the same
///   application fed what that tick saw (its sample, or none): no f32
///   rounding difference between target and host.
/// - Against the semihosting lockstep PIL run of the same plant, in guard
///   time (ticks since the first sample): the same valve events within one
///   tick, and the same drain estimate: bit-identical when every tick got
///   its sample; after a tick whose sample came late (the host more than
///   10 ms late in real time) within the PIL estimate's largest change over
///   (late ticks + 1) model steps (see the assertion).
/// - A late sample is used by the next tick, never lost or overwritten;
///   how many come late is printed (the host's real-time quality). At most
///   1 % of ticks may overrun: in QEMU that comes from the host
///   descheduling the emulator, not from the firmware (its tick costs
///   ~1 200 instructions, see the bench).
/// - The pins read back in every tick reply match the outputs.
///
/// A host stall of `stale_ticks` (5) ticks or more in a row is a real
/// controller-silent event for the firmware: the run then checks the
/// fail-safe instead (STALE latched no earlier than the 5th missed tick,
/// valve open from then on) and is repeated once for the comparison; a
/// stall in both runs fails the test with the stalls' lengths.
pub(super) fn fig15_120s_closed_loop_over_the_uart_matches_the_semihosting_pil() {
    retry_on_host_stall(fig15_attempt);
}

/// One closed-loop run of [`fig15_120s_closed_loop_over_the_uart_matches_the_semihosting_pil`]:
/// `Err(description)` of a host stall after which the fail-safe was
/// checked (panics on any failed check).
fn fig15_attempt() -> Result<(), String> {
    let duration_s = 120.0;
    let mut s = session(&[]);
    // After a host stall the run is repeated: this attempt stops 2 s (200
    // samples) after the guard first reports STALE, enough to check the
    // fail-safe below, instead of running out its 120 s (a stall at 54 s
    // cost 78 s of CI time).
    let stale = eha_guard::faults::STALE;
    let mut since_stale = 0u32;
    let mut hook = |_: &mut ProductSession, x: &ProductSample| -> anyhow::Result<bool> {
        if x.tick.out.faults.contains(stale) || since_stale > 0 {
            since_stale += 1;
        }
        Ok(since_stale <= 200)
    };
    let run = run_closed_loop(&mut s, &mut plant(duration_s), duration_s, Duration::from_secs(2), &mut hook).unwrap_or_else(|e| panic!("{e:#}"));
    let mut ticks = Vec::new();
    let st = s.status(1, &mut ticks).unwrap_or_else(|e| panic!("{e:#}"));
    drop(s);

    // Bit-identical to the host build, whatever the host's timing was.
    let sil = eha_sim::pil::product::sil_replay(&run);
    assert_eq!(sil.len(), run.ticks.len());
    for (k, ((_, fw), host)) in run.ticks.iter().zip(&sil).enumerate() {
        assert!(
            fw.tick == host.tick && fw.fresh == host.fresh && eha_guard::protocol::GuardOutput::bit_eq(&fw.out, &host.out),
            "tick {k}: firmware {fw:?} != host {host:?}"
        );
    }

    // Ticks after the first sample that had no sample of their own.
    let first = run.ticks.iter().position(|(_, t)| t.fresh).unwrap_or(0);
    let guard_ticks: Vec<_> = run.ticks[first..].iter().map(|(_, t)| *t).collect();
    let missed = guard_ticks.iter().filter(|t| !t.fresh).count();

    // The longest run of consecutive missed ticks: (first index, length).
    let (gap_at, gap_len) = longest_miss_run(&guard_ticks);
    let stale_ticks = eha_guard::guard::GuardConfig::DEFAULT.stale_ticks as usize;
    if gap_len >= stale_ticks {
        let wall_ms = 1e3 * (run.ticks[first + gap_at + gap_len - 1].0 - run.ticks[(first + gap_at).saturating_sub(1)].0);
        let stale = eha_guard::faults::STALE;
        let latched = guard_ticks.iter().position(|t| t.out.faults.contains(stale)).unwrap_or(guard_ticks.len());
        assert!(latched >= gap_at + stale_ticks - 1, "STALE at guard tick {latched}, before the {stale_ticks}th miss of the stall at {gap_at}");
        assert!(
            guard_ticks[gap_at + gap_len - 1..].iter().all(|t| t.out.faults.contains(stale) && t.out.valve_open),
            "after {gap_len} missed ticks from guard tick {gap_at} the guard must hold STALE with the valve open"
        );
        return Err(format!(
            "fig15: host stall of {gap_len} ticks ({wall_ms:.0} ms between replies) at guard tick {gap_at}, {missed} ticks missed in all"
        ));
    }
    assert_eq!(run.samples.len(), 12_000);

    let elf = firmware_for_tests(Build::F32);
    let mut q = QemuOptions::new(Build::F32, &elf);
    q.icount = false;
    let pil = run_pil(&mut plant(duration_s), &q, &LoopOptions { tick_s: 0.01, duration_s })
        .unwrap_or_else(|f| panic!("{f}"));

    // In guard time (ticks since its first sample): a tick without its
    // sample is still a tick of the guard's clock (the harness pauses the
    // plant while the host is late; the guard's clock does not pause).
    let prod_ev = events(guard_ticks.iter().map(|t| t.out.valve_open));
    let pil_ev = events(pil.records.iter().map(|r| r.reply.out.valve_open));
    let max_diff = guard_ticks
        .iter()
        .zip(&pil.records)
        .map(|(t, r)| (t.out.drain_c - r.reply.out.drain_c).abs())
        .fold(0.0f32, f32::max);
    eprintln!(
        "product: {} samples, {} ticks, {missed} missed after the first sample; valve events product {prod_ev:?} pil {pil_ev:?}; \
         max |drain diff| {max_diff:.3e} K; overruns {}; worst tick {} cycles; stack boot {} B tick {} B",
        run.samples.len(),
        run.ticks.len(),
        st.counters.overruns,
        st.worst_tick_cycles,
        st.boot_stack_b,
        st.stack_high_water_b
    );
    assert!(!pil_ev.is_empty(), "the valve opens within 120 s (paper: 110 s)");
    assert_eq!(prod_ev.len(), pil_ev.len(), "valve events: product {prod_ev:?}, PIL {pil_ev:?}");
    // The product's estimate differs from the PIL's by at most `max_diff`
    // at every guard tick (bounded below), so its valve switches where the
    // PIL's estimate is within `max_diff` of its own value at the PIL's
    // switch (the threshold), give or take a tick: with every sample on
    // time that window is the PIL's tick itself. (With 21 late samples
    // an opening was measured 9 ticks after the PIL's at 0.026 K.)
    let pil_drain: Vec<f32> = pil.records.iter().map(|r| r.reply.out.drain_c).collect();
    for (a, b) in prod_ev.iter().zip(&pil_ev) {
        let at = pil_drain[b.0];
        let near = |k: &usize| (pil_drain[*k] - at).abs() <= max_diff;
        let lo = (0..=b.0).rev().take_while(near).last().unwrap_or(b.0);
        let hi = (b.0..pil_drain.len()).take_while(near).last().unwrap_or(b.0);
        assert!(
            a.1 == b.1 && a.0 + 1 >= lo && a.0 <= hi + 1,
            "valve event product {a:?} vs PIL {b:?}: outside PIL ticks {lo}..={hi}, where its drain is within {max_diff} K of {at} degC"
        );
    }
    if missed == 0 {
        assert_eq!(max_diff, 0.0, "every tick got its sample: the estimate must be bit-identical to the PIL's");
    } else {
        // Each tick without its sample shifts the later samples by one tick
        // against guard time, which can move a valve event (and its LNG
        // credit) by a tick: the difference is bounded by the PIL estimate's
        // largest change over (missed + 1) model steps of 10 ticks. (A fixed
        // 0.01 K, the earlier bound, was measured exceeded: 0.0159 K with 3
        // late samples, the closing moved by one tick.)
        let w = 10 * (missed + 1);
        let bound = pil.records.windows(w + 1).map(|r| (r[w].reply.out.drain_c - r[0].reply.out.drain_c).abs()).fold(0.0f32, f32::max);
        assert!(max_diff <= bound, "{missed} ticks missed their sample; max drain difference {max_diff} K > {bound} K in guard time");
    }
    // A late sample is a delay, never a loss: each of the 12 000 samples
    // was used by exactly one tick (checked above: every sample got its
    // fresh reply, with fewer than `stale_ticks` missed ticks in a row, so
    // none needed resending), and none was overwritten unused. How many come
    // late is the host's real-time quality, not the firmware's: the emulated
    // UART takes one byte per QEMU main-loop pass, and on a 2-core VM most
    // misses have the sample sent ~9 ms before the tick that lacked it
    // (docs/firmware.md); the count is printed, not asserted.
    assert_eq!(st.counters.superseded, 0, "a sample was overwritten before a tick used it");
    for p in &run.samples {
        assert_eq!(p.tick.pins, Pins::for_outputs(p.tick.out.valve_open, p.tick.out.alarm), "pins at sample {}", p.request.seq);
    }
    assert!(st.counters.overruns as usize * 100 <= run.samples.len(), "more than 1 % of ticks overran: {}", st.counters.overruns);
    // A clean link garbles nothing; a sample the harness sent again after it
    // came late (every 5 ticks without it) may arrive twice: the duplicate is
    // rejected by the sequence rule.
    assert_eq!(st.counters.rejected_crc + st.counters.rejected_framing, 0);
    assert!(usize::from(st.counters.rejected_sequence) <= missed, "{} duplicates for {missed} late samples", st.counters.rejected_sequence);
    assert!(st.boot_stack_b > 0 && st.boot_stack_b <= 4096, "boot stack {} B > 4 KiB", st.boot_stack_b);
    assert!(st.stack_high_water_b > 0 && st.stack_high_water_b <= 2048, "tick stack {} B > 2 KiB", st.stack_high_water_b);
    assert_eq!(run.samples[0].tick.reset_cause, ResetCause::PowerOn);
    assert_eq!(run.samples[0].tick.restore, RestoreKind::Cold);
    let _ = FromGuard::Tick(run.samples[0].tick);
    let _ = Cmd::Status;
    Ok(())
}

/// The longest run of consecutive ticks without their sample: (index of
/// its first tick, length); (0, 0) when every tick had its sample.
fn longest_miss_run(ticks: &[eha_guard::product::wire::TickReply]) -> (usize, usize) {
    let (mut best, mut start) = ((0, 0), 0);
    for (k, t) in ticks.iter().enumerate() {
        if t.fresh {
            start = k + 1;
        } else if k + 1 - start > best.1 {
            best = (start, k + 1 - start);
        }
    }
    best
}
