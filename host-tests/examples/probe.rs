//! Prints the reduced model (`params::DEFAULT`) against the reference on a seeded
//! random mission, every 20 s: `cargo run --release -p eha-sim --example probe -- 24`.
use eha_guard::params::DEFAULT;
use eha_sim::identify::{random_mission, record, simulate_reduced};
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;

fn main() -> anyhow::Result<()> {
    let seed: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(24);
    let rec = record(&Rig::default(), "probe", &Scenario::Mission(random_mission(seed, 600.0)))?;
    let pred = simulate_reduced(&DEFAULT, &rec).ok_or_else(|| anyhow::anyhow!("model"))?;
    println!("   t    rpm   dp_bar | drain ref/model | pump ref/model | loop ref/model | block ref/model | motor ref/model");
    for k in (0..pred.len()).step_by(2000) {
        let s = &rec.sensors[k + 1];
        let (r, m) = (&rec.temps[k + 1], &pred[k]);
        println!(
            "{:5.0} {:6.0} {:7.1} | {:6.2} {:6.2} | {:6.2} {:6.2} | {:6.2} {:6.2} | {:6.2} {:6.2} | {:6.2} {:6.2}",
            s.t, s.speed_rpm, s.p_a_bar - s.p_b_bar, r[5], m[5], r[2], m[2], r[3], m[3], r[4], m[4], r[1], m[1]
        );
    }
    Ok(())
}
