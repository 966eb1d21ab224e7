use eha_sim::{rig::Rig, scenario::Scenario, plant::{Plant, Control}, sim::channels};
fn main() {
    let rig = Rig::default();
    let mut p = Plant::new(&rig, &Scenario::Case2 { duration_s: 60.0 }).unwrap();
    let r = p.run(0.5, 60.0, |s| {
        if s.t > 30.0 || s.t < 3.0 { let c = channels(s); let g = |n: &str| c.iter().find(|x| x.0 == n).unwrap().1;
        println!("t={:.1} x={:.2} v={:.1} pa={:.2} pb={:.2} rpm={:.1} I={:.1} tdrain={:.2} tloop={:.2} tact={:.2} tin={:.2} tout={:.2}", s.t, g("position_mm"), g("velocity_mm_s"), g("p_a_bar"), g("p_b_bar"), g("speed_rpm"), g("current_a"), g("t_drain_c"), g("t_loop_oil_c"), g("t_actuator_c"), g("t_inlet_c"), g("t_outlet_c")); }
        Ok(Control::default())
    });
    println!("{:?} {:?}", r, p.stats());
}
