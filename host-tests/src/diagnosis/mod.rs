//! Diagnosis of a measured run against the reference model (issue 5):
//! residual statistics, calibration, candidate extensions ranked by BIC and
//! held-out improvement, report writing.

pub mod stats;
