//! Reference lumped thermal-hydraulic model of the electro-hydrostatic
//! actuator of Liu et al., "Thermal Characteristic and Analysis of
//! Electro-Hydrostatic Actuator" (the oracle for the `eha-guard` firmware).

pub mod diagnosis;
pub mod measured;
