//! Diagnosis tests: statistics, replay of measured inputs, the command line,
//! and the hidden-effect cases (fast tier: one case per candidate and the
//! `none` guards; slow tier, `--ignored`: the rest).

mod cli;
mod effects;
mod replay;
mod stats;
