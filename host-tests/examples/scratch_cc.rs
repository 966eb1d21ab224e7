use eha_guard::{GuardConfig, GuardOf, Restore};
use eha_sim::plant::{Control, Plant, Sensors};
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
fn main() {
    let mut rig = Rig::default();
    rig.lng.flow_kg_per_s = 0.0;
    let sc = Scenario::Case1 { needle_bar: 60.0, duration_s: 3600.0 };
    let mut plant = Plant::new(&rig, &sc).unwrap();
    let mut cfg = GuardConfig::DEFAULT;
    cfg.lng.charge_l = 0.0;
    let mut guard = GuardOf::<f64>::new(&cfg, Restore::Cold);
    let mut k = 0;
    plant.run(0.01, 3600.0, |snap| {
        let tr = snap.temps;
        let s = Sensors::from(snap);
        let o = guard.tick(&s.sample());
        k += 1;
        if k % 6000 == 1 && s.t > 2700.0 {
            let st = guard.model().unwrap().states_c();
            println!("t {:.0} err {:+.3} drain {:.2} | pump {:.2}/{:.2} int {:.2}/{:.2} loop {:.2}/{:.2} motor {:.2}/{:.2} block {:.2}/{:.2} ball {:.2}/{:.2} act {:.2}/{:.2} wind {:.2}/{:.2}", s.t, o.drain_c as f64 - s.t_drain_c, s.t_drain_c,
              st[0], tr[2], st[6], tr[12], st[2], tr[6], st[7], tr[1], st[3], tr[7], st[4], tr[8], st[5], tr[11], st[8], tr[0]);
        }
        Ok(Control { lng_valve: Some(o.valve_open), stop: false })
    }).unwrap();
}
