use eha_sim::{rig::Rig, scenario::Scenario, sim::{simulate, SimOptions}};
fn main() {
    let out = simulate(&Rig::default(), &Scenario::Case2 { duration_s: 900.0 }, &SimOptions { output_interval_s: 0.1, control_interval_s: 0.1 }).unwrap();
    for ch in ["t_drain_c", "t_inlet_c", "t_outlet_c", "t_pump_c"] {
        let d = out.get(ch).unwrap();
        let p: Vec<(f64,f64)> = d.chunks_exact(50).map(|c| (c.iter().sum::<f64>()/50.0, c.iter().cloned().fold(f64::MIN,f64::max)-c.iter().cloned().fold(f64::MAX,f64::min))).collect();
        print!("{ch}: ");
        for k in [0usize, 1, 10, 20, 40, 60, 80, 100, 120, 150, 178] { print!("[{}s d={:.4} sw={:.4}] ", k*5, p[k+1].0-p[k].0, p[k].1); }
        println!();
    }
}
