//! Diagnosis tests: statistics, replay of measured inputs, the command line,
//! and the hidden-effect cases (fast tier: one case per candidate and the
//! `none` guards; slow tier, `--ignored`: the rest), and the same on logs
//! of the independent rig emulator (`emulator.rs`).

mod cli;
mod detect;
mod effect_free;
mod effects;
mod hidden;
mod emulator;
mod imprint;
mod multi;
mod plan;
mod replay;
mod stats;
mod structure;
mod unseen_sets;
