//! Diagnosis of a measured run against the reference model:
//! drive the model with the measured inputs, calibrate a nuisance set on a
//! training window, show where and how the residuals are structured, fit
//! every candidate extension, name the cause by BIC plus held-out gain, and
//! report the before/after errors.

pub mod adequacy;
pub mod analysis;
pub mod detect;
pub mod evidence;
pub mod fit;
pub mod identify;
pub mod model;
pub mod multi;
pub mod plan;
pub mod plan_cli;
pub mod plot;
pub mod progress;
pub mod projection;
pub mod regressors;
pub mod report;
pub mod reference;
pub mod stats;
pub mod sweep;
pub mod synth;
pub mod cli;
pub mod emu_result;
pub mod emu_sweep;
pub mod emu_tables;
pub mod emu_calibration;
pub mod gate_obs;

pub use analysis::{diagnose, DiagnoseError, DiagnoseOptions, Diagnosis};
pub use model::{Candidate, ParamSpec, Phase, SimSeries, Simulator};
