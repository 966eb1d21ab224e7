//! FMI 2.0 co-simulation FMUs of the EHA reference plant and of the firmware
//! guard, for system simulators (Simcenter AMESim, Dymola, OpenModelica,
//! Simulink) and Python (FMPy). One shared library serves both FMUs
//! ([`export`]); `cargo fmu` (the `eha-fmu` binary) packs them.
//!
//! - [`plant::PlantFmu`] (`EhaPlant.fmu`): the reference model, inputs held
//!   over each communication step, every simulated channel as an output.
//! - [`guard::GuardFmu`] (`EhaGuard.fmu`): the firmware's f32 guard, one
//!   10 ms tick per 10 ms of step.
//!
//! docs/fmu.md shows both in FMPy and where they go in the importing tools.

pub mod description;
pub mod export;
pub mod fmi2;
pub mod guard;
pub mod plant;
