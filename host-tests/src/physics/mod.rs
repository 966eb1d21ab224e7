//! Physics layer: the paper's equations as functions of state and
//! parameters, no time integration.
//!
//! - [`rig`]: every parameter of the machine, with its source (Table N,
//!   assumed or calibrated);
//! - [`fluid`]: oil and air properties, the oil enthalpy h(T, p);
//! - [`losses`]: eqs. (1)–(11) and the extended eq. (8);
//! - [`heat`]: film, convection and radiation correlations, eqs. (12)–(19);
//! - [`network`]: nodes, capacities and conductances;
//! - [`hydraulics`]: pump, valves, lines, cylinder, position loop;
//! - [`cooling`]: the LNG exchanger, eqs. (20)–(25);
//! - [`candidates`]: the model extensions a diagnosis tries, with their
//!   realistic magnitudes.

pub mod air;
pub mod candidates;
pub mod cooling;
pub mod fluid;
pub mod heat;
pub mod hydraulics;
pub mod losses;
pub mod mission;
pub mod network;
pub mod rig;
