//! Reference lumped thermal-hydraulic model of the electro-hydrostatic
//! actuator of Liu et al., "Thermal Characteristic and Analysis of
//! Electro-Hydrostatic Actuator": the oracle for the `eha-guard` firmware and
//! a desk tool for thermal engineers.
//!
//! Layers, one folder each, bottom to top (`tools::layers` and its test keep
//! imports running downwards):
//! - [`data`]: the measured-data format and plots;
//! - [`physics`]: the paper's equations (losses, heat transfer, fluid,
//!   hydraulics, cooling) and the rig's parameters;
//! - [`simulation`]: the model's right-hand side, the stiff solver, the
//!   paper's cases and missions;
//! - [`calibration`]: fitting the model to the paper ([`calibration::paper`])
//!   or to a user's logs, identifiability, commissioning;
//! - [`diagnosis`]: what the model gets wrong on a log, the cause, the gain;
//!   [`emulator`]: the independent truth model of its tests;
//! - [`tools`]: command line, firmware parameters, uncertainty bands,
//!   generated docs; [`pil`] and [`faults`]: the firmware in QEMU against the
//!   plant.
//!
//! The modules are also re-exported at the crate root under their short
//! names (`eha_sim::rig`, `eha_sim::sim`, ...), the paths the tests,
//! examples and benchmarks use.

#![warn(missing_docs)]

pub mod calibration;
pub mod data;
pub mod diagnosis;
pub mod emulator;
pub mod faults;
pub mod physics;
pub mod pil;
pub mod simulation;
pub mod tools;

pub use calibration::{lsq, paper as calibrate};
pub use physics::{air, cooling, fluid, heat, hydraulics, losses, network, rig};
pub use simulation::{equilibrium, fast, missions, model, plant, scenario, sim};
pub use data::{measured, plot};
pub use tools::{cli, gendoc, params_block, reader_checks, reduce, uq};
