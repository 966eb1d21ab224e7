//! Regenerates `DEFAULT` in `src/params.rs` by the identification procedure of
//! `eha_sim::identify` (docs/identification.md) and prints the fit.
//!
//! `cargo run --release -p eha-sim --example identify`

use eha_sim::identify::{drain_errors, identify_on, initial_guess, record_training, render_params_rs, splice_params_rs};
use eha_sim::rig::Rig;

fn main() -> anyhow::Result<()> {
    let t0 = std::time::Instant::now();
    let rig = Rig::default();
    let recs = record_training(&rig)?;
    println!("recorded {} training runs in {:.1} s", recs.len(), t0.elapsed().as_secs_f64());
    let p0 = initial_guess(&rig);
    for r in &recs {
        if let Some(e) = drain_errors(&p0, r) {
            println!("initial {:>16}: max |e| {:.3} K, rms {:.3} K", r.name, e.max_abs, e.rms);
        }
    }
    let id = identify_on(&rig, &recs, 0)?;
    println!("LM: {} evaluations, {}, cost {:.3} -> {:.3}", id.evaluations, id.termination, id.cost.0, id.cost.1);
    println!("ambient scale (conservative bias): {:.4}", id.ambient_scale);
    for (n, e) in &id.training {
        println!("{n:>16}: max |e| {:.3} K, rms {:.3} K, max under {:.3} K, max over {:.3} K", e.max_abs, e.rms, e.max_under, e.max_over);
    }
    let rendered = render_params_rs(&id);
    println!("{rendered}");
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/params.rs");
    let text = std::fs::read_to_string(&path)?;
    let new = splice_params_rs(&text, &rendered).ok_or_else(|| anyhow::anyhow!("DEFAULT not found in {}", path.display()))?;
    std::fs::write(&path, new)?;
    println!("wrote {} in {:.1} s", path.display(), t0.elapsed().as_secs_f64());
    Ok(())
}
