use eha_sim::{rig::Rig, calibrate::{calibrate, PAPER}};
fn main() {
    let mut rig = Rig::default();
    for a in std::env::args().skip(1) { rig.set_override(&a).unwrap(); }
    let t = std::time::Instant::now();
    let c = calibrate(&rig, &PAPER).unwrap();
    println!("{:?}\nbefore {:?}\nafter {:?}\n{:?}", t.elapsed(), c.before, c.after, c.values);
}
