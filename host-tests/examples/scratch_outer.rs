use eha_sim::network::{self, Shape};
use eha_sim::rig::Rig;
fn main() {
    let rig = Rig::default();
    let p = eha_guard::params::DEFAULT;
    let d = rig.pump.diameter_m; let a = rig.pump.area_m2;
    for (tw, ta) in [(16.5, 16.0), (20.0, 16.0), (25.0, 16.0), (40.0, 16.0), (60.0, 16.0), (80.0, 16.0), (100.0, 16.0), (40.0, 0.0)] {
        let r = network::q_outer(&rig, a, Shape::Cylinder(d), tw, ta, 0.0);
        let dt: f64 = tw - ta;
        let tm = 0.5 * (tw + ta) + 273.15;
        let f = (p.outer_w_per_k[0] + p.outer_quarter_w_per_k125[0] * dt.powf(0.25) + 4.0 * p.outer_rad_w_per_k4[0] * tm * (tm * tm + dt * dt / 4.0)) * dt;
        println!("pump tw {tw} ta {ta}: reference {r:.3} W firmware {f:.3} W ({:+.2} %)", 100.0 * (f - r) / r);
    }
}
