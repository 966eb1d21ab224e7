//! Commands: a single frame, a clear or a refill cannot restore trust or
//! close the valve faster than the rules allow.

use super::*;

/// Ticks `n` valid nominal samples (pump at rest, consistent sensors) and
/// returns the last tick reply; `cmds` are sent in the first tick.
fn settle(app: &mut App, b: &mut MemBoard, from: u16, n: u16, cmds: &[&[u8]]) -> TickReply {
    let mut last = None;
    for k in 0..n {
        if k == 0 {
            for c in cmds {
                b.push_rx(c);
            }
        }
        b.push_rx(&super::tests::at_rest(from.wrapping_add(k), 0.0, 5.0).encode());
        app.tick(b, 0);
        last = ticks_of(b).last().copied();
    }
    last.expect("a tick reply")
}

/// A CRC-valid clear frame (line noise that passes CRC-16, or a controller
/// bug) cleared every latched fault: it must not.
#[test]
fn one_crc_valid_frame_does_not_clear_faults() {
    let mut b = board();
    let mut app = boot(&mut b);
    b.push_rx(&super::tests::sample(0, f32::NAN, 5.0).encode());
    app.tick(&mut *b, 0);
    let r = settle(&mut app, &mut b, 1, 150, &[]);
    assert!(r.out.faults.contains(faults::NON_FINITE));
    // the frame the old protocol took as "clear faults": kind, token, code 1
    let raw = crate::protocol::frame(&[wire::KIND_COMMAND, 7, 0, 1], false);
    let r = settle(&mut app, &mut b, 151, 5, &[&raw]);
    assert!(r.out.faults.contains(faults::NON_FINITE), "a single CRC-valid frame cleared the faults: {:?}", r.out.faults);
}

/// After a start from an unknown thermal state (a corrupt record: every
/// node at 60 °C) a clear one second later restored trust at once; the
/// estimate needs hours to forget its start. The clear must not restore
/// trust before then.
#[test]
fn a_clear_does_not_restore_trust_faster_than_the_estimate_recovers() {
    let mut b = board();
    let mut torn = ThermalRecord::new([40.0; 6], 20.0, 0, 0, 1).with_seq(1, false);
    torn.crc ^= 1;
    b.records = [torn, torn];
    let mut app = boot(&mut b);
    let r = settle(&mut app, &mut b, 0, 150, &[]);
    assert!(r.out.faults.contains(faults::UNTRUSTED | faults::MEMORY_CORRUPT), "{:?}", r.out.faults);
    assert!(app.guard.clear_faults() != crate::ClearResult::Cleared || app.guard.faults().contains(faults::UNTRUSTED), "trust restored 1.5 s after an unknown start");
}

/// A refill with the valve open or the guard in alarm undid the empty-tank
/// and corrupt-boot rules: refused.
#[test]
fn a_refill_while_the_valve_is_open_is_refused() {
    let mut b = board();
    let mut torn = ThermalRecord::new([40.0; 6], 20.0, 0, 0, 1).with_seq(1, false);
    torn.crc ^= 1;
    b.records = [torn, torn];
    let mut app = boot(&mut b);
    let r = settle(&mut app, &mut b, 0, 50, &[]);
    assert!(r.out.valve_open && r.out.alarm && r.out.lng_remaining_kg == 0.0, "{:?}", r.out);
    let refill = crate::protocol::frame(&[wire::KIND_COMMAND, 8, 0, 2], false);
    let r = settle(&mut app, &mut b, 50, 5, &[&refill]);
    assert_eq!(r.out.lng_remaining_kg, 0.0, "refilled with the valve open and the alarm on");
    // armed and keyed: refused by the rule
    let a = super::tests::arm_confirm(&mut app, &mut b, 9, wire::Cmd::RefillArm, wire::Cmd::RefillConfirm, 55, &super::tests::at_rest(0, 0.0, 5.0));
    assert_eq!((a.result, a.value), (wire::AckResult::Refused, wire::Refusal::Rule as u32), "{a:?}");
    assert_eq!(app.guard.output().lng_remaining_kg, 0.0);
}

/// Arm-then-confirm: a wrong key, a confirmation after the arm's window, a
/// confirmation of the other command and a second clear within the
/// interval are refused, each with its reason in the ack and in the trace.
#[test]
fn armed_commands_need_the_key_the_window_and_the_interval() {
    use crate::product::tests::arm_confirm;
    use wire::{Ack, AckResult, Cmd, Command, FromGuard, Refusal};
    let mut b = board();
    let mut app = boot(&mut b);
    let rest = |k: u16| super::tests::at_rest(k, 0.0, 5.0);
    settle(&mut app, &mut b, 0, 200, &[]);
    let ack = |b: &mut MemBoard, token: u16| -> Ack {
        replies(b).iter().find_map(|f| match f {
            FromGuard::Ack(a) if a.token == token => Some(*a),
            _ => None,
        }).expect("an ack")
    };
    let arm = |app: &mut App, b: &mut MemBoard, token: u16, cmd: Cmd, seq: u16| -> u32 {
        b.push_rx(&Command { token, cmd, arg: 0 }.encode());
        b.push_rx(&rest(seq).encode());
        app.tick(&mut *b, 0);
        ack(b, token).value
    };
    let confirm = |app: &mut App, b: &mut MemBoard, token: u16, cmd: Cmd, arg: u32, seq: u16| -> Ack {
        b.push_rx(&Command { token, cmd, arg }.encode());
        b.push_rx(&rest(seq).encode());
        app.tick(&mut *b, 0);
        ack(b, token)
    };
    let refused = |a: Ack, r: Refusal| a.result == AckResult::Refused && a.value == r as u32;
    // no arm
    let a = confirm(&mut app, &mut b, 1, Cmd::ClearConfirm, 0, 200);
    assert!(refused(a, Refusal::NotArmed), "{a:?}");
    // a wrong key (the key of another nonce); the arm is used up
    let n = arm(&mut app, &mut b, 2, Cmd::ClearArm, 201);
    let a = confirm(&mut app, &mut b, 3, Cmd::ClearConfirm, wire::command_key(&[0; 16], n ^ 2, Cmd::ClearConfirm), 202);
    assert!(refused(a, Refusal::Key), "{a:?}");
    let a = confirm(&mut app, &mut b, 4, Cmd::ClearConfirm, wire::command_key(&[0; 16], n, Cmd::ClearConfirm), 203);
    assert!(refused(a, Refusal::NotArmed), "one try per arm: {a:?}");
    // the key of another rig
    let n = arm(&mut app, &mut b, 5, Cmd::ClearArm, 204);
    let a = confirm(&mut app, &mut b, 6, Cmd::ClearConfirm, wire::command_key(&[1; 16], n, Cmd::ClearConfirm), 205);
    assert!(refused(a, Refusal::Key), "{a:?}");
    // a refill confirmed on a clear's arm
    let n = arm(&mut app, &mut b, 7, Cmd::ClearArm, 206);
    let a = confirm(&mut app, &mut b, 8, Cmd::RefillConfirm, wire::command_key(&[0; 16], n, Cmd::RefillConfirm), 207);
    assert!(refused(a, Refusal::NotArmed), "{a:?}");
    // the window: 1 s
    let n = arm(&mut app, &mut b, 9, Cmd::ClearArm, 208);
    settle(&mut app, &mut b, 209, 101, &[]);
    let a = confirm(&mut app, &mut b, 10, Cmd::ClearConfirm, wire::command_key(&[0; 16], n, Cmd::ClearConfirm), 310);
    assert!(refused(a, Refusal::NotArmed), "{a:?}");
    // done, then a second one within 10 s is refused, after 10 s done
    let a = arm_confirm(&mut app, &mut b, 11, Cmd::ClearArm, Cmd::ClearConfirm, 311, &rest(0));
    assert_eq!(a.result, AckResult::Done, "{a:?}");
    let a = arm_confirm(&mut app, &mut b, 13, Cmd::ClearArm, Cmd::ClearConfirm, 313, &rest(0));
    assert!(refused(a, Refusal::TooSoon), "{a:?}");
    settle(&mut app, &mut b, 315, 1000, &[]);
    let a = arm_confirm(&mut app, &mut b, 15, Cmd::ClearArm, Cmd::ClearConfirm, 1315, &rest(0));
    assert_eq!(a.result, AckResult::Done, "{a:?}");
    // every one is in the trace (code, result)
    let t: std::vec::Vec<(u8, u8)> = app.guard.trace().iter().filter_map(|e| match *e {
        crate::trace::Trace::Command { code, result, .. } => Some((code, result)),
        _ => None,
    }).collect();
    let (k, na, too) = (Refusal::Key as u8, Refusal::NotArmed as u8, Refusal::TooSoon as u8);
    assert_eq!(t, [(5, na), (1, 0), (5, k), (5, na), (1, 0), (5, k), (1, 0), (6, na), (1, 0), (5, na), (1, 0), (5, 0), (1, 0), (5, too), (1, 0), (5, 0)]);
}

/// A clear cannot be a self-resetting latch: a controller confirming a
/// clear every tick clears at most once per 10 s.
#[test]
fn a_controller_clearing_in_a_loop_clears_at_most_every_ten_seconds() {
    use wire::{AckResult, Cmd, Command, FromGuard};
    let mut b = board();
    let mut app = boot(&mut b);
    let (mut done, mut rule) = (0u32, 0u32);
    let mut nonce = None;
    for k in 0..3000u16 {
        // arm and confirm on alternate ticks, the right key every time
        let c = match nonce.take() {
            Some(n) => Command { token: k, cmd: Cmd::ClearConfirm, arg: wire::command_key(&[0; 16], n, Cmd::ClearConfirm) },
            None => Command { token: k, cmd: Cmd::ClearArm, arg: 0 },
        };
        b.push_rx(&c.encode());
        b.push_rx(&super::tests::at_rest(k, 0.0, 5.0).encode());
        app.tick(&mut *b, 0);
        for f in replies(&mut b) {
            if let FromGuard::Ack(a) = f {
                match (a.cmd, a.result) {
                    (Cmd::ClearArm, AckResult::Done) => nonce = Some(a.value),
                    (Cmd::ClearConfirm, AckResult::Done) => done += 1,
                    (Cmd::ClearConfirm, AckResult::Refused) if a.value == wire::Refusal::Rule as u32 => rule += 1,
                    _ => {}
                }
            }
        }
    }
    // at ticks 1 (the clear rule's 1 s of valid samples not yet there),
    // 1001 and 2001
    assert_eq!((rule, done), (1, 2), "30 s of clears every 20 ms");
}
