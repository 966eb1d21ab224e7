//! The product loop with and without a commissioned parameter block in
//! flash: the default rig, another rig, a margin, an invalid block.

use super::*;
use crate::params_block;

/// No block (erased flash, or a board without the region): the compiled-in
/// paper rig runs, every tick reply says NOT_COMMISSIONED, the trace says why.
#[test]
fn without_a_block_the_default_runs_and_every_reply_says_not_commissioned() {
    for block in [None, Some(flash_block([0xFF; BLOCK_LEN]))] {
        let mut b = board();
        b.block = block;
        let mem = b.boot_memory();
        let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
        assert_eq!(app.params(), ParamSource::Default);
        for k in 0..30u16 {
            b.push_rx(&sample(k, 20.0, 60.0).encode());
            app.tick(&mut *b, 0);
        }
        let t = ticks(&replies(&mut b));
        assert!(t.iter().all(|r| r.not_commissioned && r.out.faults.is_empty()), "{t:?}");
        assert!(app.guard().trace().iter().any(|e| matches!(e, Trace::Params { source: 0, .. })));
    }
}

/// A valid block for another rig: the guard predicts with that rig's
/// constants, bit-identical to a bare guard built from them, higher than the
/// paper rig's (1.5× the pump's friction heat), and the replies say
/// commissioned.
#[test]
fn a_valid_block_runs_its_own_rig() {
    let other = other_rig();
    let mut b = board();
    b.block = Some(flash_block(params_block::encode(&other, "other-eha")));
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    assert_eq!(app.params(), ParamSource::Block);
    let mut bare = Guard::new(&GuardConfig { model: &other, ..GuardConfig::DEFAULT }, Restore::Cold);
    let mut paper = Guard::new(&GuardConfig::DEFAULT, Restore::Cold);
    let (mut last, mut last_paper) = (0.0, 0.0);
    for k in 0..3000u16 {
        let s = sample(k, 30.0, 60.0);
        b.push_rx(&s.encode());
        app.tick(&mut *b, 0);
        let want = bare.tick(&s.sample);
        last_paper = paper.tick(&s.sample).drain_c;
        let t = ticks(&replies(&mut b));
        assert!(!t[0].not_commissioned);
        assert!(crate::protocol::GuardOutput::bit_eq(&t[0].out, &want), "tick {k}: {:?} vs {want:?}", t[0].out);
        last = want.drain_c;
    }
    // 30 s at 60 bar, 500 rpm: the other rig's drain runs warmer (more friction heat)
    assert!(last > last_paper + 0.01, "other rig {last} degC vs paper rig {last_paper} degC");
    assert!(app.guard().trace().iter().any(|e| matches!(e, Trace::Params { source: 1, .. })));
}

/// A block with a commissioning margin: the tick replies carry the model's
/// drain plus the margin (the f32 sum, exactly), the valve and alarm follow
/// that estimate (bit-identical to a bare guard with the block's constants),
/// and the thermal record keeps the model's own temperatures.
#[test]
fn a_blocks_margin_reaches_the_replies_not_the_record() {
    let with = crate::model::ModelConsts { drain_margin_k: 2.5, ..other_rig() };
    let without = other_rig();
    let mut b = board();
    b.block = Some(flash_block(params_block::encode(&with, "margin")));
    let mem = b.boot_memory();
    let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
    assert_eq!(app.params(), ParamSource::Block);
    let mut bare = Guard::new(&GuardConfig { model: &with, ..GuardConfig::DEFAULT }, Restore::Cold);
    let mut plain = Guard::new(&GuardConfig { model: &without, ..GuardConfig::DEFAULT }, Restore::Cold);
    let mut known = 0;
    for k in 0..300u16 {
        let s = sample(k, 30.0, 60.0);
        b.push_rx(&s.encode());
        app.tick(&mut *b, 0);
        let want = bare.tick(&s.sample);
        let model = plain.tick(&s.sample).drain_c;
        let t = ticks(&replies(&mut b));
        assert!(crate::protocol::GuardOutput::bit_eq(&t[0].out, &want), "tick {k}: {:?} vs {want:?}", t[0].out);
        if model != crate::guard::DRAIN_C_UNKNOWN {
            assert_eq!(t[0].out.drain_c.to_bits(), (model + 2.5).to_bits(), "tick {k}");
            known += 1;
        }
    }
    assert!(known >= 290, "{known} ticks with an estimate");
    assert_eq!(app.guard().snapshot().temps_c, plain.snapshot().temps_c);
}

/// A block that fails its checks (a flipped bit: CRC; or constants whose Phi
/// belongs to another rig: stability) latches CONFIG and opens the valve from
/// the first tick, and CONFIG cannot be cleared.
#[test]
fn an_invalid_block_latches_config_and_opens_the_valve() {
    let mut torn = params_block::encode(&other_rig(), "torn");
    torn[500] ^= 0x10;
    let mut wrong_phi = other_rig();
    for g in wrong_phi.g_loop.iter_mut() {
        *g *= 1.5;
    }
    // the commissioning margin on the cold side, not a number, over its 10 K
    let margin = |m: f32| params_block::encode(&crate::model::ModelConsts { drain_margin_k: m, ..other_rig() }, "bad-margin");
    for (name, bytes, source) in [
        ("torn", torn, ParamSource::Invalid(params_block::BlockError::Crc)),
        ("phi of another rig", params_block::encode(&wrong_phi, "bad-phi"), ParamSource::Block),
        ("negative margin", margin(-0.5), ParamSource::Block),
        ("NaN margin", margin(f32::NAN), ParamSource::Block),
        ("margin over 10 K", margin(10.5), ParamSource::Block),
    ] {
        let mut b = board();
        b.block = Some(flash_block(bytes));
        let mem = b.boot_memory();
        let mut app = App::boot(&mut *b, &GuardConfig::DEFAULT, &mem);
        assert_eq!(app.params(), source, "{name}");
        assert!(!b.pins.valve_pin, "{name}: valve open (pin low) from boot");
        for k in 0..50u16 {
            b.push_rx(&sample(k, 20.0, 60.0).encode());
            app.tick(&mut *b, 0);
        }
        b.push_rx(&Command { token: 7, cmd: Cmd::ClearConfirm, arg: 0 }.encode());
        app.tick(&mut *b, 0);
        let t = ticks(&replies(&mut b));
        assert!(
            t.iter().all(|r| r.out.faults.intersects(crate::faults::CONFIG) && r.out.valve_open && !r.pins.valve_pin && r.out.alarm),
            "{name}: {t:?}"
        );
    }
}
