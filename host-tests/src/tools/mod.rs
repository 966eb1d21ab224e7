//! Tools layer: what a user runs and reads, on top of the simulation.
//!
//! - [`cli`]: the `eha-sim` subcommands of the simulation;
//! - [`cpu`]: the process's CPU time, for benches and experiments;
//! - [`reduce`]: the firmware's reduced-order parameters from a rig;
//! - [`params_block`]: the firmware's flash parameter block;
//! - [`uq`]: uncertainty bands over the rig's documented parameter ranges;
//! - [`gendoc`], [`rigdoc`]: the generated parts of `docs/`; [`layers`]: the
//!   module graph the layering test reads.

pub mod cli;
pub mod cpu;
pub mod gendoc;
pub mod layers;
pub mod params_block;
pub mod reader_checks;
pub mod reduce;
pub mod rigdoc;
pub mod uq;

#[cfg(test)]
mod reader_props;
