//! The safety case on the product loop: every path that could leave the
//! valve closed while the oil may be hot, or let a fault clear itself, has a
//! test here, by topic: the thermal memory and the flash ([`memory`]), the
//! parameter block ([`config`]), the inputs the estimate trusts — speed,
//! actuator, cooling confirmation — ([`inputs`]), the commands ([`commands`]).

extern crate std;

use super::tests::{board, replies, sample, ticks};
use super::*;
use crate::memory::ThermalRecord;
use crate::faults;
use crate::memory::nv::NvPolicy;
use crate::memory::Restore;
use crate::params_block;
use mem_board::MemBoard;
use std::boxed::Box;

mod commands;
mod config;
mod inputs;
mod memory;

/// A board with a non-volatile store and a clock at `rtc_s`.
fn nv_board(rtc_s: u32) -> Box<MemBoard> {
    let mut b = Box::new(MemBoard::new().with_nv());
    b.rtc = Some(rtc_s);
    b.rtc_backup = Some(0);
    b
}

/// Boots on `b` from what its memories hold.
fn boot(b: &mut MemBoard) -> App {
    let mem = b.boot_memory();
    App::boot(b, &GuardConfig::DEFAULT, &mem)
}

/// A hot record (55-60 °C) stamped at `rtc_s`.
fn hot_record(rtc_s: u32) -> ThermalRecord {
    ThermalRecord::new([55.0, 60.0, 50.0, 45.0, 40.0, 30.0], 20.0, 5_000_000, 0, 100).with_seq(7, true).with_rtc(Some(rtc_s))
}

/// One tick with the nominal sample `k`; the tick reply.
fn tick(app: &mut App, b: &mut MemBoard, k: u32) -> TickReply {
    b.push_rx(&sample((k & 0xFFFF) as u16, 20.0, 40.0).encode());
    app.tick(b, 0);
    *ticks(&replies(b)).last().expect("a tick reply")
}

/// The motor current of the paper rig's pump at these pressures and speed
/// and this case-oil temperature (the extended eq. 8 with the viscous
/// friction on the oil's viscosity, as the reference plant draws it):
/// consistent sensors for the cross-check.
fn current_a(p_a: f32, p_b: f32, rpm: f32, oil_c: f32) -> f32 {
    let p = &crate::params::DEFAULT;
    let d = p.displacement_m3_per_rad as f32;
    let dp = (p_a - p_b) * 1e5;
    let w = (rpm * core::f32::consts::PI / 30.0).abs();
    let t_f = p.no_load_torque_nm as f32 + (p.viscous_w_s2_per_rad2 * p.visc_ratio_at(f64::from(oil_c))) as f32 * w + p.eta_m as f32 * d * dp.abs();
    let s = if rpm < 0.0 { -1.0 } else { 1.0 };
    (d * dp + s * t_f).abs() / p.torque_constant_nm_per_a as f32
}

fn ticks_of(b: &mut MemBoard) -> std::vec::Vec<TickReply> {
    ticks(&replies(b))
}
