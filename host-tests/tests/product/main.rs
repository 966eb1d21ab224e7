//! The product image (`eha-mps2`: the flashed application with the QEMU
//! board module) in QEMU, in real time, over its emulated UART: the
//! timer-driven tick, the watchdog, the fault handlers, the pins.
//!
//! These run in real time (10 ms ticks of QEMU's virtual clock = wall
//! time), so they are in the slow tier, as one test that runs the five
//! short scenarios at once, each in its own thread with its own QEMU (they
//! mostly sleep), then the 120 s closed loop alone: ~165 s. They are a
//! test binary of their own so that no other test competes with them for
//! the CPU (a host that answers late costs samples in real time). One
//! scenario alone: `EHA_PRODUCT=hang cargo test --profile fast -p eha-sim
//! --test product -- --ignored` (names: fig15, hang, panic, garbage, alarm,
//! params; a comma-separated list selects several).

/// The scenarios, by name.
const SCENARIOS: [(&str, fn()); 6] = [
    ("fig15", fig15_120s_closed_loop_over_the_uart_matches_the_semihosting_pil),
    ("hang", hang_is_reset_by_the_watchdog_with_safe_outputs_and_warm_restore),
    ("panic", panic_gives_safe_outputs_a_reset_and_warm_restore),
    ("garbage", garbage_and_bursts_on_the_uart_are_rejected_without_a_hang),
    ("alarm", alarm_pin_follows_the_60c_alarm),
    ("params", parameter_block_in_flash_runs_its_rig_and_an_invalid_one_is_refused),
];

/// Every product scenario in QEMU; fails with the names and messages of the
/// scenarios that failed. The short scenarios run concurrently, then the
/// 120 s closed loop alone: beside the other five (a 40 KiB UART burst,
/// reboots) its samples come late more often.
#[test]
#[ignore = "slow tier: ~165 s of real time in QEMU"]
fn product_image_in_qemu_over_the_uart() {
    require_qemu();
    product_elf().unwrap_or_else(|e| panic!("building eha-mps2: {e:#}"));
    let only = std::env::var("EHA_PRODUCT").ok();
    let selected = |name: &str| only.as_deref().is_none_or(|o| o.split(',').any(|o| o.trim() == name));
    let mut failed = run_concurrently(SCENARIOS.iter().filter(|(n, _)| *n != "fig15" && selected(n)));
    failed.extend(run_concurrently(SCENARIOS.iter().filter(|(n, _)| *n == "fig15" && selected(n))));
    assert!(failed.is_empty(), "product scenarios failed:\n{}", failed.join("\n"));
}

/// Runs `scenarios`, each in its own thread, and returns "name: message"
/// of each that panicked.
fn run_concurrently<'a>(scenarios: impl Iterator<Item = &'a (&'a str, fn())>) -> Vec<String> {
    std::thread::scope(|sc| {
        let handles: Vec<_> = scenarios.map(|(name, f)| (*name, sc.spawn(*f))).collect();
        handles
            .into_iter()
            .filter_map(|(name, h)| {
                h.join().err().map(|e| {
                    let msg = e.downcast_ref::<String>().cloned().or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()));
                    format!("{name}: {}", msg.unwrap_or_default())
                })
            })
            .collect()
    })
}

use std::time::{Duration, Instant};

use eha_guard::product::wire::{Cmd, FromGuard, Pins, ResetCause};
use eha_guard::trace::RestoreKind;
use eha_sim::pil::product::{product_elf, run_closed_loop, ProductSession};
use eha_sim::pil::{firmware_for_tests, require_qemu, run_pil, Build, LoopOptions, QemuOptions};
use eha_sim::plant::Plant;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;

fn session(extra: &[String]) -> ProductSession {
    require_qemu();
    let elf = product_elf().unwrap_or_else(|e| panic!("building eha-mps2: {e:#}"));
    ProductSession::spawn(&elf, extra).unwrap_or_else(|e| panic!("{e:#}"))
}

fn plant(duration_s: f64) -> Plant {
    Plant::new(&Rig::default(), &Scenario::Lng { duration_s }).unwrap_or_else(|e| panic!("plant: {e}"))
}

/// Valve transitions as (sample index, open).
fn events(v: impl Iterator<Item = bool>) -> Vec<(usize, bool)> {
    let mut last = None;
    let mut out = Vec::new();
    for (k, open) in v.enumerate() {
        if last.is_some_and(|l| l != open) {
            out.push((k, open));
        }
        last = Some(open);
    }
    out
}

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
fn fig15_120s_closed_loop_over_the_uart_matches_the_semihosting_pil() {
    retry_on_host_stall(fig15_attempt);
}

/// One closed-loop run of [`fig15_120s_closed_loop_over_the_uart_matches_the_semihosting_pil`]:
/// `Err(description)` of a host stall after which the fail-safe was
/// checked (panics on any failed check).
fn fig15_attempt() -> Result<(), String> {
    let duration_s = 120.0;
    let mut s = session(&[]);
    let run = run_closed_loop(&mut s, &mut plant(duration_s), duration_s, Duration::from_secs(2), &mut |_, _| Ok(true))
        .unwrap_or_else(|e| panic!("{e:#}"));
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
    for (a, b) in prod_ev.iter().zip(&pil_ev) {
        assert!(a.1 == b.1 && a.0.abs_diff(b.0) <= 1, "valve event product {a:?} vs PIL {b:?}");
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

/// Pin readings through the QEMU monitor from an injected fault until the
/// first tick reply after the reboot. Returns (seconds after the command,
/// pins) and the frames received meanwhile (put back in the backlog).
fn watch_pins_until_reboot(s: &mut ProductSession, token: u16, cmd: Cmd) -> anyhow::Result<Vec<(f64, Pins)>> {
    let t0 = Instant::now();
    s.command(token, cmd)?;
    let mut log = Vec::new();
    let mut kept = Vec::new();
    loop {
        log.push((t0.elapsed().as_secs_f64(), s.pins()?));
        if std::env::var_os("EHA_DEBUG").is_some() {
            eprintln!("watch {:?}", log.last());
        }
        if let Some(r) = s.next(Duration::from_millis(5))? {
            let rebooted = matches!(r.frame, FromGuard::Tick(t) if t.tick <= 2);
            kept.push(r);
            if rebooted {
                break;
            }
        }
        anyhow::ensure!(t0.elapsed() < Duration::from_secs(10), "no reboot within 10 s of {cmd:?}");
    }
    s.backlog.extend(kept);
    Ok(log)
}

/// What the injected-fault tests check after the reboot.
fn check_fault_reset(name: &str, cmd: Cmd, at_sample: u16, cause: ResetCause, max_unsafe_s: f64) -> Result<(), String> {
    let duration_s = f64::from(at_sample) * 0.01 + 5.0;
    let mut s = session(&[]);
    let mut pins_log = Vec::new();
    let mut before = None;
    let run = run_closed_loop(&mut s, &mut plant(duration_s), duration_s, Duration::from_secs(10), &mut |s, step| {
        if std::env::var_os("EHA_DEBUG").is_some() && step.request.seq % 100 == 0 {
            eprintln!("step {}", step.request.seq);
        }
        if step.request.seq == at_sample {
            before = Some(step.tick.out);
            pins_log = watch_pins_until_reboot(s, 99, cmd)?;
        }
        Ok(true)
    })
    .unwrap_or_else(|e| panic!("{name}: {e:#}"));
    let before: eha_guard::guard::Output = before.unwrap_or_else(|| panic!("{name}: the fault was never injected"));
    if before.faults.contains(eha_guard::faults::STALE) {
        // The host stalled the loop before the injection: the guard was in
        // its controller-silent fail-safe (valve open, estimate at the hot
        // side) when the fault hit, which is not the case under test.
        assert!(before.valve_open, "{name}: STALE without the valve open: {before:?}");
        return Err(format!("{name}: STALE latched before the injection (host stall), {} steps", run.samples.len()));
    }
    // Safe for the pump = the valve pin low (valve open). The OK pin is low
    // only from the handler to the reboot's boot (microseconds of emulated
    // time, usually between two monitor readings); after the warm boot it
    // shows the restored estimate's alarm state.
    let first_safe = pins_log.iter().find(|(_, p)| !p.valve_pin).map(|(t, _)| *t);
    let after: Vec<_> = run.samples.iter().filter(|p| p.request.seq > at_sample).collect();
    let first = after.first().unwrap_or_else(|| panic!("{name}: no sample after the reboot"));
    eprintln!(
        "{name}: drain before {:.3} C, first after reboot {:.3} C (cause {:?}, restore {:?}); outputs safe {:?} s after the command; {} pin readings",
        before.drain_c,
        first.tick.out.drain_c,
        first.tick.reset_cause,
        first.tick.restore,
        first_safe,
        pins_log.len()
    );
    assert_eq!(first.tick.reset_cause, cause, "{name}: reset cause");
    assert_eq!(first.tick.restore, RestoreKind::Warm, "{name}: warm restore from the no-init record");
    let t_safe = first_safe.unwrap_or_else(|| panic!("{name}: the pins never reached the safe state: {pins_log:?}"));
    assert!(t_safe <= max_unsafe_s, "{name}: outputs safe only {t_safe:.3} s after the fault (bound {max_unsafe_s} s)");
    let k = pins_log.iter().position(|(t, _)| *t >= t_safe).unwrap_or(0);
    assert!(
        pins_log[k..].iter().all(|(_, p)| !p.valve_pin),
        "{name}: the valve left its safe (open) state during the reset: {:?}",
        &pins_log[k..]
    );
    // The plant is held while the MCU resets, so the estimate must continue
    // from where it was: within 0.1 K (one tick of heating is ~0.002 K).
    assert!((first.tick.out.drain_c - before.drain_c).abs() <= 0.1, "{name}: estimate jumped {} -> {}", before.drain_c, first.tick.out.drain_c);
    assert_eq!(run.samples.len(), (duration_s / 0.01).round() as usize, "{name}: the closed loop completed after the reboot");
    Ok(())
}

/// Runs a real-time scenario that returns `Err(description)` when a host
/// stall made the guard latch STALE (its correct controller-silent
/// response, checked by the scenario) where the case under test needs live
/// samples; repeats it once, and fails when the host stalls both runs.
fn retry_on_host_stall(f: impl Fn() -> Result<(), String>) {
    let mut stalls = Vec::new();
    for _ in 0..2 {
        match f() {
            Ok(()) => return,
            Err(stall) => {
                eprintln!("{stall}; scenario repeated");
                stalls.push(stall);
            }
        }
    }
    panic!("the host stalled the scenario in both runs: {stalls:?}");
}

/// A hang injected after 30 s: the watchdog (0.5 s warning period) resets
/// the MCU; the outputs are safe within the watchdog period plus margin and
/// stay safe through the reset; the thermal state is restored warm.
fn hang_is_reset_by_the_watchdog_with_safe_outputs_and_warm_restore() {
    retry_on_host_stall(|| check_fault_reset("hang", Cmd::InjectHang, 3000, ResetCause::Watchdog, 0.5 + 0.3));
}

/// A panic injected after 5 s: the panic handler makes the outputs safe,
/// records the cause and resets; warm restore.
fn panic_gives_safe_outputs_a_reset_and_warm_restore() {
    retry_on_host_stall(|| check_fault_reset("panic", Cmd::InjectPanic, 500, ResetCause::Panic, 0.1));
}

/// Garbage, bursts longer than the receive buffer and truncated frames on
/// the UART during a closed-loop run: no hang (the loop completes, ticks
/// keep their 100 Hz, no overrun), the junk is counted as rejected (an
/// over-long frame once), no junk is taken as sample data.
fn garbage_and_bursts_on_the_uart_are_rejected_without_a_hang() {
    use rand::{Rng, SeedableRng};
    let duration_s = 10.0;
    let mut s = session(&[]);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let run = run_closed_loop(&mut s, &mut plant(duration_s), duration_s, Duration::from_secs(2), &mut |s, step| {
        let k = step.request.seq;
        if k % 50 == 25 {
            // A burst of random bytes (zeros included), up to 600 long.
            let n = rng.random_range(1..600);
            let junk: Vec<u8> = (0..n).map(|_| rng.random()).collect();
            s.send(&junk)?;
            s.send(&[0])?;
        } else if k % 50 == 40 {
            // A truncated sample frame, then the delimiter.
            let f = step.request.encode();
            s.send(&f[..f.len() / 2])?;
            s.send(&[0])?;
        }
        Ok(true)
    })
    .unwrap_or_else(|e| panic!("{e:#}"));
    let mut ticks = Vec::new();
    let st = s.status(5, &mut ticks).unwrap_or_else(|e| panic!("{e:#}"));
    let (t_first, _) = run.ticks[0];
    let (t_last, _) = *run.ticks.last().unwrap();
    let rate = (run.ticks.len() - 1) as f64 / (t_last - t_first);
    eprintln!("garbage: {} ticks at {rate:.1} Hz; status {st:?}", run.ticks.len());
    assert_eq!(run.samples.len(), 1000, "every sample eventually got its tick");
    assert!(st.counters.rejected_crc + st.counters.rejected_framing >= 20, "20 junk bursts and 20 truncated frames: {st:?}");
    assert!((90.0..=110.0).contains(&rate), "tick rate {rate} Hz");
    assert!(st.counters.overruns * 100 <= 1000, "more than 1 % of ticks overran (host descheduling QEMU): {}", st.counters.overruns);
    // Junk never reaches the guard as data: no range, rate or non-finite
    // fault. (A sample stuck behind a long burst arrives late; more than
    // 50 ms late is STALE, which is what STALE is for, so it may latch.)
    let data_faults = eha_guard::faults::RANGE | eha_guard::faults::RATE | eha_guard::faults::NON_FINITE;
    assert!(run.samples.iter().all(|p| !p.tick.out.faults.intersects(data_faults)), "junk was taken as sample data");
    // A frame longer than any valid frame (4 KiB of non-zero bytes, then the
    // delimiter) is dropped by the frame decoder and counted once as a
    // framing reject; the firmware still answers. Whether bytes are also
    // dropped from the 256-byte receive ring depends on QEMU handing the
    // guest more than 256 bytes within one 10 ms tick, i.e. on the host's
    // speed (on the 2-core CI machine it never did, even for 40 KiB), so
    // the ring's drop counter is reported, not asserted.
    let junk: Vec<u8> = (0..4096).map(|_| rng.random_range(1..=255)).collect();
    s.send(&junk).unwrap_or_else(|e| panic!("{e:#}"));
    s.send(&[0]).unwrap_or_else(|e| panic!("{e:#}"));
    std::thread::sleep(Duration::from_millis(200));
    // A second delimiter: if the ring dropped the first one, the junk frame
    // still ends before the status command.
    s.send(&[0]).unwrap_or_else(|e| panic!("{e:#}"));
    let st2 = s.status(6, &mut ticks).unwrap_or_else(|e| panic!("{e:#}"));
    eprintln!("garbage: after a 4 KiB frame: rejected_framing {} -> {}, rx_overflow {}", st.counters.rejected_framing, st2.counters.rejected_framing, st2.rx_overflow);
    assert!(st2.counters.rejected_framing > st.counters.rejected_framing, "the 4 KiB frame is rejected and counted: {st2:?}");
    if st2.rx_overflow == 0 {
        assert_eq!(st2.counters.rejected_framing, st.counters.rejected_framing + 1, "no byte dropped, so exactly one framing reject: {st2:?}");
    }
}

/// The OK (alarm) pin follows the 60 °C alarm: the MCU boots with a warm
/// thermal record at 59.8 °C put in no-init RAM (through QEMU's gdb stub), as
/// after a reset on a hot machine; in closed loop at 60 bar the estimate
/// rises through 60 °C and the alarm is raised (measured with the pump's energy balance: from
/// 59 °C the estimate peaked at 59.32 °C after 6 s with the exchanger on,
/// then fell; from 59.8 °C it crosses 60 °C on the way up). In every tick reply the OK
/// pin read back is the inverse of the alarm, before and after the edge.
fn alarm_pin_follows_the_60c_alarm() {
    retry_on_host_stall(alarm_attempt);
}

/// One run of [`alarm_pin_follows_the_60c_alarm`]; `Err` on a host stall.
fn alarm_attempt() -> Result<(), String> {
    let elf = product_elf().unwrap_or_else(|e| panic!("{e:#}"));
    let addr = eha_sim::pil::product::symbol_addr(&elf, &["noinit", "RECORD_A"]).unwrap_or_else(|e| panic!("{e:#}"));
    let rec = eha_guard::ThermalRecord::new([59.8; eha_guard::params::N_NODES], 26.0, 0, 0, 1000).with_seq(1, true);
    let duration_s = 20.0;
    let mut s = ProductSession::spawn_with_ram(&elf, &[], &[(addr, eha_sim::pil::product::record_bytes(&rec))])
        .unwrap_or_else(|e| panic!("{e:#}"));
    let run = run_closed_loop(&mut s, &mut plant(duration_s), duration_s, Duration::from_secs(2), &mut |_, _| Ok(true))
        .unwrap_or_else(|e| panic!("{e:#}"));
    if let Some(t) = stale_tick(&run) {
        return Err(format!("alarm: STALE latched at tick {t} (host stall)"));
    }
    let alarm: Vec<bool> = run.ticks.iter().map(|(_, t)| t.out.alarm).collect();
    let raised = alarm.iter().position(|a| *a);
    eprintln!(
        "alarm: restore {:?}, first drain {:.2} C, alarm raised at tick {raised:?} (drain then {:?})",
        run.ticks[0].1.restore,
        run.ticks[0].1.out.drain_c,
        raised.map(|k| run.ticks[k].1.out.drain_c)
    );
    assert_eq!(run.ticks[0].1.restore, RestoreKind::Warm);
    assert!(!alarm[0], "59.8 C restored: no alarm at first");
    let k = raised.unwrap_or_else(|| panic!("the estimate never rose above 60 C"));
    assert!(run.ticks[k].1.out.drain_c > 60.0, "alarm raised above 60 C");
    assert!(alarm[k..].iter().all(|a| *a), "no chatter: the alarm clears only below 58 C");
    for (_, t) in &run.ticks {
        assert_eq!(t.pins.ok_pin, !t.out.alarm, "tick {}: OK pin {} with alarm {}", t.tick, t.pins.ok_pin, t.out.alarm);
    }
    Ok(())
}

/// The first tick whose output carries STALE (the guard saw `stale_ticks`
/// ticks in a row without a sample), with its fail-safe checked: valve
/// open from there on.
fn stale_tick(run: &eha_sim::pil::product::ProductRun) -> Option<u32> {
    let stale = eha_guard::faults::STALE;
    let k = run.ticks.iter().position(|(_, t)| t.out.faults.contains(stale))?;
    assert!(run.ticks[k..].iter().all(|(_, t)| t.out.valve_open), "STALE without the valve open after tick {}", run.ticks[k].1.tick);
    Some(run.ticks[k].1.tick)
}


/// Writes `block` to a file for QEMU's generic loader and returns the QEMU
/// arguments that put it at the mps2 PARAMS region (boards/mps2/memory.x).
fn loader_args(name: &str, block: &[u8]) -> Vec<String> {
    let path = std::env::temp_dir().join(format!("eha-params-{}-{name}.bin", std::process::id()));
    std::fs::write(&path, block).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    vec!["-device".into(), format!("loader,file={},addr=0x3F000", path.display())]
}

/// A parameter block for another EHA loaded into the product image's flash:
/// the firmware predicts for that rig, bit-identical to the host build of the
/// same application with the same block, and not for the paper rig; the
/// replies say commissioned. An invalid block (one flipped bit) latches
/// CONFIG with the valve open from the first tick.
fn parameter_block_in_flash_runs_its_rig_and_an_invalid_one_is_refused() {
    retry_on_host_stall(params_attempt);
}

/// One run of [`parameter_block_in_flash_runs_its_rig_and_an_invalid_one_is_refused`];
/// `Err` on a host stall during the 30 s closed loop.
fn params_attempt() -> Result<(), String> {
    // Another EHA: 30 % more pump friction (eta_m), a 30 % lighter pump
    // housing, a 30 % better case-oil film; Phi recomputed for it; and a
    // commissioning margin of 1.5 K (the image adds it as the host does).
    let mut other = eha_guard::params::DEFAULT;
    other.eta_m *= 1.3;
    other.drain_margin_k = 1.5;
    other.pump_j_per_k *= 0.7;
    for g in other.g_case_w_per_k.iter_mut() {
        *g *= 1.3;
    }
    let other = eha_sim::params_block::rediscretise(&other).expect("other rig");
    let block = eha_sim::params_block::block_for(&other, "other-eha").unwrap_or_else(|e| panic!("{e:#}"));
    let duration_s = 30.0;
    let mut s = session(&loader_args("other", &block));
    let run = run_closed_loop(&mut s, &mut plant(duration_s), duration_s, Duration::from_secs(2), &mut |_, _| Ok(true))
        .unwrap_or_else(|e| panic!("{e:#}"));
    drop(s);
    if let Some(t) = stale_tick(&run) {
        return Err(format!("params: STALE latched at tick {t} (host stall)"));
    }
    let with_block = eha_sim::pil::product::sil_replay_with_block(&run, Some(&block));
    let paper = eha_sim::pil::product::sil_replay(&run);
    assert_eq!(with_block.len(), run.ticks.len());
    for (k, ((_, fw), host)) in run.ticks.iter().zip(&with_block).enumerate() {
        assert!(!fw.not_commissioned, "tick {k}: the block is in flash");
        assert!(
            fw.tick == host.tick && eha_guard::protocol::GuardOutput::bit_eq(&fw.out, &host.out),
            "tick {k}: firmware {fw:?} != host with the block {host:?}"
        );
    }
    // After 30 s of Case-1-like load the two rigs' drain estimates differ by
    // more than f32 noise: the firmware did not run the paper rig.
    let (fw_last, paper_last) = (run.ticks.last().map(|t| t.1.out.drain_c), paper.last().map(|t| t.out.drain_c));
    let (Some(a), Some(b)) = (fw_last, paper_last) else { panic!("no ticks") };
    eprintln!("params: other rig drain {a:.4} degC, paper rig {b:.4} degC after {duration_s} s");
    assert!((a - b).abs() > 0.01, "other rig {a} vs paper rig {b}");

    let mut torn = block;
    torn[600] ^= 0x04;
    let mut s = session(&loader_args("torn", &torn));
    let mut others = Vec::new();
    let mut seen = Vec::new();
    for seq in 0..20u16 {
        s.send_sample(&eha_sim::pil::PlantSensors::default().request(seq)).unwrap_or_else(|e| panic!("{e:#}"));
        if let Some((_, t)) = s.next_tick(Duration::from_secs(2), &mut others).unwrap_or_else(|e| panic!("{e:#}")) {
            seen.push(t);
        }
    }
    let pins = s.pins().unwrap_or_else(|e| panic!("{e:#}"));
    assert!(!seen.is_empty());
    for t in &seen {
        assert!(t.out.faults.intersects(eha_guard::faults::CONFIG) && t.out.valve_open && !t.pins.valve_pin, "torn block: {t:?}");
    }
    assert!(!pins.valve_pin && !pins.ok_pin, "torn block: valve open and alarm on the pins, read {pins:?}");
    Ok(())
}
