//! Scratch: the firmware's reduced-order model (`eha_guard::rom`, f64) in closed loop
//! with the reference: the model's own 40/38 thermostat (2 s dwell) at model steps.
use eha_guard::protection::{Valve, ValveConfig};
use eha_guard::model::{Model, ModelInputN};
use eha_sim::network::Node;
use eha_sim::plant::{Control, Plant, Sensors};
use eha_sim::reduce::reduce;
use eha_sim::rig::Rig;
fn main() {
    let arg = std::env::args().nth(1).unwrap_or("4".into());
    let every: usize = std::env::args().nth(2).and_then(|s| s.parse().ok()).unwrap_or(1000);
    let Some(sc) = eha_sim::missions::run_by_name(&arg) else {
        eprintln!("unknown run {arg:?}: expected lng, case2, c1-<bar> or a random-mission seed");
        std::process::exit(2);
    };
    let rig = Rig::default();
    let p = reduce(&rig).expect("reduce");
    let mut m = Model::<f64>::new(&p).expect("model");
    let mut plant = Plant::new(&rig, &sc).unwrap();
    let cfg = ValveConfig { dwell_ticks: 20, ..ValveConfig::DEFAULT };
    let mut valve = Valve::new();
    let mut k = 0usize;
    let mut prev_x = 0.0;
    let mut max_e = 0.0f64;
    let mut events = 0;
    plant.run(0.01, 600.0, |snap| {
        let s = Sensors::from(snap);
        if k == 0 {
            m.set_uniform(s.ambient_c);
            prev_x = s.position_mm;
        }
        let e = m.drain_c() - s.t_drain_c;
        max_e = max_e.max(e.abs());
        if k.is_multiple_of(every) {
            let t = m.temperatures_c();
            let l = m.links_c();
            let rho = rig.oil.rho(40.0, 0.0);
            let f = eha_sim::hydraulics::flows(&rig, &snap.op, rig.pump.gaps.conductance(rig.oil.mu_pa_s(40.0)));
            let mm = rho * (snap.op.q_path.abs() + f.leak_a.max(0.0) + f.leak_b.max(0.0));
            let tl = snap.temp(Node::Loop);
            let qref = if valve.is_open() { rig.lng.exchanger_w(mm * rig.oil.cp(tl), tl) } else { 0.0 };
            println!("   q_lng model {:8.2} W ref {:8.2} W", m.last_lng_kw() * 1e3, qref);
            println!("{:6.1} v {} drain {:6.2} e {:+.4} | pump {:+.3} loop {:+.3} mb {:+.3} bb {:+.3} act {:+.3} | in {:+.3} out {:+.3} ball {:+.3}",
                s.t, valve.is_open() as u8, s.t_drain_c, e, t[0] - snap.temp(Node::Pump), t[2] - snap.temp(Node::Loop), t[3] - snap.temp(Node::MainBlock),
                t[4] - snap.temp(Node::BallBlock), t[5] - snap.temp(Node::Actuator), l[0] - snap.temp(Node::Inlet), l[1] - snap.temp(Node::Outlet), l[2] - snap.temp(Node::BallOil));
        }
        let u = ModelInputN::from_wire_f64(s.current_a, s.p_a_bar, s.p_b_bar, s.speed_rpm, s.position_mm - prev_x, s.ambient_c);
        prev_x = s.position_mm;
        if m.tick_n(&u) {
            let was = valve.is_open();
            m.update(if was { 10 } else { 0 });
            valve.update(m.drain_c() as f32, false, &cfg);
            if valve.is_open() != was { events += 1; }
        }
        k += 1;
        Ok(Control { lng_valve: Some(valve.is_open()), stop: false })
    })
    .unwrap();
    println!("{arg}: max |e| {max_e:.4} K, {events} valve events");
}
