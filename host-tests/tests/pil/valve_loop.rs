//! The loop applies the guard's valve command to the reference plant.
//!
//! Host-only (SIL, no QEMU): the real guard with its valve threshold lowered
//! to 19 °C, so that it opens early in the Fig. 15 case even before the
//! firmware parameters are identified, drives the real plant through the
//! same `run_closed_loop` as the PIL runs. Checked against the plant's own
//! account: the plant used LNG (eq. 24) only while commanded, and its true
//! drain temperature ends lower than in the same run with the valve held shut.

use eha_guard::GuardConfig;
use eha_sim::pil::sil::SilTarget;
use eha_sim::pil::{run_closed_loop, Build, LoopOptions, PilError, Target, TickOut, TickRecord};
use eha_sim::plant::Plant;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;

/// `open_c`: the guard's valve threshold; `None`: no guard, the valve held shut.
fn closed_loop(open_c: Option<f32>) -> (Vec<TickRecord>, Plant) {
    let mut cfg = GuardConfig::DEFAULT;
    cfg.valve.open_c = open_c.unwrap_or(40.0);
    cfg.valve.close_c = cfg.valve.open_c - 2.0;
    let mut app = SilTarget::with_config(Build::F32, &cfg);
    // no guard: the valve held shut
    let mut sil = move |rx: &[u8], k: u64| -> Result<TickOut, PilError> {
        let mut o = app.tick(rx, k)?;
        if open_c.is_none() {
            o.reply.out = eha_guard::Output::default();
        }
        Ok(o)
    };
    let mut sil = FnTarget(&mut sil);
    let duration_s = 120.0;
    let mut plant = Plant::new(&Rig::default(), &Scenario::Lng { duration_s }).unwrap();
    let opts = LoopOptions { tick_s: eha_guard::params::S_PER_TICK, duration_s };
    let records = run_closed_loop(&mut plant, &mut sil, &opts).unwrap_or_else(|f| panic!("{:#}", f.error));
    (records, plant)
}

/// One tick of a target: the received bytes and the tick number in, the
/// tick's outputs out.
type TickFn = dyn FnMut(&[u8], u64) -> Result<TickOut, PilError>;

/// A target made of a closure.
struct FnTarget<'a>(&'a mut TickFn);

impl Target for FnTarget<'_> {
    fn tick(&mut self, rx: &[u8], tick: u64) -> Result<TickOut, PilError> {
        (self.0)(rx, tick)
    }
}

#[test]
fn valve_command_reaches_the_plant() {
    let (open, plant_open) = closed_loop(Some(19.0));
    let (shut, plant_shut) = closed_loop(None);
    let t_open = open.iter().find(|r| r.reply.out.valve_open).map(|r| r.t_s).expect("guard opened at 19 °C");
    let used_open = plant_open.snapshot().lng_used_kg;
    let used_shut = plant_shut.snapshot().lng_used_kg;
    let end_open = open.last().unwrap().sensors.t_drain_c;
    let end_shut = shut.last().unwrap().sensors.t_drain_c;
    eprintln!("valve opened at {t_open:.2} s; plant LNG used {used_open:.4} kg (shut run {used_shut:.4}); final true drain {end_open:.3} vs {end_shut:.3} °C");
    assert_eq!(used_shut, 0.0, "no LNG without a valve command");
    assert!(used_open > 0.0, "the plant must use LNG after the guard opened the valve");
    assert!(end_open < end_shut - 0.1, "LNG cooling must lower the true drain temperature");
    // Before the valve opened, both runs saw identical plants (lockstep, same inputs).
    let k = open.iter().position(|r| r.reply.out.valve_open).unwrap();
    assert_eq!(open[k].sensors.t_drain_c.to_bits(), shut[k].sensors.t_drain_c.to_bits());
}
