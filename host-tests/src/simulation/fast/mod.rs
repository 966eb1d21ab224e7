//! A fast path for the reference model: a multirate scheme (the hydraulic
//! states by an adaptive Rosenbrock method, the node temperatures by
//! exponential steps of the model's own linearised heat balances) that
//! gives the BDF plant's outputs within 0.01 K at a fraction of its cost.
//! See `docs/reference-speed.md` for the profile that led here, the
//! accuracy against the tight BDF solution and the timings.
//!
//! - [`dense`]: fixed-size matrices (products, LU);
//! - [`phi`]: e^{hA} and the φ-functions of exponential integrators;
//! - [`rosenbrock`]: RODAS4 for small stiff systems;
//! - [`options`]: [`FastOptions`] and [`FastStats`];
//! - [`plant`]: [`FastPlant`], the run/callback contract of
//!   [`crate::plant::Plant`] on the multirate scheme.

pub mod dense;
pub mod hydraulic;
pub mod options;
pub mod phi;
pub mod plant;
pub mod rosenbrock;
pub mod thermal;

pub use options::{FastOptions, FastStats, THERMOSTAT_TOL_K};
pub use plant::FastPlant;
