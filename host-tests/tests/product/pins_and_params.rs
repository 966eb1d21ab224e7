//! The 60 °C alarm pin, and a parameter block in flash (another rig; an
//! invalid block refused).

use super::*;

/// The OK (alarm) pin follows the 60 °C alarm: the MCU boots with a warm
/// thermal record at 59.8 °C put in no-init RAM (through QEMU's gdb stub), as
/// after a reset on a hot machine; in closed loop at 60 bar the estimate
/// rises through 60 °C and the alarm is raised (measured with the pump's energy balance: from
/// 59 °C the estimate peaked at 59.32 °C after 6 s with the exchanger on,
/// then fell; from 59.8 °C it crosses 60 °C on the way up). In every tick reply the OK
/// pin read back is the inverse of the alarm, before and after the edge.
pub(super) fn alarm_pin_follows_the_60c_alarm() {
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
pub(super) fn parameter_block_in_flash_runs_its_rig_and_an_invalid_one_is_refused() {
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
