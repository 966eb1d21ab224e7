use eha_sim::calibration::synthetic::{log, mission, other_rig_file, Kind};
use eha_sim::diagnosis::reference::replay_inputs;
use eha_sim::plant::{Control, Plant, Sensors};
use eha_sim::scenario::Scenario;
use eha_guard::model::{Model, ModelInputN};
fn main() {
    let rig = other_rig_file();
    let p = eha_sim::reduce::reduce(&rig).unwrap();
    let run = log(&rig, &mission(Kind::SpeedSteps, 1800.0, 32), 2.0, 32, true).unwrap();
    let inputs = replay_inputs(&run, "ss").unwrap();
    let t_end = run.time_s[run.len() - 1];
    let mut plant = Plant::new(&rig, &Scenario::Replay(inputs)).unwrap();
    let mut m = Model::<f64>::new(&p).unwrap();
    let mut k = 0usize; let mut prev_x = 0.0;
    plant.run(0.01, t_end, |snap| {
        let s = Sensors::from(snap);
        if k == 0 { m.set_uniform(s.ambient_c); prev_x = s.position_mm; }
        if k % 2000 == 0 {
            let t = m.temperatures_c();
            let q = rig.displacement_m3_per_rad() * s.speed_rpm.abs() * std::f64::consts::PI / 30.0;
            let r = rig.oil.nu_m2_per_s(40.0) / rig.oil.nu_m2_per_s(s.t_loop_oil_c);
            let re: Vec<f64> = p.re_per_flow.iter().map(|x| x * 1e4 * q * r).collect();
            println!("Re {:.0?}", re);
            println!("t {:.0} rpm {:.0} pa {:.1} pb {:.1} ref drain {:.2} est {:.2} (e {:+.2}) ref loop {:.2} est {:.2} ref pump {:.2} est {:.2}", s.t, s.speed_rpm, s.p_a_bar, s.p_b_bar, s.t_drain_c, t[1], t[1]-s.t_drain_c, s.t_loop_oil_c, t[2], snap.temps[2], t[0]);
        }
        let u = ModelInputN::from_wire_f64(s.current_a, s.p_a_bar, s.p_b_bar, s.speed_rpm, s.position_mm - prev_x, s.ambient_c);
        prev_x = s.position_mm;
        if m.tick_n(&u) { m.update(0); }
        k += 1;
        Ok(Control { lng_valve: Some(false), stop: false })
    }).unwrap();
}
