//! Tools layer: what a user runs and reads, on top of the simulation.
//!
//! - [`measured`]: the shared measured-data format (reader with file, line
//!   and column errors; writer);
//! - [`cli`]: the `eha-sim` subcommands of the simulation;
//! - [`plot`]: PNG plots;
//! - [`reduce`]: the firmware's reduced-order parameters from a rig;
//! - [`params_block`]: the firmware's flash parameter block;
//! - [`uq`]: uncertainty bands over the rig's documented parameter ranges.

pub mod cli;
pub mod gendoc;
pub mod layers;
pub mod measured;
pub mod params_block;
pub mod plot;
pub mod reader_checks;
pub mod reduce;
pub mod rigdoc;
pub mod uq;

#[cfg(test)]
mod reader_props;
