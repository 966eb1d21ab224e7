use eha_sim::{rig::Rig, scenario::Scenario, sim::{simulate, SimOptions}};
fn main() {
    let mut rig = Rig::default();
    for a in std::env::args().skip(1) { rig.set_override(&a).unwrap(); }
    for sc in [Scenario::Case1 { needle_bar: 60.0, duration_s: 600.0 }, Scenario::Case1 { needle_bar: 0.0, duration_s: 600.0 }, Scenario::Lng { duration_s: 600.0 }, Scenario::Case2 { duration_s: 120.0 }] {
        let t = std::time::Instant::now();
        let o = simulate(&rig, &sc, &SimOptions { output_interval_s: 10.0, control_interval_s: 0.1 }).unwrap();
        let el = t.elapsed();
        println!("{} : {:?} rhs={} steps={} open={:?}", o.name, el, o.stats.rhs_evals, o.stats.steps, o.valve_open_times_s.first());
        for c in ["t_inlet_c","t_outlet_c","t_drain_c","t_pump_c","t_motor_c","t_block_c","t_ballvalve_c","t_oil_c","t_loop_oil_c","t_winding_c","p_a_bar","p_b_bar","current_a","speed_rpm","p_total_w","p_cu_w","p_leak_w","p_mech_w","p_throttle_w","p_line_w","e_loss_j","e_stored_j","e_ambient_j","e_lng_j"] {
            print!("{}={:.3} ", c, o.last(c).unwrap());
        }
        println!("\n  max drain {:.2}", o.max("t_drain_c").unwrap());
    }
}
