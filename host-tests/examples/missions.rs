//! Prints the random missions of a seed range (speed schedule or servo marker):
//! `cargo run --release -p eha-sim --example missions -- 1 20`.
use eha_sim::missions::random_mission;
use eha_sim::scenario::{Circuit, PositionRef};

fn main() {
    let a: Vec<u64> = std::env::args().skip(1).filter_map(|s| s.parse().ok()).collect();
    let (lo, hi) = (a.first().copied().unwrap_or(1), a.get(1).copied().unwrap_or(10));
    for seed in lo..=hi {
        let m = random_mission(seed, 600.0);
        let amb = m.ambient_c.at(0.0);
        match m.circuit {
            Circuit::Servo => {
                let n = match &m.position { PositionRef::Profile(s) => s.0.len(), _ => 0 };
                println!("seed {seed:>4}: servo, ambient {amb:.1} °C, {n} position points");
            }
            Circuit::Throttle => {
                let segs: Vec<String> = m.speed_rpm.0.iter().zip(m.needle_bar.0.iter()).step_by(2)
                    .map(|((t, w), (_, b))| format!("{t:.0}s:{w:.0}rpm/{b:.0}bar")).collect();
                println!("seed {seed:>4}: throttle, ambient {amb:.1} °C, {}", segs.join(" "));
            }
        }
    }
}
