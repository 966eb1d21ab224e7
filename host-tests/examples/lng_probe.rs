//! Closed-loop LNG case with the guard (f64) commanding the exchanger: prints the
//! true drain, the guard's estimate and the valve every 2.5 s around the cycles.
//! `cargo run --release -p eha-sim --example lng_probe`
use eha_guard::{GuardConfig, GuardOf, Restore, Sample};
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
        let o = g.step(&Sample {
            current_a: s.current_a as f32,
            p_a_bar: s.p_a_bar as f32,
            p_b_bar: s.p_b_bar as f32,
            speed_rpm: s.speed_rpm as f32,
            position_mm: s.position_mm as f32,
            ambient_c: s.ambient_c as f32,
        });
        last_pred = o.drain_c as f64;
        Ok(Control { lng_valve: Some(o.valve_open), stop: false })
    })?;
    Ok(())
}
