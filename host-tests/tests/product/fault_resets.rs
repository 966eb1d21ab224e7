//! Injected faults (a hang, a panic): safe pins through the reset, the
//! cause recorded, a warm restore.

use super::*;

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

/// A hang injected after 30 s: the watchdog (0.5 s warning period) resets
/// the MCU; the outputs are safe within the watchdog period plus margin and
/// stay safe through the reset; the thermal state is restored warm.
pub(super) fn hang_is_reset_by_the_watchdog_with_safe_outputs_and_warm_restore() {
    retry_on_host_stall(|| check_fault_reset("hang", Cmd::InjectHang, 3000, ResetCause::Watchdog, 0.5 + 0.3));
}

/// A panic injected after 5 s: the panic handler makes the outputs safe,
/// records the cause and resets; warm restore.
pub(super) fn panic_gives_safe_outputs_a_reset_and_warm_restore() {
    retry_on_host_stall(|| check_fault_reset("panic", Cmd::InjectPanic, 500, ResetCause::Panic, 0.1));
}
