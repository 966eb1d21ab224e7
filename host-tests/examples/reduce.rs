//! Regenerates `DEFAULT` in `src/params.rs` (and its model constants,
//! `src/model/default_consts.rs`) from `Rig::default()` by the
//! reduction of `eha_sim::reduce` (docs/reduction.md).
//!
//! `cargo run --release -p eha-sim --example reduce [-- --consts-only]`

use eha_sim::reduce::{reduce, render_default_consts_rs, render_params_rs, splice_params_rs};
use eha_sim::rig::Rig;

fn main() -> anyhow::Result<()> {
    // `--consts-only`: only `src/model/default_consts.rs`, from the `DEFAULT` compiled in
    // (after editing `DEFAULT` by hand, or to check that the two agree).
    if std::env::args().any(|a| a == "--consts-only") {
        return write_consts(&eha_guard::params::DEFAULT);
    }
    let p = reduce(&Rig::default()).ok_or_else(|| anyhow::anyhow!("the reduced parameters are rejected by the firmware model"))?;
    let rendered = render_params_rs(&p);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/params.rs");
    let text = std::fs::read_to_string(&path)?;
    let new = splice_params_rs(&text, &rendered).ok_or_else(|| anyhow::anyhow!("DEFAULT not found in {}", path.display()))?;
    std::fs::write(&path, new)?;
    println!("wrote {}", path.display());
    write_consts(&p)
}

fn write_consts(p: &eha_guard::params::ReducedParams) -> anyhow::Result<()> {
    let consts = render_default_consts_rs(p).map_err(|e| anyhow::anyhow!("model constants rejected: {e:?}"))?;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/model/default_consts.rs");
    std::fs::write(&path, consts)?;
    println!("wrote {}", path.display());
    Ok(())
}
