//! Closed-loop LNG case with the guard (f64) commanding the exchanger: prints the
//! true drain, the guard's estimate and the valve every 2.5 s around the cycles.
//! `cargo run --release -p eha-sim --example lng_probe`
use eha_guard::{GuardConfig, GuardOf, Restore};
use eha_sim::plant::{Control, Plant, Sensors};
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;

fn main() -> anyhow::Result<()> {
    let sc = Scenario::Lng { duration_s: 300.0 };
    let mut plant = Plant::new(&Rig::default(), &sc)?;
    let mut g = GuardOf::<f64>::new(&GuardConfig::DEFAULT, Restore::Cold);
    let mut k = 0usize;
    let mut last_pred = f64::NAN;
    plant.run(0.01, 300.0, |snap| {
        let s = Sensors::from(snap);
        if k % 250 == 0 && s.t > 60.0 {
            println!("{:7.2}  true {:7.3}  pred(prev) {:7.3}  err {:+.3}  loop {:7.3}  valve {}", s.t, s.t_drain_c, last_pred, last_pred - s.t_drain_c, s.t_loop_oil_c, s.lng_open as u8);
        }
        k += 1;
        let o = g.step(&s.sample());
        last_pred = o.drain_c as f64;
        Ok(Control { lng_valve: Some(o.valve_open), stop: false })
    })?;
    Ok(())
}
