//! PNG plot of a PIL run (not implemented yet: see the module's caller).

use std::path::{Path, PathBuf};

/// Writes the plot when plotting is available; returns its path, or `None`
/// (with a note on stderr) when it is not.
pub fn plot_if_available(_records: &[super::StepRecord], _path: &Path) -> anyhow::Result<Option<PathBuf>> {
    eprintln!("note: PNG plot not written (no plotting backend in this build yet); the CSV has every column");
    Ok(None)
}
