//! Regenerates `DEFAULT` in `src/params.rs` from `Rig::default()` by the
//! reduction of `eha_sim::reduce` (docs/reduction.md).
//!
//! `cargo run --release -p eha-sim --example reduce`

use eha_sim::reduce::{reduce, render_params_rs, splice_params_rs};
use eha_sim::rig::Rig;

fn main() -> anyhow::Result<()> {
    let p = reduce(&Rig::default()).ok_or_else(|| anyhow::anyhow!("the reduced parameters are rejected by the firmware model"))?;
    let rendered = render_params_rs(&p);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/params.rs");
    let text = std::fs::read_to_string(&path)?;
    let new = splice_params_rs(&text, &rendered).ok_or_else(|| anyhow::anyhow!("DEFAULT not found in {}", path.display()))?;
    std::fs::write(&path, new)?;
    println!("wrote {}", path.display());
    Ok(())
}
