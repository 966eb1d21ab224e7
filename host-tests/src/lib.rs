//! Reference lumped thermal-hydraulic model of the electro-hydrostatic
//! actuator of Liu et al., "Thermal Characteristic and Analysis of
//! Electro-Hydrostatic Actuator": the oracle for the `eha-guard` firmware and
//! a desk tool for thermal engineers.
//!
//! Module per physical concern: [`fluid`] (oil, air), [`losses`] (eqs. 1–11),
//! [`heat`] (eqs. 12–19), [`network`] (nodes, capacities, conductances),
//! [`hydraulics`] (pump, valves, cylinder, position loop), [`cooling`] (LNG,
//! eqs. 20–25), [`model`] (the right-hand side), [`plant`] (the stiff solver),
//! [`scenario`] (paper cases, missions, replay), [`sim`] (runs and outputs).

pub mod calibrate;
pub mod calibration;
pub mod cli;
pub mod cooling;
pub mod diagnosis;
pub mod emulator;
pub mod equilibrium;
pub mod faults;
pub mod fluid;
pub mod heat;
pub mod hydraulics;
pub mod missions;
pub mod losses;
pub mod lsq;
pub mod measured;
pub mod model;
pub mod network;
pub mod params_block;
pub mod pil;
pub mod plant;
pub mod plot;
pub mod reduce;
pub mod reader_checks;
pub mod rig;
pub mod scenario;
pub mod sim;

#[cfg(test)]
mod reader_props;
